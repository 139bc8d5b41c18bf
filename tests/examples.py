"""Documentation that runs: every example of every `--help` text and every shell block of the README,
run as pasted, in a temporary copy of the repository (tests/test_examples.py, tests/test_readme.py).

- **Help examples**: the lines starting with `fivebar ` in the `Example(s):` block of each command's
  help, found by walking the click group, so that a new command's examples are picked up.
- **README shell blocks**: every fenced block (no language, `sh`, `bash`, `console`, `shell`) holding
  command lines, that is whose first line is one: `$ COMMAND` (a transcript: the lines up to the
  next `$ ` are what it prints) or a line starting with `fivebar ` or `make `. Blocks of other
  content (YAML, Python, benchmark tables, `.qt` text) are not commands. A block is left out only when the line just above its fence is
  `<!-- not run: REASON -->`; `NOT_RUN` lists them, and the tests check it stays that short list.
- **Transcripts**: what a command prints (stdout, then stderr) must begin with the lines shown:
  exactly, except that a line `...` stands for any number of lines and a line ending in `...` for
  any end (a transcript may stop before the `wrote` lines).
  A command whose transcript shows an error line (`: error:`) must fail (status 1 or 2); one whose
  transcript ends with `(exit status N...)`, or a help example followed by `# exit N: ...`, must
  exit N; any other command must succeed.

A command line `fivebar ARGS [> FILE]` runs in this process (tests/cli_helpers.run_cli), which is
`fivebar` exactly (same entry point) at a fraction of a subprocess's cost; any other line (`make`,
a pipe) runs in `bash`, with the venv's `fivebar` first on PATH.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from cli_helpers import ENV, REPO, CliResult, run_cli

README = REPO / "README.md"
# Examples run by another test, as pasted (that test imports this and runs the very line).
ELSEWHERE = {"fivebar reproduce -o out/check --no-plot": "tests/test_golden.py"}
SHELL_LANGUAGES = ("", "sh", "bash", "console", "shell")
NOT_RUN = re.compile(r"^<!--\s*not run:\s*(?P<reason>.+?)\s*-->$")
PROMPT = re.compile(r"^(?:\S*\$ )(?P<command>.*)$")  # `$ fivebar ...`, `login$ dask ...`
COPY_IGNORE = shutil.ignore_patterns(".git", ".venv", "outputs", "__pycache__", ".pytest_cache", ".hypothesis",
                                     "*.egg-info", "build")


@dataclass
class Command:
    """One command line to run, where it comes from, and the output it documents (None: not shown)."""

    where: str
    line: str
    shown: list[str] | None = None
    status: int = 0  # the exit status documented (`# exit N: ...` after a help example; `(exit status N)`)


@dataclass
class Block:
    """A README shell block: its commands, or the reason it is not run."""

    where: str
    commands: list[Command]
    not_run: str | None = None


# ---------------------------------------------------------------- finding them


def help_examples() -> list[Command]:
    """The example lines of every command's --help as it prints (the group first, then its
    commands in order): in every block whose heading starts with `Example`, the lines starting
    with `fivebar `."""
    import click

    from fivebar_cli.cli import cli

    found = []

    def walk(command, path: str, parent=None) -> None:
        # the command's own context settings (-h for --help): click caches the help option it builds here
        ctx = click.Context(command, info_name=path.split()[-1], parent=parent, **command.context_settings)
        in_examples = False
        for line in command.get_help(ctx).splitlines():
            text = line.strip()
            if re.match(r"^Examples?\b.*:$", text):
                in_examples = True
            elif not text:
                in_examples = False
            elif in_examples and text.startswith("fivebar "):
                documented = re.search(r"#\s*exit (\d+)\b", text)
                found.append(Command(f"`{path} --help`", strip_comment(text), None,
                                     int(documented.group(1)) if documented else 0))
        if isinstance(command, click.Group):  # the commands as click lists them (`cli` imports them on first use)
            for name in command.list_commands(ctx):
                walk(command.get_command(ctx, name), f"{path} {name}", ctx)

    walk(cli, "fivebar")
    return found


def strip_comment(line: str) -> str:
    """The line without a trailing shell comment (`  # ...`)."""
    cut = re.search(r"\s+#(\s|$)", line)
    return line[: cut.start()] if cut else line


def readme_blocks(text: str | None = None) -> list[Block]:
    """The README's shell blocks, in order."""
    lines = (README.read_text(encoding="utf-8") if text is None else text).splitlines()
    blocks, i = [], 0
    while i < len(lines):
        fence = re.match(r"^```(\w*)\s*$", lines[i])
        if not fence:
            i += 1
            continue
        end = next(j for j in range(i + 1, len(lines)) if lines[j].startswith("```"))
        body = lines[i + 1:end]
        above = NOT_RUN.match(lines[i - 1].strip()) if i else None
        first = next((line for line in body if line.strip() and not line.lstrip().startswith("#")), "")
        if fence.group(1) in SHELL_LANGUAGES and _is_command(first):
            blocks.append(Block(f"README.md line {i + 1}", _commands(body, i + 2),
                                above.group("reason") if above else None))
        i = end + 1
    return blocks


