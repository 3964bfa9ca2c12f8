"""What ``hexapod-workspace replay`` reports about a log: the JSON document of
:func:`log_report` (every workspace, pose check, atlas, path check, schedule, loads call,
trigger, parameter change and axis limits recorded) and its text form
(:func:`log_report_text`, at most :data:`LIST_CAP` entries per kind).
"""

from __future__ import annotations

import math
import time
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from ..core.base.resolution import WorkspaceKind

if TYPE_CHECKING:  # the logs layer is loaded by replay itself
    from ..logs.summary import AtlasRecord, LogSummary, PoseCheckCall, WorkspaceRecord

__all__ = ["LIST_CAP", "jsonable", "log_report", "log_report_text"]


def _deg(value: float) -> float | None:
    return None if not math.isfinite(value) else math.degrees(value)


def _kind_label(kind: int) -> str:
    known = WorkspaceKind.of(kind)
    return known.label if known is not None else str(kind)


def _iso(ns: int | None) -> str:
    if ns is None:
        return "-"
    seconds, rest = divmod(ns, 1_000_000_000)
    return time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(seconds)) + f".{rest // 1_000_000:03d}Z"


def _finite(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def _workspace_json(index: int, record: WorkspaceRecord, start_ns: int) -> dict[str, Any]:
    summary = record.summary
    position = summary["position"]
    return {
        "index": index,
        "time_s": (record.log_time_ns - start_ns) / 1e9,
        "sources": record.sources,
        "request_id": summary["request_id"],
        "kind": _kind_label(int(summary["kind"])),
        "success": bool(summary["success"]),
        "message": summary["message"],
        "position": [position["x"], position["y"], position["z"]],
        "reference_reachable": bool(summary["reference_reachable"]),
        "n_rays": int(summary["n_rays"]),
        "tolerance_deg": _deg(summary["tolerance"]),
        "tilt_min_deg": _deg(summary["tilt_min"]),
        "tilt_max_deg": _deg(summary["tilt_max"]),
        "solid_angle_sr": _finite(summary["solid_angle"]),
        "psi_min_deg": _deg(summary["psi_min"]),
        "psi_max_deg": _deg(summary["psi_max"]),
        "volume": _finite(summary["volume"]),
        "n_points": int(summary["n_points"]),
        "boundary_recorded": record.points is not None,
        "elapsed_s": float(summary["elapsed"]),
    }


def _check_json(index: int, call: PoseCheckCall, start_ns: int) -> dict[str, Any]:
    response = call.response or {}
    return {
        "index": index,
        "time_s": (call.log_time_ns - start_ns) / 1e9,
        "topic": call.topic,
        "position": call.position,
        "pose_form": call.angles is None and call.n_poses is not None,
        "n_poses": call.n_poses,
        "answered": call.response is not None,
        "success": response.get("success"),
        "message": response.get("message"),
        "n_reachable": call.n_reachable,
    }


def _atlas_json(index: int, record: AtlasRecord, start_ns: int) -> dict[str, Any]:
    """An atlas cloud in a few numbers: grid extent, reachable positions, tilt capability."""
    columns = record.columns
    count = len(columns["x"]) if "x" in columns else 0
    reachable = columns.get("reference_reachable", np.zeros(count)) > 0.5
    capability = columns.get("tilt_capability", np.full(count, np.nan))[reachable]
    capability = capability[np.isfinite(capability)]

    def extent(axis: str) -> list[float] | None:
        values = columns.get(axis)
        return None if values is None or not count else [float(values.min()), float(values.max())]

    return {
        "index": index,
        "time_s": (record.log_time_ns - start_ns) / 1e9,
        "topic": record.topic,
        "n_positions": count,
        "n_reference_reachable": int(reachable.sum()),
        "extent_m": {axis: extent(axis) for axis in "xyz"},
        "tilt_capability_max_deg": _deg(float(capability.max())) if capability.size else None,
        "tilt_capability_median_deg": (
            _deg(float(np.median(capability))) if capability.size else None
        ),
    }


def log_report(summary: LogSummary) -> dict[str, Any]:
    from ..logs.paths import loads_call_report, path_call_report, schedule_call_report

    contents = summary.contents
    start = contents.start_ns or 0
    reach = summary.reachability
    return {
        "log": str(contents.path),
        "files": [str(f) for f in contents.files],
        "finished": contents.finished,
        "damaged": contents.damaged,
        "start": _iso(contents.start_ns),
        "end": _iso(contents.end_ns),
        "duration_s": ((contents.end_ns or 0) - start) / 1e9,
        "message_count": contents.message_count,
        "topics": [
            {"topic": t.topic, "type": t.msgtype, "count": t.count, "decoded": t.decoded}
            for t in contents.topics.values()
        ],
        "workspaces": [_workspace_json(i + 1, r, start) for i, r in enumerate(summary.workspaces)],
        "pose_checks": [_check_json(i + 1, c, start) for i, c in enumerate(summary.checks)],
        "atlases": [_atlas_json(i + 1, a, start) for i, a in enumerate(summary.atlases)],
        "reachability": {
            "count": len(reach),
            "reachable": sum(bool(r["success"] and r["check"]["reachable"]) for r in reach),
            "unreachable": sum(bool(r["success"] and not r["check"]["reachable"]) for r in reach),
            "invalid": sum(not r["success"] for r in reach),
        },
        "path_checks": [
            path_call_report(i + 1, call, start) for i, call in enumerate(summary.paths)
        ],
        "schedules": [
            schedule_call_report(i + 1, call, start) for i, call in enumerate(summary.schedules)
        ],
        "loads": [loads_call_report(i + 1, call, start) for i, call in enumerate(summary.loads)],
        "trigger_calls": [
            {
                "topic": t["topic"],
                "time_s": (t["log_time_ns"] - start) / 1e9,
                "success": bool(t["success"]),
                "message": t["message"],
            }
            for t in summary.triggers
        ],
        "parameter_changes": [
            {
                "time_s": (c["log_time_ns"] - start) / 1e9,
                "accepted": bool(c["accepted"]),
                "parameters": dict(zip(c["names"], c["values"], strict=False)),
                "reason": c["reason"],
            }
            for c in summary.parameter_changes
        ],
        "axis_limits": [_axis_limits_json(a, start) for a in summary.axis_limits],
        "problems": list(contents.problems),
    }


def _axis_limits_json(fields: dict[str, Any], start: int) -> dict[str, Any]:
    """One recorded AxisLimits: the frame, the pose's position (m, base frame) and per axis
    ``[minus, plus]`` (m or rad), or the reason it failed."""
    position = fields["pose"]["position"]
    return {
        "time_s": (fields["log_time_ns"] - start) / 1e9,
        "success": bool(fields["success"]),
        "message": fields["message"],
        "frame": fields["frame"],
        "position": [position["x"], position["y"], position["z"]],
        "axes": {
            name: [float(minus), float(plus)]
            for name, minus, plus in zip(
                fields["axes"], fields["minus"], fields["plus"], strict=True
            )
        },
    }


def jsonable(value: Any) -> Any:
    """NaN and infinities (a rejected request's position, a disabled margin) become null."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: jsonable(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [jsonable(item) for item in value]
    return value


def log_report_text(report: dict[str, Any], out: IO[str]) -> None:
    from ..logs.paths import loads_call_line, path_call_line, schedule_call_line

    if report["damaged"]:
        state = (
            "finished, but damaged: read as far as intact"
            if report["finished"]
            else "not finished cleanly: read as far as intact"
        )
    else:
        state = "finished" if report["finished"] else "not finished"
    out.write(f"log: {report['log']} ({state})\n")
    out.write(
        f"span: {report['start']} .. {report['end']} ({report['duration_s']:.3f} s), "
        f"{report['message_count']} messages\n"
    )
    out.write("topics:\n")
    width = max([len(t["topic"]) for t in report["topics"]] + [5])
    type_width = max([len(t["type"]) for t in report["topics"]] + [4])
    for topic in report["topics"]:
        out.write(f"  {topic['topic']:<{width}}  {topic['type']:<{type_width}}  {topic['count']}\n")
    out.write(f"workspace results: {len(report['workspaces'])}\n")
    lines = []
    for ws in report["workspaces"]:
        position = ", ".join(f"{v:.4g}" for v in ws["position"])
        request = f" request_id={ws['request_id']!r}" if ws["request_id"] else ""
        lines.append(
            f"[{ws['index']}] +{ws['time_s']:.3f} s{request} at ({position}) m: {_line(ws)}"
        )
    _capped(lines, "workspace results", out)
    if report["atlases"]:
        out.write(f"atlas results: {len(report['atlases'])}\n")
        _capped([_atlas_line(atlas) for atlas in report["atlases"]], "atlas results", out)
    if report["pose_checks"]:
        checks = report["pose_checks"]
        answered = [c for c in checks if c["answered"] and c["success"]]
        poses = sum(c["n_poses"] or 0 for c in answered)
        reachable = sum(c["n_reachable"] for c in answered)
        failed = sum(1 for c in checks if c["answered"] and not c["success"])
        out.write(
            f"pose checks: {len(checks)} ({poses} poses answered, {reachable} reachable; "
            f"{failed} calls failed)\n"
        )
        lines = []
        for check in checks:
            if not check["answered"]:
                verdict = "no response recorded"
            elif check["success"]:
                verdict = f"{check['n_reachable']}/{check['n_poses'] or 0} reachable"
                verdict += " (Pose form)" if check["pose_form"] else ""
            else:
                verdict = f"failed: {check['message']}"
            lines.append(f"[{check['index']}] +{check['time_s']:.3f} s {check['topic']}: {verdict}")
        _capped(lines, "pose checks", out)
    reach = report["reachability"]
    if reach["count"]:
        out.write(
            f"reachability results: {reach['count']} ({reach['reachable']} reachable, "
            f"{reach['unreachable']} unreachable, {reach['invalid']} invalid)\n"
        )
    if report["path_checks"]:
        out.write(f"path checks: {len(report['path_checks'])}\n")
        _capped([path_call_line(call) for call in report["path_checks"]], "path checks", out)
    if report["schedules"]:
        out.write(f"schedules: {len(report['schedules'])}\n")
        _capped([schedule_call_line(call) for call in report["schedules"]], "schedules", out)
    if report["loads"]:
        out.write(f"loads: {len(report['loads'])}\n")
        _capped([loads_call_line(call) for call in report["loads"]], "loads", out)
    if report["trigger_calls"]:
        out.write(f"trigger calls: {len(report['trigger_calls'])}\n")
        lines = [
            f"trigger {call['topic']} +{call['time_s']:.3f} s: "
            f"{'ok' if call['success'] else 'failed'}: {call['message']}"
            for call in report["trigger_calls"]
        ]
        _capped(lines, "trigger calls", out)
    changes = report.get("parameter_changes", [])
    if changes:
        refused = sum(not c["accepted"] for c in changes)
        out.write(f"parameter changes: {len(changes)} ({refused} refused)\n")
        lines = [
            f"+{c['time_s']:.3f} s "
            + ", ".join(f"{name} = {value}" for name, value in c["parameters"].items())
            + (": applied" if c["accepted"] else f": refused: {c['reason']}")
            for c in changes
        ]
        _capped(lines, "parameter changes", out)
    limits = report.get("axis_limits", [])
    if limits:
        last = limits[-1]
        out.write(f"axis limits: {len(limits)} published; the last at +{last['time_s']:.3f} s")
        if last["success"]:
            axes = ", ".join(
                f"{name} -{minus:.4g}..+{plus:.4g}" for name, (minus, plus) in last["axes"].items()
            )
            out.write(f" ({last['frame']} frame; m, rad): {axes}\n")
        else:
            out.write(f": failed: {last['message']}\n")


#: Text replay lists at most this many entries per kind (the first and the last ones).
LIST_CAP = 20


def _capped(lines: list[str], what: str, out: IO[str]) -> None:
    """Write ``lines`` indented, at most :data:`LIST_CAP`: the first and the last halves, with
    how many were left out in between (``--json`` lists every one)."""
    if len(lines) > LIST_CAP:
        half = LIST_CAP // 2
        left_out = len(lines) - 2 * half
        lines = [
            *lines[:half],
            f"... {left_out} more {what} (replay --json lists every one)",
            *lines[-half:],
        ]
    for line in lines:
        out.write(f"  {line}\n")


def _atlas_line(atlas: dict[str, Any]) -> str:
    extent = " ".join(
        f"{axis} {span[0]:.4g}..{span[1]:.4g}"
        for axis, span in atlas["extent_m"].items()
        if span is not None
    )
    capability = (
        "tilt capability: none reachable"
        if atlas["tilt_capability_max_deg"] is None
        else f"tilt capability up to {atlas['tilt_capability_max_deg']:.2f} deg (median "
        f"{atlas['tilt_capability_median_deg']:.2f} deg)"
    )
    return (
        f"[{atlas['index']}] +{atlas['time_s']:.3f} s {atlas['topic']}: {atlas['n_positions']} "
        f"positions ({extent} m), reference reachable at {atlas['n_reference_reachable']}; "
        f"{capability}"
    )


def _line(ws: dict[str, Any]) -> str:
    if not ws["success"]:
        return f"{ws['kind']}: failed: {ws['message']}"
    if ws["kind"] == "orientation":
        text = (
            f"orientation: psi {ws['psi_min_deg']:.3f}..{ws['psi_max_deg']:.3f} deg, "
            f"volume {ws['volume']:.6g} rad^3"
        )
    else:
        text = (
            f"{ws['kind']}: tilt {ws['tilt_min_deg']:.3f}..{ws['tilt_max_deg']:.3f} deg, "
            f"solid angle {ws['solid_angle_sr']:.6g} sr"
        )
    boundary = "" if ws["boundary_recorded"] else " (not recorded)"
    return f"{text}, {ws['n_points']} boundary points{boundary}"


# ---------------------------------------------------------------------------- demo
