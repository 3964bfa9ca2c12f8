"""Moves between poses: the interpolations, their rate bounds, and the motion inputs.


A **move** (segment) from pose (p₀, R₀) to (p₁, R₁) is parametrised by s ∈ [0, 1]: the position
is linear, ``p(s) = p₀ + s·Δp``, and the orientation follows one of two interpolations:

* ``"slerp"`` (what a controller does): the shortest rotation at constant rate, so the angular
  velocity has constant norm ``Ω = angle(R₀, R₁)`` (rad per unit s);
* ``"tilt-torsion"``: linear in the T&T angles, ``(φ, θ, ψ)(s) = (φ₀, θ₀, ψ₀) + s·(Δφ, Δθ, Δψ)``
  with Δφ and Δψ the wrapped (shortest) differences. At θ = 0 the azimuth is free (``R = Rz(ψ)``
  whatever φ), so an end with θ = 0 takes the other end's φ and the tilt moves along a straight
  ray; at θ = π, where ``R = Rz(2φ − ψ)·Ry(π)``, the same choice of φ is compensated in ψ.


The rate bounds (angular rate Ω, joint speed V) are derived in
:mod:`hexapod_workspace.core.path_certificate`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, ResolutionError
from .resolution import MAX_WAYPOINTS, validate_positions
from .rotations import (
    matrix_to_quaternion,
    matrix_to_tt,
    quaternion_angle,
    quaternion_slerp,
    quaternion_to_matrix,
    tt_to_matrix,
    wrap_angle,
)

__all__ = ["INTERPOLATIONS", "ROTATION_TOLERANCE"]

#: Interpolations between waypoints (see the module documentation).
INTERPOLATIONS = ("slerp", "tilt-torsion")
#: Deviation from a rotation matrix accepted in inputs (|RᵀR − I| and |det R − 1|).
ROTATION_TOLERANCE = 1e-6


def _validate_positions(positions: ArrayLike, minimum: int = 2) -> NDArray[np.float64]:
    """Waypoint positions (N, 3), m: :func:`~hexapod_workspace.core.resolution.validate_positions`
    with at least ``minimum`` and at most :data:`MAX_WAYPOINTS` rows."""
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
    ) -> None:
        self.p0 = positions0
        self.dp = positions1 - positions0
        self.translation = np.linalg.norm(self.dp, axis=1)
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
