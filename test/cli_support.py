"""Run the CLI: in this process through ``main(argv, out=, err=)``, or as the installed console
script in a subprocess (a few smoke tests)."""

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


def run_main(*args: str, stdin: str | None = None) -> tuple[int, str, str]:
    """Run ``main(argv, out=..., err=...)`` in this process: (exit code, stdout, stderr)."""
    import io

    from hexapod_workspace.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    if stdin is None:
        code = main(list(args), out=out, err=err)
    else:
        saved = sys.stdin
        sys.stdin = io.StringIO(stdin)
        try:
            code = main(list(args), out=out, err=err)
        finally:
            sys.stdin = saved
    assert "Traceback" not in err.getvalue()
    return code, out.getvalue(), err.getvalue()


def one_error_line(err: str) -> str:
    """The single line of a bad-input report (exit 2), checked to be one line."""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("hexapod-workspace: error: "), err
    return lines[0]
