"""`python -m fivebar_cli` runs the command-line tool.

Guarded: worker processes started with the `spawn` method (Dask's LocalCluster) import the main
module again under another name, and must not run the command a second time.
"""

if __name__ == "__main__":
    from fivebar_cli.cli import main

    main()
