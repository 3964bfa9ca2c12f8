"""The manipulator model: joint positions, joint axes and limits of a hexapod (6-UPS, 6-PUS or
6-RUS legs: ``geometry.architecture``, see :mod:`hexapod_workspace.core.architectures`).

Built from a ROS 2 parameters file or a plain mapping (what the node holds), validated as a
whole. Every error names the parameter, what was expected and what was given.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ConfigError, GeometryError
from .architectures import ARCHITECTURES
from .architectures import module as architecture_module
from .params import (
    CELL_PARAMETERS,
    COLLISION_PARAMETERS,
    NODE_PARAMETERS,
    ROS_PARAMETERS,
    flatten,
    load_params_file,
    unknown_parameter,
)
from .resolution import MAX_POSITION_NORM
from .validation import (
    machine_size,
    millimetre_reason,
    paired_joints_reason,
    require_usable,
    shared_joint_pairs,
    unusable_reason,
)

if TYPE_CHECKING:
    from .collision.params import CollisionScene

__all__ = [
    "ARCHITECTURE_PARAMETERS",
    "PARAMETER_DEFAULTS",
    "HomePoseWarning",
    "Manipulator",
    "required_parameters",
]

#: Parameters of the model with their defaults; ``None`` means required.
PARAMETER_DEFAULTS: dict[str, Any] = {
    "frame_id": "base",
    "geometry.base_joints": None,
    "geometry.platform_joints": None,
    "geometry.home_position": None,
    "geometry.base_joint_axes": [],
    "geometry.platform_joint_axes": [],
    "limits.leg_length_min": None,
    "limits.leg_length_max": None,
    "limits.base_joint_max_angle": None,
    "limits.platform_joint_max_angle": None,
    "limits.leg_diameter": 0.0,
    "geometry.paired_joint_length": 0.0,
    "limits.singularity_min": 0.0,
    "pose.position": None,
    "geometry.architecture": "ups",
    "geometry.rail_directions": [],
    "geometry.crank_axes": [],
    "geometry.crank_zero_directions": [],
    "geometry.crank_lengths": [],
    "geometry.leg_lengths": [],
    "geometry.branch": [],
    "limits.actuator_min": [],
    "limits.actuator_max": [],
    "limits.transmission_min": 0.1,
}
#: The parameters only one architecture has (the others refuse them when given), and the
#: required ones (``None`` in :data:`PARAMETER_DEFAULTS` or listed here) of each.
ARCHITECTURE_PARAMETERS: dict[str, tuple[str, ...]] = {
    "ups": ("limits.leg_length_min", "limits.leg_length_max", "geometry.paired_joint_length"),
    "pus": (
        "geometry.rail_directions",
        "geometry.leg_lengths",
        "geometry.branch",
        "limits.actuator_min",
        "limits.actuator_max",
        "limits.transmission_min",
    ),
    "rus": (
        "geometry.crank_axes",
        "geometry.crank_zero_directions",
        "geometry.crank_lengths",
        "geometry.leg_lengths",
        "geometry.branch",
        "limits.actuator_min",
        "limits.actuator_max",
        "limits.transmission_min",
    ),
}
_REQUIRED: dict[str, tuple[str, ...]] = {
    "ups": ("limits.leg_length_min", "limits.leg_length_max"),
    "pus": (
        "geometry.rail_directions",
        "geometry.leg_lengths",
        "limits.actuator_min",
        "limits.actuator_max",
    ),
    "rus": (
        "geometry.crank_axes",
        "geometry.crank_zero_directions",
        "geometry.crank_lengths",
        "geometry.leg_lengths",
        "limits.actuator_min",
        "limits.actuator_max",
    ),
}
_MODEL_GROUPS = ("geometry.", "limits.", "pose.")


#: Every parameter that belongs to one architecture only.
_SPECIFIC = frozenset(name for names in ARCHITECTURE_PARAMETERS.values() for name in names)


def required_parameters(architecture: str) -> tuple[str, ...]:
    """The model parameters a model of this architecture must be given (``pose.position``
    excluded: it defaults to the home position), in :data:`PARAMETER_DEFAULTS` order."""
    needed = set(_REQUIRED.get(architecture, ()))
    return tuple(
        name
        for name, default in PARAMETER_DEFAULTS.items()
        if name != "pose.position"
        and name.startswith(_MODEL_GROUPS)
        and (name in needed or (default is None and name not in _SPECIFIC))
    )


def _unset(value: Any) -> bool:
    """A parameter left out: None, or an empty list (how ROS holds an empty array)."""
    if value is None:
        return True
    if isinstance(value, (str, bytes)):
        return False
    return bool(np.ndim(value)) and np.size(value) == 0


def _foreign_parameter(architecture: str, flat: Mapping[str, Any]) -> str | None:
    """Why a parameter of another architecture is refused (given, not empty, not the default),
    or None."""
    own = set(ARCHITECTURE_PARAMETERS[architecture])
    for name in PARAMETER_DEFAULTS:
        if name not in _SPECIFIC or name in own or name not in flat or _unset(flat[name]):
            continue
        default = PARAMETER_DEFAULTS[name]
        if default is not None and not _unset(default) and flat[name] == default:
            continue  # a scalar at its default (a node holds every declared parameter)
        owners = [arch for arch, names in ARCHITECTURE_PARAMETERS.items() if name in names]
        return (
            f"{name}: a parameter of geometry.architecture {' or '.join(owners)}, given for "
            f"{architecture} (value {_describe(flat[name])}); remove it or change the "
            "architecture"
        )
    return None


def _stroke(
    low_name: str, low: Any, high_name: str, high: Any
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A per-leg (min, max) pair of lengths, m, with min < max for every leg."""
    length_min = _length(low_name, _per_leg(low_name, low))
    length_max = _length(high_name, _per_leg(high_name, high))
    bad = np.flatnonzero(length_min >= length_max)
    if bad.size:
        i = bad[0]
        msg = (
            f"{low_name}: expected < {high_name} for every leg, "
            f"got {length_min[i]:g} >= {length_max[i]:g} m for leg {i + 1}"
        )
        raise GeometryError(msg)
    return length_min, length_max


