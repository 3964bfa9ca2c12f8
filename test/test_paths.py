"""Certified move checks against dense sampling, rate bounds, torsion plans (seeded).

Independent evidence: the dense samples use their own interpolation (Rodrigues' formula for the
geodesic, plain linear T&T angles), not the module's; plans are re-checked pose by pose and move
by move; "no plan" answers are cross-checked by enumerating every torsion profile of the grid.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from path_support import random_large_moves

from hexapod_workspace import InputError, check, check_path, plan_torsion
from hexapod_workspace.core.base.rotations import (
    approach_vector,
    matrix_to_quaternion,
    tt_to_matrix,
    wrap_angle,
)
from hexapod_workspace.core.constraints.table import COLLISION, INDEX
from hexapod_workspace.core.evaluation.check import inverse_kinematics, pose_margins
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping
from hexapod_workspace.core.motions.certificate import _Certifier
from hexapod_workspace.core.motions.interpolation import _Moves

OFF_AXIS = np.array([0.2, 0.2, -0.95])

UPS_ROWS = ("leg_length", "base_joint", "platform_joint", "leg_interference", "singularity")


def rodrigues(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotations (n, 3, 3) by angles (n,) about one unit axis (closed form)."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return (
        np.eye(3) + np.sin(angle)[:, None, None] * k + (1 - np.cos(angle))[:, None, None] * (k @ k)
    )


def dense_poses(p0, p1, angles0, angles1, interpolation, s):
    """Poses along a move, computed independently of hexapod_workspace.core.motions."""
    positions = p0 + s[:, None] * (p1 - p0)
    if interpolation == "slerp":
        r0, r1 = tt_to_matrix(angles0), tt_to_matrix(angles1)
        relative = matrix_to_quaternion(r0.T @ r1)
        angle = 2.0 * math.atan2(np.linalg.norm(relative[:3]), relative[3])
        axis = relative[:3] / np.linalg.norm(relative[:3]) if angle > 0 else np.array([0, 0, 1.0])
        return r0 @ rodrigues(axis, s * angle), positions
    a0, a1 = np.asarray(angles0, float), np.asarray(angles1, float)
    delta = np.array([wrap_angle(a1[0] - a0[0]), a1[1] - a0[1], wrap_angle(a1[2] - a0[2])])
    return tt_to_matrix(a0 + s[:, None] * delta), positions


def dense_violations(manipulator, positions, angles, k, interpolation, samples):
    """Samples s and whether each violates, along the move from waypoint k to k + 1."""
    s = np.linspace(0.0, 1.0, samples)
    rotations, where = dense_poses(
        positions[k], positions[k + 1], angles[k], angles[k + 1], interpolation, s
    )
    return s, ~pose_margins(manipulator, rotations, where).reachable


@pytest.fixture(scope="module")
def random_moves(example):
    """Large random moves (±0.3 m, tilts to 30°) around the example's working volume."""
    positions, angles = random_large_moves()
    results = {
        interpolation: check_path(example, positions, angles=angles, interpolation=interpolation)
        for interpolation in ("slerp", "tilt-torsion")
    }
    return positions, angles, results


@pytest.mark.parametrize("interpolation", ["slerp", "tilt-torsion"])
def test_interior_violations_between_reachable_poses_are_caught(
    example, random_moves, interpolation
):
    positions, angles, results = random_moves
    result = results[interpolation]
    ends = result.waypoints.reachable[:-1] & result.waypoints.reachable[1:]
    caught = np.flatnonzero(ends & ~result.segments.ok)
    assert caught.size >= 2  # both ends reachable, the move is not: what endpoint checks miss
    tolerance_s = result.tolerance / (
        result.segments.angular_rate + result.segments.translation / 0.3
    )
    for k in caught[:4]:
        s, violated = dense_violations(example, positions, angles, k, interpolation, 100_000)
        assert violated.any() and not violated[0] and not violated[-1]
        # The reported first violation is the first: a violated pose, no earlier violated
        # sample beyond one tolerance step.
        reported = result.segments.first_violation_s[k]
        first = s[np.argmax(violated)]
        assert abs(first - reported) <= tolerance_s[k] + 1e-5
        rotations, where = dense_poses(
            positions[k],
            positions[k + 1],
            angles[k],
            angles[k + 1],
            interpolation,
            np.array([reported]),
        )
        np.testing.assert_allclose(where[0], result.segments.violation_positions[k], atol=1e-12)
        assert not pose_margins(example, rotations, where).reachable[0]
        assert result.segments.violated[k]
        assert result.segments.limiting_leg[k] >= 1


