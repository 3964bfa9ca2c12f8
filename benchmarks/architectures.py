#!/usr/bin/env python3
"""Leg architectures: the packaged 6-PUS and 6-RUS examples against the 6-UPS one, per pose and
per move, ratios measured in the same run (new code only; ``model.py`` compares with the code
before the open model).

Printed, for each machine at its home position:

* **check, random poses**: per-pose time of a batch :func:`hexapod_workspace.check` on the same
  N random orientations for all three (the figure ``model.py`` prints). On the 6-RUS example
  most of them leave a leg with no IK solution: the share of poses with ``ik`` violated and of
  reachable poses is printed beside it.
* **check, reachable poses**: per-pose time on N orientations that are reachable *on that
  machine* (the random ones it reaches, repeated to N): what a caller checking a tool path
  inside the workspace pays. A different set of poses for each machine.
* **check_pose**: one pose, (0.3, 0.2, 0.1) rad, per call.
* **actuator speeds**: :func:`hexapod_workspace.actuator_rates` (certified peak dq/ds) on M
  small random moves around the home pose, ms per M moves.

Times are the best of several runs, pinned to one core. Usage:
``python benchmarks/architectures.py [--poses N] [--moves M] [--repeat R]``
"""

from __future__ import annotations

import argparse
import functools
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from speed import best_of, per_call, random_poses

import hexapod_workspace as hw
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core import kernels
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.check import check_pose

EXAMPLES = {"ups": "example_gpm.yaml", "pus": "example_pus.yaml", "rus": "example_rus.yaml"}


def _moves(machine: hw.Manipulator, count: int) -> tuple[np.ndarray, np.ndarray]:
    """count + 1 waypoints of small random moves (≤ 10 mm, ≤ 3°) around the home pose."""
    rng = np.random.default_rng(17)
    positions = machine.position + rng.uniform(-0.01, 0.01, (count + 1, 3))
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count + 1),
            rng.uniform(0.0, np.radians(3.0), count + 1),
            rng.uniform(-0.05, 0.05, count + 1),
        ]
    )
    return positions, tt_to_matrix(angles)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=100_000)
    parser.add_argument("--moves", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=5)
    options = parser.parse_args()
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})  # one core
    kernels.warm_up()
    config = example_config_path().parent
    machines = {name: hw.load_manipulator(config / file) for name, file in EXAMPLES.items()}
    poses = random_poses(options.poses)
    rows: dict[str, dict[str, float]] = {}
    shares: dict[str, tuple[float, float]] = {}
    for name, machine in machines.items():
        result = hw.check(machine, poses, machine.position)
        ik = result.margins.get("ik")
        unsolved = float(np.mean(~(ik >= 0.0))) if ik is not None else 0.0
        shares[name] = (unsolved, float(np.mean(result.reachable)))
        inside = poses[result.reachable]
        inside = np.resize(inside, (options.poses, 3)) if inside.shape[0] else poses
        positions, rotations = _moves(machine, options.moves)
        hw.actuator_rates(machine, positions[:3], rotations[:3])  # warm up
        rows[name] = {
            "check, random poses (per pose)": best_of(
                options.repeat, lambda m=machine: hw.check(m, poses, m.position)
            )
            / options.poses,
            "check, reachable poses (per pose)": best_of(
                options.repeat, lambda m=machine, p=inside: hw.check(m, p, m.position)
            )
            / options.poses,
            "check_pose (per call)": per_call(
                functools.partial(check_pose, machine, 0.3, 0.2, 0.1, machine.position)
            ),
            f"actuator speeds ({options.moves} moves)": best_of(
                options.repeat,
                lambda m=machine, x=positions, r=rotations: hw.actuator_rates(m, x, r),
            ),
        }
    print(
        f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}, one core, "
        f"{options.poses} poses per batch, best of {options.repeat}"
    )
    for name, (unsolved, reachable) in shares.items():
        print(
            f"  {name}: random poses with a leg unsolved (ik violated) {100 * unsolved:5.1f} %, "
            f"reachable {100 * reachable:5.1f} %"
        )
    print(f"  {'figure':<36} {'ups':>12} {'pus':>12} {'rus':>12} {'pus/ups':>8} {'rus/ups':>8}")
    for figure in rows["ups"]:
        ups, pus, rus = (rows[name][figure] for name in EXAMPLES)
        unit, scale = ("µs", 1e6) if ups < 1e-3 else ("ms", 1e3)
        print(
            f"  {figure:<36} {ups * scale:>9.3f} {unit} {pus * scale:>9.3f} {unit}"
            f" {rus * scale:>9.3f} {unit} {pus / ups:>8.2f} {rus / ups:>8.2f}"
        )


if __name__ == "__main__":
    main()
