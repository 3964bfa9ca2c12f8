"""workspace_node as a process: clean stop on SIGINT/SIGTERM, refusal of a bad parameters file."""

from __future__ import annotations

import signal
import subprocess

import pytest
from ros_support import STOP_TIMEOUT, require_ros, running_node

require_ros()

from hexapod_workspace_msgs.msg import TiltTorsion  # noqa: E402
from hexapod_workspace_msgs.srv import CheckPoses  # noqa: E402

NODE = "/hexapod_workspace"


def serve_one_check(client) -> None:
    request = CheckPoses.Request(orientations=[TiltTorsion(phi=0.0, theta=0.1, psi=0.0)])
    request.position.z = -1.3
    response = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert response.success, response.message


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_node_stops_cleanly_on_signal(ros_client, tmp_path, sig):
    with running_node(tmp_path) as node:
        serve_one_check(ros_client)
        ros_client.drop_client(f"{NODE}/check_poses")  # the next node is discovered afresh
        status = node.stop(sig)
        output = node.output()
    assert status == 0, output
    assert "Traceback" not in output, output
    (log,) = (tmp_path / "logs").glob("*.mcap")
    # what the node serves, and where its log went when it stopped
    (ready,) = [line for line in output.splitlines() if "ready: /hexapod_workspace" in line]
    for name in ("check_poses", "check_path", "compute_workspace", "compute_atlas"):
        assert name in ready, ready
    assert "commanded_pose" in ready and "workspace_request" in ready, ready
    assert f"log finished: {log}" in output and f"stopped; the log is {log}" in output, output
    # no spurious update at start (an extension declaring its own parameter)
    assert "parameters updated" not in output, output


def test_node_stops_cleanly_while_goals_compute_and_queue(ros_client, tmp_path):
    """SIGINT with one goal computing and one queued: both end, the node exits 0, the log is
    finished."""
    from hexapod_workspace_msgs.msg import WorkspaceRequest

    from hexapod_workspace import logs

    with running_node(tmp_path) as node:
        serve_one_check(ros_client)
        ros_client.drop_client(f"{NODE}/check_poses")
        long = WorkspaceRequest(kind=0, n_rays=720, psi_step=0.001, tolerance=1e-9)
        long.position.z = -1.3
        feedback: list = []
        ros_client.send_goal(f"{NODE}/compute_workspace", long, feedback)
        ros_client.send_goal(f"{NODE}/compute_workspace", long)
        ros_client.spin_until(
            lambda: any(f.stage == "computing" for f in feedback), what="the first goal computing"
        )
        status = node.stop(signal.SIGINT)
        output = node.output()
    assert status == 0, output
    assert "Traceback" not in output, output
    (log,) = (tmp_path / "logs").glob("*.mcap")
    assert logs.read_log(log).finished


@pytest.mark.parametrize(
    ("overrides", "named"),
    [
        ({"limits.leg_length_min": [2.0]}, "limits.leg_length_min"),
        ({"geometry.base_joints": [0.0, 1.0, 2.0]}, "geometry.base_joints"),
        ({"limits.leg_diameter": 0}, "limits.leg_diameter"),  # an integer where m is a float
        ({"resolution.projected_method": "fastest"}, "resolution.projected_method"),
        ({"resolution.n_rays": 1}, "resolution.n_rays"),
        # a misspelt key or section stops the node (it used to warn and
        # answer for the example's 1.45 m legs)
        ({"limits.leg_lenght_max": [1.30]}, "limits.leg_lenght_max: unknown parameter"),
        ({"limit.leg_length_max": [1.30]}, "limit: unknown section"),
        # a degenerate machine: six legs from one point
        ({"geometry.base_joints": [0.0] * 18}, "joints 1, 2, 3, 4, 5 and 6 coincide"),
    ],
    ids=[
        "lengths",
        "joints-shape",
        "int-type",
        "method",
        "range",
        "misspelt-key",
        "misspelt-section",
        "coincident-joints",
    ],
)
def test_invalid_parameters_file_exits_with_the_reason(ros_domain, tmp_path, overrides, named):
    with running_node(tmp_path, overrides) as node:
        try:
            status = node.process.wait(timeout=STOP_TIMEOUT * 2)
        except subprocess.TimeoutExpired:
            pytest.fail(f"node kept running with invalid parameters:\n{node.output()}")
        output = node.output()
    assert status == 1, output
    assert named in output, output
    assert "Traceback" not in output, output


def test_a_partial_model_in_the_file_stops_the_node(ros_domain, tmp_path):
    """Only limits.leg_length_max given; the example must not fill in the
    rest of the machine."""
    text = (
        "hexapod_workspace:\n  ros__parameters:\n"
        f"    recording:\n      directory: {tmp_path / 'logs'}\n"
        "    limits:\n      leg_length_max: [1.30]\n"
    )
    with running_node(tmp_path, params_text=text) as node:
        try:
            status = node.process.wait(timeout=STOP_TIMEOUT * 2)
        except subprocess.TimeoutExpired:
            pytest.fail(f"node kept running with a partial model:\n{node.output()}")
        output = node.output()
    assert status == 1, output
    assert "geometry.base_joints: required parameter is missing" in output, output
    assert "Traceback" not in output, output
