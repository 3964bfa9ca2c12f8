"""The machining cell on the node: frames of requests and results, feeds on ``~/check_path``,
``~/axis_limits``, and the cell's lines on ``/diagnostics``.

Frames
    The node's model is the tool model (:func:`hexapod_workspace.core.cell.frames.tool_model`) of
    the parameters' platform and the active tool (``tool.number``: 0 = ``tool.offset`` and
    ``tool.orientation``, n = ``tools.T<n>.*``), so every pose it takes and returns is the tool
    centre point's. A request's poses are in the frame its ``header.frame_id`` names: the base
    frame ``frame_id`` (or ``""``, as before frames existed), or the work frame
    ``work.frame_id``, converted to the base frame here (:func:`angles_to_base`,
    :func:`poses_to_base`); any other name is refused with the reason. Results are in the base
    frame and carry ``frames`` (``CellFrames``): the tool and work frame they were computed with
    and the frame the request was given in.
Run-time changes
    ``tool.*``, ``tools.T<n>.*``, ``work.*`` and ``limits.actuator_speed_max`` are parameters like
    the model's: validated as a whole set (the model by
    :func:`~hexapod_workspace.core.evaluation.loading.require_usable`, the cell by
    :func:`~hexapod_workspace.core.cell.frames.cell_from_mapping`), swapped in as one state between
    two requests, and every change, accepted or refused, is recorded in the log
    (``/hexapod_workspace/parameter_changes``, ``ParameterChange``) and shown on
    ``/diagnostics`` (:class:`CellStatus`). A tool-table entry not given at start is declared
    when a client first sets it (:func:`new_dynamic_parameters`).
    The collision scene (``collision.*``: clearance, platform and tool bodies, the obstacles as
    ``collision.obstacles.names`` plus one group ``collision.obstacles.<name>.*`` per name) is
    declared the same way: the names the parameters file gives, and any a client sets (an
    obstacle added: its name in the list and its group in one atomic call). The whole scene
    is checked by :func:`~hexapod_workspace.core.model.collision.params.collision_scene` as part of
    the model (the CLI's one validation); an obstacle is removed by taking its name off the
    list and unsetting its group in one call.
Feeds
    :func:`path_speeds`: the per-move ``SegmentSpeed`` of a ``~/check_path`` request that gives
    feeds or durations.
Axis limits
    :class:`AxisLimitsPublisher`: with ``motion.current_pose_topic`` set, the ± reach along the
    six axes of ``axis_limits.frame`` at the last current pose, on ``~/axis_limits``
    (``AxisLimits``), at most ``axis_limits.rate`` per second. The 12 certified reaches take
    0.3-0.5 s, so they run in a spawned process of their own (a thread of this interpreter would
    hold the interpreter lock from the command callbacks; with the process, the commanded-pose
    median beside back-to-back axis limits is within 4 % of the node's without them in
    ``benchmarks/ros_cell_latency.py``); a thread of the node hands it the pose and publishes.
"""

from __future__ import annotations

import math
import multiprocessing
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any

import numpy as np
from hexapod_workspace_msgs.msg import AxisLimits, CellFrames, ParameterChange
from numpy.typing import NDArray

from hexapod_workspace.core.base.rotations import (
    matrix_to_quaternion,
    matrix_to_tt,
    quaternion_to_matrix,
    tt_to_matrix,
)
from hexapod_workspace.core.cell.frames import curves_to_base as work_curves_to_base
from hexapod_workspace.core.cell.frames import work_to_base
from hexapod_workspace.core.cell.reach import axis_limits
from hexapod_workspace.core.motions import PathCheck, TorsionPlan, reported_parts
from hexapod_workspace.core.motions.speeds import actuator_rates, feed_limits
from hexapod_workspace.errors import InputError
from hexapod_workspace.logs import REQUEST_QOS
from hexapod_workspace.logs.cell import (
    DEG_MIN,
    MM_MIN,
    axis_limits_fields,
    cell_frames_fields,
    segment_speed_fields,
    slow_moves_clause,
)

from .conversions import to_message, type_name
from .load_rows import require_geometric
from .parameters import State, dynamic_specs
from .scheduling import time_sharing, worker_policy

