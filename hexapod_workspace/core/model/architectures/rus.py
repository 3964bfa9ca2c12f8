"""6-RUS (6-RSS, rotary): cranks turned by motors on the base, rods of fixed length.

Crank i turns about the unit axis ``w_i`` (``geometry.crank_axes``) through ``A0_i``
(``geometry.base_joints``); at angle q its end is
``C_i(q) = A0_i + r_i·(cos q·e_i + sin q·f_i)``, ``e_i`` = ``geometry.crank_zero_directions``
(⟂ w_i), ``f_i = w_i × e_i``, ``r_i`` = ``geometry.crank_lengths``. A rod of fixed length
``L_i`` (``geometry.leg_lengths``) joins C_i to B_i. With ``d = B_i − A0_i``, ``|d − (C − A0)|²
= L²`` is ``a cos q + b sin q = c``, ``a = 2r·d·e``, ``b = 2r·d·f``, ``c = |d|² + r² − L²``:

    q = atan2(b, a) + branch·arccos(c / √(a² + b²)),

taken in the 2π window centred on ``[limits.actuator_min, limits.actuator_max]``. The distances
from B_i to the crank circle span ``[d_min, d_max]``, ``d_min² = d_∥² + (|d_⊥| − r)²``,
``d_max² = d_∥² + (|d_⊥| + r)²`` (d_∥ along w, d_⊥ across): the ``ik`` margin
``min(L − d_min, d_max − L)`` (m) is negative exactly when ``|c| > √(a² + b²)`` and is
1-Lipschitz in B_i. Transmission ``τ = n·(w × (C − A0))/r`` (the rod direction against the
crank end's unit velocity): differentiating gives ``r·τ·dq = n·dB``. The crank-end joint's axis
turns with the crank: given at q = 0, it is turned by q about w_i.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from ..manipulator import Manipulator

__all__ = [
    "ACTUATOR_UNIT",
    "FORCE_UNIT",
    "MOVING_BASE",
    "TURNING_BASE",
    "actuator_lever",
    "base_axes",
    "base_end_derivatives",
    "base_ends",
    "inverse_kinematics",
    "rotate_about",
    "transmission",
]

#: The actuated coordinate, the crank angle, in rad; its torque in N·m.
ACTUATOR_UNIT, FORCE_UNIT = "rad", "N·m"
#: The crank ends move with the cranks and turn about the crank axes.
MOVING_BASE, TURNING_BASE = True, True


def _crank(
    manipulator: Manipulator,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    w, e, r = manipulator.crank_axes, manipulator.crank_zero_directions, manipulator.crank_lengths
    assert w is not None and e is not None and r is not None
    f = np.asarray(np.cross(w, e), dtype=np.float64)
    return w, e, f, r


def inverse_kinematics(
    manipulator: Manipulator, platform: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Crank angles q (..., 6), rad (NaN without a solution), and the ``ik`` margin, m."""
    w, e, f, r = _crank(manipulator)
    length, branch = manipulator.leg_lengths, manipulator.branch
    assert length is not None and branch is not None
    d = platform - manipulator.base_joints
    a = 2.0 * r * np.sum(d * e, axis=-1)
    b = 2.0 * r * np.sum(d * f, axis=-1)
    c = np.sum(d * d, axis=-1) + r * r - length * length
    along = np.sum(d * w, axis=-1)
    across = np.linalg.norm(d - along[..., None] * w, axis=-1)
    ik = np.minimum(length - np.hypot(along, across - r), np.hypot(along, across + r) - length)
    with np.errstate(invalid="ignore", divide="ignore"):
        raw = np.arctan2(b, a) + branch * np.arccos(np.clip(c / np.hypot(a, b), -1.0, 1.0))
    low, high = manipulator.actuator_min, manipulator.actuator_max
    assert low is not None and high is not None
    centre = 0.5 * (low + high)
    q = centre + np.mod(raw - centre + math.pi, 2.0 * math.pi) - math.pi
    return np.where(ik >= 0.0, q, np.nan), ik


def base_ends(manipulator: Manipulator, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The crank ends C_i(q), (..., 6, 3), m."""
    _, e, f, r = _crank(manipulator)
    q = np.asarray(q)
    ends: NDArray[np.float64] = manipulator.base_joints + r[:, None] * (
        np.cos(q)[..., None] * e + np.sin(q)[..., None] * f
    )
    return ends


def base_end_derivatives(
    manipulator: Manipulator, q: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """dC_i/dq = r_i·(cos q·f_i − sin q·e_i) and d²C_i/dq² = −(C_i − A0_i), each (..., 6, 3), m
    per rad and per rad²; |d³C/dq³| = |dC/dq| = r_i."""
    _, e, f, r = _crank(manipulator)
    q = np.asarray(q)
    c, s = np.cos(q)[..., None], np.sin(q)[..., None]
    first: NDArray[np.float64] = r[:, None] * (c * f - s * e)
    second: NDArray[np.float64] = -r[:, None] * (c * e + s * f)
    return first, second


def transmission(
    manipulator: Manipulator, directions: NDArray[np.float64], q: NDArray[np.float64]
) -> NDArray[np.float64]:
    """τ_i = n_i·(cos q·f_i − sin q·e_i) (= n·(w × (C − A0))/r) for unit rod directions."""
    _, e, f, _ = _crank(manipulator)
    q = np.asarray(q)
    tangent = np.cos(q)[..., None] * f - np.sin(q)[..., None] * e
    tau: NDArray[np.float64] = np.sum(directions * tangent, axis=-1)
    return tau


def rotate_about(
    axes: NDArray[np.float64], angles: NDArray[np.float64], vectors: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Rodrigues: ``vectors`` (..., 6, 3) turned by ``angles`` (..., 6) about unit ``axes``."""
    c, s = np.cos(angles)[..., None], np.sin(angles)[..., None]
    along = np.sum(axes * vectors, axis=-1, keepdims=True) * axes
    turned: NDArray[np.float64] = c * vectors + s * np.cross(axes, vectors) + (1.0 - c) * along
    return turned


def base_axes(manipulator: Manipulator, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The crank-end joint axes, given at q = 0 and turned by q about w_i, (..., 6, 3)."""
    w, _, _, _ = _crank(manipulator)
    q = np.asarray(q)
    return rotate_about(w, q, np.broadcast_to(manipulator.base_joint_axes, (*q.shape, 3)))


def actuator_lever(manipulator: Manipulator) -> NDArray[np.float64]:
    """r_i = the crank length (m): the crank turns by dq = n·dB / (r·τ)."""
    radius = manipulator.crank_lengths
    assert radius is not None
    return radius
