"""The ``collision`` constraint wired into every answer: checks, moves, the planner, workspaces.

The kernels' margin is compared with the standalone scene kernel (``scene_distances``, itself
checked against coal in test_collision.py) and with coal directly; moves and boundaries with
dense sampling; the worked example (config/example_collision.yaml) with the planner.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from test_collision import coal_scene, random_poses, scene_parameters

from hexapod_workspace import Manipulator
from hexapod_workspace.core.base.params import flatten
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.constraints.table import COLLISION, CONSTRAINTS, applicable
from hexapod_workspace.core.evaluation import check as constraints
from hexapod_workspace.core.evaluation.loading import (
    example_manipulator,
    load_manipulator,
    manipulator_from_mapping,
)
from hexapod_workspace.core.model.collision import scene_distances
from hexapod_workspace.core.motions.checks import check_path
from hexapod_workspace.core.motions.planner import plan_torsion
from hexapod_workspace.core.workspaces.orientation import torsion_range
from hexapod_workspace.errors import ConfigError

EXAMPLE = Path(__file__).resolve().parents[1] / "config" / "example_collision.yaml"
HOME = np.array([0.0, 0.0, -1.3])


@pytest.fixture(scope="module")
def plain() -> Manipulator:
    return example_manipulator()


@pytest.fixture(scope="module")
def cell() -> Manipulator:
    return load_manipulator(EXAMPLE)


def with_scene(plain: Manipulator, collision: dict) -> Manipulator:
    return manipulator_from_mapping({**plain.to_parameters(), **flatten(collision)})


def test_no_scene_no_constraint(plain: Manipulator) -> None:
    """Without a scene the row is not applicable: check leaves it out, no pair is named, and
    the kernels' row is +inf (never limiting)."""
    assert COLLISION not in applicable(plain)
    result = constraints.check(plain, [[0.1, 0.2, 0.3]], HOME)
    assert "collision" not in result.margins
    assert "collision" not in result.limiting_legs
    assert result.collision_pairs == ()
    assert result.collision_pair == [""]
    found = constraints.pose_margins(plain, tt_to_matrix([[0.1, 0.2, 0.3]]), np.array([HOME]))
    assert np.isposinf(found.margins[COLLISION][0])


def test_kernels_agree_with_scene_kernel_and_coal(plain: Manipulator) -> None:
    """10 000 poses over 100 random scenes (3 obstacles, tool, platform): the batch kernel,
    the rotation kernel and the one-pose kernel give the standalone scene kernel's margin and
    pair; the verdicts agree with coal."""
    rng = np.random.default_rng(2121)
    scenes = verdicts = 0
    agree = []
    while scenes < 100:
        try:
            model = with_scene(plain, scene_parameters(rng))
        except ConfigError:  # an obstacle in collision at the home pose: refused, drawn again
            continue
        scenes += 1
        assert model.collision is not None
        rotations, positions = random_poses(rng, 100)
        reference = scene_distances(model, model.collision, rotations, positions, all_pairs=True)
        found = constraints.pose_margins(model, rotations, positions)
        # Apart, every value is exact (GJK to 1e-7 m in the kernels, 1e-9 m standalone); in
        # contact both are certified lower bounds of the depth (the kernels stop GJK as soon as
        # a pair cannot be the smallest), so there the verdict is compared.
        apart = reference.margin + model.collision.clearance > 0.0
        np.testing.assert_allclose(
            found.margins[COLLISION][apart], reference.margin[apart], rtol=0, atol=1e-6
        )
        assert np.all(found.margins[COLLISION][~apart] < 0.0)
        # The pair named holds the margin (near-ties may name either of two pairs).
        assert reference.distances is not None
        named = reference.distances[np.arange(100), found.limiting_legs[COLLISION]]
        np.testing.assert_allclose(
            named[apart] - model.collision.clearance, reference.margin[apart], atol=1e-6
        )
        for pose in range(0, 100, 10):
            one = model.collision
            values = coal_scene(model, one, rotations[pose], positions[pose])
            margin = min(values.values()) - one.clearance
            if abs(margin) > 1e-5:
                agree.append((found.margins[COLLISION, pose] >= 0) == (margin >= 0))
                verdicts += 1
    assert verdicts > 500
    assert all(agree)


