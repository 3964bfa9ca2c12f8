"""``hexapod-workspace replay LOG``: list what a log holds, redraw its workspaces, republish it.

The log is read by :mod:`hexapod_workspace.logs.summary`; ``--publish`` hands it to
:mod:`hexapod_workspace.ros.republish` (rclpy, imported only then).
"""

from __future__ import annotations

import dataclasses
import json
import math
import sys
import time
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from hexapod_workspace.core.resolution import WorkspaceKind
from hexapod_workspace.errors import LogReadError

if TYPE_CHECKING:
    pass
from hexapod_workspace.logs.summary import LogSummary, PoseCheckCall, WorkspaceRecord, summarize_log

# --------------------------------------------------------------------------- reporting


def _kind_label(kind: int) -> str:
    known = WorkspaceKind.of(kind)
    return known.label if known is not None else str(kind)


def _iso(ns: int | None) -> str:
    if ns is None:
        return "-"
    seconds, rest = divmod(ns, 1_000_000_000)
    return time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(seconds)) + f".{rest // 1_000_000:03d}Z"


def _deg(value: float) -> float | None:
    return None if not math.isfinite(value) else math.degrees(value)


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
    results = response.get("results", [])
    return {
        "index": index,
        "time_s": (call.log_time_ns - start_ns) / 1e9,
        "topic": call.topic,
        "position": call.position,
        "n_poses": None if call.angles is None else len(call.angles),
        "answered": call.response is not None,
        "success": response.get("success"),
        "message": response.get("message"),
        "n_reachable": sum(bool(r["reachable"]) for r in results),
    }


def _report(summary: LogSummary) -> dict[str, Any]:
    contents = summary.contents
    start = contents.start_ns or 0
    reach = summary.reachability
    return {
        "log": str(contents.path),
        "files": [str(f) for f in contents.files],
        "finished": contents.finished,
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
        "reachability": {
            "count": len(reach),
            "reachable": sum(bool(r["success"] and r["check"]["reachable"]) for r in reach),
            "unreachable": sum(bool(r["success"] and not r["check"]["reachable"]) for r in reach),
            "invalid": sum(not r["success"] for r in reach),
        },
        "trigger_calls": [
            {
                "topic": t["topic"],
                "time_s": (t["log_time_ns"] - start) / 1e9,
                "success": bool(t["success"]),
                "message": t["message"],
            }
            for t in summary.triggers
        ],
        "problems": list(contents.problems),
    }


