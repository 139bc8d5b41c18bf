"""The command line's start-up: the group imports a command's module when the command is asked for
(`cli/main.py`, `LazyGroup`), lists every command with the help an eagerly built group shows, and
`fivebar aspects` imports none of the other commands."""

from __future__ import annotations

import click

from fivebar_cli.cli import cli
from fivebar_cli.cli import aspects, atlas, dkp, examples, kratio, locate, path, pose_aspects, pose_locate, pose_path
from fivebar_cli.cli import refine, reproduce, rpr3, rpr3_octree, spaces, tolerance, verify, view
from fivebar_cli.cli.dispatch import ByKind
from tests.cli_helpers import REPO, modules_imported


def _eager_group() -> click.Group:
    """The group as it was built before commands were imported lazily: every command attached at once."""
    group = click.Group(cli.name, params=list(cli.params), help=cli.help, context_settings=cli.context_settings)
    sub = click.Group(rpr3.rpr3.name, commands=dict(rpr3.rpr3.commands), help=rpr3.rpr3.help,
                      context_settings=rpr3.rpr3.context_settings)
    for command in (rpr3_octree.pave_cmd, rpr3_octree.verify_cmd, dkp.dkp):
        sub.add_command(command)
    for command in (spaces.jointspace, spaces.workspace, ByKind(aspects.aspects, pose_aspects.pose_aspects),
                    ByKind(locate.locate, pose_locate.pose_locate), ByKind(path.path, pose_path.pose_path),
                    dkp.joints_dkp, verify.verify_cmd, atlas.atlas, kratio.kratio, refine.refine, refine.diff,
                    tolerance.tolerance, view.view, sub, reproduce.reproduce, examples.examples):
        group.add_command(command)
    return group


def _help(group: click.Group, *names: str) -> str:
    ctx = click.Context(group, info_name="fivebar", **group.context_settings)
    for name in names:
        group = group.get_command(ctx, name)
        ctx = click.Context(group, info_name=name, parent=ctx, **group.context_settings)
    return group.get_help(ctx)


def test_the_lazy_group_lists_and_helps_every_command_as_the_eager_one():
    eager = _eager_group()
    assert cli.list_commands(None) == sorted(eager.commands) == [
        "aspects", "atlas", "diff", "dkp", "examples", "jointspace", "kratio", "locate", "path", "refine",
        "reproduce", "rpr3", "tolerance", "verify", "view", "workspace"]
    assert _help(cli) == _help(eager)
    assert "jointspace  Certified joint space" in _help(cli)
    assert _help(cli, "rpr3") == _help(eager, "rpr3")
    assert _help(cli, "rpr3", "pave") == _help(eager, "rpr3", "pave")
    for name in eager.commands:
        assert _help(cli, name) == _help(eager, name), name
    assert cli.get_command(None, "nope") is None


def test_a_command_imports_its_own_module_only(tmp_path):
    argv = ["aspects", REPO / "configs" / "m1.yaml", "--depth", "3", "--no-plot", "-q", "-o", "o"]
    assert modules_imported([argv], ("fivebar_cli.cli.", "fivebar_cli.analyses.atlas"), tmp_path) == [
        "fivebar_cli.cli.aspects", "fivebar_cli.cli.dispatch", "fivebar_cli.cli.main", "fivebar_cli.cli.numbers",
        "fivebar_cli.cli.options", "fivebar_cli.cli.pose_aspects", "fivebar_cli.cli.poses"]
    assert (tmp_path / "o" / "aspects.csv").is_file()
