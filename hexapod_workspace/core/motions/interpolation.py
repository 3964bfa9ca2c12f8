"""Moves between poses: the interpolations, their rate bounds, and the motion inputs.


A **move** (segment) from pose (p₀, R₀) to (p₁, R₁) is parametrised by s ∈ [0, 1]: the position
is linear, ``p(s) = p₀ + s·Δp``, and the orientation follows one of two interpolations:

* ``"slerp"`` (what a controller does): the shortest rotation at constant rate, so the angular
  velocity has constant norm ``Ω = angle(R₀, R₁)`` (rad per unit s);
* ``"tilt-torsion"``: linear in the T&T angles, ``(φ, θ, ψ)(s) = (φ₀, θ₀, ψ₀) + s·(Δφ, Δθ, Δψ)``
  with Δφ and Δψ the wrapped (shortest) differences. At θ = 0 the azimuth is free (``R = Rz(ψ)``
  whatever φ), so an end with θ = 0 takes the other end's φ and the tilt moves along a straight
  ray; at θ = π, where ``R = Rz(2φ − ψ)·Ry(π)``, the same choice of φ is compensated in ψ.

A move may instead be an **arc** (what CAM writes as ``CIRCLE``): given a centre c, a unit
axis n and a signed angle φ (right-handed about n, |φ| ≤ 2π), write each end relative to c as a
height along n and an in-plane part, ``p_k − c = h_k·n + ρ_k·e_k`` (k = 0, 1, ρ_k > 0); the
end's direction must be e₀ turned by φ about n. The position is

    p(s) = c + (h₀ + s·Δh)·n + (ρ₀ + s·Δρ)·Rot(n, s·φ)·e₀,

a circle when Δh = Δρ = 0, a helix when Δh ≠ 0; a Δρ of the ends' rounding keeps both ends
exact. The orientation follows the interpolation as for a straight move. With
``Rot(n, θ)e₀ = cos θ·e₀ + sin θ·(n × e₀)``,

    p'(s) = Δh·n + Δρ·Rot·e₀ + ρ(s)·φ·(n × Rot·e₀),   |p'|² = Δh² + Δρ² + ρ(s)²φ²,
    p''(s) = 2Δρ·φ·(n × Rot·e₀) − ρ(s)·φ²·Rot·e₀,       |p''| ≤ 2|Δρ||φ| + max(ρ₀, ρ₁)·φ²,

so ``|p'| ≤ √(Δh² + Δρ² + max(ρ₀, ρ₁)²φ²)``: the arc's "translation" in the rate bounds
(the bound of |dp/ds| where a straight move has |Δp|), and its length is at least
``√(Δh² + Δρ² + min(ρ₀, ρ₁)²φ²)`` (a duration at a feed is taken from this lower bound, so
actuator speeds are never under-stated).

A move may also be a **cubic Bézier curve** (what CAM writes as NURBS, cut into its spans):
given two inner control points b₁, b₂ between the ends b₀ = p₀, b₃ = p₁,

    p(s) = (1 − s)³b₀ + 3s(1 − s)²b₁ + 3s²(1 − s)b₂ + s³b₃,
    p'(s) = 3[(1 − s)²d₀ + 2s(1 − s)d₁ + s²d₂],   d_k = b_{k+1} − b_k,
    p''(s) = 6[(1 − s)e₀ + s·e₁],                  e_k = d_{k+1} − d_k.

p' and p'' are Bézier curves of the d_k and e_k, so they lie in their convex hulls, and a norm
is convex: ``|p'| ≤ 3·max_k |d_k|`` and ``|p''| ≤ 6·max(|e₀|, |e₁|)``: the spline's
"translation" in the rate bounds and its curvature term. A polyline through points of a curve
is never longer than the curve, so the length through 33 points of it is a lower bound (a
duration at a feed is taken from it, as for arcs). The orientation follows the interpolation
as for a straight move.

The rate bounds (angular rate Ω, joint speed V) are derived in
:mod:`hexapod_workspace.core.motions.certificate`.
"""

from __future__ import annotations

