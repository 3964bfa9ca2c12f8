"""Inverse kinematics, exact segment distance and the constraint margins, batched.

Inverse kinematics of leg i (docs/theory.md, *Conventions*): ``L_i = p + R·b_i − a_i``, length
``ℓ_i = |L_i|``, unit direction ``n_i = L_i / ℓ_i`` (from base joint A_i to platform joint B_i);
:func:`inverse_kinematics` is that of the 6-UPS model. For 6-PUS and 6-RUS models the base-side
end moves (:mod:`hexapod_workspace.core.model.architectures`,
:func:`~hexapod_workspace.core.model.legs.leg_endpoints`).

Each constraint has a signed margin, ≥ 0 when it holds and < 0 when it is violated; the
constraints, their units, scales and rate bounds are the rows of
:mod:`hexapod_workspace.core.constraints.table` (``leg_interference`` is +inf when D = 0, check
disabled). The margins are evaluated by the
compiled kernels of :mod:`hexapod_workspace.core.kernels` (one pass per pose, no Python loop);
large batches of :func:`check` are split over the available cores.
"""

from __future__ import annotations

import functools
import itertools
import math
import os
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError
from .. import kernels
from ..base.resolution import MAX_POSITION_NORM, validate_position
from ..constraints.table import (
    COLLISION,
    CONSTRAINT_NAMES,
    N_CONSTRAINTS,
    SINGULARITY,
    applicable,
)

if TYPE_CHECKING:
    from ..model.manipulator import Manipulator

__all__ = [
    "CONSTRAINT_NAMES",
    "CheckResult",
    "LegKinematics",
    "PoseCheck",
    "PoseMargins",
    "check",
    "check_pose",
    "collision_pair_names",
    "home_pose_violations",
    "inverse_kinematics",
    "pose_margins",
    "relative_margins",
    "segment_distance",
    "violated_by_name",
    "violated_names",
]