def _is_command(line: str) -> bool:
    return bool(PROMPT.match(line)) or line.startswith(("fivebar ", "make "))


def _commands(body: list[str], first: int) -> list[Command]:
    """The commands of a block: transcripts (`$ ...` and the lines it prints) or plain command lines."""
    commands = []
    for n, line in enumerate(body):
        prompt = PROMPT.match(line)
        if prompt:
            commands.append(Command(f"README.md line {first + n}", strip_comment(prompt.group("command")), []))
        elif commands and commands[-1].shown is not None:
            commands[-1].shown.append(line)
        elif line.strip() and not line.lstrip().startswith("#"):
            commands.append(Command(f"README.md line {first + n}", strip_comment(line.strip())))
    return commands


# ---------------------------------------------------------------- running them


def sandbox(root: Path) -> Path:
    """A copy of the repository (without .git, the venv or outputs) to run the examples in."""
    copy = root / "repository"
    shutil.copytree(REPO, copy, ignore=COPY_IGNORE)
    return copy


def run(command: Command, cwd: Path) -> CliResult:
    """Run one command line as pasted (see the module's docstring)."""
    words = shlex.split(command.line)
    if words and words[0] == "fivebar" and not set(words) & {"|", "&&", ";", "<", ">>", "2>"}:
        if len(words) >= 3 and words[-2] == ">":  # `fivebar ... > FILE`: standard output into FILE
            result = run_cli(*words[1:-2], cwd=cwd)
            (cwd / words[-1]).write_text(result.stdout, encoding="utf-8")
            return CliResult(result.status, "", result.stderr)
        return run_cli(*words[1:], cwd=cwd)
    env = dict(ENV, PATH=f"{Path(sys.executable).parent}{os.pathsep}{ENV.get('PATH', '')}")
    r = subprocess.run(["bash", "-c", command.line], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
    return CliResult(r.returncode, r.stdout, r.stderr)


EXIT = re.compile(r"^\(exit status (\d+)\b.*\)$")


def check(command: Command, result: CliResult) -> None:
    """The status and, for a transcript, the printed lines."""
    printed = result.stdout.splitlines() + result.stderr.splitlines()
    shown = list(command.shown or [])
    status = EXIT.match(shown[-1]) if shown else None
    if status:
        shown.pop()
    fails = any(": error:" in line for line in shown)
    context = f"{command.where}: `{command.line}` exited {result.status}:\n" + "\n".join(printed[-30:])
    if status or command.status:
        assert result.status == (int(status.group(1)) if status else command.status), context
    else:
        assert (result.status in (1, 2)) if fails else result.status == 0, context
    if command.shown is not None:
        assert matches([*shown, "..."], printed), (
            f"{command.where}: `{command.line}` printed\n" + "\n".join(printed) + "\n\nthe README shows\n"
            + "\n".join(command.shown))


def matches(shown: list[str], printed: list[str]) -> bool:
    """Whether the printed lines are what the transcript shows (`...` lines and line ends as wildcards)."""
    if not shown:
        return not printed
    head, rest = shown[0], shown[1:]
    if head.strip() == "...":
        return any(matches(rest, printed[k:]) for k in range(len(printed) + 1))
    if not printed:
        return False
    if head.rstrip().endswith("..."):
        ok = printed[0].startswith(head.rstrip()[:-3].rstrip(" ,"))
    else:
        ok = printed[0].rstrip() == head.rstrip()
    return ok and matches(rest, printed[1:])