import math
from typing import Self

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError, ResolutionError
from ..base.resolution import MAX_WAYPOINTS, validate_positions
from ..base.rotations import (
    matrix_to_quaternion,
    matrix_to_tt,
    quaternion_angle,
    quaternion_slerp,
    quaternion_to_matrix,
    tt_to_matrix,
    wrap_angle,
)

__all__ = ["ARC_TOLERANCE", "INTERPOLATIONS", "ROTATION_TOLERANCE"]

#: Points of a Bézier move whose polyline gives the lower bound of its length.
_LENGTH_POINTS = 33

#: Interpolations between waypoints (see the module documentation).
INTERPOLATIONS = ("slerp", "tilt-torsion")
#: Deviation from a rotation matrix accepted in inputs (|RᵀR − I| and |det R − 1|).
ROTATION_TOLERANCE = 1e-6
#: Largest disagreement, rad, between an arc's angle φ and the direction of its end point.
ARC_TOLERANCE = 1e-6


class _CurveKind:
    """One kind of curved move over a batch: arrays with one row per move (``mask``: the moves
    of this kind; ``speed``, ``length``, ``accel``, ``jerk``: the bounds of |p'|, the length,
    |p''| and |p'''| of the module documentation)."""

    mask: NDArray[np.bool_]
    speed: NDArray[np.float64]
    length: NDArray[np.float64]
    accel: NDArray[np.float64]
    jerk: NDArray[np.float64]

    def take(self, moves: NDArray[np.int64]) -> Self:
        """The moves ``moves`` (a new batch of the same kind, in that order)."""
        taken = object.__new__(type(self))
        for name, value in vars(self).items():
            setattr(taken, name, value[moves])
        return taken


