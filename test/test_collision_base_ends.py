"""The standalone scene kernel (``collision.scene.scene_distances``: the home-pose check and the
scene pictures) puts a leg's body where its architecture puts the leg: from the crank end C_i(q)
of a 6-RUS leg or the slide joint of a 6-PUS leg, not from the crank centre / rail origin A0_i.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hexapod_workspace.core.base.params import flatten, load_params_file
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.check import check
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping
from hexapod_workspace.core.model.collision import scene_distances
from hexapod_workspace.core.model.legs import leg_endpoints
from hexapod_workspace.errors import ConfigError

CONFIG = Path(__file__).resolve().parents[1] / "config"


def point_segment(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Distance from a point to segment ab (plain numpy)."""
    t = np.clip(np.dot(point - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
    return float(np.linalg.norm(point - (a + t * (b - a))))


def test_rus_home_check_uses_the_crank_end() -> None:
    """A ball on leg 1's rod near its crank end, far from the segment A0_1–B_1: the home pose is
    in collision and the model is refused naming leg 1 (with A0_1 as the leg's end it was
    accepted)."""
    parameters = load_params_file(CONFIG / "example_rus.yaml")
    machine = manipulator_from_mapping(parameters, warn=False)
    home = np.asarray(machine.home_position, dtype=float)
    base_ends, platform_ends = leg_endpoints(machine, np.eye(3), home)
    crank_end, joint = base_ends[0, 0], platform_ends[0, 0]
    centre = crank_end + 0.15 * (joint - crank_end)
    radius = 0.01
    wrong_leg = point_segment(centre, machine.base_joints[0], joint)
    assert wrong_leg > 0.5 * machine.leg_diameter + radius + 0.05  # clear of the wrong body
    scene = {
        "collision": {
            "clearance": 0.001,
            "obstacles": {
                "names": ["ball"],
                "ball": {"shape": "sphere", "position": centre.tolist(), "radius": radius},
            },
        }
    }
    with pytest.raises(ConfigError, match=r"collision: leg 1 vs ball collide at the home pose"):
        manipulator_from_mapping({**parameters, **flatten(scene)}, warn=False)


@pytest.mark.parametrize("architecture", ["pus", "rus"])
def test_scene_distances_equal_the_kernels_for_moving_base_joints(architecture: str) -> None:
    """On random poses the standalone scene kernel gives the margin of the compiled kernels
    (which build leg bodies from the leg vectors), and NaN where a leg has no solution."""
    path = CONFIG / f"example_{architecture}.yaml"
    parameters = load_params_file(path)
    machine = manipulator_from_mapping(parameters, warn=False)
    home = np.asarray(machine.home_position, dtype=float)
    base_ends, platform_ends = leg_endpoints(machine, np.eye(3), home)
    # Balls beside legs 2 and 5, a third of the way up from their base-side ends.
    obstacles: dict = {"names": ["b2", "b5"]}
    for name, k in (("b2", 1), ("b5", 4)):
        a, b = base_ends[0, k], platform_ends[0, k]
        point = a + (b - a) / 3.0
        along = (b - a) / np.linalg.norm(b - a)
        outward = np.array([point[0], point[1], 0.0])
        outward -= np.dot(outward, along) * along  # perpendicular to the leg
        outward /= np.linalg.norm(outward)
        centre = point + (0.5 * machine.leg_diameter + 0.02 + 0.005) * outward
        obstacles[name] = {"shape": "sphere", "position": centre.tolist(), "radius": 0.02}
    scene = {"collision": {"clearance": 0.002, "obstacles": obstacles}}
    cell = manipulator_from_mapping({**parameters, **flatten(scene)}, warn=False)
    assert cell.collision is not None
    rng = np.random.default_rng(11)
    count = 2000
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, 0.5, count),
            rng.uniform(-0.4, 0.4, count),
        ]
    )
    kernels = check(cell, angles, home).margins["collision"]
    standalone = scene_distances(cell, cell.collision, tt_to_matrix(angles), home).margin
    solved = np.isfinite(kernels)
    assert solved.sum() > 200
    assert np.any(kernels[solved] < 0.0) and np.any(kernels[solved] > 0.0)
    np.testing.assert_allclose(standalone[solved], kernels[solved], atol=1e-6, rtol=0)
    assert np.all(np.isnan(standalone[~solved]))
