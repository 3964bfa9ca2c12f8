"""ROS 2 node ``hexapod_workspace`` (executable ``workspace_node``): wiring and callbacks.

A machining-cell controller calls it to get orientation workspaces and to validate commanded
tool orientations before it executes them. The node only wires ROS to the ROS-free core:

Parameters
    :mod:`hexapod_workspace.ros.parameters` (the manipulator model, ``resolution.*``,
    ``check.*``, ``recording.*``). An update is validated as a whole; a refusal names the
    parameter and the value, and the node keeps its previous model.
Action
    ``~/compute_workspace`` (hexapod_workspace_msgs/action/ComputeWorkspace): feedback
    ``progress`` (0..1, non-decreasing) and ``stage`` (queued, computing, publishing); cancel
    stops the computation within 0.5 s. Goals are always accepted and queue first-in first-out
    with the other workspace requests (one computation at a time); an invalid goal is aborted
    with the reason in ``result.message``.
Services
    ``~/check_poses`` (hexapod_workspace_msgs/srv/CheckPoses); ``~/compute_orientation_workspace``
    and ``~/compute_projected_workspace`` (std_srvs/srv/Trigger, at ``pose.position``).
Topics
    Subscribes ``~/workspace_request`` (WorkspaceRequest) and ``~/commanded_pose``
    (CommandedPose), both reliable KEEP_ALL: a command is never dropped by the node; a
    publisher that wants the same must be reliable with KEEP_ALL (or a depth that covers its
    bursts), and is then slowed down by DDS flow control when the node cannot keep up. Every
    CommandedPose gets exactly one ``~/reachability`` (ReachabilityResult); one that waited
    longer than ``check.max_command_age`` is answered ``success`` false, "overloaded".
    Publishes, transient local, ``~/orientation_workspace`` and ``~/projected_workspace``
    (sensor_msgs/msg/PointCloud2, float32 x, y, z, phi, theta, psi; sent by the worker
    process's node ``<node>_clouds``, :mod:`~hexapod_workspace.ros.clouds`), ``~/workspace_summary``
    (WorkspaceSummary), ``~/reachability`` (depth 1000); ``/diagnostics``
    (diagnostic_msgs/DiagnosticArray, 1 Hz).
Machining cell
    Tool and work frames (``tool.*``, ``tools.T<n>.*``, ``work.*``), poses in the work frame,
    feeds on ``~/check_path`` and ``~/axis_limits``: :mod:`~hexapod_workspace.ros.cell`.

Lifecycle
    A managed node (``lifecycle_msgs`` services ``~/change_state``, ``~/get_state``, ...):
    :mod:`~hexapod_workspace.ros.lifecycle` says what configure, activate, deactivate, cleanup
    and shutdown do; while not active every command is answered ``success`` false, "inactive".
    ``autostart`` (default) configures and activates at start.
Services (flat)
    ``~/check_poses_flat`` (CheckPosesFlat): the batch check in flat arrays
    (:mod:`~hexapod_workspace.ros.flat`).

Threads: the executor (single-threaded: every callback is short), the job queue
(:mod:`~hexapod_workspace.ros.jobs`; the computation runs in a worker process, so it does not
hold this interpreter), the recorder (:mod:`~hexapod_workspace.ros.recorder`, the only owner of
the MCAP log). Units: SI (m, rad), positions of the tool centre point in the base frame
``frame_id`` (requests may give the work frame).

Extensions (other services, actions) attach with one call each: :data:`EXTENSIONS` holds
functions ``attach(node)`` that :func:`main` passes to the node; they use the node's
:attr:`~WorkspaceNode.recorder`, :attr:`~WorkspaceNode.check_group`,
:attr:`~WorkspaceNode.job_group`, :attr:`~WorkspaceNode.jobs` and the recorded-wiring helpers
(:meth:`~WorkspaceNode.recorded_service`, :meth:`~WorkspaceNode.recorded_publisher`,
:meth:`~WorkspaceNode.recorded_subscription`).
"""

from __future__ import annotations

import inspect
import sys
import threading
import time
from collections.abc import Callable, Iterable
from typing import Any