#: Leg pairs (i < j, 0-based) checked for interference, in a fixed order.
PAIRS_I, PAIRS_J = np.triu_indices(6, k=1)
#: Largest batch :func:`check` accepts in one call.
MAX_POSES = 50_000_000
#: Batches of :func:`check` at least this large are split over the available cores.
PARALLEL_POSES = 32_768


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
    margins : ndarray, shape (C, N)
        Signed margins, rows in the order of :data:`CONSTRAINT_NAMES` (C constraints; units of
        the constraint table).
    limiting_legs : ndarray, shape (C, N), int
        0-based leg with the smallest margin of each constraint (for ``leg_interference`` the
        lower leg of the closest pair; 0 when the check is disabled; for ``collision`` the
        0-based index of the closest pair in :func:`collision_pair_names`, −1 without a scene).
    limiting_pairs : ndarray, shape (N, 2), int
        0-based legs (i < j) of the closest pair.
    """

    margins: NDArray[np.float64]
    limiting_legs: NDArray[np.int64]
    limiting_pairs: NDArray[np.int64]

    @property
    def reachable(self) -> NDArray[np.bool_]:
        """Shape (N,): every margin ≥ 0."""
        reachable: NDArray[np.bool_] = np.all(self.margins >= 0.0, axis=0)
        return reachable


def pose_margins(
    manipulator: Manipulator,
    rotations: ArrayLike,
    position: ArrayLike,
    *,
    interference: bool = True,
    singularity: bool = False,
) -> PoseMargins:
    """The constraint margins of N poses given as rotation matrices.

    Parameters
    ----------
    manipulator : Manipulator
    rotations : array_like, shape (N, 3, 3)
        Platform orientations (mobile frame in base frame).
    position : array_like, shape (3,) or (N, 3)
        Tool-tip positions, base frame, m.
    interference : bool
        Evaluate ``leg_interference`` (False leaves it +inf, for callers that only need the
        others).
    singularity : bool
        Evaluate the singularity margin even when ``limits.singularity_min`` is 0 (a report;
        otherwise it is +inf there).

    Returns
    -------
    PoseMargins
    """
    rotations = np.ascontiguousarray(_rotation_batch(rotations))
    if not rotations.flags.writeable:  # one compiled specialisation: writable arrays
        rotations = rotations.copy()
    count = rotations.shape[0]
    positions = _positions(position, count)
    if positions.strides[0] == 0:  # one position for every pose
        positions = positions[:1]
    positions = np.array(positions, order="C")  # a writable copy (broadcasts are read-only)
    margins = np.empty((N_CONSTRAINTS, count))
    legs = np.empty((N_CONSTRAINTS, count), dtype=np.int64)
    pairs = np.empty((count, 2), dtype=np.int64)
    model = kernels.model_vector(manipulator, report_singularity=singularity)
    variant = kernels.for_model(model)
    variant.margins_rotations(
        model,
        rotations,
        positions,
        interference,
        margins,
        legs,
        pairs,
        variant.collide,
    )
    return PoseMargins(margins, legs, pairs)


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
        Signed margin of each constraint that applies to the model's architecture (keys from
        :data:`CONSTRAINT_NAMES`, in its order: ``leg_length`` for 6-UPS, ``actuator``, ``ik``
        and ``transmission`` for pus/rus), m, rad or 1. NaN where undefined (a leg without an
        inverse-kinematics solution: every margin that needs its actuated coordinate).
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
        1-based leg of the limiting constraint (0 when it is ``collision``: a pair of bodies,
        see :attr:`collision_pair`).
    collision_pairs : tuple of str
        Names of the pairs the model's collision scene checks (``"tool vs leg 4"``, moving
        body first); empty without a scene (then ``collision`` is +inf and not reported).
        ``limiting_legs["collision"]`` is the 1-based index into it of each pose's closest pair.
    """

    position: NDArray[np.float64]
    angles: NDArray[np.float64]
    reachable: NDArray[np.bool_]
    margins: dict[str, NDArray[np.float64]]
    limiting_legs: dict[str, NDArray[np.int64]]
    limiting_pair: NDArray[np.int64]
    limiting_constraint: NDArray[np.int64]
    limiting_leg: NDArray[np.int64]
    collision_pairs: tuple[str, ...] = ()

    def __len__(self) -> int:
        return int(self.reachable.shape[0])

    # The per-pose lists below are computed on first access and kept (the result is frozen
    # and its arrays are the check's answer, not to be written), so that reading them pose by
    # pose, ``result.violated[k]`` in a loop, costs O(1) per pose and not O(N).
    @functools.cached_property
    def collision_pair(self) -> list[str]:
        """Per pose, the closest pair of the collision scene ("" without a scene)."""
        if "collision" not in self.limiting_legs:  # no scene: the row does not apply
            return [""] * len(self)
        names = ("", *self.collision_pairs)
        return [names[k] for k in self.limiting_legs["collision"].tolist()]

    @functools.cached_property
    def violated(self) -> list[list[str]]:
        """Per pose, the names of the violated constraints (in :data:`CONSTRAINT_NAMES` order)."""
        return violated_by_name(self.margins, len(self))


def violated_by_name(margins: Mapping[str, NDArray[np.float64]], count: int) -> list[list[str]]:
    """Names of the negative margins per pose, from margins keyed by constraint name (each
    shape (N,), N = ``count``; rows of the table that are absent are not violated); NaN is
    violated. In :data:`CONSTRAINT_NAMES` order."""
    names = sorted(margins, key=CONSTRAINT_NAMES.index)  # table order
    if not names:
        return [[] for _ in range(count)]
    return violated_names(
        np.stack([margins[name] for name in names]),
        [CONSTRAINT_NAMES.index(name) for name in names],
    )


@functools.cache
def _name_lists(rows: tuple[int, ...]) -> tuple[tuple[str, ...], ...]:
    """For each bit mask over ``rows`` (bit k: row ``rows[k]`` violated), the names of the
    violated constraints in table order (built once per set of rows)."""
    return tuple(
        tuple(CONSTRAINT_NAMES[row] for k, row in enumerate(rows) if mask >> k & 1)
        for mask in range(1 << len(rows))
    )


