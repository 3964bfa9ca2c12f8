"""Path checks and torsion plans <-> message fields (``CheckPath``, ``PathSegmentCheck``, poses).

The same nested-dict form as :mod:`hexapod_workspace.logs.messages`: keys are ROS field names,
values plain Python numbers, lists and dicts, so that :mod:`hexapod_workspace.ros.conversions`
(rclpy) and :mod:`hexapod_workspace.logs` (rosbags, MCAP) build messages from them.
Units: m, rad; positions and quaternions in the base frame; quaternions ``(x, y, z, w)``.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.base.rotations import matrix_to_quaternion, tt_to_matrix
from ..core.motions import (
    INTERPOLATIONS,
    PathCheck,
    SegmentChecks,
    TorsionPlan,
    reported_parts,
)
from . import messages
from .interfaces import interface

__all__ = [
    "CHECK_PATH_TOPIC",
    "CHECK_PATH_TYPE",
    "INTERPOLATION_CODES",
    "check_path_request_fields",
    "check_path_response_fields",
    "failed_check_path_response_fields",
    "loads_call_line",
    "loads_call_report",
    "path_call_fields",
    "path_call_line",
    "path_call_report",
    "pose_fields",
    "schedule_call_line",
    "schedule_call_report",
    "segment_check_fields",
    "segment_checks_fields",
]

#: The node's path service and its type (recorded as ``<service>/request`` and ``/response``).
CHECK_PATH_TOPIC = interface("check_path").name
CHECK_PATH_TYPE = interface("check_path").type
#: ``CheckPath`` interpolation constants by core name (SLERP = 0, TILT_TORSION = 1).
INTERPOLATION_CODES = {name: code for code, name in enumerate(INTERPOLATIONS)}


def pose_fields(position: ArrayLike, quaternion: ArrayLike) -> dict[str, Any]:
    """geometry_msgs/msg/Pose from a position (3,), m, and a quaternion (4,) (x, y, z, w)."""
    x, y, z, w = (float(v) for v in np.asarray(quaternion, dtype=float).reshape(4))
    return {
        "position": messages.point_fields(position),
        "orientation": {"x": x, "y": y, "z": z, "w": w},
    }


def _poses_fields(
    positions: NDArray[np.float64], quaternions: NDArray[np.float64]
) -> list[dict[str, Any]]:
    return [
        pose_fields(position, quaternion)
        for position, quaternion in zip(positions, quaternions, strict=True)
    ]


def check_path_request_fields(
    positions: ArrayLike,
    quaternions: ArrayLike,
    *,
    free_torsion: bool = False,
    interpolation: str = "slerp",
    tolerance: float = 0.0,
    max_dpsi: float | None = None,
    psi_step: float = 0.0,
) -> dict[str, Any]:
    """hexapod_workspace_msgs/srv/CheckPath_Request.

    Parameters
    ----------
    positions : array_like, shape (N, 3)
        Tool-tip positions, base frame, m.
    quaternions : array_like, shape (N, 4)
        Orientations (x, y, z, w); with ``free_torsion`` only their z-axis counts.
    free_torsion : bool
    interpolation : {"slerp", "tilt-torsion"}
    tolerance, psi_step : float
        rad; 0 = the node's default.
    max_dpsi : float, optional
        rad; None = no limit.
    """
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    quaternions = np.asarray(quaternions, dtype=float).reshape(-1, 4)
    return {
        "poses": _poses_fields(positions, quaternions),
        "free_torsion": bool(free_torsion),
        "interpolation": INTERPOLATION_CODES[interpolation],
        "tolerance": float(tolerance),
        "limit_dpsi": max_dpsi is not None,
        "max_dpsi": float(max_dpsi) if max_dpsi is not None else 0.0,
        "psi_step": float(psi_step),
        "header": messages.header_fields(0, ""),
        "rapid": [],
        "feeds_mm_min": [],
        "rapid_feed_mm_min": 0.0,
        "durations_s": [],
        "rotary_feed_deg_min": 0.0,
        "arcs": [],
        "beziers": [],
    }


def segment_checks_fields(segments: SegmentChecks, *, pairs: bool = True) -> list[dict[str, Any]]:
    """PathSegmentCheck dicts of every move of a check, in order.

    ``pairs=False`` leaves ``limiting_pair`` empty (the interference check is disabled).
    """
    violated = segments.violated
    columns = {
        "ok": segments.ok.tolist(),
        "first_violation_s": segments.first_violation_s.tolist(),
        "positions": segments.violation_positions.tolist(),
        "angles": segments.violation_angles.tolist(),
        "limiting_leg": segments.limiting_leg.tolist(),
        "limiting_pair": segments.limiting_pair.tolist(),
        "min_relative_margin": segments.min_relative_margin.tolist(),
        "min_at_s": segments.min_at_s.tolist(),
        "min_relative_margin_bound": segments.min_relative_margin_bound.tolist(),
        # the pair at the first violation (a move that is ok: ""; no scene: no names)
        "collision_pair": list(segments.collision_pair) or [""] * len(segments),
    }
    fields = []
    for k in range(len(segments)):
        x, y, z = columns["positions"][k]
        phi, theta, psi = columns["angles"][k]
        fields.append(
            {
                "ok": bool(columns["ok"][k]),
                "first_violation_s": float(columns["first_violation_s"][k]),
                "position_at_violation": {"x": x, "y": y, "z": z},
                "pose_at_violation": {"phi": phi, "theta": theta, "psi": psi},
                "violated": list(violated[k]),
                "limiting_leg": int(columns["limiting_leg"][k]),
                "limiting_pair": [int(v) for v in columns["limiting_pair"][k]] if pairs else [],
                "min_relative_margin": float(columns["min_relative_margin"][k]),
                "min_at_s": float(columns["min_at_s"][k]),
                "min_relative_margin_bound": float(columns["min_relative_margin_bound"][k]),
                "collision_pair": "" if columns["ok"][k] else columns["collision_pair"][k],
            }
        )
    return fields


def segment_check_fields(segments: SegmentChecks, index: int = 0) -> dict[str, Any]:
    """PathSegmentCheck of move ``index`` (e.g. the single move of a commanded motion)."""
    window = slice(index, index + 1)
    # The dataclass fields only: vars() would also hold the per-move lists the result keeps
    # once they have been read (``violated``), which are not constructor arguments.
    values = {field.name: getattr(segments, field.name) for field in dataclasses.fields(segments)}
    fields: dict[str, Any] = {
        name: value
        if not isinstance(value, np.ndarray)
        else (value[:, window] if name == "violation_margins" else value[window])
        for name, value in values.items()
    }
    single = SegmentChecks(**fields)
    return segment_checks_fields(single)[0]


def check_path_response_fields(
    result: PathCheck | TorsionPlan,
    *,
    pairs: bool = True,
    message: str | None = None,
    baseline: PathCheck | None = None,
) -> dict[str, Any]:
    """hexapod_workspace_msgs/srv/CheckPath_Response of a path check or a torsion plan.

    Parameters
    ----------
    result : PathCheck or TorsionPlan
        A plan without a solution reports the ψ = 0 poses (``planned_torsion`` false, the
        break point in ``break_kind``/``break_index`` and ``message``).
    pairs : bool
        Whether the interference check is enabled (``limiting_pair`` filled).
    message : str, optional
        Default: a one-line verdict (see :func:`path_verdict`).
    baseline : PathCheck, optional
        The ψ = 0 baseline of a path of fixed orientations
        (:func:`hexapod_workspace.core.motions.baseline.reported_baseline`); a plan's is its own.
    """
    path, plan = reported_parts(result)
    waypoints = path.waypoints
    rotations = tt_to_matrix(waypoints.angles)
    if plan is not None:
        baseline = plan.baseline
    fields: dict[str, Any] = {
        "success": True,
        "message": message if message is not None else path_verdict(result),
        "ok": bool(plan.ok if plan is not None else path.ok) and path.ok,
        "planned_torsion": bool(plan is not None and plan.ok),
        "poses": _poses_fields(waypoints.positions, matrix_to_quaternion(rotations)),
        "orientations": [{"phi": p, "theta": t, "psi": s} for p, t, s in waypoints.angles.tolist()],
        "waypoints": messages.pose_checks_fields(waypoints),
        "segments": segment_checks_fields(path.segments, pairs=pairs),
        "objective": float(plan.objective) if plan is not None and plan.ok else math.nan,
        "break_kind": plan.breakpoint.kind if plan is not None and plan.breakpoint else "",
        "break_index": plan.breakpoint.index if plan is not None and plan.breakpoint else -1,
        "psi_zero_waypoints_failed": baseline.failed_waypoints if baseline is not None else [],
        "psi_zero_segments_failed": baseline.failed_segments if baseline is not None else [],
        "speeds": [],
        "actuator_speed_max": [0.0] * 6,
        "frames": messages.no_cell_frames_fields(),
    }
    return fields


def failed_check_path_response_fields(reason: str) -> dict[str, Any]:
    """A CheckPath_Response refusing a bad request (``success`` false, ``message`` why)."""
    return {
        "success": False,
        "message": reason,
        "ok": False,
        "objective": math.nan,
        "break_index": -1,
    }


def path_verdict(result: PathCheck | TorsionPlan) -> str:
    """One line: whether the path runs, else where it fails (or where no torsion continues)."""
    path, plan = reported_parts(result)
    if plan is not None and not plan.ok and plan.breakpoint is not None:
        return f"no torsion plan: {plan.breakpoint.reason}"
    count, moves = len(path.waypoints), len(path.segments)
    if path.ok:
        planned = " with the planned torsion" if plan is not None else ""
        return f"path runs{planned}: {count} waypoints and {moves} moves ok"
    parts = []
    if path.failed_waypoints:
        parts.append(f"waypoints {_short_list(path.failed_waypoints)} unreachable")
    if path.failed_segments:
        first = path.failed_segments[0]
        segments = path.segments
        parts.append(
            f"moves {_short_list(path.failed_segments)} leave the workspace (first: move "
            f"{first} at s = {segments.first_violation_s[first]:.4f}, "
            f"{', '.join(segments.violated[first]) or 'violated'})"
        )
    return "path does not run: " + "; ".join(parts)


def _short_list(indices: list[int], most: int = 8) -> str:
    shown = ", ".join(str(i) for i in indices[:most])
    return shown + (f", ... ({len(indices)} in all)" if len(indices) > most else "")


# --------------------------------------------------------------------------- replay summaries
def path_call_fields(
    calls: list[dict[str, Any]], topic: str, log_time_ns: int, message: Any
) -> None:
    """Gather a recorded CheckPath request or response into ``calls`` (replay's summary).

    A request opens a call; a response completes the oldest open call of its service (the
    n-th response answers the n-th request), or stands alone when its request was not recorded.
    """
    from .fields import message_to_fields

    fields = message_to_fields(message)
    service = topic.rsplit("/", 1)[0]
    if topic.endswith("/request"):
        calls.append(
            {"service": service, "log_time_ns": log_time_ns, "request": fields, "response": None}
        )
        return
    for call in calls:
        if call["service"] == service and call["response"] is None and call["request"]:
            call["response"] = fields
            return
    calls.append(
        {"service": service, "log_time_ns": log_time_ns, "request": None, "response": fields}
    )


def path_call_report(index: int, call: dict[str, Any], start_ns: int) -> dict[str, Any]:
    """The JSON summary of one recorded CheckPath call."""
    request, response = call["request"] or {}, call["response"] or {}
    segments = response.get("segments", [])
    waypoints = response.get("waypoints", [])
    return {
        "index": index,
        "time_s": (call["log_time_ns"] - start_ns) / 1e9,
        "service": call["service"],
        "n_waypoints": len(request.get("poses", [])) if call["request"] else None,
        "free_torsion": bool(request.get("free_torsion")) if call["request"] else None,
        "answered": call["response"] is not None,
        "success": response.get("success"),
        "ok": response.get("ok"),
        "planned_torsion": response.get("planned_torsion"),
        "message": response.get("message"),
        "waypoints_failed": sum(not w["reachable"] for w in waypoints),
        "segments_failed": sum(not m["ok"] for m in segments),
        "psi_zero_waypoints_failed": len(response.get("psi_zero_waypoints_failed", [])),
        "psi_zero_segments_failed": len(response.get("psi_zero_segments_failed", [])),
        "moves_to_slow_down": sum(
            bool(m["speed_checked"]) and not m["speed_ok"] for m in response.get("speeds", [])
        ),
    }


def _call_head(report: dict[str, Any]) -> tuple[str, str | None]:
    """A recorded call's line head, and its whole line when it has no answer or failed."""
    head = f"[{report['index']}] +{report['time_s']:.3f} s {report['service']}"
    if not report["answered"]:
        return head, f"{head}: no response recorded"
    if not report["success"]:
        return head, f"{head}: failed: {report['message']}"
    return head, None


def path_call_line(report: dict[str, Any]) -> str:
    """One text line for a :func:`path_call_report`."""
    head, unanswered = _call_head(report)
    if unanswered is not None:
        return unanswered
    count = report["n_waypoints"] if report["n_waypoints"] is not None else "?"
    mode = ", torsion planned" if report["planned_torsion"] else ""
    return (
        f"{head}: {count} waypoints{mode}: {'runs' if report['ok'] else 'does not run'} "
        f"({report['waypoints_failed']} waypoints, {report['segments_failed']} moves fail; "
        f"psi = 0: {report['psi_zero_waypoints_failed']} and "
        f"{report['psi_zero_segments_failed']})"
        + (
            f"; {report['moves_to_slow_down']} move(s) must slow down (actuator speed)"
            if report.get("moves_to_slow_down")
            else ""
        )
    )


def schedule_call_report(index: int, call: dict[str, Any], start_ns: int) -> dict[str, Any]:
    """The JSON summary of one recorded ``~/schedule_path`` call (gathered by
    :func:`path_call_fields`): its time against the programmed feeds, and the moves an
    actuator holds below their feed ceiling, with the actuator and the kind of limit."""
    request, response = call["request"] or {}, call["response"] or {}
    moves = response.get("moves", [])
    slow = [
        {
            "move": k + 1,
            "limited_by": move["limited_by"],
            "actuator": int(move["limiting_actuator"]) or None,
            "feed_peak": float(move["feed_peak"]),
        }
        for k, move in enumerate(moves)
        if move["limited_by"] != "feed"
    ]
    programmed = response.get("programmed_duration_s")
    return {
        "index": index,
        "time_s": (call["log_time_ns"] - start_ns) / 1e9,
        "service": call["service"],
        "n_waypoints": len(request.get("poses", [])) if call["request"] else None,
        "answered": call["response"] is not None,
        "success": response.get("success"),
        "message": response.get("message"),
        "path_ok": response.get("path_ok"),
        "duration_s": response.get("duration_s"),
        "programmed_duration_s": (
            None if programmed is None or math.isnan(programmed) else programmed
        ),
        "n_moves": len(moves),
        "stops": len(response.get("stops", [])),
        "below_ceiling": slow,
    }


def schedule_call_line(report: dict[str, Any]) -> str:
    """One text line for a :func:`schedule_call_report`."""
    head, unanswered = _call_head(report)
    if unanswered is not None:
        return unanswered
    planned = report["programmed_duration_s"]
    against = "no programmed time" if planned is None else f"{planned:.3f} s programmed"
    return (
        f"{head}: {report['n_moves']} moves in {report['duration_s']:.3f} s ({against}), "
        f"{report['stops']} stops, {len(report['below_ceiling'])} below their feed ceiling; "
        f"path {'runs' if report['path_ok'] else 'does not run'}"
    )


def loads_call_report(index: int, call: dict[str, Any], start_ns: int) -> dict[str, Any]:
    """The JSON summary of one recorded ``~/loads`` call: the pose asked (m, quaternion
    ``x, y, z, w``, in ``frame_id``), the payload, the worst actuator force and the answer's
    one-line summary (NaN and infinities as null)."""
    request, response = call["request"] or {}, call["response"] or {}
    pose = request.get("pose")
    worst = [float(v) for v in response.get("actuator_force_worst", [])]
    return {
        "index": index,
        "time_s": (call["log_time_ns"] - start_ns) / 1e9,
        "service": call["service"],
        "answered": call["response"] is not None,
        "success": response.get("success"),
        "message": response.get("message"),
        "frame_id": request["header"]["frame_id"] if call["request"] else None,
        "position": [pose["position"][k] for k in "xyz"] if pose else None,
        "orientation": [pose["orientation"][k] for k in "xyzw"] if pose else None,
        "mass_kg": response.get("mass_kg"),
        "singular": response.get("singular"),
        "actuator_force_worst": [v if math.isfinite(v) else None for v in worst],
        "force_unit": response.get("force_unit"),
    }


def loads_call_line(report: dict[str, Any]) -> str:
    """One text line for a :func:`loads_call_report`."""
    head, unanswered = _call_head(report)
    if unanswered is not None:
        return unanswered
    where = ", ".join(f"{v:.4g}" for v in report["position"] or [])
    return f"{head}: at ({where}) m: {report['message']}"
