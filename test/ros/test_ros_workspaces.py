"""Workspace action, services and topics of workspace_node over real Fast DDS.

Summaries and boundary clouds received from the node (another process) are compared with the
ROS-free core computed here with the same parameters file.
"""

from __future__ import annotations

import contextlib
import itertools
import math
import os
import signal
import time
from pathlib import Path

import numpy as np
import pytest
from ros_support import require_ros

require_ros()

from action_msgs.msg import GoalStatus  # noqa: E402
from hexapod_workspace_msgs.action import ComputeWorkspace  # noqa: E402
from hexapod_workspace_msgs.msg import (  # noqa: E402
    TiltTorsion,
    WorkspaceRequest,
    WorkspaceSummary,
)
from hexapod_workspace_msgs.srv import CheckPoses  # noqa: E402
from sensor_msgs.msg import PointCloud2, PointField  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from hexapod_workspace.core.base.resolution import WorkspaceKind  # noqa: E402
from hexapod_workspace.core.workspaces.orientation import orientation_workspace  # noqa: E402
from hexapod_workspace.core.workspaces.projected import projected_workspace  # noqa: E402
from hexapod_workspace.logs import messages  # noqa: E402

NODE = "/hexapod_workspace"
N_PHI, N_RAYS, PSI_STEP, TOLERANCE = 72, 24, 0.05, 1e-4
NODE_PARAMS = {
    "resolution.n_phi": N_PHI,
    "resolution.n_rays": N_RAYS,
    "resolution.psi_step": PSI_STEP,
    "resolution.tolerance": TOLERANCE,
}
HOME = (0.0, 0.0, -1.3)
CLOUD_TOPIC = {
    WorkspaceKind.ORIENTATION: f"{NODE}/orientation_workspace",
    WorkspaceKind.PROJECTED_TORSION_ZERO: f"{NODE}/projected_workspace",
    WorkspaceKind.PROJECTED_EXACT: f"{NODE}/projected_workspace",
}


def core_workspace(model, kind, position=HOME, n_rays=0, psi_step=0.0, tolerance=0.0):
    """The core's result for a request with the node's resolution defaults."""
    tolerance = tolerance or TOLERANCE
    if kind == WorkspaceKind.ORIENTATION:
        return orientation_workspace(
            model,
            position,
            n_rays=n_rays or N_RAYS,
            psi_step=psi_step or PSI_STEP,
            tolerance=tolerance,
        )
    return projected_workspace(
        model,
        position,
        method=WorkspaceKind(kind).label,
        n_phi=n_rays or N_PHI,
        tolerance=tolerance,
    )


def workspace_request(kind, position=HOME, request_id="", n_rays=0, psi_step=0.0, tolerance=0.0):
    request = WorkspaceRequest(
        kind=kind, request_id=request_id, n_rays=n_rays, psi_step=psi_step, tolerance=tolerance
    )
    request.position.x, request.position.y, request.position.z = (float(v) for v in position)
    return request


def compute(client, request: WorkspaceRequest, feedback=None) -> ComputeWorkspace.Result:
    """Run the ~/compute_workspace action (rclpy ActionClient) to its end."""
    return client.compute(f"{NODE}/compute_workspace", request, feedback)


def assert_cloud_matches(cloud: PointCloud2, workspace, frame_id: str) -> None:
    """Fields, layout and points of a boundary cloud against the core's boundary points."""
    assert cloud.header.frame_id == frame_id
    assert [f.name for f in cloud.fields] == ["x", "y", "z", "phi", "theta", "psi"]
    assert all(f.datatype == PointField.FLOAT32 and f.count == 1 for f in cloud.fields)
    assert [f.offset for f in cloud.fields] == [0, 4, 8, 12, 16, 20]
    assert cloud.point_step == 24
    assert cloud.height == 1
    assert not cloud.is_bigendian
    expected = messages.boundary_points(workspace).astype(np.float32)
    assert cloud.width == expected.shape[0] > 0
    np.testing.assert_allclose(messages.pointcloud_to_array(cloud), expected, atol=1e-6)


