"""Machining-cell results <-> message fields: ``CellFrames``, ``SegmentSpeed``, ``AxisLimits``.

The same nested-dict form as :mod:`hexapod_workspace.logs.messages` (ROS field names, plain
Python values), read by the node (:mod:`hexapod_workspace.ros.cell`) and by the CLI's
``check-path --record``. Units: m, rad; speeds in the actuator's unit per second; feeds in mm/min
and deg/min as the CL files and the CLI give them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..core.cell.frames import CellFrames
from ..core.cell.reach import AXES, Reach
from ..core.motions.speeds import FeedLimits
from . import messages

__all__ = [
    "DEG_MIN",
    "MM_MIN",
    "axis_limits_fields",
    "cell_frames_fields",
    "segment_speed_fields",
    "slow_moves_clause",
]

#: m/s per mm/min and rad/s per deg/min (the units of feeds in requests and results).
MM_MIN = 1e-3 / 60.0
DEG_MIN = math.radians(1.0) / 60.0


def cell_frames_fields(cell: CellFrames | None, request_frame_id: str = "") -> dict[str, Any]:
    """hexapod_workspace_msgs/msg/CellFrames: the active tool and the work frame of ``cell``
    (when ``cell`` is None, as results computed without a cell say: the tool at the platform
    frame, no work frame)."""
    if cell is None:
        return messages.no_cell_frames_fields(request_frame_id)
    tool, work = cell.tool, cell.work
    x, y, z = (float(v) for v in tool.offset)
    return {
        "tool_number": int(tool.number),
        "tool_offset": {"x": x, "y": y, "z": z},
        "tool_orientation": messages.tilt_torsion_fields(tool.orientation),
        "work_frame_id": work.frame_id,
        "work_origin": messages.point_fields(work.origin),
        "work_orientation": messages.tilt_torsion_fields(work.orientation),
        "request_frame_id": str(request_frame_id),
    }


def segment_speed_fields(
    speeds: FeedLimits, rapid: ArrayLike, feeds: ArrayLike, rotary_feeds: ArrayLike
) -> list[dict[str, Any]]:
    """hexapod_workspace_msgs/msg/SegmentSpeed of every move.

    Parameters
    ----------
    speeds : FeedLimits
        :func:`hexapod_workspace.core.motions.speeds.feed_limits` of the moves.
    rapid : array_like of bool, shape (M,)
    feeds : array_like, shape (M,)
        Feed used per move, m/s (NaN: none).
    rotary_feeds : array_like, shape (M,)
        Rotation rate used by rotary moves, rad/s (NaN: none).
    """
    rapid = np.broadcast_to(np.asarray(rapid, dtype=bool), speeds.duration.shape)
    feed = np.broadcast_to(np.asarray(feeds, dtype=float), speeds.duration.shape)
    rotary_feed = np.broadcast_to(np.asarray(rotary_feeds, dtype=float), speeds.duration.shape)
    fields = []
    for k in range(speeds.duration.size):
        checked = speeds.speed_ok[k] is not None
        rotary = bool(speeds.rotary[k])
        feed_max = float(speeds.feed_max[k])
        fields.append(
            {
                "speed_checked": checked,
                "speed_ok": bool(speeds.speed_ok[k]) if checked else False,
                "rapid": bool(rapid[k]),
                "rotary": rotary,
                "duration_s": float(speeds.duration[k]),
                "feed_mm_min": math.nan if rotary or not checked else float(feed[k]) / MM_MIN,
                "feed_deg_min": float(rotary_feed[k]) / DEG_MIN if rotary and checked else math.nan,
                "actuator_speed_peak": float(speeds.speed_peak[k]),
                "feed_max_mm_min": math.nan if rotary else feed_max / MM_MIN,
                "feed_max_deg_min": feed_max / DEG_MIN if rotary else math.nan,
            }
        )
    return fields


def slow_moves_clause(speeds: FeedLimits, first: int = 0) -> str:
    """``"; moves 3, 7 must slow down (actuator speed)"`` for the moves whose certified peak
    exceeds a limit (numbered from ``first``), ``""`` when there are none."""
    slow = [first + k for k in range(speeds.duration.size) if speeds.speed_ok[k] is False]
    if not slow:
        return ""
    shown = ", ".join(str(k) for k in slow[:8]) + (f", ... ({len(slow)})" if len(slow) > 8 else "")
    return f"; moves {shown} must slow down (actuator speed)"


def axis_limits_fields(
    limits: dict[str, Reach] | None,
    *,
    frame: str,
    frame_id: str,
    stamp_ns: int,
    position: ArrayLike,
    quaternion: ArrayLike,
    cell: CellFrames | None,
    message: str,
) -> dict[str, Any]:
    """hexapod_workspace_msgs/msg/AxisLimits of
    :func:`hexapod_workspace.core.cell.reach.axis_limits` (``limits`` None: a failure, ``message``
    the reason)."""
    x, y, z, w = (float(v) for v in np.asarray(quaternion, dtype=float).reshape(4))
    fields: dict[str, Any] = {
        "header": messages.header_fields(stamp_ns, frame_id),
        "success": limits is not None,
        "message": message,
        "frame": frame,
        "pose": {
            "position": messages.point_fields(position),
            "orientation": {"x": x, "y": y, "z": z, "w": w},
        },
        "frames": cell_frames_fields(cell),
    }
    if limits is None:
        nan = [math.nan] * len(AXES)
        fields.update(axes=list(AXES), plus=nan, minus=nan, t_max=nan)
        return fields
    reaches = [limits[name] for name in AXES]
    fields.update(
        axes=list(AXES),
        plus=[r.plus for r in reaches],
        minus=[r.minus for r in reaches],
        limited_by_plus=[",".join(r.limited_by_plus) for r in reaches],
        limited_by_minus=[",".join(r.limited_by_minus) for r in reaches],
        t_max=[r.t_max for r in reaches],
        tolerance=reaches[0].tolerance,
    )
    return fields
