"""6-PUS (the paper's 6-PRRS, Hexaglide-like): slides on rails, legs of fixed length.

The base joint of leg i slides on a rail, ``A_i(q) = A0_i + q·u_i`` (``A0_i`` =
``geometry.base_joints``, unit ``u_i`` = ``geometry.rail_directions``), and a leg of fixed
length ``L_i`` (``geometry.leg_lengths``) joins it to ``B_i``. With ``d = B_i − A0_i``,
``|d − q·u|² = L²`` gives

    q = u·d + branch·sqrt((u·d)² − |d|² + L²),

``branch`` = ``geometry.branch`` (+1: the slide ahead of B_i along u). The discriminant is
``L² − h²``, h = ``|d − (u·d)·u|`` the distance from B_i to the rail line: the ``ik`` margin is
``L − h`` (m), negative exactly when there is no solution, 1-Lipschitz in B_i. Transmission
``τ = n·u``: differentiating ``|B − A0 − q·u|² = L²`` gives ``dq = n·dB / τ``.
"""

from __future__ import annotations

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
    "transmission",
]

#: The actuated coordinate, the slide position on its rail, in m; its force in N.
ACTUATOR_UNIT, FORCE_UNIT = "m", "N"
#: The slide joints move with the actuators and translate without turning.
MOVING_BASE, TURNING_BASE = True, False


def _rails(manipulator: Manipulator) -> NDArray[np.float64]:
    rails = manipulator.rail_directions
    assert rails is not None
    return rails


def inverse_kinematics(
    manipulator: Manipulator, platform: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Slide positions q (..., 6), m (NaN without a solution), and the ``ik`` margin, m."""
    u = _rails(manipulator)
    length, branch = manipulator.leg_lengths, manipulator.branch
    assert length is not None and branch is not None
    d = platform - manipulator.base_joints
    ud = np.sum(d * u, axis=-1)
    h = np.linalg.norm(d - ud[..., None] * u, axis=-1)
    ik = length - h
    with np.errstate(invalid="ignore"):
        q = np.where(ik >= 0.0, ud + branch * np.sqrt(np.maximum(ik * (length + h), 0.0)), np.nan)
    return q, ik


def base_ends(manipulator: Manipulator, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The slide joints A_i(q) = A0_i + q·u_i, (..., 6, 3), m."""
    return manipulator.base_joints + np.asarray(q)[..., None] * _rails(manipulator)


def base_end_derivatives(
    manipulator: Manipulator, q: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """dA_i/dq = u_i (unitless) and d²A_i/dq² = 0, each (..., 6, 3): the slide is straight."""
    rails = np.broadcast_to(_rails(manipulator), (*np.shape(q), 3)).copy()
    return rails, np.zeros_like(rails)


def transmission(
    manipulator: Manipulator, directions: NDArray[np.float64], q: NDArray[np.float64]
) -> NDArray[np.float64]:
    """τ_i = n_i·u_i for unit leg directions (..., 6, 3)."""
    tau: NDArray[np.float64] = np.sum(directions * _rails(manipulator), axis=-1)
    return tau


def base_axes(manipulator: Manipulator, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The slide joint axes translate with the slide: constant, (..., 6, 3)."""
    return np.broadcast_to(manipulator.base_joint_axes, (*np.shape(q), 3)).copy()


def actuator_lever(manipulator: Manipulator) -> NDArray[np.float64]:
    """r_i = 1 (m): the slide moves by dq = n·dB / τ."""
    return np.ones(6)
