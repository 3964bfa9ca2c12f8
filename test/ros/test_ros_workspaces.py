"""Workspace services and topics of workspace_node over real Fast DDS.

Summaries and boundary clouds received from the node (another process) are compared with the
ROS-free core computed here with the same parameters file.
"""

from __future__ import annotations

import math
import os
import signal
import time
from pathlib import Path

import numpy as np
import pytest
from ros_support import require_ros

require_ros()

from hexapod_workspace_msgs.msg import (  # noqa: E402
    TiltTorsion,
    WorkspaceRequest,
    WorkspaceSummary,
)
from hexapod_workspace_msgs.srv import CheckPoses, ComputeWorkspace  # noqa: E402
from sensor_msgs.msg import PointCloud2, PointField  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from hexapod_workspace.core.orientation import orientation_workspace  # noqa: E402
from hexapod_workspace.core.projected import projected_workspace  # noqa: E402
from hexapod_workspace.core.resolution import WorkspaceKind  # noqa: E402
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


def compute(client, request: WorkspaceRequest) -> ComputeWorkspace.Response:
    return client.call(
        ComputeWorkspace, f"{NODE}/compute_workspace", ComputeWorkspace.Request(request=request)
    )


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
    clouds = client.collect(PointCloud2, CLOUD_TOPIC[kind])
    client.spin_until(
        lambda: client.node.count_publishers(f"{NODE}/workspace_summary") > 0
        and client.node.count_publishers(CLOUD_TOPIC[kind]) > 0,
        what="the node's publishers",
    )
    response = client.call(Trigger, f"{NODE}/{service}", Trigger.Request())
    assert response.success, response.message
    client.spin_until(
        lambda: any(s.kind == kind and s.message == response.message for s in summaries)
        and len(clouds) > 0,
        what=f"summary and cloud of {service}",
    )
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


# ---------------------------------------------------------------------------- request topic


def test_workspace_request_topic_publishes_results(client, model):
    expected = core_workspace(model, WorkspaceKind.PROJECTED_TORSION_ZERO)
    summaries = client.collect(WorkspaceSummary, f"{NODE}/workspace_summary")
    clouds = client.collect(PointCloud2, f"{NODE}/projected_workspace")
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


def test_pose_checks_are_answered_during_a_long_computation(client, model):
    """A 3-D workspace computation (workspace callback group, worker process) does not hold up
    check_poses (check group, multi-threaded executor): checks are answered before it ends."""
    request = ComputeWorkspace.Request(
        request=workspace_request(
            WorkspaceKind.ORIENTATION, n_rays=180, psi_step=0.01, tolerance=1e-6
        )
    )
    long_call = client.client(ComputeWorkspace, f"{NODE}/compute_workspace").call_async(request)
    # let the request reach the node (not an assertion: a slow delivery only weakens the test)
    deadline = time.monotonic() + 0.5
    while time.monotonic() < deadline:
        client.executor.spin_once(timeout_sec=0.05)
    check_client = client.client(CheckPoses, f"{NODE}/check_poses")
    pose = CheckPoses.Request(orientations=[TiltTorsion(phi=0.1, theta=0.2, psi=0.0)])
    pose.position.z = -1.3
    answered_during = 0
    for _ in range(20):
        future = check_client.call_async(pose)
        client.executor.spin_until_future_complete(future, timeout_sec=60.0)
        assert future.done() and future.result().success
        if not long_call.done():
            answered_during += 1
    if answered_during == 0:
        pytest.skip("the computation ended before the first check: nothing overlapped")
    assert answered_during > 0
    client.executor.spin_until_future_complete(long_call, timeout_sec=600.0)
    assert long_call.done()
    assert long_call.result().success, long_call.result().message


def worker_pids(node_pid: int) -> list[int]:
    """Child processes of the node (its workspace worker), from /proc."""
    children: list[int] = []
    for task in Path(f"/proc/{node_pid}/task").iterdir():
        text = (task / "children").read_text().split()
        children += [int(pid) for pid in text]
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