__all__ = [
    "PARAMETER_CHANGES_TOPIC",
    "AxisLimitsPublisher",
    "CellStatus",
    "actuator_limits",
    "angles_to_base",
    "feed_values",
    "frames_message",
    "in_work_frame",
    "new_dynamic_parameters",
    "optional_rate",
    "path_speeds",
    "poses_to_base",
]

#: Where every parameter change (accepted or refused) is recorded in the log.
PARAMETER_CHANGES_TOPIC = "/hexapod_workspace/parameter_changes"


def in_work_frame(state: State, frame_id: str) -> bool:
    """Whether poses with ``header.frame_id`` = ``frame_id`` are in the work frame (False: the
    base frame).

    Raises
    ------
    InputError
        Any other frame, with the two the node takes.
    """
    base = state.manipulator.frame_id
    if frame_id in ("", base):
        return False
    work = state.cell.work.frame_id if state.cell is not None else None
    if frame_id == work:
        return True
    msg = (
        f"header.frame_id: expected the base frame {base!r} (or '') or the work frame "
        f"{work!r} (work.frame_id), got {frame_id!r}"
    )
    raise InputError(msg)


def angles_to_base(
    state: State, frame_id: str, angles: NDArray[np.float64], position: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """T&T angles (N, 3) at one position (3,), given in ``frame_id``, in the base frame (the
    same arrays when they already are; non-finite values are left for the core to refuse)."""
    if not in_work_frame(state, frame_id):
        return angles, position
    assert state.cell is not None
    angles = np.asarray(angles, dtype=np.float64).reshape(-1, 3)
    if not (np.all(np.isfinite(angles)) and np.all(np.isfinite(position))):
        return angles, position  # the core refuses them with its own message
    rotations, positions = work_to_base(
        tt_to_matrix(angles), np.asarray(position, dtype=np.float64)[None, :], state.cell.work
    )
    return matrix_to_tt(rotations), positions[0]


def poses_to_base(
    state: State, frame_id: str, positions: NDArray[np.float64], quaternions: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Positions (N, 3), m, and quaternions (N, 4) (x, y, z, w) given in ``frame_id``, in the base
    frame (unchanged when they already are, or when a value is not finite: the core refuses it
    with the waypoint's index)."""
    if not in_work_frame(state, frame_id) or len(positions) == 0:
        return positions, quaternions
    assert state.cell is not None
    if not (np.all(np.isfinite(positions)) and np.all(np.isfinite(quaternions))):
        return positions, quaternions
    rotations, moved = work_to_base(quaternion_to_matrix(quaternions), positions, state.cell.work)
    return moved, matrix_to_quaternion(rotations)


def curves_to_base(
    state: State,
    frame_id: str,
    arcs: NDArray[np.float64] | None,
    beziers: NDArray[np.float64] | None,
) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """A request's curved moves, ``arcs`` (K, 7) and ``beziers`` (K, 6), given in ``frame_id``,
    in the base frame (:func:`~hexapod_workspace.core.cell.frames.curves_to_base`)."""
    if not in_work_frame(state, frame_id):
        return arcs, beziers
    assert state.cell is not None
    return work_curves_to_base(arcs, beziers, state.cell.work)


_frames_cache: dict[tuple[int, str], tuple[State, Any]] = {}


def frames_message(state: State, request_frame_id: str = "") -> Any:
    """The ``CellFrames`` message of ``state`` (built once per state and request frame)."""
    key = (id(state), request_frame_id)
    cached = _frames_cache.get(key)
    if cached is not None and cached[0] is state:
        return cached[1]
    message = to_message(CellFrames, cell_frames_fields(state.cell, request_frame_id))
    if len(_frames_cache) > 64:
        _frames_cache.clear()
    _frames_cache[key] = (state, message)
    return message


# --------------------------------------------------------------------------- ~/check_path feeds
def feed_values(values: Any, count: int, name: str) -> NDArray[np.float64]:
    """Per-move values (count,) from a request array: empty (all NaN), one for every move, or
    one per move; each > 0 or NaN (none), else InputError naming ``name[k]``."""
    array = np.asarray(list(values), dtype=np.float64)
    if array.size == 0:
        return np.full(count, np.nan)
    if array.size not in (1, count):
        msg = f"{name}: expected one value or one per move ({count}), got {array.size}"
        raise InputError(msg)
    bad = ~np.isnan(array) & ~(np.isfinite(array) & (array > 0.0))
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        msg = f"{name}[{k}]: expected a finite value > 0 (NaN = none), got {float(array[k])!r}"
        raise InputError(msg)
    return np.broadcast_to(array, (count,)).copy()


def optional_rate(value: float, name: str, unit: str) -> float:
    """A request's single rate: 0 = none (NaN), else finite and > 0."""
    value = float(value)
    if value == 0.0:
        return math.nan
    if not (math.isfinite(value) and value > 0.0):
        msg = f"{name}: expected a finite value > 0 {unit} (0 = none), got {value!r}"
        raise InputError(msg)
    return value


def actuator_limits(state: State) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``limits.actuator_speed_max`` and ``limits.actuator_accel_max`` (six each, actuator
    unit/s and unit/s², 0 = unlimited) of the node's state; zeros without a cell."""
    if state.cell is None:
        return np.zeros(6, dtype=np.float64), np.zeros(6, dtype=np.float64)
    return (
        np.asarray(state.cell.actuator_speed_max, dtype=np.float64),
        np.asarray(state.cell.actuator_accel_max, dtype=np.float64),
    )


def speeds_requested(request: Any) -> bool:
    """Whether a ``CheckPath`` request asks for speeds (gives a feed, a rate or durations)."""
    return bool(
        len(request.feeds_mm_min)
        or len(request.durations_s)
        or request.rapid_feed_mm_min != 0.0
        or request.rotary_feed_deg_min != 0.0
    )


def validate_speed_request(request: Any, interpolation: str) -> None:
    """Refuse what the speed check cannot take before the path is checked (InputError)."""
    count = max(len(request.poses) - 1, 0)
    if len(request.feeds_mm_min) and len(request.durations_s):
        msg = "feeds_mm_min, durations_s: give feeds or durations, not both"
        raise InputError(msg)
    if len(request.rapid) not in (0, count):
        msg = f"rapid: expected none or one per move ({count}), got {len(request.rapid)}"
        raise InputError(msg)
    feed_values(request.feeds_mm_min, count, "feeds_mm_min")
    durations = np.asarray(list(request.durations_s), dtype=np.float64)
    if durations.size not in (0, count):
        msg = f"durations_s: expected one per move ({count}), got {durations.size}"
        raise InputError(msg)
    if durations.size and not np.all(np.isfinite(durations) & (durations > 0.0)):
        k = int(np.flatnonzero(~(np.isfinite(durations) & (durations > 0.0)))[0])
        msg = f"durations_s[{k}]: expected a finite value > 0 s, got {float(durations[k])!r}"
        raise InputError(msg)
    optional_rate(request.rapid_feed_mm_min, "rapid_feed_mm_min", "mm/min")
    optional_rate(request.rotary_feed_deg_min, "rotary_feed_deg_min", "deg/min")
    if interpolation != "slerp":
        msg = (
            "interpolation: the speed check (feeds, durations) needs SLERP (the controller's moves)"
        )
        raise InputError(msg)


def path_speeds(state: State, request: Any, result: PathCheck | TorsionPlan) -> dict[str, Any]:
    """``speeds`` and ``actuator_speed_max`` of a ``CheckPath`` response (request validated by
    :func:`validate_speed_request`), along the moves as checked (their arcs and Bézier curves).

    A move's feed: ``rapid_feed_mm_min`` when ``rapid[k]``, else ``feeds_mm_min[k]``; a move
    without translation runs at ``rotary_feed_deg_min``. With ``durations_s`` each move's feed is
    its length (or rotation angle) over its duration.
    """
    limits = actuator_limits(state)[0]
    checked, _ = reported_parts(result)
    waypoints = checked.waypoints
    count = len(waypoints) - 1
    rotations = tt_to_matrix(waypoints.angles)
    rates = actuator_rates(
        state.manipulator,
        waypoints.positions,
        rotations,
        speed_limits=limits,
        arcs=checked.arcs,
        beziers=checked.beziers,
    )
    rapid: NDArray[Any] = np.zeros(count, dtype=bool)
    if len(request.rapid):
        rapid = np.asarray(list(request.rapid), dtype=bool)
    feed: NDArray[Any]
    rotary_feed: NDArray[Any] = np.full(
        count,
        optional_rate(request.rotary_feed_deg_min, "rotary_feed_deg_min", "deg/min") * DEG_MIN,
    )
    if len(request.durations_s):
        durations = np.asarray(list(request.durations_s), dtype=np.float64)
        feed = rates.translation / durations
        rotary_feed = rates.rotation / durations
    else:
        feed = feed_values(request.feeds_mm_min, count, "feeds_mm_min") * MM_MIN
        rapid_feed = optional_rate(request.rapid_feed_mm_min, "rapid_feed_mm_min", "mm/min")
        feed = np.where(rapid, rapid_feed * MM_MIN, feed)
    # a still move (no translation, no rotation) takes no time whatever its feed
    feed = np.where(feed > 0.0, feed, np.nan)
    rotary_feed = np.where(rotary_feed > 0.0, rotary_feed, np.nan)
    speeds = feed_limits(rates, feed, rotary_feed, limits)
    fields: dict[str, Any] = {
        "speeds": segment_speed_fields(speeds, rapid, feed, rotary_feed),
        "actuator_speed_max": [float(v) for v in limits],
    }
    clause = slow_moves_clause(speeds)
    if clause:  # as check-path: a move that must slow down does not run as programmed
        fields["ok"] = False
        fields["message_suffix"] = clause
    return fields


# --------------------------------------------------------------------------- parameter changes
def new_dynamic_parameters(node: Any, parameters: list[Any]) -> dict[str, Any]:
    """Specs of the tool-table and collision parameters in ``parameters`` that ``node`` has not
    declared yet (a client adding a tool or an obstacle at run time); empty when there are
    none."""
    names = [p.name for p in parameters]
    return {
        name: spec for name, spec in dynamic_specs(names).items() if not node.has_parameter(name)
    }


class CellStatus:
    """The cell's lines on ``/diagnostics`` and the log's record of parameter changes."""

    def __init__(self, node: Any) -> None:
        self._node = node
        self.last_change = ""
        self.last_refusal = ""
        node.recorder.add_channel(PARAMETER_CHANGES_TOPIC, type_name(ParameterChange), REQUEST_QOS)

    def record(self, parameters: list[Any], *, refused: str | None) -> None:
        """Record a change (``refused`` None) or a refusal (``refused`` the reason) in the log
        and in the status."""
        change = ParameterChange(
            accepted=refused is None,
            reason=refused or "",
            names=[p.name for p in parameters],
            values=[_yaml_text(p.value) for p in parameters],
        )
        change.header.stamp = self._node.get_clock().now().to_msg()
        state = self._node.state
        change.header.frame_id = state.manipulator.frame_id if state is not None else ""
        self._node.recorder.write(PARAMETER_CHANGES_TOPIC, change)
        names = ", ".join(p.name for p in parameters)
        if refused is None:
            self.last_change = names
        else:
            self.last_refusal = refused

    def values(self, state: State | None) -> dict[str, str]:
        """Key-value lines of ``/diagnostics``: the frames in force and the last changes."""
        if state is None or state.cell is None:
            return {}
        tool, work = state.cell.tool, state.cell.work
        name = f"T{tool.number}" if tool.number else "tool.offset"
        return {
            "tool": (
                f"{name}: offset {np.round(tool.offset, 6).tolist()} m, orientation "
                f"{np.round(tool.orientation, 6).tolist()} rad"
            ),
            "work frame": (
                f"{work.frame_id}: origin {np.round(work.origin, 6).tolist()} m, orientation "
                f"{np.round(work.orientation, 6).tolist()} rad"
            ),
            "last parameter change": self.last_change,
            "last refused parameter change": self.last_refusal,
        }


def _yaml_text(value: Any) -> str:
    """A parameter value as YAML flow text (arrays as lists, floats as Python writes them)."""
    if value is None:
        return "null"
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, (bool, int, float)):
        return str(value).lower() if isinstance(value, bool) else repr(value)
    return "[" + ", ".join(_yaml_text(v) for v in list(value)) + "]"


# --------------------------------------------------------------------------- ~/axis_limits
class AxisLimitsPublisher:
    """Publishes the axis limits at the current pose (see the module documentation).

    Parameters
    ----------
    node : WorkspaceNode
    topic : str
        ``~/axis_limits``.
    current_pose : callable
        Returns the last current pose as ``(position (3,), quaternion (4,), frame_id, stamp)``
        or None.
    """

    def __init__(self, node: Any, topic: str, current_pose: Any) -> None:
        self._node = node
        self._current_pose = current_pose
        self.publisher = node.recorded_publisher(AxisLimits, topic)
        self._pool: ProcessPoolExecutor | None = None  # started with the first current pose
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="axis_limits", daemon=True)
        self._thread.start()

    def pose_received(self) -> None:
        """A new current pose arrived (the subscription's callback: returns at once)."""
        self._wake.set()

    def close(self) -> None:
        self._stop.set()
        self._wake.set()
        self._thread.join(timeout=10.0)
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)

    def _compute(
        self,
        manipulator: Any,
        rotation: NDArray[np.float64],
        position: NDArray[np.float64],
        frame: str,
        work: Any,
    ) -> dict[str, Any]:
        """:func:`~hexapod_workspace.core.cell.reach.axis_limits` in the spawned process."""
        if self._pool is None:
            self._pool = ProcessPoolExecutor(  # the worker's policy, under a real-time node too
                max_workers=1,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=time_sharing,
                initargs=(worker_policy(),),
            )
        future = self._pool.submit(
            axis_limits, manipulator, rotation, position, frame=frame, work=work
        )
        result: dict[str, Any] = future.result()
        return result

    def _run(self) -> None:
        while not self._stop.is_set():
            self._wake.wait()
            self._wake.clear()
            if self._stop.is_set():
                return
            state = self._node.state
            if state is None or not self._node.active or state.settings.axis_limits_rate <= 0.0:
                continue
            started = time.monotonic()
            try:
                self._publish(state)
            except Exception as error:  # keep publishing; the reason goes to the log
                self._node.internal_error(error)
                if self._pool is not None and isinstance(error, BrokenProcessPool):
                    self._pool = None  # the process died: the next pose starts a new one
            # rate limit: at most axis_limits.rate messages per second
            self._stop.wait(
                max(0.0, 1.0 / state.settings.axis_limits_rate - (time.monotonic() - started))
            )

    def _publish(self, state: State) -> None:
        current = self._current_pose()
        if current is None:
            return
        position, quaternion, frame_id, stamp_ns = current
        frame = state.settings.axis_limits_frame
        names = {"base": state.manipulator.frame_id, "tool": "tool"}
        axes_frame_id = names.get(frame) or (state.cell.work.frame_id if state.cell else "work")
        work = state.cell.work if state.cell is not None else None
        where = {"frame": frame, "frame_id": axes_frame_id, "stamp_ns": stamp_ns}
        try:
            positions, quaternions = poses_to_base(
                state, frame_id, position[None, :], quaternion[None, :]
            )
            rotation = quaternion_to_matrix(quaternions)[0]
            limits: dict[str, Any] | None = None
            try:
                manipulator = require_geometric(state, "the axis limits")
            except InputError as error:  # a loads limit set: no certified limits yet
                message = str(error)
            else:
                limits = self._compute(manipulator, rotation, positions[0], frame, work)
                message = _verdict(limits)
            fields = axis_limits_fields(
                limits,
                **where,
                position=positions[0],
                quaternion=quaternions[0],
                cell=state.cell,
                message=message,
            )
        except InputError as error:  # a current pose in another frame, or not a rotation
            fields = axis_limits_fields(
                None,
                **where,
                position=position,
                quaternion=quaternion,
                cell=state.cell,
                message=f"current pose: {error}",
            )
        self._node.publish(self.publisher, to_message(AxisLimits, fields))


def _verdict(limits: dict[str, Any]) -> str:
    first = next(iter(limits.values()))
    if not first.start_reachable:
        return f"the current pose is unreachable ({', '.join(first.limited_by_plus)}): limits 0"
    return "axis limits at the current pose"
