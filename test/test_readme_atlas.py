"""The atlas page's Python snippet (``docs/atlas.md``, once the README's), saved as a script
and run as a user would: on a real local Dask cluster (worker processes on
127.0.0.1, which re-import the script), twice (the second run finds the finished store and
returns it), and without its main guard (one clear error, no store left behind). Only the grid
step is coarsened, to keep it short."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytest.importorskip("distributed")

from hexapod_workspace.atlas.store import open_atlas

ROOT = Path(__file__).resolve().parents[1]


def _readme_snippet() -> str:
    """The python block of the atlas page (``docs/atlas.md``) that calls workspace_atlas."""
    page = (ROOT / "docs" / "atlas.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", page, re.DOTALL)
    (snippet,) = [block for block in blocks if "workspace_atlas(m, grid" in block]
    assert "step=0.1)" in snippet
    return snippet.replace("step=0.1)", "step=0.25)")  # 5 x 5 x 3 positions instead of 847


def _run(script: Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != "DASK_SCHEDULER_ADDRESS"}
    env["MPLBACKEND"] = "Agg"
    return subprocess.run(
        [sys.executable, str(script)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        timeout=300,
        check=False,
    )


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    """A folder where the snippet's relative config path resolves, as from the repository."""
    (tmp_path / "config").symlink_to(ROOT / "config")
    return tmp_path


def test_the_readme_atlas_snippet_runs_as_a_script_and_again(folder):
    script = folder / "atlas_example.py"
    script.write_text(_readme_snippet(), encoding="utf-8")
    first = _run(script, folder)
    assert first.returncode == 0, first.stderr[-3000:]
    lines = first.stdout.splitlines()
    assert len(lines) == 2 and "deg best tilt capability" in lines[0], first.stdout
    best = float(lines[0].split()[0])
    assert 30.0 < best < 40.0  # the example's best tilt near the home position (38.5 deg)
    store = open_atlas(folder / "gpm_atlas.zarr")
    assert store.attrs["complete"] is True
    assert dict(store.sizes)["x"] == 5
    # Run again: the finished store is found and returned (resume=True), same answers.
    again = _run(script, folder)
    assert again.returncode == 0, again.stderr[-3000:]
    assert again.stdout == first.stdout


def test_without_the_main_guard_one_clear_error_and_no_store(folder):
    body = _readme_snippet().split('if __name__ == "__main__":', 1)
    unguarded = body[0] + textwrap.dedent(body[1].split("\n", 1)[1])
    assert "__main__" not in unguarded
    script = folder / "unguarded.py"
    script.write_text(unguarded, encoding="utf-8")
    done = _run(script, folder)
    assert done.returncode == 1
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("hexapod_workspace.errors.AtlasError: the local Dask cluster did")
    assert 'under `if __name__ == "__main__":`' in last
    assert not (folder / "gpm_atlas.zarr").exists()  # a re-run after the fix starts cleanly