def test_batch_and_single_pose_paths_agree(cell: Manipulator) -> None:
    """check() (vectorised blocks), check_pose() (scalar) and pose_margins() (rotations) give
    the same collision margin and pair on 10 000 poses of the worked example."""
    rng = np.random.default_rng(5)
    angles = np.column_stack(
        [
            rng.uniform(-math.pi, math.pi, 10_000),
            rng.uniform(0, 0.7, 10_000),
            rng.uniform(-math.pi, math.pi, 10_000),
        ]
    )
    batch = constraints.check(cell, angles, HOME)
    rotations = constraints.pose_margins(cell, tt_to_matrix(angles), HOME)
    np.testing.assert_allclose(batch.margins["collision"], rotations.margins[COLLISION], atol=1e-12)
    assert np.all(batch.limiting_legs["collision"] == rotations.limiting_legs[COLLISION] + 1)
    for k in range(0, 10_000, 97):
        one = constraints.check_pose(cell, *angles[k], HOME)
        assert one.margins[COLLISION] == pytest.approx(batch.margins["collision"][k], abs=1e-12)
        assert one.limiting_legs[COLLISION] == batch.limiting_legs["collision"][k]
    colliding = batch.margins["collision"] < 0
    assert 0.01 < colliding.mean() < 0.9
    names = set(np.array(batch.collision_pair)[colliding])
    assert any(name.startswith("tool vs leg") for name in names)


def test_worked_example_psi_zero_hits_a_leg(cell: Manipulator) -> None:
    """At (90°, 30°, 0) the spindle meets leg 3 and nothing else is violated; at ψ = 20° it
    clears."""
    result = constraints.check(cell, np.radians([[90.0, 30.0, 0.0], [90.0, 30.0, 20.0]]), HOME)
    assert result.reachable[1]
    assert result.violated[0] == ["collision"]
    assert result.collision_pair[0] == "tool vs leg 3"
    assert result.limiting_leg[0] == 0


def axes_of(angles: np.ndarray) -> np.ndarray:
    phi, theta = angles[:, 0], angles[:, 1]
    return np.column_stack(
        [np.cos(phi) * np.sin(theta), np.sin(phi) * np.sin(theta), np.cos(theta)]
    )


def test_planner_turns_the_tool_clear_of_the_leg(cell: Manipulator) -> None:
    """Tilting to 30° towards φ = 90°: with ψ ≡ 0 the last waypoint hits leg 3; the torsion
    planner finds a plan whose certified moves are all clear."""
    theta = np.radians(np.linspace(0.0, 30.0, 6))
    angles = np.column_stack([np.full(6, math.radians(90.0)), theta, np.zeros(6)])
    positions = np.tile(HOME, (6, 1))
    baseline = check_path(cell, positions, angles=angles)
    assert not baseline.ok
    assert "collision" in baseline.waypoints.violated[-1]
    plan = plan_torsion(cell, positions, axes_of(angles))
    assert plan.ok
    assert plan.path is not None and plan.path.ok
    assert np.all(plan.path.waypoints.margins["collision"] >= 0.0)
    assert not plan.baseline.ok


def sphere_scene(centre: list[float], radius: float) -> dict:
    return {
        "collision": {
            "obstacles": {
                "names": ["ball"],
                "ball": {"shape": "sphere", "position": centre, "radius": radius},
            }
        }
    }


def test_a_move_that_clips_an_obstacle_between_waypoints_is_caught(plain: Manipulator) -> None:
    """A ball next to leg 1's path: both ends of a translation clear it, the middle passes
    through it (dense sampling says so); the certificate reports the move, the pair is named.
    Moved 13 cm down, below the platform joints' path, the same move is certified clear."""
    start, end = HOME + np.array([-0.08, -0.25, 0.0]), HOME + np.array([-0.08, 0.25, 0.0])
    # Just above leg 1's platform joint at the middle of the move: the ball sits there.
    middle = 0.5 * (start + end) + plain.platform_joints[0]
    radius = 0.03
    centre = middle + np.array([0.0, 0.0, 0.05])
    model = with_scene(plain, sphere_scene(centre.tolist(), radius))
    positions = np.array([start, end])
    angles = np.zeros((2, 3))
    result = check_path(model, positions, angles=angles)
    assert result.waypoints.reachable.all()
    samples = np.linspace(0.0, 1.0, 2001)
    dense = constraints.pose_margins(
        model, np.tile(np.eye(3), (2001, 1, 1)), start + samples[:, None] * (end - start)
    )
    assert np.any(dense.margins[COLLISION] < 0), "the move must clip the ball"
    assert not result.segments.ok[0]
    assert "collision" in result.segments.violated[0]
    assert result.segments.collision_pair[0] == "leg 1 vs ball"
    s = result.segments.first_violation_s[0]
    first_dense = samples[np.flatnonzero(dense.margins[COLLISION] < 0)[0]]
    assert abs(s - first_dense) < 2e-3
    clear = with_scene(plain, sphere_scene((centre - np.array([0.0, 0.0, 0.13])).tolist(), radius))
    dense = constraints.pose_margins(
        clear, np.tile(np.eye(3), (2001, 1, 1)), start + samples[:, None] * (end - start)
    )
    assert np.all(dense.margins[COLLISION] > 0)
    assert check_path(clear, positions, angles=angles).ok