@pytest.mark.parametrize("interpolation", ["slerp", "tilt-torsion"])
def test_ok_moves_have_no_violated_sample(example, random_moves, interpolation):
    positions, angles, results = random_moves
    result = results[interpolation]
    ok = np.flatnonzero(result.segments.ok)
    # The hardest ok moves: the smallest certified margins and the longest rotations.
    tight = ok[np.argsort(result.segments.min_relative_margin_bound[ok])[:3]]
    long = ok[np.argsort(-result.segments.angular_rate[ok])[:2]]
    for k in np.unique(np.concatenate([tight, long])):
        s, violated = dense_violations(example, positions, angles, k, interpolation, 100_000)
        assert not violated.any(), k
    bound = result.segments.min_relative_margin_bound[ok]
    assert np.all(bound <= result.segments.min_relative_margin[ok] + 1e-12)


def test_min_margin_is_where_it_says(example, random_moves):
    positions, angles, results = random_moves
    result = results["slerp"]
    k = int(np.flatnonzero(result.segments.ok)[0])
    s = result.segments.min_at_s[k]
    rotations, where = dense_poses(
        positions[k], positions[k + 1], angles[k], angles[k + 1], "slerp", np.array([s])
    )
    from hexapod_workspace.core.evaluation.check import relative_margins

    margins = pose_margins(example, rotations, where).margins
    assert relative_margins(example, margins).min() == pytest.approx(
        result.segments.min_relative_margin[k], abs=1e-12
    )


