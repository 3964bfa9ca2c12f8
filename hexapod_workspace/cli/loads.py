"""``loads``: actuator forces, payload capacity, stiffness, deflection and accuracy at one pose
(:mod:`hexapod_workspace.core.evaluation.loads`, conventions in docs/theory.md, "Loads").

The pose is the tool frame's (``tool.*`` of ``--config``, as ``check`` takes it) at
``--position`` (default ``pose.position``), base frame. The loads come from the same file
(``load.*``, ``process.*``, ``stiffness.*``, ``accuracy.*``, ``limits.actuator_force_max``,
``limits.actuator_force_min``, ``limits.deflection_max``, ``limits.accuracy_max``; the centre of
mass is given in the platform frame). This command does not judge the pose's geometry: that is
``check``'s.

JSON (``--json``): ``actuator_force_n`` (six, gravity plus the process centre; N, N·m for
cranks; > 0 pushes), ``actuator_force_worst_n`` (six, the largest |τ_i| over the process box),
``actuator_force_range_n`` (six [low, high] pairs over the box), ``force_margin_n`` and
``payload_capacity_kg`` (null without ``limits.actuator_force_max``), ``limiting_actuator``
(1-based), ``deflection_m``, ``deflection_rad`` and ``stiffness`` (the 6×6 K; null without
``stiffness.actuator``), ``accuracy_m``, ``accuracy_rad`` (null without
``accuracy.actuator_error``), ``jacobian`` (6×6 J), ``singular``, ``limits_hold``, ``violated``
(names of the limits exceeded), ``pose_deg``, ``position``, ``tool``. Non-finite values (a
singular pose) are null.

Exit codes: 0 every configured limit holds, 1 one does not (or the pose is singular or out of
the legs' reach; the reason on stderr), 2 bad input.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from .._resources import example_config_path
from ..core.cell.frames import cell_from_params_file, require_plausible_cell, tool_model
from ..core.evaluation.loads import (
    Loads,
    loads_at,
)
from ..core.model.architectures import module as architecture_module
from .cam import tool_json
from .commands import PROG
from .inputs import (
    add_angles_option,
    configured_model,
    pose_flag,
    tool_position,
)

__all__ = [
    "LOADS_DESCRIPTION",
    "LOADS_HELP",
    "cmd_loads",
    "loads_arguments",
]

LOADS_HELP = "actuator forces, payload capacity, deflection and accuracy at one pose"
LOADS_DESCRIPTION = (
    "The loads of --config (load.*, process.*, stiffness.*, accuracy.* and the loads' limits) "
    "at the tool frame's pose: tau = -J^-T w per actuator (gravity plus the process centre, and "
    "the worst over the process box), the largest payload every actuator holds, K = J^T diag(k) "
    "J and the worst deflection over the process box, and the tool error of the actuator "
    "errors. Exit 1 when a configured limit is exceeded or the pose is singular."
)


def loads_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of ``loads``."""
    parser.add_argument(
        "--pose",
        nargs="+",
        type=float,
        required=True,
        metavar="V",
        help="the tool frame's orientation: PHI THETA PSI in Tilt-and-Torsion angles, degrees, "
        "or the 3 angles (4 quaternion components) of --angles",
    )
    add_angles_option(parser)


