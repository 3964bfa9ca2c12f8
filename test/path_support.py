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
