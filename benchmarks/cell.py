#!/usr/bin/env python3
"""Machining cell: cost of the certified actuator-speed bound and of the reach search, against
the certified path check of the same moves, measured in one run.

* **speeds**: :func:`hexapod_workspace.actuator_rates` (certified peak of dq/ds per move,
  bound within 1 % of the sampled peak) on N random moves of up to 0.3 m and 30° around the
  packaged example's working volume, against :func:`hexapod_workspace.check_path` of the same
  moves (the reachability certificate a CL file gets anyway). Prints ms per 1000 moves for both,
  the ratio, and the samples the speed bound needed per move.
* **curved moves**: the same moves as cubic Bézier curves (inner control points a third and two
  thirds along each move, pushed 20 mm sideways: what a NURBS span of a CL file becomes), checked
  and speed-bounded along the curve, against the straight moves: ms per 1000 moves and the
  ratios.
* **axis limits**: :func:`hexapod_workspace.axis_limits` (12 certified reaches) at a few poses,
  ms per call.

Usage: python benchmarks/cell.py [--moves N] [--repeat R]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from hexapod_workspace import actuator_rates, axis_limits, check_path
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.loading import example_manipulator


def _best(function, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        function()
        times.append(time.perf_counter() - started)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--moves", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3)
    options = parser.parse_args()
    manipulator = example_manipulator()
    rng = np.random.default_rng(18)
    count = options.moves + 1
    positions = np.array([0.0, 0.0, -1.2]) + np.cumsum(rng.uniform(-0.05, 0.05, (count, 3)), 0)
    positions = np.clip(positions, [-0.15, -0.15, -1.35], [0.15, 0.15, -1.05])
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, np.radians(30.0), count),
            rng.uniform(-0.5, 0.5, count),
        ]
    )
    rotations = tt_to_matrix(angles)
    limits = np.full(6, 0.05)
    actuator_rates(manipulator, positions[:3], rotations[:3], speed_limits=limits)  # warm up
    check_path(manipulator, positions[:3], rotations=rotations[:3])
    rates = actuator_rates(manipulator, positions, rotations, speed_limits=limits)
    speed_s = _best(
        lambda: actuator_rates(manipulator, positions, rotations, speed_limits=limits),
        options.repeat,
    )
    path_s = _best(lambda: check_path(manipulator, positions, rotations=rotations), options.repeat)
    per_thousand = 1000.0 / options.moves
    # the refinement makes the largest rate of each move tight (the peak and feed_max use it)
    tightness = rates.peak_bound.max(axis=1) / np.maximum(rates.peak_sampled.max(axis=1), 1e-300)
    print(f"moves: {options.moves} (best of {options.repeat})")
    print(f"  actuator speed bound: {speed_s * per_thousand * 1e3:8.1f} ms per 1000 moves")
    print(f"  check_path:           {path_s * per_thousand * 1e3:8.1f} ms per 1000 moves")
    print(f"  ratio speed / check_path: {speed_s / path_s:.2f}")
    print(
        f"  samples per move: {rates.evaluations / options.moves:.1f}; "
        f"certified / sampled peak per move: median {np.median(tightness):.4f}, "
        f"max {tightness.max():.4f}"
    )
    # the same moves as Bézier curves bulging 20 mm sideways (perpendicular to the move, in z)
    delta = np.diff(positions, axis=0)
    side = np.cross(delta, [0.0, 0.0, 1.0])
    side *= 0.02 / np.maximum(np.linalg.norm(side, axis=1, keepdims=True), 1e-12)
    inner = np.hstack([positions[:-1] + delta / 3 + side, positions[:-1] + 2 * delta / 3 + side])
    curve_path_s = _best(
        lambda: check_path(manipulator, positions, rotations=rotations, beziers=inner),
        options.repeat,
    )
    curve_speed_s = _best(
        lambda: actuator_rates(
            manipulator, positions, rotations, speed_limits=limits, beziers=inner
        ),
        options.repeat,
    )
    print(
        f"  Bézier moves: check_path {curve_path_s * per_thousand * 1e3:8.1f} ms per 1000 moves "
        f"({curve_path_s / path_s:.2f}x the straight moves), actuator speed bound "
        f"{curve_speed_s * per_thousand * 1e3:8.1f} ms ({curve_speed_s / speed_s:.2f}x)"
    )
    poses = [(np.eye(3), np.array([0.0, 0.0, -1.2])), (tt_to_matrix([0.5, 0.3, 0.1]), positions[5])]
    axis_s = min(
        _best(lambda r=r, p=p: axis_limits(manipulator, r, p, frame="tool"), options.repeat)
        for r, p in poses
    )
    print(f"  axis_limits (12 certified reaches): {axis_s * 1e3:.1f} ms per pose")


if __name__ == "__main__":
    main()
