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


def polar_labels_clear(figure, axes) -> set[str]:
    """Draw ``figure`` and return the ring labels (texts) of polar ``axes``, after asserting
    that none covers anything plotted there (every line and marker, segments sampled densely),
    in display coordinates."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(figure).get_renderer()
    figure.draw(renderer)
    labels = {text.get_text(): text.get_window_extent(renderer) for text in axes.texts}
    for line in axes.get_lines():
        phi, theta = (np.asarray(v, dtype=float) for v in line.get_data())
        if phi.size == 0:
            continue
        if line.get_linestyle() in ("None", "", " "):  # markers only: the points themselves
            points = np.column_stack([phi, theta])
        else:  # the drawn segments, not only their vertices
            dense, index = np.linspace(0.0, 1.0, 20 * phi.size), np.linspace(0.0, 1.0, phi.size)
            points = np.column_stack([np.interp(dense, index, phi), np.interp(dense, index, theta)])
        shown = axes.transData.transform(points)
        for text, box in labels.items():
            inside = (box.x0 <= shown[:, 0]) & (shown[:, 0] <= box.x1)
            inside &= (box.y0 <= shown[:, 1]) & (shown[:, 1] <= box.y1)
            assert not np.any(inside), (text, line.get_label())
    return set(labels)
