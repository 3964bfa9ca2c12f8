"""The bounded result cloud (ros/clouds.py): which points are kept, layout unchanged."""

from __future__ import annotations

import numpy as np
import pytest

from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.logs import messages
from hexapod_workspace.ros.clouds import decimated_cloud_fields


def cloud(count: int) -> tuple[np.ndarray, dict]:
    points = np.arange(count * 6, dtype=float).reshape(count, 6)
    return points, messages.pointcloud_fields(points, frame_id="base", stamp_ns=7)


@pytest.mark.parametrize("limit", [0, 10, 11])
def test_a_cloud_within_the_bound_is_returned_as_it_is(limit):
    _, fields = cloud(10)
    assert decimated_cloud_fields(fields, limit) is fields


@pytest.mark.parametrize(("count", "limit"), [(1000, 7), (274_000, 20_000), (11, 10)])
def test_decimation_keeps_evenly_spaced_points_first_and_last(count, limit):
    points, fields = cloud(count)
    bounded = decimated_cloud_fields(fields, limit)
    back = messages.pointcloud_to_array(bounded)
    assert bounded["width"] == limit == back.shape[0]
    assert bounded["row_step"] == 24 * limit
    assert len(bounded["data"]) == 24 * limit
    assert bounded["header"] == fields["header"] and bounded["fields"] == fields["fields"]
    expected = points[np.linspace(0, count - 1, limit).round().astype(int)].astype(np.float32)
    np.testing.assert_array_equal(back, expected)
    np.testing.assert_array_equal(back[[0, -1]], points[[0, -1]].astype(np.float32))


@pytest.mark.parametrize(("record", "record_points"), [(True, 7), (True, 0), (False, 7)])
def test_the_worker_hands_the_log_a_cloud_bounded_to_record_points(
    ros_domain, record, record_points
):
    """The worker publishes the full cloud and hands back for the log the CDR bytes of a cloud
    of at most ``record_points`` points (``recording.cloud_points``), the full one (0), or
    nothing when the node does not record: the node's process never holds a large cloud."""
    from rclpy.serialization import deserialize_message
    from sensor_msgs.msg import PointCloud2

    from hexapod_workspace._resources import example_config_path
    from hexapod_workspace.core.base.resolution import WorkspaceKind
    from hexapod_workspace.ros.clouds import CloudTopics
    from hexapod_workspace.ros.worker import WorkspaceJob, WorkspaceWorker

    topic = "/clouds_test/projected_workspace"
    topics = {int(kind): topic for kind in WorkspaceKind}
    worker = WorkspaceWorker(cloud_topics=CloudTopics("clouds_test", "/", topics, ros_domain))
    job = WorkspaceJob(
        manipulator=load_manipulator(example_config_path()),
        kind=WorkspaceKind.PROJECTED_TORSION_ZERO,
        position=np.array([0.0, 0.0, -1.3]),
        n_rays=36,
        psi_step=0.05,
        tolerance=1e-4,
        stamp_ns=5,
        frame_id="base",
        record=record,
        record_points=record_points,
    )
    published: list = []
    try:
        _, full = worker.compute(job, published=published.append)  # result_points 0: all
    finally:
        worker.close()
    assert full["width"] > 7
    if not record:
        assert published == []
        return
    (cloud,) = published
    assert cloud.topic == topic
    recorded = deserialize_message(cloud.data, PointCloud2)
    expected = decimated_cloud_fields(full, record_points)
    assert recorded.width == (record_points or full["width"]) == expected["width"]
    assert bytes(recorded.data) == bytes(expected["data"])
    assert (recorded.header.frame_id, recorded.header.stamp.nanosec) == ("base", 5)
