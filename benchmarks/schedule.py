#!/usr/bin/env python3
"""The certified feed schedule: cost against the certified path check of the same moves,
measured in one run.

A toolpath of N moves (default 1000) as a CAM system writes a 5-axis finishing pass: waypoints
every 2 mm along a wavy curve around the packaged example's working volume, the tool axis
tilting slowly (up to 20°), feed 1200 mm/min, legs limited to 0.05 m/s and 0.5 m/s².
:func:`hexapod_workspace.core.motions.schedule.schedule_path` against
:func:`hexapod_workspace.check_path` of the same moves (the reachability certificate the path
gets anyway): seconds for each, the ratio, the grid intervals and the schedule's time against
the time at the programmed feed. The issue's goals: ≤ 2 s for 1000 moves on one core, ≤ 5× the
path check.

Usage: python benchmarks/schedule.py [--moves N] [--repeat R]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from hexapod_workspace import check_path
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.loading import example_manipulator
from hexapod_workspace.core.motions.schedule import schedule_path


def toolpath(moves: int) -> tuple[np.ndarray, np.ndarray]:
    """Positions (moves + 1, 3), m, and T&T angles, rad: a wavy finishing pass."""
    t = np.linspace(0.0, 1.0, moves + 1)
    length = 0.002 * moves  # 2 mm per move
    x = -0.1 + 0.2 * t
    y = 0.05 * np.sin(2.0 * np.pi * length / 0.2 * t)
    z = -1.3 + 0.01 * np.cos(2.0 * np.pi * length / 0.3 * t)
    positions = np.column_stack([x, y, z])
    angles = np.column_stack(
        [np.full(t.size, 0.3), np.radians(20.0) * (0.5 + 0.5 * np.sin(2 * np.pi * t)), 0.0 * t]
    )
    return positions, angles


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--moves", type=int, default=1000)
    parser.add_argument("--repeat", type=int, default=3)
    options = parser.parse_args()
    model = example_manipulator()
    positions, angles = toolpath(options.moves)
    rotations = tt_to_matrix(angles)
    feeds = np.full(options.moves, 0.02)
    check_path(model, positions[:3], angles=angles[:3])  # loads the kernels, untimed
    best_check, best_schedule = np.inf, np.inf
    schedule = None
    for _ in range(options.repeat):
        started = time.process_time()
        check_path(model, positions, angles=angles)
        best_check = min(best_check, time.process_time() - started)
        started = time.process_time()
        schedule = schedule_path(
            model,
            positions,
            rotations,
            speed_limits=[0.05],
            accel_limits=[0.5],
            feeds=feeds,
        )
        best_schedule = min(best_schedule, time.process_time() - started)
    assert schedule is not None
    programmed = float(np.sum(np.linalg.norm(np.diff(positions, axis=0), axis=1)) / 0.02)
    print(f"toolpath: {options.moves} moves, best of {options.repeat}, CPU seconds")
    print(f"  check_path    {best_check:8.3f} s")
    print(
        f"  schedule_path {best_schedule:8.3f} s  ({best_schedule / best_check:.2f} x the "
        f"path check; goals: <= 2 s per 1000 moves, <= 5 x)"
    )
    stops = int(np.sum(schedule.stops))
    print(
        f"  schedule: {schedule.duration:.3f} s against {programmed:.3f} s at the programmed "
        f"feed, {schedule.intervals} intervals, {stops} stops"
    )


if __name__ == "__main__":
    main()
