"""Arc moves (CAM's CIRCLE): the certificate and the actuator speeds along the arc, not its chord.

Independent evidence: dense samples of the arc from its definition here (Rodrigues' formula
about the axis, radius and height linear in s), margins pose by pose, actuator rates by finite
differences of plain-numpy leg lengths.
"""

from __future__ import annotations

import math

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
from hexapod_workspace.core.motions.interpolation import _Arcs
from hexapod_workspace.core.motions.speeds import actuator_rates

CENTRE = np.array([0.0, 0.0, -1.15])


def arc_points(p0, p1, centre, axis, phi, s):
    """The arc of the definition, sampled at s (n,): (n, 3)."""
    n = np.asarray(axis, float) / np.linalg.norm(axis)
    d0, d1 = p0 - centre, p1 - centre
    h0, h1 = d0 @ n, d1 @ n
    u0, u1 = d0 - h0 * n, d1 - h1 * n
    r0, r1 = np.linalg.norm(u0), np.linalg.norm(u1)
    e0 = u0 / r0
    k = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    out = []
    for t in s:
        angle = t * phi
        rot = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)
        out.append(centre + (h0 + t * (h1 - h0)) * n + (r0 + t * (r1 - r0)) * (rot @ e0))
    return np.array(out)


def test_the_arc_motion_and_its_bounds():
    p0 = CENTRE + np.array([0.2, 0.0, 0.01])
    p1 = CENTRE + np.array([0.0, -0.2001, 0.05])  # a quarter turn down, a helix, a radius drift
    circle = np.array([[*CENTRE, 0.0, 0.0, 1.0, -math.pi / 2]])
    arcs = _Arcs(p0[None], p1[None], circle)
    s = np.linspace(0.0, 1.0, 20001)
    moves = np.zeros(s.size, dtype=np.int64)
    points = arcs.positions(moves, s)
    np.testing.assert_allclose(
        points, arc_points(p0, p1, CENTRE, [0, 0, 1], -math.pi / 2, s), rtol=0, atol=1e-14
    )
    np.testing.assert_allclose(points[[0, -1]], [p0, p1], atol=1e-15)
    assert_curve_bounds(arcs, points, s)


def _vertical_arc(direction: float):
    """Half a circle of 0.35 m in the x–z plane about the y axis, below (+1) or above (−1): its
    ends and its chord are reachable on the example, its top (bottom) is not."""
    p0, p1 = CENTRE + np.array([-0.35, 0.0, 0.0]), CENTRE + np.array([0.35, 0.0, 0.0])
    # about +y a right-handed half turn takes −x to +x through +z (direction −1: through −z)
    phi = -math.pi * direction
    return np.array([p0, p1]), np.array([[*CENTRE, 0.0, 1.0, 0.0, phi]])


@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_an_arc_is_checked_along_the_arc_not_its_chord(example, direction):
    positions, circle = _vertical_arc(direction)
    angles = np.zeros((2, 3))
    chord = check_path(example, positions, angles=angles)
    arc = check_path(example, positions, angles=angles, arcs=circle)
    s = np.linspace(0.0, 1.0, 20001)
    points = arc_points(positions[0], positions[1], CENTRE, [0, 1, 0], circle[0, 6], s)
    where = assert_curve_found_leaving(example, chord, arc, s, points)
    np.testing.assert_allclose(np.linalg.norm((where - CENTRE)[[0, 2]]), 0.35, atol=1e-12)
    assert arc.arcs is not None


def test_certified_arcs_hide_no_violation(example):
    rng = np.random.default_rng(9)
    count = 60
    starts = CENTRE + rng.uniform(-0.15, 0.15, (count, 3))
    axes = rng.normal(size=(count, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    phis = rng.uniform(-2 * math.pi, 2 * math.pi, count)
    centres = starts + 0.1 * np.cross(axes, rng.normal(size=(count, 3)))
    ends = np.array(
        [
            arc_points(p, p, c, n, phi, [1.0])[0]
            for p, c, n, phi in zip(starts, centres, axes, phis, strict=True)
        ]
    )
    s = np.linspace(0.0, 1.0, 4001)
    missed = checked = 0
    for k in range(count):
        positions = np.array([starts[k], ends[k]])
        circle = np.array([[*centres[k], *axes[k], phis[k]]])
        angles = np.array([[0.3, 0.2, 0.1], [0.3, 0.2, 0.1]])  # constant: no interpolation
        result = check_path(example, positions, angles=angles, arcs=circle)
        if not result.segments.ok[0]:
            continue
        checked += 1
        points = arc_points(starts[k], ends[k], centres[k], axes[k], phis[k], s)
        rotations = np.repeat(tt_to_matrix(angles[0])[None], s.size, axis=0)
        # a violation narrower than the tolerance may hide: none deeper than a micrometre
        margins = pose_margins(example, rotations, points)
        missed += int(np.min(margins.margins[:4]) < -1e-6)
    assert checked >= 10
    assert missed == 0


def test_actuator_rates_along_an_arc_bound_the_finite_differences(example):
    p0 = CENTRE + np.array([0.15, 0.0, 0.0])
    p1 = CENTRE + np.array([-0.15, 0.0, 0.0])
    circle = np.array([[*CENTRE, 0.0, 0.0, 1.0, math.pi]])
    rotations = np.repeat(tt_to_matrix(np.array([0.0, 0.1, 0.0]))[None], 2, axis=0)
    arc = actuator_rates(example, np.array([p0, p1]), rotations, arcs=circle)
    chord = actuator_rates(example, np.array([p0, p1]), rotations)
    s = np.linspace(0.0, 1.0, 200001)
    points = arc_points(p0, p1, CENTRE, [0, 0, 1], math.pi, s)
    assert_rates_bound_the_finite_differences(example, arc, rotations[0], s, points)
    assert arc.translation[0] == pytest.approx(0.15 * math.pi)  # the half circle's length
    assert chord.translation[0] == pytest.approx(0.3)
    assert np.max(arc.peak_bound) > 1.2 * np.max(chord.peak_bound)


def test_a_plan_follows_the_arc(example):
    positions, circle = _vertical_arc(-1.0)
    axes = np.array([[0.0, 0.0, 1.0], [0.0, 0.1, 1.0]])
    plan = plan_torsion(example, positions, axes, arcs=circle)
    assert plan.baseline.arcs is not None
    if plan.path is not None:
        assert plan.path.arcs is not None


@pytest.mark.parametrize(
    ("circle", "message"),
    [
        (np.zeros((2, 7)), r"expected shape \(1, 7\)"),
        (np.array([[0, 0, -1.15, 0, 0, 1, np.nan]]), "move 1: expected 7 finite numbers"),
        (np.array([[0, 0, -1.15, 0, 0, 0, 1.0]]), "move 1: expected a non-zero axis"),
        (np.array([[0, 0, -1.15, 0, 0, 1, 7.0]]), "move 1: expected an angle within"),
        (np.array([[0, 0, -1.15, 0, 0, 1, 1.0]]), "move 1: the end is 62.7 deg from where"),
    ],
)
def test_arc_refusals_name_the_move(example, circle, message):
    positions = np.array([[0.1, 0.0, -1.15], [-0.05, 0.0866, -1.15]])
    with pytest.raises(InputError, match=message):
        check_path(example, positions, angles=np.zeros((2, 3)), arcs=circle)