import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from hexapod_workspace_msgs.msg import (
    CommandedPose,
    ReachabilityResult,
)
from hexapod_workspace_msgs.srv import CheckPoses
from rcl_interfaces.msg import SetParametersResult
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.exceptions import ParameterException
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.lifecycle import LifecycleNode
from rclpy.logging import get_logger
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import serialize_message

from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core import kernels
from hexapod_workspace.core.base import params
from hexapod_workspace.core.base.params import NODE_PARAMETERS, ROS_PARAMETERS, unknown_parameter
from hexapod_workspace.core.evaluation.check import check
from hexapod_workspace.core.kernels import planner as planner_kernels
from hexapod_workspace.core.model.manipulator import Manipulator
from hexapod_workspace.errors import ConfigError, InputError
from hexapod_workspace.logs import (
    REQUEST_QOS,
    SERVICE_QOS,
    messages,
    qos_profile_text,
    recorded_type,
    service_topics,
)
from hexapod_workspace.logs.interfaces import relative_name

from . import cell, health
from .commands import CommandStream
from .conversions import (
    angles_from_orientations,
    position_from_point,
    to_message,
    type_name,
)
from .flat import attach as attach_flat
from .lifecycle import ManagedTransitions, autostart_from_argv
from .load_rows import check_poses_with_loads, load_rows_of, require_geometric
from .loads import attach_loads
from .parameters import (
    MODEL_GROUPS,
    State,
    command_line_override_names,
    dynamic_specs,
    missing_model_parameters,
    model_default,
    model_given,
    parameter_specs,
    refusal,
    state_from,
)
from .paths import attach as attach_paths
from .paths import check_poses_from_poses
from .qos import COMMAND_QOS, SERVICE_QOS_PROFILE
from .recorder import Recorder
from .schedule import attach_schedule
from .scheduling import (
    realtime_priority_from_argv,
    set_realtime,
    set_worker_policy,
    worker_policy_from_argv,
)
from .worker import WorkspaceWorker
from .workspaces import WorkspaceServer

__all__ = ["EXTENSIONS", "NODE_NAME", "WorkspaceNode", "main", "warm_up_kernels"]

NODE_NAME = params.NODE_NAME  # one definition, read by the CLI's parameters files too


def _attach_atlas(node: WorkspaceNode) -> object:
    """``~/compute_atlas`` (hexapod_workspace.ros.atlas_action; goals refused with the install
    hint when the ``atlas`` extra is missing)."""
    from .atlas_action import attach_atlas_action

    return attach_atlas_action(
        node,
        lambda: require_geometric(node.configured_state, "the atlas"),
        recorder=node.recorder,
    )


def _attach_markers(node: WorkspaceNode) -> object:
    """``~/markers`` (hexapod_workspace.ros.markers: the scene for RViz and Foxglove)."""
    from .markers import attach

    return attach(node)


#: Functions ``attach(node)`` run by :func:`main` after the node is built (one per extension).
EXTENSIONS: list[Callable[[WorkspaceNode], object]] = [_attach_atlas, _attach_markers]
#: ~/reachability keeps 1000 results (1 s at 1 kHz) for a reliable reader that lags.
REACHABILITY_DEPTH = 1000
#: GIL switch interval of the node process, s: a callback waits at most about this long for the
#: interpreter while the recorder or job thread runs (Python's default is 5 ms).
SWITCH_INTERVAL = 2e-4


def _name(key: str) -> str:
    """The node-relative name (``~/...``) of :data:`messages.TOPICS` entry ``key``, so that a
    remapped namespace moves every topic, service and action with the node."""
    return relative_name(key)


def _result_qos(depth: int = 1) -> QoSProfile:
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


def warm_up_kernels(
    *manipulators: Manipulator, checks_only: bool = False, report_singularity: bool = False
) -> float:
    """Compile (first run) or load the core's kernels, so that the first pose check and the
    first planned path are as fast as the others; returns the seconds taken. The kernels of
    each manipulator's variant (checked with and without the reported singularity margin); none
    given: every variant. ``checks_only``: only what a pose check of the manipulators as
    configured needs (``kernels.CHECKS``, with the singularity margin evaluated when
    ``report_singularity``: ``check.report_singularity``), which the node compiles before it
    answers."""
    started = time.perf_counter()
    if checks_only:
        models = [
            kernels.model_vector(manipulator, report_singularity=report_singularity)
            for manipulator in manipulators
        ]
        kernels.warm_up(*models, names=kernels.CHECKS)
        return time.perf_counter() - started
    models = [
        kernels.model_vector(manipulator, report_singularity=report)
        for manipulator in manipulators
        for report in (False, True)
    ]
    kernels.warm_up(*models)
    planner_kernels.warm_up()  # ~/check_path with free torsion
    return time.perf_counter() - started


