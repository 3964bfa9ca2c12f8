"""workspace_node's MCAP log, from a real node process over real Fast DDS.

What the node published, answered and was sent is compared with what its log holds, decoded by
two independent readers (rosbags with the log's own schemas, mcap + mcap_ros2) and by
hexapod_workspace.logs. SIGINT must leave a finished log; SIGKILL must keep every message
flushed before the kill; an unwritable recording directory must not stop the node serving.
"""

from __future__ import annotations

import math
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from ros_support import DISCOVERY_TIMEOUT, require_ros, running_node, write_params

require_ros()

from hexapod_workspace_msgs.msg import (  # noqa: E402
    CheckPosesRequest,
    CheckPosesResponse,
    CommandedPose,
    ComputeWorkspaceRequest,
    ComputeWorkspaceResponse,
    ReachabilityResult,
    TiltTorsion,
    TriggerResponse,
    WorkspaceSummary,
)
from hexapod_workspace_msgs.srv import CheckPoses, ComputeWorkspace  # noqa: E402
from sensor_msgs.msg import PointCloud2  # noqa: E402
from std_msgs.msg import Empty  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from hexapod_workspace import logs  # noqa: E402
from hexapod_workspace.core.base.resolution import WorkspaceKind  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # test/recording_support.py
from recording_support import (  # noqa: E402
    plain,
    read_with_foxglove,
    read_with_mcap_ros2,
    read_with_rosbags,
)

#: Every test runs its node in its own namespace: fresh service names, so no client of an earlier
#: node (already stopped or killed) can swallow a request.
NAMESPACES = {
    "sigint": "/rec_sigint",
    "sigkill": "/rec_sigkill",
    "stream": "/rec_stream",
    True: "/rec_unwritable",
    False: "/rec_disabled",
}
NODE_PARAMS = {
    "resolution.n_phi": 36,
    "resolution.n_rays": 12,
    "resolution.psi_step": 0.1,
    "resolution.tolerance": 1e-3,
}


def the_log(directory: Path) -> Path:
    found = sorted(directory.glob("*.mcap"))
    assert len(found) == 1, f"expected one log per node run in {directory}, found {found}"
    assert found[0].name.startswith("hexapod_workspace_2")  # named by the start time
    return found[0]


def check_request(angles_deg: list[list[float]]) -> CheckPoses.Request:
    request = CheckPoses.Request()
    request.position.z = -1.3
    request.orientations = [
        TiltTorsion(phi=float(phi), theta=float(theta), psi=float(psi))
        for phi, theta, psi in np.radians(angles_deg)
    ]
    return request


def by_topic(entries: list[tuple[str, str, object]]) -> dict[str, list]:
    topics: dict[str, list] = {}
    for topic, _, message in entries:
        topics.setdefault(topic, []).append(plain(message))
    return topics


def node_args(key: object, directory: Path, overrides: dict | None = None) -> tuple[str, list]:
    """The node's fully qualified name and the arguments that put it in its own namespace,
    with its parameters in a file for ``/**`` (the example file is keyed by the bare name)."""
    namespace = NAMESPACES[key]
    params = write_params(
        directory / "params_namespaced.yaml",
        {"recording.directory": str(directory / "logs"), **NODE_PARAMS, **(overrides or {})},
    )
    document = yaml.safe_load(params.read_text(encoding="utf-8"))
    params.write_text(yaml.safe_dump({"/**": document["hexapod_workspace"]}), encoding="utf-8")
    return f"{namespace}/hexapod_workspace", [
        "-r",
        f"__ns:={namespace}",
        "--params-file",
        str(params),
    ]


def stop(node, sig: int = signal.SIGINT, timeout: float = 30.0) -> int:
    """Stop the node; when it hangs, make it dump every thread's stack (faulthandler) first."""
    node.process.send_signal(sig)
    try:
        return node.process.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        node.process.send_signal(signal.SIGABRT)
        node.process.wait(timeout=timeout)
        msg = f"node did not stop within {timeout} s of signal {sig}:\n{node.output()}"
        raise AssertionError(msg) from None


