"""Inverse kinematics, exact segment distance and the four constraint margins, batched.

Inverse kinematics of leg i (README, *Conventions*): ``L_i = p + R·b_i − a_i``, length
``ℓ_i = |L_i|``, unit direction ``n_i = L_i / ℓ_i`` (from base joint A_i to platform joint B_i).

Each constraint has a signed margin, ≥ 0 when it holds and < 0 when it is violated:

==================== ================================================ =======
name                 margin                                           unit
==================== ================================================ =======
``leg_length``       min_i min(ℓ_i − ℓmin_i, ℓmax_i − ℓ_i)            m
``base_joint``       min_i (α_i − angle(jA_i, n_i))                    rad
``platform_joint``   min_i (β_i − angle(R·jB_i, −n_i))                 rad
``leg_interference`` min_{i<j} (dist(A_iB_i, A_jB_j) − D)              m
==================== ================================================ =======

``leg_interference`` is +inf when D = 0 (check disabled). Everything is vectorised over poses
and processed in cache-sized chunks; there is no Python loop per pose.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .resolution import validate_position
from .rotations import tt_to_matrix

if TYPE_CHECKING:
    from .manipulator import Manipulator

__all__ = [
    "CONSTRAINT_NAMES",
    "CheckResult",
    "LegKinematics",
    "PoseMargins",
    "check",
    "inverse_kinematics",
    "pose_margins",
    "relative_margins",
    "segment_distance",
]

#: The constraint names, in the order of :attr:`PoseMargins.margins` rows.
CONSTRAINT_NAMES: tuple[str, ...] = (
    "leg_length",
    "base_joint",
    "platform_joint",
    "leg_interference",
)
#: Leg pairs (i < j, 0-based) checked for interference, in a fixed order.
PAIRS_I, PAIRS_J = np.triu_indices(6, k=1)
#: Poses evaluated per chunk: keeps every temporary array in the CPU cache.
CHUNK = 2048
#: Largest batch :func:`check` accepts in one call.
MAX_POSES = 50_000_000


def _positions(position: ArrayLike, count: int) -> NDArray[np.float64]:
    array = np.asarray(position, dtype=np.float64)
    if array.shape == (3,):
        return np.broadcast_to(array, (count, 3))
    if array.shape == (count, 3):
        return array
    msg = f"position: expected shape (3,) or ({count}, 3), got {array.shape}"
    raise InputError(msg)


def _rotation_batch(rotations: ArrayLike) -> NDArray[np.float64]:
    array = np.asarray(rotations, dtype=np.float64)
    if array.ndim != 3 or array.shape[1:] != (3, 3):
        msg = f"rotations: expected shape (N, 3, 3), got {array.shape}"
        raise InputError(msg)
    return array


@dataclass(frozen=True)
class LegKinematics:
    """Inverse kinematics of a batch of poses.

    Attributes
    ----------
    vectors : ndarray, shape (N, 6, 3)
        L_i = A_iB_i in the base frame, m.
    lengths : ndarray, shape (N, 6)
        ℓ_i, m.
    directions : ndarray, shape (N, 6, 3)
        n_i = L_i / ℓ_i (unit; NaN for a zero-length leg).
    platform_points : ndarray, shape (N, 6, 3)
        B_i = p + R·b_i in the base frame, m.
    """

    vectors: NDArray[np.float64]
    lengths: NDArray[np.float64]
    directions: NDArray[np.float64]
    platform_points: NDArray[np.float64]


def inverse_kinematics(
    manipulator: Manipulator, rotations: ArrayLike, position: ArrayLike
) -> LegKinematics:
    """Leg vectors, lengths and directions for N poses.

    Parameters
    ----------
    manipulator : Manipulator
    rotations : array_like, shape (N, 3, 3)
        Platform orientations R (mobile frame in base frame).
    position : array_like, shape (3,) or (N, 3)
        Tool-tip positions p = OC, base frame, m.

    Returns
    -------
    LegKinematics
    """
    rotations = _rotation_batch(rotations)
    positions = _positions(position, rotations.shape[0])
    platform = positions[:, None, :] + np.einsum(
        "nij,kj->nki", rotations, manipulator.platform_joints
    )
    vectors = platform - manipulator.base_joints
    lengths = np.linalg.norm(vectors, axis=2)
    with np.errstate(invalid="ignore", divide="ignore"):
        directions = vectors / lengths[..., None]
    return LegKinematics(vectors, lengths, directions, platform)


def segment_distance(
    p0: ArrayLike, p1: ArrayLike, q0: ArrayLike, q1: ArrayLike
) -> NDArray[np.float64]:
    """Exact minimum distance between 3-D segments [p0, p1] and [q0, q1].

    Handles parallel, collinear and zero-length (point) segments. The closest points follow
    Ericson, *Real-Time Collision Detection* (2005), section 5.1.9: the unconstrained minimiser
    of the segment parameters is clamped to [0, 1], the other parameter is recomputed from it and
    clamped, then the first is recomputed once more; for parallel segments (``a·e − b² ≤
    1e-14·a·e``) any point of the first is a valid start.

    Parameters
    ----------
    p0, p1, q0, q1 : array_like, shape (..., 3), broadcastable
        End points, m (any consistent unit).

    Returns
    -------
    ndarray, shape (...)
        Distances, same unit.
    """
    p0, p1, q0, q1 = (np.asarray(v, dtype=np.float64) for v in (p0, p1, q0, q1))
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = np.einsum("...k,...k->...", d1, d1)
    e = np.einsum("...k,...k->...", d2, d2)
    b = np.einsum("...k,...k->...", d1, d2)
    c = np.einsum("...k,...k->...", d1, r)
    f = np.einsum("...k,...k->...", d2, r)
    rr = np.einsum("...k,...k->...", r, r)
    shape = np.broadcast_shapes(a.shape, b.shape, c.shape, e.shape, f.shape, rr.shape)
    dots = (np.atleast_1d(np.broadcast_to(v, shape)) for v in (a, b, c, e, f, rr))
    return np.sqrt(_segment_distance_squared(*dots)).reshape(shape)


def _unit_interval(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Clamp to [0, 1] in place (NaN stays NaN); returns ``values``."""
    np.maximum(values, 0.0, out=values)
    return np.minimum(values, 1.0, out=values)