def test_torsion_range_boundaries_against_dense_sampling(cell: Manipulator) -> None:
    """The certified torsion scan with the scene: its feasible set equals dense sampling's,
    away from the boundaries (within the tolerance)."""
    for phi, theta in ((90.0, 30.0), (100.0, 30.0), (-165.0, 28.0)):
        found = torsion_range(cell, math.radians(phi), math.radians(theta), HOME, tolerance=1e-4)
        psi = np.linspace(-math.pi, math.pi, 20_001)
        angles = np.column_stack(
            [np.full_like(psi, math.radians(phi)), np.full_like(psi, math.radians(theta)), psi]
        )
        dense = constraints.check(cell, angles, HOME).reachable
        inside = np.zeros_like(dense)
        for low, high in found.intervals:
            inside |= (psi >= low) & (psi <= high)
        near = np.zeros_like(dense)
        for low, high in found.intervals:
            near |= (np.abs(psi - low) < 2e-4) | (np.abs(psi - high) < 2e-4)
        assert np.all(inside[~near] == dense[~near]), (phi, theta)


def test_cli_check_json_names_the_pair() -> None:
    from cli_support import run_main

    code, out, _ = run_main("check", "--config", str(EXAMPLE), "--json", "--pose", "90", "30", "0")
    assert code == 1  # unreachable
    document = json.loads(out)
    pose = document["poses"][0]
    assert pose["collision_pair"] == "tool vs leg 3"
    assert pose["margins"]["collision"] < 0
    assert pose["violated"] == ["collision"]
    _, out, _ = run_main("check", "--json", "--pose", "10", "20", "0")
    pose = json.loads(out)["poses"][0]
    assert "collision" not in pose["margins"] and "collision_pair" not in pose


def test_collision_row_rate_depends_on_the_model(plain: Manipulator, cell: Manipulator) -> None:
    row = CONSTRAINTS[COLLISION]
    assert row.coefficients(plain) == (1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    speed, turn, spin, actuate, crank, ends = row.coefficients(cell)
    assert (speed, turn, actuate, crank, ends) == (1.0, 0.0, 0.0, 0.0, 0.0)  # fixed base joints
    # ρ_c = tool reach + max |b_i| for the spindle (0.6 m) on the example's joints (0.3 m).
    assert spin == pytest.approx(0.6 + float(np.max(np.linalg.norm(cell.platform_joints, axis=1))))


def test_home_collision_refused_in_one_line(plain: Manipulator) -> None:
    with pytest.raises(ConfigError, match=r"collision: leg \d vs block collide at the home pose"):
        with_scene(
            plain,
            {
                "collision": {
                    "obstacles": {
                        "names": ["block"],
                        "block": {
                            "shape": "box",
                            "position": (HOME + plain.platform_joints[0]).tolist(),
                            "size": [2.0, 0.1, 0.1],
                        },
                    }
                }
            },
        )


def test_home_collision_checked_with_the_active_tool(plain: Manipulator) -> None:
    """The home pose is checked with the tool ``tool.number`` selects: a ball 0.5 m under the
    platform centre is clear of a short spindle at the platform (T0) and hit by the same spindle
    hung 0.5 m lower (T2)."""
    scene = {
        "collision": {
            "tool": {"radius": 0.02, "length": 0.05},
            "obstacles": {
                "names": ["ball"],
                "ball": {
                    "shape": "sphere",
                    "position": (HOME + np.array([0.0, 0.0, -0.5])).tolist(),
                    "radius": 0.05,
                },
            },
        },
        "tools": {"T2": {"offset": [0.0, 0.0, -0.5]}},
    }
    assert with_scene(plain, {**scene, "tool": {"number": 0}}).collision is not None
    with pytest.raises(ConfigError, match=r"^collision: tool vs ball collide at the home pose"):
        with_scene(plain, {**scene, "tool": {"number": 2}})
    with pytest.raises(ConfigError, match=r"^tool.number: tool 3 is not in the tool table .*T2"):
        with_scene(plain, {**scene, "tool": {"number": 3}})


def test_collision_row_adds_the_moving_base_joints_speed() -> None:
    """6-PUS with a spindle: the leg bodies' base ends slide, so the row adds ends·E (E the leg
    end rate of the constraint table) to the fixed-base bound."""
    from hexapod_workspace.core.base.params import load_params_file

    parameters = load_params_file(EXAMPLE.parent / "example_pus.yaml")
    spindle = {"collision.tool.radius": 0.02, "collision.tool.length": 0.05}
    pus = manipulator_from_mapping({**parameters, **spindle}, warn=False)
    assert COLLISION in applicable(pus)
    speed, turn, spin, actuate, crank, ends = CONSTRAINTS[COLLISION].coefficients(pus)
    assert (speed, turn, actuate, crank, ends) == (1.0, 0.0, 0.0, 0.0, 1.0)
    assert spin > 0.0
