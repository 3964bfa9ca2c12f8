"""ROS 2 node ``hexapod_workspace`` (executable ``workspace_node``).

A machining-cell controller calls it to get orientation workspaces and to validate commanded
tool orientations before it executes them. The node only wires ROS to the ROS-free core:

Parameters
    The manipulator model (``frame_id``, ``geometry.*``, ``limits.*``, ``pose.position``, the
    names of :meth:`hexapod_workspace.Manipulator.to_parameters`; defaults: the packaged example
    GPM), ``resolution.*``, ``check.max_poses`` and ``recording.*``. An update is validated as a
    whole (the would-be full set builds a :class:`~hexapod_workspace.Manipulator`); an invalid
    one is refused with its reason and the node keeps its previous model.
Services
    ``~/check_poses`` (hexapod_workspace_msgs/srv/CheckPoses), ``~/compute_workspace``
    (hexapod_workspace_msgs/srv/ComputeWorkspace), ``~/compute_orientation_workspace`` and
    ``~/compute_projected_workspace`` (std_srvs/srv/Trigger, at ``pose.position``).
Topics
    Subscribes ``~/workspace_request`` (WorkspaceRequest) and ``~/commanded_pose``
    (CommandedPose). Publishes, transient local, ``~/orientation_workspace`` and
    ``~/projected_workspace`` (sensor_msgs/msg/PointCloud2, float32 x, y, z, phi, theta, psi;
    orientation: x, y, z = θ cos φ, θ sin φ, ψ; projected: the unit approach vector),
    ``~/workspace_summary`` (WorkspaceSummary) and ``~/reachability`` (ReachabilityResult).

Workspace requests are served in their own mutually exclusive callback group, pose checks in a
reentrant one, under a multi-threaded executor; the computation itself runs in a worker process
(:mod:`hexapod_workspace.ros.worker`), so a long 3-D computation neither blocks nor slows the
pose checks (it does not hold this interpreter's lock).
Every request and result is recorded to one MCAP log per run (rosbag2 form), see
:mod:`hexapod_workspace.logs`; a failure to write turns recording off, the node keeps
serving. Units: SI (m, rad), positions in the base frame ``frame_id``.
"""

from __future__ import annotations

import collections
import contextlib
import math
import os
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import rclpy
from hexapod_workspace_msgs.msg import (
    CommandedPose,
    ReachabilityResult,
    WorkspaceRequest,
    WorkspaceSummary,
)
from hexapod_workspace_msgs.srv import CheckPoses, ComputeWorkspace
from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    SetParametersResult,
)
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.exceptions import ParameterException
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.logging import get_logger
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import serialize_message
from sensor_msgs.msg import PointCloud2
from std_srvs.srv import Trigger

from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core import resolution
from hexapod_workspace.core.constraints import check
from hexapod_workspace.core.manipulator import Manipulator
from hexapod_workspace.core.resolution import WorkspaceKind
from hexapod_workspace.errors import (
    ConfigError,
    InputError,
    RecordingError,
    UnreachableReferenceError,
)
from hexapod_workspace.logs import (
    REQUEST_QOS,
    SERVICE_QOS,
    LogWriter,
    messages,
    qos_profile_text,
    run_log_path,
    service_topics,
)

from .conversions import angles_from_orientations, position_from_point, to_message, type_name
from .paths import attach as attach_paths
from .paths import check_poses_from_poses, commanded_target
from .worker import WorkspaceJob, WorkspaceWorker

__all__ = ["NODE_NAME", "WorkspaceNode", "main"]

NODE_NAME = "hexapod_workspace"
#: Parameter ranges: the core's resolution bounds (one definition, core/resolution.py).
RAYS_RANGE = (resolution.MIN_RAYS, resolution.MAX_RAYS)
PSI_STEP_RANGE = (resolution.MIN_PSI_STEP, resolution.MAX_PSI_STEP)
TOLERANCE_RANGE = (resolution.MIN_TOLERANCE, resolution.MAX_TOLERANCE)
PROJECTED_METHODS = tuple(method.value for method in resolution.Method)
#: GIL switch interval of the node process, s: a pose check waits at most this long for the
#: interpreter while a workspace computation runs in another thread (Python's default is 5 ms).
SWITCH_INTERVAL = 2e-4
#: Seconds between two writes of the queued messages to the MCAP log (a message reaches the file
#: within about this plus the writer's flush interval).
RECORD_PERIOD = 0.2