def assert_summary_matches(summary: WorkspaceSummary, workspace, kind: int) -> None:
    assert summary.success, summary.message
    assert summary.kind == kind
    assert summary.reference_reachable
    np.testing.assert_allclose(
        [summary.position.x, summary.position.y, summary.position.z], workspace.position
    )
    assert summary.tolerance == pytest.approx(workspace.tolerance)
    if kind == WorkspaceKind.ORIENTATION:
        assert summary.psi_min == pytest.approx(workspace.psi_min, abs=1e-12)
        assert summary.psi_max == pytest.approx(workspace.psi_max, abs=1e-12)
        assert summary.volume == pytest.approx(workspace.volume, rel=1e-9)
        assert math.isnan(summary.tilt_max)
    else:
        assert summary.tilt_min == pytest.approx(workspace.tilt_min, abs=1e-12)
        assert summary.tilt_max == pytest.approx(workspace.tilt_max, abs=1e-12)
        assert summary.solid_angle == pytest.approx(workspace.solid_angle, rel=1e-9)
        assert math.isnan(summary.psi_max)
    assert summary.message == messages.summary_line(summary)


# ---------------------------------------------------------------------------- ComputeWorkspace


@pytest.mark.parametrize(
    "kind",
    [
        WorkspaceKind.PROJECTED_TORSION_ZERO,
        WorkspaceKind.PROJECTED_EXACT,
        WorkspaceKind.ORIENTATION,
    ],
    ids=["torsion_zero", "exact", "orientation"],
)
def test_compute_workspace_matches_core(client, model, kind):
    expected = core_workspace(model, kind)
    response = compute(client, workspace_request(kind, request_id=f"kind-{kind}"))
    assert response.success, response.message
    assert response.message == response.summary.message
    assert response.summary.request_id == f"kind-{kind}"
    assert_summary_matches(response.summary, expected, kind)
    assert response.summary.n_points == response.boundary.width
    assert response.summary.header.stamp == response.boundary.header.stamp
    assert_cloud_matches(response.boundary, expected, model.frame_id)


def test_compute_workspace_at_another_position_with_own_resolution(client, model):
    position = (0.05, -0.05, -1.25)
    expected = core_workspace(
        model, WorkspaceKind.PROJECTED_TORSION_ZERO, position, n_rays=40, tolerance=1e-6
    )
    request = workspace_request(
        WorkspaceKind.PROJECTED_TORSION_ZERO, position, n_rays=40, tolerance=1e-6
    )
    response = compute(client, request)
    assert response.summary.n_rays == 40
    assert_summary_matches(response.summary, expected, WorkspaceKind.PROJECTED_TORSION_ZERO)
    assert_cloud_matches(response.boundary, expected, model.frame_id)


@pytest.mark.parametrize(
    ("request_fields", "reason"),
    [
        ({"position": (math.nan, 0.0, -1.3)}, "finite"),
        ({"position": (0.0, math.inf, -1.3)}, "finite"),
        ({"n_rays": 100_000}, "n_rays"),
        ({"tolerance": math.nan}, "tolerance"),
        ({"tolerance": 0.5}, "tolerance"),
        ({"psi_step": math.inf, "kind": WorkspaceKind.ORIENTATION}, "psi_step"),
        ({"kind": 9}, "kind"),
    ],
    ids=["nan-pos", "inf-pos", "too-many-rays", "nan-tol", "coarse-tol", "inf-step", "kind"],
)
def test_compute_workspace_refuses_bad_requests(client, request_fields, reason):
    fields = {"kind": WorkspaceKind.PROJECTED_TORSION_ZERO, **request_fields}
    response = compute(client, workspace_request(**fields))
    assert not response.success
    assert reason in response.message
    assert not response.summary.success
    assert response.boundary.width == 0


@pytest.mark.parametrize("frame_id", ["work", "world"])
def test_compute_workspace_refuses_a_position_in_another_frame(client, frame_id):
    """A workspace is computed about the base frame's axes at a base-frame position: a request
    in another frame is refused with the reason, not answered for another point."""
    request = workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO)
    request.header.frame_id = frame_id
    response = compute(client, request)
    assert not response.success
    assert "header.frame_id" in response.message and repr(frame_id) in response.message
    assert response.boundary.width == 0
    request.header.frame_id = ""  # the base frame, by default: served
    assert compute(client, request).success


def test_unreachable_reference_is_an_empty_workspace_not_a_crash(client):
    # platform in the base plane: every leg far below its minimum length
    response = compute(client, workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, (0, 0, 0)))
    assert not response.success
    assert not response.summary.reference_reachable
    assert response.boundary.width == 0
    assert response.message
    # and the node still serves
    assert compute(client, workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO)).success


# ---------------------------------------------------------------------------- Trigger services