def _segment_distance_squared(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    c: NDArray[np.float64],
    e: NDArray[np.float64],
    f: NDArray[np.float64],
    rr: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Squared segment distance from the dot products of d1 = p1 − p0, d2 = q1 − q0, r = p0 − q0.

    ``a = d1·d1, b = d1·d2, c = d1·r, e = d2·d2, f = d2·r, rr = r·r`` (broadcastable arrays).
    The closest points are p0 + s·d1 and q0 + t·d2 with (Ericson 5.1.9)
    ``s = clamp((b·f − c·e) / (a·e − b²))``, ``t = clamp((b·s + f) / e)``,
    ``s = clamp((b·t − c) / a)``; recomputing s from the clamped t is a no-op when t was not
    clamped (first-order optimality), so it is done unconditionally. Parallel and point-like
    segments take a guarded path (only for the entries that need it). The squared distance is
    expanded as ``rr + s²a + t²e + 2sc − 2tf − 2stb``, so no 3-vector is formed.
    """
    # Inputs are arrays of at least one dimension that broadcast together; np.clip's Python
    # wrapper costs more than the arithmetic at the sizes used here.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        denom = a * e - b * b
        s = _unit_interval((b * f - c * e) / denom)
        t = _unit_interval((b * s + f) / e)
        s = _unit_interval((b * t - c) / a)
    special = ~(denom > 1e-14 * a * e)  # parallel, point-like, or NaN from 0/0
    if np.any(special):
        full = np.broadcast_arrays(a, b, c, e, f)
        s[special], t[special] = _degenerate_parameters(*(v[special] for v in full))
    squared = rr + s * (s * a + 2.0 * (c - t * b)) + t * (t * e - 2.0 * f)
    return np.maximum(squared, 0.0)


def _degenerate_parameters(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    c: NDArray[np.float64],
    e: NDArray[np.float64],
    f: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Closest-point parameters (s, t) for parallel or point-like segments (1-D arrays)."""
    tiny = 1e-300
    point1 = a <= tiny
    point2 = e <= tiny
    safe_a = np.where(point1, 1.0, a)
    safe_e = np.where(point2, 1.0, e)
    # Parallel (or first segment a point): start from s = 0, take the best t, then the best s.
    t = np.where(point2, 0.0, np.clip(f / safe_e, 0.0, 1.0))
    s = np.where(point1, 0.0, np.clip((b * t - c) / safe_a, 0.0, 1.0))
    return s, t


@dataclass(frozen=True)
class PoseMargins:
    """Raw margins of a batch of poses (what the workspace searches consume).

    Attributes
    ----------
    margins : ndarray, shape (4, N)
        Signed margins in the order of :data:`CONSTRAINT_NAMES` (m, rad, rad, m).
    limiting_legs : ndarray, shape (4, N), int
        0-based leg with the smallest margin of each constraint (for ``leg_interference`` the
        lower leg of the closest pair; 0 when the check is disabled).
    limiting_pairs : ndarray, shape (N, 2), int
        0-based legs (i < j) of the closest pair.
    """

    margins: NDArray[np.float64]
    limiting_legs: NDArray[np.int64]
    limiting_pairs: NDArray[np.int64]

    @property
    def reachable(self) -> NDArray[np.bool_]:
        """Shape (N,): every margin ≥ 0."""
        return np.all(self.margins >= 0.0, axis=0)


def pose_margins(
    manipulator: Manipulator,
    rotations: ArrayLike,
    position: ArrayLike,
    *,
    interference: bool = True,
) -> PoseMargins:
    """The four margins of N poses given as rotation matrices.

    Parameters
    ----------
    manipulator : Manipulator
    rotations : array_like, shape (N, 3, 3)
        Platform orientations (mobile frame in base frame).
    position : array_like, shape (3,) or (N, 3)
        Tool-tip positions, base frame, m.
    interference : bool
        Evaluate ``leg_interference`` (False leaves it +inf, for callers that only need the
        other three).

    Returns
    -------
    PoseMargins
    """
    rotations = _rotation_batch(rotations)
    count = rotations.shape[0]
    positions = _positions(position, count)
    margins = np.empty((4, count))
    legs = np.zeros((4, count), dtype=np.int64)
    pairs = np.zeros((count, 2), dtype=np.int64)
    model = _chunk_model(manipulator, interference)
    for start in range(0, count, CHUNK):
        stop = min(start + CHUNK, count)
        model.evaluate(
            rotations[start:stop],
            positions[start:stop],
            margins[:, start:stop],
            legs[:, start:stop],
            pairs[start:stop],
        )
    return PoseMargins(margins, legs, pairs)


def _chunk_model(manipulator: Manipulator, interference: bool) -> _ChunkModel:
    """The chunk model of a manipulator, cached on the (immutable) manipulator object."""
    cache = manipulator.__dict__.setdefault("_chunk_models", {})
    model = cache.get(interference)
    if model is None:
        model = cache[interference] = _ChunkModel(manipulator, interference)
    return model


class _ChunkModel:
    """Precomputed constants of a manipulator for the chunked margin evaluation.

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
        # Interference: r_ij = A_i − A_j is constant (the base joints do not move).
        r = manipulator.base_joints[PAIRS_I] - manipulator.base_joints[PAIRS_J]  # (15, 3)
        self.r = r
        self.rr = np.einsum("pk,pk->p", r, r)
        self.alpha_equal = bool(np.all(self.alpha == self.alpha[0]))
        self.beta_equal = bool(np.all(self.beta == self.beta[0]))
        self.relative_scale = _relative_scale(manipulator)

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
            _segment_distance_squared(squared[:, PAIRS_I], b, c, squared[:, PAIRS_J], f, self.rr)
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


@dataclass(frozen=True)
class CheckResult:
    """Reachability of a batch of orientations at one position.

    Attributes
    ----------
    position : ndarray, shape (3,)
        Tool-tip position OC, base frame, m.
    angles : ndarray, shape (N, 3)
        (φ, θ, ψ) of each pose, rad.
    reachable : ndarray, shape (N,), bool
        Every constraint holds.
    margins : dict of str to ndarray, shape (N,)
        Signed margin of each constraint (keys :data:`CONSTRAINT_NAMES`), m or rad.
    limiting_legs : dict of str to ndarray, shape (N,), int
        1-based leg with the smallest margin of each constraint (``leg_interference``: the lower
        leg of the closest pair; 0 when the check is disabled).
    limiting_pair : ndarray, shape (N, 2), int
        1-based legs (i < j) of the closest pair (0, 0 when the check is disabled).
    limiting_constraint : ndarray, shape (N,), int
        Index into :data:`CONSTRAINT_NAMES` of the constraint with the smallest *relative*
        margin: leg length over half the stroke (ℓmax − ℓmin)/2, joint angles over their maximum
        angle, interference over D. For an unreachable pose it is the most violated one.
    limiting_leg : ndarray, shape (N,), int
        1-based leg of the limiting constraint.
    """

    position: NDArray[np.float64]
    angles: NDArray[np.float64]
    reachable: NDArray[np.bool_]
    margins: dict[str, NDArray[np.float64]]
    limiting_legs: dict[str, NDArray[np.int64]]
    limiting_pair: NDArray[np.int64]
    limiting_constraint: NDArray[np.int64]
    limiting_leg: NDArray[np.int64]

    def __len__(self) -> int:
        return int(self.reachable.shape[0])

    @property
    def violated(self) -> list[list[str]]:
        """Per pose, the names of the violated constraints (in :data:`CONSTRAINT_NAMES` order)."""
        negative = np.stack([self.margins[name] < 0.0 for name in CONSTRAINT_NAMES], axis=1)
        masks = (negative.astype(np.int64) @ (1 << np.arange(len(CONSTRAINT_NAMES)))).tolist()
        names = [
            [name for k, name in enumerate(CONSTRAINT_NAMES) if mask >> k & 1] for mask in range(16)
        ]
        return [list(names[mask]) for mask in masks]


def relative_margins(manipulator: Manipulator, margins: NDArray[np.float64]) -> NDArray[np.float64]:
    """Margins divided by their natural scale, to compare constraints of different units.

    Parameters
    ----------
    manipulator : Manipulator
    margins : ndarray, shape (4, N)
        Margins in :data:`CONSTRAINT_NAMES` order.

    Returns
    -------
    ndarray, shape (4, N)
        Leg length over half the mean stroke, joint angles over the mean maximum angle,
        interference over D (+inf when disabled). Dimensionless.
    """
    return margins / _chunk_model(manipulator, True).relative_scale[:, None]


def _relative_scale(manipulator: Manipulator) -> NDArray[np.float64]:
    """Natural scale of each constraint's margin, shape (4,): see :func:`relative_margins`."""
    return np.array(
        [
            float(np.mean(manipulator.leg_length_max - manipulator.leg_length_min)) / 2.0,
            float(np.mean(manipulator.base_joint_max_angle)),
            float(np.mean(manipulator.platform_joint_max_angle)),
            manipulator.leg_diameter if manipulator.leg_diameter > 0.0 else 1.0,
        ]
    )


def check(
    manipulator: Manipulator, angles: ArrayLike, position: ArrayLike | None = None
) -> CheckResult:
    """Check the reachability of N orientations at one position.

    Parameters
    ----------
    manipulator : Manipulator
    angles : array_like, shape (N, 3) or (3,)
        Tilt-and-Torsion angles (φ, θ, ψ) in rad.
    position : array_like, shape (3,), optional
        Tool-tip position OC, base frame, m. Default: ``manipulator.position``.

    Returns
    -------
    CheckResult
        An unreachable pose is a result (``reachable`` False), not an exception.

    Raises
    ------
    InputError
        Wrong shapes, NaN or infinite values, more than :data:`MAX_POSES` poses.
    """
    angles = np.asarray(angles, dtype=np.float64)
    if angles.ndim == 1:
        angles = angles[None, :]
    if angles.ndim != 2 or angles.shape[1] != 3:
        msg = f"angles: expected shape (N, 3) of (phi, theta, psi), got {angles.shape}"
        raise InputError(msg)
    if angles.shape[0] > MAX_POSES:
        msg = f"angles: at most {MAX_POSES} poses per call, got {angles.shape[0]}"
        raise InputError(msg)
    if not np.all(np.isfinite(angles)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(angles), axis=1))[0])
        msg = f"angles: expected finite values, pose {bad} is {angles[bad].tolist()}"
        raise InputError(msg)
    position = validate_position(manipulator, position)  # shape, finite, |p| bounded

    count = angles.shape[0]
    margins = np.empty((4, count))
    legs = np.zeros((4, count), dtype=np.int64)
    pairs = np.zeros((count, 2), dtype=np.int64)
    model = _chunk_model(manipulator, interference=True)
    positions = np.broadcast_to(position, (CHUNK, 3))
    for start in range(0, count, CHUNK):
        stop = min(start + CHUNK, count)
        model.evaluate(
            tt_to_matrix(angles[start:stop]),
            positions[: stop - start],
            margins[:, start:stop],
            legs[:, start:stop],
            pairs[start:stop],
        )
    limiting = relative_margins(manipulator, margins).argmin(axis=0)
    enabled = manipulator.leg_diameter > 0.0
    legs_1 = legs + 1
    if not enabled:
        legs_1[3] = 0
    return CheckResult(
        position=position.copy(),
        angles=angles,
        reachable=np.all(margins >= 0.0, axis=0),
        margins={name: margins[k] for k, name in enumerate(CONSTRAINT_NAMES)},
        limiting_legs={name: legs_1[k] for k, name in enumerate(CONSTRAINT_NAMES)},
        limiting_pair=pairs + 1 if enabled else pairs,
        limiting_constraint=limiting,
        limiting_leg=legs_1[limiting, np.arange(count)],
    )