def violated_names(
    margins: NDArray[np.float64], rows: Sequence[int] | None = None
) -> list[list[str]]:
    """Names of the negative margins per column of ``margins``, shape (C, N); NaN is violated.

    Parameters
    ----------
    margins : ndarray, shape (C, N)
        Margins in :data:`CONSTRAINT_NAMES` order (C = N_CONSTRAINTS), or only the rows
        ``rows`` of that order.
    rows : sequence of int, optional
        Increasing rows of the table that ``margins`` holds (default: all of them).

    Returns
    -------
    list of N lists of str
        In :data:`CONSTRAINT_NAMES` order.
    """
    rows = tuple(range(len(CONSTRAINT_NAMES))) if rows is None else tuple(rows)
    names = _name_lists(rows)
    negative = ~(np.asarray(margins) >= 0.0)
    masks = (negative.T.astype(np.int64) @ (1 << np.arange(len(rows)))).tolist()
    return [list(names[mask]) for mask in masks]


def relative_margins(manipulator: Manipulator, margins: NDArray[np.float64]) -> NDArray[np.float64]:
    """Margins divided by their natural scale, to compare constraints of different units.

    Parameters
    ----------
    manipulator : Manipulator
    margins : ndarray, shape (C, N)
        Margins in :data:`CONSTRAINT_NAMES` order: every row of the table, or its first C rows.

    Returns
    -------
    ndarray, shape (C, N)
        Each margin over the scale of its row of the constraint table (leg length over half
        the mean stroke, joint angles over the mean maximum angle, interference over D).
        Dimensionless.
    """
    rows = min(margins.shape[0], N_CONSTRAINTS)
    scale = kernels.model_vector(manipulator)[kernels.SCALE : kernels.SCALE + rows]
    return margins / scale[:, None]