@pytest.mark.parametrize("interpolation", ["slerp", "tilt-torsion"])
def test_angular_rate_and_lipschitz_bounds_hold(example, rng, interpolation):
    """Finite differences along random moves stay under the documented bounds."""
    certifier = _Certifier(example)
    count = 60
    p0 = np.array([0.0, 0.0, -1.2]) + rng.uniform(-0.2, 0.2, (count, 3))
    p1 = np.array([0.0, 0.0, -1.2]) + rng.uniform(-0.2, 0.2, (count, 3))
    a0 = np.column_stack(
        [rng.uniform(-np.pi, np.pi, count), rng.uniform(0, 0.6, count), rng.uniform(-1, 1, count)]
    )
    a1 = np.column_stack(
        [rng.uniform(-np.pi, np.pi, count), rng.uniform(0, 0.6, count), rng.uniform(-1, 1, count)]
    )
    a1[:5, 1] = 0.0  # θ = 0 ends: the azimuth is free there
    moves = _Moves(p0, p1, tt_to_matrix(a0), tt_to_matrix(a1), interpolation, certifier.rho)
    steps = 4001
    s = np.linspace(0.0, 1.0, steps)
    ids = np.repeat(np.arange(count), steps)
    rotations, positions = moves.poses(ids, np.tile(s, count))
    rotations = rotations.reshape(count, steps, 3, 3)
    np.testing.assert_allclose(rotations[:, 0], tt_to_matrix(a0), atol=1e-12)
    np.testing.assert_allclose(rotations[:, -1], tt_to_matrix(a1), atol=1e-12)
    # Angular speed from consecutive rotations: angle of R_kᵀ R_{k+1} over ds.
    relative = np.einsum("mnji,mnjk->mnik", rotations[:, :-1], rotations[:, 1:])
    cosine = np.clip((np.trace(relative, axis1=2, axis2=3) - 1.0) / 2.0, -1.0, 1.0)
    speed = np.arccos(cosine) / (1.0 / (steps - 1))
    assert np.all(speed.max(axis=1) <= moves.omega * (1 + 1e-4) + 1e-6)
    if interpolation == "slerp":  # constant rate
        np.testing.assert_allclose(
            speed, np.broadcast_to(moves.omega[:, None], speed.shape), atol=1e-4
        )
    # Margins: |Δm| ≤ L·Δs with the floor taken as the smallest leg along the move (the
    # singularity margin evaluated: a limit > 0).
    model = manipulator_from_mapping(
        {**example.to_parameters(), "limits.singularity_min": 0.01}, warn=False
    )
    every_row = pose_margins(model, rotations.reshape(-1, 3, 3), positions).margins
    margins = every_row[[INDEX[name] for name in UPS_ROWS]]  # the rows of a 6-UPS model
    margins = margins.reshape(margins.shape[0], count, steps)
    lengths = inverse_kinematics(model, rotations.reshape(-1, 3, 3), positions).lengths
    floor = lengths.reshape(count, steps, 6).min(axis=(1, 2))
    turn = moves.speed / floor
    # Written out here from the derivations (constraint_table), not read from the table.
    lipschitz = np.stack(
        [
            moves.speed,
            turn,
            moves.omega + turn,
            2 * moves.speed,
            math.sqrt(12.0) * (turn + moves.omega),
        ]
    )
    # The example declares no collision scene: that row is +inf (its rate bound is tested with
    # a scene in test_collision.py); the five rows above are compared.
    assert np.all(np.isposinf(every_row[COLLISION]))
    rates = np.abs(np.diff(margins[: len(lipschitz)], axis=2)).max(axis=2) * (steps - 1)
    assert np.all(rates <= lipschitz * (1 + 1e-3) + 1e-9)


def test_orientation_forms_agree(example, rng):
    count = 30
    positions = OFF_AXIS + rng.uniform(-0.05, 0.05, (count, 3))
    angles = np.column_stack(
        [rng.uniform(-np.pi, np.pi, count), rng.uniform(0, 0.4, count), rng.uniform(-1, 1, count)]
    )
    rotations = tt_to_matrix(angles)
    by_angles = check_path(example, positions, angles=angles)
    by_quaternions = check_path(
        example, positions, quaternions=-3.0 * matrix_to_quaternion(rotations)
    )
    by_rotations = check_path(example, positions, rotations=rotations)
    for other in (by_quaternions, by_rotations):
        np.testing.assert_array_equal(other.segments.ok, by_angles.segments.ok)
        np.testing.assert_allclose(
            other.waypoints.margin_array, by_angles.waypoints.margin_array, atol=1e-12
        )
    # Waypoint results equal the pose check at each position.
    for k in range(0, count, 7):
        single = check(example, angles[k], positions[k])
        assert single.reachable[0] == by_angles.waypoints.reachable[k]
        assert single.limiting_leg[0] == by_angles.waypoints.limiting_leg[k]


