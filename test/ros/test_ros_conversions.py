"""ros/conversions.py: rclpy messages from the field dicts of messages.py, and back."""

from __future__ import annotations

import array
import math

import numpy as np
import pytest
from ros_support import require_ros

require_ros()

from hexapod_workspace_msgs.msg import TiltTorsion, WorkspaceSummary  # noqa: E402
from hexapod_workspace_msgs.srv import CheckPoses  # noqa: E402
from rclpy.serialization import deserialize_message, serialize_message  # noqa: E402
from sensor_msgs.msg import PointCloud2  # noqa: E402

from hexapod_workspace import check  # noqa: E402
from hexapod_workspace.core.base.resolution import WorkspaceKind  # noqa: E402
from hexapod_workspace.logs import messages  # noqa: E402
from hexapod_workspace.ros.conversions import (  # noqa: E402
    angles_from_orientations,
    margins_by_name,
    position_from_point,
    to_message,
)


def test_cloud_round_trip_through_cdr(rng):
    points = rng.normal(size=(100_000, 6))
    fields = messages.pointcloud_fields(points, frame_id="base", stamp_ns=1_700_000_000_123)
    cloud = to_message(PointCloud2, fields)
    assert isinstance(cloud.data, array.array)
    assert cloud.header.stamp.sec == 1700 and cloud.header.stamp.nanosec == 123
    assert [f.name for f in cloud.fields] == list(messages.POINT_FIELD_NAMES)
    back = deserialize_message(serialize_message(cloud), PointCloud2)
    np.testing.assert_array_equal(
        messages.pointcloud_to_array(back), points.astype(np.float32).astype(np.float64)
    )


def test_empty_cloud():
    fields = messages.pointcloud_fields(np.zeros((0, 6)), frame_id="base", stamp_ns=0)
    cloud = to_message(PointCloud2, fields)
    assert cloud.width == 0 and len(cloud.data) == 0
    assert messages.pointcloud_to_array(cloud).shape == (0, 6)


def test_check_response_with_nested_pose_checks(example, rng):
    angles = np.column_stack(
        (rng.uniform(-3, 3, 50), rng.uniform(0, 1.0, 50), rng.uniform(-0.5, 0.5, 50))
    )
    result = check(example, angles)
    response = to_message(CheckPoses.Response, messages.check_poses_response_fields(result))
    assert len(response.results) == 50
    for k, pose_check in enumerate(response.results):
        assert pose_check.reachable == bool(result.reachable[k])
        assert list(pose_check.violated) == result.violated[k]
        assert margins_by_name(pose_check)["platform_joint"] == result.margins["platform_joint"][k]
        assert pose_check.limiting_leg == result.limiting_leg[k]


def test_failed_summary_keeps_nan_fields():
    fields = messages.summary_fields(
        None,
        stamp_ns=5,
        frame_id="base",
        kind=WorkspaceKind.ORIENTATION,
        position=np.zeros(3),
        message="bad",
    )
    summary = to_message(WorkspaceSummary, fields)
    assert not summary.success and summary.message == "bad"
    assert math.isnan(summary.tilt_max) and math.isnan(summary.volume)


def test_a_message_instance_passes_through_and_unknown_fields_are_refused():
    point = TiltTorsion(phi=1.0)
    assert to_message(TiltTorsion, point) is point
    with pytest.raises(KeyError):
        to_message(TiltTorsion, {"azimuth": 1.0})


def test_requests_to_arrays():
    request = CheckPoses.Request(
        orientations=[TiltTorsion(phi=0.1, theta=0.2, psi=0.3), TiltTorsion(theta=math.nan)]
    )
    request.position.z = -1.3
    angles = angles_from_orientations(request.orientations)
    assert angles.shape == (2, 3)
    np.testing.assert_array_equal(angles[0], [0.1, 0.2, 0.3])
    assert math.isnan(angles[1, 1])
    assert angles_from_orientations([]).shape == (0, 3)
    np.testing.assert_array_equal(position_from_point(request.position), [0.0, 0.0, -1.3])


def _interface_types() -> list[tuple[str, type]]:
    """(recorded type name, rclpy class) of every message and service part of
    hexapod_workspace_msgs, from the definitions the package ships."""
    import hexapod_workspace_msgs.msg as msg_module
    import hexapod_workspace_msgs.srv as srv_module

    from hexapod_workspace._resources import data_dir

    found = []
    for path in sorted(data_dir("msg").glob("*.msg")):
        found.append((f"hexapod_workspace_msgs/msg/{path.stem}", getattr(msg_module, path.stem)))
    for path in sorted(data_dir("srv").glob("*.srv")):
        service = getattr(srv_module, path.stem)
        for part in ("Request", "Response"):
            found.append(
                (f"hexapod_workspace_msgs/srv/msg/{path.stem}_{part}", getattr(service, part))
            )
    return found


@pytest.mark.parametrize(("name", "cls"), _interface_types(), ids=lambda v: str(v).split("/")[-1])
def test_every_default_message_reads_back_with_rosbags(name, cls):
    """rclpy's CDR of every message, as the node records it, decodes with rosbags (the logs'
    reader): an empty float64[] that is not followed by an 8-byte field is sized 4-8 bytes
    longer by rclpy than it writes, which rosbags refuses, so no message may end with one."""
    from hexapod_workspace.logs.typestore import get_typestore

    decoded = get_typestore().deserialize_cdr(serialize_message(cls()), name)
    assert type(decoded).__name__ == name.replace("/", "__")