def test_sigint_log_holds_exactly_what_the_node_did(ros_domain, ros_client, tmp_path) -> None:
    node_name, args = node_args("sigint", tmp_path)
    with running_node(tmp_path, NODE_PARAMS, args) as node:
        summaries = ros_client.collect(
            WorkspaceSummary, f"{node_name}/workspace_summary", transient_local=True
        )
        clouds = ros_client.collect(
            PointCloud2, f"{node_name}/projected_workspace", transient_local=True
        )
        verdicts = ros_client.collect(
            ReachabilityResult, f"{node_name}/reachability", transient_local=True
        )
        # the clouds come from the worker's own node: seen before the first one is published
        ros_client.spin_until(
            lambda: ros_client.node.count_publishers(f"{node_name}/projected_workspace") > 0,
            what="the cloud publisher",
            timeout=DISCOVERY_TIMEOUT,
        )
        check = check_request([[0, 0, 0], [30, 20, 5], [45, 80, 10]])
        check_response = ros_client.call(CheckPoses, f"{node_name}/check_poses", check)
        compute = ComputeWorkspace.Request()
        compute.request.request_id = "recording-test"
        compute.request.kind = WorkspaceKind.PROJECTED_TORSION_ZERO
        compute.request.position.z = -1.3
        # the action's goal and result are recorded in the service's form (same fields)
        result = ros_client.compute(f"{node_name}/compute_workspace", compute.request)
        # The cloud topic keeps one cloud (KEEP_LAST 1, as a latched topic should): the next
        # one may replace this one before it reaches a busy subscriber, so the second
        # computation starts once the first cloud is here (the log must then hold both).
        ros_client.spin_until(
            lambda: len(clouds) >= 1, what="the first cloud", timeout=DISCOVERY_TIMEOUT
        )
        compute_response = ComputeWorkspace.Response(
            success=result.success,
            message=result.message,
            summary=result.summary,
            boundary=result.boundary,
        )
        trigger_response = ros_client.call(
            Trigger, f"{node_name}/compute_projected_workspace", Trigger.Request()
        )
        command = CommandedPose(request_id="cmd-1")
        command.position.z = -1.3
        command.orientation.theta = math.radians(10.0)
        ros_client.publisher(CommandedPose, f"{node_name}/commanded_pose").publish(command)
        ros_client.spin_until(
            lambda: len(verdicts) >= 1 and len(summaries) >= 2 and len(clouds) >= 2,
            what="the node's results",
            timeout=DISCOVERY_TIMEOUT,
        )
        assert stop(node) == 0, node.output()
    path = the_log(tmp_path / "logs")

    ours = logs.read_log(path)
    assert ours.finished and ours.problems == [], ours.problems
    entries = [(m.topic, m.msgtype, m.message) for m in ours.messages]
    for reader_entries in (read_with_rosbags(path), read_with_mcap_ros2(path)):
        assert by_topic(reader_entries) == by_topic(entries)
    # Every channel of the node's log opens in Foxglove (its own libraries, test/foxglove).
    # (read_with_foxglove fails on any refused channel, those without messages included.)
    opened = read_with_foxglove(path, tmp_path)
    assert set(opened) == set(ours.topics)
    assert {topic: channel["count"] for topic, channel in opened.items() if channel["count"]} == {
        topic: len(items) for topic, items in by_topic(entries).items()
    }

    recorded = by_topic(entries)
    # A request resent by the client (no answer within RESEND_AFTER, a DDS discovery race right
    # after start) was handled, and recorded, once per send.
    sent = ros_client.sent[f"{node_name}/check_poses"]
    assert recorded[f"{node_name}/check_poses/request"] == [plain(check)] * sent
    assert recorded[f"{node_name}/check_poses/response"] == [plain(check_response)] * sent
    assert recorded[f"{node_name}/compute_workspace/request"] == [plain(compute)]
    assert recorded[f"{node_name}/compute_workspace/response"] == [plain(compute_response)]
    sent = ros_client.sent[f"{node_name}/compute_projected_workspace"]
    assert recorded[f"{node_name}/compute_projected_workspace/response"][-1:] == [
        plain(trigger_response)
    ]
    assert len(recorded[f"{node_name}/compute_projected_workspace/response"]) == sent
    assert recorded[f"{node_name}/commanded_pose"] == [plain(command)]
    assert recorded[f"{node_name}/reachability"] == [plain(m) for m in verdicts]
    assert recorded[f"{node_name}/workspace_summary"] == [plain(m) for m in summaries]
    assert recorded[f"{node_name}/projected_workspace"] == [plain(m) for m in clouds]


