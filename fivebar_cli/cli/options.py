"""The registry of the options the commands share (`-o`, `--quiet`, `--no-plot`: `common_options`;
`--depth`, `--tolerance`, `--budget`; a new shared option is one function here, as rasterio's
`rio/options.py`), and what every command does around its one library call: the output folder,
progress bars, reporting, figures off screen. Command-line numbers and angles: `numbers.py`."""

from __future__ import annotations

import sys
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import click

from fivebar_cli.analyses.limits import MAX_ASPECT_DEPTH, MAX_DEPTH, MAX_OCTREE_DEPTH  # noqa: F401 - the commands' depth ranges
from fivebar_cli.cli.numbers import Number
from fivebar_cli.errors import FivebarError, InputError, NotARegularFile, Param, Text
from fivebar_cli.io.files import check_writable_dir
from fivebar_cli.io.layout import output_dir
from fivebar_cli.mechanisms.base import plural  # noqa: F401 - the commands' counts


class NamedPath(click.Path):
    """A path that must name something. An empty value (`-o "$OUT"` with OUT unset) is a usage
    error, not the current folder, where outputs would land unnoticed, or a folder read where a
    file was meant; `.` names the current folder."""

    def convert(self, value, param, ctx):
        if isinstance(value, str) and not value:
            self.fail("an empty name (an unset shell variable?)" + ("; . is the current folder" if self.dir_okay else ""),
                      param, ctx)
        return super().convert(value, param, ctx)


class ConfigPath(NamedPath):
    """A mechanism file (YAML), or where no such file exists the name of a shipped example
    (`fivebar examples`: `fivebar aspects m1` after a plain `pip install`), as `fb.load` takes
    it. Resolved here, before a command looks at the file: `cli/dispatch.py` reads its kind."""

    def convert(self, value, param, ctx):
        if isinstance(value, str) and value and not Path(value).exists():
            from fivebar_cli.api.calls import examples

            value = str(examples().get(value, value))
        return super().convert(value, param, ctx)


CONFIG = ConfigPath(path_type=Path, dir_okay=False)
STDOUT = "-"  # `-o -`: a single-file output written to standard output
STDOUT_META = "fivebar.data_on_stdout"  # click context meta: the report then goes to standard error




def common_options(func=None, *, single: str | None = None, default: str = "outputs/<config name>/"):
    """`-o/--out DIR`, `--no-plot`, `--quiet`: the options every analysis command takes. `single`
    names the one file a command writes without figures; `-o -` then writes it to standard output
    (`data_on_stdout`). `default` is the folder written without -o, as the help shows it."""
    if func is None:
        return lambda f: common_options(f, single=single, default=default)
    dash = (f" `-o -` writes {single} to standard output (no figure)." if single else "")
    func = click.option("--quiet", "-q", is_flag=True, help="Print nothing but errors; no progress bar.")(func)
    func = click.option("--no-plot", is_flag=True, help="Skip the PNG figures (faster).")(func)
    func = click.option(
        "--out", "-o", "out", type=NamedPath(file_okay=False, path_type=Path), default=None,
        help=f"Output folder [default: {default}]." + dash,
    )(func)
    return func


def data_on_stdout(out: Path | None) -> bool:
    """Whether `-o -` asks for the single-file output on standard output; the report lines then go
    to standard error, so that standard output holds the data only."""
    if out is None or str(out) != STDOUT:
        return False
    click.get_current_context().find_root().meta[STDOUT_META] = True
    return True


def refuse_stdout(out: Path | None, what: str) -> None:
    """UsageError for `-o -` on a command whose output is several files."""
    if out is not None and str(out) == STDOUT:
        raise click.UsageError(f"-o -: this command writes {what}, not one file: give a folder "
                               "(./- for a folder named '-')")


FLAGS = {  # a library parameter -> the option that sets it (`option_errors` adds a command's own)
    "allow_serial": "--allow-serial", "assembly_mode": "--assembly-mode", "budget": "--budget", "depth": "--depth",
    "folder": "-o", "geojson": "--geojson", "pose": "--pose", "procedure": "--procedure", "restart": "--restart",
    "scheduler": "--scheduler", "sets_only": "--sets-only", "tolerance": "--tolerance",
    "working_mode": "--working-mode",
}


