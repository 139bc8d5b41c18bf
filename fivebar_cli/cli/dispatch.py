"""One command name, two commands: `fivebar aspects | locate | path CONFIG ...` go to the five-bar's
commands, or to the pose-space ones (`cli/pose_aspects.py`) when the kind in CONFIG declares a
`PoseAspectModel` (the 3-RPR: aspects over (x, y, phi), `--pose X Y PHI`, `--legs R1 R2 R3`).

The two commands keep their own options and help; the choice is made from the mechanism file
before either parses the command line for good: each parses it leniently to find its CONFIG,
and the `type` in the file decides (the rest of the file is validated once, by the command chosen).
A file whose type cannot be read goes to the first command, which reports it as it always did.
"""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.mechanisms.base import Mechanism


def _config_of(command: click.Command, info_name: str, args: list[str]) -> Path | None:
    """CONFIG as `command` would read it from `args`, parsed leniently in a context of its own (a
    parent's `meta` would keep what the options' callbacks record)."""
    try:
        ctx = command.make_context(info_name, list(args), resilient_parsing=True)
    except (click.ClickException, click.exceptions.Exit):
        return None
    value = ctx.params.get("config_path")
    return Path(value) if value else None


def _first_file(args: list[str]) -> Path | None:
    """The first argument that names a file, or a shipped example (`cli.options.CONFIG`), if any."""
    from fivebar_cli.cli.options import CONFIG

    for arg in args:
        if arg == "--":
            break
        if arg.startswith("-"):
            continue
        try:
            path = CONFIG.convert(arg, None, None)
        except click.ClickException:
            continue
        if path.is_file():
            return path
    return None


def _declares_pose_aspects(path: Path) -> bool:
    """Whether the file's `type` names a kind with a pose-space aspect model: the type alone is read
    (the command chosen validates the whole file, once; a file it cannot read goes to `other`)."""
    from fivebar_cli.errors import FivebarError
    from fivebar_cli.io.schema import read_yaml
    from fivebar_cli.mechanisms.registry import is_kind, kind_class

    try:
        kind = read_yaml(path).get("type")
    except FivebarError:
        return False
    return is_kind(kind) and kind_class(kind).pose_aspect_model is not Mechanism.pose_aspect_model


class ByKind(click.Command):
    """`other`'s name, help and options; the arguments go to `pose` when CONFIG's kind declares a
    pose-space aspect model. `--help` shows both commands' help."""

    def __init__(self, other: click.Command, pose: click.Command):
        super().__init__(other.name, params=list(other.params), help=other.help, short_help=other.short_help,
                         context_settings=other.context_settings)
        self.other, self.pose = other, pose

    def _choose(self, info_name: str, args: list[str]) -> click.Command:
        """`pose` when CONFIG (as either command reads the arguments) is a mechanism file whose kind
        declares a pose-space aspect model, else `other`."""
        for command in (self.other, self.pose):
            path = _config_of(command, info_name, args)
            if path is not None and path.is_file():
                return self.pose if _declares_pose_aspects(path) else self.other
        # neither parses (an option of neither, a value of the wrong count): the first argument that
        # names a mechanism file decides, so that the command of its kind names the fault (the
        # five-bar's read a 3-RPR's `--pose X Y PHI` as a pose and an option '-5')
        path = _first_file(args)
        return self.pose if path is not None and _declares_pose_aspects(path) else self.other

    def make_context(self, info_name, args, parent=None, **extra):
        head = args[:args.index("--")] if "--" in args else args
        if any(a in ("--help", "-h") for a in head):
            ctx = click.Context(self, info_name=info_name, parent=parent)
            click.echo(self.get_help(ctx))
            ctx.exit(0)
        return self._choose(info_name, args).make_context(info_name, args, parent=parent, **extra)

    def get_help(self, ctx: click.Context) -> str:
        first = click.Context(self.other, info_name=ctx.info_name, parent=ctx.parent)
        second = click.Context(self.pose, info_name=ctx.info_name, parent=ctx.parent)
        return (self.other.get_help(first) + "\n\nFor a kind whose aspects live in one space of poses "
                "(a 3-RPR over x, y, phi):\n\n" + self.pose.get_help(second))
