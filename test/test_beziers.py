"""Cubic Bézier moves (CAM's NURBS spans): the certificate and the actuator speeds along the
curve, not its chord.

Independent evidence: dense samples of the curve from de Casteljau's construction written here
(repeated linear interpolation, not the Bernstein form the package uses), margins pose by pose,
actuator rates by finite differences of plain-numpy leg lengths.
"""

from __future__ import annotations

import numpy as np
import pytest
from path_support import (
    assert_curve_bounds,
    assert_curve_found_leaving,
    assert_rates_bound_the_finite_differences,
)

from hexapod_workspace import InputError, check_path, plan_torsion
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.check import pose_margins
from hexapod_workspace.core.motions.interpolation import _Beziers
from hexapod_workspace.core.motions.speeds import actuator_rates

CENTRE = np.array([0.0, 0.0, -1.15])


def casteljau(control: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points (n, 3) of the Bézier curve of ``control`` (4, 3) at s (n,), by de Casteljau."""
    points = np.repeat(control[None], len(s), axis=0)
    t = np.asarray(s, float)[:, None, None]
    while points.shape[1] > 1:
        points = (1.0 - t) * points[:, :-1] + t * points[:, 1:]
    return points[:, 0]


def _move(control: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Waypoints (2, 3) and the ``beziers`` row (1, 6) of one Bézier move."""
    return control[[0, 3]], control[1:3].reshape(1, 6)


def test_the_bezier_motion_and_its_bounds():
    control = CENTRE + np.array([[0.2, 0.0, 0.0], [0.1, 0.3, 0.05], [-0.2, -0.1, 0.1], [0, 0, 0]])
    curves = _Beziers(control[None, 0], control[None, 3], control[None, 1:3].reshape(1, 6))
    s = np.linspace(0.0, 1.0, 20001)
    moves = np.zeros(s.size, dtype=np.int64)
    points = curves.positions(moves, s)
    np.testing.assert_allclose(points, casteljau(control, s), rtol=0, atol=1e-14)
    np.testing.assert_allclose(points[[0, -1]], control[[0, 3]], atol=1e-15)
    length = assert_curve_bounds(curves, points, s)
    assert curves.length[0] >= 0.99 * length  # the 33-point polyline is close


def _bulge(direction: float) -> np.ndarray:
    """A move of 0.7 m along x whose curve bulges above (+1) or below (−1) its chord:
    its ends and its chord are reachable on the example, the curve's middle is not."""
    return CENTRE + np.array(
        [[-0.35, 0, 0], [-0.2, 0, 0.6 * direction], [0.2, 0, 0.6 * direction], [0.35, 0, 0]]
    )


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_a_bezier_move_is_checked_along_the_curve_not_its_chord(example, direction):
    control = _bulge(direction)
    positions, inner = _move(control)
    angles = np.zeros((2, 3))
    chord = check_path(example, positions, angles=angles)
    curve = check_path(example, positions, angles=angles, beziers=inner)
    s = np.linspace(0.0, 1.0, 20001)
    where = assert_curve_found_leaving(example, chord, curve, s, casteljau(control, s))
    s_found = curve.segments.first_violation_s[0]
    np.testing.assert_allclose(where, casteljau(control, [s_found])[0], atol=1e-12)
    assert curve.beziers is not None


def test_certified_bezier_moves_hide_no_violation(example):
    rng = np.random.default_rng(11)
    count = 60
    s = np.linspace(0.0, 1.0, 4001)
    missed = checked = 0
    for _ in range(count):
        control = CENTRE + rng.uniform(-0.2, 0.2, (4, 3))
        positions, inner = _move(control)
        angles = np.array([[0.3, 0.2, 0.1], [0.3, 0.2, 0.1]])  # constant: no interpolation
        result = check_path(example, positions, angles=angles, beziers=inner)
        if not result.segments.ok[0]:
            continue
        checked += 1
        rotations = np.repeat(tt_to_matrix(angles[0])[None], s.size, axis=0)
        # a violation narrower than the tolerance may hide: none deeper than a micrometre
        margins = pose_margins(example, rotations, casteljau(control, s))
        missed += int(np.min(margins.margins[:4]) < -1e-6)
    assert checked >= 10
    assert missed == 0


def test_actuator_rates_along_a_bezier_move_bound_the_finite_differences(example):
    control = CENTRE + np.array([[0.15, 0, 0], [0.15, 0.2, 0], [-0.15, 0.2, 0.05], [-0.15, 0, 0]])
    positions, inner = _move(control)
    rotations = np.repeat(tt_to_matrix(np.array([0.0, 0.1, 0.0]))[None], 2, axis=0)
    curve = actuator_rates(example, positions, rotations, beziers=inner)
    chord = actuator_rates(example, positions, rotations)
    s = np.linspace(0.0, 1.0, 200001)
    points = casteljau(control, s)
    assert_rates_bound_the_finite_differences(example, curve, rotations[0], s, points)
    length = float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))
    assert length * 0.99 <= curve.translation[0] <= length  # a lower bound of the length
    assert chord.translation[0] == pytest.approx(0.3)
    assert np.max(curve.peak_bound) > 1.2 * np.max(chord.peak_bound)


def test_a_plan_follows_the_curve(example):
    positions, inner = _move(_bulge(-1.0))
    axes = np.array([[0.0, 0.0, 1.0], [0.0, 0.1, 1.0]])
    plan = plan_torsion(example, positions, axes, beziers=inner)
    assert plan.baseline.beziers is not None
    assert not plan.baseline.segments.ok[0]  # the curve leaves the workspace at ψ = 0
    if plan.path is not None:
        assert plan.path.beziers is not None


@pytest.mark.parametrize(
    ("inner", "arcs", "message"),
    [
        (np.zeros((2, 6)), None, r"beziers: expected shape \(1, 6\)"),
        (np.array([[0, 0, -1.15, 0, 0, np.nan]]), None, "beziers: move 1: expected 6 finite"),
        (np.array([[0, 0, 2e6, 0, 0, -1.15]]), None, "beziers: move 1: expected 6 finite"),
        (
            np.array([[0, 0, -1.15, 0, 0, -1.15]]),
            np.array([[0, 0, -1.15, 0, 0, 1, np.arctan2(0.0866, -0.05)]]),
            "beziers: move 1 is an arc too",
        ),
    ],
)
def test_bezier_refusals_name_the_move(example, inner, arcs, message):
    positions = np.array([[0.1, 0.0, -1.15], [-0.05, 0.0866, -1.15]])
    with pytest.raises(InputError, match=message):
        check_path(example, positions, angles=np.zeros((2, 3)), arcs=arcs, beziers=inner)
