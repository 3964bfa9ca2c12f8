"""~/check_poses_flat over real Fast DDS: the verdicts of the core and of ~/check_poses in flat
arrays, refusals with the reason, and the calls recorded and read back (rosbags, replay)."""

from __future__ import annotations

import array
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from ros_support import INSTALL, require_ros, running_node

require_ros()

from hexapod_workspace_msgs.srv import CheckPoses, CheckPosesFlat  # noqa: E402
from test_ros_node import check_request, sample_angles  # noqa: E402

from hexapod_workspace import check, logs  # noqa: E402
from hexapod_workspace.core.evaluation.loading import load_manipulator  # noqa: E402
from hexapod_workspace.errors import InputError  # noqa: E402
from hexapod_workspace.logs.summary import summarize_log  # noqa: E402
from hexapod_workspace.ros.conversions import margins_by_name  # noqa: E402
from hexapod_workspace.ros.flat import angles_from_flat, flat_margins  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # test/recording_support.py
from recording_support import read_with_foxglove, read_with_rosbags_documented  # noqa: E402
from test_node_recording import NAMESPACES, node_args  # noqa: E402

#: The constraints of a 6-UPS model: the names the node gives for the example (the rows of the
#: constraint table that apply to it), as before the leg architectures.
CONSTRAINT_NAMES = ("leg_length", "base_joint", "platform_joint", "leg_interference", "singularity")

NAMESPACES.setdefault("flat", "/flat_log")  # node_args puts the node there

NODE = "/hexapod_workspace"
FLAT = f"{NODE}/check_poses_flat"
NODE_PARAMS = {"check.max_poses": 2000}


def flat_request(angles: np.ndarray, position=(0.0, 0.0, -1.3)) -> CheckPosesFlat.Request:
    request = CheckPosesFlat.Request()
    request.position.x, request.position.y, request.position.z = (float(v) for v in position)
    request.angles = np.asarray(angles, dtype=float).reshape(-1).tolist()
    return request


def margins_of(response: CheckPosesFlat.Response) -> np.ndarray:
    """Shape (N, K) from the flat answer, columns named by the answer itself."""
    names = list(response.constraint_names)
    return np.asarray(response.margins, dtype=float).reshape(-1, len(names))


def assert_flat_matches_core(response: CheckPosesFlat.Response, expected) -> None:
    assert response.success, response.message
    names = list(response.constraint_names)
    assert names == list(CONSTRAINT_NAMES)
    margins = margins_of(response)
    assert margins.shape == (len(expected), len(names))
    for k, name in enumerate(names):  # by name, float64 exactly
        np.testing.assert_array_equal(margins[:, k], expected.margins[name])
    np.testing.assert_array_equal(np.asarray(response.reachable, bool), expected.reachable)
    np.testing.assert_array_equal(np.asarray(response.limiting_leg), expected.limiting_leg)
    reachable = int(np.count_nonzero(expected.reachable))
    assert response.message == f"{reachable}/{len(expected)} reachable"


# ---------------------------------------------------------------------------- without DDS


def test_angles_from_flat_takes_the_rclpy_array_without_a_copy():
    values = array.array("d", [0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    angles = angles_from_flat(values, 10)
    assert angles.shape == (2, 3)
    np.testing.assert_array_equal(angles, [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]])
    values[0] = 9.0
    assert angles[0, 0] == 9.0  # a view of the message's buffer


@pytest.mark.parametrize(
    ("values", "reason"),
    [
        ([], "at least one pose"),
        ([0.1, 0.2], "3 values per pose"),
        ([0.0] * 33, "at most 10 poses"),
    ],
    ids=["empty", "not-3n", "too-many"],
)
def test_angles_from_flat_refuses_with_the_reason(values, reason):
    with pytest.raises(InputError, match=reason):
        angles_from_flat(array.array("d", values), 10)


def test_flat_margins_columns_follow_the_constraint_names(model_from_file):
    angles = sample_angles(20)
    result = check(model_from_file, angles, model_from_file.position)
    margins = flat_margins(result)
    assert margins.shape == (20, len(CONSTRAINT_NAMES))
    for k, name in enumerate(CONSTRAINT_NAMES):
        np.testing.assert_array_equal(margins[:, k], result.margins[name])


@pytest.fixture(scope="module")
def model_from_file():
    from hexapod_workspace._resources import example_config_path

    return load_manipulator(example_config_path())


# ---------------------------------------------------------------------------- over DDS


def test_flat_check_matches_core_and_the_nested_form(client, model):
    angles = sample_angles(1000, seed=11)
    expected = check(model, angles, model.position)
    assert 0 < np.count_nonzero(expected.reachable) < len(expected), "need both verdicts"
    flat = client.call(CheckPosesFlat, FLAT, flat_request(angles))
    assert_flat_matches_core(flat, expected)
    nested = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles))
    assert nested.success, nested.message
    for k, name in enumerate(flat.constraint_names):
        got = np.array([margins_by_name(r)[name] for r in nested.results])
        np.testing.assert_array_equal(margins_of(flat)[:, k], got)
    assert flat.message == nested.message


