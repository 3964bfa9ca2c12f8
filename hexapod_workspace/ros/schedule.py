"""The ``~/schedule_path`` service: the fastest certified feed schedule of a path, from ROS.

:func:`attach_schedule` adds to a node the service ``~/schedule_path``
(``hexapod_workspace_msgs/srv/SchedulePath``): a path of ``geometry_msgs/Pose`` in the base or
the work frame (``header.frame_id``, as ``~/check_path``), with the arcs and Bézier moves
``~/check_path`` takes, per-move programmed feeds (ceilings, not targets), rapid moves and the
stops asked for. The answer is :func:`hexapod_workspace.core.motions.schedule.schedule_path`
under the node's ``limits.actuator_speed_max`` and ``limits.actuator_accel_max``, as the CLI's
``schedule`` command gives it (the same moves, ceilings and summary), plus ``path_ok``: the path
checked as ``~/check_path`` checks it. Requests and responses are recorded in the node's log
(``replay`` lists them).

A service, not an action: a schedule of 1,000 moves takes about a second of CPU
(``benchmarks/schedule.py``), and the grid is bounded
(:data:`~hexapod_workspace.core.motions.schedule.MAX_SCHEDULE_INTERVALS`); a request with more
than :data:`MAX_WAYPOINTS` waypoints is refused, naming the bound.

Units: m, rad, s; feeds in mm/min (rotations deg/min) as the CL files and ``~/check_path`` give
them; actuator speeds m/s (legs, slides) or rad/s (cranks).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from hexapod_workspace_msgs.srv import SchedulePath
from numpy.typing import NDArray

from ..core.base.rotations import quaternion_to_matrix
from ..core.motions import DEFAULT_PATH_TOLERANCE, check_path
from ..core.motions.schedule import schedule_path
from ..core.motions.schedule_report import (
    feed_ceilings,
    limited_by,
    programmed_duration,
    rapid_boundaries,
)
from ..core.motions.speeds import ACTUATOR_MODELS
from ..errors import HexapodWorkspaceError, InputError
from ..logs.cell import DEG_MIN, MM_MIN, cell_frames_fields
from . import cell
from .load_rows import require_geometric
from .parameters import State
from .paths import curve_rows, pose_arrays, positive_option
from .services import fields_service

__all__ = ["MAX_WAYPOINTS", "attach_schedule", "schedule_response_fields"]

#: The most waypoints one request may give (a bounded answer time; overload is refused).
MAX_WAYPOINTS = 20_001


def _ceilings(
    request: Any, count: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], float, NDArray[np.bool_]]:
    """Per move: the feed ceiling (m/s, inf: none) and the programmed feed (m/s, NaN: none);
    the rotary ceiling (rad/s, NaN: none) and the rapid flags (validated, InputError)."""
    rapid: NDArray[np.bool_] = np.zeros(count, dtype=bool)
    if len(request.rapid):
        if len(request.rapid) != count:
            msg = f"rapid: expected none or one per move ({count}), got {len(request.rapid)}"
            raise InputError(msg)
        rapid = np.asarray(list(request.rapid), dtype=bool)
    feeds = cell.feed_values(request.feeds_mm_min, count, "feeds_mm_min") * MM_MIN
    rapid_feed = cell.optional_rate(request.rapid_feed_mm_min, "rapid_feed_mm_min", "mm/min")
    rotary = cell.optional_rate(request.rotary_feed_deg_min, "rotary_feed_deg_min", "deg/min")
    feed_max = cell.optional_rate(request.feed_max_mm_min, "feed_max_mm_min", "mm/min")
    linear, programmed = feed_ceilings(feeds, rapid, rapid_feed * MM_MIN, feed_max * MM_MIN)
    return linear, programmed, rotary * DEG_MIN, rapid


def _stops(request: Any, count: int, rapid: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """The waypoints the request asks to rest at (the ends always rest)."""
    stops: NDArray[np.bool_] = np.zeros(count + 1, dtype=bool)
    if len(request.stops):
        if len(request.stops) != count + 1:
            msg = (
                f"stops: expected none or one per waypoint ({count + 1}), got {len(request.stops)}"
            )
            raise InputError(msg)
        stops = np.asarray(list(request.stops), dtype=bool)
    if request.stop_at_rapids:
        stops |= rapid_boundaries(rapid)
    return stops


def _moves(
    schedule: Any, linear: NDArray[np.float64], rotary: float, rapid: NDArray[np.bool_]
) -> list[dict[str, Any]]:
    """``ScheduledMove`` fields of every move (mm/min, deg/min for rotations)."""
    turning = math.inf if math.isnan(rotary) else rotary
    ceiling = np.where(schedule.rotary, turning, linear)
    kinds, actuators = limited_by(schedule, ceiling)
    moves = []
    for k in range(schedule.t_start.size):
        unit = DEG_MIN if schedule.rotary[k] else MM_MIN
        top = float(ceiling[k])
        moves.append(
            {
                "actuator_speed_peak": [float(v) for v in schedule.speed_peak[k]],
                "actuator_accel_peak": [float(v) for v in schedule.accel_peak[k]],
                "t_start_s": float(schedule.t_start[k]),
                "t_end_s": float(schedule.t_end[k]),
                "feed_peak": float(schedule.feed_peak[k] / unit),
                "feed_ceiling": top / unit if math.isfinite(top) else math.nan,
                "rotary": bool(schedule.rotary[k]),
                "rapid": bool(rapid[k]),
                "limited_by": kinds[k],
                "limiting_actuator": int(actuators[k]),
            }
        )
    return moves


def _summary(duration: float, programmed: float, moves: list[dict[str, Any]]) -> str:
    against = (
        "no programmed time (a move has no feed)"
        if math.isnan(programmed)
        else f"{programmed:.3f} s at the programmed feeds"
    )
    slow = [m for m in moves if m["limited_by"] != "feed"]
    return (
        f"schedule: {duration:.3f} s ({against}), {len(moves)} moves, {len(slow)} below "
        "their feed ceiling (actuator speed or acceleration)"
    )


def schedule_response_fields(state: State, request: Any) -> dict[str, Any]:
    """``SchedulePath_Response`` fields answering ``request`` with the node's state (a refusal,
    ``success`` false with the reason, for a bad request or a move that cannot be scheduled).
    """
    frames = cell_frames_fields(state.cell, request.header.frame_id)
    unit = ACTUATOR_MODELS.get(state.manipulator.architecture)
    try:
        require_geometric(state, "a schedule")
        count = len(request.poses) - 1
        if count + 1 > MAX_WAYPOINTS:
            msg = f"poses: at most {MAX_WAYPOINTS} waypoints per request, got {count + 1}"
            raise InputError(msg)
        if count < 1:
            msg = f"poses: expected at least 2 waypoints, got {count + 1}"
            raise InputError(msg)
        tolerance = positive_option(request.tolerance, "tolerance", DEFAULT_PATH_TOLERANCE)
        positions, quaternions = pose_arrays(request.poses)
        arcs = curve_rows(request.arcs, count + 1, 7, "arcs")
        beziers = curve_rows(request.beziers, count + 1, 6, "beziers")
        linear, programmed, rotary, rapid = _ceilings(request, count)
        stops = _stops(request, count, rapid)
        positions, quaternions = cell.poses_to_base(
            state, request.header.frame_id, positions, quaternions
        )
        arcs, beziers = cell.curves_to_base(state, request.header.frame_id, arcs, beziers)
        manipulator = state.manipulator
        checked = check_path(
            manipulator,
            positions,
            quaternions=quaternions,
            tolerance=tolerance,
            arcs=arcs,
            beziers=beziers,
        )
        limits = cell.actuator_limits(state)
        schedule = schedule_path(
            manipulator,
            positions,
            quaternion_to_matrix(quaternions),
            speed_limits=limits[0],
            accel_limits=limits[1],
            feeds=linear,
            rotary_feeds=np.full(count, math.inf if math.isnan(rotary) else rotary),
            stops=stops,
            arcs=arcs,
            beziers=beziers,
        )
    except HexapodWorkspaceError as error:
        return {"success": False, "message": str(error), "frames": frames}
    planned = programmed_duration(schedule, programmed, rotary)
    moves = _moves(schedule, linear, rotary, rapid)
    return {
        "success": True,
        "message": _summary(schedule.duration, planned, moves),
        "path_ok": bool(checked.ok),
        "s": [float(v) for v in schedule.s],
        "duration_s": schedule.duration,
        "sdot": [float(v) for v in schedule.sdot],
        "programmed_duration_s": planned,
        "moves": moves,
        "stops": [int(k) for k in np.flatnonzero(schedule.stops)],
        "intervals": int(schedule.intervals),
        "actuator_speed_max": [float(v) for v in limits[0]],
        "actuator_accel_max": [float(v) for v in limits[1]],
        "actuator_unit": unit.unit if unit is not None else "",
        "frames": frames,
    }


def attach_schedule(node: Any) -> Any:
    """Create ``~/schedule_path`` on ``node``, answered by :func:`schedule_response_fields`
    with the node's state and recorded (:func:`~hexapod_workspace.ros.services.fields_service`)."""
    return fields_service(node, SchedulePath, "schedule_path", schedule_response_fields)
