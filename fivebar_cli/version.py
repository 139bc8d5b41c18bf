"""The package version (one place: the package top, the CLI's --version and the atlas manifests read it)."""

__version__ = "0.1.0"