_MODEL_DESCRIPTIONS = {
    "frame_id": "Base frame: frame_id of every published cloud and result header.",
    "geometry.base_joints": (
        "a_1..a_6 = OA_i: base (universal) joint centres, base frame, m; 18 floats (x y z)."
    ),
    "geometry.platform_joints": (
        "b_1..b_6 = CB'_i: platform (spherical) joint centres, mobile frame (origin at the tool "
        "tip C, z' along the tool), m; 18 floats (x' y' z')."
    ),
    "geometry.home_position": (
        "Home position OC, base frame, m (3 floats); default joint axes = leg directions there."
    ),
    "geometry.base_joint_axes": (
        "Axes of symmetry of the base joints, base frame, pointing into the legs: 18 floats, or "
        "empty/unset = leg directions at the home pose."
    ),
    "geometry.platform_joint_axes": (
        "Axes of symmetry of the platform joints, mobile frame, pointing into the legs: 18 "
        "floats, or empty/unset = reversed leg directions at the home pose."
    ),
    "limits.leg_length_min": "Minimum leg length |A_iB_i|, m: 1 value (all legs) or 6.",
    "limits.leg_length_max": "Maximum leg length |A_iB_i|, m: 1 value (all legs) or 6.",
    "limits.base_joint_max_angle": (
        "Maximum angle between a base joint axis and its leg, rad, in (0, pi): 1 or 6 values."
    ),
    "limits.platform_joint_max_angle": (
        "Maximum angle between a platform joint axis and its leg, rad, in (0, pi): 1 or 6 values."
    ),
    "limits.leg_diameter": (
        "Leg diameter D, m: legs (segments A_iB_i) must stay D apart; 0 disables the check."
    ),
    "pose.position": (
        "Default tool-tip position OC, base frame, m (3 floats): used by the Trigger services."
    ),
}


@dataclass(frozen=True)
class _Spec:
    """Declaration of one parameter."""

    name: str
    default: Any
    description: str
    read_only: bool = False
    dynamic_typing: bool = False
    float_range: tuple[float, float] | None = None
    int_range: tuple[int, int] | None = None
    constraints: str = ""

    def descriptor(self) -> ParameterDescriptor:
        descriptor = ParameterDescriptor(
            name=self.name,
            description=self.description,
            read_only=self.read_only,
            dynamic_typing=self.dynamic_typing,
            additional_constraints=self.constraints,
        )
        if not self.dynamic_typing:
            descriptor.type = Parameter.Type.from_parameter_value(self.default).value
        if self.float_range is not None:
            low, high = self.float_range
            descriptor.floating_point_range = [
                FloatingPointRange(from_value=low, to_value=high, step=0.0)
            ]
        if self.int_range is not None:
            low, high = self.int_range
            descriptor.integer_range = [IntegerRange(from_value=low, to_value=high, step=1)]
        return descriptor