class WorkspaceNode(ManagedTransitions, LifecycleNode):
    """The ``hexapod_workspace`` node (see the module docstring), a managed (lifecycle) node:
    :mod:`~hexapod_workspace.ros.lifecycle` says what each transition does.

    Parameters
    ----------
    extensions : iterable of callables, optional
        ``attach(node)`` for each extension, called once the node is wired.
    autostart : bool
        Configure and activate before returning (default), so the node serves at once;
        False leaves it unconfigured (every command answered "inactive").
    **kwargs
        Passed to :class:`rclpy.lifecycle.LifecycleNode` (``parameter_overrides``,
        ``context``, ...).

    Raises
    ------
    ConfigError
        A value has the wrong type; with ``autostart``, also when the parameters (file or
        overrides) do not describe a valid manipulator (the message names the parameter and
        the value).
    """

    def __init__(
        self,
        *,
        extensions: Iterable[Callable[[Any], object]] = (),
        override_names: Iterable[str] = (),
        autostart: bool = True,
        **kwargs: Any,
    ) -> None:
        super().__init__(NODE_NAME, **kwargs)
        given = [p.name for p in kwargs.get("parameter_overrides") or []]
        self._override_names = [*override_names, *given]
        self.stats = health.Counters()
        self.recorder = Recorder(self.get_logger())
        self._specs = parameter_specs()
        self.guard_change_state()
        #: the model and settings: built by configure (None while unconfigured)
        self.state: State | None = None
        try:
            self._declare_parameters()
        except Exception:
            self.recorder.shutdown()
            super().destroy_node()
            raise
        self.add_on_set_parameters_callback(self._validate_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)

        #: callback groups for extensions (the executor is single-threaded: every callback
        #: must be short; long work goes to :attr:`jobs` or a thread of the extension)
        self.check_group = ReentrantCallbackGroup()
        self.job_group = MutuallyExclusiveCallbackGroup()
        self.worker = WorkspaceWorker()
        self._reachability = self.recorded_publisher(
            ReachabilityResult, _name("reachability"), depth=REACHABILITY_DEPTH
        )
        self.recorded_service(
            CheckPoses, _name("check_poses"), self._on_check_poses, self.check_group
        )
        attach_flat(self, _name("check_poses_flat"))  # the flat form (ros/flat.py)
        self._commanded = self.recorded_subscription(
            CommandedPose,
            _name("commanded_pose"),
            lambda data: self._commands.on_command(data),
            raw=True,  # the stream records the bytes it takes (ros/commands.py)
        )
        self._commands = CommandStream(self, self._commanded, self._reachability)
        self.workspaces = WorkspaceServer(self, _name)
        #: the one job queue of workspace computations (extensions may submit to it)
        self.jobs = self.workspaces.jobs
        self._diagnostics = self.create_publisher(DiagnosticArray, "/diagnostics", 10)
        self.create_timer(1.0, self._publish_diagnostics)
        # ~/check_path, Pose inputs and the current-pose parameter (hexapod_workspace.ros.paths)
        self.paths = attach_paths(
            self,
            lambda: self.configured_state.manipulator,
            self.recorder,
            lambda: self.configured_state,
        )
        # ~/schedule_path (hexapod_workspace.ros.schedule)
        self.schedules = attach_schedule(self)
        # ~/loads (hexapod_workspace.ros.loads)
        self.loads = attach_loads(self)
        self.cell_status = cell.CellStatus(self)  # parameter changes: log and /diagnostics
        self._extensions = list(extensions)
        for attach in self._extensions:
            attach(self)
        if autostart:
            try:
                self.autostart()  # configure + activate (ros/lifecycle.py)
            except Exception:
                self.destroy_node()
                raise

    def interfaces_line(self) -> str:
        """What the active node serves and listens on, for its log."""
        atlas = ", compute_atlas (action)" if _attach_atlas in self._extensions else ""
        current = self.paths.subscription
        return (
            f"{self.get_fully_qualified_name()} serving check_poses, check_poses_flat, "
            f"check_path, schedule_path, loads, compute_workspace (action){atlas}, "
            "compute_orientation_workspace, compute_projected_workspace; listening on "
            "commanded_pose, workspace_request"
            + (f", {current.topic_name} (current pose)" if current is not None else "")
        )

    @property
    def configured_state(self) -> State:
        """:attr:`state`; ``InputError`` "inactive: ..." while the node is unconfigured."""
        if self.state is None:
            raise InputError(self.inactive_reason() or "inactive: the node is unconfigured")
        return self.state

    def warm_up(self) -> float:
        """Load (or compile) the pose-check kernels of the configured manipulator; seconds
        taken (configure calls it). The others (searches, the reported singularity margin,
        the torsion planner) are loaded or compiled after, in a thread of their own, while the
        node already answers: after a plain colcon build the cache is empty, and a first
        answer should not wait for every kernel."""
        manipulators = [self.state.manipulator] if self.state is not None else []
        report = self.state is not None and self.state.settings.report_singularity
        seconds = warm_up_kernels(*manipulators, checks_only=True, report_singularity=report)
        threading.Thread(
            target=warm_up_kernels, args=manipulators, name="kernel-warm-up", daemon=True
        ).start()
        return seconds

    # ------------------------------------------------------------------ wiring helpers
    def recorded_publisher(self, message_class: type, topic: str, depth: int = 1) -> Any:
        """A reliable, transient-local publisher whose messages :meth:`publish` records."""
        publisher = self.create_publisher(message_class, topic, _result_qos(depth))
        qos = qos_profile_text(durability="transient_local", depth=depth)
        self.recorder.add_channel(publisher.topic_name, type_name(message_class), qos)
        return publisher

    def record_service_channels(self, service_class: Any, name: str) -> tuple[str, str]:
        """Register ``<service>/request`` and ``/response`` in the logs; return both topics."""
        request_topic, response_topic = service_topics(self.resolve_service_name(name))
        for topic, part in (
            (request_topic, service_class.Request),
            (response_topic, service_class.Response),
        ):
            # recorded as the message twin of the service part (same CDR bytes)
            self.recorder.add_channel(topic, recorded_type(type_name(part)), SERVICE_QOS)
        return request_topic, response_topic

    def recorded_service(
        self, service_class: Any, name: str, callback: Callable, group: Any = None
    ) -> Any:
        """A service whose requests and responses are recorded (``<name>/request``,
        ``<name>/response``); ``callback(request, response)`` may be a coroutine. While the
        node is not active the callback is not called: the answer is ``success`` false with
        the "inactive: ..." reason in ``message``."""
        request_topic, response_topic = self.record_service_channels(service_class, name)

        inactive = _inactive_answer(service_class)

        async def recorded_async(request: Any, response: Any) -> Any:
            self.recorder.write(request_topic, request)
            reason = self.inactive_reason()
            answer = await callback(request, response) if reason is None else inactive(reason)
            self.recorder.write(response_topic, answer)
            return answer

        def recorded(request: Any, response: Any) -> Any:
            self.recorder.write(request_topic, request)
            reason = self.inactive_reason()
            answer = callback(request, response) if reason is None else inactive(reason)
            self.recorder.write(response_topic, answer)
            return answer

        handler = recorded_async if _is_coroutine(callback) else recorded
        return self.create_service(
            service_class, name, handler, qos_profile=SERVICE_QOS_PROFILE, callback_group=group
        )

    def recorded_subscription(
        self,
        message_class: type,
        topic: str,
        callback: Callable,
        group: Any = None,
        raw: bool = False,
    ) -> Any:
        """A reliable KEEP_ALL subscription; ``callback`` records what it takes itself (with
        ``raw``, it is given the CDR bytes: it records them as they are and deserialises
        once)."""
        subscription = self.create_subscription(
            message_class, topic, callback, COMMAND_QOS, callback_group=group, raw=raw
        )
        self.recorder.add_channel(subscription.topic_name, type_name(message_class), REQUEST_QOS)
        return subscription

    def publish(self, publisher: Any, message: Any) -> None:
        """Record and publish ``message`` (any thread). Recorded first: a SIGINT (rclpy raises
        KeyboardInterrupt in the main thread) between the two cannot leave a published message
        out of the log. While recording, the message is serialised once, here, and the same
        bytes are published and recorded (publishing a message serialises it anyway; the
        recorder thread would serialise it again, in this process)."""
        if not self.recorder.recording:
            publisher.publish(message)
            return
        data = serialize_message(message)
        self.recorder.write_serialized(publisher.topic_name, data)
        publisher.publish(data)

    def _now_ns(self) -> int:
        return self.get_clock().now().nanoseconds

    # ------------------------------------------------------------------ parameters
    def _declare_parameters(self) -> None:
        """Declare the table. Refused with a ConfigError naming the parameter: a name no part
        of the node declares (misspelt key or section), a model given in part, a wrong type.
        With no model parameter given the packaged example is the model, and the log says so."""
        names = set(self._override_names) | set(getattr(self, "_parameter_overrides", {}))
        self._specs.update(dynamic_specs(names))  # the tool table and collision.* given
        unknown = unknown_parameter(names, (*self._specs, *NODE_PARAMETERS, *ROS_PARAMETERS))
        if unknown is not None:
            raise ConfigError(f"unknown parameter given to the node: {unknown}")
        given = model_given(names)
        overrides = getattr(self, "_parameter_overrides", {})
        chosen = overrides.get("geometry.architecture")
        architecture = str(chosen.value) if chosen is not None else "ups"
        missing = missing_model_parameters(given, architecture) if given else None
        if missing is not None:
            raise ConfigError(missing)
        declared: dict[str, Any] = {}
        for name, spec in self._specs.items():
            default = spec.default
            if given and name.startswith(MODEL_GROUPS) and name not in given:
                default = model_default(name, declared)
            try:
                declared[name] = self.declare_parameter(name, default, spec.descriptor()).value
            except ParameterException as error:  # a wrong type in the file
                raise ConfigError(f"{name}: {error}") from error
        if not given:
            self.get_logger().info(
                "no model parameter (geometry.*, limits.*, pose.*) given: using the packaged "
                f"example {example_config_path()}"
            )

    def _parameter_values(self) -> dict[str, Any]:
        return {
            name: self.get_parameter(name).value
            for name in self._specs
            if self.has_parameter(name)  # a tool-table entry being declared
        }

    def set_parameters(self, parameter_list: list[Parameter]) -> list[SetParametersResult]:
        """As rclpy's, with refusals that name the parameter and the value."""
        return [self.set_parameters_atomically([parameter]) for parameter in parameter_list]

    def set_parameters_atomically(self, parameter_list: list[Parameter]) -> SetParametersResult:
        """As rclpy's, with refusals that name the parameter and the value (unknown names and
        wrong types included); a tool-table entry not declared yet is declared (after the whole
        set is validated). Every outcome is recorded
        (:class:`~hexapod_workspace.ros.cell.CellStatus`)."""
        result = self._set_parameters_checked(parameter_list)
        status = getattr(self, "cell_status", None)
        if status is not None:
            status.record(parameter_list, refused=None if result.successful else result.reason)
        return result

    def _set_parameters_checked(self, parameter_list: list[Parameter]) -> SetParametersResult:
        new_tools = cell.new_dynamic_parameters(self, parameter_list)
        if new_tools:  # a tool or obstacle added: checked as a whole set, then declared
            self._specs.update(new_tools)
            reason = next((r for p in parameter_list if (r := refusal(self._specs, p))), None)
            checked = (
                SetParametersResult(successful=False, reason=reason)
                if reason is not None
                else self._validate_parameters(parameter_list)
            )
            if not checked.successful:
                for name in new_tools:
                    del self._specs[name]
                return checked
            # declared one by one: rclpy's callbacks see each alone, so they stand aside (the
            # set was checked whole above) and the state is swapped once, with the rest
            self._declaring = True
            try:
                for name, spec in new_tools.items():
                    given = next((p for p in parameter_list if p.name == name), None)
                    value = given.value if given is not None else spec.default
                    self.declare_parameter(name, value, spec.descriptor())
            finally:
                self._declaring = False
            declared = [p for p in parameter_list if p.name in new_tools]
            parameter_list = [p for p in parameter_list if p.name not in new_tools]
            if not parameter_list:
                self._apply_parameters(declared)
                return SetParametersResult(successful=True)
        for parameter in parameter_list:
            if parameter.name not in self._specs and self.has_parameter(parameter.name):
                # an extension's or rclpy's own (use_sim_time, ...): rclpy checks the rest
                if self.describe_parameter(parameter.name).read_only:
                    reason = f"{parameter.name}: read-only, set at start only (value "
                    reason += f"{parameter.value!r} refused)"
                    return SetParametersResult(successful=False, reason=reason)
                continue
            refused = refusal(self._specs, parameter)
            if refused is not None:
                return SetParametersResult(successful=False, reason=refused)
        return super().set_parameters_atomically(parameter_list)

    def _validate_parameters(self, parameters: list[Parameter]) -> SetParametersResult:
        """Accept an update only when the would-be full parameter set is valid (while
        unconfigured, configure validates the whole set)."""
        if not self.configured or getattr(self, "_declaring", False):
            return SetParametersResult(successful=True)
        values = self._parameter_values()
        values.update({p.name: p.value for p in parameters if p.name in self._specs})
        try:
            state_from(values)
        except (ConfigError, InputError) as error:
            return SetParametersResult(successful=False, reason=str(error))
        except Exception as error:  # never let a bad value take the parameter service down
            return SetParametersResult(successful=False, reason=f"invalid parameters: {error}")
        return SetParametersResult(successful=True)

    def _apply_parameters(self, parameters: list[Parameter]) -> None:
        """Swap in the new model and settings after an accepted update (configured only)."""
        names = [p.name for p in parameters if p.name in self._specs]
        if not names or getattr(self, "_declaring", False):  # an extension's own; a new group
            return
        if self.state is None or not self.configured:
            self.get_logger().info(f"parameters set: {', '.join(names)}")
            return
        previous, state = self.state, state_from(self._parameter_values())
        self.state = state
        self.get_logger().info(f"parameters updated: {', '.join(names)}")
        if state.settings.recording_enabled != previous.settings.recording_enabled:
            if state.settings.recording_enabled:
                self.recorder.open(
                    state.settings.recording_directory, state.settings.recording_rotation
                )
            else:
                self.recorder.close()

    # ------------------------------------------------------------------ pose checks
    def _on_check_poses(
        self, request: CheckPoses.Request, response: CheckPoses.Response
    ) -> CheckPoses.Response:
        self.stats.check_calls += 1
        try:
            fields = self._check_fields(self.configured_state, request)
        except Exception as error:
            fields = messages.check_poses_response_fields(
                None, success=False, message=self.internal_error(error)
            )
        if not fields["success"]:
            self.stats.check_refused += 1
        return to_message(CheckPoses.Response, fields)

    @staticmethod
    def _check_fields(state: State, request: CheckPoses.Request) -> dict[str, Any]:
        fields = WorkspaceNode._check_verdicts(state, request)
        fields["frames"] = cell.frames_message(state, request.header.frame_id)
        return fields

    @staticmethod
    def _check_verdicts(state: State, request: CheckPoses.Request) -> dict[str, Any]:
        if len(request.poses):  # the geometry_msgs/Pose form (hexapod_workspace.ros.paths)
            return check_poses_from_poses(
                state.manipulator, request, state.settings.max_poses, state
            )
        count, limit = len(request.orientations), state.settings.max_poses
        reason = None
        if count == 0:
            reason = "orientations: expected at least one pose, got none"
        elif count > limit:
            reason = (
                f"orientations: at most {limit} poses per request (check.max_poses), got {count}"
            )
        if reason is None:
            try:
                angles, position = cell.angles_to_base(  # base or work frame (ros/cell.py)
                    state,
                    request.header.frame_id,
                    angles_from_orientations(request.orientations),
                    position_from_point(request.position),
                )
                result = check(
                    state.manipulator,
                    angles,
                    position,
                    singularity=state.settings.report_singularity,
                )
                rows = load_rows_of(state, position, angles=angles)
                return check_poses_with_loads(messages.check_poses_response_fields(result), rows)
            except InputError as error:
                reason = str(error)
        return messages.check_poses_response_fields(None, success=False, message=reason)

    # ------------------------------------------------------------------ health
    def _publish_diagnostics(self) -> None:
        frame_id = self.state.manipulator.frame_id if self.state is not None else ""
        array = health.diagnostic_array(
            name=self.get_fully_qualified_name(),
            hardware_id=frame_id or self.get_name(),
            stamp=self.get_clock().now().to_msg(),
            counters=self.stats,
            jobs_depth=self.jobs.depth,
            worker_alive=self.worker.alive,
            recorder=self.recorder.status(),
            lifecycle=health.Lifecycle(self.lifecycle_state, self.active, self.configure_error),
            extra=self.cell_status.values(self.state),
        )
        self._diagnostics.publish(array)

    # ------------------------------------------------------------------ lifecycle
    def internal_error(self, error: BaseException) -> str:
        self.get_logger().error(f"internal error: {error!r}")
        reason = f"internal error: {type(error).__name__}: {error}"
        self.stats.last_error = reason
        return reason

    def stop_worker(self) -> None:
        """Cancel the queued and running computations and end the worker process."""
        self.workspaces.stop()
        self.worker.close()
        if self.paths.axis_limits is not None:
            self.paths.axis_limits.close()

    def destroy_node(self) -> None:
        """Stop the jobs and the worker, finish the MCAP log (logging where it went), then
        destroy the node and its lifecycle state machine (rclpy leaves the latter to the
        garbage collector, which may run after the context is shut down: a segfault was seen
        in the test process)."""
        self.stop_worker()
        markers = getattr(self, "markers", None)  # the ~/markers thread (ros/markers.py)
        if markers is not None:
            markers.close()
        path = self.recorder.status().path
        self.recorder.shutdown()
        self.get_logger().info(
            f"stopped; the log is {path}" if path else "stopped (recording was off)"
        )
        super().destroy_node()
        self._state_machine.destroy_when_not_in_use()