def test_sigkill_keeps_what_was_flushed(ros_domain, ros_client, tmp_path) -> None:
    node_name, args = node_args("sigkill", tmp_path)
    with running_node(tmp_path, NODE_PARAMS, args) as node:
        request = check_request([[0, 0, 0], [10, 5, 0]])
        response = ros_client.call(CheckPoses, f"{node_name}/check_poses", request)
        log_dir = tmp_path / "logs"

        def flushed() -> bool:  # the flush interval bounds how long this takes
            found = list(log_dir.glob("*.mcap"))
            if len(found) != 1:
                return False
            topics = [m.topic for m in logs.read_log(found[0]).messages]
            return f"{node_name}/check_poses/response" in topics

        ros_client.spin_until(
            flushed, what="the check to reach the log on disk", timeout=DISCOVERY_TIMEOUT
        )
        node.stop(signal.SIGKILL)
    path = the_log(tmp_path / "logs")
    contents = logs.read_log(path)
    assert not contents.finished
    recorded = by_topic([(m.topic, m.msgtype, m.message) for m in contents.messages])
    assert recorded[f"{node_name}/check_poses/request"] == [plain(request)]
    assert recorded[f"{node_name}/check_poses/response"] == [plain(response)]
    assert by_topic(read_with_mcap_ros2(path)) == recorded


#: Commands per second of the stream killed by SIGKILL, and how many kills at random points.
STREAM_RATE, KILLS = 200.0, 3


