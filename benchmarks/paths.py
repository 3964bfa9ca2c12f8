#!/usr/bin/env python3
"""Certified move checks against dense sampling with the same guarantee; torsion planning time.

Dense sampling gives the certified check's guarantee (no violated band wider than the tolerance
is missed) only with a sample at least every ``h = tol / (Ω + |Δp|/ρ)`` along each move (the
tolerance measured as platform rotation or joint travel, as in
:mod:`hexapod_workspace.core.motions`). Both are timed in this run on the same moves:

* short moves: a fine 5-axis toolpath on the packaged example (a helix of tool-tip positions,
  tool axes on a 15° cone, ψ = 0; moves of about 0.6 mm and 0.2°);
* large moves: random moves of ±0.3 m and tilts up to 30° (most cross the workspace boundary).

Then :func:`hexapod_workspace.plan_torsion` on a 1,000-waypoint off-axis toolpath (docs/paths.md's
example shape), without a torsion limit and with ``max_dpsi`` = 5°, timed in the same run with
the compiled dynamic programmes and with the numpy ones they replaced (the plans must be equal).

Usage: python benchmarks/paths.py [--short N] [--large N] [--waypoints N]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

# One core: keep any BLAS threads out of the measurement (set before numpy loads).
for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(variable, "1")

import numpy as np  # noqa: E402

from hexapod_workspace import check_path, plan_torsion  # noqa: E402
from hexapod_workspace._resources import example_config_path  # noqa: E402
from hexapod_workspace.core.base.rotations import approach_vector, tt_to_matrix  # noqa: E402
from hexapod_workspace.core.evaluation.check import pose_margins  # noqa: E402
from hexapod_workspace.core.evaluation.loading import load_manipulator  # noqa: E402
from hexapod_workspace.core.motions import DEFAULT_PATH_TOLERANCE  # noqa: E402
from hexapod_workspace.core.motions.interpolation import _Moves  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "test"))
from planner_reference import numpy_planner  # noqa: E402

#: Samples per pose_margins call of the dense reference (bounded memory).
BATCH = 200_000


def best_of(repeats: int, function) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeats):
        started = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - started)
    return min(times), result


def short_moves(count: int) -> tuple[np.ndarray, np.ndarray]:
    """A helix of tool-tip positions on the axis with tool axes on a 15° cone, ψ = 0
    (40 turns: with 20,000 moves, 0.6 mm and 0.2° of rotation per move)."""
    t = np.linspace(0.0, 80.0 * np.pi, count)
    positions = np.column_stack([0.03 * np.cos(t), 0.03 * np.sin(t), -1.25 - 0.05 * t / t[-1]])
    angles = np.column_stack([t, np.full(count, np.radians(15.0)), np.zeros(count)])
    return positions, angles


def large_moves(count: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(3)
    positions = np.array([0.0, 0.0, -1.15]) + rng.uniform(-0.3, 0.3, (count, 3))
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, np.radians(30.0), count),
            rng.uniform(-0.6, 0.6, count),
        ]
    )
    return positions, angles


def dense(manipulator, positions, angles, tolerance) -> tuple[np.ndarray, int]:
    """Dense sampling with the certified check's guarantee: per move, samples spaced by at most
    h = tol / (Ω + |Δp|/ρ). Returns per-move "no violated sample" and the samples evaluated."""
    rho = float(np.max(np.linalg.norm(manipulator.platform_joints, axis=1)))
    rotations = tt_to_matrix(angles)
    moves = _Moves(positions[:-1], positions[1:], rotations[:-1], rotations[1:], "slerp", rho)
    steps = np.maximum(np.ceil(moves.rate / tolerance).astype(np.int64), 1)
    ok = np.ones(len(steps), dtype=bool)
    total = int(np.sum(steps + 1))
    move_ids = np.repeat(np.arange(len(steps)), steps + 1)
    starts = np.concatenate([[0], np.cumsum(steps + 1)[:-1]])
    s = (np.arange(total) - np.repeat(starts, steps + 1)) / np.repeat(steps, steps + 1)
    for first in range(0, total, BATCH):
        window = slice(first, min(first + BATCH, total))
        pose, where = moves.poses(move_ids[window], s[window])
        bad = ~pose_margins(manipulator, pose, where).reachable
        ok[np.unique(move_ids[window][bad])] = False
    return ok, total


def compare(name: str, manipulator, positions, angles, tolerance) -> None:
    moves = len(positions) - 1
    certified_time, result = best_of(3, lambda: check_path(manipulator, positions, angles=angles))
    dense_time, (dense_ok, samples) = best_of(
        1, lambda: dense(manipulator, positions, angles, tolerance)
    )
    evaluations = result.segments.evaluations + len(positions)
    agree = np.array_equal(result.segments.ok, dense_ok)
    print(f"{name}: {moves} moves, {np.count_nonzero(result.segments.ok)} ok")
    print(
        f"  certified check : {moves / certified_time:12,.0f} moves/s  ({certified_time:.3f} s, "
        f"{evaluations / moves:.2f} poses per move)"
    )
    print(
        f"  dense sampling  : {moves / dense_time:12,.0f} moves/s  ({dense_time:.3f} s, "
        f"{samples / moves:.1f} poses per move)"
    )
    print(f"  ratio           : {dense_time / certified_time:12.1f} x   verdicts agree: {agree}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--short", type=int, default=20_000, help="short moves")
    parser.add_argument("--large", type=int, default=300, help="large moves")
    parser.add_argument("--waypoints", type=int, default=1_000, help="planned toolpath")
    options = parser.parse_args()
    try:
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})  # pin to one core
        pinned = True
    except (AttributeError, OSError):
        pinned = False
    manipulator = load_manipulator(example_config_path())
    tolerance = DEFAULT_PATH_TOLERANCE
    print(
        f"certified moves vs dense sampling, packaged example, tolerance "
        f"{math.degrees(tolerance):g} deg, {'pinned to one core' if pinned else 'one process'}"
    )
    compare("short moves (fine toolpath)", manipulator, *short_moves(options.short + 1), tolerance)
    compare("large random moves", manipulator, *large_moves(options.large + 1), tolerance)

    count = options.waypoints
    t = np.linspace(0.0, 2.0 * np.pi, count)
    positions = np.column_stack(
        [0.2 + 0.02 * np.cos(t), 0.2 + 0.02 * np.sin(t), np.full(count, -0.95)]
    )
    axes = approach_vector(t, np.radians(17.0))
    print(
        f"free-torsion toolpath, {count} waypoints off the axis (tool axes on a 17° cone); "
        f"compiled programmes vs the numpy ones they replaced (test/planner_reference.py):"
    )
    for label, max_dpsi in (("no torsion limit", None), ("max_dpsi 5 deg", np.radians(5.0))):

        def plan(max_dpsi=max_dpsi):
            return plan_torsion(manipulator, positions, axes, max_dpsi=max_dpsi)

        elapsed, planned = best_of(3, plan)
        with numpy_planner():
            before, expected = best_of(3, plan)
        same = (
            planned.ok == expected.ok
            and planned.objective == expected.objective
            and (not planned.ok or np.array_equal(planned.psi, expected.psi))
        )
        print(
            f"  {label:<16}: {elapsed:6.3f} s (numpy programmes {before:6.3f} s, "
            f"{before / elapsed:4.1f}x)  plan {'found' if planned.ok else 'NOT found'}, "
            f"margin {planned.objective:.3f}, {planned.moves_checked} moves checked in full; "
            f"same plan: {same}; psi = 0 fails {len(planned.baseline.failed_waypoints)} "
            f"waypoints; goal 1 s {'met' if elapsed <= 1.0 else 'not met'}"
        )


if __name__ == "__main__":
    main()
