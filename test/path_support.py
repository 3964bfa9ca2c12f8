"""Shared inputs of the path tests: large random moves around the example's working volume."""

from __future__ import annotations

import numpy as np


def random_large_moves(count: int = 3000, seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Positions (count, 3), m, ±0.3 m around (0, 0, −1.15), and T&T angles (count, 3), rad,
    tilts to 30°. With seed 3, some moves between two reachable poses leave the workspace for
    both interpolations (found by the certified check and confirmed by dense sampling)."""
    rng = np.random.default_rng(seed)
    positions = np.array([0.0, 0.0, -1.15]) + rng.uniform(-0.3, 0.3, (count, 3))
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, np.radians(30.0), count),
            rng.uniform(-0.6, 0.6, count),
        ]
    )
    return positions, angles


def assert_curve_found_leaving(manipulator, chord, curved, s, points) -> np.ndarray:
    """One move checked straight (``chord``) and along its curve (``curved``, a PathCheck), the
    curve sampled densely at ``s`` (points (n, 3), identity orientation): the straight move stays
    inside, the curve leaves, and the certified check finds where within 1e-3 of s. Returns
    the violation position the check reports (m)."""
    from hexapod_workspace.core.evaluation.check import pose_margins

    dense = pose_margins(manipulator, np.repeat(np.eye(3)[None], len(s), axis=0), points)
    assert dense.reachable[0] and dense.reachable[-1]
    assert chord.segments.ok[0]  # the straight move stays inside
    assert not dense.reachable.all() and not curved.segments.ok[0]  # the curve leaves
    first = s[np.argmax(~dense.reachable)]
    assert abs(curved.segments.first_violation_s[0] - first) < 1e-3
    where = curved.segments.violation_positions[0]
    assert not pose_margins(manipulator, np.eye(3)[None], where).reachable[0]
    return where


def assert_rates_bound_the_finite_differences(manipulator, rates, rotation, s, points) -> None:
    """The certified peak leg rates of one move (``rates``: MoveRates of a 6-UPS model) against
    finite differences of plain-numpy leg lengths |p + R·b − a| along ``points`` (n, 3) sampled
    at ``s``, orientation ``rotation`` (3, 3): never below them, within 2 % of the largest."""
    joints = (rotation @ manipulator.platform_joints.T).T
    lengths = np.linalg.norm(points[:, None, :] + joints - manipulator.base_joints, axis=2)
    dense_peak = (np.abs(np.diff(lengths, axis=0)) / s[1]).max(axis=0)
    assert np.all(rates.peak_bound[0] >= dense_peak * (1 - 1e-6))
    # tight to 1 % of the largest actuator's (the refinement's target, module speeds)
    assert np.max(rates.peak_bound[0]) <= np.max(dense_peak) * 1.02


def assert_curve_bounds(kind, points, s) -> float:
    """One curved move of ``kind`` (``_Arcs`` or ``_Beziers``, move 0) sampled at ``s``, its
    positions ``points`` (n, 3) already checked against the definition: the velocity agrees
    with central differences of them, and |p'|, |p''| stay within the kind's bounds; the length
    bound is at most the polyline's. Returns that polyline's length (m)."""
    velocity = kind.velocities(np.zeros(len(s), dtype=np.int64), s)
    np.testing.assert_allclose(velocity[1:-1], (points[2:] - points[:-2]) / (2 * s[1]), atol=1e-6)
    assert np.linalg.norm(velocity, axis=1).max() <= kind.speed[0] + 1e-15
    length = float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))
    assert kind.length[0] <= length + 1e-12
    accel = np.linalg.norm(np.diff(velocity, axis=0), axis=1) / s[1]
    assert accel.max() <= kind.accel[0] * (1 + 1e-6)
    return length
