"""Run the installed ``hexapod-workspace`` console script in a subprocess."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def cli_command() -> list[str]:
    """The console script next to this interpreter, else ``python -m hexapod_workspace``."""
    script = Path(sys.executable).with_name("hexapod-workspace")
    return [str(script)] if script.exists() else [sys.executable, "-m", "hexapod_workspace"]


def run_cli(*args: str, timeout: float = 300.0, **kwargs) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env.setdefault("MPLBACKEND", "Agg")
    return subprocess.run(
        [*cli_command(), *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        check=False,
        **kwargs,
    )
