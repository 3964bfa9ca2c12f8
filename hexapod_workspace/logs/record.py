"""Record results of the core in the node's log format (what the CLI's ``--record FILE`` writes)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from hexapod_workspace.core.base.resolution import WorkspaceKind
from hexapod_workspace.errors import RecordingError
from hexapod_workspace.logs import (
    RESULT_QOS,
    SERVICE_QOS,
    LogWriter,
    messages,
    recorded_type,
    service_topics,
)

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence


def record_results(
    path: str | Path,
    results: Iterable[Any],
    *,
    frame_id: str = "base",
    request_id: str = "",
    stamp_ns: int | None = None,
    stamps_ns: Sequence[int] | None = None,
) -> Path:
    """Record CLI results in the node's log format (what ``--record FILE`` writes).

    Each ``CheckResult`` is recorded as a CheckPoses call (request and response on
    ``/hexapod_workspace/check_poses/{request,response}``, as
    :func:`~hexapod_workspace.logs.typestore.recorded_type` says); each projected or orientation
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
        Time of the first request (ns since the epoch) when ``stamps_ns`` is not given;
        default now minus the results' computation times, so the log ends now. The results
        are laid out one after the other: each request at its start, its response (or summary
        and cloud) its computation time (``elapsed``) later.
    stamps_ns : sequence of int, optional
        When each result's computation started (ns since the epoch), one per result: each
        request is recorded then, its response ``elapsed`` later.

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
    results = list(results)
    durations = [max(1_000, int(getattr(r, "elapsed", 0.0) * 1e9)) for r in results]
    if stamps_ns is None:
        start = time.time_ns() - sum(durations) if stamp_ns is None else int(stamp_ns)
        starts, at = [], start
        for duration in durations:
            starts.append(at)
            at += duration + 1_000
    else:
        starts = [int(s) for s in stamps_ns]
        if len(starts) != len(results):
            msg = f"stamps_ns: expected one per result ({len(results)}), got {len(starts)}"
            raise RecordingError(msg)
    # One chunk per message: a damaged file keeps every message before the damage.
    with LogWriter(path, flush_interval=0, flush_messages=1) as writer:
        for result, stamp, duration in zip(results, starts, durations, strict=True):
            if hasattr(result, "margins"):  # a CheckResult
                request, response = service_topics(topics["check_poses"])
                writer.write_fields(
                    request,
                    recorded_type(f"{types['check_poses']}_Request"),
                    messages.check_poses_request_fields(result.position, result.angles),
                    stamp,
                    qos=SERVICE_QOS,
                )
                writer.write_fields(
                    response,
                    recorded_type(f"{types['check_poses']}_Response"),
                    messages.check_poses_response_fields(result),
                    stamp + duration,
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
                    stamp_ns=stamp + duration,
                    frame_id=frame_id,
                    request_id=request_id,
                    kind=kind,
                    n_points=len(points),
                )
                writer.write_fields(
                    topics["workspace_summary"],
                    types["workspace_summary"],
                    summary,
                    stamp + duration,
                    qos=RESULT_QOS,
                )
                cloud = (
                    "orientation_workspace"
                    if kind == WorkspaceKind.ORIENTATION
                    else "projected_workspace"
                )
                writer.write_fields(
                    topics[cloud],
                    types[cloud],
                    messages.pointcloud_fields(
                        points, frame_id=frame_id, stamp_ns=stamp + duration
                    ),
                    stamp + duration,
                    qos=RESULT_QOS,
                )
    return Path(path)
