"""The ``hexapod-workspace`` command line: commands, reports, progress, plots, demo."""

from .main import main

__all__ = ["main"]