def _inactive_answer(service_class: Any) -> Callable[[str], Any]:
    """The refusal of ``service_class`` while the node is not active: its Response with
    ``success`` false and the reason in ``message`` (every service of the node has both)."""

    def answer(reason: str) -> Any:
        response = service_class.Response()
        response.success = False
        response.message = reason
        return response

    return answer


def _is_coroutine(callback: Callable) -> bool:
    return inspect.iscoroutinefunction(callback)


def main(args: list[str] | None = None) -> int:
    """Run the node until SIGINT/SIGTERM or an external shutdown (``ros2 run`` entry point).

    Returns
    -------
    int
        Process exit status: 0 after a clean shutdown, 1 when the parameters are invalid, 2
        when an option (``--autostart=``, ``--realtime-priority=``, ``--worker-scheduling=``)
        is invalid or refused.
    """
    sys.setswitchinterval(SWITCH_INTERVAL)
    try:
        autostart, args = autostart_from_argv(sys.argv if args is None else args)
        priority, args = realtime_priority_from_argv(args)
        policy, args = worker_policy_from_argv(args)
        set_realtime(priority)  # before rclpy starts a thread: they all inherit it
        set_worker_policy(policy)  # the worker and axis-limits processes (ros/scheduling.py)
    except ConfigError as error:
        get_logger(NODE_NAME).fatal(str(error))
        return 2
    rclpy.init(args=args)
    node = None
    executor = None
    status = 0
    try:
        node = WorkspaceNode(
            extensions=EXTENSIONS,
            override_names=command_line_override_names(args, NODE_NAME),
            autostart=autostart,
        )
        node.exit_when_finalized = True  # the shutdown transition ends the process
        executor = SingleThreadedExecutor()
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
            node.stop_worker()
        if executor is not None:
            executor.shutdown(timeout_sec=10.0)
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return status


if __name__ == "__main__":
    sys.exit(main())
