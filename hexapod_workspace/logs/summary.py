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
_SCHEDULE_REQUEST = "hexapod_workspace_msgs/srv/SchedulePath_Request"
_SCHEDULE_RESPONSE = "hexapod_workspace_msgs/srv/SchedulePath_Response"
_LOADS_REQUEST = "hexapod_workspace_msgs/srv/Loads_Request"
_LOADS_RESPONSE = "hexapod_workspace_msgs/srv/Loads_Response"
_PARAMETER_CHANGE = "hexapod_workspace_msgs/msg/ParameterChange"
_AXIS_LIMITS = "hexapod_workspace_msgs/msg/AxisLimits"


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
    order); ``response`` holds the fields of either form.

    ``position`` is None for the ``geometry_msgs/Pose`` form (each pose has its own position,
    ``angles`` is then None) and for a response without its request; ``n_poses`` counts the
    poses of either form.
    """

    log_time_ns: int
    topic: str
    position: list[float] | None = None
    angles: np.ndarray | None = None
    response: dict[str, Any] | None = None
    n_poses: int | None = None

    @property
    def n_reachable(self) -> int:
        """Poses answered reachable (nested ``results`` or flat ``reachable``)."""
        response = self.response or {}
        if "results" in response:
            return sum(bool(r["reachable"]) for r in response["results"])
        return int(np.count_nonzero(np.asarray(response.get("reachable", []), dtype=bool)))


@dataclass
class AtlasRecord:
    """One recorded atlas cloud (``~/atlas``: x, y, z then one float32 per atlas value).

    Attributes
    ----------
    log_time_ns : int
    topic : str
    columns : dict of str to ndarray, shape (M,)
        Every FLOAT32/FLOAT64 field of the cloud by name (x, y, z in m, angles in rad).
    """

    log_time_ns: int
    topic: str
    columns: dict[str, np.ndarray]


@dataclass
class LogSummary:
    """Everything :func:`hexapod_workspace.cli.replay.run_replay` reports about a log."""

    contents: LogContents
    workspaces: list[WorkspaceRecord] = field(default_factory=list)
    checks: list[PoseCheckCall] = field(default_factory=list)
    reachability: list[dict[str, Any]] = field(default_factory=list)
    triggers: list[dict[str, Any]] = field(default_factory=list)
    paths: list[dict[str, Any]] = field(default_factory=list)
    #: the ~/schedule_path calls (request and response fields, paired as ``paths``)
    schedules: list[dict[str, Any]] = field(default_factory=list)
    #: the ~/loads calls (request and response fields, paired as ``paths``)
    loads: list[dict[str, Any]] = field(default_factory=list)
    atlases: list[AtlasRecord] = field(default_factory=list)
    #: the node's set_parameters calls (ParameterChange fields, with ``log_time_ns``)
    parameter_changes: list[dict[str, Any]] = field(default_factory=list)
    #: the published axis limits (AxisLimits fields, with ``log_time_ns``)
    axis_limits: list[dict[str, Any]] = field(default_factory=list)
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
        elif msgtype == _CLOUD and _is_atlas(fields := message_to_fields(item.message)):
            columns = _cloud_columns(fields, contents, item.topic)
            if columns is not None:
                summary.atlases.append(AtlasRecord(item.log_time_ns, item.topic, columns))
        elif msgtype == _CLOUD:
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
            poses = [] if msgtype == _FLAT_REQUEST else fields.get("poses") or []
            if poses:  # the geometry_msgs/Pose form: each pose at its own position
                call = PoseCheckCall(item.log_time_ns, item.topic, n_poses=len(poses))
            else:
                if msgtype == _FLAT_REQUEST:
                    angles = np.asarray(fields["angles"], dtype=float).reshape(-1, 3)
                else:
                    angles = np.array(
                        [[o["phi"], o["theta"], o["psi"]] for o in fields["orientations"]],
                        dtype=float,
                    ).reshape(-1, 3)
                call = PoseCheckCall(
                    item.log_time_ns,
                    item.topic,
                    [position["x"], position["y"], position["z"]],
                    angles,
                    n_poses=len(angles),
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
        elif msgtype in (_SCHEDULE_REQUEST, _SCHEDULE_RESPONSE):
            path_call_fields(summary.schedules, item.topic, item.log_time_ns, item.message)
        elif msgtype in (_LOADS_REQUEST, _LOADS_RESPONSE):
            path_call_fields(summary.loads, item.topic, item.log_time_ns, item.message)
        elif msgtype == _TRIGGER_RESPONSE:
            fields = message_to_fields(item.message)
            fields.update(topic=item.topic, log_time_ns=item.log_time_ns)
            summary.triggers.append(fields)
        elif msgtype in (_PARAMETER_CHANGE, _AXIS_LIMITS):
            fields = message_to_fields(item.message)
            fields["log_time_ns"] = item.log_time_ns
            kept_in = (
                summary.parameter_changes if msgtype == _PARAMETER_CHANGE else summary.axis_limits
            )
            kept_in.append(fields)
    return summary, kept


def _service_of(topic: str) -> str:
    return topic.rsplit("/", 1)[0]


#: A cloud with this field is an atlas (``~/atlas``), not a workspace boundary.
_ATLAS_FIELD = "tilt_capability"


def _is_atlas(fields: dict[str, Any]) -> bool:
    return any(str(f["name"]) == _ATLAS_FIELD for f in fields["fields"])


def _cloud_columns(
    fields: dict[str, Any], contents: LogContents, topic: str
) -> dict[str, np.ndarray] | None:
    """Every FLOAT32/FLOAT64 field of a cloud by name, or None (a note) when unreadable."""
    count = int(fields["width"]) * int(fields["height"])
    step = int(fields["point_step"])
    buffer = np.frombuffer(bytes(fields["data"]), dtype=np.uint8)
    if buffer.size < count * step:
        contents.problems.append(
            f"{topic}: a PointCloud2 could not be read (data has {buffer.size} bytes, "
            f"expected {count * step})"
        )
        return None
    order = ">" if fields["is_bigendian"] else "<"
    rows = buffer[: count * step].reshape(count, step)
    columns: dict[str, np.ndarray] = {}
    for point_field in fields["fields"]:
        datatype, offset = int(point_field["datatype"]), int(point_field["offset"])
        if datatype in (7, 8):  # FLOAT32, FLOAT64
            width = 4 if datatype == 7 else 8
            raw = np.ascontiguousarray(rows[:, offset : offset + width])
            columns[str(point_field["name"])] = raw.view(f"{order}f{width}")[:, 0].astype(float)
    return columns


def _cloud_points(fields: dict[str, Any], contents: LogContents, topic: str) -> np.ndarray | None:
    try:
        return messages.pointcloud_to_array(fields)
    except ValueError as err:
        contents.problems.append(f"{topic}: a PointCloud2 could not be read ({err})")
        return None
