"""The ``~/loads`` service: the loads at one pose, with the node's loads parameters.

:func:`attach_loads` adds ``~/loads`` (``hexapod_workspace_msgs/srv/Loads``) to a node: for a
``geometry_msgs/Pose`` of the tool centre point (base or work frame by ``header.frame_id``, as
every pose the node takes), :func:`hexapod_workspace.core.evaluation.loads.loads_at` under the
node's ``load.*``, ``process.*``, ``stiffness.actuator`` and ``accuracy.actuator_error`` in
force (set at run time as one validated whole with the model and the cell: a tool change or a
new payload between two requests; every change is on ``~/parameter_changes``). The centre of
mass is given in the platform frame and moved into the active tool's frame here, as the CLI's
``loads`` does. With ``limits.actuator_force_max`` set, ``force_margin`` and
``payload_capacity_kg`` are given (NaN without it); the loads' limits also enter every pose
verdict of the node (:mod:`~hexapod_workspace.ros.load_rows`). Calls are recorded.

Units: N (legs, slides) or N·m (cranks), m, rad, kg; matrices row-major.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from hexapod_workspace_msgs.srv import Loads as LoadsService
from numpy.typing import NDArray

from ..core.base.rotations import quaternion_to_matrix
from ..core.evaluation.loads import Loads, loads_at
from ..core.model.architectures import module as architecture_module
from ..errors import HexapodWorkspaceError, InputError
from ..logs.cell import cell_frames_fields
from . import cell
from .load_rows import tool_case
from .parameters import State
from .paths import pose_arrays
from .services import fields_service

__all__ = ["attach_loads", "loads_response_fields"]


def _flat(values: NDArray[np.float64] | None, size: int) -> list[float]:
    """A matrix row-major (NaN everywhere when not given)."""
    if values is None:
        return [math.nan] * size
    return [float(v) for v in np.asarray(values, dtype=np.float64).reshape(-1)]


def _number(value: float | None) -> float:
    return math.nan if value is None else float(value)


def _summary(result: Loads, mass: float, unit: str) -> str:
    if result.singular:
        return "singular pose (or a leg out of reach): the actuators cannot hold any load"
    worst = int(np.argmax(result.actuator_force_worst))
    text = (
        f"payload {mass:g} kg: largest |force| {result.actuator_force_worst[worst]:.6g} {unit} "
        f"(actuator {worst + 1}) over the process box"
    )
    if result.deflection_m is not None:
        text += f"; deflection {result.deflection_m * 1e6:.4g} µm"
    if result.accuracy_m is not None:
        text += f"; tool error {result.accuracy_m * 1e6:.4g} µm"
    return text


def loads_response_fields(state: State, request: Any) -> dict[str, Any]:
    """``Loads_Response`` fields for ``request`` with the node's state (``success`` false and
    the reason for a bad pose or frame)."""
    frames = cell_frames_fields(state.cell, request.header.frame_id)
    try:
        positions, quaternions = pose_arrays([request.pose])
        if not (np.all(np.isfinite(positions)) and np.all(np.isfinite(quaternions))):
            msg = "pose: expected a finite position and orientation"
            raise InputError(msg)
        positions, quaternions = cell.poses_to_base(
            state, request.header.frame_id, positions, quaternions
        )
        rotation = quaternion_to_matrix(quaternions)[0]
    except HexapodWorkspaceError as error:
        return {"success": False, "message": str(error), "frames": frames}
    case = tool_case(state)
    manipulator = state.manipulator
    result = loads_at(manipulator, case, rotation, positions[0])
    unit = architecture_module(manipulator.architecture).FORCE_UNIT
    return {
        "success": True,
        "message": _summary(result, case.mass, unit),
        "singular": bool(result.singular),
        "actuator_force": _flat(result.actuator_force, 6),
        "actuator_force_worst": _flat(result.actuator_force_worst, 6),
        "actuator_force_spread": _flat(result.actuator_force_spread, 6),
        "jacobian": _flat(result.jacobian, 36),
        "stiffness": _flat(result.stiffness, 36),
        "deflection_m": _number(result.deflection_m),
        "deflection_rad": _number(result.deflection_rad),
        "accuracy_m": _number(result.accuracy_m),
        "accuracy_rad": _number(result.accuracy_rad),
        "force_margin": _number(result.force_margin),
        "payload_capacity_kg": _number(result.payload_capacity),
        "limiting_actuator": int(result.limiting_actuator),
        "mass_kg": float(case.mass),
        "force_unit": unit,
        "frames": frames,
    }


def attach_loads(node: Any) -> Any:
    """Create ``~/loads`` on ``node``, answered by :func:`loads_response_fields` with the node's
    state and recorded (:func:`~hexapod_workspace.ros.services.fields_service`)."""
    return fields_service(node, LoadsService, "loads", loads_response_fields)