def _parameter_specs() -> list[_Spec]:
    """Every parameter of the node, defaults from the packaged example manipulator."""
    example = Manipulator.from_params_file(example_config_path(), warn=False).to_parameters()
    specs = []
    for name, default in example.items():
        axes = name in ("geometry.base_joint_axes", "geometry.platform_joint_axes")
        specs.append(
            _Spec(
                name,
                [] if axes else default,
                _MODEL_DESCRIPTIONS[name],
                read_only=name == "frame_id",
                # an empty YAML list arrives as an unset parameter: allow unset and any type,
                # the model validation refuses non-numbers
                dynamic_typing=axes,
                float_range=(0.0, 10.0) if name == "limits.leg_diameter" else None,
            )
        )
    specs += [
        _Spec(
            "resolution.n_phi",
            resolution.DEFAULT_N_PHI,
            "Projected workspace: number of equally spaced azimuths phi (rays).",
            int_range=RAYS_RANGE,
        ),
        _Spec(
            "resolution.n_rays",
            resolution.DEFAULT_N_RAYS,
            "Orientation workspace: rays per psi slice.",
            int_range=RAYS_RANGE,
        ),
        _Spec(
            "resolution.psi_step",
            resolution.DEFAULT_PSI_STEP,
            "Orientation workspace: torsion step between slices, rad.",
            float_range=PSI_STEP_RANGE,
        ),
        _Spec(
            "resolution.tolerance",
            resolution.DEFAULT_TOLERANCE,
            "Boundary tolerance of every workspace computation, rad.",
            float_range=TOLERANCE_RANGE,
        ),
        _Spec(
            "resolution.projected_method",
            resolution.Method.TORSION_ZERO.value,
            "Method of ~/compute_projected_workspace: torsion_zero (psi = 0, the paper's) or "
            "exact (true shadow over all psi).",
            constraints="one of: torsion_zero, exact",
        ),
        _Spec(
            "check.max_poses",
            100_000,
            "Largest number of orientations accepted in one check_poses request.",
            read_only=True,
            int_range=(1, 10_000_000),
        ),
        _Spec(
            "recording.enabled",
            True,
            "Record every request and result to an MCAP log (rosbag2 form); false stops.",
        ),
        _Spec(
            "recording.directory",
            "",
            "Folder of the MCAP logs (one per run, named by start time); empty = "
            "$ROS_HOME/hexapod_workspace/logs (ROS_HOME defaults to ~/.ros).",
            read_only=True,
        ),
    ]
    return specs


@dataclass(frozen=True)
class _Settings:
    """Node settings that are not part of the manipulator model."""

    n_phi: int
    n_rays: int
    psi_step: float
    tolerance: float
    projected_method: str
    max_poses: int
    recording_enabled: bool
    recording_directory: Path


@dataclass(frozen=True)
class _State:
    """What the callbacks read: swapped as a whole when parameters change."""

    manipulator: Manipulator
    settings: _Settings


def _plain(value: Any) -> Any:
    """A parameter value as the model wants it (unset/empty arrays as empty lists)."""
    if value is None:
        return []
    if isinstance(value, (str, bool, int, float)):
        return value
    return list(value)


def _state_from(values: dict[str, Any], model_names: list[str]) -> _State:
    """Build (and so validate) the node state from a full set of parameter values.

    Raises
    ------
    ConfigError
        Invalid model or settings; the message names the parameter.
    """
    manipulator = Manipulator.from_mapping(
        {name: _plain(values[name]) for name in model_names}, warn=False
    )
    method = str(values["resolution.projected_method"])
    if method not in PROJECTED_METHODS:
        msg = (
            f"resolution.projected_method: expected one of {', '.join(PROJECTED_METHODS)}, "
            f"got {method!r}"
        )
        raise ConfigError(msg)
    directory = str(values["recording.directory"]).strip()
    if directory:
        folder = Path(directory).expanduser()
    else:
        ros_home = os.environ.get("ROS_HOME") or str(Path("~/.ros").expanduser())
        folder = Path(ros_home) / "hexapod_workspace" / "logs"
    settings = _Settings(
        n_phi=int(values["resolution.n_phi"]),
        n_rays=int(values["resolution.n_rays"]),
        psi_step=float(values["resolution.psi_step"]),
        tolerance=float(values["resolution.tolerance"]),
        projected_method=method,
        max_poses=int(values["check.max_poses"]),
        recording_enabled=bool(values["recording.enabled"]),
        recording_directory=folder,
    )
    return _State(manipulator, settings)


