"""``~/compute_atlas`` over real Fast DDS: an rclpy ActionClient here, the action server in
another process (test/ros/atlas_action_server.py, what ``attach_atlas_action`` adds to the
workspace node), loopback discovery in this module's own ROS domain."""

from __future__ import annotations

import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from ros_support import DISCOVERY_TIMEOUT, node_environment, require_ros

require_ros()

from action_msgs.msg import GoalStatus  # noqa: E402
from hexapod_workspace_msgs.action import ComputeAtlas  # noqa: E402
from rclpy.action import ActionClient  # noqa: E402
from sensor_msgs.msg import PointCloud2  # noqa: E402

from hexapod_workspace import AtlasOptions  # noqa: E402
from hexapod_workspace.core.workspaces.atlas import position_capability  # noqa: E402
from hexapod_workspace.logs import read_log  # noqa: E402
from hexapod_workspace.ros.atlas_action import CLOUD_FIELDS  # noqa: E402

SERVER = Path(__file__).with_name("atlas_action_server.py")
ACTION = "/hexapod_workspace/compute_atlas"
CLOUD = "/hexapod_workspace/atlas"
WAIT = 120.0


@pytest.fixture(scope="module")
def server(ros_domain, tmp_path_factory):
    folder = tmp_path_factory.mktemp("atlas_action")
    log = folder / "atlas.mcap"
    output = (folder / "server.out").open("wb")
    process = subprocess.Popen(
        [sys.executable, str(SERVER), str(log)],
        stdout=output,
        stderr=subprocess.STDOUT,
        env=node_environment(),
    )
    try:
        yield process, log
    finally:
        if process.poll() is None:
            process.send_signal(2)  # SIGINT: the log is finished
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(timeout=30)
        output.close()
        print((folder / "server.out").read_text(errors="replace"))


@pytest.fixture(scope="module")
def action_client(ros_client, server):
    client = ActionClient(ros_client.node, ComputeAtlas, ACTION)
    assert client.wait_for_server(timeout_sec=DISCOVERY_TIMEOUT), "action server not discovered"
    yield client
    client.destroy()


def _goal(box, step, tilts_deg=()) -> ComputeAtlas.Goal:
    goal = ComputeAtlas.Goal()
    goal.box = [float(v) for v in box]
    goal.step = float(step)
    goal.n_phi = 24
    goal.tolerance = 1e-3
    goal.tilt_required = [math.radians(t) for t in tilts_deg]
    return goal


def _send(ros_client, action_client, goal, feedback: list, on_feedback=None):
    def collect(message):
        feedback.append(message.feedback)
        if on_feedback is not None:
            on_feedback(message.feedback)

    sent = action_client.send_goal_async(goal, feedback_callback=collect)
    ros_client.executor.spin_until_future_complete(sent, timeout_sec=WAIT)
    handle = sent.result()
    assert handle is not None and handle.accepted
    return handle


def _result(ros_client, handle):
    future = handle.get_result_async()
    ros_client.executor.spin_until_future_complete(future, timeout_sec=WAIT)
    assert future.done(), "no result in time"
    return future.result()


def _cloud_table(cloud) -> np.ndarray:
    names = [field.name for field in cloud.fields]
    assert names == ["x", "y", "z", *CLOUD_FIELDS]
    assert cloud.point_step == 4 * len(names) and not cloud.is_bigendian
    return np.frombuffer(bytes(cloud.data), dtype="<f4").reshape(cloud.width, len(names))


def test_atlas_goal_feedback_result_and_late_transient_local_cloud(
    ros_client, action_client, example
):
    feedback: list = []
    handle = _send(
        ros_client, action_client, _goal([-0.1, 0.1, 0.0, 0.1, -1.3, -1.2], 0.1, [30]), feedback
    )
    answer = _result(ros_client, handle)
    assert answer.status == GoalStatus.STATUS_SUCCEEDED, answer.result.reason
    result = answer.result
    assert result.success and result.positions == 12 and result.reachable_positions == 12
    assert feedback and feedback[-1].positions_done == feedback[-1].positions_total == 12
    done = [f.positions_done for f in feedback]
    assert done == sorted(done)
    # Subscribed only now: transient-local durability hands over the last atlas.
    received = ros_client.collect(PointCloud2, CLOUD, transient_local=True)
    ros_client.spin_until(lambda: bool(received), what="the atlas cloud", timeout=WAIT)
    table = _cloud_table(received[-1])
    assert table.shape == (12, 3 + len(CLOUD_FIELDS))
    options = AtlasOptions(n_phi=24, tolerance=1e-3)
    capability = []
    for row in table[[0, 5, 11]]:
        expected = position_capability(example, row[:3].astype(np.float64), options)
        for k, name in enumerate(CLOUD_FIELDS):
            assert row[3 + k] == pytest.approx(expected[name], rel=1e-6, abs=1e-6), name
    capability = table[:, 3 + CLOUD_FIELDS.index("tilt_capability")]
    assert result.tilt_capability_min == pytest.approx(capability.min(), rel=1e-6)
    count = int((capability >= np.float32(math.radians(30))).sum())
    assert list(result.dexterous_volume) == pytest.approx([count * 0.1**3])


def test_cancel_stops_after_the_chunk_in_flight(ros_client, action_client):
    feedback: list = []
    cancelled: list = []

    def cancel_once(message) -> None:
        if message.positions_done > 0 and not cancelled:
            cancelled.append(handle.cancel_goal_async())

    handle = None
    goal = _goal([-0.2, 0.2, -0.2, 0.2, -1.3, -1.2], 0.05)  # 9 x 9 x 3 = 243 positions
    handle = _send(ros_client, action_client, goal, feedback, cancel_once)
    started = time.monotonic()
    answer = _result(ros_client, handle)
    assert cancelled, "no progress reported before the end"
    assert answer.status == GoalStatus.STATUS_CANCELED
    assert not answer.result.success and answer.result.reason == "cancelled"
    assert feedback[-1].positions_done < feedback[-1].positions_total == 243
    assert time.monotonic() - started < WAIT


def test_bad_goal_is_refused_with_a_reason_and_the_server_keeps_serving(ros_client, action_client):
    handle = _send(ros_client, action_client, _goal([0, 0, 0, 0, -1.3, -1.3], 0.0), [])
    answer = _result(ros_client, handle)
    assert answer.status == GoalStatus.STATUS_ABORTED
    assert not answer.result.success and "step" in answer.result.reason
    handle = _send(ros_client, action_client, _goal([0.1, -0.1, 0, 0, -1.3, -1.3], 0.1), [])
    answer = _result(ros_client, handle)
    assert answer.status == GoalStatus.STATUS_ABORTED and "empty" in answer.result.reason
    handle = _send(ros_client, action_client, _goal([0, 0, 0, 0, -1.3, -1.3], 0.1), [])
    assert _result(ros_client, handle).status == GoalStatus.STATUS_SUCCEEDED


def test_the_published_atlas_is_recorded(server, action_client):
    # Runs last in this module: stops the server, which finishes its log.
    process, log = server
    process.send_signal(2)
    process.wait(timeout=30)
    contents = read_log(log)
    clouds = [m for m in contents.messages if m.topic == CLOUD]
    assert len(clouds) == 2  # the two succeeded goals; the cancelled/refused ones publish none
    assert [c.message.width for c in clouds] == [12, 1]