@pytest.mark.parametrize(
    ("service", "kind"),
    [
        ("compute_projected_workspace", WorkspaceKind.PROJECTED_TORSION_ZERO),
        ("compute_orientation_workspace", WorkspaceKind.ORIENTATION),
    ],
)
def test_trigger_publishes_cloud_and_summary(client, model, service, kind):
    expected = core_workspace(model, kind, tuple(model.position))
    summaries = client.collect(WorkspaceSummary, f"{NODE}/workspace_summary")
    # transient local, as the README asks of a cloud subscriber: the cloud comes from the
    # worker's node, which may discover a new reader after it has published
    clouds = client.collect(PointCloud2, CLOUD_TOPIC[kind], transient_local=True)
    client.spin_until(
        lambda: client.node.count_publishers(f"{NODE}/workspace_summary") > 0
        and client.node.count_publishers(CLOUD_TOPIC[kind]) > 0,
        what="the node's publishers",
    )
    response = client.call(Trigger, f"{NODE}/{service}", Trigger.Request())
    assert response.success, response.message

    def summary_and_cloud() -> bool:
        stamps = {
            s.header.stamp.sec * 10**9 + s.header.stamp.nanosec
            for s in summaries
            if s.kind == kind and s.message == response.message
        }
        return any(c.header.stamp.sec * 10**9 + c.header.stamp.nanosec in stamps for c in clouds)

    client.spin_until(summary_and_cloud, what=f"summary and cloud of {service}")
    summary = next(s for s in summaries if s.message == response.message)
    assert_summary_matches(summary, expected, kind)
    cloud = next(c for c in clouds if c.header.stamp == summary.header.stamp)
    assert_cloud_matches(cloud, expected, model.frame_id)


def test_late_subscriber_gets_the_last_result(client, model):
    """Transient-local results: a subscriber created after the computation still gets it."""
    response = compute(client, workspace_request(WorkspaceKind.PROJECTED_EXACT, request_id="late"))
    assert response.success, response.message
    summaries = client.collect(WorkspaceSummary, f"{NODE}/workspace_summary", transient_local=True)
    clouds = client.collect(PointCloud2, f"{NODE}/projected_workspace", transient_local=True)
    client.spin_until(lambda: summaries and clouds, what="the latched summary and cloud")
    assert summaries[0].request_id == "late"
    assert summaries[0].header.stamp == clouds[0].header.stamp
    assert clouds[0].width == response.boundary.width


def test_failed_requests_leave_the_last_boundary_for_late_subscribers(client):
    """Failures publish their summary only; the transient-local cloud stays
    the last computed boundary, and an unknown kind's summary keeps its kind."""
    good = compute(client, workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, request_id="ok"))
    assert good.success and good.boundary.width > 0, good.message
    failures = [
        workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, (math.nan, 0, 0), "nan"),
        workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, (0, 0, 0), "unreachable"),
    ]
    for request in failures:
        assert not compute(client, request).success
    late = client.collect(PointCloud2, f"{NODE}/projected_workspace", transient_local=True)
    client.spin_until(lambda: late, what="the latched cloud")
    assert late[-1].width == good.boundary.width
    assert late[-1].header.stamp == good.summary.header.stamp
    summaries = client.collect(WorkspaceSummary, f"{NODE}/workspace_summary")
    publisher = client.publisher(WorkspaceRequest, f"{NODE}/workspace_request")
    publisher.publish(workspace_request(7, request_id="kind-7"))
    client.spin_until(
        lambda: any(s.request_id == "kind-7" for s in summaries), what="the kind-7 summary"
    )
    failed = next(s for s in summaries if s.request_id == "kind-7")
    assert (failed.kind, failed.success) == (7, False)
    assert "kind: expected 0 (orientation)" in failed.message


# ---------------------------------------------------------------------------- request topic


def test_workspace_request_topic_publishes_results(client, model):
    expected = core_workspace(model, WorkspaceKind.PROJECTED_TORSION_ZERO)
    summaries = client.collect(WorkspaceSummary, f"{NODE}/workspace_summary")
    clouds = client.collect(PointCloud2, f"{NODE}/projected_workspace", transient_local=True)
    publisher = client.publisher(WorkspaceRequest, f"{NODE}/workspace_request")
    publisher.publish(workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, request_id="topic-1"))
    bad = workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, (math.nan, 0, 0), "topic-bad")
    publisher.publish(bad)
    client.spin_until(
        lambda: {"topic-1", "topic-bad"} <= {s.request_id for s in summaries},
        what="summaries of both requests",
    )
    by_id = {s.request_id: s for s in summaries}
    assert_summary_matches(by_id["topic-1"], expected, WorkspaceKind.PROJECTED_TORSION_ZERO)
    assert not by_id["topic-bad"].success
    assert "finite" in by_id["topic-bad"].message
    client.spin_until(
        lambda: any(c.header.stamp == by_id["topic-1"].header.stamp for c in clouds),
        what="the cloud of the request",
    )


