"""Actuator speeds along moves against finite differences of independently computed
actuated coordinates.

Independent evidence: the dense samples compute the slerp with their own matrix logarithm and
Rodrigues' formula and the actuated coordinates from the formulas (leg lengths
``|p + R·b_i − a_i|`` for 6-UPS; the slide position ``u·d + branch·sqrt((u·d)² − |d|² + L²)``
for 6-PUS; the crank angle ``atan2(b, a) + branch·arccos(c/√(a² + b²))`` for 6-RUS), not from
the kernels; by the mean value theorem every finite difference ``(q(s + h) − q(s))/h`` equals
some dq/ds on the move, so no certified peak may lie below the largest of them, and a tight one
lies just above it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.cell.frames import Tool, tool_model
from hexapod_workspace.core.evaluation.loading import example_manipulator, load_manipulator
from hexapod_workspace.core.model.manipulator import Manipulator
from hexapod_workspace.core.motions.speeds import actuator_rates, feed_limits
from hexapod_workspace.errors import InputError

DENSE = 20_001


def log_axis_angle(rotation: np.ndarray) -> tuple[np.ndarray, float]:
    """Axis and angle of a rotation matrix (angle in [0, π), away from π)."""
    angle = math.acos(max(-1.0, min(1.0, (np.trace(rotation) - 1.0) / 2.0)))
    if angle < 1e-12:
        return np.array([0.0, 0.0, 1.0]), 0.0
    skew = np.array(
        [
            rotation[2, 1] - rotation[1, 2],
            rotation[0, 2] - rotation[2, 0],
            rotation[1, 0] - rotation[0, 1],
        ]
    )
    return skew / (2.0 * math.sin(angle)), angle


def rodrigues(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return (
        np.eye(3)
        + np.sin(angles)[:, None, None] * k
        + (1.0 - np.cos(angles))[:, None, None] * (k @ k)
    )


def coordinates_at(
    model: Manipulator, p0, p1, r0, r1, s: np.ndarray, points: np.ndarray | None = None
) -> np.ndarray:
    """Actuated coordinates (len(s), 6) at ``s`` along the slerp move, from the formulas; the
    tool centre point on the chord, or at ``points`` (len(s), 3) for a curved move."""
    axis, angle = log_axis_angle(r1 @ r0.T)
    rotations = rodrigues(axis, s * angle) @ r0
    positions = p0 + s[:, None] * (p1 - p0) if points is None else points
    points = positions[:, None, :] + np.einsum("nij,kj->nki", rotations, model.platform_joints)
    d = points - model.base_joints[None]
    if model.architecture == "ups":
        return np.linalg.norm(d, axis=2)
    length, branch = model.leg_lengths, model.branch
    if model.architecture == "pus":
        u = model.rail_directions
        ud = np.sum(d * u, axis=2)
        discriminant = ud**2 - np.sum(d * d, axis=2) + length**2
        assert np.all(discriminant > 0.0)  # every leg reaches along the whole move
        return ud + branch * np.sqrt(discriminant)
    w, e, r = model.crank_axes, model.crank_zero_directions, model.crank_lengths
    f = np.cross(w, e)
    a = 2.0 * r * np.sum(d * e, axis=2)
    b = 2.0 * r * np.sum(d * f, axis=2)
    c = np.sum(d * d, axis=2) + r**2 - length**2
    ratio = c / np.hypot(a, b)
    assert np.all(np.abs(ratio) < 1.0)
    return np.unwrap(np.arctan2(b, a) + branch * np.arccos(ratio), axis=0)


def dense_coordinates(model: Manipulator, p0, p1, r0, r1) -> np.ndarray:
    """Actuated coordinates (DENSE, 6) along the slerp move, from the formulas."""
    return coordinates_at(model, p0, p1, r0, r1, np.linspace(0.0, 1.0, DENSE))


def dense_rate_peaks(model: Manipulator, positions, rotations) -> np.ndarray:
    """max over the dense samples of |Δq_i/Δs| per move and leg, (M, 6)."""
    peaks = []
    for k in range(len(positions) - 1):
        q = dense_coordinates(model, positions[k], positions[k + 1], rotations[k], rotations[k + 1])
        peaks.append(np.max(np.abs(np.diff(q, axis=0)), axis=0) * (DENSE - 1))
    return np.array(peaks)


def random_path(seed: int, count: int, centre=(0.0, 0.0, -1.2), scale: float = 1.0):
    rng = np.random.default_rng(seed)
    positions = np.array(centre) + rng.uniform(-0.15, 0.15, (count, 3)) * scale
    angles = np.column_stack(
        [
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(0.0, 0.5, count) * scale,
            rng.uniform(-0.8, 0.8, count) * scale,
        ]
    )
    rotations = tt_to_matrix(angles)
    # a pure rotation and a pure translation among the moves
    positions[4] = positions[3]
    rotations[6] = rotations[5]
    return positions, rotations


CONFIG = Path(__file__).resolve().parents[1] / "config"
#: Each architecture's model and a path of small moves about its home pose (every leg reaches).
CASES = {
    "ups": (None, (0.0, 0.0, -1.2), 1.0),
    "pus": ("example_pus.yaml", (0.0, 0.0, -0.80), 0.3),
    "rus": ("example_rus.yaml", (0.0, 0.0, 0.52), 0.2),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def model(request) -> Manipulator:
    name, _, _ = CASES[request.param]
    base = example_manipulator() if name is None else load_manipulator(CONFIG / name)
    offset, tilt = (0.15, 0.2) if name is None else (0.05, 0.05)
    tool = Tool(np.array([0.01, 0.0, -offset]), np.array([0.0, tilt, 0.0]))
    return tool_model(base, tool)


@pytest.fixture(scope="module")
def path(model):
    _, centre, scale = CASES[model.architecture]
    positions, rotations = random_path(18, 25, centre, scale)
    return positions, rotations, dense_rate_peaks(model, positions, rotations)


def test_peak_bound_is_certified_and_tight(model, path):
    positions, rotations, dense = path
    rates = actuator_rates(model, positions, rotations)
    tolerance = 1e-9 * dense.max()
    assert np.all(rates.peak_bound >= dense - tolerance)  # never below a true rate
    peak_bound, peak_dense = rates.peak_bound.max(axis=1), dense.max(axis=1)
    assert np.all(peak_bound <= 1.015 * peak_dense)  # within 1 % (+ sampling) of the peak
    # samples are exact rates: within the finite differences' own error (K·h/2) of them
    assert np.all(rates.peak_sampled <= dense * (1 + 1e-3))


def test_feed_max_is_safe_and_tight_and_speeds_follow_the_feed(model, path):
    positions, rotations, dense = path
    # limits a fraction of the path's typical speeds at 20 mm/s, so both verdicts occur
    travel = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    scale = float(np.median(dense.max(axis=1)[travel > 0] / travel[travel > 0]))
    limits = np.array([0.05, 0.05, 0.06, 0.05, 0.04, 0.05]) * scale
    rates = actuator_rates(model, positions, rotations, speed_limits=limits)
    feeds = np.full(len(positions) - 1, 0.02)  # 1200 mm/min
    rotary = np.full(len(positions) - 1, math.radians(30.0))  # 30 deg/s
    result = feed_limits(rates, feeds, rotary, limits)
    translation = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    assert result.rotary.tolist() == (translation == 0.0).tolist()
    length = np.where(result.rotary, rates.rotation, translation)
    used = np.where(result.rotary, rotary, feeds)
    np.testing.assert_allclose(result.duration, length / used)
    # the peak speed over the move: certified bound just above the finite differences
    dense_speed = dense.max(axis=1) / result.duration
    assert np.all(result.speed_peak >= dense_speed * (1 - 1e-9))
    # tight in the measure the refinement uses: every actuator weighted by its limit
    weighted = np.max(rates.peak_bound / limits, axis=1)
    assert np.all(weighted <= np.max(dense / limits, axis=1) * 1.015)
    over = np.any(dense / result.duration[:, None] > limits, axis=1)
    assert over.any() and not over.all()  # both verdicts occur
    verdict = np.array([bool(v) for v in result.speed_ok])
    assert np.all(verdict <= ~over)  # never "ok" when a sample exceeds
    # feed_max: no sample exceeds at it, some sample exceeds 3 % above it
    for k in range(len(length)):
        at_max = dense[k] * result.feed_max[k] / length[k]
        assert np.all(at_max <= limits * (1 + 1e-9)), k
        assert np.any(at_max * 1.03 > limits), k


def test_no_move_no_feed_and_no_limits():
    model = example_manipulator()
    positions = np.array([[0.0, 0.0, -1.2]] * 2 + [[0.01, 0.0, -1.2]])
    rotations = np.stack([np.eye(3)] * 3)
    rates = actuator_rates(model, positions, rotations)
    assert np.all(rates.peak_bound[0] == 0.0)
    result = feed_limits(rates, [np.nan, np.nan], [np.nan, np.nan], np.zeros(6))
    assert result.speed_ok.tolist() == [True, None]
    assert np.isnan(result.duration[1]) and np.isnan(result.speed_peak[1])
    assert np.isnan(result.feed_max).all()  # no limit applies
    with pytest.raises(InputError, match="architecture: expected the model's 'ups', got 'rus'"):
        actuator_rates(model, positions, rotations, architecture="rus")
    with pytest.raises(InputError, match="architecture: expected one of ups, pus, rus, got 'x'"):
        actuator_rates(model, positions, rotations, architecture="x")
