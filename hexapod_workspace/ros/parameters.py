"""The node's parameters: the table, their descriptors, validation and the state they build.

One table (:func:`parameter_specs`) declares every parameter: name, default, description and the
range or read-only flag shown by ``ros2 param describe``. The manipulator model's names and
defaults are those of :meth:`hexapod_workspace.Manipulator.to_parameters` for the packaged
example GPM; the resolution bounds and defaults come from
:mod:`hexapod_workspace.core.base.resolution`.

:func:`refusal` checks one parameter as a client sent it (unknown name, wrong type, read-only,
out of range) and :func:`state_from` the would-be full set (it builds the
:class:`~hexapod_workspace.Manipulator` and refuses an unusable one with
:func:`~hexapod_workspace.core.evaluation.loading.require_usable`): the node's start-up and run-time
validation are this one function, and every refusal names the parameter and the value given.

The packaged example stands in for the model only when the node is given no model parameter at
all (:func:`model_given`); given any, it must be given the whole model
(:func:`missing_model_parameters`), the optional ones taking the model's own defaults
(:func:`model_default`), never the example's.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.parameter import Parameter

from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.base import resolution
from hexapod_workspace.core.cell.frames import (
    CELL_DEFAULTS,
    CellFrames,
    cell_from_mapping,
    require_plausible_cell,
    tool_model,
)
from hexapod_workspace.core.evaluation.loading import (
    load_manipulator,
    manipulator_from_mapping,
    require_usable,
)
from hexapod_workspace.core.evaluation.loads import (
    LOAD_PARAMETERS,
    LoadCase,
    load_case_from_mapping,
    require_plausible_loads,
)
from hexapod_workspace.core.model.architectures import ARCHITECTURES
from hexapod_workspace.core.model.manipulator import (
    ARCHITECTURE_PARAMETERS,
    PARAMETER_DEFAULTS,
    Manipulator,
    required_parameters,
)
from hexapod_workspace.errors import ConfigError

from .recorder import Rotation

__all__ = [
    "LOAD_DESCRIPTIONS",
    "MODEL_DESCRIPTIONS",
    "MODEL_GROUPS",
    "Settings",
    "Spec",
    "State",
    "command_line_override_names",
    "dynamic_specs",
    "missing_model_parameters",
    "model_default",
    "model_given",
    "parameter_specs",
    "refusal",
    "state_from",
    "tool_table_specs",
]

#: Parameter ranges: the core's resolution bounds (one definition, core/base/resolution.py).
RAYS_RANGE = (resolution.MIN_RAYS, resolution.MAX_RAYS)
PROJECTED_METHODS = tuple(method.value for method in resolution.Method)

MODEL_DESCRIPTIONS = {
    "frame_id": "Base frame: frame_id of every published cloud and result header.",
    "geometry.base_joints": (
        "a_1..a_6 = OA_i: base (universal) joint centres, base frame, m; 18 floats (x y z)."
    ),
    "geometry.platform_joints": (
        "b_1..b_6 = CB'_i: platform (spherical) joint centres, mobile frame (origin at the tool "
        "tip C, z' along the tool), m; 18 floats (x' y' z')."
    ),
    "geometry.home_position": (
        "Home position OC, base frame, m (3 floats); default joint axes = leg directions there."
    ),
    "geometry.base_joint_axes": (
        "Axes of symmetry of the base joints, base frame, pointing into the legs: 18 floats, or "
        "empty/unset = leg directions at the home pose."
    ),
    "geometry.platform_joint_axes": (
        "Axes of symmetry of the platform joints, mobile frame, pointing into the legs: 18 "
        "floats, or empty/unset = reversed leg directions at the home pose."
    ),
    "limits.leg_length_min": "ups: minimum leg length |A_iB_i|, m: 1 value (all legs) or 6.",
    "limits.leg_length_max": "ups: maximum leg length |A_iB_i|, m: 1 value (all legs) or 6.",
    "limits.base_joint_max_angle": (
        "Maximum angle between a base joint axis and its leg, rad, in (0, pi): 1 or 6 values."
    ),
    "limits.platform_joint_max_angle": (
        "Maximum angle between a platform joint axis and its leg, rad, in (0, pi): 1 or 6 values."
    ),
    "limits.leg_diameter": (
        "Leg diameter D, m: legs (segments A_iB_i) must stay D apart; 0 disables the check."
    ),
    "geometry.paired_joint_length": (
        "ups: where legs share a joint (paired joints: 6-3, 3-3, LinuxCNC's default), the "
        "length of each leg from the shared joint centre that the joint occupies, m; their "
        "interference is measured on the rest. Required then with limits.leg_diameter > 0; "
        "0 = no legs share a joint."
    ),
    "limits.singularity_min": (
        "Smallest allowed singular value of the homogenised Plucker matrix of the legs, in "
        "[0, 1]; 0 disables the singularity margin."
    ),
    "pose.position": (
        "Default tool-tip position OC, base frame, m (3 floats): used by the Trigger services."
    ),
    "geometry.architecture": (
        "Leg architecture: ups (legs of variable length between fixed joints), pus (slides on "
        "rails, legs of fixed length) or rus (cranks, rods of fixed length)."
    ),
    "geometry.rail_directions": (
        "pus: direction u_i of each rail, base frame, 18 floats (normalised); "
        "A_i(q) = A0_i + q u_i with A0_i = geometry.base_joints. Empty for ups and rus."
    ),
    "geometry.crank_axes": (
        "rus: crank (motor) axis w_i through A0_i = geometry.base_joints, base frame, 18 floats "
        "(normalised). Empty for ups and pus."
    ),
    "geometry.crank_zero_directions": (
        "rus: crank direction e_i at q = 0, perpendicular to w_i, 18 floats (normalised). "
        "Empty for ups and pus."
    ),
    "geometry.crank_lengths": "rus: crank length r_i, m: 1 value (all legs) or 6.",
    "geometry.leg_lengths": "pus, rus: fixed leg (rod) length L_i, m: 1 value or 6.",
    "geometry.branch": (
        "pus, rus: assembly branch of each leg, +1 or -1: 1 value or 6 (empty = +1)."
    ),
    "limits.actuator_min": (
        "pus: slide stroke minimum along the rail, m; rus: crank angle minimum, rad: 1 or 6."
    ),
    "limits.actuator_max": (
        "pus: slide stroke maximum, m; rus: crank angle maximum, rad (max - min < 2 pi): 1 or 6."
    ),
    "limits.transmission_min": (
        "pus, rus: smallest |tau_i| allowed (tau: the leg direction against the actuator's "
        "motion), in (0, 1)."
    ),
}
#: Ranges of the model's scalar parameters (the model validation says the same).
_FLOAT_RANGES = {
    "limits.leg_diameter": (0.0, 10.0),
    "geometry.paired_joint_length": (0.0, 10.0),
    "limits.singularity_min": (0.0, 1.0),
    "limits.transmission_min": (0.0, 1.0),
}
#: Axes that may be empty: an empty YAML list arrives as an unset parameter of any type.
_OPTIONAL_AXES = ("geometry.base_joint_axes", "geometry.platform_joint_axes")
#: Arrays that are empty for some architecture (the model refuses non-numbers): typed at run
#: time, like the optional axes.
_ARCHITECTURE_ARRAYS = tuple(
    name
    for names in ARCHITECTURE_PARAMETERS.values()
    for name in names
    if isinstance(PARAMETER_DEFAULTS[name], list) or PARAMETER_DEFAULTS[name] is None
)


@dataclass(frozen=True)
class Spec:
    """Declaration of one parameter."""

    name: str
    default: Any
    description: str
    read_only: bool = False
    dynamic_typing: bool = False
    float_range: tuple[float, float] | None = None
    int_range: tuple[int, int] | None = None
    constraints: str = ""

    @property
    def type_(self) -> Parameter.Type:
        return Parameter.Type.from_parameter_value(self.default)

    def descriptor(self) -> ParameterDescriptor:
        descriptor = ParameterDescriptor(
            name=self.name,
            description=self.description,
            read_only=self.read_only,
            dynamic_typing=self.dynamic_typing,
            additional_constraints=self.constraints,
        )
        if not self.dynamic_typing:
            descriptor.type = self.type_.value
        if self.float_range is not None:
            low, high = self.float_range
            descriptor.floating_point_range = [
                FloatingPointRange(from_value=low, to_value=high, step=0.0)
            ]
        if self.int_range is not None:
            low, high = self.int_range
            descriptor.integer_range = [IntegerRange(from_value=low, to_value=high, step=1)]
        return descriptor


def parameter_specs() -> dict[str, Spec]:
    """Every parameter of the node by name, model defaults from the packaged example."""
    example = load_manipulator(example_config_path()).to_parameters()
    specs = [
        Spec(
            name,
            [] if name in _OPTIONAL_AXES else default,
            MODEL_DESCRIPTIONS[name],
            read_only=name == "frame_id",
            # the model validation refuses non-numbers
            dynamic_typing=name in _OPTIONAL_AXES or name in _ARCHITECTURE_ARRAYS,
            float_range=_FLOAT_RANGES.get(name),
            constraints=(
                f"one of: {', '.join(ARCHITECTURES)}" if name == "geometry.architecture" else ""
            ),
        )
        for name, default in example.items()
    ]
    specs += [
        Spec(
            "resolution.n_phi",
            resolution.DEFAULT_N_PHI,
            "Projected workspace: number of equally spaced azimuths phi (rays).",
            int_range=RAYS_RANGE,
        ),
        Spec(
            "resolution.n_rays",
            resolution.DEFAULT_N_RAYS,
            "Orientation workspace: rays per psi slice.",
            int_range=RAYS_RANGE,
        ),
        Spec(
            "resolution.psi_step",
            resolution.DEFAULT_PSI_STEP,
            "Orientation workspace: torsion step between slices, rad.",
            float_range=(resolution.MIN_PSI_STEP, resolution.MAX_PSI_STEP),
        ),
        Spec(
            "resolution.tolerance",
            resolution.DEFAULT_TOLERANCE,
            "Boundary tolerance of every workspace computation, rad.",
            float_range=(resolution.MIN_TOLERANCE, resolution.MAX_TOLERANCE),
        ),
        Spec(
            "resolution.projected_method",
            resolution.Method.TORSION_ZERO.value,
            "Method of ~/compute_projected_workspace: torsion_zero (psi = 0, the paper's) or "
            "exact (true shadow over all psi).",
            constraints=f"one of: {', '.join(PROJECTED_METHODS)}",
        ),
        Spec(
            "check.max_poses",
            100_000,
            "Largest number of orientations accepted in one check_poses request.",
            read_only=True,
            int_range=(1, 10_000_000),
        ),
        Spec(
            "check.max_command_age",
            0.5,
            "A CommandedPose whose header stamp is older than this when its turn comes (s, node "
            "clock) is answered success=false 'overloaded' instead of checked; 0 = never. "
            "Commands with a zero stamp are always checked.",
            float_range=(0.0, 3600.0),
        ),
        Spec(
            "check.report_singularity",
            False,
            "Report the singularity margin (sigma_min of the legs' Pluecker matrix) in the "
            "answers of check_poses, check_poses_flat, the command stream and the waypoints of "
            "check_path even when "
            "limits.singularity_min is 0 (then it never changes a verdict); false: null/+inf "
            "there, at no cost.",
        ),
        Spec(
            "recording.enabled",
            True,
            "Record every request and result to an MCAP log (rosbag2 form); false stops.",
        ),
        Spec(
            "recording.max_file_mb",
            100.0,
            "Split the log (finish it, go on in a new one, as rosbag2's --max-bag-size) once "
            "its messages reach this many MB; 0 = no size split.",
            read_only=True,
            float_range=(0.0, 1e6),
        ),
        Spec(
            "recording.max_file_duration",
            3600.0,
            "Split the log once it is this many s old (at its next message, as rosbag2's "
            "--max-bag-duration); 0 = no age split.",
            read_only=True,
            float_range=(0.0, 1e9),
        ),
        Spec(
            "recording.max_total_mb",
            1000.0,
            "Keep the folder's hexapod_workspace_*.mcap logs (earlier runs included) under this "
            "many MB by removing the oldest when a log starts; 0 = keep every log.",
            read_only=True,
            float_range=(0.0, 1e9),
        ),
        *_cell_specs(),
        *_load_specs(),
        Spec(
            "recording.cloud_points",
            20_000,
            "Most points of each boundary cloud written to the log: evenly spaced along the "
            "cloud (first and last kept), as in the action's result; the cloud topic always "
            "gets the full cloud. 0 = the full cloud in the log too (a 274k-point 3-D boundary "
            "is 6.6 MB a goal, written by the node's process: see the latency figures).",
            int_range=(0, 100_000_000),
        ),
        Spec(
            "recording.directory",
            "",
            "Folder of the MCAP logs (one per run, named by start time); empty = "
            "$ROS_HOME/hexapod_workspace/logs (ROS_HOME defaults to ~/.ros).",
            read_only=True,
        ),
    ]
    return {spec.name: spec for spec in specs}


#: The machining cell's parameters (hexapod_workspace.core.cell.frames), settable at run time.
CELL_DESCRIPTIONS = {
    "tool.offset": (
        "Tool centre point C in the platform frame (the frame of geometry.platform_joints), m, "
        "3 floats: every pose given to and returned by the node is C's (tool.number 0)."
    ),
    "tool.orientation": (
        "Tool frame's axes in the platform frame, rad, T&T angles (phi, theta, psi) "
        "(tool.number 0)."
    ),
    "tool.number": (
        "Active tool: 0 = tool.offset/tool.orientation, n > 0 = the tool table's tools.T<n> "
        "(a tool change sets it; a number not in the table is refused)."
    ),
    "work.origin": "Work (workpiece) frame's origin in the base frame, m, 3 floats.",
    "work.orientation": "Work frame's axes in the base frame, rad, T&T angles (phi, theta, psi).",
    "work.frame_id": (
        "Name of the work frame: poses with this header.frame_id are converted from it; "
        "another name than the base frame_id."
    ),
    "limits.actuator_speed_max": (
        "Largest actuator speed, actuator unit/s (m/s for legs), 1 value or 6; 0 = unlimited "
        "(~/check_path's speed verdicts)."
    ),
    "limits.actuator_accel_max": (
        "Largest actuator acceleration, actuator unit/s² (m/s² for legs), 1 value or 6; "
        "0 = unlimited (the schedule command's limit; validated with the cell)."
    ),
}
#: The loads the node takes (hexapod_workspace.core.evaluation.loads), settable at run time:
#: the payload, the process wrench, the actuators and the loads' limits
#: (hexapod_workspace.ros.load_rows).
LOAD_DESCRIPTIONS = {
    "load.mass": "Payload on the platform, kg (>= 0; ~/loads).",
    "load.center_of_mass": (
        "Payload's centre of mass in the platform frame (the frame of "
        "geometry.platform_joints), m, 3 floats (~/loads)."
    ),
    "load.gravity": (
        "Gravity in the base frame, m/s², 3 floats: [0, 0, -9.81] on a pedestal, "
        "[0, 0, 9.81] on a ceiling (~/loads)."
    ),
    "process.wrench": (
        "Centre of the process wrench box in the tool frame at the tool centre point: "
        "fx fy fz (N), mx my mz (N·m) (~/loads)."
    ),
    "process.wrench_range": "Half-widths of the process wrench box, N and N·m, 6 floats >= 0.",
    "stiffness.actuator": (
        "Axial actuator stiffness, N/m (legs, slides) or N·m/rad (cranks), 1 or 6 values > 0; "
        "empty = not given (~/loads' stiffness and deflection)."
    ),
    "accuracy.actuator_error": (
        "Actuator error bound, m or rad, 1 or 6 values >= 0; empty = not given (~/loads' accuracy)."
    ),
    "limits.actuator_force_max": (
        "Largest actuator push, N (legs, slides) or N·m (cranks), 1 or 6 values > 0; empty = "
        "no force limit. Set, every pose verdict carries the actuator_force row; moves and "
        "workspaces are refused until their rate bounds exist."
    ),
    "limits.actuator_force_min": (
        "Largest pull (a value below the push limit, usually negative), 1 or 6 values; empty "
        "= minus limits.actuator_force_max."
    ),
    "limits.deflection_max": (
        "Largest tool translation under the process box, m; 0 = no limit (needs "
        "stiffness.actuator). Set: the deflection row in every pose verdict."
    ),
    "limits.accuracy_max": (
        "Largest tool translation from the actuator errors, m; 0 = no limit (needs "
        "accuracy.actuator_error). Set: the accuracy row in every pose verdict."
    ),
}


def _load_specs() -> list[Spec]:
    """The loads parameters (typed at run time: integers and floats both are numbers)."""
    return [
        Spec(name, LOAD_PARAMETERS[name], description, dynamic_typing=True)
        for name, description in LOAD_DESCRIPTIONS.items()
    ]


#: The tool table's parameter names (declared from the parameters given at start, or when a
#: client sets a new one).
TOOL_TABLE_NAME = re.compile(r"^tools\.T([1-9][0-9]*)\.(offset|orientation)$")
#: The cell parameters the collision scene is placed with (as the CLI reads them).
_SCENE_FRAMES = ("tool.offset", "tool.orientation", "work.origin", "work.orientation")
#: ~/axis_limits settings.
AXIS_LIMITS_FRAMES = ("base", "work", "tool")


def _cell_specs() -> list[Spec]:
    specs = [
        Spec(
            name,
            CELL_DEFAULTS[name],
            description,
            int_range=(0, 1_000_000) if name == "tool.number" else None,
        )
        for name, description in CELL_DESCRIPTIONS.items()
    ]
    specs += [
        Spec(
            "axis_limits.frame",
            "base",
            "Frame of the axes of ~/axis_limits: base, work or tool.",
            constraints=f"one of: {', '.join(AXIS_LIMITS_FRAMES)}",
        ),
        Spec(
            "axis_limits.rate",
            2.0,
            "Most ~/axis_limits messages per second (computed beside the command path, for "
            "the last current pose); 0 = none published.",
            float_range=(0.0, 100.0),
        ),
    ]
    return specs


def tool_table_specs(names: Iterable[str]) -> dict[str, Spec]:
    """Specs of the tool-table parameters (``tools.T<n>.offset``, ``.orientation``) among
    ``names``, plus ``tools.T<n>.orientation`` (default zero) for every ``tools.T<n>.offset``."""
    specs: dict[str, Spec] = {}
    for name in sorted(names):
        match = TOOL_TABLE_NAME.match(name)
        if match is None:
            continue
        number = match.group(1)
        for key, text in (
            ("offset", "m, tool centre point in the platform frame (3 floats)"),
            ("orientation", "rad, T&T angles of the tool frame in the platform frame"),
        ):
            if key == "offset" and match.group(2) != "offset":
                continue
            full = f"tools.T{number}.{key}"
            specs[full] = Spec(full, [0.0, 0.0, 0.0], f"Tool table, tool {number}: {text}.")
    return specs


#: The collision scene's parameter names (``collision.*``): declared like the tool table, from
#: the parameters given at start or when a client first sets one (an obstacle added at run
#: time); their names and values are checked as a whole by
#: :func:`~hexapod_workspace.core.model.collision.params.collision_scene`.
COLLISION_NAME = re.compile(r"^collision\.[A-Za-z0-9_.]+$")
#: Descriptions of the collision parameters by their last name part.
COLLISION_DESCRIPTIONS = {
    "clearance": "m, kept between every checked pair (subtracted from each distance)",
    "radius": "m (platform cylinder, tool capsule, obstacle cylinder, capsule or sphere)",
    "z_min": "m, platform cylinder's lower end along z of the platform frame",
    "z_max": "m, platform cylinder's upper end along z of the platform frame",
    "length": "m (tool capsule from C along +z of the tool frame; obstacle along its local z)",
    "names": "the obstacles, one group collision.obstacles.<name>.* per name",
    "shape": "box, cylinder, sphere or capsule",
    "frame": "base or work: the frame of position and orientation (default base)",
    "position": "m, the obstacle's centre in its frame (3 floats)",
    "orientation": "roll, pitch, yaw (rad) or a quaternion x, y, z, w (default identity)",
    "size": "m, box: full edge lengths along its local x, y, z (3 floats)",
}


def dynamic_specs(names: Iterable[str]) -> dict[str, Spec]:
    """Specs of the parameters declared by name among ``names``: the tool table
    (:func:`tool_table_specs`) and the collision scene (``collision.*``, dynamically typed:
    the scene's own validation names a wrong type with the parameter and the value; unset =
    removed, so that an obstacle can be taken out at run time)."""
    names = list(names)
    specs = tool_table_specs(names)
    for name in sorted(names):
        if COLLISION_NAME.match(name):
            text = COLLISION_DESCRIPTIONS.get(name.rsplit(".", 1)[1], "see docs/collision.md")
            specs[name] = Spec(name, None, f"Collision scene: {text}.", dynamic_typing=True)
    return specs


@dataclass(frozen=True)
class Settings:
    """Node settings that are not part of the manipulator model."""

    n_phi: int
    n_rays: int
    psi_step: float
    tolerance: float
    projected_method: str
    max_poses: int
    max_command_age: float
    report_singularity: bool
    recording_enabled: bool
    recording_directory: Path
    recording_rotation: Rotation
    axis_limits_frame: str = "base"
    axis_limits_rate: float = 2.0
    #: most points of a boundary cloud in the log (0 = all)
    recording_cloud_points: int = 20_000


@dataclass(frozen=True)
class State:
    """What the callbacks read: swapped as a whole when parameters change.

    Attributes
    ----------
    manipulator : Manipulator
        The model that answers for tool-frame poses
        (:func:`~hexapod_workspace.core.cell.frames.tool_model` of ``platform`` and the active
        tool): what every check uses.
    settings : Settings
    platform : Manipulator
        The model as the parameters give it (platform frame).
    cell : CellFrames
        The active tool, the work frame, the tool table and the actuator speed limits.
    loads : LoadCase
        The payload, the process wrench, the actuator stiffness and errors (no limits; the
        centre of mass in the platform frame).
    """

    manipulator: Manipulator
    settings: Settings
    platform: Manipulator | None = None
    cell: CellFrames | None = None
    loads: LoadCase = field(default_factory=LoadCase)


def _plain(value: Any) -> Any:
    """A parameter value as the model wants it (unset/empty arrays as empty lists)."""
    if value is None:
        return []
    if isinstance(value, (str, bool, int, float)):
        return value
    return list(value)


def _shown(value: Any) -> str:
    """A parameter value for a refusal text (long arrays shortened)."""
    value = _plain(value)
    if isinstance(value, list) and len(value) > 8:
        return f"[{', '.join(map(repr, value[:6]))}, ... ({len(value)} values)]"
    return repr(value)


def _type_label(type_: Parameter.Type) -> str:
    return type_.name.lower().replace("_array", "[]")


def _article(type_: Parameter.Type) -> str:
    label = _type_label(type_)
    return f"{'an' if label[0] in 'aeiou' else 'a'} {label}"


def refusal(specs: dict[str, Spec], parameter: Parameter) -> str | None:
    """Why a client's new value of one parameter is refused, or None when it may be applied.

    Checks what rclpy would refuse with a text that names neither the parameter nor the value:
    an unknown name, a wrong type, a read-only parameter, a value out of the declared range,
    unsetting. The full-set checks (the model) are :func:`state_from`'s.
    """
    name, value = parameter.name, parameter.value
    spec = specs.get(name)
    if spec is None:
        return f"{name}: no such parameter of this node (value {_shown(value)} refused)"
    if spec.read_only:
        return f"{name}: read-only, set at start only (value {_shown(value)} refused)"
    if parameter.type_ == Parameter.Type.NOT_SET:
        if spec.dynamic_typing:
            return None
        return f"{name}: parameters of this node cannot be unset (deleted)"
    if not spec.dynamic_typing and parameter.type_ != spec.type_:
        return (
            f"{name}: expected {_article(spec.type_)}, got {_shown(value)} "
            f"({_type_label(parameter.type_)})"
        )
    for bounds in (spec.float_range, spec.int_range):
        if bounds is not None and not (bounds[0] <= value <= bounds[1]):
            return f"{name}: expected {bounds[0]:g} to {bounds[1]:g}, got {_shown(value)}"
    return None


def state_from(values: dict[str, Any]) -> State:
    """Build (and so validate) the node state from a full set of parameter values.

    Raises
    ------
    ConfigError
        Invalid model or settings; the message names the parameter and the value.
    """
    model = {name: _plain(values[name]) for name in MODEL_DESCRIPTIONS}
    scene = {
        name: _plain(value)
        for name, value in values.items()
        if COLLISION_NAME.match(name) and value is not None  # None: unset (removed)
    }
    if scene:  # with the cell frames it is placed with (work-frame obstacles, the tool body)
        model.update(scene)
        model.update(
            {name: _plain(values[name]) for name in _SCENE_FRAMES if values.get(name) is not None}
        )
    platform = require_usable(manipulator_from_mapping(model, warn=False))
    cell = cell_from_mapping(
        {
            name: _plain(value)
            for name, value in values.items()
            if name in CELL_DESCRIPTIONS or TOOL_TABLE_NAME.match(name)
        }
    )
    require_plausible_cell(platform, cell)  # the CLI's unit rule: values in millimetres
    if cell.work.frame_id == platform.frame_id:
        msg = (
            f"work.frame_id: expected a name other than the base frame frame_id, got "
            f"{cell.work.frame_id!r}"
        )
        raise ConfigError(msg)
    frame = str(values.get("axis_limits.frame", "base"))
    if frame not in AXIS_LIMITS_FRAMES:
        msg = f"axis_limits.frame: expected one of {', '.join(AXIS_LIMITS_FRAMES)}, got {frame!r}"
        raise ConfigError(msg)
    loads = require_plausible_loads(
        platform,
        load_case_from_mapping(
            {name: _plain(values[name]) for name in LOAD_DESCRIPTIONS if name in values}
        ),
    )
    manipulator = tool_model(platform, cell.tool)
    method = str(values["resolution.projected_method"])
    if method not in PROJECTED_METHODS:
        msg = (
            f"resolution.projected_method: expected one of {', '.join(PROJECTED_METHODS)}, "
            f"got {method!r}"
        )
        raise ConfigError(msg)
    age = float(values["check.max_command_age"])
    if not (math.isfinite(age) and age >= 0.0):
        msg = f"check.max_command_age: expected a finite value >= 0 s, got {age!r}"
        raise ConfigError(msg)
    directory = str(values["recording.directory"]).strip()
    if directory:
        folder = Path(directory).expanduser()
    else:
        ros_home = os.environ.get("ROS_HOME") or str(Path("~/.ros").expanduser())
        folder = Path(ros_home) / "hexapod_workspace" / "logs"
    settings = Settings(
        n_phi=int(values["resolution.n_phi"]),
        n_rays=int(values["resolution.n_rays"]),
        psi_step=float(values["resolution.psi_step"]),
        tolerance=float(values["resolution.tolerance"]),
        projected_method=method,
        max_poses=int(values["check.max_poses"]),
        max_command_age=age,
        report_singularity=bool(values["check.report_singularity"]),
        recording_enabled=bool(values["recording.enabled"]),
        recording_directory=folder,
        recording_rotation=Rotation(
            max_file_bytes=int(float(values["recording.max_file_mb"]) * 1e6),
            max_file_seconds=float(values["recording.max_file_duration"]),
            max_total_bytes=int(float(values["recording.max_total_mb"]) * 1e6),
        ),
        axis_limits_frame=frame,
        axis_limits_rate=float(values.get("axis_limits.rate", 2.0)),
        recording_cloud_points=int(values["recording.cloud_points"]),
    )
    return State(manipulator, settings, platform, cell, loads)


#: Name prefixes of the model's parameters (``frame_id`` only names the frame).
MODEL_GROUPS = ("geometry.", "limits.", "pose.")


def model_given(names: Iterable[str]) -> list[str]:
    """The model parameters (``geometry.*``, ``limits.*``, ``pose.*``) among ``names`` (the
    cell's ``limits.actuator_speed_max`` and the loads' limits are not part of the model)."""
    return sorted(
        {
            name
            for name in names
            if name.startswith(MODEL_GROUPS)
            and name not in CELL_DEFAULTS
            and name not in LOAD_PARAMETERS
        }
    )


def missing_model_parameters(given: Iterable[str], architecture: str = "ups") -> str | None:
    """Why a start with model parameters ``given`` (non-empty) is refused, or None.

    A node given any model parameter must be given every required one of its architecture
    (``geometry.architecture`` as given, else ups): the packaged example never fills in the
    rest of a user's machine.
    """
    given = set(given)
    required = list(required_parameters(architecture))
    missing = [name for name in required if name not in given]
    if not missing:
        return None
    also = f" (and {', '.join(missing[1:])})" if len(missing) > 1 else ""
    return (
        f"{missing[0]}: required parameter is missing{also}; the node was given "
        f"{', '.join(sorted(given))}, and a node given any model parameter must be given the "
        "whole model (the packaged example is used only when none is given)"
    )


def model_default(name: str, declared: dict[str, Any]) -> Any:
    """The start value of optional model parameter ``name`` when the user gives a model but
    not this parameter: the model's own default (no joint axes given, no interference check,
    ``pose.position`` = ``geometry.home_position``), not the packaged example's value."""
    if name == "pose.position":
        return list(declared["geometry.home_position"])
    if name in CELL_DEFAULTS:  # limits.actuator_speed_max: the cell's own default
        return CELL_DEFAULTS[name]
    if name in LOAD_PARAMETERS:  # the loads' limits: not set
        return LOAD_PARAMETERS[name]
    if name in _ARCHITECTURE_ARRAYS:
        return []  # not this architecture's: left empty
    return PARAMETER_DEFAULTS[name]


