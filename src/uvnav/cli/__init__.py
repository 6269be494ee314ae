"""Layer 8: the ``uvnav`` command line (Typer app in :mod:`uvnav.cli.app`)."""

from uvnav.cli.app import app, main

__all__ = ["app", "main"]