def _finite(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _list(values: NDArray[np.float64] | None) -> Any:
    if values is None:
        return None
    return [_list(row) if np.ndim(row) else _finite(float(row)) for row in values]


def _violated(result: Loads, deflection_max: float, accuracy_max: float) -> list[str]:
    names = []
    if result.singular:
        names.append("singular")
    if result.force_margin is not None and result.force_margin < 0.0:
        names.append("actuator_force")
    deflection, accuracy = result.deflection_m, result.accuracy_m
    if deflection_max > 0.0 and deflection is not None and deflection > deflection_max:
        names.append("deflection")
    if accuracy_max > 0.0 and accuracy is not None and accuracy > accuracy_max:
        names.append("accuracy")
    return names


def cmd_loads(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``loads``: the loads at one pose."""
    path = Path(options.config) if options.config else example_config_path()
    platform, platform_case = configured_model(path, None, err, with_tool=False, loads_read=True)
    cell = require_plausible_cell(platform, cell_from_params_file(path))
    manipulator = tool_model(platform, cell.tool)
    case = platform_case.in_tool_frame(cell.tool.offset, cell.tool.rotation)
    position = tool_position(options.position, manipulator, platform)
    given = pose_flag(options.pose, options.angles)
    rotation = given.matrices()[0]
    result = loads_at(manipulator, case, rotation, position)
    violated = _violated(result, case.deflection_max, case.accuracy_max)
    spread = result.actuator_force_spread
    document: dict[str, Any] = {
        "actuator_force_n": _list(result.actuator_force),
        "actuator_force_worst_n": _list(result.actuator_force_worst),
        "actuator_force_range_n": _list(
            np.stack([result.actuator_force - spread, result.actuator_force + spread], axis=1)
        ),
        "force_margin_n": _finite(result.force_margin),
        "limiting_actuator": result.limiting_actuator,
        "payload_capacity_kg": _finite(result.payload_capacity),
        "deflection_m": _finite(result.deflection_m),
        "deflection_rad": _finite(result.deflection_rad),
        "stiffness": _list(result.stiffness),
        "accuracy_m": _finite(result.accuracy_m),
        "accuracy_rad": _finite(result.accuracy_rad),
        "jacobian": _list(result.jacobian),
        "singular": result.singular,
        "limits_hold": not violated,
        "violated": violated,
        "pose_deg": given.tt_degrees()[0].tolist(),
        "position": [float(v) for v in position],
        "tool": tool_json(cell.tool),
    }
    if options.json:
        out.write(json.dumps(document, allow_nan=False) + "\n")
    else:
        _text(document, result, case.mass, manipulator.architecture, out)
    if violated:
        err.write(f"{PROG}: loads: limits exceeded at this pose: {', '.join(violated)}\n")
        return 1
    return 0


def _row(values: Any) -> str:
    return " ".join("inf" if v is None else f"{v:10.4g}" for v in values)


def _text(
    document: dict[str, Any], result: Loads, mass: float, architecture: str, out: IO[str]
) -> None:
    phi, theta, psi = document["pose_deg"]
    out.write(
        f"pose phi {phi:.6g}, theta {theta:.6g}, psi {psi:.6g} deg (tt) at "
        f"{', '.join(f'{v:.6g}' for v in document['position'])} m, payload {mass:g} kg\n"
    )
    if result.singular:
        out.write("singular pose (or a leg out of reach): the actuators cannot hold any load\n")
    unit = architecture_module(architecture).FORCE_UNIT
    out.write(f"actuator force, {unit} (> 0 pushes):  {_row(document['actuator_force_n'])}\n")
    out.write(f"worst |force| over the process box: {_row(document['actuator_force_worst_n'])}\n")
    if result.force_margin is None:
        out.write("no actuator force limit (limits.actuator_force_max): no payload capacity\n")
    else:
        margin = document["force_margin_n"]
        shown = "-inf" if margin is None else f"{margin:.6g}"
        capacity = document["payload_capacity_kg"]
        held = "unbounded (no gravity)" if capacity is None else f"{capacity:.6g} kg"
        out.write(
            f"force margin: {shown} N (actuator {document['limiting_actuator']}); "
            f"payload capacity: {held}\n"
        )
    for label, key, configured in (
        ("deflection over the process box", "deflection", result.deflection_m),
        ("tool error from actuator errors", "accuracy", result.accuracy_m),
    ):
        if configured is None:
            continue
        metres, radians = document[f"{key}_m"], document[f"{key}_rad"]
        shown = "inf" if metres is None else f"{metres * 1e6:.4g} µm, {radians:.4g} rad"
        out.write(f"{label}: {shown}\n")