def _directions(name: str, value: Any, what: str) -> NDArray[np.float64]:
    """18 numbers as six unit vectors; a zero vector is refused with its leg."""
    array = _numbers(name, value)
    if array.size != 18:
        msg = f"{name}: expected 18 numbers (6 {what}s × x, y, z), got {array.size}"
        raise GeometryError(msg)
    rows = array.reshape(6, 3)
    norms = np.linalg.norm(rows, axis=1)
    zero = np.flatnonzero(norms < 1e-9)
    if zero.size:
        msg = (
            f"{name}: expected non-zero directions, the {what} of leg {zero[0] + 1} has zero "
            f"length ({rows[zero[0]].tolist()})"
        )
        raise GeometryError(msg)
    # Rows already of unit length to rounding are kept as given, so that a model written back
    # by to_parameters reads as the same model.
    scale = np.where(np.abs(norms - 1.0) <= 4e-16, 1.0, norms)
    unit: NDArray[np.float64] = rows / scale[:, None]
    return unit


def _positive(name: str, value: Any) -> NDArray[np.float64]:
    array = _length(name, _per_leg(name, value))
    bad = np.flatnonzero(array <= 0.0)
    if bad.size:
        msg = f"{name}: expected values > 0 m, got {array[bad[0]]:g} for leg {bad[0] + 1}"
        raise GeometryError(msg)
    return array


def _architecture_parts(architecture: str, values: Mapping[str, Any]) -> dict[str, Any]:
    """The pus or rus fields of the model from its parameters, validated."""
    parts: dict[str, Any] = {
        "leg_lengths": _positive("geometry.leg_lengths", values["geometry.leg_lengths"])
    }
    branch_value = values["geometry.branch"]
    branch = _per_leg("geometry.branch", [1.0] if _unset(branch_value) else branch_value)
    bad = np.flatnonzero(np.abs(branch) != 1.0)
    if bad.size:
        msg = (
            f"geometry.branch: expected +1 or -1 for every leg, got {branch[bad[0]]:g} for "
            f"leg {bad[0] + 1}"
        )
        raise GeometryError(msg)
    parts["branch"] = branch
    if architecture == "pus":
        parts["rail_directions"] = _directions(
            "geometry.rail_directions", values["geometry.rail_directions"], "rail"
        )
        low, high = _stroke(
            "limits.actuator_min",
            values["limits.actuator_min"],
            "limits.actuator_max",
            values["limits.actuator_max"],
        )
    else:
        axes = _directions("geometry.crank_axes", values["geometry.crank_axes"], "crank axis")
        zero = _directions(
            "geometry.crank_zero_directions",
            values["geometry.crank_zero_directions"],
            "crank zero direction",
        )
        dots = np.einsum("ij,ij->i", axes, zero)
        bad = np.flatnonzero(np.abs(dots) > 1e-6)
        if bad.size:
            i = bad[0]
            msg = (
                f"geometry.crank_zero_directions: expected each perpendicular to its crank axis "
                f"(geometry.crank_axes), leg {i + 1} has cos(angle) = {dots[i]:.6g} "
                f"(zero direction {np.round(zero[i], 6).tolist()}, axis "
                f"{np.round(axes[i], 6).tolist()})"
            )
            raise GeometryError(msg)
        parts["crank_axes"] = axes
        parts["crank_zero_directions"] = zero
        parts["crank_lengths"] = _positive(
            "geometry.crank_lengths", values["geometry.crank_lengths"]
        )
        low = _per_leg("limits.actuator_min", values["limits.actuator_min"])
        high = _per_leg("limits.actuator_max", values["limits.actuator_max"])
        wide = np.flatnonzero(~((low < high) & (high - low < 2.0 * math.pi)))
        if wide.size:
            i = wide[0]
            msg = (
                f"limits.actuator_min: expected limits.actuator_min < limits.actuator_max < "
                f"limits.actuator_min + 2 pi (rad) for every leg, got {low[i]:g} and {high[i]:g} "
                f"for leg {i + 1}"
            )
            raise GeometryError(msg)
    parts["actuator_min"], parts["actuator_max"] = low, high
    tau = _numbers("limits.transmission_min", values["limits.transmission_min"])
    if tau.size != 1 or not 0.0 < tau[0] < 1.0:
        msg = (
            f"limits.transmission_min: expected one value in (0, 1), got "
            f"{_describe(values['limits.transmission_min'])}"
        )
        raise GeometryError(msg)
    parts["transmission_min"] = float(tau[0])
    return parts