def test_huge_angles_are_reduced_before_combining(example):
    positions = np.tile(OFF_AXIS, (2, 1))
    huge = np.array([[1e300, 0.2, -1e300], [3e200, 0.1, 7e15]])
    reduced = wrap_angle(huge)
    a = check_path(example, positions, angles=huge)
    b = check_path(example, positions, angles=reduced)
    np.testing.assert_array_equal(a.waypoints.margin_array, b.waypoints.margin_array)
    np.testing.assert_array_equal(a.segments.ok, b.segments.ok)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"positions": [[0, 0, -1.3]], "angles": [[0, 0, 0]]}, "2 to"),
        ({"positions": [[0, 0, -1.3], [0, 0, np.nan]], "angles": [[0, 0, 0]] * 2}, "finite"),
        ({"positions": [[0, 0, -1.3], [1e300, 0, 0]], "angles": [[0, 0, 0]] * 2}, "within"),
        ({"positions": [[0, 0, -1.3]] * 2, "angles": [[0, np.inf, 0]] * 2}, "finite"),
        ({"positions": [[0, 0, -1.3]] * 2, "quaternions": [[0, 0, 0, 0]] * 2}, "non-zero"),
        ({"positions": [[0, 0, -1.3]] * 2, "rotations": [np.eye(3) * 2] * 2}, "rotation"),
        ({"positions": [[0, 0, -1.3]] * 2}, "exactly one"),
        (
            {"positions": [[0, 0, -1.3]] * 2, "angles": [[0, 0, 0]] * 2, "interpolation": "x"},
            "one of",
        ),
        (
            {"positions": [[0, 0, -1.3]] * 2, "angles": [[0, 0, 0]] * 2, "tolerance": 0.0},
            "tolerance",
        ),
    ],
)
def test_check_path_refuses_bad_input(example, kwargs, match):
    with pytest.raises(InputError, match=match):
        check_path(example, **kwargs)


def test_check_path_refuses_what_check_refuses(example):
    """Positions are bounded by their distance to the base origin, as in a pose check: a point
    within ±1e6 m per coordinate but 1.27e6 m away is refused by both."""
    far = [9e5, 9e5, 0.0]
    with pytest.raises(InputError, match="position"):
        check(example, [0.0, 0.0, 0.0], far)
    with pytest.raises(InputError, match="within 1e\\+06 m of the base origin, waypoint 1"):
        check_path(example, [[0, 0, -1.3], far], angles=[[0, 0, 0]] * 2)
    with pytest.raises(InputError, match="waypoint 1"):
        plan_torsion(example, [[0, 0, -1.3], far], [[0, 0, 1]] * 2)


# ============================================================================ planner
def cone_toolpath(count: int, tilt_deg: float, radius: float = 0.02):
    """Tool tip on a circle around the off-axis position, tool axes on a cone of ``tilt_deg``."""
    t = np.linspace(0.0, 2.0 * np.pi, count)
    positions = OFF_AXIS + np.column_stack([radius * np.cos(t), radius * np.sin(t), 0 * t])
    return positions, approach_vector(t, np.radians(tilt_deg))


def test_plan_passes_where_torsion_zero_fails(example):
    positions, axes = cone_toolpath(60, 17.0)
    plan = plan_torsion(example, positions, axes, psi_step=np.radians(5.0))
    assert plan.baseline.failed_waypoints  # the paper's ψ = 0 fails off the axis
    assert plan.ok and plan.path.ok and plan.breakpoint is None
    # Pose by pose: the planned orientation has the requested tool axis and is reachable.
    matrices = tt_to_matrix(plan.path.waypoints.angles)
    np.testing.assert_allclose(matrices[:, :, 2], axes, atol=1e-12)
    single = check(example, plan.path.waypoints.angles[0], positions[0])
    assert single.reachable[0]
    for k in range(len(positions)):
        assert check(example, plan.path.waypoints.angles[k], positions[k]).reachable[0]
    # Move by move, against dense sampling.
    angles = np.column_stack([plan.path.waypoints.angles[:, :2], plan.psi])
    for k in range(0, len(positions) - 1, 6):
        _, violated = dense_violations(example, positions, angles, k, "slerp", 20_000)
        assert not violated.any()
    # The objective is a certified lower bound of the re-checked plan (one level of slack).
    assert plan.objective > 0.0
    assert plan.path.segments.min_relative_margin_bound.min() >= plan.objective - 1e-12


def test_max_dpsi_is_respected(example):
    positions, axes = cone_toolpath(60, 17.0)
    limit = np.radians(5.0)
    plan = plan_torsion(example, positions, axes, psi_step=np.radians(2.5), max_dpsi=limit)
    assert plan.ok
    assert np.abs(wrap_angle(np.diff(plan.psi))).max() <= limit + 1e-9


