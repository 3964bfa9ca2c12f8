#!/usr/bin/env python3
"""The collision benchmark's questions to one source tree, for before/after runs in alternation.

Asks ``check`` (batch), ``check_pose``, the projected workspace and the torsion range of 24 tool
directions of the machine with and without the scene of ``benchmarks/collision.py``, timed in
process CPU time (best of 3–5; the machine is shared), and prints one line:
``question=with/without(ratio)``. The tree is whichever ``hexapod_workspace`` Python imports:
to compare a commit with this one, unpack it (``git archive REV | tar -x -C DIR``) and run

    PYTHONPATH=DIR taskset -c 1 .venv/bin/python benchmarks/collision_compare.py --tag before
    taskset -c 1 .venv/bin/python benchmarks/collision_compare.py --tag after

alternately, a few rounds each (the line says which tree was imported).
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

import numpy as np
from collision import SCENE, best_of, random_angles

import hexapod_workspace
from hexapod_workspace import Manipulator
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.base.params import flatten, load_params_file
from hexapod_workspace.core.evaluation.check import check, check_pose
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping
from hexapod_workspace.core.workspaces.orientation import torsion_range
from hexapod_workspace.core.workspaces.projected import projected_workspace


def cpu(repeats: int, function: Callable[[], object]) -> float:
    """Best of ``repeats`` runs in process CPU time, s (a shared machine: wall time varies more)."""
    return best_of(repeats, function, time.process_time)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tag", default="tree")
    parser.add_argument("--poses", type=int, default=20000)
    arguments = parser.parse_args()
    count = arguments.poses
    parameters = load_params_file(example_config_path())
    plain = manipulator_from_mapping(parameters)
    cell = manipulator_from_mapping({**parameters, **flatten(SCENE)})
    angles = random_angles(count)
    position = np.array([0.0, 0.0, -1.3])
    directions = [
        (phi, theta)
        for phi in np.linspace(-np.pi, np.pi, 8, endpoint=False)
        for theta in (0.15, 0.3, 0.45)
    ]
    single = angles[:2000]

    def torsion(model: Manipulator) -> None:
        for phi, theta in directions:
            torsion_range(model, phi, theta, position=position)

    times: dict[str, dict[str, float]] = {}
    for name, model in (("without", plain), ("with", cell)):
        check(model, angles[:10], position)  # warm up (compile or load every kernel)
        check_pose(model, *angles[0], position)
        projected_workspace(model, position, n_phi=8)
        torsion(model)
        times[name] = {
            "check_us": cpu(5, lambda m=model: check(m, angles, position)) / count * 1e6,
            "check_pose_us": cpu(3, lambda m=model: [check_pose(m, *a, position) for a in single])
            / len(single)
            * 1e6,
            "projected_ms": cpu(3, lambda m=model: projected_workspace(m, position)) * 1e3,
            "torsion_ms": cpu(3, lambda m=model: torsion(m)) / len(directions) * 1e3,
        }
    line = " ".join(
        f"{key}={times['with'][key]:.3f}/{times['without'][key]:.3f}"
        f"({times['with'][key] / times['without'][key]:.2f}x)"
        for key in times["with"]
    )
    tree = os.path.dirname(os.path.dirname(hexapod_workspace.__file__))
    print(f"{arguments.tag} ({tree}) load={os.getloadavg()[0]:.2f} {line}", flush=True)


if __name__ == "__main__":
    main()
