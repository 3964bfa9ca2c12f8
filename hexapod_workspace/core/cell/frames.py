"""Tool and work frames of a machining cell, the tool table, and poses between the frames.

Frames
------
* **Platform frame P**: the frame in which ``geometry.platform_joints`` (b_i) and
  ``geometry.platform_joint_axes`` (jB_i) are written; ``geometry.home_position`` is its origin
  at the home pose (identity orientation), whatever the tool.
* **Tool frame C**: ``tool.offset`` t (m) and ``tool.orientation`` (φ, θ, ψ) (rad, T&T, giving
  R_tool) place C in P: a point with coordinates x in C is at ``t + R_tool·x`` in P. Default zero:
  C = P, so files written before the tool frame keep their answers.
* **Work frame W**: ``work.origin`` o (m) and ``work.orientation`` (rad, T&T, giving R_W) place
  the workpiece frame in the base frame O: x in W is at ``o + R_W·x`` in O. Its name in messages
  is ``work.frame_id`` (default ``"work"``).

Every position and orientation a caller gives is the tool frame's (OC and R of C in O). The
platform then is at (homogeneous transforms, ``T_OP = T_OC · T_PC⁻¹``)::

    R_P = R · R_toolᵀ,        p_P = p − R_P · t.

**Equivalent model.** Leg i is ``L_i = p_P + R_P·b_i − a_i = p + R·R_toolᵀ(b_i − t) − a_i``,
and the platform joint's axis in O is ``R_P·jB_i = R·R_toolᵀ jB_i``. So the manipulator whose
platform joints are ``b'_i = R_toolᵀ(b_i − t)`` and platform joint axes ``jB'_i = R_toolᵀ jB_i``
answers for tool-frame poses directly, with the same margins: :func:`tool_model` builds it, and
every workspace, check and move certificate of the package becomes one about the tool centre
point (ρ = max|b'_i| in the rate bounds follows automatically, as the joints' speed about C).
The joint axes are resolved in P *before* the change (defaults from the home pose of P), so the
tool does not move them.

Tool table
----------
``tools.T<n>.offset`` (3 numbers, m) and ``tools.T<n>.orientation`` (3 numbers, rad, default
zero), n = 1, 2, ... (ROS parameter names cannot start with a digit). A tool change (CL
``LOADTL/n``) selects entry n. ``tool.number`` (default 0) selects the active tool: 0 is the
``tool.offset``/``tool.orientation`` pair, n > 0 is table entry n (which must exist); the node
changes tools by setting it at run time.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import ConfigError, InputError
from ..base.params import flatten, load_params_file
from ..base.rotations import tt_to_matrix
from ..base.validation import machine_size, millimetre_reason
from ..base.values import (
    angles3,
    describe,
    frozen,
    numbers,
    tool_number,
    unknown_tool,
    vector3,
)
from ..model.architectures import module as architecture_module
from ..model.manipulator import Manipulator

__all__ = [
    "CELL_DEFAULTS",
    "CellFrames",
    "Tool",
    "WorkFrame",
    "cell_from_mapping",
    "cell_from_params_file",
    "cell_unit_reason",
    "curves_to_base",
    "platform_pose",
    "require_plausible_cell",
    "tool_model",
    "tool_pose",
    "vectors_to_base",
    "work_to_base",
]

#: Parameters of the cell with their defaults (``tools.T<n>.*`` are the tool table).
CELL_DEFAULTS: dict[str, Any] = {
    "tool.offset": [0.0, 0.0, 0.0],
    "tool.orientation": [0.0, 0.0, 0.0],
    "tool.number": 0,
    "work.origin": [0.0, 0.0, 0.0],
    "work.orientation": [0.0, 0.0, 0.0],
    "work.frame_id": "work",
    "limits.actuator_speed_max": [0.0],
    "limits.actuator_accel_max": [0.0],
}
_TOOL_KEY = re.compile(r"^tools\.T([1-9][0-9]*)\.(offset|orientation)$")


def _rotation(angles: NDArray[np.float64]) -> NDArray[np.float64]:
    matrix: NDArray[np.float64] = tt_to_matrix(angles)
    return matrix


@dataclass(frozen=True, eq=False)
class Tool:
    """A tool frame C in the platform frame P.

    Attributes
    ----------
    offset : ndarray, shape (3,)
        t = PC in the platform frame, m.
    orientation : ndarray, shape (3,)
        (φ, θ, ψ) of C in P, rad (T&T).
    number : int
        Tool-table number (0: the ``tool.*`` parameters, not the table).
    """

    offset: NDArray[np.float64] = field(default_factory=lambda: frozen(np.zeros(3)))
    orientation: NDArray[np.float64] = field(default_factory=lambda: frozen(np.zeros(3)))
    number: int = 0

    @property
    def rotation(self) -> NDArray[np.float64]:
        """R_tool, shape (3, 3): C's axes in P."""
        return _rotation(self.orientation)

    @property
    def is_identity(self) -> bool:
        """C = P (no offset, no rotation)."""
        return not np.any(self.offset) and not np.any(self.orientation)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Tool):
            return NotImplemented
        return (
            np.array_equal(self.offset, other.offset)
            and np.array_equal(self.orientation, other.orientation)
            and self.number == other.number
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True, eq=False)
class WorkFrame:
    """The workpiece frame W in the base frame O.

    Attributes
    ----------
    origin : ndarray, shape (3,)
        OW in the base frame, m.
    orientation : ndarray, shape (3,)
        (φ, θ, ψ) of W in O, rad (T&T).
    frame_id : str
        Its name in messages (``header.frame_id``).
    """

    origin: NDArray[np.float64] = field(default_factory=lambda: frozen(np.zeros(3)))
    orientation: NDArray[np.float64] = field(default_factory=lambda: frozen(np.zeros(3)))
    frame_id: str = "work"

    @property
    def rotation(self) -> NDArray[np.float64]:
        """R_W, shape (3, 3): W's axes in O."""
        return _rotation(self.orientation)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, WorkFrame):
            return NotImplemented
        return (
            np.array_equal(self.origin, other.origin)
            and np.array_equal(self.orientation, other.orientation)
            and self.frame_id == other.frame_id
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class CellFrames:
    """The cell's parameters besides the manipulator: frames, tool table, actuator speeds.

    Attributes
    ----------
    tool : Tool
        The active tool: ``tool.offset``/``tool.orientation`` (number 0), or the table entry
        ``tool.number`` selects.
    work : WorkFrame
    tools : dict of int to Tool
        The tool table (``tools.T<n>.*``), by number.
    actuator_speed_max : ndarray, shape (6,)
        Largest actuator speed per actuator (m/s for 6-UPS legs); 0 = unlimited.
    actuator_accel_max : ndarray, shape (6,)
        Largest actuator acceleration per actuator (m/s² for legs and slides, rad/s² for
        cranks); 0 = unlimited (the ``schedule`` command's limit).
    """

    tool: Tool
    work: WorkFrame
    tools: dict[int, Tool]
    actuator_speed_max: NDArray[np.float64]
    actuator_accel_max: NDArray[np.float64] = field(default_factory=lambda: frozen(np.zeros(6)))

    def select(self, number: int) -> Tool:
        """Tool ``number`` of the table.

        Raises
        ------
        InputError
            The table has no such tool.
        """
        if number not in self.tools:
            have = ", ".join(f"T{n}" for n in sorted(self.tools)) or "none"
            msg = f"tool {number}: not in the tool table (tools.T<n>; defined: {have})"
            raise InputError(msg)
        return self.tools[number]


def cell_from_mapping(parameters: Mapping[str, Any]) -> CellFrames:
    """Read and validate ``tool.*``, ``work.*``, ``tools.T<n>.*`` and
    ``limits.actuator_speed_max`` from a parameter mapping (nested or dotted names).

    Other names are left to
    :func:`~hexapod_workspace.core.evaluation.loading.manipulator_from_mapping` and the node.

    Returns
    -------
    CellFrames

    Raises
    ------
    ConfigError
        One line naming the parameter, what was expected and the value given: unknown names
        under ``tool``, ``work`` or ``tools``, non-numbers, NaN or infinities, wrong counts,
        negative speeds, an empty frame name.
    """
    flat = flatten(parameters)
    for name in sorted(flat):
        if name.startswith(("tool.", "work.")) and name not in CELL_DEFAULTS:
            known = ", ".join(k for k in CELL_DEFAULTS if k.split(".")[0] == name.split(".")[0])
            msg = f"{name}: unknown parameter (expected one of {known})"
            raise ConfigError(msg)
        if name.startswith("tools.") and not _TOOL_KEY.match(name):
            msg = (
                f"{name}: unknown parameter (expected tools.T<n>.offset or "
                "tools.T<n>.orientation, n = 1, 2, ...)"
            )
            raise ConfigError(msg)
    values = {**CELL_DEFAULTS, **{k: v for k, v in flat.items() if k in CELL_DEFAULTS}}
    tool = Tool(
        frozen(vector3("tool.offset", values["tool.offset"])),
        frozen(angles3("tool.orientation", values["tool.orientation"])),
    )
    frame_id = values["work.frame_id"]
    if not isinstance(frame_id, str) or not frame_id.strip():
        msg = f"work.frame_id: expected a non-empty string, got {describe(frame_id)}"
        raise ConfigError(msg)
    work = WorkFrame(
        frozen(vector3("work.origin", values["work.origin"])),
        frozen(angles3("work.orientation", values["work.orientation"])),
        frame_id,
    )
    entries: dict[int, dict[str, Any]] = {}
    for name, value in flat.items():
        match = _TOOL_KEY.match(name)
        if match:
            entries.setdefault(int(match.group(1)), {})[match.group(2)] = value
    tools = {}
    for number in sorted(entries):
        entry = entries[number]
        if "offset" not in entry:
            msg = f"tools.T{number}.offset: required parameter is missing (tool T{number})"
            raise ConfigError(msg)
        tools[number] = Tool(
            frozen(vector3(f"tools.T{number}.offset", entry["offset"])),
            frozen(angles3(f"tools.T{number}.orientation", entry.get("orientation", [0.0] * 3))),
            number,
        )
    tool = _selected(tool, tools, values["tool.number"])
    speeds, accels = (
        _actuator_limits(name, values[name])
        for name in ("limits.actuator_speed_max", "limits.actuator_accel_max")
    )
    return CellFrames(tool, work, tools, speeds, accels)


def _actuator_limits(name: str, value: Any) -> NDArray[np.float64]:
    """One or six values >= 0 (0 = unlimited) of ``name``, as six (ConfigError otherwise)."""
    limits = numbers(name, value)
    if limits.size not in (1, 6):
        msg = f"{name}: expected 1 or 6 numbers, got {limits.size}"
        raise ConfigError(msg)
    if np.any(limits < 0.0):
        msg = f"{name}: expected values >= 0 (0 = unlimited), got {describe(limits.tolist())}"
        raise ConfigError(msg)
    return frozen(np.broadcast_to(limits, (6,)).copy())


def _selected(tool: Tool, tools: dict[int, Tool], number: Any) -> Tool:
    """The active tool: ``tool`` for ``tool.number`` 0, else the table's entry (ConfigError
    naming ``tool.number`` and the defined tools when there is none)."""
    number = tool_number(number)
    if number == 0:
        return tool
    if number not in tools:
        raise unknown_tool(number, tools)
    return tools[number]


def cell_from_params_file(path: str | Path) -> CellFrames:
    """:func:`cell_from_mapping` of a ROS 2 parameters file (the one the CLI reads).

    Raises
    ------
    ConfigError
        Unreadable file, or a cell parameter :func:`cell_from_mapping` refuses (prefixed with
        the file name).
    """
    parameters = load_params_file(path)
    try:
        return cell_from_mapping(parameters)
    except ConfigError as error:
        msg = f"parameters file {path}: {error}"
        raise ConfigError(msg) from error


def tool_model(manipulator: Manipulator, tool: Tool) -> Manipulator:
    """The manipulator that answers for tool-frame poses (see the module documentation).

    Parameters
    ----------
    manipulator : Manipulator
        The model in the platform frame P (``geometry.platform_joints`` as written).
    tool : Tool

    Returns
    -------
    Manipulator
        Platform joints ``b'_i = R_toolᵀ(b_i − t)`` and axes ``jB'_i = R_toolᵀ·jB_i`` (frame C);
        the same object when the tool is the identity. Its ``home_position`` is C's position
        at P's home pose, ``home + t`` (used only to order leg pairs); ``position`` (the
        default pose position) is the tool centre point's.
    """
    if tool.is_identity and manipulator.collision is None:
        return manipulator
    scene = manipulator.collision
    if scene is not None:
        transform = np.eye(4)
        transform[:3, :3] = tool.rotation
        transform[:3, 3] = tool.offset
        scene = scene.in_tool_frame(transform)
    if tool.is_identity:
        return replace(manipulator, collision=scene)
    rotation_t = tool.rotation.T
    joints = (manipulator.platform_joints - tool.offset) @ rotation_t.T
    axes = manipulator.platform_joint_axes @ rotation_t.T
    return replace(
        manipulator,
        platform_joints=frozen(joints),
        platform_joint_axes=frozen(axes),
        home_position=frozen(manipulator.home_position + tool.offset),
        axes_from_home=(manipulator.axes_from_home[0], False),
        collision=scene,
    )


def _pose_arrays(
    rotations: ArrayLike, positions: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    rotation = np.asarray(rotations, dtype=np.float64)
    position = np.asarray(positions, dtype=np.float64)
    if rotation.shape[-2:] != (3, 3) or position.shape[-1:] != (3,):
        msg = (
            f"poses: expected rotations (..., 3, 3) and positions (..., 3), "
            f"got {rotation.shape} and {position.shape}"
        )
        raise InputError(msg)
    return rotation, position


def platform_pose(
    rotations: ArrayLike, positions: ArrayLike, tool: Tool
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The platform frame's pose for tool-frame poses: ``R_P = R·R_toolᵀ``, ``p_P = p − R_P·t``.

    Parameters
    ----------
    rotations : array_like, shape (..., 3, 3)
        R of the tool frame C in the base frame.
    positions : array_like, shape (..., 3)
        OC, base frame, m.
    tool : Tool

    Returns
    -------
    rotations, positions : ndarray, shapes (..., 3, 3) and (..., 3)
        R_P and OP, base frame, m.
    """
    rotation, position = _pose_arrays(rotations, positions)
    platform = rotation @ tool.rotation.T
    return platform, position - np.einsum("...ij,j->...i", platform, tool.offset)


def tool_pose(
    rotations: ArrayLike, positions: ArrayLike, tool: Tool
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The inverse of :func:`platform_pose`: ``R = R_P·R_tool``, ``p = p_P + R_P·t``."""
    rotation, position = _pose_arrays(rotations, positions)
    return rotation @ tool.rotation, position + np.einsum("...ij,j->...i", rotation, tool.offset)


def work_to_base(
    rotations: ArrayLike, positions: ArrayLike, work: WorkFrame
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Poses given in the work frame, in the base frame: ``R_O = R_W·R``, ``p_O = o + R_W·p``.

    Parameters
    ----------
    rotations : array_like, shape (..., 3, 3)
        Orientations in W.
    positions : array_like, shape (..., 3)
        Positions in W, m.
    work : WorkFrame

    Returns
    -------
    rotations, positions : ndarray, shapes (..., 3, 3) and (..., 3)
        In the base frame, m.
    """
    rotation, position = _pose_arrays(rotations, positions)
    r_w = work.rotation
    return r_w @ rotation, work.origin + position @ r_w.T


def vectors_to_base(vectors: ArrayLike, work: WorkFrame) -> NDArray[np.float64]:
    """Free vectors (tool axes, directions), shape (..., 3), from W to the base frame."""
    array = np.asarray(vectors, dtype=np.float64)
    rotated: NDArray[np.float64] = array @ work.rotation.T
    return rotated


def curves_to_base(
    arcs: NDArray[np.float64] | None, beziers: NDArray[np.float64] | None, work: WorkFrame
) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """Curved moves from W to the base frame, one row per move: ``arcs`` (K, 7: the centre moves
    as a point, the axis turns as a vector, the angle stays) and ``beziers`` (K, 6: two inner
    control points, as points). None stays None, NaN rows stay NaN."""
    if arcs is not None:
        arcs = arcs.copy()
        arcs[:, :3] = work.origin + arcs[:, :3] @ work.rotation.T
        arcs[:, 3:6] = vectors_to_base(arcs[:, 3:6], work)
    if beziers is not None:
        beziers = (work.origin + beziers.reshape(-1, 3) @ work.rotation.T).reshape(-1, 6)
    return arcs, beziers


def cell_unit_reason(manipulator: Manipulator, cell: CellFrames) -> str | None:
    """:func:`~hexapod_workspace.core.base.validation.millimetre_reason` of the cell's lengths and
    speeds against the machine's size: ``tool.offset``, ``tools.T<n>.offset``, ``work.origin``
    (m) and, for actuators that slide (``ups``, ``pus``: m/s), ``limits.actuator_speed_max``."""
    size = machine_size(
        manipulator.base_joints, manipulator.platform_joints, manipulator.home_position
    )
    checks: list[tuple[str, ArrayLike, str, str]] = [
        ("tool.offset", cell.tool.offset if cell.tool.number == 0 else np.zeros(3), "m", ""),
        *((f"tools.T{n}.offset", t.offset, "m", "") for n, t in sorted(cell.tools.items())),
        ("work.origin", cell.work.origin, "m", ""),
    ]
    if architecture_module(manipulator.architecture).ACTUATOR_UNIT == "m":
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
