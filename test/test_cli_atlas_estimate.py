"""The atlas command's cost estimate is measured on the run's own grid (it used
to assume 0.3 s per position and announced 205 core-hours for about 3)."""

from __future__ import annotations

import re

import numpy as np
from cli_support import one_error_line, run_main

from hexapod_workspace.cli.atlas import ESTIMATE_SAMPLES, MAX_POSITIONS
from hexapod_workspace.cli.atlas import measured_seconds_per_position as measured
from hexapod_workspace.core.workspaces.atlas import AtlasGrid, AtlasOptions

ESTIMATE = re.compile(
    r"give (\d+) positions, more than the cap of (\d+) \(about ([\d.e+]+) core-hours: "
    r"([\d.e+]+) ms per position, measured here at (\d+) positions of this grid\)"
)


def test_the_force_message_gives_a_measured_estimate(tmp_path):
    box = ["-0.5", "0.5", "-0.5", "0.5", "-1.45", "-0.9"]
    code, out, err = run_main(
        "atlas", "--box", *box, "--step", "0.01", "--out", str(tmp_path / "a.zarr")
    )
    assert (code, out) == (2, "")
    line = one_error_line(err)
    match = ESTIMATE.search(line)
    assert match, line
    count, cap, hours, ms, timed = match.groups()
    assert int(count) == AtlasGrid.box([-0.5, 0.5, -0.5, 0.5, -1.45, -0.9], 0.01).size
    assert int(cap) == MAX_POSITIONS and int(timed) == ESTIMATE_SAMPLES
    # the hours are the count times the measured time (to the 3 digits shown)
    np.testing.assert_allclose(float(hours), int(count) * float(ms) / 3.6e6, rtol=2e-2)
    assert "add --force" in line and not (tmp_path / "a.zarr").exists()


def test_the_timed_positions_are_spread_over_the_grid(example):
    grid = AtlasGrid.box([0.0, 0.3, 0.0, 0.0, -1.3, -1.3], 0.1)  # 4 positions
    seconds, timed = measured(example, grid, AtlasOptions(n_phi=12, tolerance=1e-3), samples=8)
    assert timed == grid.size - 1  # every position but the untimed first one
    assert seconds > 0.0
