"""Quaternion helpers and slerp: closed forms, equivalences and round trips (seeded)."""

from __future__ import annotations

import numpy as np
import pytest

from hexapod_workspace.core.base.rotations import (
    approach_to_tilt,
    approach_vector,
    axis_angle_to_quaternion,
    matrix_to_quaternion,
    quaternion_angle,
    quaternion_conjugate,
    quaternion_multiply,
    quaternion_slerp,
    quaternion_to_matrix,
    tt_to_matrix,
)
from hexapod_workspace.errors import InputError


def rodrigues(axis: np.ndarray, angle: float) -> np.ndarray:
    """Closed form R = I + sin(a) K + (1 − cos a) K² of a rotation about a unit axis."""
    x, y, z = axis / np.linalg.norm(axis)
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * k @ k


def random_quaternions(rng: np.random.Generator, count: int) -> np.ndarray:
    q = rng.normal(size=(count, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def test_axis_angle_matches_rodrigues(rng):
    for _ in range(50):
        axis = rng.normal(size=3)
        angle = rng.uniform(-np.pi, np.pi)
        np.testing.assert_allclose(
            quaternion_to_matrix(axis_angle_to_quaternion(axis, angle)),
            rodrigues(axis, angle),
            atol=1e-14,
        )


def test_multiply_is_the_matrix_product_and_conjugate_the_inverse(rng):
    left, right = random_quaternions(rng, 200), random_quaternions(rng, 200)
    np.testing.assert_allclose(
        quaternion_to_matrix(quaternion_multiply(left, right)),
        quaternion_to_matrix(left) @ quaternion_to_matrix(right),
        atol=1e-14,
    )
    identity = quaternion_multiply(left, quaternion_conjugate(left))
    np.testing.assert_allclose(identity, np.tile([0.0, 0.0, 0.0, 1.0], (200, 1)), atol=1e-15)


def test_angle_between_rotations_matches_the_trace(rng):
    first, second = random_quaternions(rng, 500), random_quaternions(rng, 500)
    relative = quaternion_to_matrix(first).transpose(0, 2, 1) @ quaternion_to_matrix(second)
    # Closed form: cos(angle) = (trace(R0ᵀR1) − 1) / 2.
    expected = np.arccos(np.clip((np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0, -1, 1))
    np.testing.assert_allclose(quaternion_angle(first, second), expected, atol=1e-7)
    # Sign of either quaternion does not matter (q and −q are the same rotation).
    np.testing.assert_allclose(quaternion_angle(first, -second), expected, atol=1e-7)


def test_angle_is_accurate_near_zero_and_pi():
    for angle in (1e-9, 1e-6, np.pi - 1e-9):
        q = axis_angle_to_quaternion([0.3, -0.2, 0.9], angle)
        assert quaternion_angle([0.0, 0.0, 0.0, 1.0], q) == pytest.approx(angle, rel=1e-9)


def test_slerp_about_z_is_the_fraction_of_the_angle():
    # Closed form: between I and Rz(a), slerp at s is Rz(s·a).
    angle = 1.2
    s = np.linspace(0.0, 1.0, 11)
    q = quaternion_slerp([0, 0, 0, 1.0], axis_angle_to_quaternion([0, 0, 1.0], angle), s)
    for value, quaternion in zip(s, q, strict=True):
        np.testing.assert_allclose(
            quaternion_to_matrix(quaternion),
            rodrigues(np.array([0, 0, 1.0]), value * angle),
            atol=1e-14,
        )


def test_slerp_is_the_geodesic_at_constant_rate(rng):
    # R(s) = R0 · exp(s · log(R0ᵀ R1)): the relative rotation's axis and s times its angle.
    for _ in range(40):
        q0, q1 = random_quaternions(rng, 2)
        r0, r1 = quaternion_to_matrix(q0), quaternion_to_matrix(q1)
        relative = matrix_to_quaternion(r0.T @ r1)  # w >= 0: the shortest rotation
        angle = 2.0 * np.arctan2(np.linalg.norm(relative[:3]), relative[3])
        axis = relative[:3] if angle > 0 else np.array([0, 0, 1.0])
        s = rng.uniform(0.0, 1.0, 5)
        for value in s:
            expected = r0 @ rodrigues(axis, value * angle)
            np.testing.assert_allclose(
                quaternion_to_matrix(quaternion_slerp(q0, q1, value)), expected, atol=1e-12
            )
        # Constant rate: the angle between two interpolated poses is |s − t| times the total.
        qs = quaternion_slerp(q0, q1, s)
        qt = quaternion_slerp(q0, q1, s[::-1])
        np.testing.assert_allclose(quaternion_angle(qs, qt), np.abs(s - s[::-1]) * angle, atol=1e-9)
        # Shortest: q1 and −q1 give the same path.
        np.testing.assert_allclose(
            quaternion_to_matrix(quaternion_slerp(q0, -q1, s)),
            quaternion_to_matrix(qs),
            atol=1e-12,
        )


def test_slerp_ends_and_tiny_angles():
    q0 = axis_angle_to_quaternion([1.0, 0, 0], 0.3)
    q1 = axis_angle_to_quaternion([1.0, 0, 0], 0.3 + 1e-12)
    np.testing.assert_allclose(quaternion_slerp(q0, q1, 0.0), q0, atol=1e-15)
    np.testing.assert_allclose(quaternion_slerp(q0, q1, 1.0), q1, atol=1e-12)
    assert np.all(np.isfinite(quaternion_slerp(q0, q0, np.linspace(0, 1, 5))))


def test_approach_to_tilt_round_trip(rng):
    phi = rng.uniform(-np.pi, np.pi, 500)
    theta = rng.uniform(0.0, np.pi, 500)
    back = approach_to_tilt(approach_vector(phi, theta) * rng.uniform(0.1, 10, (500, 1)))
    np.testing.assert_allclose(back[:, 1], theta, atol=1e-12)
    regular = np.sin(theta) > 1e-6
    np.testing.assert_allclose(np.cos(back[regular, 0] - phi[regular]), 1.0, atol=1e-12)
    # The approach vector is column 2 of the T&T matrix.
    matrices = tt_to_matrix(np.column_stack([phi, theta, np.zeros(500)]))
    np.testing.assert_allclose(approach_vector(*back.T), matrices[:, :, 2], atol=1e-12)
    # Singular directions: phi = 0 by convention.
    np.testing.assert_allclose(approach_to_tilt([[0, 0, 2.0], [0, 0, -1.0]]), [[0, 0], [0, np.pi]])


@pytest.mark.parametrize("axis", [[0.0, 0.0, 0.0], [np.nan, 0.0, 1.0], [np.inf, 0.0, 0.0]])
def test_approach_to_tilt_refuses_bad_axes(axis):
    with pytest.raises(InputError, match="axis"):
        approach_to_tilt(axis)
