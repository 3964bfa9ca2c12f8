"""Tilt-and-Torsion conversions: properties, equivalences and round trips (seeded)."""

from __future__ import annotations

import numpy as np
import pytest

from hexapod_workspace.core.base.rotations import (
    approach_vector,
    matrix_to_quaternion,
    matrix_to_tt,
    quaternion_to_matrix,
    quaternion_to_tt,
    tt_to_matrix,
    tt_to_quaternion,
    tt_to_zyz,
    wrap_angle,
    zyz_to_matrix,
    zyz_to_tt,
)
from hexapod_workspace.errors import InputError


def rz(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def ry(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def random_tt(rng: np.random.Generator, count: int) -> np.ndarray:
    return np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, np.pi, count),
            rng.uniform(-np.pi, np.pi, count),
        ]
    )


def test_matrix_is_the_product_of_elementary_rotations(rng):
    # Definition (docs/theory.md, Conventions): R = Rz(phi) Ry(theta) Rz(-phi) Rz(psi).
    for phi, theta, psi in random_tt(rng, 50):
        expected = rz(phi) @ ry(theta) @ rz(-phi) @ rz(psi)
        np.testing.assert_allclose(tt_to_matrix([phi, theta, psi]), expected, atol=1e-14)


def test_matrices_are_orthonormal_with_unit_determinant(rng):
    matrices = tt_to_matrix(random_tt(rng, 1000))
    identity = np.broadcast_to(np.eye(3), matrices.shape)
    np.testing.assert_allclose(matrices @ np.swapaxes(matrices, 1, 2), identity, atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(matrices), 1.0, atol=1e-14)


def test_tt_equals_zyz_with_psi_minus_phi(rng):
    angles = random_tt(rng, 500)
    zyz = angles.copy()
    zyz[:, 2] = angles[:, 2] - angles[:, 0]
    np.testing.assert_allclose(tt_to_matrix(angles), zyz_to_matrix(zyz), atol=1e-14)
    np.testing.assert_allclose(zyz_to_matrix(tt_to_zyz(angles)), zyz_to_matrix(zyz), atol=1e-14)


def test_approach_vector_is_the_third_column(rng):
    angles = random_tt(rng, 500)
    expected = np.column_stack(
        [
            np.cos(angles[:, 0]) * np.sin(angles[:, 1]),
            np.sin(angles[:, 0]) * np.sin(angles[:, 1]),
            np.cos(angles[:, 1]),
        ]
    )
    np.testing.assert_allclose(approach_vector(angles[:, 0], angles[:, 1]), expected, atol=1e-15)
    np.testing.assert_allclose(tt_to_matrix(angles)[:, :, 2], expected, atol=1e-14)


def test_theta_zero_is_a_pure_torsion_whatever_phi(rng):
    for phi in rng.uniform(-np.pi, np.pi, 20):
        psi = rng.uniform(-np.pi, np.pi)
        np.testing.assert_allclose(tt_to_matrix([phi, 0.0, psi]), rz(psi), atol=1e-14)
        np.testing.assert_allclose(approach_vector(phi, 0.0), [0.0, 0.0, 1.0], atol=1e-15)
        phi_back, theta_back, psi_back = matrix_to_tt(rz(psi))
        assert (phi_back, theta_back) == (0.0, 0.0)
        assert psi_back == pytest.approx(psi, abs=1e-14)


def test_theta_pi_is_defined(rng):
    for psi in rng.uniform(-np.pi, np.pi, 20):
        matrix = tt_to_matrix([0.7, np.pi, psi])
        back = matrix_to_tt(matrix)
        assert back[0] == 0.0
        assert back[1] == pytest.approx(np.pi)
        np.testing.assert_allclose(tt_to_matrix(back), matrix, atol=1e-12)


def test_matrix_round_trip_recovers_canonical_angles(rng):
    angles = random_tt(rng, 2000)
    angles[:, 1] = np.clip(angles[:, 1], 1e-6, np.pi - 1e-6)  # away from the singularities
    back = matrix_to_tt(tt_to_matrix(angles))
    np.testing.assert_allclose(back[:, 1], angles[:, 1], atol=1e-9)
    np.testing.assert_allclose(wrap_angle(back[:, 0] - angles[:, 0]), 0.0, atol=1e-8)
    np.testing.assert_allclose(wrap_angle(back[:, 2] - angles[:, 2]), 0.0, atol=1e-8)


def test_matrix_round_trip_near_singularities_keeps_the_rotation(rng):
    angles = random_tt(rng, 200)
    angles[:100, 1] = rng.uniform(0.0, 1e-10, 100)
    angles[100:, 1] = np.pi - rng.uniform(0.0, 1e-10, 100)
    matrices = tt_to_matrix(angles)
    np.testing.assert_allclose(tt_to_matrix(matrix_to_tt(matrices)), matrices, atol=1e-9)


