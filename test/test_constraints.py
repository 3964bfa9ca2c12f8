"""Constraint margins: exact segment distance, literal references, symmetry, closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference import pose_margins_literal, segment_distance_literal

from hexapod_workspace import InputError, check
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.check import (
    inverse_kinematics,
    pose_margins,
    segment_distance,
)
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping

#: The 6-UPS model's constraints (the rows of the table that apply to it), as before the leg
#: architectures: ``check`` gives exactly these names for a 6-UPS manipulator.
CONSTRAINT_NAMES = ("leg_length", "base_joint", "platform_joint", "leg_interference", "singularity")


def brute_segment_distance(p0, p1, q0, q1, samples: int = 4001) -> float:
    """Dense sampling of both segments: an upper bound within half a sample spacing."""
    s = np.linspace(0.0, 1.0, samples)[:, None]
    first = p0 + s * (p1 - p0)
    second = q0 + s * (q1 - q0)
    # Distance from every sample of the first to the second segment, exactly (point-segment).
    d2 = q1 - q0
    length2 = d2 @ d2
    t = np.clip(((first - q0) @ d2) / length2, 0.0, 1.0) if length2 > 0 else np.zeros(samples)
    best_first = np.linalg.norm(first - (q0 + t[:, None] * d2), axis=1).min()
    d1 = p1 - p0
    length1 = d1 @ d1
    t = np.clip(((second - p0) @ d1) / length1, 0.0, 1.0) if length1 > 0 else np.zeros(samples)
    best_second = np.linalg.norm(second - (p0 + t[:, None] * d1), axis=1).min()
    return float(min(best_first, best_second))


def segment_cases(rng: np.random.Generator):
    for _ in range(200):
        yield "random", rng.normal(size=(4, 3))
    for _ in range(50):
        p0, p1, q0 = rng.normal(size=(3, 3))
        yield "parallel", np.array([p0, p1, q0, q0 + (p1 - p0) * rng.uniform(-2.0, 2.0)])
    for _ in range(50):
        p0, p1 = rng.normal(size=(2, 3))
        u, v = sorted(rng.uniform(-1.0, 2.0, 2))
        yield "collinear", np.array([p0, p1, p0 + u * (p1 - p0), p0 + v * (p1 - p0)])
    for _ in range(30):
        p0, q0, q1 = rng.normal(size=(3, 3))
        yield "first is a point", np.array([p0, p0, q0, q1])
        yield "second is a point", np.array([q0, q1, p0, p0])
        yield "both points", np.array([p0, p0, q0, q0])
    for _ in range(30):
        # Crossing segments: distance exactly 0.
        centre, u, v = rng.normal(size=(3, 3))
        yield "crossing", np.array([centre - u, centre + u, centre - v, centre + v])


def test_segment_distance_against_brute_force_sampling(rng):
    for kind, (p0, p1, q0, q1) in segment_cases(rng):
        exact = float(segment_distance(p0, p1, q0, q1))
        sampled = brute_segment_distance(p0, p1, q0, q1)
        spacing = max(np.linalg.norm(p1 - p0), np.linalg.norm(q1 - q0)) / 4000
        # The exact minimum is never above a sampled distance (up to rounding) ...
        assert exact <= sampled + 1e-7, kind
        # ... and sampling gets within its spacing of it.
        assert sampled - exact <= spacing + 1e-7, kind
        # Independent closed-form reference (critical point + edges).
        assert exact == pytest.approx(segment_distance_literal(p0, p1, q0, q1), abs=1e-7), kind


def test_segment_distance_known_values():
    # Skew perpendicular segments one unit apart (hand calculation).
    assert segment_distance([-1, 0, 0], [1, 0, 0], [0, -1, 1], [0, 1, 1]) == pytest.approx(1.0)
    # Parallel, overlapping: distance between the lines.
    assert segment_distance([0, 0, 0], [2, 0, 0], [1, 0.5, 0], [3, 0.5, 0]) == pytest.approx(0.5)
    # Parallel, disjoint along the axis: end to end.
    assert segment_distance([0, 0, 0], [1, 0, 0], [3, 0, 4], [5, 0, 4]) == pytest.approx(
        math.hypot(2.0, 4.0)
    )
    # Collinear, disjoint: the gap.
    assert segment_distance([0, 0, 0], [1, 0, 0], [2.5, 0, 0], [4, 0, 0]) == pytest.approx(1.5)
    # Both points.
    assert segment_distance([1, 2, 3], [1, 2, 3], [4, 6, 3], [4, 6, 3]) == pytest.approx(5.0)


def test_segment_distance_broadcasts(rng):
    p0, p1, q0, q1 = rng.normal(size=(4, 7, 3))
    batched = segment_distance(p0, p1, q0, q1)
    assert batched.shape == (7,)
    for k in range(7):
        assert batched[k] == pytest.approx(segment_distance_literal(p0[k], p1[k], q0[k], q1[k]))


def random_angles(rng: np.random.Generator, count: int, tilt: float = 0.9) -> np.ndarray:
    return np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, tilt, count),
            rng.uniform(-1.5, 1.5, count),
        ]
    )


def test_margins_match_the_literal_definitions(example, rng):
    angles = random_angles(rng, 300)
    positions = [example.position, np.array([0.2, 0.2, -0.95]), np.array([-0.1, 0.05, -1.1])]
    for position in positions:
        result = check(example, angles, position)
        for index in range(len(angles)):
            literal = pose_margins_literal(example, angles[index], position)
            for name in CONSTRAINT_NAMES:
                assert result.margins[name][index] == pytest.approx(literal[name], abs=1e-9), name
            assert result.reachable[index] == (min(literal.values()) >= 0.0)


def test_margins_with_per_leg_limits_match_literal(example, rng):
    parameters = example.to_parameters()
    parameters["limits.base_joint_max_angle"] = [0.5, 0.6, 0.7, 0.8, 0.9, 1.0]
    parameters["limits.platform_joint_max_angle"] = [1.0, 0.9, 0.8, 0.7, 0.6, 0.5]
    parameters["limits.leg_length_min"] = [0.80, 0.81, 0.82, 0.83, 0.84, 0.85]
    model = manipulator_from_mapping(parameters, warn=False)
    angles = random_angles(rng, 200)
    result = check(model, angles)
    for index in range(len(angles)):
        literal = pose_margins_literal(model, angles[index], model.position)
        for name in CONSTRAINT_NAMES:
            assert result.margins[name][index] == pytest.approx(literal[name], abs=1e-9)


def test_home_pose_closed_form(example):
    # Hand calculation for leg 1 at p = (0, 0, -1.3), R = I:
    # L_1 = p + b_1 - a_1 = (0.200739 - 0.537981, -0.222943 + 0.114351, 0.1 - 1.3)
    #     = (-0.337242, -0.108592, -1.2), |L_1| = sqrt(1.565524...) = 1.251209...
    # The design is axisymmetric, so all six legs have that length; the leg-length margin is
    # l_max - |L| = 1.45 - 1.251209 = 0.198791 m.
    result = check(example, [0.0, 0.0, 0.0], [0.0, 0.0, -1.3])
    length = math.sqrt(0.337242**2 + 0.108592**2 + 1.2**2)
    assert result.margins["leg_length"][0] == pytest.approx(1.45 - length, abs=1e-6)
    # Default joint axes are the home leg directions, so both joint angles are zero there.
    assert result.margins["base_joint"][0] == pytest.approx(0.7854, abs=1e-7)
    assert result.margins["platform_joint"][0] == pytest.approx(0.7854, abs=1e-7)
    assert result.reachable[0]
    assert result.violated == [[]]


def test_pure_vertical_translation_changes_lengths_only(example):
    # On the axis, a vertical move keeps the symmetry: all legs equal, closed form per leg.
    for z in (-1.0, -1.2, -1.4):
        kinematics = inverse_kinematics(example, np.eye(3)[None], [0.0, 0.0, z])
        expected = math.sqrt(0.337242**2 + 0.108592**2 + (z + 0.1) ** 2)
        np.testing.assert_allclose(kinematics.lengths[0], expected, atol=1e-6)
        np.testing.assert_allclose(np.linalg.norm(kinematics.directions[0], axis=1), 1.0)


def test_example_matches_its_exact_polar_description(example, symmetric):
    np.testing.assert_allclose(example.base_joints, symmetric.base_joints, atol=5e-7)
    np.testing.assert_allclose(example.platform_joints, symmetric.platform_joints, atol=5e-7)


def test_axisymmetry_permutes_legs_and_keeps_margins(symmetric, rng):
    # Rotating the pose by 120 deg about z with the position on the axis maps leg i to leg
    # i + 2: R' = Rz(120) R Rz(-120), i.e. (phi, theta, psi) -> (phi + 120 deg, theta, psi).
    angles = random_angles(rng, 500)
    rotated = angles.copy()
    rotated[:, 0] += 2.0 * math.pi / 3.0
    position = np.array([0.0, 0.0, -1.2])
    example = symmetric
    before = check(example, angles, position)
    after = check(example, rotated, position)
    for name in CONSTRAINT_NAMES:
        np.testing.assert_allclose(after.margins[name], before.margins[name], atol=1e-12)
    np.testing.assert_array_equal(after.reachable, before.reachable)
    lengths_before = inverse_kinematics(example, tt_to_matrix(angles), position).lengths
    lengths_after = inverse_kinematics(example, tt_to_matrix(rotated), position).lengths
    np.testing.assert_allclose(lengths_after, np.roll(lengths_before, 2, axis=1), atol=1e-12)
    moved = (before.limiting_legs["leg_length"] - 1 + 2) % 6 + 1
    agree = after.limiting_legs["leg_length"] == moved
    assert agree.mean() > 0.99  # ties between symmetric legs may pick either


def test_violated_names_and_limiting_leg(example):
    result = check(example, [[0.0, 0.0, 0.0], [0.0, math.radians(60.0), 0.0]])
    assert result.violated == [[], ["leg_length", "platform_joint"]]
    assert list(result.reachable) == [True, False]
    assert set(result.limiting_leg.tolist()) <= set(range(1, 7))
    assert np.all(result.limiting_pair[:, 0] < result.limiting_pair[:, 1])


def test_violated_is_computed_once_and_equals_the_margins(example, rng):
    """Per-pose lists are kept after the first access (O(1) per pose when read pose by pose)
    and name exactly the negative (or NaN) margins, in table order."""
    result = check(example, random_angles(rng, 500))
    violated = result.violated
    assert result.violated is violated and result.collision_pair is result.collision_pair
    names = list(result.margins)
    for k in range(len(result)):
        expected = [name for name in names if not result.margins[name][k] >= 0.0]
        assert violated[k] == expected
        assert (violated[k] == []) == bool(result.reachable[k])
    assert result.collision_pair == [""] * len(result)  # no scene


def test_limiting_leg_is_the_leg_of_the_smallest_margin(example, rng):
    angles = random_angles(rng, 200)
    result = check(example, angles)
    rotations = tt_to_matrix(angles)
    lengths = inverse_kinematics(example, rotations, example.position).lengths
    per_leg = np.minimum(lengths - example.leg_length_min, example.leg_length_max - lengths)
    np.testing.assert_array_equal(result.limiting_legs["leg_length"], per_leg.argmin(axis=1) + 1)


def test_disabled_interference_is_infinite(example):
    parameters = example.to_parameters()
    parameters["limits.leg_diameter"] = 0.0
    model = manipulator_from_mapping(parameters)
    result = check(model, [0.0, 0.1, 0.0])
    assert result.margins["leg_interference"][0] == math.inf
    assert result.limiting_legs["leg_interference"][0] == 0
    assert result.limiting_pair.tolist() == [[0, 0]]


def test_interference_detects_touching_legs(example):
    # Enlarge D to the distance found at the home pose: the margin is zero there, and a
    # slightly larger D makes the pose unreachable with leg_interference violated.
    home = check(example, [0.0, 0.0, 0.0], example.home_position)
    distance = home.margins["leg_interference"][0] + example.leg_diameter
    parameters = example.to_parameters()
    parameters["limits.leg_diameter"] = distance + 1e-6
    model = manipulator_from_mapping(parameters, warn=False)
    result = check(model, [0.0, 0.0, 0.0], example.home_position)
    assert result.violated == [["leg_interference"]]
    assert result.margins["leg_interference"][0] == pytest.approx(-1e-6, abs=1e-12)


def test_pose_margins_batches_positions(example, rng):
    angles = random_angles(rng, 50)
    positions = rng.uniform(-0.1, 0.1, size=(50, 3)) + example.position
    batched = pose_margins(example, tt_to_matrix(angles), positions)
    for k in range(50):
        single = check(example, angles[k], positions[k])
        for row, name in enumerate(CONSTRAINT_NAMES):
            assert batched.margins[row, k] == pytest.approx(single.margins[name][0], abs=1e-14)


def test_large_batches_cross_chunk_boundaries(example, rng):
    angles = random_angles(rng, 5000)
    whole = check(example, angles)
    parts = [check(example, angles[i : i + 777]) for i in range(0, 5000, 777)]
    for name in CONSTRAINT_NAMES:
        np.testing.assert_array_equal(
            whole.margins[name], np.concatenate([p.margins[name] for p in parts])
        )


@pytest.mark.parametrize(
    ("angles", "position", "message"),
    [
        ([[0.0, math.nan, 0.0]], None, "angles: expected finite values, pose 0"),
        ([[0.0, 0.0, math.inf]], None, "angles: expected finite values"),
        ([[0.0, 0.0]], None, r"angles: expected shape \(N, 3\)"),
        ([0.0, 0.0, 0.0], [0.0, 0.0], r"position: expected 3 finite values"),
        ([0.0, 0.0, 0.0], [0.0, math.nan, -1.0], "position: expected 3 finite values"),
    ],
)
def test_bad_input_is_refused(example, angles, position, message):
    with pytest.raises(InputError, match=message):
        check(example, angles, position)


def test_empty_batch(example):
    result = check(example, np.zeros((0, 3)))
    assert len(result) == 0
    assert result.violated == []


def test_batch_outputs_share_one_block_without_overlapping(example, rng):
    """check's output arrays are views of one allocation (see ``_output_arrays``): each is
    C-contiguous, aligned and writable, none overlaps another, and every pose's answer equals
    the one-pose check's."""
    angles = np.column_stack(
        [rng.uniform(-np.pi, np.pi, 257), rng.uniform(0, 0.6, 257), rng.uniform(-1, 1, 257)]
    )
    result = check(example, angles, singularity=True)
    arrays = [
        *result.margins.values(),
        *result.limiting_legs.values(),
        result.limiting_pair,
        result.limiting_constraint,
        result.reachable,
    ]
    for array in arrays:
        assert array.flags.c_contiguous and array.flags.aligned and array.flags.writeable
    separate = [*result.margins.values(), result.reachable, result.limiting_pair]
    for i, first in enumerate(separate):
        for second in separate[i + 1 :]:
            assert not np.shares_memory(first, second)
    for n in (0, 128, 256):
        one = check(example, angles[n], singularity=True)
        assert one.reachable[0] == result.reachable[n]
        for name, values in result.margins.items():
            assert one.margins[name][0] == values[n]
        np.testing.assert_array_equal(one.limiting_pair[0], result.limiting_pair[n])