def _with_home_axes(manipulator: Manipulator, base: bool, platform: bool) -> Manipulator:
    """The model with its default joint axes (the leg directions at the home pose: base axes
    from the base end towards B_i, turned back to crank angle 0 for rus; platform axes
    reversed), after checking that every leg has a solution and a non-zero length there."""
    from dataclasses import replace

    legs = architecture_module(manipulator.architecture)
    home = manipulator.home_position + manipulator.platform_joints
    q, ik = legs.inverse_kinematics(manipulator, home)
    unsolved = np.flatnonzero(~(ik >= 0.0))
    if unsolved.size:
        i = unsolved[0]
        msg = (
            f"geometry.home_position: expected a pose every leg can reach, leg {i + 1} has no "
            f"inverse-kinematics solution at {manipulator.home_position.tolist()} m (identity "
            f"orientation; ik margin {ik[i]:.6g} m: its length geometry.leg_lengths does not "
            "reach its joint)"
        )
        raise GeometryError(msg)
    vectors = home - legs.base_ends(manipulator, q)
    lengths = np.linalg.norm(vectors, axis=1)
    degenerate = np.flatnonzero(lengths < 1e-9)
    if degenerate.size:
        msg = (
            f"geometry.home_position: expected non-zero legs at the home pose, "
            f"leg {degenerate[0] + 1} has zero length there"
        )
        raise GeometryError(msg)
    directions = vectors / lengths[:, None]
    changes: dict[str, Any] = {}
    if base:
        axes = directions
        if manipulator.architecture == "rus":
            from .architectures.rus import rotate_about

            assert manipulator.crank_axes is not None
            axes = rotate_about(manipulator.crank_axes, -q, directions)
        changes["base_joint_axes"] = _frozen(axes)
    if platform:
        changes["platform_joint_axes"] = _frozen(-directions)
    return replace(manipulator, **changes) if changes else manipulator


class HomePoseWarning(UserWarning):
    """The home pose (home position, identity orientation) violates a constraint."""


