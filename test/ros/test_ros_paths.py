"""Paths over real Fast DDS: ~/check_path, geometry_msgs/Pose inputs, moves from the current pose.

The node runs from the install space (another process); every verdict is compared with the
ROS-free core computed here from the same parameters file.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from cli_support import run_cli
from path_support import random_large_moves
from recording_support import plain, read_with_mcap_ros2, read_with_rosbags
from ros_support import require_ros

require_ros()

from geometry_msgs.msg import Pose, PoseStamped  # noqa: E402
from hexapod_workspace_msgs.msg import (  # noqa: E402
    CommandedPose,
    ReachabilityResult,
    TiltTorsion,
)
from hexapod_workspace_msgs.srv import CheckPath, CheckPoses  # noqa: E402

from hexapod_workspace import check, check_path, plan_torsion  # noqa: E402
from hexapod_workspace.core.base.rotations import (  # noqa: E402
    approach_vector,
    matrix_to_quaternion,
    quaternion_to_matrix,
    tt_to_matrix,
)
from hexapod_workspace.core.motions.baseline import psi_zero_baseline  # noqa: E402
from hexapod_workspace.ros.conversions import margins_by_name  # noqa: E402

NODE = "/hexapod_workspace"
CURRENT_POSE_TOPIC = "/test_current_pose"
NODE_PARAMS = {"motion.current_pose_topic": CURRENT_POSE_TOPIC}


def ros_pose(position, quaternion) -> Pose:
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = (float(v) for v in position)
    x, y, z, w = (float(v) for v in quaternion)
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = x, y, z, w
    return pose


def ros_poses(positions, angles) -> list[Pose]:
    quaternions = matrix_to_quaternion(tt_to_matrix(angles))
    return [ros_pose(p, q) for p, q in zip(positions, quaternions, strict=True)]


def cone(count: int):
    t = np.linspace(0.0, 2.0 * np.pi, count)
    positions = np.column_stack(
        [0.2 + 0.02 * np.cos(t), 0.2 + 0.02 * np.sin(t), np.full(count, -0.95)]
    )
    return positions, t


def test_check_path_fixed_orientations_matches_core(client, model):
    rng = np.random.default_rng(11)
    count = 30
    positions = np.array([0.0, 0.0, -1.15]) + rng.uniform(-0.25, 0.25, (count, 3))
    angles = np.column_stack(
        [rng.uniform(-np.pi, np.pi, count), rng.uniform(0, 0.5, count), rng.uniform(-1, 1, count)]
    )
    request = CheckPath.Request(poses=ros_poses(positions, angles))
    response = client.call(CheckPath, f"{NODE}/check_path", request)
    assert response.success, response.message
    expected = check_path(model, positions, angles=angles)
    assert response.ok == expected.ok and not response.planned_torsion
    # the psi = 0 baseline, as the CLI reports it (one function: core.baseline)
    baseline = psi_zero_baseline(model, expected)
    assert list(response.psi_zero_waypoints_failed) == baseline.failed_waypoints
    assert list(response.psi_zero_segments_failed) == baseline.failed_segments
    assert [w.reachable for w in response.waypoints] == expected.waypoints.reachable.tolist()
    assert [s.ok for s in response.segments] == expected.segments.ok.tolist()
    for k, segment in enumerate(response.segments):
        if not segment.ok:
            assert segment.first_violation_s == expected.segments.first_violation_s[k]
            assert list(segment.violated) == expected.segments.violated[k]
        assert segment.limiting_leg == expected.segments.limiting_leg[k]
    np.testing.assert_allclose(
        [[o.phi, o.theta, o.psi] for o in response.orientations],
        expected.waypoints.angles,
        atol=1e-12,
    )


def test_check_path_free_torsion_plans_the_poses(client, model):
    positions, t = cone(40)
    # Poses as a controller would send them: tool axis on a 17° cone, any rotation about it.
    angles = np.column_stack([t, np.full(40, np.radians(17.0)), np.full(40, 0.7)])
    request = CheckPath.Request(
        poses=ros_poses(positions, angles),
        free_torsion=True,
        limit_dpsi=True,
        max_dpsi=math.radians(5.0),
    )
    response = client.call(CheckPath, f"{NODE}/check_path", request)
    assert response.success, response.message
    expected = plan_torsion(
        model, positions, approach_vector(t, np.radians(17.0)), max_dpsi=math.radians(5.0)
    )
    assert response.ok and response.planned_torsion and expected.ok
    assert list(response.psi_zero_waypoints_failed) == expected.baseline.failed_waypoints
    assert response.psi_zero_waypoints_failed  # ψ ≡ 0 fails here
    assert response.objective == expected.objective
    # The planned poses keep each tool axis and pass the core's check on their own.
    planned = np.array(
        [
            [p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w]
            for p in response.poses
        ]
    )
    np.testing.assert_allclose(
        quaternion_to_matrix(planned)[:, :, 2], approach_vector(t, np.radians(17.0)), atol=1e-9
    )
    assert check_path(model, positions, quaternions=planned).ok


def test_check_path_refuses_bad_requests_and_keeps_serving(client):
    zero = ros_pose([0.0, 0.0, -1.3], [0.0, 0.0, 0.0, 0.0])
    good = ros_pose([0.0, 0.0, -1.3], [0.0, 0.0, 0.0, 1.0])
    for request, reason in (
        (CheckPath.Request(poses=[good]), "2 to"),
        (CheckPath.Request(poses=[good, zero]), "non-zero"),
        (CheckPath.Request(poses=[good, zero], free_torsion=True), "quaternion"),
        (CheckPath.Request(poses=[good, good], interpolation=7), "interpolation"),
        (CheckPath.Request(poses=[good, good], tolerance=-1.0), "tolerance"),
    ):
        response = client.call(CheckPath, f"{NODE}/check_path", request)
        assert not response.success and reason in response.message, response.message
    response = client.call(CheckPath, f"{NODE}/check_path", CheckPath.Request(poses=[good, good]))
    assert response.success and response.ok


def test_check_poses_accepts_ros_poses(client, model):
    positions = np.array([[0.0, 0.0, -1.3], [0.2, 0.2, -0.95], [0.1, 0.0, -1.2]])
    angles = np.radians([[30.0, 20.0, 5.0], [130.0, 19.0, 0.0], [0.0, 70.0, 0.0]])
    request = CheckPoses.Request(poses=ros_poses(positions, angles))
    response = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert response.success, response.message
    for k, result in enumerate(response.results):
        expected = check(model, angles[k], positions[k])
        assert result.reachable == expected.reachable[0]
        # The pose went through a quaternion and back to T&T angles: equal to rounding.
        assert margins_by_name(result)["leg_length"] == pytest.approx(
            expected.margins["leg_length"][0], abs=1e-12
        )
    assert [r.reachable for r in response.results] == [True, False, False]
    both = CheckPoses.Request(poses=ros_poses(positions, angles), orientations=[TiltTorsion()])
    refused = client.call(CheckPoses, f"{NODE}/check_poses", both)
    assert not refused.success and "not both" in refused.message


def test_commanded_pose_is_checked_as_a_move_from_the_current_pose(client, model):
    results = client.collect(ReachabilityResult, f"{NODE}/reachability", transient_local=True)
    commands = client.publisher(CommandedPose, f"{NODE}/commanded_pose")
    current = client.publisher(PoseStamped, CURRENT_POSE_TOPIC)
    # A pose command given as geometry_msgs/Pose, before any current pose is known.
    target_angles = np.radians([[40.0, 15.0, 0.0]])
    target = ros_poses([[0.0, 0.0, -1.3]], target_angles)[0]
    commands.publish(CommandedPose(request_id="first", use_pose=True, pose=target))
    client.spin_until(lambda: any(r.request_id == "first" for r in results), what="first")
    first = next(r for r in results if r.request_id == "first")
    assert first.success and first.check.reachable and not first.motion_checked
    np.testing.assert_allclose(
        [first.orientation.phi, first.orientation.theta, first.orientation.psi],
        target_angles[0],
        atol=1e-12,
    )
    # The current pose: on the other side, tilted; the straight move to the target passes
    # through poses found here by the core (random search, seeded) to leave the workspace.
    start_position, start_angles, goal_position, goal_angles = interior_violation(model)
    stamped = PoseStamped()
    stamped.header.frame_id = model.frame_id
    stamped.pose = ros_poses([start_position], start_angles[None, :])[0]
    expected = check_path(
        model,
        np.vstack([start_position, goal_position]),
        angles=np.vstack([start_angles, goal_angles]),
    )
    for attempt in range(20):  # the node may receive the current pose after the command
        current.publish(stamped)
        client.spin_until(lambda: True, what="nothing", timeout=0.2)
        request_id = f"move{attempt}"
        goal = ros_poses([goal_position], goal_angles[None, :])[0]
        commands.publish(CommandedPose(request_id=request_id, use_pose=True, pose=goal))
        client.spin_until(
            lambda rid=request_id: any(r.request_id == rid for r in results), what=request_id
        )
        answer = next(r for r in results if r.request_id == request_id)
        if answer.motion_checked:
            break
    assert answer.motion_checked, answer.message
    assert answer.success and answer.check.reachable  # the target alone is fine ...
    assert not answer.motion_ok  # ... the move to it is not
    assert not answer.motion.ok
    assert answer.motion.first_violation_s == expected.segments.first_violation_s[0]
    assert "leaves the workspace" in answer.message
    assert answer.current_pose.position.x == start_position[0]


def interior_violation(model):
    """Two reachable poses whose straight move (slerp) leaves the workspace (seeded search)."""
    positions, angles = random_large_moves()
    result = check_path(model, positions, angles=angles)
    ends = result.waypoints.reachable[:-1] & result.waypoints.reachable[1:]
    k = int(np.flatnonzero(ends & ~result.segments.ok)[0])
    return positions[k], angles[k], positions[k + 1], angles[k + 1]


def test_path_calls_are_recorded_and_replayed(client, workspace_node):
    """Last in the module: stops the node (SIGINT finishes its log) and reads the log back."""
    positions, t = cone(8)
    angles = np.column_stack([t, np.full(8, np.radians(10.0)), np.zeros(8)])
    request = CheckPath.Request(poses=ros_poses(positions, angles))
    response = client.call(CheckPath, f"{NODE}/check_path", request)
    assert response.success and response.ok
    assert workspace_node.stop() == 0
    logs = sorted(workspace_node.record_dir.glob("*.mcap"))
    assert len(logs) == 1
    for reader in (read_with_rosbags, read_with_mcap_ros2):
        recorded = [
            (topic, plain(message))
            for topic, _, message in reader(logs[0])
            if topic.startswith(f"{NODE}/check_path/")
        ]
        requests = [m for topic, m in recorded if topic.endswith("/request")]
        responses = [m for topic, m in recorded if topic.endswith("/response")]
        assert len(requests) == len(responses) >= 1
        assert requests[-1] == plain(request)
        assert responses[-1] == plain(response)
        # the current pose of every motion verdict is in the log, before it
        current = None
        verdicts = 0
        for topic, _, message in reader(logs[0]):
            if topic == CURRENT_POSE_TOPIC:
                current = plain(message)["pose"]
            elif topic == f"{NODE}/reachability" and plain(message)["motion_checked"]:
                assert current is not None
                assert plain(message)["current_pose"] == current
                verdicts += 1
        assert verdicts >= 1
    replay = run_cli("replay", str(logs[0]), "--json")
    assert replay.returncode == 0, replay.stderr
    calls = json.loads(replay.stdout)["path_checks"]
    assert calls and calls[-1]["ok"] is True and calls[-1]["n_waypoints"] == 8