def check(
    manipulator: Manipulator,
    angles: ArrayLike,
    position: ArrayLike | None = None,
    *,
    singularity: bool = False,
) -> CheckResult:
    """Check the reachability of N orientations at one position.

    Parameters
    ----------
    manipulator : Manipulator
    angles : array_like, shape (N, 3) or (3,)
        Tilt-and-Torsion angles (φ, θ, ψ) in rad.
    position : array_like, shape (3,), optional
        Tool-tip position OC, base frame, m. Default: ``manipulator.position``.
    singularity : bool
        Report the singularity margin even when ``limits.singularity_min`` is 0 (then it is
        σ_min of the homogenised Plücker matrix, never negative, so it changes no verdict).
        Otherwise it is +inf there (not evaluated; ``null`` in the CLI's JSON). With
        ``limits.singularity_min`` > 0 it is always evaluated and enforced.

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
    count = angles.shape[0]
    if count > MAX_POSES:
        msg = f"angles: at most {MAX_POSES} poses per call, got {count}"
        raise InputError(msg)
    angles = np.ascontiguousarray(angles)
    if position is not None:
        candidate = np.asarray(position, dtype=np.float64)
        if candidate.shape != (3,) or not np.all(np.isfinite(candidate)):
            _require_finite_angles(angles)  # bad angles are reported before a bad position
    position = validate_position(position, manipulator.position)  # 3 finite values, |p| bounded
    # One compiled signature per kernel: C-contiguous, writable float64 (a strided view such as
    # T[:3, 3], or a frozen Manipulator's read-only position, is copied).
    position = kernels.vector(position)
    angles = kernels.vector(angles)

    model = kernels.model_vector(manipulator, report_singularity=singularity)
    # Only the rows up to the last one that applies (6-UPS: 5 of the table's rows): the others
    # are +inf for every pose, and allocating them would cost more than the check itself.
    used = int(model[kernels.ROWS_USED])
    margins, ints, pairs, reachable = _output_arrays(used, count)
    outputs = (margins, ints, pairs, reachable)
    workers = _cores() if count >= PARALLEL_POSES else 1
    variant = kernels.for_model(model)

    def check_range(start: int, stop: int) -> int:
        status: int = variant.check_angles(
            model, angles, position, start, stop, *outputs, variant.collide
        )
        return status

    if workers == 1:
        status = check_range(0, count)
    else:
        _require_finite_angles(angles)
        bounds = np.linspace(0, count, workers + 1).astype(int)
        jobs = [
            _pool().submit(check_range, int(start), int(stop))
            for start, stop in itertools.pairwise(bounds)
        ]
        status = min(job.result() for job in jobs)
    if status >= 0:
        _require_finite_angles(angles)
    if status == -2:  # not reached: validate_position refused it above
        msg = f"position: expected 3 finite values (x, y, z) in m, got {position.tolist()}"
        raise InputError(msg)
    legs = ints[:used]
    rows = applicable(manipulator)
    limiting_constraint, limiting_leg = ints[used], ints[used + 1]
    if singularity and manipulator.singularity_min == 0.0:
        # Reported, not enforced: the singularity margin never limits a pose. The limiting
        # constraint is the one with the smallest relative margin among the others.
        full = np.full((N_CONSTRAINTS, count), np.inf)
        full[:used] = margins
        relative = relative_margins(manipulator, full)
        relative[SINGULARITY] = np.inf
        relative = np.where(np.isnan(relative), -np.inf, relative)  # NaN is violated
        limiting_constraint = np.argmin(relative, axis=0).astype(np.int64)
        limiting_leg = legs[limiting_constraint, np.arange(count)]
    limiting_leg = np.where(limiting_constraint == COLLISION, 0, limiting_leg)
    return CheckResult(
        position=position,
        angles=angles,
        reachable=reachable,
        margins={CONSTRAINT_NAMES[k]: margins[k] for k in rows},
        limiting_legs={CONSTRAINT_NAMES[k]: legs[k] for k in rows},
        limiting_pair=pairs,
        limiting_constraint=limiting_constraint,
        limiting_leg=limiting_leg,
        collision_pairs=collision_pair_names(manipulator),
    )


def collision_pair_names(manipulator: Manipulator) -> tuple[str, ...]:
    """Names of the pairs the model's collision scene checks, in the kernels' pair order
    (``"tool vs leg 4"``, ``"leg 2 vs vise"``: moving body first); empty without a scene."""
    scene = manipulator.collision
    if scene is None or scene.pair_count == 0:
        return ()
    from ..model.collision.scene import pair_table

    return pair_table(scene)[1]


def home_pose_violations(manipulator: Manipulator) -> list[str]:
    """Names of the constraints violated at the home pose (``manipulator.home_position``,
    identity orientation); empty when it is reachable. The loaders warn with it."""
    result = check(manipulator, np.zeros((1, 3)), manipulator.home_position)
    return result.violated[0]


class PoseCheck(NamedTuple):
    """Reachability of one pose (:func:`check_pose`): plain Python numbers, no arrays.

    Attributes
    ----------
    reachable : bool
        Every constraint holds.
    margins : tuple of float
        Signed margins in :data:`CONSTRAINT_NAMES` order (units of the constraint table).
    limiting_legs : tuple of int
        1-based leg with the smallest margin of each constraint (``leg_interference``: the
        lower leg of the closest pair; 0 when the check is disabled; ``collision``: the 1-based
        index of the closest pair in :func:`collision_pair_names`, 0 without a scene).
    limiting_pair : tuple of 2 int
        1-based closest pair (0, 0 when the check is disabled).
    limiting_constraint : int
        Index into :data:`CONSTRAINT_NAMES` of the smallest relative margin.
    limiting_leg : int
        1-based leg of the limiting constraint.
    """

    reachable: bool
    margins: tuple[float, ...]
    limiting_legs: tuple[int, ...]
    limiting_pair: tuple[int, int]
    limiting_constraint: int
    limiting_leg: int


#: Builds a PoseCheck from the kernel's tuple of its fields without the keyword handling of
#: ``PoseCheck(...)`` (a NamedTuple is a tuple: what ``PoseCheck._make`` does, minus a call).
_POSE_CHECK = tuple.__new__


def check_pose(
    manipulator: Manipulator,
    phi: float,
    theta: float,
    psi: float,
    position: ArrayLike | None = None,
) -> PoseCheck:
    """Check one orientation: the same verdict and margins as :func:`check`, in microseconds.

    Parameters
    ----------
    manipulator : Manipulator
    phi, theta, psi : float
        Tilt-and-Torsion angles, rad.
    position : array_like, shape (3,), optional
        Tool-tip position OC, base frame, m. Default: ``manipulator.position``.

    Returns
    -------
    PoseCheck

    Raises
    ------
    InputError
        NaN or infinite values, a position that is not 3 values.
    """
    angles = (float(phi), float(theta), float(psi))
    if not all(map(math.isfinite, angles)):
        msg = f"angles: expected finite values, pose 0 is {list(angles)}"
        raise InputError(msg)
    if position is None:
        x, y, z = manipulator.position.tolist()
    else:
        values = np.asarray(position, dtype=np.float64)
        if values.shape != (3,):
            # raises, with the same reason as check()
            validate_position(values, manipulator.position)
        x, y, z = values.tolist()
        if (
            not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z))
            or math.sqrt(x * x + y * y + z * z) > MAX_POSITION_NORM
        ):
            # raises, with the same reason as check()
            validate_position(values, manipulator.position)
    model = kernels.model_vector(manipulator)
    variant = kernels.for_model(model)
    fields = variant.check_one(model, *angles, x, y, z, variant.collide)
    return _POSE_CHECK(PoseCheck, fields)


def _output_arrays(
    used: int, count: int
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64], NDArray[np.bool_]]:
    """The batch check's outputs as views of one allocation: margins (used, N) float64,
    limiting legs + limiting constraint + limiting leg (used + 2, N) int64, pairs (N, 2)
    int64, reachable (N,) bool.

    One block instead of four: glibc serves a large block from its heap once a block that size
    has been freed, and gives the heap's top back to the system when more than twice the
    largest freed block lies free there. With four arrays, the whole of them (23 MB for 2·10⁵
    6-UPS poses) exceeded twice the largest (11 MB), so every call returned the memory and
    page-faulted it in again, about 17 ns per pose on a 100 ns check; one block stays in the
    heap (``benchmarks/model.py``). The arrays live as long as any one of them is referenced.
    """
    floats = used * count
    words = (used + 2) * count + 2 * count
    block = np.empty(8 * (floats + words) + count, dtype=np.uint8)
    margins = block[: 8 * floats].view(np.float64).reshape(used, count)
    ints = block[8 * floats : 8 * (floats + (used + 2) * count)].view(np.int64)
    pairs = block[8 * (floats + (used + 2) * count) : 8 * (floats + words)].view(np.int64)
    reachable = block[8 * (floats + words) :].view(np.bool_)
    return margins, ints.reshape(used + 2, count), pairs.reshape(count, 2), reachable


def _require_finite_angles(angles: NDArray[np.float64]) -> None:
    """Raise InputError naming the first pose (N, 3) with a non-finite angle, if any."""
    finite = np.isfinite(angles).all(axis=1)
    if not finite.all():
        bad = int(np.flatnonzero(~finite)[0])
        msg = f"angles: expected finite values, pose {bad} is {angles[bad].tolist()}"
        raise InputError(msg)


_POOL: ThreadPoolExecutor | None = None


def _cores() -> int:
    """CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _pool() -> ThreadPoolExecutor:
    """Threads for large batches (the kernels release the GIL), created on first use."""
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=os.cpu_count(), thread_name_prefix="hexapod-check")
    return _POOL
