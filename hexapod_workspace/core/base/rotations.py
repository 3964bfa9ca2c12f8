"""Tilt-and-Torsion angles and the other orientation representations, batch-first.

Conventions (docs/theory.md): the Tilt-and-Torsion (T&T) angles (φ, θ, ψ) of Bonev & Ryu
define ``R(φ, θ, ψ) = Rz(φ) · Ry(θ) · Rz(−φ) · Rz(ψ)``, the orientation of the mobile frame
relative to the base frame, with φ ∈ (−π, π] (azimuth of the tilt axis), θ ∈ [0, π] (tilt) and
ψ ∈ [−π, π] (torsion). The same rotation in ZYZ Euler angles is (φ, θ, ψ − φ). The *approach
vector* (the tool axis z' in the base frame) is ``(cos φ sin θ, sin φ sin θ, cos θ)``.

At θ = 0 the T&T representation is singular: φ and ψ merge and ``R = Rz(ψ)``. Every function
here is defined there: the forward maps need no special case and the inverse maps return φ = 0
and the whole rotation in ψ. At θ = π (tool pointing straight down) the approach vector has no
azimuth either; the inverse maps return φ = 0 there too.

Any finite angle denotes one orientation, however large: every function here takes the sine and
cosine of each input angle (numpy reduces the argument exactly) before angles are combined, so
``φ = 1e20`` rad is the orientation of ``1e20 mod 2π``, never a rounding of ``ψ − φ``.

Quaternions are ``(x, y, z, w)``, scalar last, as in ROS ``geometry_msgs/Quaternion``.
All functions take arrays of any leading shape ``(...)`` and broadcast like numpy.

The controllers' conventions (:data:`ANGLE_CONVENTIONS`, docs/configuration.md "Poses in the
controllers' conventions"), each read into T&T by :func:`convention_to_tt`:

* ``xyz-moving`` (U, V, W), PI's hexapods: ``R = Rx(U) · Ry(V) · Rz(W)``, rotations about the
  axes moving with the platform, U first, then V, then W;
* ``xyz-fixed`` (A, B, C), LinuxCNC ``genhexkins``: ``R = Rz(C) · Ry(B) · Rx(A)``, roll, pitch
  and yaw about the fixed axes, A first;
* ``symetrie`` (Rx, Ry, Rz), Symétrie's hexapods: their "Euler type II" convention, rotations
  about the fixed axes X0, then Y0, then Z0, ``R = Rz(Rz) · Ry(Ry) · Rx(Rx)`` (the matrix of
  ``xyz-fixed``, under Symétrie's names);
* ``quaternion`` (qx, qy, qz, qw), as ROS.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError

__all__ = [
    "ANGLE_CONVENTIONS",
    "AngleConvention",
    "approach_to_tilt",
    "approach_vector",
    "axis_angle_to_quaternion",
    "convention_to_matrix",
    "convention_to_tt",
    "degrees_to_radians",
    "matrix_to_quaternion",
    "matrix_to_tt",
    "quaternion_angle",
    "quaternion_conjugate",
    "quaternion_multiply",
    "quaternion_slerp",
    "quaternion_to_matrix",
    "quaternion_to_tt",
    "tt_to_matrix",
    "tt_to_quaternion",
    "tt_to_zyz",
    "wrap_angle",
    "xyz_fixed_to_matrix",
    "xyz_moving_to_matrix",
    "zyz_to_matrix",
    "zyz_to_tt",
]

#: Below this value of sin θ the inverse maps treat the rotation as lying on a singularity.
SINGULAR_SIN = 1e-12


def _last_axis(values: ArrayLike, size: int, name: str) -> NDArray[np.float64]:
    array = np.asarray(values, dtype=np.float64)
    if array.ndim == 0 or array.shape[-1] != size:
        msg = f"{name}: expected an array of shape (..., {size}), got shape {array.shape}"
        raise InputError(msg)
    return array


def _matrices(matrix: ArrayLike) -> NDArray[np.float64]:
    array = np.asarray(matrix, dtype=np.float64)
    if array.ndim < 2 or array.shape[-2:] != (3, 3):
        msg = f"matrix: expected an array of shape (..., 3, 3), got shape {array.shape}"
        raise InputError(msg)
    return array


def wrap_angle(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles into (−π, π] (their principal values).

    Angles already in [−π, π] are returned unchanged (bit for bit, except −π -> π); larger ones
    are reduced through their sine and cosine, which numpy evaluates with exact argument
    reduction, so even ``1e300`` rad gives the principal value of the angle it denotes.

    Parameters
    ----------
    angle : array_like, shape (...)
        Angles in rad, any finite values.

    Returns
    -------
    ndarray, shape (...)
        The same angles in (−π, π], rad.
    """
    angle = np.asarray(angle, dtype=np.float64)
    inside = np.abs(angle) <= np.pi
    if np.all(inside):
        wrapped = angle
    else:
        wrapped = np.where(inside, angle, np.arctan2(np.sin(angle), np.cos(angle)))
    return np.where(wrapped == -np.pi, np.pi, wrapped)