def as_flags(text: str, flags: dict[str, str] | None = None) -> str:
    """Library text with the parameters it names (`errors.Text`: `depth`, `depth=12`,
    `allow_serial=True`, `procedure='exact'`) spelled as the options that set them (`--depth`,
    `--depth 12`, `--allow-serial`, `--procedure exact`), and nothing else rewritten (a name or a
    path, whatever it holds); a plain str as it is. The one place the command line turns the
    library's names into its own. `flags` adds a command's own options to `FLAGS`."""
    if not isinstance(text, Text):
        return text
    names = {**FLAGS, **(flags or {})}

    def spell(p: Param) -> str:
        if p.name not in names:
            return str(p)
        return names[p.name] if p.value is None or p.value is True else f"{names[p.name]} {p.value}"

    return text.spelled(spell)


@contextmanager
def option_errors(**flags: str) -> Iterator[None]:
    """Library errors in the command line's words (`as_flags`): an InputError on one of the
    `flags` with no source (`range="--range"`) becomes click's usage error on that option;
    any other FivebarError keeps its type and exit status, its parameters spelled as options. A
    context and a decorator: every command's callback is wrapped in it."""
    try:
        yield
    except FivebarError as exc:
        field = exc.field.strip("`") if isinstance(exc, InputError) and not exc.source else None
        if field in flags:
            raise click.BadParameter(as_flags(exc.message, flags), param_hint=flags[field]) from None
        if isinstance(exc, InputError):
            exc.source, exc.field, exc.message = (as_flags(t, flags) for t in (exc.source, exc.field, exc.message))
        exc.args = tuple(as_flags(a, flags) for a in exc.args)
        if isinstance(exc, NotARegularFile):  # (the library's line, and the command line's way around it)
            exc.args = (f"{exc.args[0]} (-o - writes a single-file output to standard output)", *exc.args[1:])
        raise


def depth_option(default: int = 10, limit: int = MAX_DEPTH, octrees: bool = False):
    """`--depth`; with `octrees`, for a command that also paves spaces of three axes, whose limit
    the library checks once the space is known (`limits.check_paving_depth`)."""
    octree = f"; 0..{MAX_OCTREE_DEPTH} for a space of three axes, an octree" if octrees else ""
    return click.option("--depth", "-d", type=click.IntRange(0, limit), default=default, show_default=True,
                        help=f"Maximum depth d of the tree (cells are root/2^d wide; 0..{limit}{octree}).")


def jobs_option(func):
    """`--jobs N`: worker processes for the independent pavings of a command (`analyses.jobs`)."""
    return click.option(
        "--jobs", "-j", type=click.IntRange(1, None), default=None, envvar="FIVEBAR_JOBS", show_envvar=True,
        help="Worker processes for the independent pavings and files [default: one per core]; "
             "1: all in this process. The outputs are the same bytes for any N.",
    )(func)


def tolerance_option(func):
    """`--tolerance T`: every link length widened to [L - T, L + T] (manufacturing tolerances)."""
    return click.option(
        "--tolerance", type=Number(lo=0), default=0.0, show_default=True,
        help="Widen every link length to [L - T, L + T]: black then means valid for every length in "
             "the box (robust), the complement valid for none (impossible).",
    )(func)


def with_tolerance(m, tolerance: float, source):
    """The mechanism with its lengths widened by `tolerance` (0: unchanged)."""
    from fivebar_cli.api.calls import widened

    return widened(m, tolerance, source)


def load_with_aspects(config_path, tolerance: float = 0.0):
    """CONFIG's mechanism (widened by --tolerance), which must have working and assembly modes."""
    from fivebar_cli.api.calls import load, with_aspects

    return with_aspects(load(config_path, tolerance=tolerance), config_path)


