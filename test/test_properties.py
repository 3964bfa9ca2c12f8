"""Universal properties, stated with Hypothesis: they hold for every input, not for a sample.

* Rotations: Tilt-and-Torsion angles -> matrix -> angles -> matrix is the identity on
  orientations (angles themselves are not unique at θ = 0 and θ = π), and so is the round trip
  through quaternions.
* The machine's symmetry: the packaged example is invariant under a 120° rotation about z
  (legs 1 -> 3 -> 5, 2 -> 4 -> 6). Turning the pose with it, position Rz(α)·p and orientation
  Rz(α)·R·Rz(−α) = R(φ + α, θ, ψ) (rotations about z commute), turns every leg vector by
  Rz(α) and permutes the legs, so the four margins (minima over legs and leg pairs) are equal.
* Monotone boundaries: a stricter limit can only shrink the workspace. With a smaller platform
  joint angle the boundary tilt along every azimuth is no larger (to the tolerance), and the
  ``exact`` projected boundary is never inside the paper's ψ = 0 one.
* The reference's own segment distance (test/reference.py, batched from dot products) equals
  the literal per-pair one on arbitrary segments, degenerate ones included.

No example database and no deadline: the runs are reproducible (``derandomize``) and nothing is
timed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from reference import segment_distance_literal, segment_distance_squared_batch

from hexapod_workspace import Manipulator, check, projected_workspace
from hexapod_workspace.core.base.rotations import (
    matrix_to_quaternion,
    matrix_to_tt,
    quaternion_to_matrix,
    tt_to_matrix,
)
from hexapod_workspace.core.evaluation.loading import example_manipulator, manipulator_from_mapping

PROPERTY = settings(
    max_examples=60,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)

phi = st.floats(-math.pi, math.pi, allow_nan=False)
theta = st.floats(0.0, math.pi, allow_nan=False)
psi = st.floats(-math.pi, math.pi, allow_nan=False)


@PROPERTY
@given(phi, theta, psi)
def test_tilt_torsion_round_trip_is_the_identity_on_orientations(p, t, s):
    matrix = tt_to_matrix([p, t, s])
    again = tt_to_matrix(matrix_to_tt(matrix))
    np.testing.assert_allclose(again, matrix, atol=1e-12)
    angles = matrix_to_tt(matrix)
    assert -math.pi < angles[0] <= math.pi and 0.0 <= angles[1] <= math.pi
    assert -math.pi <= angles[2] <= math.pi


@PROPERTY
@given(phi, theta, psi)
def test_quaternion_round_trip_is_the_identity_on_orientations(p, t, s):
    matrix = tt_to_matrix([p, t, s])
    quaternion = matrix_to_quaternion(matrix)
    assert np.linalg.norm(quaternion) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(quaternion_to_matrix(quaternion), matrix, atol=1e-12)


@pytest.fixture(scope="module")
def example() -> Manipulator:
    return example_manipulator()


def _rz(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@pytest.fixture(scope="module")
def symmetric(example) -> Manipulator:
    """The example with joints 3-6 made exact 120° and 240° turns of joints 1-2 (the packaged
    file gives them to 6 decimals, symmetric to 1e-6 m only)."""
    parameters = example.to_parameters()
    for key in ("geometry.base_joints", "geometry.platform_joints"):
        first = np.reshape(parameters[key], (6, 3))[:2]
        joints = [first @ _rz(k * 2.0 * math.pi / 3.0).T for k in range(3)]
        parameters[key] = np.concatenate(joints).ravel().tolist()
    return manipulator_from_mapping(parameters, warn=False)


@PROPERTY
@given(
    x=st.floats(-0.25, 0.25),
    y=st.floats(-0.25, 0.25),
    z=st.floats(-1.4, -0.9),
    p=phi,
    t=st.floats(0.0, 1.2),
    s=st.floats(-1.5, 1.5),
    turns=st.sampled_from([1, 2]),
)
def test_margins_are_invariant_under_the_machines_120_degree_symmetry(
    symmetric, x, y, z, p, t, s, turns
):
    alpha = turns * 2.0 * math.pi / 3.0
    position = np.array([x, y, z])
    first = check(symmetric, [p, t, s], position)
    turned = check(symmetric, [p + alpha, t, s], _rz(alpha) @ position)
    for name, margin in first.margins.items():
        np.testing.assert_allclose(turned.margins[name], margin, atol=1e-9, err_msg=name)
    assert bool(turned.reachable[0]) == bool(first.reachable[0]) or (
        min(abs(float(m[0])) for m in first.margins.values()) < 1e-9
    )


def test_the_example_is_symmetric_as_the_symmetry_test_assumes(example, symmetric):
    """The premise of the property above: the packaged example is the symmetric machine to the
    6 decimals of its file."""
    for key in ("geometry.base_joints", "geometry.platform_joints"):
        np.testing.assert_allclose(
            symmetric.to_parameters()[key], example.to_parameters()[key], atol=1e-6, err_msg=key
        )


def _with_platform_limit(example: Manipulator, limit: float) -> Manipulator:
    parameters = example.to_parameters()
    parameters["limits.platform_joint_max_angle"] = [limit]
    return manipulator_from_mapping(parameters, warn=False)


@settings(PROPERTY, max_examples=12)
@given(
    tighter=st.floats(0.45, 0.78),
    looser_by=st.floats(0.0, 0.3),
    x=st.floats(-0.2, 0.2),
    z=st.floats(-1.35, -1.0),
)
def test_a_stricter_limit_never_widens_the_boundary(example, tighter, looser_by, x, z):
    tolerance = 1e-6
    position = [x, 0.0, z]
    strict = _with_platform_limit(example, tighter)
    loose = _with_platform_limit(example, tighter + looser_by)
    inner = projected_workspace(strict, position, n_phi=36, tolerance=tolerance)
    outer = projected_workspace(loose, position, n_phi=36, tolerance=tolerance)
    assert np.all(inner.theta <= outer.theta + 2 * tolerance)


@settings(PROPERTY, max_examples=8)
@given(x=st.floats(-0.2, 0.2), y=st.floats(-0.2, 0.2), z=st.floats(-1.3, -0.95))
def test_the_exact_shadow_is_never_inside_the_torsion_zero_boundary(example, x, y, z):
    tolerance = 1e-6
    position = [x, y, z]
    paper = projected_workspace(example, position, n_phi=24, tolerance=tolerance)
    exact = projected_workspace(example, position, n_phi=24, tolerance=tolerance, method="exact")
    assert np.all(exact.theta >= paper.theta - 2 * tolerance)


point = st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3)


@PROPERTY
@given(point, point, point, point, st.sampled_from(["general", "parallel", "point"]))
def test_reference_segment_distances_agree(p0, p1, q0, q1, kind):
    p0, p1, q0, q1 = (np.array(v) for v in (p0, p1, q0, q1))
    if kind == "parallel":
        q1 = q0 + 0.7 * (p1 - p0)
    elif kind == "point":
        p1 = p0.copy()
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    dots = [np.array([v]) for v in (d1 @ d1, d1 @ d2, d1 @ r, d2 @ d2, d2 @ r, r @ r)]
    batched = math.sqrt(float(segment_distance_squared_batch(*dots)[0]))
    assert batched == pytest.approx(segment_distance_literal(p0, p1, q0, q1), abs=1e-7)
