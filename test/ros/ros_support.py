"""Helpers of the ROS tests: a real workspace_node process, an rclpy client, real Fast DDS.

The node runs from the colcon install space (``install/hexapod_workspace/lib/hexapod_workspace/
workspace_node``, what ``ros2 run`` runs) in a separate process with a parameters file; the test
process talks to it through an rclpy client node (:class:`RosClient`).

The environment of the install space (PYTHONPATH, LD_LIBRARY_PATH, AMENT_PREFIX_PATH) comes from
``tools/ros_env.sh`` (``make test`` runs pytest in it). Without it the ROS test modules skip
themselves (:func:`require_ros`), unless HEXAPOD_REQUIRE_ROS=1 (set by ``make test``), which
turns the skip into a failure.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import signal
import subprocess
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
import yaml

REPO = Path(__file__).resolve().parents[2]
INSTALL = REPO / "install"
NODE_EXECUTABLE = INSTALL / "hexapod_workspace" / "lib" / "hexapod_workspace" / "workspace_node"
EXAMPLE_PARAMS = REPO / "config" / "example_gpm.yaml"
#: Generous: discovery on a loaded 2-core CI machine can take seconds.
DISCOVERY_TIMEOUT = 60.0
CALL_TIMEOUT = 120.0
RESEND_AFTER = 20.0
STOP_TIMEOUT = 30.0


def require_ros() -> None:
    """Skip (or, with HEXAPOD_REQUIRE_ROS=1, fail) when ROS or the install space is missing."""
    problem = None
    if not NODE_EXECUTABLE.is_file():
        problem = f"{NODE_EXECUTABLE} is missing (run `make ros`)"
    else:
        for module in ("rclpy", "hexapod_workspace_msgs.srv", "std_srvs.srv", "sensor_msgs.msg"):
            try:
                importlib.import_module(module)
            except ImportError as error:
                problem = f"cannot import {module} ({error}); source tools/ros_env.sh"
                break
    if problem is None:
        return
    if os.environ.get("HEXAPOD_REQUIRE_ROS") == "1":
        pytest.fail(f"ROS tests required but unavailable: {problem}", pytrace=False)
    pytest.skip(f"ROS tests skipped: {problem}", allow_module_level=True)


_next_domain = [os.getpid() % 100]


def domain_selector() -> Callable[[], int]:
    """Domain ids 1..100, starting from a pid-derived one and never reused by this process
    (domain_coordinator tries up to 100): a module's stale DDS participants cannot meet the
    next module's."""

    def select() -> int:
        value = _next_domain[0] % 100 + 1
        _next_domain[0] += 1
        return value

    return select


def write_params(path: Path, overrides: dict[str, Any] | None = None) -> Path:
    """Write the example parameters file with dotted-name ``overrides`` applied.

    Parameters
    ----------
    path : Path
        Where to write the YAML file.
    overrides : dict, optional
        ``{"resolution.n_rays": 36, "limits.leg_length_max": [1.4], ...}``.
    """
    document = yaml.safe_load(EXAMPLE_PARAMS.read_text(encoding="utf-8"))
    parameters = document["hexapod_workspace"]["ros__parameters"]
    for name, value in (overrides or {}).items():
        *groups, leaf = name.split(".")
        target = parameters
        for group in groups:
            target = target.setdefault(group, {})
        target[leaf] = value
    path.write_text(yaml.safe_dump(document, sort_keys=False), encoding="utf-8")
    return path


@dataclass
class NodeProcess:
    """A workspace_node process started from the install space."""

    process: subprocess.Popen
    log_path: Path
    params_path: Path
    record_dir: Path
    stopped: bool = field(default=False)

    def output(self) -> str:
        """Everything the node wrote to stdout/stderr so far."""
        return self.log_path.read_text(encoding="utf-8", errors="replace")

    def stop(self, sig: int = signal.SIGINT, timeout: float = STOP_TIMEOUT) -> int:
        """Send ``sig`` and wait; SIGKILL after ``timeout`` s. Returns the exit status."""
        if self.process.poll() is None:
            self.process.send_signal(sig)
            try:
                self.process.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                # SIGABRT: faulthandler (PYTHONFAULTHANDLER=1) dumps every thread's stack
                self.process.send_signal(signal.SIGABRT)
                with contextlib.suppress(subprocess.TimeoutExpired):
                    self.process.wait(timeout=timeout)
                if self.process.poll() is None:
                    self.process.kill()
                    self.process.wait(timeout=timeout)
                self.stopped = True
                msg = f"node did not stop within {timeout} s of signal {sig}:\n{self.output()}"
                raise AssertionError(msg) from None
        self.stopped = True
        return self.process.returncode