# ---------------------------------------------------------------------------- responsiveness


#: A 3-D request that takes far longer than the checks below (it is canceled once they are done).
LONG = {"n_rays": 720, "psi_step": 0.001, "tolerance": 1e-9}


def wait_for_stage(client, feedback: list, stage: str) -> None:
    client.spin_until(
        lambda: any(f.stage == stage for f in feedback), what=f"feedback stage {stage!r}"
    )


def test_pose_checks_are_answered_during_a_long_computation(client, model):
    """A 3-D workspace computation (job thread, worker process) does not hold up check_poses:
    every check is answered while the goal is still computing (no result yet)."""
    feedback: list = []
    handle = client.send_goal(
        f"{NODE}/compute_workspace",
        workspace_request(WorkspaceKind.ORIENTATION, request_id="long", **LONG),
        feedback,
    )
    result_future = handle.get_result_async()
    wait_for_stage(client, feedback, "computing")
    check_client = client.client(CheckPoses, f"{NODE}/check_poses")
    pose = CheckPoses.Request(orientations=[TiltTorsion(phi=0.1, theta=0.2, psi=0.0)])
    pose.position.z = -1.3
    for _ in range(20):
        future = check_client.call_async(pose)
        client.executor.spin_until_future_complete(future, timeout_sec=60.0)
        assert future.done() and future.result().success
    assert not result_future.done(), "the computation ended before the checks: make LONG longer"
    handle.cancel_goal_async()
    client.spin_until(result_future.done, what="the canceled goal's result")
    assert result_future.result().status == GoalStatus.STATUS_CANCELED


def test_action_progress_is_monotonic_and_ends_at_one(client, model):
    feedback: list = []
    request = workspace_request(WorkspaceKind.ORIENTATION, request_id="progress", psi_step=0.02)
    status, result = client.goal_result(
        client.send_goal(f"{NODE}/compute_workspace", request, feedback)
    )
    assert status == GoalStatus.STATUS_SUCCEEDED and result.success, result.message
    progress = [f.progress for f in feedback]
    assert len(progress) >= 3
    assert all(0.0 <= p <= 1.0 for p in progress)
    assert all(b >= a for a, b in itertools.pairwise(progress))
    assert {"queued", "computing"} <= {f.stage for f in feedback}
    expected = core_workspace(model, WorkspaceKind.ORIENTATION, psi_step=0.02)
    assert_summary_matches(result.summary, expected, WorkspaceKind.ORIENTATION)


def test_cancel_stops_the_computation_and_the_node_keeps_serving(client, workspace_node):
    feedback: list = []
    handle = client.send_goal(
        f"{NODE}/compute_workspace",
        workspace_request(WorkspaceKind.ORIENTATION, request_id="cancel-me", **LONG),
        feedback,
    )
    wait_for_stage(client, feedback, "computing")
    (worker,) = worker_pids(workspace_node.process.pid)
    cancel = handle.cancel_goal_async()
    client.spin_until(cancel.done, what="the cancel response")
    assert len(cancel.result().goals_canceling) == 1
    status, result = client.goal_result(handle)
    assert status == GoalStatus.STATUS_CANCELED
    assert not result.success and result.message == "canceled"
    # the worker stopped computing: it waits for the next job (or was replaced)
    # A computing worker is never asleep (R, or waiting for a CPU on a loaded machine, which is
    # R too); one that waits for its next job sleeps (S). One sample can catch it between the
    # two (sending its reply), so it is sampled until it sleeps; the bound only ends a hang.
    if worker in worker_pids(workspace_node.process.pid):
        deadline = time.monotonic() + 60.0
        while process_state(worker) != "S" and time.monotonic() < deadline:
            time.sleep(0.05)
        assert process_state(worker) == "S", "the worker still computes after the cancel"
    response = compute(client, workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO))
    assert response.success, response.message