def test_quaternion_closed_form_matches_matrix(rng):
    angles = random_tt(rng, 1000)
    quaternions = tt_to_quaternion(angles)
    np.testing.assert_allclose(np.linalg.norm(quaternions, axis=1), 1.0, atol=1e-15)
    np.testing.assert_allclose(quaternion_to_matrix(quaternions), tt_to_matrix(angles), atol=1e-14)


def test_quaternion_round_trips(rng):
    angles = random_tt(rng, 1000)
    matrices = tt_to_matrix(angles)
    quaternions = matrix_to_quaternion(matrices)
    # q and -q are the same rotation: compare up to sign.
    reference = tt_to_quaternion(angles)
    sign = np.sign(np.sum(quaternions * reference, axis=1))
    np.testing.assert_allclose(quaternions, reference * sign[:, None], atol=1e-12)
    np.testing.assert_allclose(tt_to_matrix(quaternion_to_tt(reference)), matrices, atol=1e-12)
    # An unnormalised quaternion is the same rotation.
    np.testing.assert_allclose(quaternion_to_matrix(3.0 * reference), matrices, atol=1e-13)


def test_zyz_round_trip(rng):
    angles = random_tt(rng, 500)
    np.testing.assert_allclose(
        tt_to_matrix(zyz_to_tt(tt_to_zyz(angles))), tt_to_matrix(angles), atol=1e-12
    )


def test_canonical_ranges(rng):
    back = matrix_to_tt(tt_to_matrix(rng.uniform(-10.0, 10.0, size=(1000, 3))))
    assert np.all((back[:, 0] > -np.pi) & (back[:, 0] <= np.pi))
    assert np.all((back[:, 1] >= 0.0) & (back[:, 1] <= np.pi))
    assert np.all((back[:, 2] > -np.pi) & (back[:, 2] <= np.pi))


def test_batch_shapes_are_preserved(rng):
    angles = rng.uniform(-1.0, 1.0, size=(4, 5, 3))
    assert tt_to_matrix(angles).shape == (4, 5, 3, 3)
    assert tt_to_quaternion(angles).shape == (4, 5, 4)
    assert matrix_to_tt(tt_to_matrix(angles)).shape == (4, 5, 3)


@pytest.mark.parametrize("bad", [np.zeros(2), np.zeros((5, 4))])
def test_wrong_shapes_are_refused(bad):
    with pytest.raises(InputError, match="expected an array of shape"):
        tt_to_matrix(bad)


def test_zero_quaternion_is_refused():
    with pytest.raises(InputError, match="non-zero"):
        quaternion_to_matrix([0.0, 0.0, 0.0, 0.0])


# ---------------------------------------------------------------------------- huge angles
def test_any_finite_angle_denotes_its_principal_value(rng):
    """A huge but finite angle is the orientation of its principal value. numpy's sin
    and cos reduce the argument exactly, so the reference is atan2(sin a, cos a)."""
    huge = np.array([1e20, -3.7e15, 1e300, 2.0**60, -1e200])
    for a in huge:
        principal = np.arctan2(np.sin(a), np.cos(a))
        for angles, reduced in (
            ([a, 0.3, 0.2], [principal, 0.3, 0.2]),
            ([0.4, 0.3, a], [0.4, 0.3, principal]),
            ([a, 0.3, a], [principal, 0.3, principal]),
            ([0.4, a, -0.2], [0.4, principal, -0.2]),
        ):
            np.testing.assert_allclose(tt_to_matrix(angles), tt_to_matrix(reduced), atol=1e-14)
            np.testing.assert_allclose(
                quaternion_to_matrix(tt_to_quaternion(angles)), tt_to_matrix(reduced), atol=1e-14
            )
        assert wrap_angle(a) == pytest.approx(principal, abs=1e-15)
    # Ordinary angles are unchanged by the reduction, bit for bit.
    angles = random_tt(rng, 1000)
    np.testing.assert_array_equal(wrap_angle(angles), np.where(angles == -np.pi, np.pi, angles))


def test_psi_survives_a_huge_phi():
    """Before: psi - phi was formed first, so with |phi| = 1e20 psi was lost entirely."""
    one = tt_to_matrix([1e20, 0.5, 0.0])
    other = tt_to_matrix([1e20, 0.5, 2.0])
    assert not np.allclose(one, other)
    np.testing.assert_allclose(
        tt_to_zyz([1e20, 0.5, 2.0])[2], wrap_angle(2.0 - np.arctan2(np.sin(1e20), np.cos(1e20)))
    )


def test_degrees_reduce_exactly_modulo_360():
    from hexapod_workspace.core.base.rotations import degrees_to_radians

    for typed, principal in ((1e20, -80.0), (-1e20, 80.0), (720.5, 0.5), (-190.0, 170.0)):
        assert float(degrees_to_radians(typed)) == np.radians(principal)
    values = np.array([-180.0, -12.5, 0.0, 33.0, 180.0])
    np.testing.assert_array_equal(degrees_to_radians(values), np.radians(values))
