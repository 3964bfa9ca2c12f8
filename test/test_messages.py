"""Tests of logs.messages: results -> ROS field dicts -> CDR -> back (ROS-free)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from recording_support import NAN, plain

from hexapod_workspace import logs
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.base.resolution import WorkspaceKind
from hexapod_workspace.core.constraints.table import CONSTRAINT_NAMES
from hexapod_workspace.core.evaluation import check as constraints
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.core.model.manipulator import Manipulator
from hexapod_workspace.core.workspaces.orientation import OrientationSlice, OrientationWorkspace
from hexapod_workspace.core.workspaces.projected import ProjectedWorkspace
from hexapod_workspace.logs import messages


@pytest.fixture(scope="module")
def manipulator() -> Manipulator:
    return load_manipulator(example_config_path())


@pytest.fixture(scope="module")
def check_result(manipulator: Manipulator) -> constraints.CheckResult:
    angles = np.radians([[0.0, 0.0, 0.0], [30.0, 20.0, 5.0], [45.0, 80.0, 10.0]])
    return constraints.check(manipulator, angles)


def projected_stub(method: str = "torsion_zero", n: int = 36) -> ProjectedWorkspace:
    """A projected workspace built by hand (no algorithm needed): a real result dataclass."""
    phi = np.linspace(-math.pi, math.pi, n, endpoint=False)
    theta = 0.5 + 0.1 * np.cos(3 * phi)
    return ProjectedWorkspace(
        method=method,
        position=np.array([0.0, 0.0, 1.2]),
        phi=phi,
        theta=theta,
        psi=np.zeros(n) if method != "exact" else 0.1 * phi,
        tilt_min=float(theta.min()),
        tilt_max=float(theta.max()),
        solid_angle=1.234,
        tolerance=1e-6,
        elapsed=0.01,
        limiting=["leg_length"] * n,
    )


def orientation_stub() -> OrientationWorkspace:
    """An orientation workspace of three circular slices built by hand: a real dataclass."""
    phi = np.linspace(-math.pi, math.pi, 8, endpoint=False)
    slices = [
        OrientationSlice(psi=psi, center=np.zeros(2), phi=phi, theta=np.full(8, 0.4))
        for psi in (-0.1, 0.0, 0.1)
    ]
    return OrientationWorkspace(
        position=np.array([0.0, 0.0, 1.2]),
        slices=slices,
        psi_min=-0.1,
        psi_max=0.1,
        volume=0.05,
        n_rays=8,
        psi_step=0.1,
        tolerance=1e-5,
        elapsed=0.2,
    )


def roundtrip(msgtype: str, fields: dict) -> dict:
    return plain(logs.deserialize(msgtype, logs.serialize(msgtype, fields)))


def test_pose_check_fields_match_the_result(check_result: constraints.CheckResult) -> None:
    all_fields = messages.pose_checks_fields(check_result)
    assert len(all_fields) == len(check_result)
    for index, fields in enumerate(all_fields):
        assert fields == messages.pose_check_fields(check_result, index)
        assert fields["reachable"] == bool(check_result.reachable[index])
        assert fields["violated"] == check_result.violated[index]
        assert fields["constraint_names"] == list(check_result.margins)  # the model's rows
        for name, margin in zip(fields["constraint_names"], fields["margins"], strict=True):
            assert margin == check_result.margins[name][index]
        assert fields["limiting_leg"] == int(check_result.limiting_leg[index])
        assert roundtrip("hexapod_workspace_msgs/msg/PoseCheck", fields) == plain(fields)


def test_check_poses_request_and_response(check_result: constraints.CheckResult) -> None:
    request = messages.check_poses_request_fields(check_result.position, check_result.angles)
    assert len(request["orientations"]) == len(check_result)
    assert roundtrip("hexapod_workspace_msgs/srv/CheckPoses_Request", request) == plain(request)
    response = messages.check_poses_response_fields(check_result)
    reachable = int(check_result.reachable.sum())
    assert response["message"] == f"{reachable}/{len(check_result)} reachable"
    assert roundtrip("hexapod_workspace_msgs/srv/CheckPoses_Response", response) == plain(response)
    failed = messages.check_poses_response_fields(None, message="empty request")
    assert failed == {"success": False, "message": "empty request", "results": []}


def test_reachability_result_success_and_invalid(check_result: constraints.CheckResult) -> None:
    command = {
        "position": check_result.position,
        "angles": check_result.angles[2],
        "stamp_ns": 1_500_000_000_123,
        "frame_id": "base",
        "request_id": "cmd-7",
        "index": 2,
    }
    ok = messages.reachability_result_fields(check_result, **command)
    assert ok["success"] is True
    assert ok["header"] == {"stamp": {"sec": 1500, "nanosec": 123}, "frame_id": "base"}
    assert ok["check"]["reachable"] == bool(check_result.reachable[2])
    # the command stream's form: every pose's fields computed once for the whole result
    pose_checks = messages.pose_checks_fields(check_result)
    given = messages.reachability_result_fields(check_result, **command, check=pose_checks[2])
    assert given == ok
    assert ok["message"].startswith("unreachable: ")  # the pose's violated names in the verdict
    bad = messages.reachability_result_fields(
        None,
        position=[0, 0, 1],
        angles=[0, 0, 0],
        stamp_ns=0,
        frame_id="base",
        message="NaN in command",
        names=list(check_result.margins),
    )
    assert bad["success"] is False and bad["message"] == "NaN in command"
    # The model's rows (6-UPS: not actuator, ik, transmission or collision), all NaN.
    assert bad["check"]["constraint_names"] == list(check_result.margins)
    assert "actuator" not in bad["check"]["constraint_names"]
    assert all(math.isnan(margin) for margin in bad["check"]["margins"])
    decoded = roundtrip("hexapod_workspace_msgs/msg/ReachabilityResult", bad)
    assert decoded["check"]["margins"] == [NAN] * len(check_result.margins)
    assert decoded == plain(bad)
    unconfigured = messages.reachability_result_fields(
        None, position=[0, 0, 1], angles=[0, 0, 0], stamp_ns=0, frame_id="", message="inactive"
    )
    assert unconfigured["check"]["constraint_names"] == []
    assert unconfigured["check"]["margins"] == []


@pytest.mark.parametrize("method", ["torsion_zero", "exact"])
def test_projected_summary_and_boundary(method: str) -> None:
    workspace = projected_stub(method)
    kind = messages.workspace_kind(workspace)
    assert WorkspaceKind(kind).label == method
    points = messages.boundary_points(workspace)
    assert points.shape == (36, 6)
    np.testing.assert_allclose(np.linalg.norm(points[:, :3], axis=1), 1.0)
    np.testing.assert_allclose(points[:, 2], np.cos(workspace.theta))
    summary = messages.summary_fields(workspace, stamp_ns=5, frame_id="base", request_id="r")
    assert summary["tilt_max"] == workspace.tilt_max and summary["n_points"] == 36
    assert summary["n_rays"] == 36 and math.isnan(summary["psi_min"])
    assert "tilt" in summary["message"]
    assert roundtrip("hexapod_workspace_msgs/msg/WorkspaceSummary", summary) == plain(summary)
    request = messages.compute_workspace_request_fields(workspace, request_id="r")
    assert request["request"]["kind"] == kind and request["request"]["n_rays"] == 36


def test_orientation_summary_and_failure() -> None:
    workspace = orientation_stub()
    summary = messages.summary_fields(workspace, stamp_ns=5, frame_id="base")
    assert summary["kind"] == WorkspaceKind.ORIENTATION
    assert (summary["psi_min"], summary["psi_max"], summary["n_points"]) == (-0.1, 0.1, 24)
    assert math.isnan(summary["tilt_min"])
    failed = messages.summary_fields(
        None,
        stamp_ns=5,
        frame_id="base",
        kind=1,
        position=[0, 0, 3],
        reference_reachable=False,
        message="reference orientation unreachable",
    )
    assert failed["success"] is False and failed["reference_reachable"] is False
    assert failed["position"] == {"x": 0.0, "y": 0.0, "z": 3.0}
    assert messages.summary_line(failed).endswith("reference orientation unreachable")
    response = messages.compute_workspace_response_fields(
        None, stamp_ns=5, frame_id="base", summary=failed
    )
    decoded = roundtrip("hexapod_workspace_msgs/srv/ComputeWorkspace_Response", response)
    assert decoded["boundary"]["width"] == 0 and decoded["summary"]["success"] is False


def test_pointcloud_round_trip_float32_nan_and_empty() -> None:
    rng = np.random.default_rng(20261121)
    points = rng.normal(size=(1000, 6))
    points[3, 4] = np.nan
    fields = messages.pointcloud_fields(points, frame_id="base", stamp_ns=42)
    assert fields["point_step"] == 24 and fields["row_step"] == 24_000
    assert [f["name"] for f in fields["fields"]] == list(messages.POINT_FIELD_NAMES)
    assert fields["is_dense"] is False
    decoded = logs.deserialize(
        "sensor_msgs/msg/PointCloud2", logs.serialize("sensor_msgs/msg/PointCloud2", fields)
    )
    back = messages.pointcloud_to_array(decoded)
    np.testing.assert_array_equal(back, points.astype(np.float32).astype(float))
    np.testing.assert_array_equal(messages.pointcloud_to_array(fields), back)
    empty = messages.pointcloud_fields(np.zeros((0, 6)), frame_id="base", stamp_ns=0)
    assert messages.pointcloud_to_array(empty).shape == (0, 6)


def test_pointcloud_to_array_other_layouts() -> None:
    """float64, big-endian, padded, with extra and missing fields (sensor_msgs_py style)."""
    dtype = np.dtype([("x", ">f8"), ("pad", ">u4"), ("theta", ">f4"), ("intensity", ">f4")])
    cloud = np.zeros(3, dtype=dtype)
    cloud["x"], cloud["theta"] = [1.0, 2.0, 3.0], [0.1, 0.2, 0.3]
    fields = {
        "width": 3,
        "height": 1,
        "point_step": dtype.itemsize,
        "is_bigendian": True,
        "data": cloud.tobytes(),
        "fields": [
            {"name": "x", "offset": 0, "datatype": 8, "count": 1},
            {"name": "theta", "offset": 12, "datatype": 7, "count": 1},
            {"name": "intensity", "offset": 16, "datatype": 7, "count": 1},
        ],
    }
    back = messages.pointcloud_to_array(fields)
    np.testing.assert_array_equal(back[:, 0], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(back[:, 4], [0.1, 0.2, 0.3], rtol=1e-7)
    assert np.isnan(back[:, [1, 2, 3, 5]]).all()
    with pytest.raises(ValueError, match="expected"):
        messages.pointcloud_to_array({**fields, "data": cloud.tobytes()[:-1]})


def test_stamps_and_small_pieces() -> None:
    stamp = messages.stamp_fields(1_700_000_000_999_999_999)
    assert stamp == {"sec": 1_700_000_000, "nanosec": 999_999_999}
    assert messages.stamp_to_ns(stamp) == 1_700_000_000_999_999_999
    assert messages.tilt_torsion_fields([0.1, 0.2, 0.3]) == {"phi": 0.1, "theta": 0.2, "psi": 0.3}
    pose = messages.commanded_pose_fields([0.1, 0.2, 0.3], [0, 0, 1], request_id="c1")
    assert roundtrip("hexapod_workspace_msgs/msg/CommandedPose", pose) == plain(pose)
    request = messages.workspace_request_fields(WorkspaceKind.PROJECTED_EXACT, [0, 0, 1], n_rays=90)
    assert roundtrip("hexapod_workspace_msgs/msg/WorkspaceRequest", request) == plain(request)


def test_every_topic_type_is_in_the_typestore() -> None:
    for name, msgtype in messages.TYPES.items():
        if "/srv/" in msgtype:
            for part in ("_Request", "_Response"):
                assert logs.message_definition(msgtype + part) is not None, name
        else:
            assert logs.message_definition(msgtype), name


def test_pose_check_constants_are_the_constraint_table() -> None:
    """The string constants of PoseCheck.msg name exactly the constraints of the table."""
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "msg_defs/msg/PoseCheck.msg").read_text()
    constants = re.findall(r'^string ([A-Z_]+)="([a-z_]+)"', text, flags=re.MULTILINE)
    assert [value for _, value in constants] == list(CONSTRAINT_NAMES)
    assert all(name == value.upper() for name, value in constants)


def test_segment_check_fields_after_the_result_was_read(manipulator: Manipulator) -> None:
    """The PathSegmentCheck of one move is built from the dataclass fields only, also after
    the per-move lists the result keeps (``violated``) have been read."""
    from hexapod_workspace import check_path
    from hexapod_workspace.logs import paths as path_fields

    waypoints = manipulator.position + np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0]])
    angles = np.array([[0.0, 0.0, 0.0], [0.0, 1.2, 0.0]])  # the move ends out of reach
    segments = check_path(manipulator, waypoints, angles=angles).segments
    violated = segments.violated  # read first: kept on the result
    fields = path_fields.segment_check_fields(segments, 0)
    assert fields["violated"] == violated[0] != []
    assert fields["ok"] is False
