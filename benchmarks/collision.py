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
* the torsion range (the orientation workspace's ψ scan) of 24 tool directions, with the scene
  also with the collision margin at every sample (``RaySearch.lazy_collision = False``);
* the collision kernel alone on the batch, with its broad phase and evaluating every pair;
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
from hexapod_workspace.core.base.params import flatten, load_params_file
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.check import check, check_pose
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping
from hexapod_workspace.core.model.collision import scene_distances
from hexapod_workspace.core.workspaces.orientation import torsion_range
from hexapod_workspace.core.workspaces.projected import projected_workspace
from hexapod_workspace.core.workspaces.search import RaySearch

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


def best_of(repeats: int, function, clock=time.perf_counter) -> float:
    best = float("inf")
    for _ in range(repeats):
        start = clock()
        function()
        best = min(best, clock() - start)
    return best


def random_angles(count: int) -> np.ndarray:
    """The benchmark's poses: tilt-and-torsion angles (φ, θ, ψ), rad, shape (count, 3)."""
    rng = np.random.default_rng(0)
    return np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0, 0.6, count),
            rng.uniform(-0.5, 0.5, count),
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=20000)
    count = parser.parse_args().poses
    parameters = load_params_file(example_config_path())
    plain = manipulator_from_mapping(parameters)
    cell = manipulator_from_mapping({**parameters, **flatten(SCENE)})
    scene = cell.collision
    assert scene is not None
    angles = random_angles(count)
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
    # The torsion range (the orientation workspace's scan) over 24 tool directions.
    directions = [
        (phi, theta)
        for phi in np.linspace(-np.pi, np.pi, 8, endpoint=False)
        for theta in (0.15, 0.3, 0.45)
    ]

    def torsion(model: Manipulator) -> None:
        for phi, theta in directions:
            torsion_range(model, phi, theta, position=position)

    for name, model in (("today", plain), ("scene", cell)):
        torsion(model)
        times[name]["torsion"] = best_of(3, lambda m=model: torsion(m)) / len(directions)
    RaySearch.lazy_collision = False
    eager = best_of(3, lambda: projected_workspace(cell, position))
    eager_torsion = best_of(3, lambda: torsion(cell)) / len(directions)
    RaySearch.lazy_collision = True
    # The kernel alone on the batch: with its broad phase, and evaluating every pair. (Imported
    # here: collision_compare.py imports this module to ask trees that predate these.)
    from hexapod_workspace.core.kernels.collision import collision_margins
    from hexapod_workspace.core.kernels.layout import MODEL_SIZE, B, model_vector
    from hexapod_workspace.core.model.legs import leg_endpoints

    base_ends, platform_ends = leg_endpoints(cell, rotations, position)
    legs = np.ascontiguousarray(np.transpose(platform_ends - base_ends, (0, 2, 1)))
    vector = model_vector(cell)
    flat = np.ascontiguousarray(rotations.reshape(-1, 9))
    where = np.ascontiguousarray(np.broadcast_to(position, (count, 3)))
    found = np.empty((count, 3))
    kernel = {}
    for pruned in (True, False):
        collision_margins(vector, MODEL_SIZE, B, flat[:10], where[:10], legs[:10], pruned, found)
        kernel[pruned] = (
            best_of(
                5,
                lambda p=pruned: collision_margins(
                    vector, MODEL_SIZE, B, flat, where, legs, p, found
                ),
            )
            / count
        )
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
        ("torsion", "ms", 1e3),
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
    print(
        f"torsion range, scene, collision at every sample {eager_torsion * 1e3:9.3f} ms"
        f"   ratio {eager_torsion / times['today']['torsion']:6.2f}"
        f" (lazy/eager {times['scene']['torsion'] / eager_torsion:.2f})"
    )
    print(
        f"collision kernel alone, batch: broad phase {kernel[True] * 1e6:8.3f} µs/pose,"
        f" every pair {kernel[False] * 1e6:8.3f} µs/pose"
    )
    print(f"scene_distances (standalone, batch) {t_scene * 1e6:8.3f} µs/pose")
    print("goals: check_pose and check ratio <= 2, projected ratio <= 3")


if __name__ == "__main__":
    main()
