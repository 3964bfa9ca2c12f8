#!/usr/bin/env python3
"""Throughput of the batched reachability check, all four constraints on, one core.

Prints poses per second of :func:`hexapod_workspace.check` on random poses of the packaged
example, the same for a straightforward per-pose loop (the literal definitions of
:mod:`hexapod_workspace.reference`, one pose at a time), the ratio of the two measured in this
run, and where the batched time goes.

Usage: python benchmarks/check_throughput.py [--poses N] [--loop-poses N]
"""

from __future__ import annotations

import argparse
import os
import time

# One core: keep any BLAS threads out of the measurement (set before numpy loads).
for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(variable, "1")

import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

# The literal reference is a test oracle (test/reference.py), not part of the package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))

from reference import pose_margins_literal  # noqa: E402

from hexapod_workspace import Manipulator, check  # noqa: E402
from hexapod_workspace._resources import example_config_path  # noqa: E402
from hexapod_workspace.core.constraints import CHUNK, _chunk_model  # noqa: E402
from hexapod_workspace.core.rotations import tt_to_matrix  # noqa: E402


def random_poses(count: int, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, np.radians(45.0), count),
            rng.uniform(-np.radians(60.0), np.radians(60.0), count),
        ]
    )


def best_of(repeats: int, function) -> float:
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        function()
        times.append(time.perf_counter() - started)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=1_000_000)
    parser.add_argument("--loop-poses", type=int, default=3_000)
    options = parser.parse_args()
    try:
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})  # pin to one core
        pinned = True
    except (AttributeError, OSError):
        pinned = False

    manipulator = Manipulator.from_params_file(example_config_path())
    poses = random_poses(options.poses)
    check(manipulator, poses[:CHUNK])  # warm up caches
    batched = best_of(3, lambda: check(manipulator, poses))
    reachable = float(np.mean(check(manipulator, poses).reachable))

    loop_poses = poses[: options.loop_poses]

    def loop() -> None:
        for pose in loop_poses:
            pose_margins_literal(manipulator, pose, manipulator.position)

    looped = best_of(1, loop)
    batched_rate = options.poses / batched
    loop_rate = options.loop_poses / looped

    # Where the batched time goes, per pose: rotations, three margins, interference, the rest.
    model = _chunk_model(manipulator, True)
    model_no_interference = _chunk_model(manipulator, False)
    chunk = poses[:CHUNK]
    rotations = tt_to_matrix(chunk)
    positions = np.broadcast_to(manipulator.position, (CHUNK, 3))
    margins = np.empty((4, CHUNK))
    legs = np.empty((4, CHUNK), dtype=np.int64)
    pairs = np.empty((CHUNK, 2), dtype=np.int64)
    repeats = 200
    t_rotation = best_of(5, lambda: [tt_to_matrix(chunk) for _ in range(repeats)])
    t_three = best_of(
        5,
        lambda: [
            model_no_interference.evaluate(rotations, positions, margins, legs, pairs)
            for _ in range(repeats)
        ],
    )
    t_all = best_of(
        5,
        lambda: [
            model.evaluate(rotations, positions, margins, legs, pairs) for _ in range(repeats)
        ],
    )
    per_pose = 1e9 / (repeats * CHUNK)

    print(
        f"check throughput, packaged example, {options.poses} random poses "
        f"({reachable:.1%} reachable), all four constraints, "
        f"{'pinned to one core' if pinned else 'one process'}"
    )
    print(f"  batched check       : {batched_rate / 1e6:8.3f} M poses/s  ({batched:.3f} s)")
    print(
        f"  per-pose loop       : {loop_rate / 1e3:8.3f} k poses/s  "
        f"({options.loop_poses} poses in {looped:.3f} s)"
    )
    print(f"  ratio batched/loop  : {batched_rate / loop_rate:8.0f} x")
    print(
        f"  goal 2 M poses/s    : {'met' if batched_rate >= 2e6 else 'not met'} "
        f"({batched_rate / 2e6:.0%} of it)"
    )
    print("  time per pose, chunks of", CHUNK)
    print(f"    T&T -> rotation matrix        : {t_rotation * per_pose:7.1f} ns")
    print(f"    leg length + two joint angles : {t_three * per_pose:7.1f} ns")
    print(f"    leg interference (15 pairs)   : {(t_all - t_three) * per_pose:7.1f} ns")
    total = batched / options.poses * 1e9
    rest = total - (t_rotation + t_all) * per_pose
    print(f"    bookkeeping (limiting legs...): {rest:7.1f} ns")
    print(f"    total                         : {total:7.1f} ns")


if __name__ == "__main__":
    main()
