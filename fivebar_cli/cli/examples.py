"""`fivebar examples`: the papers' mechanisms shipped with the package, listed or copied out."""

from __future__ import annotations

from pathlib import Path

import click

from fivebar_cli.cli.options import NamedPath, option_errors, plural, report, wrote


@click.command(short_help="List the shipped example mechanisms, or copy them into a folder.")
@click.option("--copy", "copy_to", type=NamedPath(file_okay=False, path_type=Path), default=None, metavar="DIR",
              help="Copy every example (YAML files, in their subfolders) into DIR, to edit them or to run "
                   "`fivebar reproduce --configs DIR`.")
@click.option("--replace", is_flag=True,
              help="With --copy: also replace the files in DIR that differ from the shipped examples (edited "
                   "copies). Without it such a file stops the copy, and nothing is copied.")
@click.option("--quiet", "-q", is_flag=True, help="Print nothing but errors.")
@option_errors(replace="--replace")
def examples(copy_to, replace, quiet):
    """The mechanisms of both papers, shipped with the package (the repository's configs/): M1 and
    M2 (five-bars), with joint limits and an obstacle, the 3-RPR designs, the 2-RPR and the atlas
    specs. Prints each example's name and file; with --copy DIR, copies them into DIR. A file in
    DIR that differs from the shipped one (an edited copy) is not replaced: the command then
    copies nothing and says which (exit status 1), unless --replace. A file that already holds
    the shipped bytes is left as it is (its modification time too). They work from any folder
    after a plain `pip install`: every command takes an example's name for its CONFIG (`fivebar
    aspects m1`; a file of that name in the folder comes first); in Python,
    `fivebar_cli.load("m1")`; `fivebar reproduce` uses them when ./configs does not exist.

    \b
    Examples:
      fivebar examples
      fivebar examples --copy out/configs
      fivebar examples --copy out/configs --replace
    """
    from fivebar_cli.api import copy_examples, examples as shipped

    if copy_to is None:
        if replace:
            raise click.UsageError("--replace goes with --copy DIR")
        for name, path in shipped().items():
            report(quiet, f"{name:<34} {path}")
        return
    written = copy_examples(copy_to, replace=replace)
    wrote(quiet, written)
    kept = len(shipped()) - len(written)
    if kept:
        report(quiet, f"  left {plural(kept, 'file')} in {copy_to} as they were (already the shipped bytes)")
