"""Literal, per-pose reference implementations (slow on purpose).

They follow the definitions of the README, *Conventions*, line by line, one pose at a time, with a
segment distance computed by a different method than :mod:`hexapod_workspace.core.constraints`
(interior critical point plus the four edge cases). Tests use them as independent evidence
for the batched code; the benchmarks use them as the "straightforward per-pose loop" and the
paper's literal projected-workspace procedure.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hexapod_workspace.core.manipulator import Manipulator

__all__ = [
    "paper_projected_workspace",
    "point_segment_distance",
    "pose_margins_literal",
    "segment_distance_literal",
]


def point_segment_distance(point: NDArray, start: NDArray, end: NDArray) -> float:
    """Distance from a point to the segment [start, end] (degenerate segments included)."""
    direction = end - start
    length_squared = float(direction @ direction)
    if length_squared == 0.0:
        return float(np.linalg.norm(point - start))
    t = min(1.0, max(0.0, float((point - start) @ direction) / length_squared))
    return float(np.linalg.norm(point - (start + t * direction)))


def segment_distance_literal(p0: NDArray, p1: NDArray, q0: NDArray, q1: NDArray) -> float:
    """Minimum distance between segments: the interior critical point of |P(s) − Q(t)|² when
    it lies in the open unit square, otherwise the best of the four end-point-to-segment
    distances (the minimum of a convex function over a square is interior or on its edges)."""
    p0, p1, q0, q1 = (np.asarray(v, dtype=float) for v in (p0, p1, q0, q1))
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a, b, e = d1 @ d1, d1 @ d2, d2 @ d2
    c, f = d1 @ r, d2 @ r
    candidates = [
        point_segment_distance(p0, q0, q1),
        point_segment_distance(p1, q0, q1),
        point_segment_distance(q0, p0, p1),
        point_segment_distance(q1, p0, p1),
    ]
    denom = a * e - b * b
    if denom > 1e-12 * max(a * e, 1e-300):
        s = (b * f - c * e) / denom
        t = (a * f - b * c) / denom
        if 0.0 < s < 1.0 and 0.0 < t < 1.0:
            candidates.append(float(np.linalg.norm(r + s * d1 - t * d2)))
    return min(candidates)


def _rotation(phi: float, theta: float, psi: float) -> NDArray:
    def rz(angle: float) -> NDArray:
        c, s = math.cos(angle), math.sin(angle)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    c, s = math.cos(theta), math.sin(theta)
    ry = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return rz(phi) @ ry @ rz(-phi) @ rz(psi)


def _angle(u: NDArray, v: NDArray) -> float:
    return math.atan2(float(np.linalg.norm(np.cross(u, v))), float(u @ v))


def pose_margins_literal(
    manipulator: Manipulator, angles: ArrayLike, position: ArrayLike
) -> dict[str, float]:
    """The four margins of one pose, straight from the definitions.

    Parameters
    ----------
    manipulator : Manipulator
    angles : array_like, shape (3,)
        (φ, θ, ψ), rad.
    position : array_like, shape (3,)
        OC, base frame, m.

    Returns
    -------
    dict
        ``{"leg_length": m, "base_joint": rad, "platform_joint": rad, "leg_interference": m}``.
    """
    phi, theta, psi = (float(v) for v in angles)
    rotation = _rotation(phi, theta, psi)
    p = np.asarray(position, dtype=float)
    legs = [
        p + rotation @ manipulator.platform_joints[i] - manipulator.base_joints[i] for i in range(6)
    ]
    lengths = [float(np.linalg.norm(leg)) for leg in legs]
    leg_length = min(
        min(lengths[i] - manipulator.leg_length_min[i], manipulator.leg_length_max[i] - lengths[i])
        for i in range(6)
    )
    base = min(
        manipulator.base_joint_max_angle[i] - _angle(manipulator.base_joint_axes[i], legs[i])
        for i in range(6)
    )
    platform = min(
        manipulator.platform_joint_max_angle[i]
        - _angle(rotation @ manipulator.platform_joint_axes[i], -legs[i])
        for i in range(6)
    )
    if manipulator.leg_diameter > 0.0:
        ends = [
            (manipulator.base_joints[i], manipulator.base_joints[i] + legs[i]) for i in range(6)
        ]
        interference = min(
            segment_distance_literal(*ends[i], *ends[j]) - manipulator.leg_diameter
            for i in range(6)
            for j in range(i + 1, 6)
        )
    else:
        interference = math.inf
    return {
        "leg_length": leg_length,
        "base_joint": base,
        "platform_joint": platform,
        "leg_interference": interference,
    }


def paper_projected_workspace(
    manipulator: Manipulator,
    position: ArrayLike,
    n_phi: int = 360,
    step: float = math.radians(0.1),
    steps_back: int = 5,
) -> NDArray[np.float64]:
    """The paper's projected-workspace procedure, literally (Bonev & Ryu, torsion ψ = 0).

    For each of ``n_phi`` azimuths φ = k·2π/n_phi, θ is walked in steps of Δθ (0.1° in the
    paper) with one individual pose check per step. The first ray starts at θ = 0; each next ray
    starts ``steps_back`` steps (the paper's m = 5) below the previous ray's boundary, walking
    outward while the pose is reachable, or inward until it is.

    Returns
    -------
    ndarray, shape (n_phi,)
        Per azimuth, the first θ on the Δθ grid where a constraint is violated, rad (π when
        none is).
    """
    p = np.asarray(position, dtype=float)

    def reachable(phi: float, theta: float) -> bool:
        margins = pose_margins_literal(manipulator, (phi, theta, 0.0), p)
        return min(margins.values()) >= 0.0

    limit = math.floor(math.pi / step)
    boundary = np.empty(n_phi)
    index = 0  # grid index of the current θ
    for k in range(n_phi):
        phi = 2.0 * math.pi * k / n_phi
        index = max(0, index - steps_back)
        if reachable(phi, index * step):
            while index < limit and reachable(phi, (index + 1) * step):
                index += 1
            first_violated = index + 1
        else:
            while index > 0 and not reachable(phi, (index - 1) * step):
                index -= 1
            first_violated = index
            index = max(0, index - 1)
        boundary[k] = min(first_violated * step, math.pi)
    return boundary
