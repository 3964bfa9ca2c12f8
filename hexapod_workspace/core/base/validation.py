"""Rules on a model's numbers, before any evaluation: shared joints and units.

One set of rules for every door a model comes in by (the CLI's ``--config`` file, the node's
parameters at start, a ``set_parameters`` call): the loader
(:mod:`~hexapod_workspace.core.evaluation.loading`, which adds the rules that need the evaluator: a
singular or unreachable home pose) and the cell
(:func:`~hexapod_workspace.core.cell.frames.cell_unit_reason`) apply them.

* **Paired joints** (:func:`shared_joint_pairs`, :func:`paired_joints_reason`): two joint
  centres closer than :data:`COINCIDENT_TOLERANCE` are one joint shared by two legs, as
  builders draw the 6-3, 3-3 and zig-zag designs and LinuxCNC's default ``genhexkins``
  machine. 6-UPS legs may share joints (the interference of two legs that share one is
  measured along their free lengths, ``geometry.paired_joint_length``:
  :mod:`~hexapod_workspace.core.constraints.table`); refused are four or more legs through one
  point (their lines are always linearly dependent: the platform is singular at every pose),
  two legs that share both joints (one leg twice), and shared joints of the pus and rus legs,
  whose base-side ends move (not modelled).
* **Values in millimetres** (:func:`millimetre_reason`, the one unit rule): a length or a speed
  that fits the machine only once divided by 1000 is refused with the unit hint, whichever
  parameter it is: the leg length limits and ``limits.actuator_speed_max`` against the size of
  the machine (:func:`machine_size`: the farthest joint centre from the base origin at home,
  per second for a speed), ``tool.offset``, ``tools.T<n>.offset`` and ``work.origin`` against
  the same size, positions typed or read by the CLI likewise. "Fits" means within
  :data:`PLAUSIBLE_RATIO` times the size; a value beyond that which is within it once divided
  by 1000 is a unit mistake, not a machine.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "COINCIDENT_TOLERANCE",
    "MM",
    "PLAUSIBLE_RATIO",
    "SINGULAR_TOLERANCE",
    "coincident_joints_reason",
    "machine_size",
    "millimetre_reason",
    "paired_joints_reason",
    "shared_joint_pairs",
]

#: Two joint centres closer than this (m) are the same point.
COINCIDENT_TOLERANCE = 1e-6
#: Smallest singular value of the normalised Plücker matrix below which the platform is singular.
#: The example GPM has 0.13 at home; rounding errors of an exactly singular layout are ~1e-16.
SINGULAR_TOLERANCE = 1e-6
#: Lengths in a file written in millimetres are 1000 times too large (mm per m).
MM = 1000.0
#: A length (m) or speed (m/s) more than this many times the machine's size (m) does not fit it.
PLAUSIBLE_RATIO = 10.0


def machine_size(
    base_joints: ArrayLike, platform_joints: ArrayLike, home_position: ArrayLike
) -> float:
    """The size of the machine: the farthest joint centre from the base origin at home, m.

    Parameters
    ----------
    base_joints, platform_joints : array_like, shape (6, 3)
        m, base and platform frames.
    home_position : array_like, shape (3,)
        m, base frame.
    """
    base = np.linalg.norm(np.asarray(base_joints, dtype=np.float64), axis=-1)
    platform = np.linalg.norm(
        np.asarray(platform_joints, dtype=np.float64) + np.asarray(home_position), axis=-1
    )
    return float(max(base.max(), platform.max()))


def millimetre_reason(
    name: str, values: ArrayLike, size: float, unit: str = "m", per: str = ""
) -> str | None:
    """The one unit rule: why ``values`` look like millimetres, or None.

    A value larger than :data:`PLAUSIBLE_RATIO` times the machine's size that is within it once
    divided by 1000 is refused with the hint.

    Parameters
    ----------
    name : str
        The parameter, column or flag, for the message.
    values : array_like, shape (...)
        Its values, in ``unit`` (m, m/s).
    size : float
        :func:`machine_size`, m; a size that is not positive and finite checks nothing.
    unit : str
        The unit the values should be in.
    per : str
        ``"/s"`` for a speed (compared with the size per second).

    Returns
    -------
    str or None
        One line: the parameter, the value given, what would fit, the hint.
    """
    array = np.abs(np.atleast_1d(np.asarray(values, dtype=np.float64)))
    if not (np.isfinite(size) and size > 0.0) or not np.all(np.isfinite(array)):
        return None
    limit = PLAUSIBLE_RATIO * size
    fits = array / MM <= limit
    big = np.flatnonzero((array > limit) & fits)
    if not big.size or not np.all(fits):
        return None
    value = float(np.atleast_1d(np.asarray(values, dtype=np.float64))[big[0]])
    return (
        f"{name}: expected {unit} (at most {limit:.3g} {unit} for a machine of {size:.3g} m"
        f"{', per second' if per else ''}), got {value:g}, which fits once divided by 1000: "
        f"it looks like milli{'metres' if unit == 'm' else unit.replace('m/', 'metres/')}; "
        f"parameters are in metres{' per second' if per else ''}"
    )


def shared_joint_pairs(joints: ArrayLike) -> NDArray[np.bool_]:
    """Which leg pairs share a joint centre (closer than :data:`COINCIDENT_TOLERANCE`).

    Parameters
    ----------
    joints : array_like, shape (6, 3)
        Base or platform joint centres, m.

    Returns
    -------
    ndarray of bool, shape (15,)
        Per pair i < j in the order of ``numpy.triu_indices(6, 1)`` (the interference pairs).
    """
    array = np.asarray(joints, dtype=np.float64)
    i, j = np.triu_indices(6, 1)
    shared: NDArray[np.bool_] = np.linalg.norm(array[i] - array[j], axis=-1) < COINCIDENT_TOLERANCE
    return shared


def paired_joints_reason(
    base_joints: NDArray[np.float64], platform_joints: NDArray[np.float64], architecture: str
) -> str | None:
    """Why shared joint centres make no machine, or None (see the module's *Paired joints*).

    Parameters
    ----------
    base_joints, platform_joints : ndarray, shape (6, 3)
        Joint centres, m (base and platform frames).
    architecture : str
        ``"ups"``, ``"pus"`` or ``"rus"``.
    """
    if architecture != "ups":
        for name, joints in (
            ("geometry.base_joints", base_joints),
            ("geometry.platform_joints", platform_joints),
        ):
            reason = coincident_joints_reason(name, joints)
            if reason is not None:
                return (
                    f"{reason}; paired joints are modelled for geometry.architecture ups only "
                    f"(got {architecture}, whose base-side joints move)"
                )
        return None
    for name, joints in (
        ("geometry.base_joints", base_joints),
        ("geometry.platform_joints", platform_joints),
    ):
        for k in range(6):
            group = np.flatnonzero(
                np.linalg.norm(joints - joints[k], axis=-1) < COINCIDENT_TOLERANCE
            )
            if group.size > 3:
                legs = ", ".join(str(int(g) + 1) for g in group[:-1])
                return (
                    f"{name}: expected at most three legs per joint centre, joints {legs} and "
                    f"{int(group[-1]) + 1} coincide at {np.round(joints[k], 9).tolist()} m (four "
                    "or more leg lines through one point are linearly dependent: the platform "
                    "would be singular at every pose)"
                )
    both = np.flatnonzero(shared_joint_pairs(base_joints) & shared_joint_pairs(platform_joints))
    if both.size:
        i, j = (int(v[both[0]]) + 1 for v in np.triu_indices(6, 1))
        return (
            f"geometry.platform_joints: legs {i} and {j} share both their base and their "
            "platform joint: expected six distinct legs, got one leg twice"
        )
    return None


def coincident_joints_reason(name: str, joints: NDArray[np.float64]) -> str | None:
    """Why six joint centres are not six distinct ones (two at one point), or None.

    Parameters
    ----------
    name : str
        The parameter (``geometry.base_joints``), for the message.
    joints : ndarray, shape (6, 3)
        Joint centres, m.
    """
    gaps = np.linalg.norm(joints[:, None, :] - joints[None, :, :], axis=-1)
    close = np.argwhere(np.triu(gaps < COINCIDENT_TOLERANCE, k=1))
    if close.size == 0:
        return None
    i, j = (int(k) for k in close[0])
    return (
        f"{name}: expected six distinct joint centres, joints {i + 1} and {j + 1} coincide "
        f"at {np.round(joints[i], 9).tolist()} m (distance {gaps[i, j]:.3g} m < "
        f"{COINCIDENT_TOLERANCE:g} m)"
    )