class _Recorder:
    """The node's MCAP log: thread-safe, turns itself off on the first write failure.

    A callback only serialises the message and appends it to a queue (microseconds); a thread
    of the recorder writes the queue to the log every :data:`RECORD_PERIOD` seconds, so that no
    request waits for the log writer (nor shares the interpreter with it while it is answered).
    """

    def __init__(self, node: Node) -> None:
        self._logger = node.get_logger()
        self._lock = threading.Lock()
        self._writer: LogWriter | None = None
        self._channels: dict[str, tuple[str, str]] = {}
        self._queue: collections.deque[tuple[str, bytes, int]] = collections.deque()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def add_channel(self, topic: str, msgtype: str, qos: str) -> None:
        """Declare a topic recorded in every log (registered when a log opens)."""
        self._channels[topic] = (msgtype, qos)

    def open(self, directory: Path) -> None:
        """Start a new log in ``directory`` (named by the start time); no-op when open."""
        with self._lock:
            if self._writer is not None:
                return
            try:
                writer = LogWriter(run_log_path(directory), on_error=self._failed)
                for topic, (msgtype, qos) in self._channels.items():
                    writer.add_channel(topic, msgtype, qos)
            except (RecordingError, OSError) as error:
                self._logger.error(f"recording off: {error}")
                return
            self._writer = writer
            if self._thread is None:
                self._thread = threading.Thread(
                    target=self._run, name="hexapod_workspace_recorder", daemon=True
                )
                self._thread.start()
        self._logger.info(f"recording to {writer.path}")

    def write(self, topic: str, message: Any) -> None:
        """Queue one rclpy message (serialised to CDR now) for ``topic`` when recording."""
        if self._writer is not None:
            self._queue.append((topic, serialize_message(message), time.time_ns()))

    def _run(self) -> None:
        while not self._stop.wait(RECORD_PERIOD):
            with self._lock:
                self._drain_locked()

    def _drain_locked(self) -> None:
        """Write the queued messages (under ``self._lock``)."""
        writer = self._writer
        while self._queue:
            topic, data, stamp_ns = self._queue.popleft()
            if writer is None:
                continue
            try:
                writer.write(topic, data, log_time_ns=stamp_ns)
            except (RecordingError, OSError) as error:
                self._logger.error(f"recording off after a write failure: {error}")
                self._writer = None
                with contextlib.suppress(RecordingError, OSError):
                    writer.close()
                writer = None

    def _failed(self, error: Exception) -> None:
        """A background flush of the writer failed: recording off."""
        writer, self._writer = self._writer, None
        if writer is not None:
            self._logger.error(f"recording off after a write failure: {error}")
            with contextlib.suppress(RecordingError, OSError):
                writer.close()

    def close(self) -> None:
        """Write what is queued and finish the log (idempotent); recording can reopen."""
        with self._lock:
            self._drain_locked()
            writer, self._writer = self._writer, None
            if writer is not None:
                try:
                    writer.close()
                except (RecordingError, OSError) as error:
                    self._logger.error(f"could not finish the log {writer.path}: {error}")

    def shutdown(self) -> None:
        """:meth:`close` and stop the recorder thread."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=10.0)
        self.close()


def _result_qos(depth: int = 1) -> QoSProfile:
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


class WorkspaceNode(Node):
    """The ``hexapod_workspace`` node: parameters, services, topics (see the module docstring).

    Raises
    ------
    ConfigError
        At construction, when the parameters (file or overrides) do not describe a valid
        manipulator; rclpy's ``InvalidParameterTypeException`` when a value has the wrong type
        (e.g. an integer where a float is expected).
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(NODE_NAME, **kwargs)
        self._recorder = _Recorder(self)
        self._worker = WorkspaceWorker()
        self._service_topics: dict[Any, tuple[str, str]] = {}
        specs = _parameter_specs()
        self._parameter_names = [spec.name for spec in specs]
        self._model_names = [s.name for s in specs if s.name in _MODEL_DESCRIPTIONS]
        for spec in specs:
            self.declare_parameter(spec.name, spec.default, spec.descriptor())
        # ~/check_path, Pose inputs and the current-pose parameter (hexapod_workspace.ros.paths)
        self._paths = attach_paths(self, lambda: self._state.manipulator, self._recorder)
        self._parameter_names += self._paths.parameter_names
        self._warn_unknown_overrides()
        self._state = _state_from(self._parameter_values(), self._model_names)
        self._warn_home_pose()
        self.add_on_set_parameters_callback(self._validate_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)

        workspace_group = MutuallyExclusiveCallbackGroup()
        check_group = ReentrantCallbackGroup()

        self._cloud_publishers = {
            WorkspaceKind.ORIENTATION: self._publisher(PointCloud2, "~/orientation_workspace"),
            WorkspaceKind.PROJECTED_TORSION_ZERO: self._publisher(
                PointCloud2, "~/projected_workspace"
            ),
        }
        self._cloud_publishers[WorkspaceKind.PROJECTED_EXACT] = self._cloud_publishers[
            WorkspaceKind.PROJECTED_TORSION_ZERO
        ]
        self._summary_publisher = self._publisher(WorkspaceSummary, "~/workspace_summary")
        self._reachability_publisher = self._publisher(
            ReachabilityResult, "~/reachability", depth=10
        )

        self._check_service = self._service(
            CheckPoses, "~/check_poses", self._on_check_poses, check_group
        )
        self._compute_service = self._service(
            ComputeWorkspace, "~/compute_workspace", self._on_compute_workspace, workspace_group
        )
        self._orientation_service = self._service(
            Trigger,
            "~/compute_orientation_workspace",
            self._on_compute_orientation,
            workspace_group,
        )
        self._projected_service = self._service(
            Trigger, "~/compute_projected_workspace", self._on_compute_projected, workspace_group
        )
        self._commanded_subscription = self._subscription(
            CommandedPose, "~/commanded_pose", self._on_commanded_pose, check_group
        )
        self._request_subscription = self._subscription(
            WorkspaceRequest, "~/workspace_request", self._on_workspace_request, workspace_group
        )
        if self._state.settings.recording_enabled:
            self._recorder.open(self._state.settings.recording_directory)
        self._worker.start()
        self.get_logger().info(
            f"ready: {self.get_fully_qualified_name()} serving check_poses, compute_workspace, "
            f"compute_orientation_workspace, compute_projected_workspace"
        )

    # ------------------------------------------------------------------ wiring helpers
    def _publisher(self, message_class: type, topic: str, depth: int = 1) -> Any:
        publisher = self.create_publisher(message_class, topic, _result_qos(depth))
        qos = qos_profile_text(durability="transient_local", depth=depth)
        self._recorder.add_channel(publisher.topic_name, type_name(message_class), qos)
        return publisher

    def _service(self, service_class: type, name: str, callback: Any, group: Any) -> Any:
        service = self.create_service(service_class, name, callback, callback_group=group)
        # recorded as <resolved service name>/request and /response
        request_topic, response_topic = service_topics(self.resolve_service_name(name))
        self._service_topics[service] = (request_topic, response_topic)
        self._recorder.add_channel(request_topic, type_name(service_class.Request), SERVICE_QOS)
        self._recorder.add_channel(response_topic, type_name(service_class.Response), SERVICE_QOS)
        return service

    def _subscription(self, message_class: type, topic: str, callback: Any, group: Any) -> Any:
        subscription = self.create_subscription(
            message_class, topic, callback, 10, callback_group=group
        )
        self._recorder.add_channel(subscription.topic_name, type_name(message_class), REQUEST_QOS)
        return subscription

    def _publish(self, publisher: Any, message: Any) -> None:
        publisher.publish(message)
        self._recorder.write(publisher.topic_name, message)

    def _now_ns(self) -> int:
        return self.get_clock().now().nanoseconds

    # ------------------------------------------------------------------ parameters
    def _parameter_values(self) -> dict[str, Any]:
        return {name: self.get_parameter(name).value for name in self._parameter_names}

    def _warn_unknown_overrides(self) -> None:
        overrides = getattr(self, "_parameter_overrides", {})
        unknown = sorted(
            name
            for name in overrides
            if name not in self._parameter_names and name != "use_sim_time"
        )
        if unknown:
            self.get_logger().warning(f"ignoring unknown parameters: {', '.join(unknown)}")

    def _warn_home_pose(self) -> None:
        problems = self._state.manipulator.home_pose_violations()
        if problems:
            self.get_logger().warning(
                f"the home pose (geometry.home_position, identity orientation) is unreachable: "
                f"{', '.join(problems)} violated"
            )

    def _validate_parameters(self, parameters: list[Parameter]) -> SetParametersResult:
        """Accept an update only when the would-be full parameter set is valid."""
        unset = [p.name for p in parameters if p.type_ == Parameter.Type.NOT_SET]
        if unset:
            reason = f"{unset[0]}: parameters of this node cannot be unset (deleted)"
            return SetParametersResult(successful=False, reason=reason)
        values = self._parameter_values()
        values.update({parameter.name: parameter.value for parameter in parameters})
        try:
            _state_from(values, self._model_names)
        except (ConfigError, InputError) as error:
            return SetParametersResult(successful=False, reason=str(error))
        except Exception as error:  # never let a bad value take the parameter service down
            return SetParametersResult(successful=False, reason=f"invalid parameters: {error}")
        return SetParametersResult(successful=True)

    def _apply_parameters(self, parameters: list[Parameter]) -> None:
        """Swap in the new model and settings after an accepted update."""
        previous, state = self._state, _state_from(self._parameter_values(), self._model_names)
        self._state = state
        names = ", ".join(parameter.name for parameter in parameters)
        self.get_logger().info(f"parameters updated: {names}")
        if state.manipulator != previous.manipulator:
            self._warn_home_pose()
        if state.settings.recording_enabled:
            self._recorder.open(state.settings.recording_directory)
        else:
            self._recorder.close()

    # ------------------------------------------------------------------ pose checks
    def _check_response(self, state: _State, request: CheckPoses.Request) -> dict[str, Any]:
        if len(request.poses):  # geometry_msgs/Pose form
            return check_poses_from_poses(state.manipulator, request, state.settings.max_poses)
        count = len(request.orientations)
        if count == 0:
            reason = "orientations: expected at least one pose, got none"
            return messages.check_poses_response_fields(None, success=False, message=reason)
        if count > state.settings.max_poses:
            reason = (
                f"orientations: at most {state.settings.max_poses} poses per request "
                f"(check.max_poses), got {count}"
            )
            return messages.check_poses_response_fields(None, success=False, message=reason)
        try:
            result = check(
                state.manipulator,
                angles_from_orientations(request.orientations),
                position_from_point(request.position),
            )
        except InputError as error:
            return messages.check_poses_response_fields(None, success=False, message=str(error))
        return messages.check_poses_response_fields(result)

    def _on_check_poses(
        self, request: CheckPoses.Request, response: CheckPoses.Response
    ) -> CheckPoses.Response:
        request_topic, response_topic = self._service_topics[self._check_service]
        self._recorder.write(request_topic, request)
        try:
            response = to_message(CheckPoses.Response, self._check_response(self._state, request))
        except Exception as error:
            response = CheckPoses.Response(success=False, message=self._internal_error(error))
        self._recorder.write(response_topic, response)
        return response

    def _on_commanded_pose(self, command: CommandedPose) -> None:
        self._recorder.write(self._commanded_subscription.topic_name, command)
        state = self._state
        try:
            position, angles = commanded_target(command)  # T&T or geometry_msgs/Pose
        except InputError:
            position, angles = np.full(3, np.nan), np.full((1, 3), np.nan)
        common = {
            "position": position,
            "angles": angles[0],
            "stamp_ns": self._now_ns(),
            "frame_id": state.manipulator.frame_id,
            "request_id": command.request_id,
        }
        try:
            result = check(state.manipulator, angles, position)
            fields = messages.reachability_result_fields(result, **common)
            fields = self._paths.with_motion(fields, state.manipulator, position, angles)
        except InputError as error:
            fields = messages.reachability_result_fields(None, message=str(error), **common)
        except Exception as error:
            fields = messages.reachability_result_fields(
                None, message=self._internal_error(error), **common
            )
        self._publish(self._reachability_publisher, to_message(ReachabilityResult, fields))

    # ------------------------------------------------------------------ workspaces
    def _compute(
        self,
        kind: int,
        position: np.ndarray,
        *,
        n_rays: int = 0,
        psi_step: float = 0.0,
        tolerance: float = 0.0,
        request_id: str = "",
    ) -> tuple[WorkspaceSummary, PointCloud2]:
        """Compute one workspace, publish its summary (and cloud) and return both messages.

        Zero resolution values mean the node's parameters. Failures (bad request, unreachable
        reference orientation) give a summary with ``success`` false and the reason.
        """
        state = self._state
        settings = state.settings
        frame_id = state.manipulator.frame_id
        stamp_ns = self._now_ns()
        failure = {
            "stamp_ns": stamp_ns,
            "frame_id": frame_id,
            "request_id": request_id,
            "kind": kind,
            "position": np.nan_to_num(position),
        }
        if WorkspaceKind.of(kind) is None:
            reason = f"kind: expected 0 (orientation), 1 (torsion_zero) or 2 (exact), got {kind}"
            return self._publish_failure(reason, failure)
        if not np.all(np.isfinite(position)):
            reason = f"position: expected finite values, got {position.tolist()}"
            return self._publish_failure(reason, failure)
        for name, value in (("psi_step", psi_step), ("tolerance", tolerance)):
            if not math.isfinite(value) or value < 0.0:
                reason = f"{name}: expected a finite value >= 0 (0 = node parameter), got {value}"
                return self._publish_failure(reason, failure)
        rays = int(n_rays) or (
            settings.n_rays if kind == WorkspaceKind.ORIENTATION else settings.n_phi
        )
        tolerance = float(tolerance) or settings.tolerance
        psi_step = float(psi_step) or settings.psi_step
        if not RAYS_RANGE[0] <= rays <= RAYS_RANGE[1]:
            reason = f"n_rays: expected {RAYS_RANGE[0]}..{RAYS_RANGE[1]}, got {rays}"
            return self._publish_failure(reason, failure, n_rays=rays)
        job = WorkspaceJob(
            manipulator=state.manipulator,
            kind=kind,
            position=position,
            n_rays=rays,
            psi_step=psi_step,
            tolerance=tolerance,
            stamp_ns=stamp_ns,
            frame_id=frame_id,
            request_id=request_id,
        )
        try:
            summary_fields, cloud_fields = self._worker.compute(job)
        except UnreachableReferenceError as error:
            return self._publish_failure(
                str(error), failure, n_rays=rays, tolerance=tolerance, empty_cloud=True
            )
        except InputError as error:
            return self._publish_failure(str(error), failure, n_rays=rays, tolerance=tolerance)
        cloud = to_message(PointCloud2, cloud_fields)
        summary = to_message(WorkspaceSummary, summary_fields)
        self._publish(self._cloud_publishers[kind], cloud)
        self._publish(self._summary_publisher, summary)
        self.get_logger().info(summary.message)
        return summary, cloud

    def _publish_failure(
        self,
        reason: str,
        failure: dict[str, Any],
        *,
        n_rays: int = 0,
        tolerance: float = math.nan,
        empty_cloud: bool = False,
    ) -> tuple[WorkspaceSummary, PointCloud2]:
        """Publish (and return) the summary of a failed computation.

        ``empty_cloud``: the workspace is empty (unreachable reference): publish an empty cloud
        so that viewers do not keep showing a stale boundary.
        """
        fields = messages.summary_fields(
            None,
            message=reason,
            reference_reachable=not empty_cloud,
            n_rays=n_rays,
            tolerance=tolerance,
            **failure,
        )
        summary = to_message(WorkspaceSummary, fields)
        cloud = to_message(
            PointCloud2,
            messages.pointcloud_fields(
                np.zeros((0, 6)), frame_id=failure["frame_id"], stamp_ns=failure["stamp_ns"]
            ),
        )
        if empty_cloud and failure["kind"] in self._cloud_publishers:
            self._publish(self._cloud_publishers[failure["kind"]], cloud)
        self._publish(self._summary_publisher, summary)
        self.get_logger().warning(f"workspace request failed: {reason}")
        return summary, cloud

    def _compute_guarded(self, kind: int, position: np.ndarray, **options: Any) -> Any:
        """:meth:`_compute`, turning an unexpected error into a failed summary (never raises)."""
        try:
            return self._compute(kind, position, **options)
        except Exception as error:
            failure = {
                "stamp_ns": self._now_ns(),
                "frame_id": self._state.manipulator.frame_id,
                "request_id": options.get("request_id", ""),
                "kind": kind if WorkspaceKind.of(kind) is not None else WorkspaceKind.ORIENTATION,
                "position": np.nan_to_num(position),
            }
            return self._publish_failure(self._internal_error(error), failure)

    def _on_compute_workspace(
        self, request: ComputeWorkspace.Request, response: ComputeWorkspace.Response
    ) -> ComputeWorkspace.Response:
        request_topic, response_topic = self._service_topics[self._compute_service]
        self._recorder.write(request_topic, request)
        summary, cloud = self._workspace_from_request(request.request)
        response = ComputeWorkspace.Response(
            success=summary.success, message=summary.message, summary=summary, boundary=cloud
        )
        self._recorder.write(response_topic, response)
        return response

    def _on_workspace_request(self, request: WorkspaceRequest) -> None:
        self._recorder.write(self._request_subscription.topic_name, request)
        self._workspace_from_request(request)

    def _workspace_from_request(
        self, request: WorkspaceRequest
    ) -> tuple[WorkspaceSummary, PointCloud2]:
        return self._compute_guarded(
            int(request.kind),
            position_from_point(request.position),
            n_rays=int(request.n_rays),
            psi_step=float(request.psi_step),
            tolerance=float(request.tolerance),
            request_id=request.request_id,
        )

    def _on_trigger(self, service: Any, kind: int, response: Trigger.Response) -> Any:
        request_topic, response_topic = self._service_topics[service]
        self._recorder.write(request_topic, Trigger.Request())
        summary, _ = self._compute_guarded(kind, np.array(self._state.manipulator.position))
        response = Trigger.Response(success=summary.success, message=summary.message)
        self._recorder.write(response_topic, response)
        return response

    def _on_compute_orientation(
        self, request: Trigger.Request, response: Trigger.Response
    ) -> Trigger.Response:
        return self._on_trigger(self._orientation_service, WorkspaceKind.ORIENTATION, response)

    def _on_compute_projected(
        self, request: Trigger.Request, response: Trigger.Response
    ) -> Trigger.Response:
        method = self._state.settings.projected_method
        kind = WorkspaceKind.projected(method)
        return self._on_trigger(self._projected_service, kind, response)

    # ------------------------------------------------------------------ lifecycle
    def _internal_error(self, error: Exception) -> str:
        self.get_logger().error(f"internal error: {error!r}")
        return f"internal error: {type(error).__name__}: {error}"

    def stop_worker(self) -> None:
        """Terminate the workspace worker process (a running computation fails at once)."""
        self._worker.close()

    def destroy_node(self) -> None:
        """Stop the workspace worker, finish the MCAP log, then destroy the node."""
        self._worker.close()
        self._recorder.shutdown()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run the node until SIGINT/SIGTERM or an external shutdown (``ros2 run`` entry point).

    Returns
    -------
    int
        Process exit status: 0 after a clean shutdown, 1 when the parameters are invalid.
    """
    sys.setswitchinterval(SWITCH_INTERVAL)
    rclpy.init(args=args)
    node = None
    executor = None
    status = 0
    try:
        node = WorkspaceNode()
        executor = MultiThreadedExecutor(num_threads=4)
        executor.add_node(node)
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except (ConfigError, ParameterException) as error:
        get_logger(NODE_NAME).fatal(f"invalid parameters: {error}")
        status = 1
    except Exception:
        # A signal shuts the context down from under the executor; rclpy then sometimes raises
        # RCLError ("context is not valid") instead of ExternalShutdownException.
        if rclpy.ok():
            raise
    finally:
        if node is not None:
            node.stop_worker()  # ends a running computation, which frees its executor thread
        if executor is not None:
            executor.shutdown(timeout_sec=10.0)  # joins the executor's threads
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return status


if __name__ == "__main__":
    sys.exit(main())
