"""Output sets: the files one run of a command writes into a folder, recorded so that a folder
never passes for one run when it mixes two.

An output folder (`outputs/M1/`) is shared by several commands (`workspace`, `jointspace`,
`aspects`, `path`, `tolerance`, ...), so a run cannot swap the whole folder in. Instead each
command writes its files inside `with output_set(folder, "aspects", owns):`

- before its first file changes, `OUT/.fivebar/<set>.json` says `"state": "writing"`;
- every file written inside the block (by any writer of `io.files`) is recorded;
- when the block ends without error, the files the set `owns` (glob patterns) that this run did
  not write are removed (a nominal `workspace` rerun removes the `workspace.band.qt` of an earlier
  tolerance run), then the manifest lists every file of the run with its SHA-256, `"state":
  "complete"`.

A run that fails or is interrupted after its first write leaves the "writing" manifest; one that
fails before writes nothing, and creates no folder. Readers call `read_runs(folder)`: a file is
read when a complete manifest lists it with its very bytes and every other file of that manifest
is there with its bytes too; a file that a set owns (its patterns) but that is not of that set's
complete, whole run is not read (`why` says why: an interrupted run, a run partly replaced by
another one, a file that run did not write). A file no set owns (a folder written before output
sets existed, a command that does not record its runs, a file put there by hand) is taken as it
is: nothing can be checked there.

Adopting it for a new output file is nothing when the file is written inside an existing set's
block, and one `with output_set(...)` line around the writing part of a new command.
"""

from __future__ import annotations

import fnmatch
import hashlib
import json
import os
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Iterator

from fivebar_cli.errors import FivebarWarning
from fivebar_cli.io.files import ACTIVE_SET, check_writable_dir, write_text

MANIFESTS = ".fivebar"
FORMAT = "fivebar-output-set 1"


def manifest_path(folder: Path, name: str) -> Path:
    return Path(folder) / MANIFESTS / f"{name}.json"


def _digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _relative(folder: Path, path: Path) -> str | None:
    """`path` relative to `folder` (posix), or None when it lies outside."""
    rel = os.path.relpath(os.path.abspath(path), os.path.abspath(folder))
    if rel == os.curdir or rel.startswith(os.pardir + os.sep) or rel == os.pardir:
        return None
    return Path(rel).as_posix()


def _save(folder: Path, name: str, content: dict) -> None:
    """Write a manifest (never recorded as a file of the set itself)."""
    token = ACTIVE_SET.set(None)
    try:
        write_text(manifest_path(folder, name), json.dumps(content, indent=1, sort_keys=True) + "\n")
    finally:
        ACTIVE_SET.reset(token)


@dataclass
class OutputSet:
    """One run's files in one folder (see the module's docstring)."""

    folder: Path
    name: str
    command: str
    owns: tuple[str, ...]
    files: dict[str, Path] = field(default_factory=dict)
    started: bool = False

    def before_write(self, path: Path) -> None:
        if not self.started and _relative(self.folder, path) is not None:
            self.started = True
            _save(self.folder, self.name, {"format": FORMAT, "set": self.name, "command": self.command,
                                           "state": "writing", "owns": list(self.owns)})

    def written(self, path: Path) -> None:
        rel = _relative(self.folder, path)
        if rel is not None:
            self.files[rel] = Path(path)

    def owned(self) -> Iterator[Path]:
        """The regular files of the folder that match the set's patterns (of any run)."""
        return owned_files(self.folder, self.owns)

    def commit(self) -> None:
        """Remove this set's files of earlier runs that this run did not write; write the manifest."""
        if not self.started:
            return
        for path in self.owned():
            if _relative(self.folder, path) not in self.files:
                path.unlink(missing_ok=True)
        digests = {rel: _digest(path) for rel, path in sorted(self.files.items())}
        _save(self.folder, self.name, {"format": FORMAT, "set": self.name, "command": self.command,
                                       "state": "complete", "owns": list(self.owns), "files": digests})


@contextmanager
def output_set(folder: str | Path, name: str, owns: Iterable[str], command: str | None = None) -> Iterator[OutputSet]:
    """Write one run's files into `folder` as the set `name` (file `.fivebar/<name>.json`); `owns`
    are the glob patterns (relative to the folder) of the files this set writes in any of its runs;
    `command` names what writes it, for readers' messages (`fivebar <name>` by default). A folder
    that is a file (or under one) is refused before anything is written (`check_writable_dir`), as
    the commands' `-o` is."""
    s = OutputSet(check_writable_dir(folder), name, command or f"fivebar {name}", tuple(owns))
    token = ACTIVE_SET.set(s)
    try:
        yield s
    finally:
        ACTIVE_SET.reset(token)
    s.commit()


