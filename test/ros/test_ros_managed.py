"""workspace_node as a managed (lifecycle) node over real Fast DDS, driven from this process with
the lifecycle_msgs services (ChangeState, GetState): every transition, what each state answers
(a command while not active gets success=false "inactive", never silence), the worker and the
log released by cleanup and shutdown, and a bad parameter set that leaves it unconfigured with
the reason."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
from ros_support import require_ros, running_node

require_ros()

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from hexapod_workspace_msgs.msg import (  # noqa: E402
    CommandedPose,
    ReachabilityResult,
    TiltTorsion,
    WorkspaceRequest,
)
from hexapod_workspace_msgs.srv import CheckPoses, CheckPosesFlat  # noqa: E402
from lifecycle_msgs.msg import Transition  # noqa: E402
from lifecycle_msgs.srv import ChangeState, GetState  # noqa: E402
from rcl_interfaces.msg import Parameter as ParameterMsg  # noqa: E402
from rcl_interfaces.msg import ParameterType, ParameterValue  # noqa: E402
from rcl_interfaces.srv import SetParameters  # noqa: E402

from hexapod_workspace import check, logs  # noqa: E402
from hexapod_workspace.core.evaluation.loading import load_manipulator  # noqa: E402

NODE = "/hexapod_workspace"
MANUAL = ["--autostart=false"]
POSE = (0.3, 0.2, 0.1)


@pytest.fixture(autouse=True)
def fresh_clients(ros_client):
    """Each test starts a node of its own: its services are discovered afresh."""
    yield
    for name in [n for n in ros_client._clients if n.startswith(NODE)]:
        ros_client.drop_client(name)


def state_of(client) -> str:
    response = client.call(GetState, f"{NODE}/get_state", GetState.Request())
    return response.current_state.label


def change(client, transition: int) -> bool:
    request = ChangeState.Request(transition=Transition(id=transition))
    return client.call(ChangeState, f"{NODE}/change_state", request).success


def check_one(client) -> CheckPoses.Response:
    request = CheckPoses.Request(
        orientations=[TiltTorsion(phi=POSE[0], theta=POSE[1], psi=POSE[2])]
    )
    request.position.z = -1.3
    return client.call(CheckPoses, f"{NODE}/check_poses", request)


def check_flat(client) -> CheckPosesFlat.Response:
    request = CheckPosesFlat.Request(angles=list(POSE))
    request.position.z = -1.3
    return client.call(CheckPosesFlat, f"{NODE}/check_poses_flat", request)


class Commands:
    """Publishes CommandedPose and collects the ReachabilityResult of each, by request_id."""

    def __init__(self, client) -> None:
        self.client = client
        self.results = client.collect(ReachabilityResult, f"{NODE}/reachability")
        self.publisher = client.publisher(CommandedPose, f"{NODE}/commanded_pose")
        self.count = 0

    def send(self) -> ReachabilityResult:
        self.count += 1
        request_id = f"managed-{self.count}"
        command = CommandedPose(request_id=request_id)
        command.orientation = TiltTorsion(phi=POSE[0], theta=POSE[1], psi=POSE[2])
        command.position.z = -1.3
        self.publisher.publish(command)
        self.client.spin_until(
            lambda: any(r.request_id == request_id for r in self.results),
            what=f"the result of {request_id}",
        )
        return next(r for r in self.results if r.request_id == request_id)


def assert_inactive(client, commands: Commands, state: str) -> None:
    """Every kind of command answers success=false "inactive" naming the state."""
    for response in (check_one(client), check_flat(client)):
        assert not response.success
        assert response.message.startswith("inactive"), response.message
        assert state in response.message, response.message
    result = commands.send()
    assert not result.success
    assert result.message.startswith("inactive"), result.message
    goal = WorkspaceRequest(kind=WorkspaceRequest.PROJECTED_TORSION_ZERO, n_rays=36)
    goal.position.z = -1.3
    answer = client.compute(f"{NODE}/compute_workspace", goal)
    assert not answer.success
    assert answer.message.startswith("inactive"), answer.message


def diagnostics_value(client, key: str, expected: str, timeout: float = 15.0) -> DiagnosticArray:
    """Wait for a /diagnostics status of the node whose ``key`` is ``expected``."""
    received = client.collect(DiagnosticArray, "/diagnostics")

    def value(array: DiagnosticArray) -> str | None:
        for status in array.status:
            if status.name == NODE:
                return next((kv.value for kv in status.values if kv.key == key), None)
        return None

    client.spin_until(
        lambda: any(value(a) == expected for a in received),
        what=f"/diagnostics with {key} = {expected}",
        timeout=timeout,
    )
    return next(a for a in received if value(a) == expected)


def test_every_transition_over_dds(ros_client, tmp_path):
    model = load_manipulator(logs_example_path())
    expected = check(model, np.array([POSE]), (0.0, 0.0, -1.3))
    with running_node(tmp_path, node_options=MANUAL) as node:
        ros_client.client(GetState, f"{NODE}/get_state")
        assert state_of(ros_client) == "unconfigured"
        commands = Commands(ros_client)
        assert_inactive(ros_client, commands, "unconfigured")
        diagnostics_value(ros_client, "lifecycle state", "unconfigured")
        assert not list(node.record_dir.glob("*.mcap")), "no log before configure"

        assert change(ros_client, Transition.TRANSITION_CONFIGURE)
        assert state_of(ros_client) == "inactive"
        assert_inactive(ros_client, commands, "inactive")

        assert change(ros_client, Transition.TRANSITION_ACTIVATE)
        assert state_of(ros_client) == "active"
        response = check_one(ros_client)
        assert response.success, response.message
        assert response.results[0].reachable == bool(expected.reachable[0])
        assert commands.send().success
        diagnostics_value(ros_client, "lifecycle state", "active")

        assert change(ros_client, Transition.TRANSITION_DEACTIVATE)
        assert state_of(ros_client) == "inactive"
        assert_inactive(ros_client, commands, "inactive")  # never silence

        assert change(ros_client, Transition.TRANSITION_CLEANUP)
        assert state_of(ros_client) == "unconfigured"
        (first,) = node.record_dir.glob("*.mcap")
        assert logs.read_log(first).finished, "cleanup finishes the log"
        diagnostics_value(ros_client, "worker alive", "False")

        # configured again: a new worker computes, a new log records
        assert change(ros_client, Transition.TRANSITION_CONFIGURE)
        assert change(ros_client, Transition.TRANSITION_ACTIVATE)
        goal = WorkspaceRequest(kind=WorkspaceRequest.PROJECTED_TORSION_ZERO, n_rays=36)
        goal.position.z = -1.3
        answer = ros_client.compute(f"{NODE}/compute_workspace", goal)
        assert answer.success, answer.message

        # finalized: the log is finished and the process ends by itself, status 0
        assert change(ros_client, Transition.TRANSITION_ACTIVE_SHUTDOWN)
        try:
            status = node.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            status = None
        assert status == 0, f"status {status} after the shutdown transition\n{node.output()}"
        node.stopped = True
        assert "finalized: the process exits" in node.output()
        logs_after = sorted(node.record_dir.glob("*.mcap"))
        assert len(logs_after) == 2
        assert all(logs.read_log(path).finished for path in logs_after)
        ros_client.drop_client(f"{NODE}/check_poses")
    # the inactive answers of the second log were recorded like any other
    recorded = logs.read_log(logs_after[1])
    assert recorded.finished


def test_invalid_transition_is_refused(ros_client, tmp_path):
    with running_node(tmp_path, node_options=MANUAL) as node:
        ros_client.client(GetState, f"{NODE}/get_state")
        assert not change(ros_client, Transition.TRANSITION_ACTIVATE)  # not configured yet
        assert state_of(ros_client) == "unconfigured"
        assert node.stop() == 0, node.output()


def test_bad_parameters_leave_it_unconfigured_with_the_reason(ros_client, tmp_path):
    """configure fails with the reason (log line, /diagnostics ERROR); a corrected value is
    accepted while unconfigured and the next configure succeeds."""
    with running_node(tmp_path, {"limits.leg_length_min": [2.0]}, node_options=MANUAL) as node:
        ros_client.client(GetState, f"{NODE}/get_state")
        assert not change(ros_client, Transition.TRANSITION_CONFIGURE)
        assert state_of(ros_client) == "unconfigured"
        array = diagnostics_value(ros_client, "lifecycle state", "unconfigured")
        (status,) = [s for s in array.status if s.name == NODE]
        assert status.level == status.ERROR
        assert "limits.leg_length_min" in status.message, status.message
        assert "limits.leg_length_min" in node.output()
        assert node.process.poll() is None, "the node keeps running, unconfigured"

        fixed = ParameterMsg(
            name="limits.leg_length_min",
            value=ParameterValue(
                type=ParameterType.PARAMETER_DOUBLE_ARRAY, double_array_value=[1.0]
            ),
        )
        answer = ros_client.call(
            SetParameters, f"{NODE}/set_parameters", SetParameters.Request(parameters=[fixed])
        )
        assert answer.results[0].successful, answer.results[0].reason
        assert change(ros_client, Transition.TRANSITION_CONFIGURE)
        assert change(ros_client, Transition.TRANSITION_ACTIVATE)
        assert check_one(ros_client).success
        ros_client.drop_client(f"{NODE}/check_poses")
        assert node.stop() == 0, node.output()


@pytest.mark.parametrize("value", ["maybe"])
def test_bad_autostart_option_exits_2(ros_domain, tmp_path, value):
    with running_node(tmp_path, node_options=[f"--autostart={value}"]) as node:
        status = node.process.wait(timeout=60)
        output = node.output()
    assert status == 2, output
    assert "--autostart" in output and value in output, output


def logs_example_path():
    from hexapod_workspace._resources import example_config_path

    return example_config_path()


def test_autostart_option_is_read_before_ros_args_only():
    from hexapod_workspace.errors import ConfigError
    from hexapod_workspace.ros.lifecycle import autostart_from_argv

    argv = ["workspace_node", "--autostart=false", "--ros-args", "-p", "a:=1"]
    assert autostart_from_argv(argv) == (False, ["workspace_node", "--ros-args", "-p", "a:=1"])
    assert autostart_from_argv(["workspace_node", "--autostart=TRUE"]) == (True, ["workspace_node"])
    assert autostart_from_argv(["workspace_node"]) == (True, ["workspace_node"])
    after = ["workspace_node", "--ros-args", "--autostart=false"]  # ROS's, not ours
    assert autostart_from_argv(after) == (True, after)
    with pytest.raises(ConfigError, match="--autostart: expected true or false, got 'maybe'"):
        autostart_from_argv(["workspace_node", "--autostart=maybe"])
