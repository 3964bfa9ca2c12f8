"""~/markers over real Fast DDS: the scene at the current pose, from a node in another process,
and the same scene in its MCAP log as rosbags, mcap_ros2 and Foxglove's libraries read it.

Every marker is compared with the ROS-free geometry computed here from the same parameters file
(:func:`hexapod_workspace.core.model.legs.leg_endpoints`, the projected workspace of the core).
"""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import numpy as np
import pytest
from ros_support import require_ros

require_ros()

from geometry_msgs.msg import PoseStamped  # noqa: E402
from visualization_msgs.msg import Marker, MarkerArray  # noqa: E402

from hexapod_workspace.core.base.rotations import (  # noqa: E402
    matrix_to_quaternion,
    quaternion_to_matrix,
    tt_to_matrix,
)
from hexapod_workspace.core.model.legs import leg_endpoints  # noqa: E402
from hexapod_workspace.core.workspaces.projected import projected_workspace  # noqa: E402
from hexapod_workspace.ros.markers import CONE_AZIMUTHS  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # test/recording_support.py
from recording_support import (  # noqa: E402
    foxglove_form,
    plain,
    read_with_foxglove,
    read_with_mcap_ros2,
    read_with_rosbags,
)

NODE = "/hexapod_workspace"
CURRENT_POSE_TOPIC = "/markers_current_pose"
NODE_PARAMS = {"motion.current_pose_topic": CURRENT_POSE_TOPIC}
MARKERS = f"{NODE}/markers"


def by_namespace(array: MarkerArray) -> dict[str, list[Marker]]:
    out: dict[str, list[Marker]] = {}
    for marker in array.markers:
        out.setdefault(marker.ns, []).append(marker)
    return out


def axis_of(marker: Marker) -> np.ndarray:
    q = marker.pose.orientation
    return quaternion_to_matrix(np.array([q.x, q.y, q.z, q.w]))[:, 2]


def centre_of(marker: Marker) -> np.ndarray:
    p = marker.pose.position
    return np.array([p.x, p.y, p.z])


def assert_scene(array: MarkerArray, model, position, rotation) -> None:
    """The markers are the machine at (position, rotation) and the cone at the position."""
    assert array.markers[0].action == Marker.DELETEALL
    spaces = by_namespace(array)
    base_ends, platform_ends = leg_endpoints(model, rotation, position)
    legs = sorted(spaces["legs"], key=lambda m: m.id)
    assert [m.id for m in legs] == [1, 2, 3, 4, 5, 6]
    for k, marker in enumerate(legs):
        a, b = base_ends[0, k], platform_ends[0, k]
        assert marker.type == Marker.CYLINDER
        assert marker.header.frame_id == model.frame_id
        np.testing.assert_allclose(centre_of(marker), 0.5 * (a + b), atol=1e-9)
        np.testing.assert_allclose(marker.scale.z, np.linalg.norm(b - a), atol=1e-9)
        np.testing.assert_allclose(marker.scale.x, model.leg_diameter, atol=1e-12)
        np.testing.assert_allclose(axis_of(marker), (b - a) / np.linalg.norm(b - a), atol=1e-9)
    # The platform: the polygon through the platform joints (no collision scene in this node).
    (platform,) = spaces["platform"]
    assert platform.type == Marker.LINE_STRIP
    np.testing.assert_allclose(
        [[p.x, p.y, p.z] for p in platform.points[:6]], platform_ends[0], atol=1e-9
    )
    (tool,) = spaces["tool"]
    start = tool.points[0]
    np.testing.assert_allclose([start.x, start.y, start.z], position, atol=1e-12)
    # The cone: the projected workspace of the core at the position, as triangles.
    (cone,) = spaces["tool_directions"]
    assert cone.type == Marker.TRIANGLE_LIST and len(cone.points) == 3 * CONE_AZIMUTHS
    expected = projected_workspace(model, position, n_phi=CONE_AZIMUTHS, tolerance=1e-4)
    rims = np.array([[p.x, p.y, p.z] for p in cone.points[1::3]])
    directions = rims - position
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    np.testing.assert_allclose(directions, expected.approach_vectors(), atol=1e-3)
    # The closest pair: two legs (leg_interference), coloured in their own markers too.
    line, text = spaces["closest_pair"]
    assert line.type == Marker.LINE_LIST and len(line.points) == 2
    assert " vs " in text.text and text.text.endswith(" mm")


