"""The one place a model is built: a parameters file or mapping in, a validated
:class:`~hexapod_workspace.core.model.manipulator.Manipulator` out, or a refusal in one line.

Above the evaluator: besides the parameters' own checks (:mod:`~hexapod_workspace.core.base.values`,
:mod:`~hexapod_workspace.core.base.validation`) a model is refused, or warned about, when no verdict
can be given for it (:func:`unusable_reason`):

* **a platform singular at the home pose** (:func:`home_conditioning`): the 6×6 matrix whose
  rows are the legs' normalised Plücker coordinates ``(n_i, (R·b_i × n_i) / ρ)`` (identity R at
  the home pose, ρ the platform radius max |b_i|, so that both halves are dimensionless and of
  order 1) has its smallest singular value below
  :data:`~hexapod_workspace.core.base.validation.SINGULAR_TOLERANCE`. Six legs through one point,
  six parallel legs, a planar layout with every leg in the plane: rank < 6, the leg lengths do
  not fix the platform and no verdict about its orientation means anything;
* **an unreachable home pose**: the home pose is where the machine is assembled; a model that
  cannot take it (any constraint of :func:`~hexapod_workspace.core.evaluation.check.check`) is
  almost always a unit mistake (millimetres in a file of metres, degrees for radians) and is refused
  with that hint;
* **a collision at the home pose** (a body of ``collision.*`` against an obstacle or a leg).

Every door a model comes in by (the CLI's ``--config`` file, the node's parameters at start, a
``set_parameters`` call) ends here.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..._resources import example_config_path
from ...errors import ConfigError, GeometryError
from ..base.params import (
    CELL_PARAMETERS,
    COLLISION_PARAMETERS,
    NODE_PARAMETERS,
    ROS_PARAMETERS,
    flatten,
    load_params_file,
    unknown_parameter,
)
from ..base.validation import (
    MM,
    SINGULAR_TOLERANCE,
    machine_size,
    millimetre_reason,
    paired_joints_reason,
    shared_joint_pairs,
)
from ..base.values import (
    active_tool_group,
    bounded_lengths,
    cell_transform,
    describe,
    frozen,
    joint_array,
    numbers,
    per_leg,
    unit_axes,
    vector3,
)
from ..model.architectures import ARCHITECTURES
from ..model.architectures import module as architecture_module
from ..model.architectures.rus import rotate_about
from ..model.collision.params import collision_scene
from ..model.collision.scene import require_free_home
from ..model.legs import leg_endpoints
from ..model.manipulator import (
    ARCHITECTURE_PARAMETERS,
    MODEL_GROUPS,
    PARAMETER_DEFAULTS,
    REQUIRED_PARAMETERS,
    SPECIFIC_PARAMETERS,
    Manipulator,
)
from .check import home_pose_violations
from .loads import LOAD_LIMITS, LOAD_PARAMETERS

__all__ = [
    "HomePoseWarning",
    "example_manipulator",
    "home_conditioning",
    "load_manipulator",
    "manipulator_from_mapping",
    "require_usable",
    "unusable_reason",
]


def manipulator_from_mapping(
    parameters: Mapping[str, Any], *, warn: bool = True, loads_read: bool = False
) -> Manipulator:
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
        platform is singular there (:func:`unusable_reason`).
        The node and :func:`load_manipulator` refuse such a model instead.
    loads_read : bool
        The caller reads the loads' limits (``limits.actuator_force_max``,
        ``limits.deflection_max``, ...: :mod:`~hexapod_workspace.core.evaluation.loads`), as
        ``hexapod-workspace loads`` and ``check`` do. Otherwise a limit set to a value is
        refused: the constraint table, the searches and the motions do not take it yet (the
        node takes it into its pose verdicts only), and a verdict that ignored it would be
        for another machine.

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
    values = _checked_values(flat, loads_read)
    architecture = values["geometry.architecture"]
    base_joints = joint_array("geometry.base_joints", values["geometry.base_joints"])
    platform_joints = joint_array("geometry.platform_joints", values["geometry.platform_joints"])
    paired = paired_joints_reason(base_joints, platform_joints, architecture)
    if paired is not None:
        raise GeometryError(paired)
    home = vector3("geometry.home_position", values["geometry.home_position"])
    position = vector3("pose.position", values["pose.position"])
    if architecture == "ups":
        length_min, length_max = _leg_stroke(values, base_joints, platform_joints, home)
        legs: dict[str, Any] = {}
    else:
        legs = _architecture_parts(architecture, values)
        length_min = length_max = legs["leg_lengths"]
    angles = _joint_angles(values)
    diameter = _leg_diameter(values)
    paired_length = _paired_joint_length(
        values["geometry.paired_joint_length"],
        base_joints,
        platform_joints,
        diameter,
        length_min,
        machine_size(base_joints, platform_joints, home),
    )

    base_axes = unit_axes("geometry.base_joint_axes", values["geometry.base_joint_axes"])
    platform_axes = unit_axes(
        "geometry.platform_joint_axes", values["geometry.platform_joint_axes"]
    )
    frozen_legs: dict[str, Any] = {
        key: frozen(value) if isinstance(value, np.ndarray) else value
        for key, value in legs.items()
    }
    manipulator = Manipulator(
        base_joints=frozen(base_joints),
        platform_joints=frozen(platform_joints),
        base_joint_axes=frozen(np.zeros((6, 3)) if base_axes is None else base_axes),
        platform_joint_axes=frozen(np.zeros((6, 3)) if platform_axes is None else platform_axes),
        leg_length_min=frozen(length_min),
        leg_length_max=frozen(length_max),
        base_joint_max_angle=frozen(angles["limits.base_joint_max_angle"]),
        platform_joint_max_angle=frozen(angles["limits.platform_joint_max_angle"]),
        leg_diameter=diameter,
        paired_joint_length=paired_length,
        home_position=frozen(home),
        position=frozen(position),
        frame_id=values["frame_id"],
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


def _checked_values(flat: Mapping[str, Any], loads_read: bool) -> dict[str, Any]:
    """The model's parameters with their defaults, after the refusals that need no geometry:
    unknown names, a loads limit the caller does not read, the architecture and its own
    parameters, a missing required parameter, the frame id."""
    unknown = sorted(
        name
        for name in flat
        if name.startswith(MODEL_GROUPS)
        and name not in PARAMETER_DEFAULTS
        and name not in CELL_PARAMETERS
        and name not in LOAD_PARAMETERS
    )
    if unknown:
        msg = f"{unknown[0]}: unknown parameter (expected one of {_model_names()})"
        raise ConfigError(msg)
    if not loads_read:
        given = [name for name in LOAD_LIMITS if name in flat and not _unset_limit(flat[name])]
        if given:
            msg = (
                f"{given[0]}: a loads limit, read by 'hexapod-workspace loads' and 'check' "
                "only (and the node's pose verdicts); the workspace searches and motions do "
                "not take it as a constraint yet (leave it out of this file)"
            )
            raise ConfigError(msg)
    values = dict(PARAMETER_DEFAULTS)
    values.update({k: v for k, v in flat.items() if k in PARAMETER_DEFAULTS})
    if values["pose.position"] is None:
        values["pose.position"] = values["geometry.home_position"]
    architecture = values["geometry.architecture"]
    if architecture not in ARCHITECTURES:
        msg = (
            f"geometry.architecture: expected one of {', '.join(ARCHITECTURES)}, "
            f"got {describe(architecture)}"
        )
        raise ConfigError(msg)
    foreign = _foreign_parameter(architecture, flat)
    if foreign is not None:
        raise ConfigError(foreign)
    needed = set(REQUIRED_PARAMETERS[architecture])
    missing = [
        name
        for name, default in PARAMETER_DEFAULTS.items()
        if (name in needed or (default is None and name not in SPECIFIC_PARAMETERS))
        and _unset(values[name])
    ]
    if missing:
        msg = f"{missing[0]}: required parameter is missing"
        raise ConfigError(msg)

    frame_id = values["frame_id"]
    if not isinstance(frame_id, str) or not frame_id.strip():
        msg = f"frame_id: expected a non-empty string, got {describe(frame_id)}"
        raise ConfigError(msg)
    return values


def _leg_stroke(
    values: Mapping[str, Any],
    base_joints: NDArray[np.float64],
    platform_joints: NDArray[np.float64],
    home: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """6-UPS: ``limits.leg_length_min`` and ``_max`` (m, per leg), refused when negative or
    when they fit the machine only once divided by 1000."""
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
    return length_min, length_max


def _joint_angles(values: Mapping[str, Any]) -> dict[str, NDArray[np.float64]]:
    """``limits.base_joint_max_angle`` and ``limits.platform_joint_max_angle`` (rad, per leg,
    in (0, π))."""
    angles = {}
    for name in ("limits.base_joint_max_angle", "limits.platform_joint_max_angle"):
        angle = per_leg(name, values[name])
        outside = np.flatnonzero((angle <= 0.0) | (angle >= math.pi))
        if outside.size:
            msg = (
                f"{name}: expected angles in (0, pi) rad, "
                f"got {angle[outside[0]]:g} for leg {outside[0] + 1}"
            )
            raise GeometryError(msg)
        angles[name] = angle
    return angles


def _leg_diameter(values: Mapping[str, Any]) -> float:
    """``limits.leg_diameter``: one length >= 0, m."""
    diameter = bounded_lengths(
        "limits.leg_diameter", numbers("limits.leg_diameter", values["limits.leg_diameter"])
    )
    if diameter.size != 1:
        msg = f"limits.leg_diameter: expected one number, got {diameter.size}"
        raise GeometryError(msg)
    if diameter[0] < 0.0:
        msg = f"limits.leg_diameter: expected a value >= 0 m, got {diameter[0]:g}"
        raise GeometryError(msg)
    return float(diameter[0])


def load_manipulator(path: str | Path, *, loads_read: bool = False) -> Manipulator:
    """Build a manipulator from a ROS 2 parameters file (root key ``hexapod_workspace``
    or ``/**``).

    Every name in the file must be known: the model's, the node's (``resolution.*``,
    ``check.*``, ``recording.*``, read by the node only) or ROS's own (``use_sim_time``,
    ...). A misspelt name is reported at its own level (``limitz: unknown section``).
    A model whose home pose is unreachable or singular is refused
    (:func:`require_usable`, with a unit hint). Every
    message starts with the file's name.

    Parameters
    ----------
    path : str or pathlib.Path
        YAML parameters file, as in docs/configuration.md.
    loads_read : bool
        As for :func:`manipulator_from_mapping`: the caller reads the loads' limits.

    Returns
    -------
    Manipulator

    Raises
    ------
    ConfigError
        Unreadable file, unknown names, a model :func:`manipulator_from_mapping` refuses, or an
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
            *LOAD_PARAMETERS,
        ),
    )
    if unknown is not None:
        msg = f"parameters file {path}: {unknown}"
        raise ConfigError(msg)
    try:
        return require_usable(
            manipulator_from_mapping(parameters, warn=False, loads_read=loads_read)
        )
    except ConfigError as error:
        msg = f"parameters file {path}: {error}"
        raise type(error)(msg) from error


def example_manipulator() -> Manipulator:
    """The packaged example GPM (``config/example_gpm.yaml``), from any working directory.

    Returns
    -------
    Manipulator
    """
    return load_manipulator(example_config_path())


def home_conditioning(manipulator: Manipulator) -> float:
    """Smallest singular value of the normalised Plücker matrix of the legs at the home pose.

    Rows ``(n_i, (b_i × n_i) / ρ)``: n_i the unit leg direction at the home position with the
    identity orientation, b_i the platform joint (mobile frame = base frame orientation there),
    ρ = max |b_i| (1 m when every b_i is 0). Dimensionless; 0 for a singular platform.
    """
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
    if np.all((low / MM <= lengths) & (lengths <= high / MM)):
        return (
            f"the legs are {span} long there and limits.leg_length_min/max look like "
            "millimetres (they fit once divided by 1000); parameters are in metres"
        )
    if np.all((low <= lengths / MM) & (lengths / MM <= high)):
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


def _unset(value: Any) -> bool:
    """A parameter left out: None, or an empty list (how ROS holds an empty array)."""
    if value is None:
        return True
    if isinstance(value, (str, bytes)):
        return False
    return bool(np.ndim(value)) and np.size(value) == 0


def _unset_limit(value: Any) -> bool:
    """A loads limit left at its "not set" value: absent, an empty list or 0."""
    if value is None or (isinstance(value, (list, tuple)) and len(value) == 0):
        return True
    return isinstance(value, (int, float)) and not isinstance(value, bool) and value == 0


def _foreign_parameter(architecture: str, flat: Mapping[str, Any]) -> str | None:
    """Why a parameter of another architecture is refused (given, not empty, not the default),
    or None."""
    own = set(ARCHITECTURE_PARAMETERS[architecture])
    for name in PARAMETER_DEFAULTS:
        if name not in SPECIFIC_PARAMETERS or name in own or name not in flat or _unset(flat[name]):
            continue
        default = PARAMETER_DEFAULTS[name]
        if default is not None and not _unset(default) and flat[name] == default:
            continue  # a scalar at its default (a node holds every declared parameter)
        owners = [arch for arch, names in ARCHITECTURE_PARAMETERS.items() if name in names]
        return (
            f"{name}: a parameter of geometry.architecture {' or '.join(owners)}, given for "
            f"{architecture} (value {describe(flat[name])}); remove it or change the "
            "architecture"
        )
    return None


def _stroke(
    low_name: str, low: Any, high_name: str, high: Any
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A per-leg (min, max) pair of lengths, m, with min < max for every leg."""
    length_min = bounded_lengths(low_name, per_leg(low_name, low))
    length_max = bounded_lengths(high_name, per_leg(high_name, high))
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
    array = numbers(name, value)
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
    array = bounded_lengths(name, per_leg(name, value))
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
    branch = per_leg("geometry.branch", [1.0] if _unset(branch_value) else branch_value)
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
        low = per_leg("limits.actuator_min", values["limits.actuator_min"])
        high = per_leg("limits.actuator_max", values["limits.actuator_max"])
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
    tau = numbers("limits.transmission_min", values["limits.transmission_min"])
    if tau.size != 1 or not 0.0 < tau[0] < 1.0:
        msg = (
            f"limits.transmission_min: expected one value in (0, 1), got "
            f"{describe(values['limits.transmission_min'])}"
        )
        raise GeometryError(msg)
    parts["transmission_min"] = float(tau[0])
    return parts


def _with_home_axes(manipulator: Manipulator, base: bool, platform: bool) -> Manipulator:
    """The model with its default joint axes (the leg directions at the home pose: base axes
    from the base end towards B_i, turned back to crank angle 0 for rus; platform axes
    reversed), after checking that every leg has a solution and a non-zero length there."""
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
        if legs.TURNING_BASE:
            assert manipulator.crank_axes is not None
            axes = rotate_about(manipulator.crank_axes, -q, directions)
        changes["base_joint_axes"] = frozen(axes)
    if platform:
        changes["platform_joint_axes"] = frozen(-directions)
    return replace(manipulator, **changes) if changes else manipulator


class HomePoseWarning(UserWarning):
    """The home pose (home position, identity orientation) violates a constraint."""


def _singularity_min(value: Any) -> float:
    """``limits.singularity_min``: one finite number in [0, 1] (σ_min of a matrix of unit
    rows is at most √6, but a limit above 1 leaves no practical workspace)."""
    name = "limits.singularity_min"
    array = numbers(name, value)
    if array.size != 1:
        msg = f"{name}: expected one number, got {array.size}"
        raise GeometryError(msg)
    if not 0.0 <= array[0] <= 1.0:
        msg = f"{name}: expected a value in [0, 1] (0 disables the check), got {array[0]:g}"
        raise GeometryError(msg)
    return float(array[0])


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
    length = bounded_lengths(name, numbers(name, value))
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
    work = cell_transform(flat, "work", "origin")
    tool = cell_transform(flat, *active_tool_group(flat))
    scene = require_free_home(
        manipulator, collision_scene(flat, work_transform=work, tool_transform=tool)
    )
    if scene.pair_count == 0:
        return manipulator
    return replace(manipulator, collision=scene)


def _model_names() -> str:
    return ", ".join(name for name in PARAMETER_DEFAULTS if name.startswith(MODEL_GROUPS))