def node_environment() -> dict[str, str]:
    """The environment of a node process: ours (install space, domain, LOCALHOST)."""
    env = dict(os.environ)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env["PYTHONUNBUFFERED"] = "1"
    env["PYTHONFAULTHANDLER"] = "1"
    env["RCUTILS_LOGGING_BUFFERED_STREAM"] = "0"
    return env


@contextlib.contextmanager
def running_node(
    directory: Path,
    overrides: dict[str, Any] | None = None,
    extra_args: list[str] | None = None,
    params_text: str | None = None,
    node_options: list[str] | None = None,
) -> Iterator[NodeProcess]:
    """Start workspace_node with a parameters file in ``directory``; stop it on exit.

    The file is the example with ``overrides``, or ``params_text`` as given. The node records
    into ``directory / "logs"``. ``extra_args`` follow ``--ros-args``;
    ``node_options`` (``--autostart=false``) precede it. Needs ROS_DOMAIN_ID set (``ros_domain``).
    """
    assert "ROS_DOMAIN_ID" in os.environ, "use the ros_domain fixture first"
    record_dir = directory / "logs"
    if params_text is None:
        params = write_params(
            directory / "params.yaml",
            {"recording.directory": str(record_dir), **(overrides or {})},
        )
    else:
        params = directory / "params.yaml"
        params.write_text(params_text, encoding="utf-8")
    log_path = directory / "node.log"
    command = [
        str(NODE_EXECUTABLE),
        *(node_options or []),
        "--ros-args",
        "--params-file",
        str(params),
    ]
    with log_path.open("wb") as log:
        process = subprocess.Popen(
            [*command, *(extra_args or [])],
            stdout=log,
            stderr=subprocess.STDOUT,
            env=node_environment(),
            cwd=directory,
        )
    node = NodeProcess(process, log_path, params, record_dir)
    try:
        yield node
    finally:
        # shown by pytest when the test fails
        print(f"---- workspace_node output ({log_path}):\n{node.output()}")
        if process.poll() is None:  # a clean stop leaves no stale DDS participant behind
            process.send_signal(signal.SIGINT)
            try:
                process.wait(timeout=STOP_TIMEOUT)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(timeout=STOP_TIMEOUT)


