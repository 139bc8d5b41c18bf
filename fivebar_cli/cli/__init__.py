"""The command line: a thin layer of click commands, one module per command group, over library calls."""

from fivebar_cli.cli.main import cli, main

__all__ = ["cli", "main"]