def _jsonable(value: Any) -> Any:
    """NaN and infinities (a rejected request's position, a disabled margin) become null."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: _jsonable(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(item) for item in value]
    return value


def _print_text(report: dict[str, Any], out: IO[str]) -> None:
    state = "finished" if report["finished"] else "not finished cleanly (read as far as intact)"
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
    for ws in report["workspaces"]:
        position = ", ".join(f"{v:.4g}" for v in ws["position"])
        request = f" request_id={ws['request_id']!r}" if ws["request_id"] else ""
        out.write(
            f"  [{ws['index']}] +{ws['time_s']:.3f} s{request} at ({position}) m: {_line(ws)}\n"
        )
    if report["pose_checks"]:
        out.write(f"pose checks: {len(report['pose_checks'])}\n")
        for check in report["pose_checks"]:
            if not check["answered"]:
                verdict = "no response recorded"
            elif check["success"]:
                verdict = f"{check['n_reachable']}/{check['n_poses'] or 0} reachable"
            else:
                verdict = f"failed: {check['message']}"
            out.write(
                f"  [{check['index']}] +{check['time_s']:.3f} s {check['topic']}: {verdict}\n"
            )
    reach = report["reachability"]
    if reach["count"]:
        out.write(
            f"reachability results: {reach['count']} ({reach['reachable']} reachable, "
            f"{reach['unreachable']} unreachable, {reach['invalid']} invalid)\n"
        )
    for call in report["trigger_calls"]:
        out.write(
            f"  trigger {call['topic']} +{call['time_s']:.3f} s: "
            f"{'ok' if call['success'] else 'failed'}: {call['message']}\n"
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


# --------------------------------------------------------------------------- plots


def _rebuild(record: WorkspaceRecord) -> Any:
    """Rebuild the core result dataclass from a recorded summary and boundary cloud."""
    summary, points = record.summary, record.points
    position = np.array([summary["position"][k] for k in "xyz"])
    kind = int(summary["kind"])
    if kind == WorkspaceKind.ORIENTATION:
        from hexapod_workspace.core.orientation import (
            OrientationSlice,
            OrientationWorkspace,
        )

        psi = points[:, 5].astype(np.float32)
        levels = np.unique(psi)
        slices = []
        for level in levels:
            rows = points[psi == level]
            # The ray origin is not recorded; the centroid of the slice's boundary stands in.
            slices.append(
                _make(
                    OrientationSlice,
                    psi=float(rows[0, 5]),
                    center=rows[:, :2].mean(axis=0),
                    phi=rows[:, 3],
                    theta=rows[:, 4],
                )
            )
        step = float(np.median(np.diff(levels))) if levels.size > 1 else 0.0
        return _make(
            OrientationWorkspace,
            position=position,
            slices=slices,
            psi_min=summary["psi_min"],
            psi_max=summary["psi_max"],
            volume=summary["volume"],
            n_rays=int(summary["n_rays"]),
            psi_step=step,
            tolerance=summary["tolerance"],
            elapsed=summary["elapsed"],
        )
    from hexapod_workspace.core.projected import ProjectedWorkspace

    return _make(
        ProjectedWorkspace,
        method=WorkspaceKind(kind).label,
        position=position,
        phi=points[:, 3],
        theta=points[:, 4],
        psi=points[:, 5],
        tilt_min=summary["tilt_min"],
        tilt_max=summary["tilt_max"],
        solid_angle=summary["solid_angle"],
        tolerance=summary["tolerance"],
        elapsed=summary["elapsed"],
        limiting=[""] * len(points),
    )


def _make(cls: type, **values: Any) -> Any:
    """Build a result dataclass from the values a log can give; other fields keep defaults."""
    names = {f.name for f in dataclasses.fields(cls)}
    return cls(**{k: v for k, v in values.items() if k in names})


def _plot(summary: LogSummary, plot_dir: Path, out: IO[str], err: IO[str]) -> list[Path]:
    """Redraw the recorded workspaces; one that cannot be redrawn is a note, not a failure."""
    from hexapod_workspace.cli import plotting

    plot_dir.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    projected: dict[tuple[float, ...], list[tuple[int, Any]]] = {}

    def draw(index: int, function: Any, workspace: Any, path: Path) -> None:
        try:
            written.append(Path(function(workspace, path)))
        except (ValueError, IndexError, TypeError, ArithmeticError) as error:
            err.write(f"note: workspace {index} could not be redrawn ({error})\n")

    for index, record in enumerate(summary.workspaces, start=1):
        if not record.summary["success"] or record.points is None or not len(record.points):
            continue
        try:
            workspace = _rebuild(record)
        except (ValueError, IndexError, TypeError, KeyError) as error:
            err.write(f"note: workspace {index} could not be rebuilt from the log ({error})\n")
            continue
        if int(record.summary["kind"]) == WorkspaceKind.ORIENTATION:
            path = plot_dir / f"workspace_{index:03d}_orientation.png"
            draw(index, plotting.plot_orientation, workspace, path)
        else:  # methods computed at one position are overlaid, like the live command
            key = tuple(np.round(workspace.position, 9))
            projected.setdefault(key, []).append((index, workspace))
    for group in projected.values():
        path = plot_dir / f"workspace_{group[0][0]:03d}_projected.png"
        draw(group[0][0], plotting.plot_projected, [ws for _, ws in group], path)
    for path in written:
        out.write(f"plot: {path}\n")
    return written


def run_replay(
    log: str | Path,
    *,
    as_json: bool = False,
    plot_dir: str | Path | None = None,
    publish: bool = False,
    rate: float = 1.0,
    stdout: IO[str] | None = None,
    stderr: IO[str] | None = None,
    allow_network: bool = False,
    wait_for_subscribers: float = 0.0,
) -> int:
    """Report what a log holds; optionally redraw its workspaces and republish it.

    Parameters
    ----------
    log : str or Path
        Bare ``.mcap`` file or rosbag2 bag directory (``metadata.yaml`` + ``.mcap``).
    as_json : bool
        One JSON document on stdout instead of text.
    plot_dir : str or Path, optional
        Redraw every recorded workspace with the live commands' plots into this folder.
    publish : bool
        Republish the recorded messages on their topics (needs rclpy). Sets
        ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` when unset and refuses other values unless
        ``allow_network``.
    rate : float
        Playback speed factor for ``publish`` (1 = recorded pace, 2 = twice as fast,
        0 = as fast as possible).
    stdout, stderr : text streams, optional
        Default ``sys.stdout``/``sys.stderr``.
    allow_network : bool
        Let ``publish`` run with a discovery range other than LOCALHOST.
    wait_for_subscribers : float
        ``publish``: wait up to this many seconds for every topic to have a subscriber.

    Returns
    -------
    int
        0 when something usable was read (notes about damage go to stderr), 2 when the log
        cannot be read or nothing in it could be decoded (one line on stderr).
    """
    out = stdout if stdout is not None else sys.stdout
    err = stderr if stderr is not None else sys.stderr
    if not (rate >= 0 and math.isfinite(rate)):
        err.write(f"replay: --rate must be a finite number >= 0, got {rate}\n")
        return 2
    try:
        summary, kept = summarize_log(log, keep_messages=publish)
    except LogReadError as error:
        err.write(f"replay: {error}\n")
        return 2
    except OSError as error:
        err.write(f"replay: {log}: {error.strerror or error}\n")
        return 2
    contents = summary.contents
    for problem in contents.problems:
        err.write(f"note: {problem}\n")
    if summary.decoded == 0 and (contents.problems or not contents.finished):
        err.write(f"replay: nothing usable in {log}\n")
        return 2
    report = _report(summary)
    if as_json:
        json.dump(_jsonable(report), out, indent=1, allow_nan=False)
        out.write("\n")
    else:
        _print_text(report, out)
    if plot_dir is not None:
        try:
            _plot(summary, Path(plot_dir), err if as_json else out, err)
        except OSError as error:
            err.write(f"replay: cannot write plots to {plot_dir}: {error.strerror or error}\n")
            return 2
    if publish:
        try:
            from hexapod_workspace.ros.republish import publish_log
        except ImportError as error:
            err.write(f"replay --publish needs rclpy (a ROS 2 environment): {error}\n")
            return 2
        return publish_log(
            summary,
            kept,
            rate,
            err,
            allow_network=allow_network,
            wait_for_subscribers=wait_for_subscribers,
        )
    return 0