class _Arcs(_CurveKind):
    """The arc moves of a batch of K moves (module documentation); straight moves have NaN
    rows and are left to :class:`_Moves`.

    Parameters
    ----------
    positions0, positions1 : ndarray, shape (K, 3)
        The moves' ends, m.
    circles : ndarray, shape (K, 7)
        Per move: centre c (m), axis n (any non-zero length), angle φ (rad, right-handed
        about n); a row of NaN for a straight move. Validated by :func:`_validate_arcs`.
    """

    def __init__(
        self,
        positions0: NDArray[np.float64],
        positions1: NDArray[np.float64],
        circles: NDArray[np.float64],
    ) -> None:
        self.mask = np.isfinite(circles[:, 0])
        rows = np.where(self.mask[:, None], circles, 0.0)
        self.centre = rows[:, :3]
        norm = np.linalg.norm(rows[:, 3:6], axis=1, keepdims=True)
        self.axis = np.where(norm > 0.0, rows[:, 3:6] / np.where(norm > 0.0, norm, 1.0), 0.0)
        self.phi = rows[:, 6]
        d0, d1 = positions0 - self.centre, positions1 - self.centre
        self.h0 = np.einsum("kj,kj->k", d0, self.axis)
        h1 = np.einsum("kj,kj->k", d1, self.axis)
        u0 = d0 - self.h0[:, None] * self.axis
        u1 = d1 - h1[:, None] * self.axis
        self.rho0 = np.linalg.norm(u0, axis=1)
        rho1 = np.linalg.norm(u1, axis=1)
        self.e0 = np.where(
            self.rho0[:, None] > 0.0, u0 / np.where(self.rho0 > 0.0, self.rho0, 1.0)[:, None], 0.0
        )
        self.e1 = np.where(rho1[:, None] > 0.0, u1 / np.where(rho1 > 0.0, rho1, 1.0)[:, None], 0.0)
        self.dh, self.drho = h1 - self.h0, rho1 - self.rho0
        largest, smallest = np.maximum(self.rho0, rho1), np.minimum(self.rho0, rho1)
        base = self.dh**2 + self.drho**2
        #: Bound of |p'(s)| (m per unit s), the lower bound of the length (m), bound of |p''|.
        self.speed = np.sqrt(base + (largest * self.phi) ** 2)
        self.length = np.sqrt(base + (smallest * self.phi) ** 2)
        self.accel = 2.0 * np.abs(self.drho * self.phi) + largest * self.phi**2
        # p''' = −3·Δρ·φ²·T − ρ·φ³·A (T, A the unit radial and tangential directions)
        self.jerk = 3.0 * np.abs(self.drho) * self.phi**2 + largest * np.abs(self.phi) ** 3

    def _turned(
        self, moves: NDArray[np.int64], s: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Rot(n, s·φ)·e₀, n × Rot(n, s·φ)·e₀ (n, 3) and ρ(s) (n,)."""
        angle = s * self.phi[moves]
        e0, n = self.e0[moves], self.axis[moves]
        side = np.cross(n, e0)
        cos, sin = np.cos(angle)[:, None], np.sin(angle)[:, None]
        turned = cos * e0 + sin * side
        return turned, cos * side - sin * e0, self.rho0[moves] + s * self.drho[moves]

    def positions(self, moves: NDArray[np.int64], s: NDArray[np.float64]) -> NDArray[np.float64]:
        """p(s) (n, 3) of arc moves ``moves`` (n,) at ``s`` (n,), m."""
        turned, _, rho = self._turned(moves, s)
        height = self.h0[moves] + s * self.dh[moves]
        result: NDArray[np.float64] = (
            self.centre[moves] + height[:, None] * self.axis[moves] + rho[:, None] * turned
        )
        return result

    def velocities(self, moves: NDArray[np.int64], s: NDArray[np.float64]) -> NDArray[np.float64]:
        """p'(s) (n, 3), m per unit s."""
        turned, along, rho = self._turned(moves, s)
        result: NDArray[np.float64] = (
            self.dh[moves][:, None] * self.axis[moves]
            + self.drho[moves][:, None] * turned
            + (rho * self.phi[moves])[:, None] * along
        )
        return result

    def accelerations(
        self, moves: NDArray[np.int64], s: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """p''(s) = 2·Δρ·φ·A − ρ·φ²·T (n, 3), m per unit s²."""
        turned, along, rho = self._turned(moves, s)
        phi = self.phi[moves]
        bend = (2.0 * self.drho[moves] * phi)[:, None] * along
        result: NDArray[np.float64] = bend - (rho * phi**2)[:, None] * turned
        return result


def _validate_arcs(arcs: ArrayLike | None, positions: NDArray[np.float64]) -> _Arcs | None:
    """``arcs`` (N − 1, 7) of a path of N waypoints as :class:`_Arcs`, or None (no arcs).

    Refused (InputError naming the move): a wrong shape, a row neither all finite nor all NaN,
    a zero axis, an end on the axis (ρ = 0), |φ| > 2π, an end whose direction is not e₀ turned
    by φ (within :data:`ARC_TOLERANCE`).
    """
    if arcs is None:
        return None
    count = positions.shape[0] - 1
    circles = np.asarray(arcs, dtype=np.float64)
    if circles.shape != (count, 7):
        msg = f"arcs: expected shape ({count}, 7) (one row per move), got {circles.shape}"
        raise InputError(msg)
    finite = np.isfinite(circles)
    mixed = np.flatnonzero(~(finite.all(axis=1) | np.isnan(circles).all(axis=1)))
    if mixed.size:
        msg = (
            f"arcs: move {mixed[0] + 1}: expected 7 finite numbers (centre, axis, angle) or "
            "7 NaN (a straight move)"
        )
        raise InputError(msg)
    result = _Arcs(positions[:-1], positions[1:], circles)
    for k in np.flatnonzero(result.mask):
        where = f"arcs: move {k + 1}"
        if not np.linalg.norm(circles[k, 3:6]) > 0.0:
            raise InputError(f"{where}: expected a non-zero axis")
        if not (result.rho0[k] > 0.0 and np.linalg.norm(result.e1[k]) > 0.0):
            raise InputError(f"{where}: expected both ends off the arc's axis")
        if abs(result.phi[k]) > 2.0 * math.pi:
            msg = f"{where}: expected an angle within ±2π, got {result.phi[k]:g} rad"
            raise InputError(msg)
        e0, e1, n = result.e0[k], result.e1[k], result.axis[k]
        reached = math.atan2(float(np.cross(e0, e1) @ n), float(e0 @ e1))
        gap = abs(math.remainder(reached - result.phi[k], 2.0 * math.pi))
        if gap > ARC_TOLERANCE:
            msg = (
                f"{where}: the end is {math.degrees(gap):.3g} deg from where the angle "
                f"{math.degrees(result.phi[k]):.6g} deg turns the start about the axis"
            )
            raise InputError(msg)
    return result if result.mask.any() else None


class _Beziers(_CurveKind):
    """The cubic Bézier moves of a batch of K moves (module documentation); other moves have
    NaN rows.

    Parameters
    ----------
    positions0, positions1 : ndarray, shape (K, 3)
        The moves' ends b₀, b₃, m.
    inner : ndarray, shape (K, 6)
        Per move: the inner control points b₁, b₂ (m); a row of NaN for another move.
    """

    def __init__(
        self,
        positions0: NDArray[np.float64],
        positions1: NDArray[np.float64],
        inner: NDArray[np.float64],
    ) -> None:
        self.mask = np.isfinite(inner[:, 0])
        rows = np.where(self.mask[:, None], inner, 0.0)  # other moves: never used
        self.control = np.stack([positions0, rows[:, :3], rows[:, 3:], positions1], axis=1)
        d = np.diff(self.control, axis=1)  # (K, 3, 3)
        e = np.diff(d, axis=1)  # (K, 2, 3)
        #: Bound of |p'(s)| (m per unit s), the lower bound of the length (m), bound of |p''|.
        self.speed = 3.0 * np.linalg.norm(d, axis=2).max(axis=1)
        self.accel = 6.0 * np.linalg.norm(e, axis=2).max(axis=1)
        self.jerk = 6.0 * np.linalg.norm(e[:, 1] - e[:, 0], axis=1)  # p''' is constant
        grid = np.linspace(0.0, 1.0, _LENGTH_POINTS, dtype=np.float64)
        points = np.einsum("sk,nkj->nsj", _bernstein(grid), self.control)
        self.length = np.linalg.norm(np.diff(points, axis=1), axis=2).sum(axis=1)

    def positions(self, moves: NDArray[np.int64], s: NDArray[np.float64]) -> NDArray[np.float64]:
        """p(s) (n, 3) of Bézier moves ``moves`` (n,) at ``s`` (n,), m."""
        result: NDArray[np.float64] = np.einsum("nk,nkj->nj", _bernstein(s), self.control[moves])
        return result

    def velocities(self, moves: NDArray[np.int64], s: NDArray[np.float64]) -> NDArray[np.float64]:
        """p'(s) (n, 3), m per unit s."""
        d = np.diff(self.control[moves], axis=1)
        weights = np.column_stack([(1.0 - s) ** 2, 2.0 * s * (1.0 - s), s**2]) * 3.0
        result: NDArray[np.float64] = np.einsum("nk,nkj->nj", weights, d)
        return result

    def accelerations(
        self, moves: NDArray[np.int64], s: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """p''(s) = 6·((1 − s)·e₀ + s·e₁) (n, 3), m per unit s² (e: second differences of the
        control points)."""
        e = np.diff(self.control[moves], n=2, axis=1)
        weights = np.column_stack([1.0 - s, s]) * 6.0
        result: NDArray[np.float64] = np.einsum("nk,nkj->nj", weights, e)
        return result


def _bernstein(s: NDArray[np.float64]) -> NDArray[np.float64]:
    """The cubic Bernstein polynomials at ``s`` (n,): shape (n, 4)."""
    t = 1.0 - s
    return np.column_stack([t**3, 3.0 * s * t**2, 3.0 * s**2 * t, s**3])


class _Curves:
    """The curved moves of a batch (arcs, Bézier moves or both), as one: per move its kind's
    position, velocity and bounds; straight moves are left to :class:`_Moves`."""

    def __init__(self, arcs: _Arcs | None, beziers: _Beziers | None) -> None:
        self.kinds: list[_Arcs | _Beziers] = [k for k in (arcs, beziers) if k is not None]
        assert self.kinds
        self.mask: NDArray[np.bool_] = np.logical_or.reduce([k.mask for k in self.kinds])
        #: Per move: bound of |p'(s)|, lower bound of the length, bound of |p''| (its kind's).
        self.speed = self._merged([k.speed for k in self.kinds])
        self.length = self._merged([k.length for k in self.kinds])
        self.accel = self._merged([k.accel for k in self.kinds])
        self.jerk = self._merged([k.jerk for k in self.kinds])

    def _merged(self, values: list[NDArray[np.float64]]) -> NDArray[np.float64]:
        merged = np.zeros(self.mask.shape)
        for kind, value in zip(self.kinds, values, strict=True):
            merged = np.where(kind.mask, value, merged)
        return merged

    def take(self, moves: NDArray[np.int64]) -> _Curves:
        """The moves ``moves`` (a new batch in that order)."""
        taken = object.__new__(_Curves)
        taken.kinds = [kind.take(moves) for kind in self.kinds]
        taken.mask = self.mask[moves]
        taken.speed, taken.length = self.speed[moves], self.length[moves]
        taken.accel, taken.jerk = self.accel[moves], self.jerk[moves]
        return taken

    def _each(
        self, method: str, moves: NDArray[np.int64], s: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        result = np.zeros((moves.shape[0], 3))
        for kind in self.kinds:
            mine = kind.mask[moves]
            if mine.any():
                result[mine] = getattr(kind, method)(moves[mine], s[mine])
        return result

    def positions(self, moves: NDArray[np.int64], s: NDArray[np.float64]) -> NDArray[np.float64]:
        """p(s) (n, 3) of curved moves ``moves`` (n,) at ``s`` (n,), m."""
        return self._each("positions", moves, s)

    def velocities(self, moves: NDArray[np.int64], s: NDArray[np.float64]) -> NDArray[np.float64]:
        """p'(s) (n, 3), m per unit s."""
        return self._each("velocities", moves, s)

    def accelerations(
        self, moves: NDArray[np.int64], s: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """p''(s) (n, 3), m per unit s²."""
        return self._each("accelerations", moves, s)


def _validate_beziers(beziers: ArrayLike | None, positions: NDArray[np.float64]) -> _Beziers | None:
    """``beziers`` (N − 1, 6) of a path of N waypoints as :class:`_Beziers`, or None (none).

    Refused (InputError naming the move): a wrong shape, a row neither all finite nor all NaN,
    a control point beyond 1e6 m.
    """
    if beziers is None:
        return None
    count = positions.shape[0] - 1
    inner = np.asarray(beziers, dtype=np.float64)
    if inner.shape != (count, 6):
        msg = f"beziers: expected shape ({count}, 6) (one row per move), got {inner.shape}"
        raise InputError(msg)
    finite = np.asarray(np.isfinite(inner).all(axis=1), dtype=np.bool_)
    size = np.abs(np.where(finite[:, None], inner, 0.0)).max(axis=1)
    bad = np.flatnonzero(~(finite | np.isnan(inner).all(axis=1)) | (finite & (size > 1e6)))
    if bad.size:
        msg = (
            f"beziers: move {bad[0] + 1}: expected 6 finite numbers within 1e6 m (the inner "
            "control points) or 6 NaN (another move)"
        )
        raise InputError(msg)
    result = _Beziers(positions[:-1], positions[1:], inner)
    return result if result.mask.any() else None


def _validate_curves(
    arcs: ArrayLike | None, beziers: ArrayLike | None, positions: NDArray[np.float64]
) -> _Curves | None:
    """The curved moves of a path: :func:`_validate_arcs` and :func:`_validate_beziers`, a move
    given as both refused; None when every move is straight."""
    circles = _validate_arcs(arcs, positions)
    curves = _validate_beziers(beziers, positions)
    if circles is not None and curves is not None:
        both = np.flatnonzero(circles.mask & curves.mask)
        if both.size:
            msg = f"beziers: move {both[0] + 1} is an arc too (expected one curve per move)"
            raise InputError(msg)
    if circles is None and curves is None:
        return None
    return _Curves(circles, curves)


def _validate_positions(positions: ArrayLike, minimum: int = 2) -> NDArray[np.float64]:
    """Waypoint positions (N, 3), m:
    :func:`~hexapod_workspace.core.base.resolution.validate_positions` with at least ``minimum`` and
    at most :data:`MAX_WAYPOINTS` rows."""
    return validate_positions(positions, minimum, MAX_WAYPOINTS)


def _first_bad_row(ok: NDArray[np.bool_]) -> int | None:
    bad = np.flatnonzero(~ok)
    return int(bad[0]) if bad.size else None


def _orientations(
    count: int,
    angles: ArrayLike | None,
    quaternions: ArrayLike | None,
    rotations: ArrayLike | None,
) -> NDArray[np.float64]:
    """Rotation matrices (N, 3, 3) from exactly one of the three forms, validated."""
    given = [
        name
        for name, v in (("angles", angles), ("quaternions", quaternions), ("rotations", rotations))
        if v is not None
    ]
    if len(given) != 1:
        msg = f"orientations: give exactly one of angles, quaternions, rotations (got {given})"
        raise InputError(msg)
    if angles is not None:
        array = np.asarray(angles, dtype=np.float64)
        if array.shape != (count, 3):
            msg = f"angles: expected shape ({count}, 3) of (phi, theta, psi), got {array.shape}"
            raise InputError(msg)
        row = _first_bad_row(np.all(np.isfinite(array), axis=1))
        if row is not None:
            msg = f"angles: expected finite values, waypoint {row} is {array[row].tolist()}"
            raise InputError(msg)
        # Reduce each angle to its principal value first (exact): combining huge angles
        # (ψ − φ) before reducing would lose every significant digit.
        return tt_to_matrix(wrap_angle(array))
    if quaternions is not None:
        unit = _unit_rows(quaternions, count, 4, "quaternions", "(x, y, z, w)")
        return quaternion_to_matrix(unit)
    array = np.asarray(rotations, dtype=np.float64)
    if array.shape != (count, 3, 3):
        msg = f"rotations: expected shape ({count}, 3, 3), got {array.shape}"
        raise InputError(msg)
    finite = np.all(np.isfinite(array), axis=(1, 2))
    safe = np.where(finite[:, None, None], array, np.eye(3))
    gram = np.abs(np.einsum("nki,nkj->nij", safe, safe) - np.eye(3)).max(axis=(1, 2))
    row = _first_bad_row(
        finite & (gram <= ROTATION_TOLERANCE) & (np.abs(np.linalg.det(safe) - 1.0) <= 1e-5)
    )
    if row is not None:
        msg = f"rotations: waypoint {row} is not a finite rotation matrix (orthonormal, det 1)"
        raise InputError(msg)
    return array


def _unit_rows(
    values: ArrayLike, count: int, width: int, name: str, what: str
) -> NDArray[np.float64]:
    """Rows (count, width) normalised to unit length; zero or non-finite rows refused."""
    array = np.asarray(values, dtype=np.float64)
    if array.shape != (count, width):
        msg = f"{name}: expected shape ({count}, {width}) of {what}, got {array.shape}"
        raise InputError(msg)
    # Scale each row by its largest component first: huge or tiny finite rows keep their
    # direction instead of overflowing or underflowing in the norm.
    with np.errstate(invalid="ignore"):
        scale = np.max(np.abs(array), axis=1)
    row = _first_bad_row(np.all(np.isfinite(array), axis=1) & (scale > 0.0))
    if row is not None:
        msg = f"{name}: expected finite non-zero values, waypoint {row} is {array[row].tolist()}"
        raise InputError(msg)
    scaled = array / scale[:, None]
    unit: NDArray[np.float64] = scaled / np.linalg.norm(scaled, axis=1, keepdims=True)
    return unit


def _validate_interpolation(interpolation: str) -> str:
    if interpolation not in INTERPOLATIONS:
        msg = f"interpolation: expected one of {', '.join(INTERPOLATIONS)}, got {interpolation!r}"
        raise InputError(msg)
    return interpolation


def _validate_tolerance(tolerance: float) -> float:
    value = float(tolerance)
    if not (math.isfinite(value) and 1e-9 <= value <= 0.1):
        msg = f"tolerance: expected 1e-09 to 0.1 rad, got {tolerance!r}"
        raise ResolutionError(msg)
    return value


# ============================================================================ moves
class _Moves:
    """A batch of K moves: interpolated poses and the rate bounds of the module documentation.

    Parameters
    ----------
    positions0, positions1 : ndarray, shape (K, 3)
        m.
    rotations0, rotations1 : ndarray, shape (K, 3, 3)
    interpolation : str
    rho : float
        max_i |b_i|, m.
    quaternions : (ndarray, ndarray), optional
        The ends' unit quaternions (K, 4), when the caller has them.
    arcs : _Curves, optional
        Which moves are curves, arcs or Bézier (their positions follow the curve, their
        ``translation`` is the bound of |dp/ds|); None: every move is straight.
    """

    def __init__(
        self,
        positions0: NDArray[np.float64],
        positions1: NDArray[np.float64],
        rotations0: NDArray[np.float64],
        rotations1: NDArray[np.float64],
        interpolation: str,
        rho: float,
        quaternions: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
        arcs: _Curves | None = None,
    ) -> None:
        self.p0 = positions0
        self.dp = positions1 - positions0
        self.arcs = arcs
        #: |Δp| of a straight move, the bound of |dp/ds| of a curve (module documentation), m.
        self.translation = np.linalg.norm(self.dp, axis=1)
        if arcs is not None:
            self.translation = np.where(arcs.mask, arcs.speed, self.translation)
        self.interpolation = interpolation
        if interpolation == "slerp":
            q0, q1 = (
                quaternions
                if quaternions is not None
                else (matrix_to_quaternion(rotations0), matrix_to_quaternion(rotations1))
            )
            self.q0, self.q1 = q0, q1
            self.omega = quaternion_angle(q0, q1)
        else:
            a0, a1 = matrix_to_tt(rotations0), matrix_to_tt(rotations1)
            a0, a1 = _align_singular(a0, a1), _align_singular(a1, a0)
            self.a0 = a0
            self.da = np.column_stack(
                [
                    wrap_angle(a1[:, 0] - a0[:, 0]),
                    a1[:, 1] - a0[:, 1],
                    wrap_angle(a1[:, 2] - a0[:, 2]),
                ]
            )
            d_alpha, d_beta = self.da[:, 0], self.da[:, 1]
            d_gamma = self.da[:, 2] - self.da[:, 0]
            base = d_alpha**2 + d_beta**2 + d_gamma**2
            cross = 2.0 * d_alpha * d_gamma
            squared = np.maximum(base + cross * np.cos(a0[:, 1]), base + cross * np.cos(a1[:, 1]))
            self.omega = np.sqrt(np.maximum(squared, 0.0))
        self.speed = self.translation + rho * self.omega  # V, m per unit s
        self.rate = self.omega + self.translation / rho  # motion in rad-equivalent per unit s

    def poses(
        self, moves: NDArray[np.int64], s: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Rotations (n, 3, 3) and positions (n, 3) of moves ``moves`` (n,) at parameters s."""
        positions = self.p0[moves] + s[:, None] * self.dp[moves]
        if self.arcs is not None:
            on_arc = self.arcs.mask[moves]
            if on_arc.any():
                positions[on_arc] = self.arcs.positions(moves[on_arc], s[on_arc])
        if self.interpolation == "slerp":
            rotations = quaternion_to_matrix(quaternion_slerp(self.q0[moves], self.q1[moves], s))
        else:
            rotations = tt_to_matrix(self.a0[moves] + s[:, None] * self.da[moves])
        return rotations, positions


def _align_singular(angles: NDArray[np.float64], other: NDArray[np.float64]) -> NDArray[np.float64]:
    """T&T angles with φ taken from ``other`` where θ is 0 or π (same rotation), (K, 3)."""
    theta = angles[:, 1]
    top = np.sin(theta) < 1e-12
    if not np.any(top):
        return angles
    out = angles.copy()
    phi_new = other[:, 0]
    bottom = top & (np.cos(theta) < 0.0)
    # θ = 0: R = Rz(ψ) for every φ. θ = π: R = Rz(2φ − ψ)·Ry(π), so ψ moves by 2Δφ.
    out[top, 0] = phi_new[top]
    out[bottom, 2] = wrap_angle(angles[bottom, 2] + 2.0 * (phi_new[bottom] - angles[bottom, 0]))
    return out