@pytest.fixture(scope="module")
def received(client):
    return client.collect(MarkerArray, MARKERS, transient_local=True)


def test_markers_latched_scene_at_the_model_pose(client, model, received):
    client.spin_until(lambda: len(received) >= 1, what="the first MarkerArray")
    assert_scene(received[0], model, model.position, np.eye(3))


def test_markers_follow_the_current_pose(client, model, received):
    current = client.publisher(PoseStamped, CURRENT_POSE_TOPIC)
    position = np.array([0.05, -0.03, -1.25])
    rotation = tt_to_matrix(np.radians([30.0, 12.0, 5.0]))
    stamped = PoseStamped()
    stamped.header.frame_id = model.frame_id
    stamped.pose.position.x, stamped.pose.position.y, stamped.pose.position.z = position
    q = matrix_to_quaternion(rotation)
    o = stamped.pose.orientation
    o.x, o.y, o.z, o.w = (float(v) for v in q)
    current.publish(stamped)

    def tool_start(array: MarkerArray) -> np.ndarray:
        (tool,) = by_namespace(array)["tool"]
        return np.array([tool.points[0].x, tool.points[0].y, tool.points[0].z])

    client.spin_until(
        lambda: bool(received) and np.allclose(tool_start(received[-1]), position, atol=1e-12),
        what="markers at the current pose",
    )
    assert_scene(received[-1], model, position, rotation)


def test_markers_are_recorded_and_read_by_every_reader(client, workspace_node, received, tmp_path):
    client.spin_until(lambda: len(received) >= 2, what="two scenes")
    assert workspace_node.stop(signal.SIGINT) == 0
    (log,) = sorted(workspace_node.record_dir.glob("*.mcap"))
    sent = [plain(m) for m in received]
    rosbags = [plain(m) for topic, _, m in read_with_rosbags(log) if topic == MARKERS]
    mcap = [plain(m) for topic, _, m in read_with_mcap_ros2(log) if topic == MARKERS]
    assert rosbags == sent
    assert mcap == sent
    foxglove = read_with_foxglove(log, tmp_path)[MARKERS]
    assert foxglove["schema"] == "visualization_msgs/msg/MarkerArray"
    assert foxglove["messages"] == [foxglove_form(m) for m in sent]


def test_obstacles_appear_once_the_state_carries_a_collision_scene(ros_context, ros_client):
    """The markers draw the model's collision scene (ros.markers.node_scene reads
    ``state.manipulator.collision``): a node in this process whose model carries a scene draws
    its obstacles and colours the pair in violation."""
    import dataclasses

    from rclpy.parameter import Parameter

    from hexapod_workspace.core.model.collision import collision_scene
    from hexapod_workspace.ros.markers import attach
    from hexapod_workspace.ros.node import WorkspaceNode

    node = WorkspaceNode(
        context=ros_context,
        namespace="/inproc",
        parameter_overrides=[Parameter("recording.enabled", value=False)],
        extensions=[attach],
    )
    try:
        received = ros_client.collect(
            MarkerArray, "/inproc/hexapod_workspace/markers", transient_local=True
        )
        leg = leg_endpoints(node.state.manipulator, np.eye(3), node.state.manipulator.position)
        middle = 0.5 * (leg[0][0, 2] + leg[1][0, 2])  # leg 3 at the model's pose
        scene = collision_scene(
            {
                "collision.obstacles.names": ["clamp"],
                "collision.obstacles.clamp.shape": "sphere",
                "collision.obstacles.clamp.position": middle.tolist(),
                "collision.obstacles.clamp.radius": 0.05,
            }
        )
        model = dataclasses.replace(node.state.manipulator, collision=scene)
        node.state = dataclasses.replace(node.state, manipulator=model)

        def drawn() -> bool:
            return bool(received) and "obstacles" in by_namespace(received[-1])

        ros_client.spin_until(drawn, what="the obstacles on ~/markers")
        spaces = by_namespace(received[-1])
        (clamp,) = spaces["obstacles"]
        assert clamp.type == Marker.SPHERE
        np.testing.assert_allclose(centre_of(clamp), middle, atol=1e-12)
        assert spaces["closest_pair"][1].text.startswith("VIOLATED leg 3 vs clamp: -")
        legs = {m.id: m for m in spaces["legs"]}
        assert legs[3].color.r > 0.8 and legs[3].color.g < 0.2  # red: the pair in violation
    finally:
        node.destroy_node()
