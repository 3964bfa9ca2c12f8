"""ROS side of motions: ``~/check_path``, poses as ROS holds them, moves from the current pose.

Everything here is wired onto a node by :func:`attach` (a few lines in the node), so the node
module keeps only its own wiring:

* service ``~/check_path`` (``hexapod_workspace_msgs/srv/CheckPath``): a path of
  ``geometry_msgs/Pose`` in the base or the work frame (``header.frame_id``,
  :mod:`~hexapod_workspace.ros.cell`), checked move by move (certified), or with
  ``free_torsion`` the rotation about each pose's z-axis (the tool axis) planned; with feeds or
  durations, each move's certified peak actuator speed and largest feed (``speeds``);
* parameter ``motion.current_pose_topic`` (read-only, default ``""``): a
  ``geometry_msgs/PoseStamped`` topic; when set, the last pose received there is the *current
  pose* (base or work frame, by its ``header.frame_id``) and :meth:`PathServices.with_motion`
  checks each commanded pose as a move from it, and ``~/axis_limits`` follows it
  (:class:`~hexapod_workspace.ros.cell.AxisLimitsPublisher`); every pose received there is
  recorded (the log reproduces each motion verdict);
* conversions of ``geometry_msgs/Pose`` to arrays and back, and of the Pose forms of
  ``CheckPoses`` requests and ``CommandedPose`` messages.

Units: m and rad; positions and quaternions ``(x, y, z, w)``; results in the base frame.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from geometry_msgs.msg import PoseStamped
from hexapod_workspace_msgs.srv import CheckPath
from numpy.typing import NDArray
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.callback_groups import ReentrantCallbackGroup

from ..core.base.rotations import matrix_to_tt, quaternion_to_matrix, tt_to_matrix, wrap_angle
from ..core.model.manipulator import Manipulator
from ..core.motions import (
    DEFAULT_PATH_TOLERANCE,
    DEFAULT_PLAN_PSI_STEP,
    INTERPOLATIONS,
    PathCheck,
    TorsionPlan,
    check_path,
    check_waypoints,
    plan_torsion,
    report_singularity,
)
from ..core.motions.baseline import reported_baseline
from ..errors import HexapodWorkspaceError, InputError
from ..logs import (
    REQUEST_QOS,
    SERVICE_QOS,
    messages,
    recorded_type,
    service_topics,
)
from ..logs import paths as path_fields
from ..logs.interfaces import relative_name
from . import cell
from .conversions import to_message, type_name
from .load_rows import check_poses_with_loads, load_rows_of, require_geometric
from .parameters import State
from .qos import SERVICE_QOS_PROFILE

__all__ = [
    "CURRENT_POSE_PARAMETER",
    "PathServices",
    "attach",
    "check_path_response_fields",
    "check_poses_from_poses",
    "commanded_target",
    "curve_rows",
    "pose_arrays",
    "positive_option",
]

#: Parameter naming the current-pose topic (geometry_msgs/PoseStamped); "" = none.
CURRENT_POSE_PARAMETER = "motion.current_pose_topic"


def pose_arrays(poses: Sequence[Any]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Positions (N, 3), m, and quaternions (N, 4) ``(x, y, z, w)`` of Pose messages.

    Not validated here (NaN stays NaN; the core refuses it with the waypoint's index).
    """
    flat = [
        value
        for pose in poses
        for value in (
            pose.position.x,
            pose.position.y,
            pose.position.z,
            pose.orientation.x,
            pose.orientation.y,
            pose.orientation.z,
            pose.orientation.w,
        )
    ]
    values = np.array(flat, dtype=np.float64).reshape(-1, 7)
    return values[:, :3], values[:, 3:]


