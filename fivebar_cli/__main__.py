"""`python -m fivebar_cli` runs the command-line tool."""

from fivebar_cli.cli import main

main()
