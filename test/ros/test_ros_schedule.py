"""``~/schedule_path`` over real Fast DDS, from another process, for 6-UPS, 6-PUS and 6-RUS: the
node's schedule is the core's (computed here from the same file and the same poses), refusals
name the field and leave the node serving, and the calls are in the node's log as rosbags and
mcap_ros2 read it and as ``replay`` reports it."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from cli_support import run_main
from recording_support import read_with_foxglove, read_with_mcap_ros2, read_with_rosbags
from ros_support import require_ros, running_node

require_ros()

from geometry_msgs.msg import Pose  # noqa: E402
from hexapod_workspace_msgs.srv import SchedulePath  # noqa: E402
from test_ros_architectures import params_text  # noqa: E402

from hexapod_workspace.core.base.rotations import (  # noqa: E402
    matrix_to_quaternion,
    quaternion_to_matrix,
    tt_to_matrix,
)
from hexapod_workspace.core.evaluation.loading import load_manipulator  # noqa: E402
from hexapod_workspace.core.motions import check_path  # noqa: E402
from hexapod_workspace.core.motions.schedule import schedule_path  # noqa: E402
from hexapod_workspace.core.motions.schedule_report import limited_by  # noqa: E402

NODE = "/hexapod_workspace"
SERVICE = f"{NODE}/schedule_path"
MM_MIN = 1e-3 / 60.0
#: (speed, acceleration) limits: m/s and m/s² for legs and slides, rad/s and rad/s² for cranks
LIMITS = {"gpm": (0.01, 0.05), "pus": (0.01, 0.05), "rus": (0.1, 0.5)}
FEEDS_MM_MIN = [3000.0, 3000.0, 1500.0, 3000.0, 3000.0]
RAPID = [False, False, False, True, False]


def waypoints(home: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Six poses about the home position (m, base frame): corners, and a rapid move (3)
    collinear with the move before it (the schedule runs through waypoint 3)."""
    offsets = 1e-3 * np.array(
        [[0, 0, 0], [20, 0, 0], [20, 20, 0], [30, 20, 0], [40, 20, 0], [0, 0, 0]], dtype=float
    )
    angles = np.radians([[0, 0, 0], [0, 4, 0], [90, 4, 0], [90, 4, 0], [90, 4, 0], [0, 0, 0]])
    rotations = quaternion_to_matrix(matrix_to_quaternion(tt_to_matrix(angles)))
    return home + offsets, rotations


def ros_poses(positions: np.ndarray, rotations: np.ndarray) -> list[Pose]:
    poses = []
    for position, quaternion in zip(positions, matrix_to_quaternion(rotations), strict=True):
        pose = Pose()
        pose.position.x, pose.position.y, pose.position.z = (float(v) for v in position)
        x, y, z, w = (float(v) for v in quaternion)
        pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = x, y, z, w
        poses.append(pose)
    return poses