def test_goals_queue_in_order_and_a_queued_goal_can_be_canceled(client):
    first_feedback: list = []
    first = client.send_goal(
        f"{NODE}/compute_workspace",
        workspace_request(WorkspaceKind.ORIENTATION, request_id="first", **LONG),
        first_feedback,
    )
    wait_for_stage(client, first_feedback, "computing")
    queued_feedback: list = []
    queued = client.send_goal(
        f"{NODE}/compute_workspace",
        workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, request_id="queued"),
        queued_feedback,
    )
    third = client.send_goal(
        f"{NODE}/compute_workspace",
        workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, request_id="third"),
    )
    wait_for_stage(client, queued_feedback, "queued")
    cancel = queued.cancel_goal_async()
    client.spin_until(cancel.done, what="the cancel response")
    status, result = client.goal_result(queued)
    assert status == GoalStatus.STATUS_CANCELED and result.message == "canceled"
    assert not any(f.stage == "computing" for f in queued_feedback), "a canceled goal ran"
    first.cancel_goal_async()
    assert client.goal_result(first)[0] == GoalStatus.STATUS_CANCELED
    status, result = client.goal_result(third)
    assert status == GoalStatus.STATUS_SUCCEEDED and result.summary.request_id == "third"


def test_invalid_goal_is_aborted_with_the_reason(client):
    request = workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, (math.nan, 0, 0))
    status, result = client.goal_result(client.send_goal(f"{NODE}/compute_workspace", request))
    assert status == GoalStatus.STATUS_ABORTED
    assert not result.success and "position" in result.message and "finite" in result.message


def process_state(pid: int) -> str:
    """The scheduler state letter of a process (R running, S sleeping, ...), from /proc."""
    return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]


def worker_pids(node_pid: int) -> list[int]:
    """The node's workspace worker processes (multiprocessing spawn children), from /proc."""
    children: list[int] = []
    for task in Path(f"/proc/{node_pid}/task").iterdir():
        for pid in map(int, (task / "children").read_text().split()):
            with contextlib.suppress(OSError):
                if b"spawn_main" in Path(f"/proc/{pid}/cmdline").read_bytes():
                    children.append(pid)
    return children


def test_a_killed_worker_process_is_replaced(client, workspace_node):
    """The computation process dies (OOM killer, a bug): the node keeps serving and starts a
    new one for the next request."""
    assert compute(client, workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO)).success
    pids = worker_pids(workspace_node.process.pid)
    assert pids, "the node has no worker process"
    for pid in pids:
        os.kill(pid, signal.SIGKILL)
    response = compute(
        client, workspace_request(WorkspaceKind.PROJECTED_TORSION_ZERO, request_id="w")
    )
    assert response.success, response.message
    assert response.summary.request_id == "w"
    assert set(worker_pids(workspace_node.process.pid)).isdisjoint(pids)


def test_an_atlas_goal_runs_in_the_node_while_checks_are_answered(client):
    """~/compute_atlas is attached to the workspace node (an extension); its blocking run is in a
    thread of its own (ros.jobs.in_thread), so the single-threaded executor keeps answering."""
    from hexapod_workspace_msgs.action import ComputeAtlas
    from rclpy.action import ActionClient

    atlas = ActionClient(client.node, ComputeAtlas, f"{NODE}/compute_atlas")
    try:
        assert atlas.wait_for_server(timeout_sec=60)
        goal = ComputeAtlas.Goal(box=[-0.1, 0.1, -0.1, 0.1, -1.35, -1.2], step=0.05, n_phi=24)
        goal.tolerance = 1e-3
        feedback: list = []
        sent = atlas.send_goal_async(goal, feedback_callback=lambda m: feedback.append(m))
        client.spin_until(sent.done, what="the atlas goal response")
        result = sent.result().get_result_async()
        client.spin_until(lambda: bool(feedback), what="atlas feedback")
        pose = CheckPoses.Request(orientations=[TiltTorsion(phi=0.1, theta=0.2, psi=0.0)])
        pose.position.z = -1.3
        answered_during = 0
        for _ in range(10):
            response = client.call(CheckPoses, f"{NODE}/check_poses", pose)
            assert response.success
            answered_during += not result.done()
        client.spin_until(result.done, what="the atlas result", timeout=600)
        assert result.result().status == GoalStatus.STATUS_SUCCEEDED, result.result().result
        assert result.result().result.positions == 5 * 5 * 4
        print(f"{answered_during} of 10 checks answered while the atlas ran")
        assert answered_during > 0, "no check was answered while the atlas ran (blocked?)"
    finally:
        atlas.destroy()