def enumerate_grid(example, positions, directions, grid, interpolation="slerp", max_dpsi=None):
    """Brute force: every torsion profile on the grid, each waypoint and move checked by
    check_path (a 2-waypoint path per torsion pair). Returns the feasible profiles."""
    count, size = len(positions), len(grid)
    waypoint_ok = np.zeros((count, size), dtype=bool)
    move_ok = np.zeros((count - 1, size, size), dtype=bool)
    for k in range(count - 1):
        g, h = np.meshgrid(np.arange(size), np.arange(size), indexing="ij")
        g, h = g.ravel(), h.ravel()
        # Waypoints [start_g, end_h] for every pair, one path; every even move is a pair.
        angles = np.empty((2 * g.size, 3))
        angles[0::2] = np.column_stack([np.tile(directions[k], (g.size, 1)), grid[g]])
        angles[1::2] = np.column_stack([np.tile(directions[k + 1], (g.size, 1)), grid[h]])
        where = np.empty((2 * g.size, 3))
        where[0::2], where[1::2] = positions[k], positions[k + 1]
        result = check_path(example, where, angles=angles, interpolation=interpolation)
        move_ok[k] = result.segments.ok[0::2].reshape(size, size)
        waypoint_ok[k] = result.waypoints.reachable[0::2][::size]
        waypoint_ok[k + 1] = result.waypoints.reachable[1::2][:size]
    feasible = []
    for profile in itertools.product(range(size), repeat=count):
        if not all(waypoint_ok[k, profile[k]] for k in range(count)):
            continue
        if max_dpsi is not None and any(
            abs(wrap_angle(grid[profile[k + 1]] - grid[profile[k]])) > max_dpsi + 1e-9
            for k in range(count - 1)
        ):
            continue
        if all(move_ok[k, profile[k], profile[k + 1]] for k in range(count - 1)):
            feasible.append(profile)
    return feasible, waypoint_ok, move_ok


def test_no_plan_at_an_unreachable_waypoint_is_named(example):
    positions, axes = cone_toolpath(4, 17.0)
    axes = axes.copy()
    axes[2] = approach_vector(0.3, np.radians(70.0))  # beyond any torsion's reach
    plan = plan_torsion(example, positions, axes, psi_step=np.radians(30.0))
    assert not plan.ok and plan.psi is None
    assert plan.breakpoint.kind == "waypoint" and plan.breakpoint.index == 2
    assert "waypoint 2" in plan.breakpoint.reason
    grid = wrap_angle(-np.pi + np.radians(30.0) * np.arange(12))
    directions = plan.directions
    feasible, waypoint_ok, _ = enumerate_grid(example, positions, directions, grid)
    assert not feasible and not waypoint_ok[2].any() and waypoint_ok[1].any()


def test_no_plan_at_a_move_is_named_and_matches_brute_force(example):
    # Two tool directions whose feasible torsions lie far apart; max_dpsi forbids the jump.
    positions = np.tile(OFF_AXIS, (3, 1))
    # torsion_range at OFF_AXIS: (140°, 24°) needs ψ in [-35.8°, -18.6°],
    # (-120°, 35°) needs ψ in [39.4°, 47.2°].
    directions = np.radians([[140.0, 24.0], [140.0, 24.0], [-120.0, 35.0]])
    axes = approach_vector(directions[:, 0], directions[:, 1])
    step, limit = np.radians(15.0), np.radians(15.0)
    plan = plan_torsion(example, positions, axes, psi_step=step, max_dpsi=limit)
    grid = wrap_angle(-np.pi + step * np.arange(24))
    feasible, waypoint_ok, _ = enumerate_grid(
        example, positions, plan.directions, grid, max_dpsi=limit
    )
    assert waypoint_ok.any(axis=1).all()  # every waypoint alone has a torsion
    assert not plan.ok and not feasible
    assert plan.breakpoint.kind == "segment" and plan.breakpoint.index == 1
    assert "max_dpsi" in plan.breakpoint.reason
    # Without the limit the brute force and the planner agree again.
    free = plan_torsion(example, positions, axes, psi_step=step)
    feasible_free, _, _ = enumerate_grid(example, positions, plan.directions, grid)
    assert free.ok == bool(feasible_free)
    if free.ok:
        index = np.round((free.psi + np.pi) / step).astype(int) % 24
        assert tuple(index) in set(feasible_free)


