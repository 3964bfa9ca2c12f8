"""Replay recorded MCAP logs: list what they hold, redraw the workspaces, republish on ROS.

:func:`run_replay` is what ``hexapod-workspace replay LOG`` calls; :func:`record_results` is
what ``check``/``projected``/``orientation --record FILE`` call. Neither needs ROS; only
``--publish`` imports rclpy, lazily.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from hexapod_workspace.errors import LogReadError
from hexapod_workspace.logs import messages
from hexapod_workspace.logs.paths import path_call_fields, path_call_line, path_call_report
from hexapod_workspace.logs.recording import (
    RESULT_QOS,
    SERVICE_QOS,
    LogContents,
    LogMessage,
    LogWriter,
    iter_log,
    message_to_fields,
    service_topics,
)

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

__all__ = [
    "LogSummary",
    "PoseCheckCall",
    "WorkspaceRecord",
    "record_results",
    "run_replay",
    "summarize_log",
]

_SUMMARY = "hexapod_workspace_msgs/msg/WorkspaceSummary"
_CLOUD = "sensor_msgs/msg/PointCloud2"
_REACHABILITY = "hexapod_workspace_msgs/msg/ReachabilityResult"
_WORKSPACE_RESPONSE = "hexapod_workspace_msgs/srv/ComputeWorkspace_Response"
_CHECK_REQUEST = "hexapod_workspace_msgs/srv/CheckPoses_Request"
_CHECK_RESPONSE = "hexapod_workspace_msgs/srv/CheckPoses_Response"
_TRIGGER_RESPONSE = "std_srvs/srv/Trigger_Response"
_PATH_REQUEST = "hexapod_workspace_msgs/srv/CheckPath_Request"
_PATH_RESPONSE = "hexapod_workspace_msgs/srv/CheckPath_Response"
_DISCOVERY = "ROS_AUTOMATIC_DISCOVERY_RANGE"


# --------------------------------------------------------------------------- what a log holds


@dataclass
class WorkspaceRecord:
    """One recorded workspace result: its summary fields and, when recorded, its boundary.

    Attributes
    ----------
    log_time_ns : int
        When the summary was recorded.
    sources : list of str
        Topics it was found on (a topic summary and a service response of the same computation
        are one record).
    summary : dict
        WorkspaceSummary fields (SI units).
    points : ndarray, shape (M, 6) or None
        Boundary points x, y, z, φ, θ, ψ.
    """

    log_time_ns: int
    sources: list[str]
    summary: dict[str, Any]
    points: np.ndarray | None = None

    @property
    def key(self) -> tuple[Any, ...]:
        """Identity of a computation: header stamp, request id, kind."""
        header = self.summary["header"]
        return (
            messages.stamp_to_ns(header["stamp"]),
            self.summary["request_id"],
            int(self.summary["kind"]),
        )


@dataclass
class PoseCheckCall:
    """One recorded CheckPoses call (request and its response, paired in order)."""

    log_time_ns: int
    topic: str
    position: list[float] | None = None
    angles: np.ndarray | None = None
    response: dict[str, Any] | None = None


@dataclass
class LogSummary:
    """Everything :func:`run_replay` reports about a log."""

    contents: LogContents
    workspaces: list[WorkspaceRecord] = field(default_factory=list)
    checks: list[PoseCheckCall] = field(default_factory=list)
    reachability: list[dict[str, Any]] = field(default_factory=list)
    triggers: list[dict[str, Any]] = field(default_factory=list)
    paths: list[dict[str, Any]] = field(default_factory=list)
    decoded: int = 0


def summarize_log(
    log: str | Path, *, keep_messages: bool = False
) -> tuple[LogSummary, list[LogMessage]]:
    """Read a log and gather its workspace results, pose checks and reachability results.

    Parameters
    ----------
    log : str or Path
        Bare ``.mcap`` file or rosbag2 bag directory.
    keep_messages : bool
        Also return every message read (for republishing).

    Raises
    ------
    LogReadError
        The log cannot be opened at all.
    """
    contents = LogContents(Path(log))
    summary = LogSummary(contents)
    kept: list[LogMessage] = []
    by_key: dict[tuple[Any, ...], WorkspaceRecord] = {}
    clouds: dict[int, np.ndarray] = {}  # boundary clouds whose summary is still to come
    awaiting: dict[int, WorkspaceRecord] = {}  # summaries whose boundary is still to come
    pending_requests: dict[str, list[PoseCheckCall]] = {}
    for item in iter_log(log, contents):
        if keep_messages:
            kept.append(item)
        if item.message is None:
            continue
        summary.decoded += 1
        msgtype = item.msgtype
        if msgtype in (_SUMMARY, _WORKSPACE_RESPONSE):
            fields = message_to_fields(item.message)
            points = None
            if msgtype == _WORKSPACE_RESPONSE:
                points = _cloud_points(fields["boundary"], contents, item.topic)
                fields = fields["summary"]
            record = WorkspaceRecord(item.log_time_ns, [item.topic], fields, points)
            known = by_key.get(record.key)
            if known is None:
                by_key[record.key] = record
                summary.workspaces.append(record)
                known = record
            elif item.topic not in known.sources:
                known.sources.append(item.topic)
            if known.points is None:
                known.points = points if points is not None else clouds.pop(record.key[0], None)
            if known.points is None:
                awaiting[record.key[0]] = known
        elif msgtype == _CLOUD:
            fields = message_to_fields(item.message)
            points = _cloud_points(fields, contents, item.topic)
            stamp = messages.stamp_to_ns(fields["header"]["stamp"])
            waiting = awaiting.pop(stamp, None)
            if waiting is not None:
                waiting.points = points
            elif points is not None:
                clouds[stamp] = points
        elif msgtype == _CHECK_REQUEST:
            fields = message_to_fields(item.message)
            position = fields["position"]
            call = PoseCheckCall(
                item.log_time_ns,
                item.topic,
                [position["x"], position["y"], position["z"]],
                np.array(
                    [[o["phi"], o["theta"], o["psi"]] for o in fields["orientations"]], dtype=float
                ).reshape(-1, 3),
            )
            summary.checks.append(call)
            pending_requests.setdefault(_service_of(item.topic), []).append(call)
        elif msgtype == _CHECK_RESPONSE:
            queue = pending_requests.get(_service_of(item.topic), [])
            call = queue.pop(0) if queue else None
            if call is None:  # response without its request (log cut before it)
                call = PoseCheckCall(item.log_time_ns, item.topic)
                summary.checks.append(call)
            call.response = message_to_fields(item.message)
        elif msgtype == _REACHABILITY:
            fields = message_to_fields(item.message)
            fields["log_time_ns"] = item.log_time_ns
            summary.reachability.append(fields)
        elif msgtype in (_PATH_REQUEST, _PATH_RESPONSE):
            path_call_fields(summary.paths, item.topic, item.log_time_ns, item.message)
        elif msgtype == _TRIGGER_RESPONSE:
            fields = message_to_fields(item.message)
            fields.update(topic=item.topic, log_time_ns=item.log_time_ns)
            summary.triggers.append(fields)
    return summary, kept


def _service_of(topic: str) -> str:
    return topic.rsplit("/", 1)[0]


def _cloud_points(fields: dict[str, Any], contents: LogContents, topic: str) -> np.ndarray | None:
    try:
        return messages.pointcloud_to_array(fields)
    except ValueError as err:
        contents.problems.append(f"{topic}: a PointCloud2 could not be read ({err})")
        return None


# --------------------------------------------------------------------------- reporting


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
        "kind": messages.KIND_NAMES.get(int(summary["kind"]), str(summary["kind"])),
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
        "path_checks": [
            path_call_report(i + 1, call, start) for i, call in enumerate(summary.paths)
        ],
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
    if report["path_checks"]:
        out.write(f"path checks: {len(report['path_checks'])}\n")
        for call in report["path_checks"]:
            out.write(f"  {path_call_line(call)}\n")
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
    if kind == messages.ORIENTATION:
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
        method=messages.KIND_NAMES[kind],
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
        if int(record.summary["kind"]) == messages.ORIENTATION:
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


# --------------------------------------------------------------------------- republish


def _message_class(msgtype: str) -> Any:
    """The rclpy message class of ``pkg/msg/Type`` or ``pkg/srv/Name_Request``."""
    import importlib

    package, kind, name = msgtype.split("/")
    module = importlib.import_module(f"{package}.{kind}")
    if kind == "srv":
        service, _, part = name.rpartition("_")
        return getattr(getattr(module, service), part)
    return getattr(module, name)


def _qos(text: str) -> Any:
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    transient = "transient_local" in text
    return QoSProfile(
        depth=1 if transient else 10,
        reliability=ReliabilityPolicy.BEST_EFFORT
        if "best_effort" in text
        else ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if transient else DurabilityPolicy.VOLATILE,
    )


def _publish(
    summary: LogSummary,
    kept: Sequence[LogMessage],
    rate: float,
    err: IO[str],
    *,
    allow_network: bool,
    wait_for_subscribers: float,
) -> int:
    """Republish the recorded bytes on their topics at ``rate`` × the recorded pace."""
    value = os.environ.get(_DISCOVERY)
    if value is None:
        os.environ[_DISCOVERY] = "LOCALHOST"
    elif value != "LOCALHOST" and not allow_network:
        err.write(
            f"replay --publish: refusing to publish with {_DISCOVERY}={value}; "
            "set it to LOCALHOST (or unset it)\n"
        )
        return 2
    try:
        import rclpy
        from rclpy.duration import Duration
        from rclpy.node import Node
    except ImportError as error:
        err.write(f"replay --publish needs rclpy (a ROS 2 environment): {error}\n")
        return 2
    usable = [m for m in kept if m.message is not None]
    classes: dict[str, Any] = {}
    for info in summary.contents.topics.values():
        try:
            classes[info.topic] = _message_class(info.msgtype)
        except (ImportError, AttributeError, ValueError):
            err.write(
                f"note: {info.topic}: type {info.msgtype} not available in this ROS "
                "environment; not republished\n"
            )
    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        node = Node("hexapod_workspace_replay", context=context)
        publishers = {
            topic: node.create_publisher(cls, topic, _qos(summary.contents.topics[topic].qos))
            for topic, cls in classes.items()
        }
        deadline = time.monotonic() + wait_for_subscribers
        while any(p.get_subscription_count() == 0 for p in publishers.values()):
            if time.monotonic() >= deadline:
                break
            time.sleep(0.01)
        start_wall = time.monotonic()
        start_log = usable[0].log_time_ns if usable else 0
        for item in usable:
            publisher = publishers.get(item.topic)
            if publisher is None:
                continue
            if rate > 0:
                due = start_wall + (item.log_time_ns - start_log) / 1e9 / rate
                delay = due - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
            publisher.publish(item.data)  # serialized bytes go out unchanged
        for publisher in publishers.values():  # let reliable subscribers receive everything
            publisher.wait_for_all_acked(Duration(seconds=5))
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    err.write(f"republished {len(usable)} messages on {len(classes)} topics\n")
    return 0


# --------------------------------------------------------------------------- entry points


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
        return _publish(
            summary,
            kept,
            rate,
            err,
            allow_network=allow_network,
            wait_for_subscribers=wait_for_subscribers,
        )
    return 0


def record_results(
    path: str | Path,
    results: Iterable[Any],
    *,
    frame_id: str = "base",
    request_id: str = "",
    stamp_ns: int | None = None,
) -> Path:
    """Record CLI results in the node's log format (what ``--record FILE`` writes).

    Each ``CheckResult`` is recorded as a CheckPoses call (request and response on
    ``/hexapod_workspace/check_poses/{request,response}``); each projected or orientation
    workspace as the WorkspaceRequest that asks for it, then its WorkspaceSummary and its
    boundary PointCloud2 (same header stamp) on the node's topics.

    Parameters
    ----------
    path : str or Path
        The ``.mcap`` file to write (replaced if it exists).
    results : iterable
        ``CheckResult``, ``ProjectedWorkspace`` and/or ``OrientationWorkspace`` objects.
    frame_id : str
        The manipulator's base frame.
    request_id : str
        Copied into requests and summaries.
    stamp_ns : int, optional
        Time of the first record (ns since the epoch); default now. Later records follow 1 µs
        apart so that every message keeps its order.

    Returns
    -------
    Path
        The finished log.

    Raises
    ------
    RecordingError
        The file cannot be written.
    """
    topics, types = messages.TOPICS, messages.TYPES
    stamp = time.time_ns() if stamp_ns is None else int(stamp_ns)
    # One chunk per message: a damaged file keeps every message before the damage.
    with LogWriter(path, flush_interval=0, flush_messages=1) as writer:
        for result in results:
            if hasattr(result, "margins"):  # a CheckResult
                request, response = service_topics(topics["check_poses"])
                writer.write_fields(
                    request,
                    f"{types['check_poses']}_Request",
                    messages.check_poses_request_fields(result.position, result.angles),
                    stamp,
                    qos=SERVICE_QOS,
                )
                writer.write_fields(
                    response,
                    f"{types['check_poses']}_Response",
                    messages.check_poses_response_fields(result),
                    stamp + 1_000,
                    qos=SERVICE_QOS,
                )
            else:
                kind = messages.workspace_kind(result)
                request_fields = messages.compute_workspace_request_fields(
                    result, request_id=request_id, stamp_ns=stamp, frame_id=frame_id
                )["request"]
                writer.write_fields(
                    topics["workspace_request"], types["workspace_request"], request_fields, stamp
                )
                points = messages.boundary_points(result)
                summary = messages.summary_fields(
                    result,
                    stamp_ns=stamp + 1_000,
                    frame_id=frame_id,
                    request_id=request_id,
                    kind=kind,
                    n_points=len(points),
                )
                writer.write_fields(
                    topics["workspace_summary"],
                    types["workspace_summary"],
                    summary,
                    stamp + 1_000,
                    qos=RESULT_QOS,
                )
                cloud = (
                    "orientation_workspace"
                    if kind == messages.ORIENTATION
                    else "projected_workspace"
                )
                writer.write_fields(
                    topics[cloud],
                    types[cloud],
                    messages.pointcloud_fields(points, frame_id=frame_id, stamp_ns=stamp + 1_000),
                    stamp + 1_000,
                    qos=RESULT_QOS,
                )
            stamp += 2_000
    return Path(path)