def reuse_options(what: str):
    """`-o DIR` (an earlier `aspects` run's folder to reuse) and `--csv` (`what` printed as CSV): locate's."""
    def decorate(func):
        func = click.option("--csv", "as_csv", is_flag=True, help=f"Print the {what} as CSV.")(func)
        return click.option(
            "--out", "-o", "out", type=NamedPath(file_okay=False, path_type=Path), default=None,
            help="Folder of an earlier `aspects` run to reuse when it holds this mechanism at this depth "
                 "[default: outputs/<config name>/]; otherwise the aspects are computed (nothing is written).",
        )(func)
    return decorate


def budget_option(func=None, *, help: str | None = None):
    """`--budget N`: box evaluations local refinement below --depth may spend (aspects, locate)."""
    if func is None:
        return lambda f: budget_option(f, help=help)
    from fivebar_cli.analyses.aspects import DEFAULT_BUDGET

    return click.option(
        "--budget", type=click.IntRange(0, None), default=DEFAULT_BUDGET, show_default=True,
        help=help or ("Box evaluations that local refinement below --depth may spend to join or separate pieces "
                      "(0: none; the count may then stay uncertified)."),
    )(func)


def prepare_out(out: Path | None, name: str, what: str = "several files") -> Path:
    """The output folder (outputs/<name>/ unless --out is given), checked before any computation:
    it is created only when the command writes its first file, so a failed run leaves no folder.
    `-o -` is refused (`what` the command writes instead)."""
    refuse_stdout(out, what)
    return check_writable_dir(output_dir(out, name))


def report(quiet: bool, message: str) -> None:
    """A line of the run summary on stdout (silent with --quiet; on stderr when stdout holds data),
    the parameters it names spelled as options (`as_flags`)."""
    if not quiet:
        ctx = click.get_current_context(silent=True)
        click.echo(as_flags(message), err=bool(ctx and ctx.find_root().meta.get(STDOUT_META)))


@contextmanager
def narrated(quiet: bool) -> Iterator[None]:
    """What the library tells along a call (`logging` records of `fivebar_cli` at INFO: the cluster
    an atlas runs on, say) as lines of the run summary (`report`), under the command's first line;
    nowhere else meanwhile (not to a handler of the root logger too)."""
    import logging

    class Lines(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            report(quiet, "  " + record.getMessage())

    logger, handler = logging.getLogger("fivebar_cli"), Lines()
    before = logger.level, logger.propagate
    logger.addHandler(handler)
    logger.setLevel(logging.INFO)
    logger.propagate = False
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(before[0])
        logger.propagate = before[1]


def wrote(quiet: bool, paths) -> None:
    """List written files, relative where possible (stable and short)."""
    for path in paths:
        report(quiet, f"  wrote {path}")


def offscreen() -> None:
    """The command line draws off screen: it selects matplotlib's Agg backend (the library never does)."""
    import matplotlib

    matplotlib.use("Agg")


def save_files(value, folder: Path, no_plot: bool, **options) -> list[Path]:
    """A result's files in `folder` (`value.save`), its figures drawn off screen unless --no-plot."""
    if not no_plot:
        offscreen()
    return value.save(folder, figures=not no_plot, **options)


@contextmanager
def progress(quiet: bool, length: int, label: str, unit: str | None = None) -> Iterator:
    """A progress bar on stderr, silent with --quiet or when stderr is not a terminal; with `unit`,
    it also shows the count done and the rate (`12.5 designs/s`).

    Yields a callable `advance(n=1)`.
    """
    if quiet or not sys.stderr.isatty():
        yield lambda n=1: None
        return
    start, done = time.monotonic(), [0]

    def rate(_item) -> str | None:
        elapsed = time.monotonic() - start
        return f"{done[0] / elapsed:.3g} {unit}/s" if unit and done[0] and elapsed > 0 else None

    with click.progressbar(length=length, label=label, file=sys.stderr, show_eta=True, show_pos=unit is not None,
                           item_show_func=rate) as bar:
        def advance(n: int = 1) -> None:
            done[0] += n
            bar.update(n, n)

        yield advance