def test_huge_and_tiny_axes_keep_their_direction(example):
    positions = np.tile([0.0, 0.0, -1.3], (3, 1))
    axes = np.array([[0.0, 0.0, 1.0], [1e300, 0.0, 3e300], [1e-310, 0.0, 3e-310]])
    plan = plan_torsion(example, positions, axes, psi_step=np.radians(30.0))
    np.testing.assert_allclose(plan.directions[1], plan.directions[2], atol=1e-12)
    np.testing.assert_allclose(plan.directions[1], [0.0, np.arctan2(1.0, 3.0)], atol=1e-12)


@pytest.mark.parametrize(
    ("axes", "match"),
    [
        ([[0, 0, 1.0], [0, 0, 0.0]], "non-zero"),
        ([[0, 0, 1.0], [np.nan, 0, 1.0]], "finite"),
        ([[0, 0, 1.0]], "shape"),
    ],
)
def test_plan_refuses_bad_axes(example, axes, match):
    with pytest.raises(InputError, match=match):
        plan_torsion(example, np.tile([0, 0, -1.3], (2, 1)), axes)


def test_singular_ends_take_the_other_azimuth_and_keep_their_rotation():
    from hexapod_workspace.core.motions.interpolation import _align_singular

    angles = np.array([[0.3, np.pi, 0.7], [0.2, 0.0, -0.4], [0.1, 0.5, 0.2]])
    other = np.array([[1.1, 0.5, 0.0], [-2.0, 0.3, 0.1], [3.0, 0.4, 0.0]])
    aligned = _align_singular(angles, other)
    np.testing.assert_allclose(tt_to_matrix(aligned), tt_to_matrix(angles), atol=1e-14)
    np.testing.assert_array_equal(aligned[:2, 0], other[:2, 0])
    np.testing.assert_array_equal(aligned[2], angles[2])  # regular: unchanged


def test_report_singularity_fills_the_waypoints_as_check_does(example):
    """At limits.singularity_min 0 the path leaves the singularity margin +inf; the report
    evaluates it at every waypoint (as check(..., singularity=True)) and changes nothing else."""
    from hexapod_workspace.core.motions import report_singularity

    rng = np.random.default_rng(5)
    positions = np.array([0.0, 0.0, -1.15]) + rng.uniform(-0.1, 0.1, (6, 3))
    angles = np.column_stack(
        [rng.uniform(-np.pi, np.pi, 6), rng.uniform(0, 0.4, 6), rng.uniform(-0.5, 0.5, 6)]
    )
    result = check_path(example, positions, angles=angles)
    assert np.all(np.isposinf(result.waypoints.margins["singularity"]))
    reported = report_singularity(example, result)
    expected = [
        check(example, angles[k : k + 1], positions[k], singularity=True).margins["singularity"][0]
        for k in range(len(positions))
    ]
    np.testing.assert_allclose(reported.waypoints.margins["singularity"], expected, rtol=1e-12)
    assert reported.ok == result.ok and reported.segments is result.segments
    for name, values in result.waypoints.margins.items():
        if name != "singularity":
            np.testing.assert_array_equal(reported.waypoints.margins[name], values)
    plan = plan_torsion(example, positions[:3], np.tile([0.0, 0.0, 1.0], (3, 1)))
    planned = report_singularity(example, plan)
    assert np.all(np.isfinite(planned.baseline.waypoints.margins["singularity"]))