class RosClient:
    """An rclpy node in the test process with helpers to call services and collect topics."""

    def __init__(self, context: Any, name: str) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        self.context = context
        self.node = rclpy.create_node(name, context=context)
        self.executor = SingleThreadedExecutor(context=context)
        #: Requests sent per service name by :meth:`call` (resends included: a node that answers
        #: a resent request has handled, and recorded, it twice).
        self.sent: dict[str, int] = {}
        self.executor.add_node(self.node)
        self._clients: dict[str, Any] = {}

    def client(self, service_type: type, name: str) -> Any:
        """A (cached) service client, waited for until discovered."""
        if name not in self._clients:
            client = self.node.create_client(service_type, name)
            if not client.wait_for_service(timeout_sec=DISCOVERY_TIMEOUT):
                msg = f"service {name} not discovered within {DISCOVERY_TIMEOUT} s"
                raise AssertionError(msg)
            self._clients[name] = client
        return self._clients[name]

    def drop_client(self, name: str) -> None:
        """Destroy the cached client of ``name`` (its server went away; rediscover next time)."""
        client = self._clients.pop(name, None)
        if client is not None:
            self.node.destroy_client(client)

    def call(
        self,
        service_type: type,
        name: str,
        request: Any,
        timeout: float = CALL_TIMEOUT,
        resend_after: float = RESEND_AFTER,
    ) -> Any:
        """Call a service and wait for the response (spinning this client).

        The request is sent again every ``resend_after`` s without an answer (every service of
        the node is idempotent): a response can be lost while the server has not yet discovered
        this client's response reader, a known DDS race right after discovery.
        """
        client = self.client(service_type, name)
        deadline = time.monotonic() + timeout
        while True:
            future = client.call_async(request)
            self.sent[name] = self.sent.get(name, 0) + 1
            wait = max(0.0, min(resend_after, deadline - time.monotonic()))
            self.executor.spin_until_future_complete(future, timeout_sec=wait)
            if future.done():
                return future.result()
            client.remove_pending_request(future)
            if time.monotonic() >= deadline:
                msg = f"no response from {name} within {timeout} s"
                raise AssertionError(msg)
            print(f"no response from {name} within {resend_after} s: request sent again")

    def action_client(self, name: str) -> Any:
        """A (cached) ComputeWorkspace action client, waited for until its server is seen."""
        from hexapod_workspace_msgs.action import ComputeWorkspace
        from rclpy.action import ActionClient

        from hexapod_workspace.ros.qos import FEEDBACK_QOS_PROFILE

        key = f"action:{name}"
        if key not in self._clients:
            # every feedback message of a goal (about 105) fits the history, as the server's
            client = ActionClient(
                self.node, ComputeWorkspace, name, feedback_sub_qos_profile=FEEDBACK_QOS_PROFILE
            )
            if not client.wait_for_server(timeout_sec=DISCOVERY_TIMEOUT):
                msg = f"action server {name} not discovered within {DISCOVERY_TIMEOUT} s"
                raise AssertionError(msg)
            self._clients[key] = client
        return self._clients[key]

    def send_goal(self, name: str, request: Any, feedback: list | None = None) -> Any:
        """Send a ComputeWorkspace goal with ``request`` (a WorkspaceRequest); return the
        accepted goal handle. Feedback messages are appended to ``feedback``."""
        from hexapod_workspace_msgs.action import ComputeWorkspace

        client = self.action_client(name)
        goal = ComputeWorkspace.Goal(request=request)
        callback = (
            (lambda message: feedback.append(message.feedback)) if feedback is not None else None
        )
        future = client.send_goal_async(goal, feedback_callback=callback)
        self.spin_until(future.done, what=f"the goal response of {name}")
        handle = future.result()
        assert handle.accepted, "the node rejected a goal"
        return handle

    def goal_result(self, handle: Any, timeout: float = CALL_TIMEOUT) -> tuple[int, Any]:
        """Wait for a goal's end; return (GoalStatus status, ComputeWorkspace.Result)."""
        future = handle.get_result_async()
        self.spin_until(future.done, what="the goal's result", timeout=timeout)
        response = future.result()
        return response.status, response.result

    def compute(self, name: str, request: Any, feedback: list | None = None) -> Any:
        """Run one ComputeWorkspace goal to its end; return its result."""
        _, result = self.goal_result(self.send_goal(name, request, feedback))
        return result

    def collect(self, message_type: type, topic: str, *, transient_local: bool = False) -> list:
        """Subscribe to ``topic``; received messages are appended to the returned list."""
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

        received: list = []
        qos = QoSProfile(
            depth=100,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=(
                DurabilityPolicy.TRANSIENT_LOCAL if transient_local else DurabilityPolicy.VOLATILE
            ),
        )
        self.node.create_subscription(message_type, topic, received.append, qos)
        return received

    def publisher(self, message_type: type, topic: str) -> Any:
        """A reliable publisher, waited for until the node's subscription matches it."""
        publisher = self.node.create_publisher(message_type, topic, 10)
        self.spin_until(
            lambda: publisher.get_subscription_count() > 0,
            what=f"a subscriber on {topic}",
            timeout=DISCOVERY_TIMEOUT,
        )
        return publisher

    def spin_until(
        self, predicate: Callable[[], bool], *, what: str, timeout: float = CALL_TIMEOUT
    ) -> None:
        """Spin until ``predicate()`` holds; fail after ``timeout`` s."""
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline:
                msg = f"timed out after {timeout} s waiting for {what}"
                raise AssertionError(msg)
            self.executor.spin_once(timeout_sec=0.05)

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
