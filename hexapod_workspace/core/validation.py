"""Layouts no verdict can be given for: refused with the reason, at start-up and at run time.

One set of rules for every door a model comes in by (the CLI's ``--config`` file, the node's
parameters at start, a ``set_parameters`` call): the node's start-up and run-time validation
and the CLI's all end here.

* **Paired joints** (:func:`shared_joint_pairs`, :func:`paired_joints_reason`): two joint
  centres closer than :data:`COINCIDENT_TOLERANCE` are one joint shared by two legs, as
  builders draw the 6-3, 3-3 and zig-zag designs and LinuxCNC's default ``genhexkins``
  machine. 6-UPS legs may share joints (the interference of two legs that share one is
  measured along their free lengths, ``geometry.paired_joint_length``:
  :mod:`~hexapod_workspace.core.constraint_table`); refused are four or more legs through one
  point (their lines are always linearly dependent: the platform is singular at every pose),
  two legs that share both joints (one leg twice), and shared joints of the pus and rus legs,
  whose base-side ends move (not modelled).
* **Zero-length legs** at the home pose (checked by the model builder itself).
* **A platform singular at the home pose** (:func:`home_conditioning`): the 6×6 matrix whose
  rows are the legs' normalised Plücker coordinates ``(n_i, (R·b_i × n_i) / ρ)`` (identity
  R at the home pose, ρ the platform radius max |b_i|, so that both halves are dimensionless and
  of order 1) has its smallest singular value below :data:`SINGULAR_TOLERANCE`. Six legs through
  one point, six parallel legs, a planar layout with every leg in the plane: rank < 6, the leg
  lengths do not fix the platform and no verdict about its orientation means anything.
* **An unreachable home pose** (:func:`unusable_reason`): the home pose is where the machine is
  assembled; a model that cannot take it is almost always a unit mistake (millimetres in a file
  of metres, degrees for radians) and is refused with that hint.
* **Values in millimetres** (:func:`millimetre_reason`, the one unit rule): a length or a speed
  that fits the machine only once divided by 1000 is refused with the unit hint, whichever
  parameter it is: the leg length limits and ``limits.actuator_speed_max`` against the size of
  the machine (the farthest joint centre from the base origin at home, per second for a
  speed), ``tool.offset``, ``tools.T<n>.offset`` and ``work.origin`` against the same size
  (:func:`cell_unit_reason`), positions typed or read by the CLI likewise. "Fits" means within
  :data:`PLAUSIBLE_RATIO` times the size; a value beyond that which is within it once divided
  by 1000 is a unit mistake, not a machine.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ConfigError, GeometryError

if TYPE_CHECKING:
    from .frames import CellFrames
    from .manipulator import Manipulator

__all__ = [
    "COINCIDENT_TOLERANCE",
    "PLAUSIBLE_RATIO",
    "SINGULAR_TOLERANCE",
    "cell_unit_reason",
    "coincident_joints_reason",
    "home_conditioning",
    "machine_size",
    "millimetre_reason",
    "paired_joints_reason",
    "require_plausible_cell",
    "require_usable",
    "shared_joint_pairs",
    "unusable_reason",
]

#: Two joint centres closer than this (m) are the same point.
COINCIDENT_TOLERANCE = 1e-6
#: Smallest singular value of the normalised Plücker matrix below which the platform is singular.
#: The example GPM has 0.13 at home; rounding errors of an exactly singular layout are ~1e-16.
SINGULAR_TOLERANCE = 1e-6
#: Lengths in a file written in millimetres are 1000 times too large.
_MM = 1000.0
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
    fits = array / _MM <= limit
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


def cell_unit_reason(manipulator: Manipulator, cell: CellFrames) -> str | None:
    """:func:`millimetre_reason` of the cell's lengths and speeds against the machine's size:
    ``tool.offset``, ``tools.T<n>.offset``, ``work.origin`` (m) and, for actuators that slide
    (``ups``, ``pus``: m/s), ``limits.actuator_speed_max``."""
    size = machine_size(
        manipulator.base_joints, manipulator.platform_joints, manipulator.home_position
    )
    checks: list[tuple[str, ArrayLike, str, str]] = [
        ("tool.offset", cell.tool.offset if cell.tool.number == 0 else np.zeros(3), "m", ""),
        *((f"tools.T{n}.offset", t.offset, "m", "") for n, t in sorted(cell.tools.items())),
        ("work.origin", cell.work.origin, "m", ""),
    ]
    if manipulator.architecture in ("ups", "pus"):
        checks.append(("limits.actuator_speed_max", cell.actuator_speed_max, "m/s", "/s"))
    for name, values, unit, per in checks:
        reason = millimetre_reason(name, values, size, unit, per)
        if reason is not None:
            return reason
    return None


def require_plausible_cell(manipulator: Manipulator, cell: CellFrames) -> CellFrames:
    """Return ``cell``, or raise :class:`ConfigError` with :func:`cell_unit_reason`."""
    reason = cell_unit_reason(manipulator, cell)
    if reason is not None:
        raise ConfigError(reason)
    return cell


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


def home_conditioning(manipulator: Manipulator) -> float:
    """Smallest singular value of the normalised Plücker matrix of the legs at the home pose.

    Rows ``(n_i, (b_i × n_i) / ρ)``: n_i the unit leg direction at the home position with the
    identity orientation, b_i the platform joint (mobile frame = base frame orientation there),
    ρ = max |b_i| (1 m when every b_i is 0). Dimensionless; 0 for a singular platform.
    """
    from .legs import leg_endpoints

    base, platform = leg_endpoints(manipulator, np.eye(3), manipulator.home_position)
    legs = platform[0] - base[0]
    directions = legs / np.linalg.norm(legs, axis=1)[:, None]
    radius = float(np.max(np.linalg.norm(manipulator.platform_joints, axis=1))) or 1.0
    moments = np.cross(manipulator.platform_joints, directions) / radius
    plucker = np.hstack((directions, moments))
    return float(np.linalg.svd(plucker, compute_uv=False)[-1])


def _unit_hint(manipulator: Manipulator) -> str:
    """Which lengths look like millimetres, from the home leg lengths against the limits."""
    if manipulator.architecture != "ups":
        return (
            "parameters are in metres and radians (a unit mistake, millimetres or degrees, is "
            "the usual cause)"
        )
    legs = manipulator.home_position + manipulator.platform_joints - manipulator.base_joints
    lengths = np.linalg.norm(legs, axis=1)
    low, high = manipulator.leg_length_min, manipulator.leg_length_max
    span = f"{lengths.min():.4g} to {lengths.max():.4g} m"
    if np.all((low / _MM <= lengths) & (lengths <= high / _MM)):
        return (
            f"the legs are {span} long there and limits.leg_length_min/max look like "
            "millimetres (they fit once divided by 1000); parameters are in metres"
        )
    if np.all((low <= lengths / _MM) & (lengths / _MM <= high)):
        return (
            f"the legs are {span} long there, which fits limits.leg_length_min/max once "
            "divided by 1000: geometry.* look like millimetres; parameters are in metres"
        )
    return (
        f"the legs are {span} long there; parameters are in metres and radians (a unit "
        "mistake, millimetres or degrees, is the usual cause)"
    )


def unusable_reason(manipulator: Manipulator) -> str | None:
    """Why no verdict can be given for this model (see the module documentation), or None."""
    # The evaluator is imported here, not at module level: the model (manipulator.py imports
    # this module) does not import the evaluator.
    from .constraints import home_pose_violations

    problems = home_pose_violations(manipulator)
    if problems:
        return (
            f"the home pose (geometry.home_position {manipulator.home_position.tolist()} m, "
            f"identity orientation) is unreachable: {', '.join(problems)} violated; "
            f"{_unit_hint(manipulator)}"
        )
    conditioning = home_conditioning(manipulator)
    if conditioning < SINGULAR_TOLERANCE:
        return (
            "geometry: the platform is singular at the home pose (smallest singular value of "
            f"the legs' Plücker matrix {conditioning:.3g} < {SINGULAR_TOLERANCE:g}): the leg "
            "lengths do not fix the platform there"
        )
    return None


def require_usable(manipulator: Manipulator) -> Manipulator:
    """Return ``manipulator``, or raise :class:`GeometryError` with :func:`unusable_reason`."""
    reason = unusable_reason(manipulator)
    if reason is not None:
        raise GeometryError(reason)
    return manipulator