def degrees_to_radians(degrees: ArrayLike) -> NDArray[np.float64]:
    """Angles in degrees to their principal values in rad, exactly for any finite value.

    ``np.radians(1e20)`` is 1.745e18 rad with a rounding error of hundreds of radians: it no
    longer denotes the orientation the user typed. Reducing modulo 360 first is exact in
    floating point (``fmod`` by an exactly representable 360), so the result is the principal
    value of the typed angle to the last bit of the conversion.

    Parameters
    ----------
    degrees : array_like, shape (...)
        Angles in degrees, any finite values.

    Returns
    -------
    ndarray, shape (...)
        Angles in rad; values in [−180°, 180°] convert unchanged, others land in (−π, π].
    """
    degrees = np.asarray(degrees, dtype=np.float64)
    reduced = np.fmod(degrees, 360.0)  # exact
    reduced = np.where(reduced > 180.0, reduced - 360.0, reduced)  # exact (same binade or below)
    reduced = np.where(reduced < -180.0, reduced + 360.0, reduced)
    radians: NDArray[np.float64] = np.radians(np.where(np.abs(degrees) <= 180.0, degrees, reduced))
    return radians


def zyz_to_matrix(zyz: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices from ZYZ Euler angles ``Rz(α) · Ry(β) · Rz(γ)``.

    Parameters
    ----------
    zyz : array_like, shape (..., 3)
        (α, β, γ) in rad.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Rotation matrices (mobile frame expressed in the base frame).
    """
    zyz = _last_axis(zyz, 3, "zyz")
    return _zyz_matrix(zyz[..., 0], zyz[..., 1], zyz[..., 2])


def _zyz_matrix(
    alpha: NDArray[np.float64], beta: NDArray[np.float64], gamma: NDArray[np.float64]
) -> NDArray[np.float64]:
    return _zyz_matrix_from_trig(
        (np.cos(alpha), np.sin(alpha)), (np.cos(beta), np.sin(beta)), (np.cos(gamma), np.sin(gamma))
    )


def _zyz_matrix_from_trig(
    alpha: tuple[NDArray[np.float64], NDArray[np.float64]],
    beta: tuple[NDArray[np.float64], NDArray[np.float64]],
    gamma: tuple[NDArray[np.float64], NDArray[np.float64]],
) -> NDArray[np.float64]:
    """Rz(α)·Ry(β)·Rz(γ) from the (cos, sin) pairs of its three angles; shape (..., 3, 3)."""
    (ca, sa), (cb, sb), (cg, sg) = alpha, beta, gamma
    matrix = np.empty((*np.shape(ca), 3, 3))
    matrix[..., 0, 0] = ca * cb * cg - sa * sg
    matrix[..., 0, 1] = -ca * cb * sg - sa * cg
    matrix[..., 0, 2] = ca * sb
    matrix[..., 1, 0] = sa * cb * cg + ca * sg
    matrix[..., 1, 1] = -sa * cb * sg + ca * cg
    matrix[..., 1, 2] = sa * sb
    matrix[..., 2, 0] = -sb * cg
    matrix[..., 2, 1] = sb * sg
    matrix[..., 2, 2] = cb
    return matrix


def tt_to_zyz(angles: ArrayLike) -> NDArray[np.float64]:
    """Convert T&T angles (φ, θ, ψ) to ZYZ Euler angles (φ, θ, ψ − φ).

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        (φ, θ, ψ) in rad.

    Returns
    -------
    ndarray, shape (..., 3)
        (α, β, γ) in rad, γ wrapped into (−π, π].
    """
    angles = _last_axis(angles, 3, "angles")
    zyz = angles.copy()
    zyz[..., 2] = wrap_angle(wrap_angle(angles[..., 2]) - wrap_angle(angles[..., 0]))
    return zyz


def zyz_to_tt(zyz: ArrayLike) -> NDArray[np.float64]:
    """Convert ZYZ Euler angles (α, β, γ) to T&T angles in their canonical ranges.

    Parameters
    ----------
    zyz : array_like, shape (..., 3)
        (α, β, γ) in rad, any values.

    Returns
    -------
    ndarray, shape (..., 3)
        (φ, θ, ψ) in rad with φ ∈ (−π, π], θ ∈ [0, π], ψ ∈ (−π, π]; φ = 0 on the
        singularities θ = 0 and θ = π.
    """
    return matrix_to_tt(zyz_to_matrix(zyz))


def tt_to_matrix(angles: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices from T&T angles, ``Rz(φ) · Ry(θ) · Rz(ψ − φ)``.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        (φ, θ, ψ) in rad. Any values are accepted (θ outside [0, π] is the same rotation as
        its canonical representative).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Rotation matrices of the mobile frame in the base frame; column 2 is the approach
        vector.
    """
    angles = _last_axis(angles, 3, "angles")
    phi, theta, psi = angles[..., 0], angles[..., 1], angles[..., 2]
    # ZYZ (φ, θ, ψ − φ) with cos/sin of ψ − φ from those of φ and ψ: no angle is combined
    # before its sine and cosine are taken (exact for any finite φ, ψ).
    cp, sp = np.cos(phi), np.sin(phi)
    cs, ss = np.cos(psi), np.sin(psi)
    cb, sb = np.cos(theta), np.sin(theta)
    cg = cs * cp + ss * sp
    sg = ss * cp - cs * sp
    return _zyz_matrix_from_trig((cp, sp), (cb, sb), (cg, sg))


def matrix_to_tt(matrix: ArrayLike) -> NDArray[np.float64]:
    """T&T angles of rotation matrices.

    Parameters
    ----------
    matrix : array_like, shape (..., 3, 3)
        Rotation matrices (assumed orthonormal with determinant 1).

    Returns
    -------
    ndarray, shape (..., 3)
        (φ, θ, ψ) in rad, φ ∈ (−π, π], θ ∈ [0, π], ψ ∈ (−π, π]. On the singularities
        (sin θ < 1e-12) φ = 0 and ψ carries the whole rotation about the tool axis.
    """
    matrix = _matrices(matrix)
    r02, r12, r22 = matrix[..., 0, 2], matrix[..., 1, 2], matrix[..., 2, 2]
    sin_theta = np.hypot(r02, r12)
    theta = np.arctan2(sin_theta, r22)
    regular = sin_theta >= SINGULAR_SIN
    phi = np.where(regular, np.arctan2(r12, r02), 0.0)
    gamma = np.arctan2(matrix[..., 2, 1], -matrix[..., 2, 0])
    psi_regular = gamma + phi
    # θ = 0: R = Rz(ψ). θ = π: R = Ry(π) · Rz(ψ) with φ = 0, so R[0, 0] = −cos ψ, R[0, 1] = sin ψ.
    psi_top = np.arctan2(matrix[..., 1, 0], matrix[..., 0, 0])
    psi_bottom = np.arctan2(matrix[..., 0, 1], -matrix[..., 0, 0])
    psi = np.where(regular, psi_regular, np.where(r22 > 0.0, psi_top, psi_bottom))
    return np.stack([wrap_angle(phi), theta, wrap_angle(psi)], axis=-1)


def tt_to_quaternion(angles: ArrayLike) -> NDArray[np.float64]:
    """Unit quaternions ``(x, y, z, w)`` of T&T angles, in closed form.

    With α + γ = ψ and α − γ = 2φ − ψ, the ZYZ quaternion gives
    ``x = −sin(θ/2) sin(φ − ψ/2)``, ``y = sin(θ/2) cos(φ − ψ/2)``,
    ``z = cos(θ/2) sin(ψ/2)``, ``w = cos(θ/2) cos(ψ/2)``.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        (φ, θ, ψ) in rad.

    Returns
    -------
    ndarray, shape (..., 4)
        Quaternions (x, y, z, w), unit norm.
    """
    angles = _last_axis(angles, 3, "angles")
    phi, theta, psi = (
        wrap_angle(angles[..., 0]),
        wrap_angle(angles[..., 1]),
        wrap_angle(angles[..., 2]),
    )
    half_tilt_sin, half_tilt_cos = np.sin(theta / 2.0), np.cos(theta / 2.0)
    azimuth = phi - psi / 2.0
    return np.stack(
        [
            -half_tilt_sin * np.sin(azimuth),
            half_tilt_sin * np.cos(azimuth),
            half_tilt_cos * np.sin(psi / 2.0),
            half_tilt_cos * np.cos(psi / 2.0),
        ],
        axis=-1,
    )


def quaternion_to_matrix(quaternion: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices of quaternions ``(x, y, z, w)`` (normalised first).

    Parameters
    ----------
    quaternion : array_like, shape (..., 4)
        Quaternions (x, y, z, w), any non-zero norm.

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Raises
    ------
    InputError
        When a quaternion has zero or non-finite norm.
    """
    quaternion = _last_axis(quaternion, 4, "quaternion")
    norm = np.linalg.norm(quaternion, axis=-1)
    if not np.all(np.isfinite(norm) & (norm > 0.0)):
        msg = "quaternion: expected finite, non-zero quaternions"
        raise InputError(msg)
    x, y, z, w = np.moveaxis(quaternion / norm[..., None], -1, 0)
    matrix = np.empty((*quaternion.shape[:-1], 3, 3))
    matrix[..., 0, 0] = 1.0 - 2.0 * (y * y + z * z)
    matrix[..., 0, 1] = 2.0 * (x * y - z * w)
    matrix[..., 0, 2] = 2.0 * (x * z + y * w)
    matrix[..., 1, 0] = 2.0 * (x * y + z * w)
    matrix[..., 1, 1] = 1.0 - 2.0 * (x * x + z * z)
    matrix[..., 1, 2] = 2.0 * (y * z - x * w)
    matrix[..., 2, 0] = 2.0 * (x * z - y * w)
    matrix[..., 2, 1] = 2.0 * (y * z + x * w)
    matrix[..., 2, 2] = 1.0 - 2.0 * (x * x + y * y)
    return matrix


def matrix_to_quaternion(matrix: ArrayLike) -> NDArray[np.float64]:
    """Unit quaternions ``(x, y, z, w)`` of rotation matrices, with w ≥ 0.

    Uses the largest-diagonal branch (Shepperd's method) for accuracy everywhere.

    Parameters
    ----------
    matrix : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 4)
    """
    matrix = _matrices(matrix)
    m00, m11, m22 = matrix[..., 0, 0], matrix[..., 1, 1], matrix[..., 2, 2]
    trace = m00 + m11 + m22
    candidates = np.stack(
        [
            # 4w², 4x², 4y², 4z² up to a common factor: choose the largest for stability.
            1.0 + trace,
            1.0 + m00 - m11 - m22,
            1.0 - m00 + m11 - m22,
            1.0 - m00 - m11 + m22,
        ],
        axis=-1,
    )
    choice = np.argmax(candidates, axis=-1)
    largest = np.sqrt(np.maximum(np.take_along_axis(candidates, choice[..., None], -1)[..., 0], 0))
    s = 2.0 * largest
    d21 = matrix[..., 2, 1] - matrix[..., 1, 2]
    d02 = matrix[..., 0, 2] - matrix[..., 2, 0]
    d10 = matrix[..., 1, 0] - matrix[..., 0, 1]
    s01 = matrix[..., 0, 1] + matrix[..., 1, 0]
    s02 = matrix[..., 0, 2] + matrix[..., 2, 0]
    s12 = matrix[..., 1, 2] + matrix[..., 2, 1]
    half = largest / 2.0
    by_branch = np.stack(
        [
            np.stack([d21 / s, d02 / s, d10 / s, half], axis=-1),
            np.stack([half, s01 / s, s02 / s, d21 / s], axis=-1),
            np.stack([s01 / s, half, s12 / s, d02 / s], axis=-1),
            np.stack([s02 / s, s12 / s, half, d10 / s], axis=-1),
        ],
        axis=-2,
    )
    quaternion = np.take_along_axis(by_branch, choice[..., None, None], axis=-2)[..., 0, :]
    quaternion = np.where(quaternion[..., 3:4] < 0.0, -quaternion, quaternion)
    unit: NDArray[np.float64] = quaternion / np.linalg.norm(quaternion, axis=-1, keepdims=True)
    return unit


def quaternion_to_tt(quaternion: ArrayLike) -> NDArray[np.float64]:
    """T&T angles of quaternions ``(x, y, z, w)`` (normalised first).

    Parameters
    ----------
    quaternion : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3)
        (φ, θ, ψ) in rad, canonical ranges as :func:`matrix_to_tt`.
    """
    return matrix_to_tt(quaternion_to_matrix(quaternion))


def approach_vector(phi: ArrayLike, theta: ArrayLike) -> NDArray[np.float64]:
    """Unit approach vectors (tool axis z' in the base frame) of tool directions.

    Parameters
    ----------
    phi, theta : array_like, broadcastable shapes (...)
        Azimuth and tilt in rad.

    Returns
    -------
    ndarray, shape (..., 3)
        ``(cos φ sin θ, sin φ sin θ, cos θ)``; at θ = 0 it is (0, 0, 1) whatever φ.
    """
    phi, theta = np.broadcast_arrays(
        np.asarray(phi, dtype=np.float64), np.asarray(theta, dtype=np.float64)
    )
    sin_theta = np.sin(theta)
    return np.stack([np.cos(phi) * sin_theta, np.sin(phi) * sin_theta, np.cos(theta)], axis=-1)


def approach_to_tilt(axis: ArrayLike) -> NDArray[np.float64]:
    """Tool direction (φ, θ) of approach vectors (the inverse of :func:`approach_vector`).

    Parameters
    ----------
    axis : array_like, shape (..., 3)
        Tool axes z' in the base frame, any non-zero finite length (normalised first).

    Returns
    -------
    ndarray, shape (..., 2)
        (φ, θ) in rad, φ ∈ (−π, π], θ ∈ [0, π]; φ = 0 on the singularities θ = 0 and θ = π
        (the same convention as :func:`matrix_to_tt`).

    Raises
    ------
    InputError
        When an axis is zero or not finite.
    """
    axis = _last_axis(axis, 3, "axis")
    norm = np.linalg.norm(axis, axis=-1)
    if not np.all(np.isfinite(norm) & (norm > 0.0)):
        msg = "axis: expected finite, non-zero tool axes"
        raise InputError(msg)
    unit = axis / norm[..., None]
    sin_theta = np.hypot(unit[..., 0], unit[..., 1])
    theta = np.arctan2(sin_theta, unit[..., 2])
    phi = np.where(sin_theta >= SINGULAR_SIN, np.arctan2(unit[..., 1], unit[..., 0]), 0.0)
    return np.stack([wrap_angle(phi), theta], axis=-1)


def axis_angle_to_quaternion(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Quaternions ``(x, y, z, w)`` of rotations by ``angle`` about ``axis``.

    Parameters
    ----------
    axis : array_like, shape (..., 3)
        Rotation axes, base frame, non-zero (normalised first).
    angle : array_like, shape (...)
        Rotation angles, rad (right-hand rule).

    Returns
    -------
    ndarray, shape (..., 4)
        ``(sin(a/2)·u, cos(a/2))``.
    """
    axis = _last_axis(axis, 3, "axis")
    norm = np.linalg.norm(axis, axis=-1, keepdims=True)
    if not np.all(np.isfinite(norm) & (norm > 0.0)):
        msg = "axis: expected finite, non-zero rotation axes"
        raise InputError(msg)
    half = 0.5 * np.asarray(angle, dtype=np.float64)[..., None]
    return np.concatenate([np.sin(half) * axis / norm, np.cos(half)], axis=-1)


def quaternion_conjugate(quaternion: ArrayLike) -> NDArray[np.float64]:
    """Conjugates ``(−x, −y, −z, w)`` (the inverse rotation of a unit quaternion).

    Parameters
    ----------
    quaternion : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 4)
    """
    quaternion = _last_axis(quaternion, 4, "quaternion")
    conjugate: NDArray[np.float64] = quaternion * np.array([-1.0, -1.0, -1.0, 1.0])
    return conjugate


def quaternion_multiply(left: ArrayLike, right: ArrayLike) -> NDArray[np.float64]:
    """Hamilton products ``left ⊗ right`` (the rotation ``right`` first, then ``left``).

    Parameters
    ----------
    left, right : array_like, shape (..., 4), broadcastable
        Quaternions (x, y, z, w).

    Returns
    -------
    ndarray, shape (..., 4)
        Matches ``quaternion_to_matrix(left) @ quaternion_to_matrix(right)``.
    """
    left = _last_axis(left, 4, "left")
    right = _last_axis(right, 4, "right")
    x1, y1, z1, w1 = np.moveaxis(left, -1, 0)
    x2, y2, z2, w2 = np.moveaxis(right, -1, 0)
    return np.stack(
        [
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        ],
        axis=-1,
    )


def quaternion_angle(first: ArrayLike, second: ArrayLike) -> NDArray[np.float64]:
    """Angle of the shortest rotation between two orientations, in [0, π].

    The quaternions (unit 4-vectors, ``q₁`` taken in the hemisphere of ``q₀``) are an angle
    α = half the rotation angle apart, and ``|q₀ − q₁| = 2 sin(α/2)``, ``|q₀ + q₁| = 2 cos(α/2)``:
    the rotation angle is ``4·atan2(|q₀ − q₁|, |q₀ + q₁|)``, accurate near 0 and π (unlike
    ``2·acos|q₀·q₁|``).

    Parameters
    ----------
    first, second : array_like, shape (..., 4), broadcastable
        Unit quaternions (x, y, z, w).

    Returns
    -------
    ndarray, shape (...)
        rad.
    """
    first = _last_axis(first, 4, "first")
    second = _last_axis(second, 4, "second")
    dot = np.einsum("...k,...k->...", first, second)
    second = np.where(dot[..., None] < 0.0, -second, second)
    difference = np.linalg.norm(first - second, axis=-1)
    total = np.linalg.norm(first + second, axis=-1)
    angle: NDArray[np.float64] = 4.0 * np.arctan2(difference, total)
    return angle


def quaternion_slerp(first: ArrayLike, second: ArrayLike, s: ArrayLike) -> NDArray[np.float64]:
    """Spherical linear interpolation along the shortest rotation, at constant angular rate.

    ``q(s) = sin((1 − s)Ω)/sin Ω · q₀ + sin(sΩ)/sin Ω · q₁`` with ``q₁`` in the hemisphere of
    ``q₀`` and ``cos Ω = |q₀·q₁|``: the rotation ``R₀ → R(s)`` is ``s`` times the shortest
    rotation ``R₀ → R₁`` (same axis), so the platform turns at the constant rate
    ``2Ω = quaternion_angle(q₀, q₁)`` rad per unit ``s``.

    Parameters
    ----------
    first, second : array_like, shape (..., 4), broadcastable
        Unit quaternions (x, y, z, w) at s = 0 and s = 1.
    s : array_like, shape (...), broadcastable
        Interpolation parameters (normally in [0, 1]).

    Returns
    -------
    ndarray, shape (..., 4)
        Unit quaternions; at s = 0 exactly ``first``.
    """
    first = _last_axis(first, 4, "first")
    second = _last_axis(second, 4, "second")
    s = np.asarray(s, dtype=np.float64)[..., None]
    dot = np.einsum("...k,...k->...", first, second)[..., None]
    second = np.where(dot < 0.0, -second, second)
    half = 0.5 * quaternion_angle(first, second)[..., None]
    sin_half = np.sin(half)
    small = sin_half < 1e-9
    safe = np.where(small, 1.0, sin_half)
    weight_first = np.where(small, 1.0 - s, np.sin((1.0 - s) * half) / safe)
    weight_second = np.where(small, s, np.sin(s * half) / safe)
    result = weight_first * first + weight_second * second
    unit: NDArray[np.float64] = result / np.linalg.norm(result, axis=-1, keepdims=True)
    return unit


# ---------------------------------------------------------------------------- controllers
def _axis_rotations(
    angles: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Rx(a₀), Ry(a₁), Rz(a₂) of ``angles`` (..., 3), each shape (..., 3, 3)."""
    c, s = np.cos(angles), np.sin(angles)
    shape = (*angles.shape[:-1], 3, 3)
    rx, ry, rz = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    rx[..., 0, 0] = 1.0
    rx[..., 1, 1], rx[..., 1, 2] = c[..., 0], -s[..., 0]
    rx[..., 2, 1], rx[..., 2, 2] = s[..., 0], c[..., 0]
    ry[..., 1, 1] = 1.0
    ry[..., 0, 0], ry[..., 0, 2] = c[..., 1], s[..., 1]
    ry[..., 2, 0], ry[..., 2, 2] = -s[..., 1], c[..., 1]
    rz[..., 2, 2] = 1.0
    rz[..., 0, 0], rz[..., 0, 1] = c[..., 2], -s[..., 2]
    rz[..., 1, 0], rz[..., 1, 1] = s[..., 2], c[..., 2]
    return rx, ry, rz


def xyz_moving_to_matrix(angles: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices ``Rx(U) · Ry(V) · Rz(W)`` (PI's U, V, W).

    Rotations about the axes that move with the platform: U about x, then V about the y axis
    the first rotation carried, then W about the z axis the first two carried.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        (U, V, W) in rad, any finite values.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Rotation matrices of the mobile frame in the base frame.
    """
    rx, ry, rz = _axis_rotations(_last_axis(angles, 3, "angles"))
    matrix: NDArray[np.float64] = rx @ ry @ rz
    return matrix


def xyz_fixed_to_matrix(angles: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices ``Rz(C) · Ry(B) · Rx(A)`` (LinuxCNC's A, B, C; Symétrie's Rx, Ry, Rz).

    Rotations about the fixed base axes: A about x first, then B about y, then C about z.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        (A, B, C) in rad, any finite values.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Rotation matrices of the mobile frame in the base frame.
    """
    rx, ry, rz = _axis_rotations(_last_axis(angles, 3, "angles"))
    matrix: NDArray[np.float64] = rz @ ry @ rx
    return matrix


@dataclass(frozen=True)
class AngleConvention:
    """One way of writing an orientation.

    Attributes
    ----------
    name : str
        What ``--angles`` takes (``"xyz-moving"``).
    components : tuple of str
        The names of its numbers, as CSV columns and JSON keys spell them (``("u", "v", "w")``).
    angular : bool
        True for angles (rad in the core, degrees or radians in files), False for the
        quaternion's unitless components.
    formula : str
        The rotation it denotes, in words.
    to_matrix : callable
        ``(..., len(components))`` (rad) to rotation matrices ``(..., 3, 3)``.
    """

    name: str
    components: tuple[str, ...]
    angular: bool
    formula: str
    to_matrix: Callable[[ArrayLike], NDArray[np.float64]]


#: Every convention a pose may be given in, by ``--angles`` name; ``tt`` first (the default).
ANGLE_CONVENTIONS: dict[str, AngleConvention] = {
    c.name: c
    for c in (
        AngleConvention(
            "tt", ("phi", "theta", "psi"), True, "Rz(phi) Ry(theta) Rz(-phi) Rz(psi)", tt_to_matrix
        ),
        AngleConvention(
            "xyz-moving", ("u", "v", "w"), True, "Rx(u) Ry(v) Rz(w)", xyz_moving_to_matrix
        ),
        AngleConvention(
            "xyz-fixed", ("a", "b", "c"), True, "Rz(c) Ry(b) Rx(a)", xyz_fixed_to_matrix
        ),
        AngleConvention(
            "symetrie", ("rx", "ry", "rz"), True, "Rz(rz) Ry(ry) Rx(rx)", xyz_fixed_to_matrix
        ),
        AngleConvention(
            "quaternion",
            ("qx", "qy", "qz", "qw"),
            False,
            "unit quaternion, scalar last",
            quaternion_to_matrix,
        ),
    )
}


def _convention(name: str) -> AngleConvention:
    try:
        return ANGLE_CONVENTIONS[name]
    except KeyError:
        msg = f"angles: expected one of {', '.join(ANGLE_CONVENTIONS)}, got {name!r}"
        raise InputError(msg) from None


def convention_to_matrix(values: ArrayLike, convention: str) -> NDArray[np.float64]:
    """Rotation matrices of orientations written in ``convention``.

    Parameters
    ----------
    values : array_like, shape (..., 3) or (..., 4)
        Angles in rad (any finite values) or quaternions (x, y, z, w), any non-zero norm.
    convention : str
        A key of :data:`ANGLE_CONVENTIONS`.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Rotation matrices of the mobile frame in the base frame.
    """
    found = _convention(convention)
    _last_axis(values, len(found.components), found.name)
    return found.to_matrix(values)


def convention_to_tt(values: ArrayLike, convention: str) -> NDArray[np.float64]:
    """T&T angles of orientations written in ``convention``.

    ``tt`` is returned unchanged (no round trip through a matrix); every other convention goes
    through its rotation matrix and :func:`matrix_to_tt`, so the result is in the canonical
    ranges and defined at θ = 0 (φ = 0, the whole rotation in ψ).

    Parameters
    ----------
    values : array_like, shape (..., 3) or (..., 4)
        As :func:`convention_to_matrix`.
    convention : str
        A key of :data:`ANGLE_CONVENTIONS`.

    Returns
    -------
    ndarray, shape (..., 3)
        (φ, θ, ψ) in rad; φ ∈ (−π, π], θ ∈ [0, π], ψ ∈ (−π, π] except for ``tt`` (as given).
    """
    if _convention(convention).name == "tt":
        return _last_axis(values, 3, "tt")
    return matrix_to_tt(convention_to_matrix(values, convention))
