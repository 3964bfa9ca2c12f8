"""Leg segments at a pose: where each leg runs, for display, collision bodies and references.

The compiled kernels compute the same segments inside their margin loops; this numpy function is
the one place outside them that knows where a leg starts and ends, so that the markers, the
scene plots and the collision scene follow the model's leg architecture instead of assuming
fixed base joints.

The platform-side end is ``B_i = p + R·b_i`` (``geometry.platform_joints`` in the mobile
frame). The base-side end follows the leg architecture
(:mod:`hexapod_workspace.core.model.architectures`): for 6-UPS the fixed base joint ``A_i = a_i``
(``geometry.base_joints``); for 6-PUS the slide joint ``A_i(q_i) = A0_i + q_i·u_i``; for 6-RUS
the crank end ``C_i(q_i)``, with q_i from the leg's inverse kinematics at the pose (NaN where
the leg has no solution).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError
from .architectures import module as architecture_module

if TYPE_CHECKING:
    from .manipulator import Manipulator

__all__ = ["leg_endpoints"]


def leg_endpoints(
    manipulator: Manipulator, rotations: ArrayLike, positions: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Both ends of every leg at n poses.

    Parameters
    ----------
    manipulator : Manipulator
    rotations : array_like, shape (n, 3, 3) or (3, 3)
        Platform orientations R (mobile frame to base frame).
    positions : array_like, shape (n, 3) or (3,)
        Positions OC of the mobile frame's origin, base frame, m; one position is shared by all
        rotations.

    Returns
    -------
    base_ends : ndarray, shape (n, 6, 3)
        Base-side end of each leg (the base joint, slide joint or crank end), base frame, m;
        NaN rows for legs without an inverse-kinematics solution (pus, rus).
    platform_ends : ndarray, shape (n, 6, 3)
        Platform-side end B_i = p + R·b_i, base frame, m.
    """
    r = np.asarray(rotations, dtype=np.float64)
    if r.shape == (3, 3):
        r = r[None]
    if r.ndim != 3 or r.shape[1:] != (3, 3):
        msg = f"rotations: expected shape (n, 3, 3) or (3, 3), got {np.shape(rotations)}"
        raise InputError(msg)
    p = np.asarray(positions, dtype=np.float64)
    if p.shape == (3,):
        p = np.broadcast_to(p, (r.shape[0], 3))
    if p.shape != (r.shape[0], 3):
        msg = f"positions: expected shape ({r.shape[0]}, 3) or (3,), got {np.shape(positions)}"
        raise InputError(msg)
    platform_ends = p[:, None, :] + np.einsum("nij,kj->nki", r, manipulator.platform_joints)
    legs = architecture_module(manipulator.architecture)
    q, _ = legs.inverse_kinematics(manipulator, platform_ends)
    base_ends: NDArray[np.float64] = legs.base_ends(manipulator, q)
    return base_ends, platform_ends
