#!/usr/bin/env python3
"""Cost of the ``collision`` margin (the core collision bodies) against today's pose check,
in the same run.

The scene is the example machine with the tool, the platform and three obstacles (a box vise,
a cylinder column, a sphere) around it: 6 + 3 × 8 = 30 pairs. Measured per pose:

* ``check_pose`` (one pose, plain Python numbers) and ``check`` (a batch of poses), today's
  four constraints;
* ``scene_distances`` on the same batch (the closest pair, pairs skipped by bounding spheres),
  and with every pair's distance (``all_pairs``).

The goal: a pose check with collisions within 2× of today's, i.e. (check + scene) /
check ≤ 2. Times are the best of several runs (the machine is shared); the load average is
printed with the results. Usage: python benchmarks/collision.py [--poses N]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from hexapod_workspace import Manipulator
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.collision import collision_scene, scene_distances
from hexapod_workspace.core.constraints import check, check_pose
from hexapod_workspace.core.params import load_params_file
from hexapod_workspace.core.rotations import tt_to_matrix

SCENE = {
    "collision": {
        "clearance": 0.005,
        "platform": {"radius": 0.33, "z_min": 0.08, "z_max": 0.14},
        "tool": {"radius": 0.04, "length": 0.25},
        "obstacles": {
            "names": ["vise", "column", "ball"],
            "vise": {"shape": "box", "position": [0.0, 0.0, -1.75], "size": [0.3, 0.2, 0.1]},
            "column": {
                "shape": "cylinder",
                "position": [0.75, 0.0, -0.8],
                "radius": 0.1,
                "length": 1.2,
            },
            "ball": {"shape": "sphere", "position": [0.35, 0.35, -1.2], "radius": 0.05},
        },
    }
}


def best_of(repeats: int, function) -> float:
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=20000)
    count = parser.parse_args().poses
    manipulator = Manipulator.from_mapping(load_params_file(example_config_path()))
    scene = collision_scene(SCENE, manipulator=manipulator)
    rng = np.random.default_rng(0)
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0, 0.6, count),
            rng.uniform(-0.5, 0.5, count),
        ]
    )
    position = np.array([0.0, 0.0, -1.3])
    rotations = tt_to_matrix(angles)
    # Warm up (compile or load every kernel).
    check(manipulator, angles[:10], position)
    check_pose(manipulator, *angles[0], position)
    scene_distances(manipulator, scene, rotations[:10], position)
    scene_distances(manipulator, scene, rotations[:10], position, all_pairs=True)

    single = angles[:2000]
    t_pose = best_of(3, lambda: [check_pose(manipulator, *a, position) for a in single]) / len(
        single
    )
    t_check = best_of(5, lambda: check(manipulator, angles, position)) / count
    t_rotations = best_of(5, lambda: tt_to_matrix(angles)) / count
    t_scene = best_of(5, lambda: scene_distances(manipulator, scene, rotations, position)) / count
    t_all = (
        best_of(3, lambda: scene_distances(manipulator, scene, rotations, position, all_pairs=True))
        / count
    )
    t_one = (
        best_of(
            3, lambda: [scene_distances(manipulator, scene, r, position) for r in rotations[:2000]]
        )
        / 2000
    )
    margin = scene_distances(manipulator, scene, rotations, position).margin
    print(
        f"load average {os.getloadavg()[0]:.2f}; {count} poses; 30 pairs (tool, platform, 6 legs"
        f" × 3 obstacles + tool × 6 legs); {np.mean(margin < 0):.1%} of the poses collide"
    )
    print(f"check (batch)                        {t_check * 1e6:8.3f} µs/pose")
    print(f"check_pose (one call per pose)       {t_pose * 1e6:8.3f} µs/pose")
    print(f"T&T -> matrix (batch)                {t_rotations * 1e6:8.3f} µs/pose")
    print(f"scene_distances (batch, closest)     {t_scene * 1e6:8.3f} µs/pose")
    print(f"scene_distances (batch, all pairs)   {t_all * 1e6:8.3f} µs/pose")
    print(f"scene_distances (one call per pose)  {t_one * 1e6:8.3f} µs/pose")
    batch = (t_check + t_rotations + t_scene) / t_check
    single_ratio = (t_pose + t_one) / t_pose
    print(f"ratio batch (check + matrices + scene) / check = {batch:.2f}  (goal ≤ 2)")
    print(f"ratio one pose (check_pose + scene) / check_pose = {single_ratio:.2f}  (goal ≤ 2)")


if __name__ == "__main__":
    main()