@pytest.mark.parametrize("kill", range(KILLS))
def test_sigkill_under_a_stream_loses_nothing_older_than_the_flush_bound(
    ros_domain, ros_client, tmp_path, kill: int
) -> None:
    """A 200 Hz CommandedPose stream; SIGKILL at a random point: every result this process
    received more than FLUSH_BOUND s before the kill is in the log, with its command."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    from hexapod_workspace.ros.recorder import FLUSH_BOUND

    rng = np.random.default_rng(100 + kill)
    node_name, args = node_args("stream", tmp_path)
    args = ["-r", f"__ns:={NAMESPACES['stream']}{kill}", *args[2:]]
    node_name = f"{NAMESPACES['stream']}{kill}/hexapod_workspace"
    qos = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
    received: dict[str, float] = {}
    with running_node(tmp_path, NODE_PARAMS, args) as node:
        ros_client.node.create_subscription(  # transient local: no result lost to discovery
            ReachabilityResult,
            f"{node_name}/reachability",
            lambda m: received.setdefault(m.request_id, time.monotonic()),
            QoSProfile(
                history=HistoryPolicy.KEEP_ALL,
                reliability=ReliabilityPolicy.RELIABLE,
                durability=DurabilityPolicy.TRANSIENT_LOCAL,
            ),
        )
        publisher = ros_client.node.create_publisher(
            CommandedPose, f"{node_name}/commanded_pose", qos
        )
        ros_client.spin_until(
            lambda: publisher.get_subscription_count() > 0
            and ros_client.node.count_publishers(f"{node_name}/reachability") > 0,
            what="the node's command topics",
            timeout=DISCOVERY_TIMEOUT,
        )
        warm = CommandedPose(request_id=f"k{kill}-warm-up")
        warm.position.z = -1.3
        publisher.publish(warm)
        ros_client.spin_until(lambda: warm.request_id in received, what="the warm-up result")
        kill_after = rng.uniform(1.5, 4.0)  # s of stream before the kill
        start = time.monotonic()
        index = 0
        while time.monotonic() - start < kill_after:
            command = CommandedPose(request_id=f"k{kill}-{index}")
            command.position.z = -1.3
            command.orientation.theta = float(rng.uniform(0.0, 0.6))
            command.orientation.phi = float(rng.uniform(-math.pi, math.pi))
            publisher.publish(command)
            index += 1
            deadline = start + index / STREAM_RATE
            while time.monotonic() < deadline:
                ros_client.executor.spin_once(timeout_sec=max(0.0, deadline - time.monotonic()))
        killed_at = time.monotonic()
        node.stop(signal.SIGKILL)
    acknowledged = [rid for rid, at in received.items() if at < killed_at - FLUSH_BOUND]
    assert len(acknowledged) > STREAM_RATE * 0.5, "too few results before the kill to judge"
    contents = logs.read_log(the_log(tmp_path / "logs"))
    assert not contents.finished
    logged = {
        topic: {m.message.request_id for m in contents.messages if m.topic == topic}
        for topic in (f"{node_name}/reachability", f"{node_name}/commanded_pose")
    }
    for topic, ids in logged.items():
        missing = sorted(set(acknowledged) - ids)
        assert not missing, f"{len(missing)} acknowledged messages missing from {topic}"
    print(
        f"kill {kill} after {kill_after:.2f} s: {index} commands sent, {len(received)} results, "
        f"{len(acknowledged)} older than {FLUSH_BOUND} s, all logged; "
        f"{len(logged[f'{node_name}/reachability'])} results in the log"
    )


@pytest.mark.parametrize("enabled", [True, False])
def test_unwritable_directory_or_disabled_recording_keeps_serving(
    ros_domain, ros_client, tmp_path, enabled: bool
) -> None:
    blocker = tmp_path / "not_a_directory"
    blocker.write_text("a file where the log folder should be")
    overrides = {
        **NODE_PARAMS,
        "recording.enabled": enabled,
        "recording.directory": str(blocker / "logs"),
    }
    node_name, args = node_args(enabled, tmp_path, overrides)
    with running_node(tmp_path, overrides, args) as node:
        response = ros_client.call(
            CheckPoses, f"{node_name}/check_poses", check_request([[0, 0, 0]])
        )
        assert response.success and response.results[0].reachable
        assert stop(node) == 0, node.output()
    if enabled:
        assert "recording off" in node.output()
    assert not list(tmp_path.rglob("*.mcap"))


def test_recorded_type_hashes_are_the_ones_rclpy_announces(ros_client) -> None:
    """topic_type_hash in the channel metadata equals the hash rclpy publishes with."""
    classes = {
        "hexapod_workspace_msgs/msg/WorkspaceSummary": WorkspaceSummary,
        "hexapod_workspace_msgs/msg/ReachabilityResult": ReachabilityResult,
        "hexapod_workspace_msgs/msg/CommandedPose": CommandedPose,
        "hexapod_workspace_msgs/srv/CheckPoses_Request": CheckPoses.Request,
        "hexapod_workspace_msgs/srv/CheckPoses_Response": CheckPoses.Response,
        "hexapod_workspace_msgs/srv/ComputeWorkspace_Request": ComputeWorkspace.Request,
        "hexapod_workspace_msgs/srv/ComputeWorkspace_Response": ComputeWorkspace.Response,
        "std_srvs/srv/Trigger_Request": Trigger.Request,
        "std_srvs/srv/Trigger_Response": Trigger.Response,
        "sensor_msgs/msg/PointCloud2": PointCloud2,
        # The message twins service calls are recorded as (logs.recorded_type).
        "hexapod_workspace_msgs/msg/CheckPosesRequest": CheckPosesRequest,
        "hexapod_workspace_msgs/msg/CheckPosesResponse": CheckPosesResponse,
        "hexapod_workspace_msgs/msg/ComputeWorkspaceRequest": ComputeWorkspaceRequest,
        "hexapod_workspace_msgs/msg/ComputeWorkspaceResponse": ComputeWorkspaceResponse,
        "hexapod_workspace_msgs/msg/TriggerResponse": TriggerResponse,
        "std_msgs/msg/Empty": Empty,
    }
    for index, (msgtype, message_class) in enumerate(classes.items()):
        topic = f"/type_hash_check/t{index}"
        ros_client.node.create_publisher(message_class, topic, 1)
        (info,) = ros_client.node.get_publishers_info_by_topic(topic)
        assert logs.type_hash(msgtype) == str(info.topic_type_hash), msgtype
