"""6-UPS (Gough-Stewart): fixed base joints A_i = a_i, actuated leg length ℓ_i = |B_i − a_i|."""

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

#: The actuated coordinate, the leg length, in m; its force in N (the interface:
#: :class:`~hexapod_workspace.core.model.architectures.Architecture`).
ACTUATOR_UNIT, FORCE_UNIT = "m", "N"
#: The base joints are fixed: neither moving nor turning base-side ends.
MOVING_BASE, TURNING_BASE = False, False


def inverse_kinematics(
    manipulator: Manipulator, platform: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Leg lengths (..., 6), m, and the ``ik`` margin (+inf: every pose has a solution)."""
    lengths = np.linalg.norm(platform - manipulator.base_joints, axis=-1)
    return lengths, np.full(lengths.shape, np.inf)


def base_ends(manipulator: Manipulator, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The fixed base joints, broadcast to (..., 6, 3), m."""
    return np.broadcast_to(manipulator.base_joints, (*np.shape(q), 3)).copy()


def base_end_derivatives(
    manipulator: Manipulator, q: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """dA_i/dq and d²A_i/dq²: zero (the base joints do not move with the leg length)."""
    zeros = np.zeros((*np.shape(q), 3))
    return zeros, zeros.copy()


def transmission(
    manipulator: Manipulator, directions: NDArray[np.float64], q: NDArray[np.float64]
) -> NDArray[np.float64]:
    """τ = 1: the actuator moves along the leg line."""
    return np.ones(np.shape(q))


def base_axes(manipulator: Manipulator, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The fixed base joint axes, (..., 6, 3)."""
    return np.broadcast_to(manipulator.base_joint_axes, (*np.shape(q), 3)).copy()


def actuator_lever(manipulator: Manipulator) -> NDArray[np.float64]:
    """r_i = 1 (m): the leg length changes by n·dB."""
    return np.ones(6)
