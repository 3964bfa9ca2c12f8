"""The bounded result cloud (ros/clouds.py): which points are kept, layout unchanged."""

from __future__ import annotations

import numpy as np
import pytest

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