@pytest.mark.parametrize("architecture", ["gpm", "pus", "rus"])
def test_schedule_path_is_the_cores_schedule_and_is_recorded(
    architecture, ros_domain, ros_client, tmp_path
):
    speed, accel = LIMITS[architecture]
    text = params_text(
        architecture,
        tmp_path,
        **{"limits.actuator_speed_max": [speed], "limits.actuator_accel_max": [accel]},
    )
    with running_node(tmp_path, params_text=text) as node:
        model = load_manipulator(node.params_path)
        positions, rotations = waypoints(model.position)
        request = SchedulePath.Request(
            poses=ros_poses(positions, rotations),
            feeds_mm_min=FEEDS_MM_MIN,
            rapid=RAPID,
            rapid_feed_mm_min=6000.0,
            feed_max_mm_min=2500.0,
        )
        ros_client.client(SchedulePath, SERVICE)
        response = ros_client.call(SchedulePath, SERVICE, request)
        assert response.success, response.message

        # the core, from the same file and poses (ceilings: rapid feed or feed, capped at 2500)
        ceilings = np.minimum(np.where(RAPID, 6000.0, FEEDS_MM_MIN), 2500.0) * MM_MIN
        expected = schedule_path(
            model,
            positions,
            rotations,
            speed_limits=[speed],
            accel_limits=[accel],
            feeds=ceilings,
        )
        assert response.duration_s == pytest.approx(expected.duration, rel=1e-12)
        np.testing.assert_allclose(response.s, expected.s, rtol=0, atol=1e-12)
        np.testing.assert_allclose(response.sdot, expected.sdot, rtol=1e-10, atol=1e-12)
        assert list(response.stops) == [int(k) for k in np.flatnonzero(expected.stops)]
        assert response.intervals == expected.intervals
        kinds, actuators = limited_by(expected, ceilings)
        assert [m.limited_by for m in response.moves] == kinds
        assert [m.limiting_actuator for m in response.moves] == actuators.tolist()
        assert {"velocity", "acceleration"} & set(kinds), "the limits must bind somewhere"
        for move, k in zip(response.moves, range(len(RAPID)), strict=True):
            assert move.t_end_s == pytest.approx(expected.t_end[k], rel=1e-12)
            assert move.feed_peak == pytest.approx(expected.feed_peak[k] / MM_MIN, rel=1e-12)
            assert move.feed_ceiling == pytest.approx(ceilings[k] / MM_MIN, rel=1e-12)
            np.testing.assert_allclose(move.actuator_speed_peak, expected.speed_peak[k], rtol=1e-12)
            assert move.rapid == RAPID[k]
        lengths = np.linalg.norm(np.diff(positions, axis=0), axis=1)
        programmed = np.where(RAPID, 6000.0, FEEDS_MM_MIN) * MM_MIN
        assert response.programmed_duration_s == pytest.approx(np.sum(lengths / programmed))
        assert response.path_ok == check_path(model, positions, rotations=rotations).ok
        assert list(response.actuator_speed_max) == [speed] * 6
        assert list(response.actuator_accel_max) == [accel] * 6
        assert response.actuator_unit == ("rad" if architecture == "rus" else "m")
        assert f"schedule: {expected.duration:.3f} s" in response.message

        # asked stops and stops at rapids: rest there too
        stopped = ros_client.call(
            SchedulePath,
            SERVICE,
            SchedulePath.Request(
                poses=request.poses,
                feeds_mm_min=[2500.0],
                rapid=RAPID,
                stop_at_rapids=True,
                stops=[False, False, False, False, False, False],
            ),
        )
        assert stopped.success, stopped.message
        assert {3, 4} <= set(stopped.stops)
        assert 3 not in response.stops and 3 in stopped.stops
        assert set(response.stops) <= set(stopped.stops)
        assert node.stop() == 0

    (log,) = sorted(node.record_dir.glob("*.mcap"))
    for read in (read_with_rosbags, read_with_mcap_ros2):
        messages = read(log)
        requests = [m for topic, _, m in messages if topic == f"{SERVICE}/request"]
        responses = [m for topic, _, m in messages if topic == f"{SERVICE}/response"]
        assert len(requests) == len(responses) == 2, read.__name__
        assert list(requests[0].feeds_mm_min) == FEEDS_MM_MIN
        assert responses[0].duration_s == response.duration_s
        assert [m.limited_by for m in responses[0].moves] == kinds
    foxglove = read_with_foxglove(log, tmp_path)[f"{SERVICE}/response"]["messages"]
    assert [m["duration_s"] for m in foxglove] == [response.duration_s, stopped.duration_s]
    assert foxglove[0]["sdot"] == list(response.sdot)
    assert [m["limited_by"] for m in foxglove[0]["moves"]] == kinds
    code, out, _ = run_main("replay", str(log), "--json")
    assert code == 0
    recorded = json.loads(out)["schedules"]
    assert [r["duration_s"] for r in recorded] == [response.duration_s, stopped.duration_s]
    assert recorded[0]["n_waypoints"] == 6 and recorded[0]["n_moves"] == 5
    assert [m["move"] for m in recorded[0]["below_ceiling"]] == [
        k + 1 for k, kind in enumerate(kinds) if kind != "feed"
    ]
    code, text_out, _ = run_main("replay", str(log))
    assert code == 0
    assert f"5 moves in {response.duration_s:.3f} s" in text_out


def test_bad_schedule_requests_are_refused_naming_the_field(ros_domain, ros_client, tmp_path):
    text = params_text("gpm", tmp_path, **{"limits.actuator_speed_max": [0.01]})
    with running_node(tmp_path, params_text=text) as node:
        model = load_manipulator(node.params_path)
        positions, rotations = waypoints(model.position)
        poses = ros_poses(positions, rotations)
        ros_client.client(SchedulePath, SERVICE)
        cases = [
            (SchedulePath.Request(poses=poses[:1]), "poses: expected at least 2 waypoints, got 1"),
            (SchedulePath.Request(poses=poses, feeds_mm_min=[-5.0]), "feeds_mm_min[0]"),
            (SchedulePath.Request(poses=poses, feeds_mm_min=[1.0, 2.0]), "feeds_mm_min: expected"),
            (SchedulePath.Request(poses=poses, rapid=[True]), "rapid: expected none or one per"),
            (SchedulePath.Request(poses=poses, stops=[True]), "stops: expected none or one per"),
            (SchedulePath.Request(poses=poses, beziers=[0.0] * 6), "beziers: expected none or 6"),
            (SchedulePath.Request(poses=poses, feed_max_mm_min=-1.0), "feed_max_mm_min"),
            (SchedulePath.Request(poses=poses, tolerance=math.nan), "tolerance"),
        ]
        other = SchedulePath.Request(poses=poses)
        other.header.frame_id = "elsewhere"
        cases.append((other, "elsewhere"))
        for bad, expected in cases:
            answer = ros_client.call(SchedulePath, SERVICE, bad)
            assert not answer.success
            assert expected in answer.message
            assert "\n" not in answer.message
            assert len(answer.moves) == 0
        # no acceleration limit and no feed on a rotation-free move is still bounded by speed;
        # a path with the speed limit gets its schedule after every refusal
        good = ros_client.call(SchedulePath, SERVICE, SchedulePath.Request(poses=poses))
        assert good.success, good.message
        assert good.duration_s > 0.0 and all(m.limited_by == "velocity" for m in good.moves)
        assert node.stop() == 0
    # the refusals (empty arrays) and the answer are in the log, as every reader reads it
    (log,) = sorted(node.record_dir.glob("*.mcap"))
    for read in (read_with_rosbags, read_with_mcap_ros2):
        responses = [m for topic, _, m in read(log) if topic == f"{SERVICE}/response"]
        assert [m.success for m in responses] == [False] * len(cases) + [True], read.__name__
        assert responses[-1].duration_s == good.duration_s
    foxglove = read_with_foxglove(log, tmp_path)[f"{SERVICE}/response"]["messages"]
    assert [m["success"] for m in foxglove] == [False] * len(cases) + [True]
    assert foxglove[0]["message"] == "poses: expected at least 2 waypoints, got 1"