# ---------------------------------------------------------------- reading


@dataclass(frozen=True)
class Run:
    """One manifest as found: the set's last run, and which of its files still hold its bytes."""

    name: str
    command: str
    owns: tuple[str, ...]
    files: tuple[str, ...]  # files of the run (empty when it did not complete)
    intact: frozenset[str]  # those still holding the run's bytes
    complete: bool

    @property
    def whole(self) -> bool:
        return self.complete and len(self.intact) == len(self.files)

    def claims(self, rel: str) -> bool:
        return rel in self.files or any(fnmatch.fnmatchcase(rel, pattern) for pattern in self.owns)

    def problem(self) -> str:
        if not self.complete:
            return f"the last run of `{self.command}` did not complete (interrupted or failed): rerun it"
        bad = [rel for rel in self.files if rel not in self.intact]
        if bad:
            return (f"the run of `{self.command}` it belongs to is no longer whole ({bad[0]} was replaced or removed"
                    + (f", and {len(bad) - 1} more" if len(bad) > 1 else "") + "): rerun it")
        return f"a file of `{self.command}` that its last complete run did not write: rerun it"


@dataclass(frozen=True)
class FolderRuns:
    """The runs recorded in a folder, to decide which files may be read together."""

    folder: Path
    runs: tuple[Run, ...] = ()

    def accepts(self, path: str | Path) -> bool:
        """A file of a whole run (every file of that run still holds its bytes), or a file no
        output set claims (a legacy folder, a command that does not record its runs, a file put
        there by hand). What a folder reader (`view`) shows, so that it never mixes two runs."""
        return self.why(path) is None

    def why(self, path: str | Path) -> str | None:
        """None when `accepts(path)`, else why not."""
        rel = _relative(self.folder, Path(path))
        if rel is None or any(rel in run.files and run.whole for run in self.runs):
            return None
        return next((run.problem() for run in self.runs if run.claims(rel)), None)

    def set_of(self, path: str | Path) -> str | None:
        """The output set whose whole run holds this file (None: none)."""
        rel = _relative(self.folder, Path(path))
        return next((run.name for run in self.runs if rel in run.files and run.whole), None)

    def one_run(self, paths) -> str | None:
        """None when these files hold the bytes one complete run wrote (or no set claims any of
        them), else why not: what a reader of a few files (`refine` of a pair) checks."""
        rels = [_relative(self.folder, Path(p)) for p in paths]
        if any(run.complete and all(rel in run.intact for rel in rels) for run in self.runs):
            return None
        claimed = [run for run in self.runs for rel in rels if run.claims(rel)]
        return claimed[0].problem() if claimed else None


def of_complete_runs(folder: str | Path, paths, instead: str) -> bool:
    """Whether every existing file of `paths` may be read (`FolderRuns.accepts`); if not, a
    FivebarWarning names the first that may not, why, and what the reader does `instead`."""
    runs = read_runs(folder)
    foreign = next((Path(p) for p in paths if Path(p).exists() and not runs.accepts(p)), None)
    if foreign is not None:
        warnings.warn(FivebarWarning(f"{foreign}: not read ({runs.why(foreign)}); {instead}"))
    return foreign is None


def read_runs(folder: str | Path) -> FolderRuns:
    """The output sets of `folder`, each run checked file by file against its manifest."""
    folder = Path(folder)
    runs = []
    for path in sorted((folder / MANIFESTS).glob("*.json")):
        try:
            content = json.loads(path.read_text(encoding="utf-8"))
            if not isinstance(content, dict) or content.get("format") != FORMAT:
                continue  # a later format: not ours to judge
            complete = content.get("state") == "complete"
            files = {str(k): v for k, v in (content.get("files") or {}).items()} if complete else {}
            runs.append(Run(path.stem, str(content.get("command") or path.stem),
                            tuple(str(p) for p in content.get("owns") or ()), tuple(files),
                            frozenset(rel for rel, digest in files.items() if _matches(folder / rel, digest)),
                            complete))
        except (OSError, ValueError, TypeError, AttributeError):
            continue
    return FolderRuns(folder, tuple(runs))


def owned_files(folder: Path, patterns: Iterable[str]) -> Iterator[Path]:
    """The regular files of `folder` matching the glob patterns (hidden files left out)."""
    for pattern in patterns:
        for path in sorted(Path(folder).glob(pattern)):
            if path.is_file() and not path.is_symlink() and not path.name.startswith("."):
                yield path


def _matches(path: Path, digest: object) -> bool:
    try:
        return path.is_file() and not path.is_symlink() and _digest(path) == digest
    except OSError:
        return False
