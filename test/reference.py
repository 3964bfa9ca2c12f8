"""Literal, per-pose reference implementations (slow on purpose).

They follow the definitions of docs/theory.md, line by line, one pose at a time, with a
segment distance computed by a different method than :mod:`hexapod_workspace.core.evaluation.check`
(interior critical point plus the four edge cases). Tests use them as independent evidence
for the batched code; the benchmarks use them as the "straightforward per-pose loop" and the
paper's literal projected-workspace procedure.

:class:`BatchedMargins` is the numpy batch evaluation the package used before its compiled
kernels: the kernels must reproduce its margins to 1e-12 and its verdicts exactly.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.check import PAIRS_I, PAIRS_J
from hexapod_workspace.core.model.manipulator import Manipulator

__all__ = [
    "BatchedMargins",
    "batched_margins",
    "free_lengths_literal",
    "paper_projected_workspace",
    "point_segment_distance",
    "pose_margins_literal",
    "segment_distance_literal",
    "segment_distance_squared_batch",
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


def segment_distance_squared_batch(
    a: NDArray, b: NDArray, c: NDArray, e: NDArray, f: NDArray, rr: NDArray
) -> NDArray:
    """Squared segment distances from the dot products of d1 = p1 − p0, d2 = q1 − q0,
    r = p0 − q0 (``a = d1·d1, b = d1·d2, c = d1·r, e = d2·d2, f = d2·r, rr = r·r``).

    The same method as :func:`segment_distance_literal`, batched: the squared distance
    ``D(s, t) = rr + s²a + t²e + 2sc − 2tf − 2stb`` is convex on the unit square, so its minimum
    is the interior critical point (when there is one inside) or the minimum over the four
    edges, where D is a parabola in one parameter minimised by clamping its vertex. Unlike the
    package (Ericson's clamp-and-recompute), every candidate is evaluated and the least taken.
    """

    def clamp(numerator: NDArray, denominator: NDArray) -> NDArray:
        with np.errstate(divide="ignore", invalid="ignore"):
            value = np.where(denominator > 0.0, numerator / denominator, 0.0)
        return np.clip(value, 0.0, 1.0)

    def squared(s: NDArray, t: NDArray) -> NDArray:
        return rr + s * s * a + t * t * e + 2.0 * s * c - 2.0 * t * f - 2.0 * s * t * b

    zero, one = np.zeros_like(a), np.ones_like(a)
    candidates = [
        squared(zero, clamp(f, e)),  # s = 0
        squared(one, clamp(f + b, e)),  # s = 1
        squared(clamp(-c, a), zero),  # t = 0
        squared(clamp(b - c, a), one),  # t = 1
    ]
    denom = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s_in = (b * f - c * e) / denom
        t_in = (a * f - b * c) / denom
    inside = (denom > 1e-12 * a * e) & (s_in > 0.0) & (s_in < 1.0) & (t_in > 0.0) & (t_in < 1.0)
    interior = squared(np.where(inside, s_in, 0.0), np.where(inside, t_in, 0.0))
    candidates.append(np.where(inside, interior, np.inf))
    return np.maximum(np.minimum.reduce(candidates), 0.0)


def free_lengths_literal(
    manipulator: Manipulator, legs: list[NDArray], i: int, j: int
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """The segments of legs i and j whose distance is their interference: the whole legs
    A_kB_k, or, for legs that share a joint, what is left once ``paired_joint_length`` (c, m)
    is taken off each leg at every shared end (measured along the leg from the joint centre;
    nothing is left past the other end). From the definition in arc length, not the kernels'
    fractions."""
    c = manipulator.paired_joint_length
    base_shared = bool(
        np.linalg.norm(manipulator.base_joints[i] - manipulator.base_joints[j]) < 1e-6
    )
    platform_shared = bool(
        np.linalg.norm(manipulator.platform_joints[i] - manipulator.platform_joints[j]) < 1e-6
    )
    ends = []
    for k in (i, j):
        length = float(np.linalg.norm(legs[k]))
        unit = legs[k] / length
        near = min(c, length) if base_shared else 0.0
        far = max(length - c, near) if platform_shared else length
        start = manipulator.base_joints[k]
        ends.extend([start + near * unit, start + far * unit])
    return ends[0], ends[1], ends[2], ends[3]


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
    """The margins of one pose, straight from the definitions.

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
        interference = min(
            segment_distance_literal(*free_lengths_literal(manipulator, legs, i, j))
            - manipulator.leg_diameter
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
        "singularity": singularity_literal(manipulator, rotation, legs)
        if manipulator.singularity_min > 0.0
        else math.inf,
        "collision": collision_literal(manipulator, rotation, position),
    }


def collision_literal(manipulator: Manipulator, rotation: NDArray, position: NDArray) -> float:
    """The collision margin by the standalone scene kernel (checked against coal and dense
    surface sampling in test_collision.py); +inf without a scene."""
    scene = manipulator.collision
    if scene is None or scene.pair_count == 0:
        return math.inf
    from hexapod_workspace.core.model.collision import scene_distances

    return float(scene_distances(manipulator, scene, rotation, position).margin[0])


def singularity_literal(manipulator: Manipulator, rotation: NDArray, legs: list[NDArray]) -> float:
    """σ_min(M) − singularity_min, M rows (n_i, (R b_i) × n_i / ρ), by numpy's SVD."""
    rho = max(float(np.linalg.norm(b)) for b in manipulator.platform_joints)
    rows = []
    for i in range(6):
        n = legs[i] / np.linalg.norm(legs[i])
        rows.append(
            np.concatenate([n, np.cross(rotation @ manipulator.platform_joints[i], n) / rho])
        )
    sigma = np.linalg.svd(np.array(rows), compute_uv=False)
    return float(sigma.min()) - manipulator.singularity_min


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


#: Poses per chunk of the numpy batch reference (keeps its temporaries in the CPU cache).
CHUNK = 2048


class BatchedMargins:
    """The numpy batch evaluation of the four margins, as the package computed them before the
    compiled kernels (commit 0b9ef59): the reference the kernels are compared with.

    Arrays are laid out component-first, ``(3, 6)``, so each chunk's temporaries are
    ``(n, 6)`` or ``(n, 15)`` planes of contiguous memory.
    """

    def __init__(self, manipulator: Manipulator, interference: bool) -> None:
        self.b_t = np.ascontiguousarray(manipulator.platform_joints.T)  # (3, 6), mobile frame
        self.a_t = np.ascontiguousarray(manipulator.base_joints.T)  # (3, 6), base frame
        self.ja_t = np.ascontiguousarray(manipulator.base_joint_axes.T)  # (3, 6)
        self.jb_t = np.ascontiguousarray(manipulator.platform_joint_axes.T)  # (3, 6)
        self.b_jb_t = np.ascontiguousarray(np.hstack([self.b_t, self.jb_t]))  # (3, 12)
        self.length_min = manipulator.leg_length_min
        self.length_max = manipulator.leg_length_max
        self.alpha = manipulator.base_joint_max_angle
        self.beta = manipulator.platform_joint_max_angle
        self.diameter = manipulator.leg_diameter
        self.interference = interference and manipulator.leg_diameter > 0.0
        # Whole legs only: legs that share a joint go through pose_margins_literal.
        assert not self.interference or manipulator.paired_joint_length == 0.0
        # Interference: r_ij = A_i − A_j is constant (the base joints do not move).
        r = manipulator.base_joints[PAIRS_I] - manipulator.base_joints[PAIRS_J]  # (15, 3)
        self.r = r
        self.rr = np.einsum("pk,pk->p", r, r)
        self.alpha_equal = bool(np.all(self.alpha == self.alpha[0]))
        self.beta_equal = bool(np.all(self.beta == self.beta[0]))

    def evaluate(
        self,
        rotations: NDArray[np.float64],
        positions: NDArray[np.float64],
        margins_out: NDArray[np.float64],
        legs_out: NDArray[np.int64],
        pairs_out: NDArray[np.int64],
    ) -> None:
        """Margins of one chunk of n poses, written into the ``*_out`` views."""
        n = rotations.shape[0]
        rows = np.arange(n)
        # One batched product gives R·b_i and R·jB_i: (n, 3, 12), component planes of (n, 6).
        rotated = rotations @ self.b_jb_t
        lx = rotated[:, 0, :6] + (positions[:, 0:1] - self.a_t[0])
        ly = rotated[:, 1, :6] + (positions[:, 1:2] - self.a_t[1])
        lz = rotated[:, 2, :6] + (positions[:, 2:3] - self.a_t[2])
        squared = lx * lx + ly * ly + lz * lz
        lengths = np.sqrt(squared)
        inverse = 1.0 / lengths

        per_leg = np.minimum(lengths - self.length_min, self.length_max - lengths)
        leg = per_leg.argmin(axis=1)
        legs_out[0] = leg
        margins_out[0] = per_leg[rows, leg]

        # Base joint: angle between jA_i (base frame) and n_i.
        cos_a = (self.ja_t[0] * lx + self.ja_t[1] * ly + self.ja_t[2] * lz) * inverse
        self._angle_margin(cos_a, self.alpha, self.alpha_equal, rows, margins_out[1], legs_out[1])

        # Platform joint: angle between R·jB_i and −n_i.
        cos_b = (
            rotated[:, 0, 6:] * lx + rotated[:, 1, 6:] * ly + rotated[:, 2, 6:] * lz
        ) * -inverse
        self._angle_margin(cos_b, self.beta, self.beta_equal, rows, margins_out[2], legs_out[2])

        if not self.interference:
            margins_out[3] = np.inf
            legs_out[3] = 0
            pairs_out[:] = 0
            return
        # Segment i: A_i + s·L_i, segment j: A_j + t·L_j, r = A_i − A_j.
        xi, yi, zi = lx[:, PAIRS_I], ly[:, PAIRS_I], lz[:, PAIRS_I]
        xj, yj, zj = lx[:, PAIRS_J], ly[:, PAIRS_J], lz[:, PAIRS_J]
        b = xi * xj + yi * yj + zi * zj
        c = xi * self.r[:, 0] + yi * self.r[:, 1] + zi * self.r[:, 2]
        f = xj * self.r[:, 0] + yj * self.r[:, 1] + zj * self.r[:, 2]
        distance = np.sqrt(
            segment_distance_squared_batch(
                squared[:, PAIRS_I], b, c, squared[:, PAIRS_J], f, self.rr
            )
        )
        pair = distance.argmin(axis=1)
        margins_out[3] = distance[rows, pair] - self.diameter
        legs_out[3] = PAIRS_I[pair]
        pairs_out[:, 0] = PAIRS_I[pair]
        pairs_out[:, 1] = PAIRS_J[pair]

    @staticmethod
    def _angle_margin(
        cosine: NDArray[np.float64],
        limit: NDArray[np.float64],
        equal: bool,
        rows: NDArray[np.int64],
        margin_out: NDArray[np.float64],
        leg_out: NDArray[np.int64],
    ) -> None:
        """min_i (limit_i − arccos(cos_i)) and its leg; one arccos per pose when limits are equal
        (the margin is then decreasing in the angle, so the smallest cosine is the limiting leg).
        """
        if equal:
            leg = cosine.argmin(axis=1)
            smallest = np.minimum(np.maximum(cosine[rows, leg], -1.0), 1.0)
            margin_out[:] = limit[0] - np.arccos(smallest)
        else:
            per_leg = limit - np.arccos(np.minimum(np.maximum(cosine, -1.0), 1.0))
            leg = per_leg.argmin(axis=1)
            margin_out[:] = per_leg[rows, leg]
        leg_out[:] = leg


#: Rows of :func:`batched_margins` (the machines it checks have no singularity limit).
BATCHED_NAMES = ("leg_length", "base_joint", "platform_joint", "leg_interference")


def batched_margins(
    manipulator: Manipulator, angles: ArrayLike, position: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """The numpy batch reference for poses (N, 3) of T&T angles (rad) at one position (3,), m.

    Returns
    -------
    margins : ndarray, shape (4, N)
    legs : ndarray, shape (4, N), int
        0-based limiting leg of each constraint.
    pairs : ndarray, shape (N, 2), int
        0-based closest pair.
    """
    angles = np.asarray(angles, dtype=np.float64)
    count = angles.shape[0]
    model = BatchedMargins(manipulator, interference=True)
    margins = np.empty((4, count))
    legs = np.zeros((4, count), dtype=np.int64)
    pairs = np.zeros((count, 2), dtype=np.int64)
    positions = np.broadcast_to(np.asarray(position, dtype=np.float64), (CHUNK, 3))
    for start in range(0, count, CHUNK):
        stop = min(start + CHUNK, count)
        model.evaluate(
            tt_to_matrix(angles[start:stop]),
            positions[: stop - start],
            margins[:, start:stop],
            legs[:, start:stop],
            pairs[start:stop],
        )
    return margins, legs, pairs
