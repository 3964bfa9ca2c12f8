#!/usr/bin/env python3
"""Loads at a pose: the cost of :func:`hexapod_workspace.core.evaluation.loads.loads_at` (forces,
the process box, payload capacity, stiffness, deflection and accuracy, all configured) against
the geometric pose check of the same pose, one pose per call, measured in one run, per leg
architecture (the packaged examples).

Prints µs per pose for both and their ratio (the issue's goal for a check with the three loads
rows: at most 3× the geometric check), the cost of the Jacobian alone for a batch, and a batch
check of all the poses (:func:`~hexapod_workspace.core.evaluation.check.check`, as the CLI's
``check`` and the node's ``~/check_poses`` run it) without and with the three rows
(:func:`~hexapod_workspace.core.evaluation.loads.load_rows`, every pose at once).

Usage: python benchmarks/loads.py [--poses N] [--repeat R]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np

from hexapod_workspace._resources import data_path
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.check import check, check_pose
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.core.evaluation.loads import (
    actuator_jacobian,
    load_case_from_mapping,
    load_rows,
    loads_at,
)

EXAMPLES = {"ups": "example_gpm.yaml", "pus": "example_pus.yaml", "rus": "example_rus.yaml"}
CASE = {
    "load.mass": 40.0,
    "load.center_of_mass": [0.0, 0.0, 0.2],
    "process.wrench_range": [300.0, 300.0, 300.0, 20.0, 20.0, 20.0],
    "limits.actuator_force_max": [5000.0],
    "stiffness.actuator": [3e7],
    "limits.deflection_max": 1e-4,
    "accuracy.actuator_error": [2e-6],
    "limits.accuracy_max": 2e-5,
}


def _best(function: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        function()
        times.append(time.perf_counter() - started)
    return min(times)


def _figures(name: str, case: object, poses: int, repeat: int) -> tuple[float, ...]:
    """Seconds per pose: check_pose, loads_at, the batch Jacobian, the batch check, and the
    batch check with the rows."""
    manipulator = load_manipulator(data_path("config", name))
    rng = np.random.default_rng(4)
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, poses),
            rng.uniform(0.0, np.radians(20.0), poses),
            rng.uniform(-0.3, 0.3, poses),
        ]
    )
    rotations = tt_to_matrix(angles)
    position = manipulator.position
    check_pose(manipulator, *angles[0], position)  # compiled before timing
    check(manipulator, angles[:2], position)

    def geometric() -> None:
        for row in angles:
            check_pose(manipulator, *row, position)

    def loads() -> None:
        for rotation in rotations:
            loads_at(manipulator, case, rotation, position)  # type: ignore[arg-type]

    def batch() -> None:
        actuator_jacobian(manipulator, rotations, position)

    def batch_check() -> None:
        check(manipulator, angles, position)

    def batch_rows() -> None:
        check(manipulator, angles, position)
        load_rows(manipulator, case, rotations, position)  # type: ignore[arg-type]

    functions = (geometric, loads, batch, batch_check, batch_rows)
    return tuple(_best(f, repeat) / poses for f in functions)


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--poses", type=int, default=500)
    parser.add_argument("--repeat", type=int, default=3)
    options = parser.parse_args()
    case = load_case_from_mapping(CASE)
    print(f"{options.poses} poses, best of {options.repeat}, one pose per call")
    print(
        f"{'arch':5} {'check_pose µs':>14} {'loads_at µs':>12} {'ratio':>6} "
        f"{'J batch µs/pose':>16} {'check batch':>12} {'+ rows':>8} {'ratio':>6}"
    )
    for architecture, name in EXAMPLES.items():
        geometric, loads, batch, many, with_rows = _figures(
            name, case, options.poses, options.repeat
        )
        print(
            f"{architecture:5} {geometric * 1e6:14.1f} {loads * 1e6:12.1f} "
            f"{loads / geometric:6.2f} {batch * 1e6:16.2f} {many * 1e6:12.2f} "
            f"{with_rows * 1e6:8.2f} {with_rows / many:6.2f}"
        )
    print("(check batch and + rows: µs per pose of one call for all the poses)")


if __name__ == "__main__":
    main()
