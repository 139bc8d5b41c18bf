"""Running the `fivebar` command line in tests: in-process (the default) or in a subprocess.

`run_cli` calls the console script's entry point, `fivebar_cli.cli.main(argv)`, in this process:
the very code that maps every error to one line on stderr and an exit status, without the cost of
starting Python and importing numpy and matplotlib for each run. Its streams behave like a real
process's (UTF-8; stdout strict, stderr backslash-replacing; not a terminal) and the warnings a
fresh interpreter would print are written to its stderr, so the one-line contract is checked as
users see it. It restores what `main` changes (the SIGINT handler, the warnings filters) and the
working directory; it is not thread-safe.

`run_process` starts `python -m fivebar_cli` for the few tests where the process is the point:
signals, the entry point itself, an address-space limit.

`one_line` checks the failure contract on the result of either; `csv_rows` reads a table a run
wrote; `snapshot` and `check_whole` check
what a run left in its folders (nothing changed, or every file old or complete).
"""

from __future__ import annotations

import csv
import io
import os
import re
import signal
import subprocess
import sys
import warnings
from pathlib import Path
from typing import NamedTuple

from fivebar_cli.cli import main
from fivebar_cli.errors import InputError
from fivebar_cli.io.qtfile import read_qt

REPO = Path(__file__).resolve().parents[1]
MEMORY_LIMIT = 3 << 30  # address-space cap for runs that could otherwise exhaust the machine
ENV = {k: v for k, v in os.environ.items() if k != "FIVEBAR_DEBUG"}
ENV.update(PYTHONPATH=str(REPO), MPLBACKEND="Agg")

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
PNG_END = b"IEND\xaeB`\x82"
TMP_NAME = re.compile(r"^\.(?P<target>.+)\.[A-Za-z0-9_]+\.tmp$")  # files.atomic_write: .<name>.<hex>.tmp

# What a fresh interpreter ignores (python -W / -X dev aside); everything else is printed once.
_DEFAULT_IGNORED = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)


class CliResult(NamedTuple):
    status: int
    stdout: str
    stderr: str


def _exit_status(code) -> tuple[int, str]:
    """The status and stderr text of `sys.exit(code)`, as the interpreter turns them into a process's."""
    if code is None:
        return 0, ""
    if isinstance(code, int):
        return code, ""
    return 1, f"{code}\n"


def run_cli(*args, cwd: Path | str | None = None) -> CliResult:
    """`fivebar ARGS` in this process (working directory `cwd`): its status, stdout and stderr."""
    argv = [str(a) for a in args]
    out_bytes, err_bytes = io.BytesIO(), io.BytesIO()
    out = io.TextIOWrapper(out_bytes, encoding="utf-8", errors="strict", newline="\n", write_through=True)
    err = io.TextIOWrapper(err_bytes, encoding="utf-8", errors="backslashreplace", newline="\n",
                           write_through=True)
    old_cwd, old_streams = os.getcwd(), (sys.stdout, sys.stderr)
    old_sigint = signal.getsignal(signal.SIGINT)
    debug = os.environ.pop("FIVEBAR_DEBUG", None)
    extra = ""
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.resetwarnings()
            warnings.simplefilter("default")
            for category in _DEFAULT_IGNORED:
                warnings.simplefilter("ignore", category)
            if cwd is not None:
                os.chdir(cwd)
            sys.stdout, sys.stderr = out, err
            try:
                main(argv)
            except SystemExit as exc:
                status, extra = _exit_status(exc.code)
            else:  # main always exits; returning is a bug of its own
                raise AssertionError(f"fivebar {' '.join(argv)}: main() returned instead of exiting")
            finally:
                sys.stdout, sys.stderr = old_streams
            for w in caught:
                err.write(warnings.formatwarning(w.message, w.category, w.filename, w.lineno, w.line))
    finally:
        os.chdir(old_cwd)
        signal.signal(signal.SIGINT, old_sigint)
        if debug is not None:
            os.environ["FIVEBAR_DEBUG"] = debug
    err.write(extra)
    return CliResult(status, out_bytes.getvalue().decode("utf-8"), err_bytes.getvalue().decode("utf-8"))


def command(args, memory_limit: bool = False) -> list[str]:
    """The argv of `python -m fivebar_cli ARGS` (under an address-space limit if asked)."""
    args = [str(a) for a in args]
    if not memory_limit:
        return [sys.executable, "-m", "fivebar_cli", *args]
    code = ("import resource, runpy; resource.setrlimit(resource.RLIMIT_AS, (%d, %d)); "
            "runpy.run_module('fivebar_cli', run_name='__main__', alter_sys=True)" % (MEMORY_LIMIT, MEMORY_LIMIT))
    return [sys.executable, "-c", code, *args]