def _flatten(tree: dict[str, Any], prefix: str = "") -> list[str]:
    names: list[str] = []
    for key, value in tree.items():
        if isinstance(value, dict):
            names += _flatten(value, f"{prefix}{key}.")
        else:
            names.append(f"{prefix}{key}")
    return names


def command_line_override_names(argv: list[str], node_name: str) -> list[str]:
    """Names of the parameters the command line gives the node (``-p``, ``--params-file``).

    Parameters
    ----------
    argv : list of str
        The process arguments (``--ros-args`` sections are read).
    node_name : str
        The node's name: a parameters file's ``<name>``, ``/<name>`` and ``/**`` entries count.
    """
    names: list[str] = []
    in_ros_args = False
    tokens = iter(argv)
    for token in tokens:
        if token == "--ros-args":
            in_ros_args = True
        elif token == "--":
            in_ros_args = False
        elif in_ros_args and token in ("-p", "--param"):
            names.append(next(tokens, "").split(":=", 1)[0])
        elif in_ros_args and token == "--params-file":
            path = next(tokens, "")
            try:
                document = yaml.safe_load(Path(path).read_text(encoding="utf-8")) or {}
            except (OSError, yaml.YAMLError):
                continue  # rcl reports an unreadable file itself
            for key in ("/**", node_name, f"/{node_name}"):
                section = document.get(key) or {}
                names += _flatten(section.get("ros__parameters") or {})
    return names
