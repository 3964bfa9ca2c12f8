#!/usr/bin/env python3
"""Cost of the ``collision`` constraint, wired into the kernels, against today's answers in the
same run.

The scene is the example machine with the tool, the platform and three obstacles (a box vise,
a cylinder column, a sphere) around it: 6 + 3 × 8 = 30 pairs. The same questions are asked of
the model without a scene and with it:

* ``check_pose`` (one pose, plain Python numbers) and ``check`` (a batch of poses);
* the projected workspace (certified ray searches, ψ = 0) at the home position, with the
  scene also with the collision margin evaluated at every probe of the searches
  (``RaySearch.lazy_collision = False``: the searches before the lazy bound);
* for reference, the standalone scene kernel ``scene_distances`` on the batch.

Goals: a pose check within 2× of today's, the projected workspace within 3×. Times are the
best of several runs (the machine is shared); the load average is printed with the results.
Usage: python benchmarks/collision.py [--poses N]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from hexapod_workspace import Manipulator
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.collision import scene_distances
from hexapod_workspace.core.constraints import check, check_pose
from hexapod_workspace.core.params import flatten, load_params_file
from hexapod_workspace.core.projected import projected_workspace
from hexapod_workspace.core.rotations import tt_to_matrix
from hexapod_workspace.core.search import RaySearch

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
    parameters = load_params_file(example_config_path())
    plain = Manipulator.from_mapping(parameters)
    cell = Manipulator.from_mapping({**parameters, **flatten(SCENE)})
    scene = cell.collision
    assert scene is not None
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
    single = angles[:2000]
    times: dict[str, dict[str, float]] = {}
    for name, model in (("today", plain), ("scene", cell)):
        check(model, angles[:10], position)  # warm up (compile or load every kernel)
        check_pose(model, *angles[0], position)
        projected_workspace(model, position, n_phi=8)
        times[name] = {
            "check_pose": best_of(3, lambda m=model: [check_pose(m, *a, position) for a in single])
            / len(single),
            "check": best_of(5, lambda m=model: check(m, angles, position)) / count,
            "projected": best_of(3, lambda m=model: projected_workspace(m, position)),
        }
    RaySearch.lazy_collision = False
    eager = best_of(3, lambda: projected_workspace(cell, position))
    RaySearch.lazy_collision = True
    t_scene = best_of(5, lambda: scene_distances(cell, scene, rotations, position)) / count
    margin = check(cell, angles, position).margins["collision"]
    print(
        f"load average {os.getloadavg()[0]:.2f}; {count} poses; 30 pairs (tool, platform, 6 legs"
        f" × 3 obstacles + tool × 6 legs); {np.mean(margin < 0):.1%} of the poses collide"
    )
    for key, unit, factor in (
        ("check_pose", "µs/pose", 1e6),
        ("check", "µs/pose", 1e6),
        ("projected", "ms", 1e3),
    ):
        ratio = times["scene"][key] / times["today"][key]
        print(
            f"{key:<12} today {times['today'][key] * factor:9.3f} {unit:<8}"
            f"with scene {times['scene'][key] * factor:9.3f} {unit:<8} ratio {ratio:6.2f}"
        )
    print(
        f"projected, scene, collision at every probe {eager * 1e3:9.3f} ms"
        f"   ratio {eager / times['today']['projected']:6.2f}"
        f" (lazy/eager {times['scene']['projected'] / eager:.2f})"
    )
    print(f"scene_distances (standalone, batch) {t_scene * 1e6:8.3f} µs/pose")
    print("goals: check_pose and check ratio <= 2, projected ratio <= 3")


if __name__ == "__main__":
    main()
