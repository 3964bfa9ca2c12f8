"""What a recorded log holds: the workspaces (summary, boundary cloud, request) and pose checks.

:func:`summarize_log` pairs the messages of a node or CLI log into :class:`WorkspaceRecord` and
:class:`PoseCheckCall` objects; the CLI's ``replay`` reports and redraws them, the ROS layer can
republish them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from hexapod_workspace.logs import (
    LogContents,
    LogMessage,
    iter_log,
    message_to_fields,
    messages,
    service_part,
)
from hexapod_workspace.logs.paths import path_call_fields

if TYPE_CHECKING:
    pass

_SUMMARY = "hexapod_workspace_msgs/msg/WorkspaceSummary"
_CLOUD = "sensor_msgs/msg/PointCloud2"
_REACHABILITY = "hexapod_workspace_msgs/msg/ReachabilityResult"
_WORKSPACE_RESPONSE = "hexapod_workspace_msgs/srv/ComputeWorkspace_Response"
_CHECK_REQUEST = "hexapod_workspace_msgs/srv/CheckPoses_Request"
_CHECK_RESPONSE = "hexapod_workspace_msgs/srv/CheckPoses_Response"
_FLAT_REQUEST = "hexapod_workspace_msgs/srv/CheckPosesFlat_Request"
_FLAT_RESPONSE = "hexapod_workspace_msgs/srv/CheckPosesFlat_Response"
_TRIGGER_RESPONSE = "std_srvs/srv/Trigger_Response"
_PATH_REQUEST = "hexapod_workspace_msgs/srv/CheckPath_Request"
_PATH_RESPONSE = "hexapod_workspace_msgs/srv/CheckPath_Response"


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
    """One recorded CheckPoses or CheckPosesFlat call (request and its response, paired in
    order); ``response`` holds the fields of either form."""

    log_time_ns: int
    topic: str
    position: list[float] | None = None
    angles: np.ndarray | None = None
    response: dict[str, Any] | None = None

    @property
    def n_reachable(self) -> int:
        """Poses answered reachable (nested ``results`` or flat ``reachable``)."""
        response = self.response or {}
        if "results" in response:
            return sum(bool(r["reachable"]) for r in response["results"])
        return int(np.count_nonzero(np.asarray(response.get("reachable", []), dtype=bool)))


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
        msgtype = service_part(item.msgtype)  # a recorded service part, or a log of old form
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
        elif msgtype in (_CHECK_REQUEST, _FLAT_REQUEST):
            fields = message_to_fields(item.message)
            position = fields["position"]
            if msgtype == _FLAT_REQUEST:
                angles = np.asarray(fields["angles"], dtype=float).reshape(-1, 3)
            else:
                angles = np.array(
                    [[o["phi"], o["theta"], o["psi"]] for o in fields["orientations"]], dtype=float
                ).reshape(-1, 3)
            call = PoseCheckCall(
                item.log_time_ns,
                item.topic,
                [position["x"], position["y"], position["z"]],
                angles,
            )
            summary.checks.append(call)
            pending_requests.setdefault(_service_of(item.topic), []).append(call)
        elif msgtype in (_CHECK_RESPONSE, _FLAT_RESPONSE):
            queue = pending_requests.get(_service_of(item.topic), [])
            if queue:
                call = queue.pop(0)
            else:  # response without its request (log cut before it)
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