def default_ctrl_c() -> None:
    """`preexec_fn` of a child that must be stoppable by Ctrl-C: a process started with SIGINT ignored
    (pytest run in the background by a shell, nohup) passes that on, and Python then leaves Ctrl-C
    ignored, as the CLI rightly does too."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def run_process(*args, cwd: Path | str | None = None, memory_limit: bool = False, timeout: float = 180) -> CliResult:
    """`python -m fivebar_cli ARGS` in a subprocess: its status, stdout and stderr."""
    r = subprocess.run(command(args, memory_limit), cwd=cwd, env=ENV, capture_output=True, text=True,
                       encoding="utf-8", timeout=timeout)
    return CliResult(r.returncode, r.stdout, r.stderr)


def modules_imported(runs: list[list], prefixes: tuple[str, ...], cwd: Path | str) -> list[str]:
    """The modules whose names start with one of `prefixes` that `fivebar` imported, run in process
    with each argv of `runs` in turn, in a fresh interpreter (every run must succeed), sorted."""
    argvs = [[str(a) for a in argv] for argv in runs]
    code = ("import sys\nfrom fivebar_cli.cli import main\n"
            f"for argv in {argvs!r}:\n"
            "    try:\n        main(argv)\n    except SystemExit as e:\n        assert e.code in (0, None), e.code\n"
            f"print(' '.join(sorted(m for m in sys.modules if m.startswith({tuple(prefixes)!r}))))\n")
    r = subprocess.run([sys.executable, "-c", code], cwd=cwd, env=ENV, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return r.stdout.splitlines()[-1].split()  # (the runs' own output before it)


def csv_rows(path: Path) -> list[dict]:
    """The rows of a CSV file, by column name (the file closed again: no ResourceWarning)."""
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def ok(result: CliResult) -> CliResult:
    """The run succeeded (status 0), else fail with its stderr."""
    assert result.status == 0, (result.status, result.stderr[-2000:])
    return result


def one_line(result: CliResult, status: int, *needles: str) -> str:
    """The failure contract: this status, no traceback, exactly one line on stderr holding every needle."""
    assert "Traceback" not in result.stderr and "Traceback" not in result.stdout, result.stderr[-2000:]
    assert result.status == status, (result.status, result.stderr[-2000:])
    lines = result.stderr.splitlines()
    assert len(lines) == 1, f"expected one line on stderr, got {len(lines)}: {result.stderr[-2000:]!r}"
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


# ---------------------------------------------------------------- what a run left behind


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file below `folder` (relative path -> bytes); empty folders do not count."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def problem_with(path: Path, old: bytes | None) -> str | None:
    """None when `path` is whole: its old bytes, or a complete new file of its kind."""
    data = path.read_bytes()
    if old is not None and data == old:
        return None
    name = path.name
    if name.endswith(".qt"):
        try:
            read_qt(path)
        except InputError as exc:
            return f"not a whole .qt file: {exc}"
    elif name.endswith(".csv"):
        text = data.decode("utf-8", "replace")
        if not text.endswith("\n"):
            return "CSV cut short (no final newline)"
        lines = text.split("\n")[:-1]
        if not lines:
            return "empty CSV"
        if old is not None and lines[0] != old.decode().split("\n")[0]:
            return f"CSV header changed: {lines[0]!r}"
        width = lines[0].count(",")
        short = [i for i, line in enumerate(lines) if line.count(",") != width]
        if short:
            return f"CSV rows {short} do not have {width + 1} cells"
    elif name.endswith(".png"):
        if not (data.startswith(PNG_MAGIC) and data.endswith(PNG_END)):
            return "PNG cut short"
    elif name.endswith(".html"):
        if not (data.startswith(b"<!DOCTYPE html>") and data.endswith(b"</html>\n")):
            return "HTML page cut short"
    return None


def check_whole(folder: Path, before: dict[str, bytes], allow_tmp: bool) -> list[str]:
    """Every file is old or complete, none disappeared; returns the temporary leftovers."""
    after = sorted(p for p in folder.rglob("*") if p.is_file())
    names = {p.relative_to(folder).as_posix() for p in after}
    missing = [rel for rel in before if rel not in names]
    assert not missing, f"outputs disappeared: {missing}"
    problems, leftovers = [], []
    for path in after:
        rel = path.relative_to(folder).as_posix()
        match = TMP_NAME.match(path.name)
        if match and rel not in before:
            leftovers.append(rel)
            continue
        problem = problem_with(path, before.get(rel))
        if problem:
            problems.append(f"{rel}: {problem}")
    assert not problems, problems
    if not allow_tmp:
        assert not leftovers, f"temporary files left: {leftovers}"
    return leftovers