def commanded_target(command: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Position (3,), m, and T&T angles (1, 3), rad, of a ``CommandedPose`` in either form.

    With ``use_pose`` the pose is ``command.pose`` (quaternion, converted here: a controller
    never converts to T&T itself); otherwise ``position`` + ``orientation``.

    Raises
    ------
    InputError
        A zero or non-finite quaternion.
    """
    if getattr(command, "use_pose", False):
        positions, quaternions = pose_arrays([command.pose])
        return positions[0], matrix_to_tt(quaternion_to_matrix(quaternions))
    point, tt = command.position, command.orientation
    return (
        np.array([point.x, point.y, point.z], dtype=np.float64),
        np.array([[tt.phi, tt.theta, tt.psi]], dtype=np.float64),
    )


def check_poses_from_poses(
    manipulator: Manipulator, request: Any, max_poses: int, state: State | None = None
) -> dict[str, Any]:
    """``CheckPoses_Response`` fields for a request that gives ``poses`` (geometry_msgs/Pose).

    Each pose is checked at its own position; ``orientations`` must then be empty. With
    ``state``, the poses are in the frame ``request.header.frame_id`` names (base or work).
    """
    count = len(request.poses)
    if len(request.orientations):
        reason = "give either orientations (at position) or poses, not both"
        return messages.check_poses_response_fields(None, success=False, message=reason)
    if count > max_poses:
        reason = f"poses: at most {max_poses} poses per request (check.max_poses), got {count}"
        return messages.check_poses_response_fields(None, success=False, message=reason)
    positions, quaternions = pose_arrays(request.poses)
    try:
        if state is not None:
            positions, quaternions = cell.poses_to_base(
                state, request.header.frame_id, positions, quaternions
            )
        result = check_waypoints(manipulator, positions, quaternions=quaternions)
        rows = None
        if state is not None:
            rows = load_rows_of(state, positions, quaternions=quaternions)
    except InputError as error:
        return messages.check_poses_response_fields(None, success=False, message=str(error))
    return check_poses_with_loads(messages.check_poses_response_fields(result), rows)


def check_path_response_fields(
    manipulator: Manipulator, request: Any, state: State | None = None
) -> dict[str, Any]:
    """``CheckPath_Response`` fields answering a request (a refusal with the reason when the
    request is malformed). With ``state``: poses in the frame ``request.header.frame_id`` names,
    the speeds of the moves when the request gives feeds or durations
    (:func:`hexapod_workspace.ros.cell.path_speeds`), and the frames used."""
    speeds = state is not None and cell.speeds_requested(request)
    try:
        if request.interpolation >= len(INTERPOLATIONS):
            msg = (
                f"interpolation: expected SLERP (0) or TILT_TORSION (1), got "
                f"{request.interpolation}"
            )
            raise InputError(msg)
        interpolation = INTERPOLATIONS[request.interpolation]
        tolerance = positive_option(request.tolerance, "tolerance", DEFAULT_PATH_TOLERANCE)
        positions, quaternions = pose_arrays(request.poses)
        arcs = curve_rows(request.arcs, len(positions), 7, "arcs")
        beziers = curve_rows(request.beziers, len(positions), 6, "beziers")
        if state is not None:
            require_geometric(state, "a path")
            positions, quaternions = cell.poses_to_base(
                state, request.header.frame_id, positions, quaternions
            )
            arcs, beziers = cell.curves_to_base(state, request.header.frame_id, arcs, beziers)
            if speeds:
                cell.validate_speed_request(request, interpolation)
        if request.free_torsion:
            psi_step = positive_option(request.psi_step, "psi_step", DEFAULT_PLAN_PSI_STEP)
            max_dpsi = None
            if request.limit_dpsi:
                max_dpsi = float(request.max_dpsi)
                if not (math.isfinite(max_dpsi) and max_dpsi >= 0.0):
                    msg = f"max_dpsi: expected a finite value >= 0 rad, got {max_dpsi!r}"
                    raise InputError(msg)
            if len(quaternions) and not np.all(np.isfinite(quaternions)):
                msg = "poses: expected finite quaternions"
                raise InputError(msg)
            axes = _tool_axes(quaternions)
            result: PathCheck | TorsionPlan = plan_torsion(
                manipulator,
                positions,
                axes,
                psi_step=psi_step,
                max_dpsi=max_dpsi,
                interpolation=interpolation,
                tolerance=tolerance,
                arcs=arcs,
                beziers=beziers,
            )
        else:
            result = check_path(
                manipulator,
                positions,
                quaternions=quaternions,
                interpolation=interpolation,
                tolerance=tolerance,
                arcs=arcs,
                beziers=beziers,
            )
        if state is not None and state.settings.report_singularity:
            result = report_singularity(manipulator, result)
        fields = path_fields.check_path_response_fields(
            result,
            pairs=manipulator.leg_diameter > 0.0,
            baseline=reported_baseline(manipulator, result),
        )
        if speeds:
            assert state is not None
            speed_fields = cell.path_speeds(state, request, result)
            fields["message"] += speed_fields.pop("message_suffix", "")
            fields.update(speed_fields)
    except HexapodWorkspaceError as error:
        fields = path_fields.failed_check_path_response_fields(str(error))
    if state is not None:
        fields["frames"] = cell.cell_frames_fields(state.cell, request.header.frame_id)
    return fields


def curve_rows(values: Any, count: int, width: int, name: str) -> NDArray[np.float64] | None:
    """A request's flattened per-move curve rows as (count − 1, width), or None when empty
    (every move straight); the core validates the rows (naming the move)."""
    array = np.asarray(list(values), dtype=np.float64)
    if array.size == 0:
        return None
    moves = max(count - 1, 0)
    if array.size != moves * width:
        msg = (
            f"{name}: expected none or {width} values per move ({moves} moves: "
            f"{moves * width}), got {array.size}"
        )
        raise InputError(msg)
    return array.reshape(moves, width)


def positive_option(value: float, name: str, default: float) -> float:
    """A request's angle option: 0 = ``default``, else finite and > 0 rad (InputError)."""
    value = float(value)
    if value == 0.0:
        return default
    if not (math.isfinite(value) and value > 0.0):
        msg = f"{name}: expected a finite value > 0 rad (0 = default), got {value!r}"
        raise InputError(msg)
    return value


def _tool_axes(quaternions: NDArray[np.float64]) -> NDArray[np.float64]:
    """z-axes (N, 3) of the poses' orientations: the tool axes (InputError for a zero one)."""
    if len(quaternions) == 0:
        return np.zeros((0, 3))
    return quaternion_to_matrix(quaternions)[:, :, 2]


@dataclass
class _CurrentPose:
    position: NDArray[np.float64]
    quaternion: NDArray[np.float64]
    frame_id: str
    stamp_ns: int


class PathServices:
    """What :func:`attach` created on a node; see the module documentation.

    Parameters
    ----------
    node : rclpy.node.Node
    get_manipulator : callable
        Returns the node's current manipulator (it changes with the parameters).
    recorder : object, optional
        With ``add_channel(topic, msgtype, qos)`` and ``write(topic, message)`` (the node's MCAP
        recorder): requests and responses of ``~/check_path`` are recorded there.
    """

    def __init__(
        self,
        node: Any,
        get_manipulator: Callable[[], Manipulator],
        recorder: Any | None = None,
        get_state: Callable[[], State] | None = None,
    ) -> None:
        self._node = node
        self._get_manipulator = get_manipulator
        self._get_state = get_state
        #: ~/axis_limits (hexapod_workspace.ros.cell), with a current-pose topic and a state
        self.axis_limits: cell.AxisLimitsPublisher | None = None
        self._recorder = recorder
        self._lock = threading.Lock()
        self._current: _CurrentPose | None = None
        self.parameter_names = [CURRENT_POSE_PARAMETER]
        group = ReentrantCallbackGroup()
        self.service = node.create_service(
            CheckPath,
            relative_name("check_path"),
            self._on_check_path,
            qos_profile=SERVICE_QOS_PROFILE,
            callback_group=group,
        )
        self._request_topic, self._response_topic = service_topics(
            node.resolve_service_name(relative_name("check_path"))
        )
        if recorder is not None:
            recorder.add_channel(
                self._request_topic,
                recorded_type(f"{path_fields.CHECK_PATH_TYPE}_Request"),
                SERVICE_QOS,
            )
            recorder.add_channel(
                self._response_topic,
                recorded_type(f"{path_fields.CHECK_PATH_TYPE}_Response"),
                SERVICE_QOS,
            )
        topic = node.declare_parameter(
            CURRENT_POSE_PARAMETER,
            "",
            ParameterDescriptor(
                description="geometry_msgs/PoseStamped topic of the platform's current pose "
                "(tool centre point; header.frame_id the base frame or work.frame_id). When set, "
                "each commanded pose is validated as a move (slerp) from the last pose received "
                "and ~/axis_limits follows it; empty = targets only.",
                read_only=True,
            ),
        ).value
        self.subscription = None
        self._current_pose_topic = ""
        if topic:
            self.subscription = node.create_subscription(
                PoseStamped, str(topic), self._on_current_pose, 10, callback_group=group
            )
            self._current_pose_topic = self.subscription.topic_name
            if recorder is not None:  # every pose a motion verdict may start from is in the log
                recorder.add_channel(self._current_pose_topic, type_name(PoseStamped), REQUEST_QOS)
            if get_state is not None:
                self.axis_limits = cell.AxisLimitsPublisher(
                    node, relative_name("axis_limits"), self.latest_current_pose
                )

    # ------------------------------------------------------------------ check_path
    def _on_check_path(self, request: Any, response: Any) -> Any:
        self._record(self._request_topic, request)
        try:
            state = self._get_state() if self._get_state is not None else None
            manipulator = state.manipulator if state is not None else self._get_manipulator()
            fields = check_path_response_fields(manipulator, request, state)
        except Exception as error:  # keep serving; the reason goes back to the caller
            self._node.get_logger().error(f"check_path: internal error: {error!r}")
            fields = path_fields.failed_check_path_response_fields(f"internal error: {error}")
        response = to_message(CheckPath.Response, fields)
        self._record(self._response_topic, response)
        return response

    def _record(self, topic: str, message: Any) -> None:
        if self._recorder is not None:
            self._recorder.write(topic, message)

    # ------------------------------------------------------------------ current pose
    def _on_current_pose(self, message: Any) -> None:
        """Keep the last current pose, recorded first: in the log, each motion verdict comes
        after the pose it started from."""
        self._record(self._current_pose_topic, message)
        positions, quaternions = pose_arrays([message.pose])
        stamp = message.header.stamp
        with self._lock:
            self._current = _CurrentPose(
                positions[0],
                quaternions[0],
                str(message.header.frame_id),
                stamp.sec * 1_000_000_000 + stamp.nanosec,
            )
        if self.axis_limits is not None:
            self.axis_limits.pose_received()

    def latest_current_pose(
        self,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], str, int] | None:
        """The last current pose as received: position (3,), quaternion (4,), its frame_id and
        its stamp (ns); None before the first."""
        with self._lock:
            current = self._current
        if current is None:
            return None
        return current.position, current.quaternion, current.frame_id, current.stamp_ns

    @property
    def current_pose(self) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """The last current pose received (position (3,), quaternion (4,)), or None."""
        with self._lock:
            current = self._current
        return None if current is None else (current.position, current.quaternion)

    def with_motion(
        self,
        fields: dict[str, Any],
        manipulator: Manipulator,
        position: NDArray[np.float64],
        angles: NDArray[np.float64],
    ) -> dict[str, Any]:
        """``ReachabilityResult`` fields with the move from the current pose added.

        Parameters
        ----------
        fields : dict
            The result's fields (``messages.reachability_result_fields``); returned unchanged
            when the command was invalid or no current pose is known.
        manipulator : Manipulator
        position : ndarray, shape (3,)
            Target position, m.
        angles : ndarray, shape (1, 3) or (3,)
            Target T&T angles, rad.

        Returns
        -------
        dict
            ``motion_checked``, ``motion_ok``, ``current_pose`` and ``motion`` filled, and a
            clause about the move appended to ``message``.
        """
        with self._lock:
            current = self._current
        if current is None or not fields.get("success", False):
            return fields
        fields = dict(fields)
        if self._get_state is not None:
            try:
                require_geometric(self._get_state(), "the move from the current pose")
            except InputError as error:
                fields["message"] += f"; move not checked: {error}"
                return fields
        position_now, quaternion_now = current.position, current.quaternion
        try:
            if self._get_state is not None:
                moved, turned = cell.poses_to_base(
                    self._get_state(),
                    current.frame_id,
                    position_now[None, :],
                    quaternion_now[None, :],
                )
                position_now, quaternion_now = moved[0], turned[0]
            elif current.frame_id and current.frame_id != manipulator.frame_id:
                msg = (
                    f"the current pose is in frame {current.frame_id!r}, not "
                    f"{manipulator.frame_id!r}"
                )
                raise InputError(msg)
        except InputError as error:
            fields["message"] += f"; move not checked: current pose: {error}"
            return fields
        try:
            start = quaternion_to_matrix(quaternion_now[None, :])
            target = tt_to_matrix(wrap_angle(np.asarray(angles, dtype=float).reshape(1, 3)))
            result = check_path(
                manipulator,
                np.vstack([position_now, np.asarray(position, dtype=float)]),
                rotations=np.concatenate([start, target]),
            )
        except InputError as error:
            fields["message"] += f"; move not checked: {error}"
            return fields
        segments = result.segments
        if result.ok:
            clause = "the move from the current pose runs"
        elif not result.waypoints.reachable[0]:
            clause = "the current pose itself is unreachable"
        elif not segments.ok[0]:
            clause = (
                f"the move from the current pose leaves the workspace at s = "
                f"{segments.first_violation_s[0]:.4f} ({', '.join(segments.violated[0])})"
            )
        else:
            clause = "the target is unreachable"
        fields.update(
            motion_checked=True,
            motion_ok=result.ok,
            current_pose=path_fields.pose_fields(position_now, quaternion_now),
            motion=path_fields.segment_check_fields(segments, 0),
            message=f"{fields['message']}; {clause}",
        )
        return fields


def attach(
    node: Any,
    get_manipulator: Callable[[], Manipulator],
    recorder: Any | None = None,
    get_state: Callable[[], State] | None = None,
) -> PathServices:
    """Create ``~/check_path``, the ``motion.current_pose_topic`` parameter and its
    subscription (and, with ``get_state``, ``~/axis_limits``) on ``node``; see
    :class:`PathServices`."""
    return PathServices(node, get_manipulator, recorder, get_state)