def test_flat_check_at_another_position(client, model):
    angles = sample_angles(40, seed=3)
    position = (0.2, 0.2, -0.95)
    flat = client.call(CheckPosesFlat, FLAT, flat_request(angles, position))
    assert_flat_matches_core(flat, check(model, angles, position))


@pytest.mark.parametrize(
    ("values", "position", "reason"),
    [
        ([], (0.0, 0.0, -1.3), "at least one pose"),
        ([0.1, 0.2, 0.3, 0.4], (0.0, 0.0, -1.3), "got 4 values"),
        ([0.0, math.nan, 0.0], (0.0, 0.0, -1.3), "finite"),
        ([0.0, 0.1, 0.0], (0.0, math.inf, -1.3), "finite"),
        ([0.0] * 3 * 2001, (0.0, 0.0, -1.3), "at most 2000"),
    ],
    ids=["empty", "not-3n", "nan", "inf-position", "too-many"],
)
def test_flat_check_refuses_bad_requests(client, values, position, reason):
    response = client.call(CheckPosesFlat, FLAT, flat_request(np.array(values), position))
    assert not response.success
    assert reason in response.message, response.message
    assert len(response.margins) == 0
    assert len(response.reachable) == 0
    assert list(response.constraint_names) == list(CONSTRAINT_NAMES)


def test_flat_calls_are_recorded_and_read_back(ros_client, tmp_path, model):
    """Request and answer on <service>/request and /response as the message twins: rosbags'
    documented API and Foxglove's libraries decode them, the replay summary pairs them."""
    angles = sample_angles(25, seed=5)
    name, args = node_args("flat", tmp_path)  # a node of its own, beside the module's
    service = f"{name}/check_poses_flat"
    with running_node(tmp_path, extra_args=args) as node:
        answer = ros_client.call(CheckPosesFlat, service, flat_request(angles))
        # a refused request without poses is recorded too, and reads back (its empty float64[]
        # comes first in the message: see CheckPosesFlatRequest.msg)
        empty = ros_client.call(CheckPosesFlat, service, CheckPosesFlat.Request())
        ros_client.drop_client(service)
        assert node.stop() == 0, node.output()
    assert answer.success, answer.message
    assert not empty.success and "at least one pose" in empty.message
    # the node (a child of this process, which set NUMBA_CACHE_DIR for the source tree) loads
    # the kernels the install space was built with, from the install space's cache
    assert f"(compiled-code cache: {INSTALL}/" in node.output(), node.output()
    (log,) = (tmp_path / "logs").glob("*.mcap")
    request_topic, response_topic = logs.service_topics(service)
    everything = read_with_rosbags_documented(log)
    requests = [m for topic, _, m in everything if topic == request_topic]
    assert [len(r.angles) for r in requests] == [angles.size, 0]
    np.testing.assert_array_equal(requests[0].angles, angles.reshape(-1))
    # the first answer (the dict keeps each topic's first message)
    decoded: dict[str, tuple[str, object]] = {}
    for topic, msgtype, m in everything:
        decoded.setdefault(topic, (msgtype, m))
    assert decoded[request_topic][0] == "hexapod_workspace_msgs/msg/CheckPosesFlatRequest"
    msgtype, response = decoded[response_topic]
    assert msgtype == "hexapod_workspace_msgs/msg/CheckPosesFlatResponse"
    assert list(response.constraint_names) == list(CONSTRAINT_NAMES)
    np.testing.assert_array_equal(response.margins, np.asarray(answer.margins))
    np.testing.assert_array_equal(response.reachable, np.asarray(answer.reachable))
    foxglove = read_with_foxglove(log, tmp_path)
    assert foxglove[response_topic]["count"] == 2 and foxglove[request_topic]["count"] == 2
    summary, _ = summarize_log(log)
    call, refused = [c for c in summary.checks if c.topic.startswith(service)]
    np.testing.assert_array_equal(call.angles, angles)
    assert len(refused.angles) == 0
    assert call.n_reachable == int(np.count_nonzero(check(model, angles, model.position).reachable))