def _describe(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _numbers(name: str, value: Any) -> NDArray[np.float64]:
    """A flat float array from a parameter value, refusing non-numbers and non-finite values."""
    if isinstance(value, (str, bytes)) or value is None:
        msg = f"{name}: expected numbers, got {_describe(value)}"
        raise ConfigError(msg)
    items = list(np.ravel(np.asarray(value, dtype=object))) if np.ndim(value) else [value]
    for item in items:
        if isinstance(item, (bool, np.bool_)) or not isinstance(item, (int, float, np.number)):
            msg = f"{name}: expected numbers, got {_describe(value)}"
            raise ConfigError(msg)
    array = np.asarray(items, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        msg = f"{name}: expected finite numbers, got {_describe(value)}"
        raise ConfigError(msg)
    return array


def _length(name: str, array: NDArray[np.float64]) -> NDArray[np.float64]:
    """Refuse lengths (m) beyond MAX_POSITION_NORM, where margins would stop being finite."""
    if array.size and float(np.max(np.abs(array))) > MAX_POSITION_NORM:
        shown = _describe(array.tolist())
        msg = f"{name}: expected values within ±{MAX_POSITION_NORM:g} m, got {shown}"
        raise GeometryError(msg)
    return array


def _joint_array(name: str, value: Any) -> NDArray[np.float64]:
    array = _length(name, _numbers(name, value))
    if array.size != 18:
        msg = f"{name}: expected 18 numbers (6 joints × x, y, z), got {array.size}"
        raise GeometryError(msg)
    return array.reshape(6, 3)


def _vector3(name: str, value: Any) -> NDArray[np.float64]:
    array = _length(name, _numbers(name, value))
    if array.size != 3:
        msg = f"{name}: expected 3 numbers (x, y, z), got {array.size}"
        raise GeometryError(msg)
    return array


def _per_leg(name: str, value: Any) -> NDArray[np.float64]:
    array = _numbers(name, value)
    if array.size not in (1, 6):
        msg = f"{name}: expected 1 or 6 numbers, got {array.size}"
        raise GeometryError(msg)
    return np.broadcast_to(array, (6,)).copy()


def _axes(name: str, value: Any) -> NDArray[np.float64] | None:
    array = _numbers(name, value)
    if array.size == 0:
        return None
    if array.size != 18:
        msg = f"{name}: expected 18 numbers (6 axes × x, y, z) or an empty list, got {array.size}"
        raise GeometryError(msg)
    axes = array.reshape(6, 3)
    norms = np.linalg.norm(axes, axis=1)
    zero = np.flatnonzero(norms < 1e-12)
    if zero.size:
        msg = f"{name}: expected non-zero axes, axis of joint {zero[0] + 1} is zero"
        raise GeometryError(msg)
    unit: NDArray[np.float64] = axes / norms[:, None]
    return unit


def _angles3(name: str, value: Any) -> NDArray[np.float64]:
    """Three angles (φ, θ, ψ) in rad, within ±1e6 (the cell's frame orientations)."""
    array = _numbers(name, value)
    if array.size != 3:
        msg = f"{name}: expected 3 numbers (phi, theta, psi) in rad, got {array.size}"
        raise ConfigError(msg)
    if float(np.max(np.abs(array))) > 1e6:
        msg = f"{name}: expected angles within ±1e6 rad, got {_describe(array.tolist())}"
        raise ConfigError(msg)
    return array


def _cell_transform(flat: Mapping[str, Any], group: str, offset: str) -> NDArray[np.float64]:
    """The 4×4 transform of the cell's ``tool`` (P <- C: ``offset``, ``orientation``) or
    ``work`` (O <- W: ``origin``, ``orientation``) frame, from its parameters (default zero),
    as :mod:`hexapod_workspace.core.frames` reads them."""
    from .rotations import tt_to_matrix

    transform = np.eye(4)
    transform[:3, 3] = _vector3(f"{group}.{offset}", flat.get(f"{group}.{offset}", [0.0] * 3))
    angles = _angles3(f"{group}.orientation", flat.get(f"{group}.orientation", [0.0] * 3))
    transform[:3, :3] = tt_to_matrix(angles)
    return transform


def _singularity_min(value: Any) -> float:
    """``limits.singularity_min``: one finite number in [0, 1] (σ_min of a matrix of unit
    rows is at most √6, but a limit above 1 leaves no practical workspace)."""
    name = "limits.singularity_min"
    array = _numbers(name, value)
    if array.size != 1:
        msg = f"{name}: expected one number, got {array.size}"
        raise GeometryError(msg)
    if not 0.0 <= array[0] <= 1.0:
        msg = f"{name}: expected a value in [0, 1] (0 disables the check), got {array[0]:g}"
        raise GeometryError(msg)
    return float(array[0])


def _frozen(array: NDArray[np.float64]) -> NDArray[np.float64]:
    array = np.ascontiguousarray(array, dtype=np.float64)
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Manipulator:
    """A 6-UPS Gough-Stewart platform: geometry, joint axes and limits, validated.

    Attributes
    ----------
    base_joints : ndarray, shape (6, 3)
        a_i = OA_i, centres of the base (universal) joints, base frame, m.
    platform_joints : ndarray, shape (6, 3)
        b_i = CB'_i, centres of the platform (spherical) joints, mobile frame (origin at the
        tool tip C), m.
    base_joint_axes : ndarray, shape (6, 3)
        jA_i, unit axes of symmetry of the base joints, base frame, pointing into the legs.
    platform_joint_axes : ndarray, shape (6, 3)
        jB_i, unit axes of symmetry of the platform joints, mobile frame, pointing into the legs.
    leg_length_min, leg_length_max : ndarray, shape (6,)
        Leg length limits, m.
    base_joint_max_angle, platform_joint_max_angle : ndarray, shape (6,)
        Maximum angle between a joint axis and its leg, rad, in (0, π).
    leg_diameter : float
        D, m; legs must stay at least D apart (segment distance); 0 disables the check.
    paired_joint_length : float
        c, m (ups): along each leg, from a joint centre it shares with another leg, the length
        the joint occupies; the interference of two legs that share a joint is measured on the
        rest of them (their free lengths). 0 when no legs share a joint or D = 0.
    home_position : ndarray, shape (3,)
        Home position OC, base frame, m; the default joint axes are the leg directions there.
    position : ndarray, shape (3,)
        Default tool-tip position OC (``pose.position``), base frame, m.
    frame_id : str
        Name of the base frame in published results.
    axes_from_home : tuple of bool
        Whether the (base, platform) joint axes were derived from the home pose (not given).
    singularity_min : float
        σ_lim ≥ 0: the smallest singular value of the homogenised Plücker matrix of the legs
        allowed (constraint ``singularity``, see :mod:`~hexapod_workspace.core.constraint_table`);
        0 disables the constraint (dimensionless).
    architecture : str
        ``"ups"`` (legs of variable length between fixed joints, the default), ``"pus"``
        (slides on rails, legs of fixed length) or ``"rus"`` (cranks, rods of fixed length):
        :mod:`hexapod_workspace.core.architectures`. For pus and rus, ``base_joints`` are the
        rail origins or crank pivots A0_i, ``leg_length_min`` and ``leg_length_max`` both hold
        the fixed leg lengths, and the base joint axes of rus are given at crank angle 0.
    leg_lengths, branch : ndarray, shape (6,), or None
        pus/rus: fixed leg (rod) lengths L_i, m; assembly branch ±1 of each leg.
    rail_directions : ndarray, shape (6, 3), or None
        pus: unit rail directions u_i, base frame.
    crank_axes, crank_zero_directions : ndarray, shape (6, 3), or None
        rus: unit crank axes w_i and zero directions e_i ⟂ w_i, base frame.
    crank_lengths : ndarray, shape (6,), or None
        rus: crank lengths r_i, m.
    actuator_min, actuator_max : ndarray, shape (6,), or None
        pus: slide stroke along the rail, m; rus: crank range, rad (max − min < 2π).
    transmission_min : float
        pus/rus: smallest |τ_i| allowed (constraint ``transmission``), in (0, 1).
    collision : CollisionScene or None
        The collision scene (``collision.*``: platform and tool bodies, obstacles), with its
        moving bodies in this model's mobile frame; None when no scene is declared (then the
        ``collision`` constraint does not exist: +inf, left out of the interfaces).
    """

    base_joints: NDArray[np.float64]
    platform_joints: NDArray[np.float64]
    base_joint_axes: NDArray[np.float64]
    platform_joint_axes: NDArray[np.float64]
    leg_length_min: NDArray[np.float64]
    leg_length_max: NDArray[np.float64]
    base_joint_max_angle: NDArray[np.float64]
    platform_joint_max_angle: NDArray[np.float64]
    leg_diameter: float
    home_position: NDArray[np.float64]
    position: NDArray[np.float64]
    frame_id: str = "base"
    axes_from_home: tuple[bool, bool] = field(default=(True, True))
    singularity_min: float = 0.0
    architecture: str = "ups"
    leg_lengths: NDArray[np.float64] | None = None
    branch: NDArray[np.float64] | None = None
    rail_directions: NDArray[np.float64] | None = None
    crank_axes: NDArray[np.float64] | None = None
    crank_zero_directions: NDArray[np.float64] | None = None
    crank_lengths: NDArray[np.float64] | None = None
    actuator_min: NDArray[np.float64] | None = None
    actuator_max: NDArray[np.float64] | None = None
    transmission_min: float = 0.1
    collision: CollisionScene | None = None
    paired_joint_length: float = 0.0

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_mapping(cls, parameters: Mapping[str, Any], *, warn: bool = True) -> Manipulator:
        """Build and validate a manipulator from parameters.

        Parameters
        ----------
        parameters : Mapping
            Nested (as in the parameters file under ``ros__parameters``) or dotted names
            (``"geometry.base_joints"``, as a ROS node holds them), or mixed. Keys outside the
            ``geometry``, ``limits`` and ``pose`` groups and ``frame_id`` are ignored (they
            belong to the node: resolution, recording).
        warn : bool
            Emit a :class:`HomePoseWarning` when the home pose violates a constraint or the
            platform is singular there (:func:`~hexapod_workspace.core.validation.unusable_reason`).
            The node and :meth:`from_params_file` refuse such a model instead.

        Returns
        -------
        Manipulator

        Raises
        ------
        GeometryError
            Invalid geometry or limits (names the parameter, the expectation and the value),
            coincident base or platform joints, a zero-length leg at the home pose.
        ConfigError
            Missing or unknown model parameters, non-numbers, non-finite values.
        """
        flat = flatten(parameters)
        unknown = sorted(
            name
            for name in flat
            if name.startswith(_MODEL_GROUPS)
            and name not in PARAMETER_DEFAULTS
            and name not in CELL_PARAMETERS
        )
        if unknown:
            msg = f"{unknown[0]}: unknown parameter (expected one of {_model_names()})"
            raise ConfigError(msg)
        values = dict(PARAMETER_DEFAULTS)
        values.update({k: v for k, v in flat.items() if k in PARAMETER_DEFAULTS})
        if values["pose.position"] is None:
            values["pose.position"] = values["geometry.home_position"]
        architecture = values["geometry.architecture"]
        if architecture not in ARCHITECTURES:
            msg = (
                f"geometry.architecture: expected one of {', '.join(ARCHITECTURES)}, "
                f"got {_describe(architecture)}"
            )
            raise ConfigError(msg)
        foreign = _foreign_parameter(architecture, flat)
        if foreign is not None:
            raise ConfigError(foreign)
        needed = set(_REQUIRED[architecture])
        missing = [
            name
            for name, default in PARAMETER_DEFAULTS.items()
            if (name in needed or (default is None and name not in _SPECIFIC))
            and _unset(values[name])
        ]
        if missing:
            msg = f"{missing[0]}: required parameter is missing"
            raise ConfigError(msg)

        frame_id = values["frame_id"]
        if not isinstance(frame_id, str) or not frame_id.strip():
            msg = f"frame_id: expected a non-empty string, got {_describe(frame_id)}"
            raise ConfigError(msg)

        base_joints = _joint_array("geometry.base_joints", values["geometry.base_joints"])
        platform_joints = _joint_array(
            "geometry.platform_joints", values["geometry.platform_joints"]
        )
        paired = paired_joints_reason(base_joints, platform_joints, architecture)
        if paired is not None:
            raise GeometryError(paired)
        home = _vector3("geometry.home_position", values["geometry.home_position"])
        position = _vector3("pose.position", values["pose.position"])
        if architecture == "ups":
            length_min, length_max = _stroke(
                "limits.leg_length_min",
                values["limits.leg_length_min"],
                "limits.leg_length_max",
                values["limits.leg_length_max"],
            )
            if np.any(length_min < 0.0):
                msg = f"limits.leg_length_min: expected values >= 0 m, got {length_min.min():g}"
                raise GeometryError(msg)
            size = machine_size(base_joints, platform_joints, home)
            for name, limit in (
                ("limits.leg_length_min", length_min),
                ("limits.leg_length_max", length_max),
            ):
                unit_reason = millimetre_reason(name, limit, size)
                if unit_reason is not None:
                    raise GeometryError(unit_reason)
            legs: dict[str, Any] = {}
        else:
            legs = _architecture_parts(architecture, values)
            length_min = length_max = legs["leg_lengths"]
        angles = {}
        for name in ("limits.base_joint_max_angle", "limits.platform_joint_max_angle"):
            angle = _per_leg(name, values[name])
            outside = np.flatnonzero((angle <= 0.0) | (angle >= math.pi))
            if outside.size:
                msg = (
                    f"{name}: expected angles in (0, pi) rad, "
                    f"got {angle[outside[0]]:g} for leg {outside[0] + 1}"
                )
                raise GeometryError(msg)
            angles[name] = angle
        diameter = _length(
            "limits.leg_diameter", _numbers("limits.leg_diameter", values["limits.leg_diameter"])
        )
        if diameter.size != 1:
            msg = f"limits.leg_diameter: expected one number, got {diameter.size}"
            raise GeometryError(msg)
        if diameter[0] < 0.0:
            msg = f"limits.leg_diameter: expected a value >= 0 m, got {diameter[0]:g}"
            raise GeometryError(msg)
        paired_length = _paired_joint_length(
            values["geometry.paired_joint_length"],
            base_joints,
            platform_joints,
            float(diameter[0]),
            length_min,
            machine_size(base_joints, platform_joints, home),
        )

        base_axes = _axes("geometry.base_joint_axes", values["geometry.base_joint_axes"])
        platform_axes = _axes(
            "geometry.platform_joint_axes", values["geometry.platform_joint_axes"]
        )
        frozen_legs: dict[str, Any] = {
            key: _frozen(value) if isinstance(value, np.ndarray) else value
            for key, value in legs.items()
        }
        manipulator = cls(
            base_joints=_frozen(base_joints),
            platform_joints=_frozen(platform_joints),
            base_joint_axes=_frozen(np.zeros((6, 3)) if base_axes is None else base_axes),
            platform_joint_axes=_frozen(
                np.zeros((6, 3)) if platform_axes is None else platform_axes
            ),
            leg_length_min=_frozen(length_min),
            leg_length_max=_frozen(length_max),
            base_joint_max_angle=_frozen(angles["limits.base_joint_max_angle"]),
            platform_joint_max_angle=_frozen(angles["limits.platform_joint_max_angle"]),
            leg_diameter=float(diameter[0]),
            paired_joint_length=paired_length,
            home_position=_frozen(home),
            position=_frozen(position),
            frame_id=frame_id,
            axes_from_home=(base_axes is None, platform_axes is None),
            singularity_min=_singularity_min(values["limits.singularity_min"]),
            architecture=architecture,
            **frozen_legs,
        )
        manipulator = _with_home_axes(manipulator, base_axes is None, platform_axes is None)
        if any(name.startswith(COLLISION_PARAMETERS) for name in flat):
            manipulator = _with_scene(manipulator, flat)
        if warn:
            reason = unusable_reason(manipulator)
            if reason is not None:
                warnings.warn(reason, HomePoseWarning, stacklevel=2)
        return manipulator

    @classmethod
    def from_params_file(cls, path: str | Path, *, warn: bool = True) -> Manipulator:
        """Build a manipulator from a ROS 2 parameters file (root key ``hexapod_workspace``
        or ``/**``).

        Every name in the file must be known: the model's, the node's (``resolution.*``,
        ``check.*``, ``recording.*``, read by the node only) or ROS's own (``use_sim_time``,
        ...). A misspelt name is reported at its own level (``limitz: unknown section``).
        A model whose home pose is unreachable or singular is refused
        (:func:`~hexapod_workspace.core.validation.require_usable`, with a unit hint). Every
        message starts with the file's name.

        Parameters
        ----------
        path : str or pathlib.Path
            YAML parameters file, as in docs/configuration.md.
        warn : bool
            No effect (a file's unusable model is refused, not warned about); accepted so that
            callers written when it warned keep working.

        Returns
        -------
        Manipulator

        Raises
        ------
        ConfigError
            Unreadable file, unknown names, a model :meth:`from_mapping` refuses, or an
            unreachable or singular home pose (:class:`GeometryError`).
        """
        parameters = load_params_file(path)
        unknown = unknown_parameter(
            parameters,
            (
                *PARAMETER_DEFAULTS,
                *NODE_PARAMETERS,
                *CELL_PARAMETERS,
                *COLLISION_PARAMETERS,
                *ROS_PARAMETERS,
            ),
        )
        if unknown is not None:
            msg = f"parameters file {path}: {unknown}"
            raise ConfigError(msg)
        try:
            return require_usable(cls.from_mapping(parameters, warn=False))
        except ConfigError as error:
            msg = f"parameters file {path}: {error}"
            raise type(error)(msg) from error

    @classmethod
    def example(cls, *, warn: bool = True) -> Manipulator:
        """The packaged example GPM (``config/example_gpm.yaml``), from any working directory.

        Returns
        -------
        Manipulator
        """
        from .._resources import example_config_path

        return cls.from_params_file(example_config_path(), warn=warn)

    # ------------------------------------------------------------------ views
    def to_parameters(self) -> dict[str, Any]:
        """The model as ROS parameters (dotted names, plain Python values).

        ``Manipulator.from_mapping(m.to_parameters())`` rebuilds an equal manipulator; joint axes
        that were derived from the home pose are given back as empty lists so that they keep
        following ``geometry.home_position``.

        Returns
        -------
        dict
            ``{"frame_id": str, "geometry.base_joints": [18 floats], ...}``.
        """

        def floats(array: NDArray[np.float64]) -> list[float]:
            return [float(v) for v in np.ravel(array)]

        def optional(array: NDArray[np.float64] | None) -> list[float]:
            return [] if array is None else floats(array)

        ups = self.architecture == "ups"

        scene = dict(self.collision.parameters) if self.collision is not None else {}
        return {
            **scene,
            "frame_id": self.frame_id,
            "geometry.base_joints": floats(self.base_joints),
            "geometry.platform_joints": floats(self.platform_joints),
            "geometry.home_position": floats(self.home_position),
            "geometry.base_joint_axes": []
            if self.axes_from_home[0]
            else floats(self.base_joint_axes),
            "geometry.platform_joint_axes": []
            if self.axes_from_home[1]
            else floats(self.platform_joint_axes),
            "limits.leg_length_min": floats(self.leg_length_min) if ups else [],
            "limits.leg_length_max": floats(self.leg_length_max) if ups else [],
            "limits.base_joint_max_angle": floats(self.base_joint_max_angle),
            "limits.platform_joint_max_angle": floats(self.platform_joint_max_angle),
            "limits.leg_diameter": float(self.leg_diameter),
            "geometry.paired_joint_length": float(self.paired_joint_length),
            "limits.singularity_min": float(self.singularity_min),
            "pose.position": floats(self.position),
            "geometry.architecture": self.architecture,
            "geometry.rail_directions": optional(self.rail_directions),
            "geometry.crank_axes": optional(self.crank_axes),
            "geometry.crank_zero_directions": optional(self.crank_zero_directions),
            "geometry.crank_lengths": optional(self.crank_lengths),
            "geometry.leg_lengths": optional(self.leg_lengths),
            "geometry.branch": optional(self.branch),
            "limits.actuator_min": optional(self.actuator_min),
            "limits.actuator_max": optional(self.actuator_max),
            "limits.transmission_min": float(self.transmission_min),
        }

    def with_position(self, position: Any) -> Manipulator:
        """A copy whose default position (``pose.position``) is ``position`` (m, base frame)."""
        from dataclasses import replace

        return replace(self, position=_frozen(_vector3("position", position)))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Manipulator):
            return NotImplemented
        arrays_equal = all(
            np.array_equal(getattr(self, name), getattr(other, name))
            for name in (
                "base_joints",
                "platform_joints",
                "base_joint_axes",
                "platform_joint_axes",
                "leg_length_min",
                "leg_length_max",
                "base_joint_max_angle",
                "platform_joint_max_angle",
                "home_position",
                "position",
            )
        )
        optional_equal = all(
            (getattr(self, name) is None and getattr(other, name) is None)
            or (
                getattr(self, name) is not None
                and getattr(other, name) is not None
                and np.array_equal(getattr(self, name), getattr(other, name))
            )
            for name in (
                "leg_lengths",
                "branch",
                "rail_directions",
                "crank_axes",
                "crank_zero_directions",
                "crank_lengths",
                "actuator_min",
                "actuator_max",
            )
        )
        return (
            arrays_equal
            and optional_equal
            and self.architecture == other.architecture
            and self.transmission_min == other.transmission_min
            and self.leg_diameter == other.leg_diameter
            and self.paired_joint_length == other.paired_joint_length
            and self.singularity_min == other.singularity_min
            and self.frame_id == other.frame_id
            and self.axes_from_home == other.axes_from_home
            and self.collision == other.collision
        )

    __hash__ = None  # type: ignore[assignment]

    @property
    def shared_base_pairs(self) -> NDArray[np.bool_]:
        """Leg pairs i < j (``numpy.triu_indices(6, 1)`` order, shape (15,)) that share a base
        joint."""
        return shared_joint_pairs(self.base_joints)

    @property
    def shared_platform_pairs(self) -> NDArray[np.bool_]:
        """Leg pairs i < j (shape (15,)) that share a platform joint."""
        return shared_joint_pairs(self.platform_joints)


def _paired_joint_length(
    value: Any,
    base_joints: NDArray[np.float64],
    platform_joints: NDArray[np.float64],
    diameter: float,
    length_min: NDArray[np.float64],
    size: float,
) -> float:
    """``geometry.paired_joint_length`` validated against the joints that legs share (m).

    Required (> 0) when legs share a joint and the interference check is on; refused when no
    legs share one (it would change nothing: a value the user meant for another machine); less
    than the shortest leg's length once per shared end, so that every leg keeps a free length.
    """
    name = "geometry.paired_joint_length"
    length = _length(name, _numbers(name, value))
    if length.size != 1:
        msg = f"{name}: expected one number, got {length.size}"
        raise GeometryError(msg)
    c = float(length[0])
    if c < 0.0:
        msg = f"{name}: expected a value >= 0 m, got {c:g}"
        raise GeometryError(msg)
    unit_reason = millimetre_reason(name, c, size)
    if unit_reason is not None:
        raise GeometryError(unit_reason)
    base, platform = shared_joint_pairs(base_joints), shared_joint_pairs(platform_joints)
    pair_i, pair_j = np.triu_indices(6, 1)
    if not (base.any() or platform.any()):
        if c > 0.0:
            gaps = [
                float(np.min(np.linalg.norm(joints[pair_i] - joints[pair_j], axis=-1)))
                for joints in (base_joints, platform_joints)
            ]
            msg = (
                f"{name}: given ({c:g} m), but no two legs share a joint (the closest joint "
                f"centres are {min(gaps):.3g} m apart); remove it"
            )
            raise GeometryError(msg)
        return 0.0
    if diameter > 0.0 and c == 0.0:
        first = int(np.flatnonzero(base | platform)[0])
        where = "base" if base[first] else "platform"
        msg = (
            f"{name}: required when legs share a joint and limits.leg_diameter > 0 (legs "
            f"{pair_i[first] + 1} and {pair_j[first] + 1} share a {where} joint): the length "
            "of each leg from the shared joint centre that the joint occupies, m; their "
            "interference is measured on the rest"
        )
        raise GeometryError(msg)
    ends = np.zeros(6)
    for shared in (base, platform):
        legs = np.unique(np.concatenate([pair_i[shared], pair_j[shared]]))
        ends[legs] += 1.0
    short = np.flatnonzero(ends * c >= length_min)
    if short.size:
        k = int(short[0])
        msg = (
            f"{name}: expected less than {length_min[k] / ends[k]:g} m (leg {k + 1}: "
            f"limits.leg_length_min {length_min[k]:g} m over its {int(ends[k])} shared "
            f"joint(s), so that it keeps a free length), got {c:g}"
        )
        raise GeometryError(msg)
    return c


def _with_scene(manipulator: Manipulator, flat: Mapping[str, Any]) -> Manipulator:
    """The model with its collision scene (``collision.*``), built in the platform frame P.

    Obstacles given in the work frame are placed with ``work.*``; the tool body starts at the
    tool centre point of the active tool (``tool.*``, or ``tools.T<n>.*`` when ``tool.number``
    is n > 0), so the home pose is checked with the tool the machine carries. A scene with no
    pair to check (no tool and no obstacle) leaves the model without one. Refuses, naming the
    pair, an obstacle or body in collision at the home pose.
    """
    from dataclasses import replace

    from .collision.params import collision_scene

    work = _cell_transform(flat, "work", "origin")
    tool = _cell_transform(flat, *_active_tool_group(flat))
    scene = collision_scene(flat, work_transform=work, tool_transform=tool, manipulator=manipulator)
    if scene.pair_count == 0:
        return manipulator
    return replace(manipulator, collision=scene)


def _tool_number(value: Any) -> int:
    """``tool.number`` as an int >= 0 (0: ``tool.*``, n: ``tools.T<n>.*``), else ConfigError."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        msg = f"tool.number: expected an integer >= 0 (0 = tool.offset), got {_describe(value)}"
        raise ConfigError(msg)
    return int(value)


def _unknown_tool(number: int, defined: Iterable[int]) -> ConfigError:
    """The refusal of a ``tool.number`` that names no entry of the tool table."""
    have = ", ".join(f"T{n}" for n in sorted(defined)) or "none"
    return ConfigError(
        f"tool.number: tool {number} is not in the tool table (tools.T<n>; defined: {have})"
    )


def _active_tool_group(flat: Mapping[str, Any]) -> tuple[str, str]:
    """The parameter group and offset name of the tool ``tool.number`` selects: ``("tool",
    "offset")`` for 0, ``("tools.T<n>", "offset")`` for n (ConfigError naming ``tool.number``
    otherwise, worded as the cell's loader words it)."""
    number = _tool_number(flat.get("tool.number", 0))
    if number == 0:
        return "tool", "offset"
    group = f"tools.T{number}"
    if f"{group}.offset" not in flat:
        tags = {name.split(".")[1][1:] for name in flat if name.startswith("tools.T")}
        raise _unknown_tool(number, (int(tag) for tag in tags if tag.isdigit()))
    return group, "offset"


def _model_names() -> str:
    return ", ".join(name for name in PARAMETER_DEFAULTS if name.startswith(_MODEL_GROUPS))
