"""~/markers' fields (logs/markers): the scene as visualization_msgs/MarkerArray, ROS-free.

Built from a scene whose pair in violation is known (a ball through leg 1 at the home pose),
serialised to CDR and read back with rosbags' typestore; every marker is checked against the
bodies of core/scene_view.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.base.rotations import quaternion_to_matrix
from hexapod_workspace.core.cell.scene_view import cone_of, scene_view
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.core.model.collision import collision_scene
from hexapod_workspace.core.workspaces.projected import projected_workspace
from hexapod_workspace.logs import deserialize, serialize
from hexapod_workspace.logs import markers as m

HOME = np.array([0.0, 0.0, -1.3])
#: Leg 1 at home runs from (0.538, -0.114, 0) to (0.201, -0.223, -1.2): its middle is in the ball.
SCENE = {
    "collision.clearance": 0.005,
    "collision.tool.radius": 0.04,
    "collision.tool.length": 0.25,
    "collision.platform.radius": 0.33,
    "collision.platform.z_min": 0.08,
    "collision.platform.z_max": 0.14,
    "collision.obstacles.names": ["ball", "vise", "column", "bar"],
    "collision.obstacles.ball.shape": "sphere",
    "collision.obstacles.ball.position": [0.3694, -0.1686, -0.6],
    "collision.obstacles.ball.radius": 0.05,
    "collision.obstacles.vise.shape": "box",
    "collision.obstacles.vise.position": [0.0, 0.0, -1.75],
    "collision.obstacles.vise.orientation": [0.0, 0.0, 0.3],
    "collision.obstacles.vise.size": [0.3, 0.2, 0.1],
    "collision.obstacles.column.shape": "cylinder",
    "collision.obstacles.column.position": [0.75, 0.0, -0.8],
    "collision.obstacles.column.radius": 0.1,
    "collision.obstacles.column.length": 1.2,
    "collision.obstacles.bar.shape": "capsule",
    "collision.obstacles.bar.position": [-0.8, 0.0, -1.0],
    "collision.obstacles.bar.radius": 0.03,
    "collision.obstacles.bar.length": 0.4,
}


def markers_of(view, frame_id="base"):
    fields = m.marker_array_fields(view, frame_id=frame_id, stamp={"sec": 7, "nanosec": 9})
    decoded = deserialize(m.MARKER_ARRAY_TYPE, bytes(serialize(m.MARKER_ARRAY_TYPE, fields)))
    return decoded.markers


def spaces(markers):
    out = {}
    for marker in markers[1:]:
        out.setdefault(marker.ns, []).append(marker)
    return out


def rgba(marker):
    """The colour as the float32 RGBA of the message, back in the module's float tuples."""
    colour = (marker.color.r, marker.color.g, marker.color.b, marker.color.a)
    for name in ("LEG", "MACHINE", "PLATFORM", "OBSTACLE", "VIOLATED", "CLOSEST", "CONE", "TEXT"):
        if np.allclose(colour, getattr(m, name), atol=1e-6):
            return getattr(m, name)
    return colour


def rotation_of(marker):
    q = marker.pose.orientation
    return quaternion_to_matrix(np.array([q.x, q.y, q.z, q.w]))


def centre_of(marker):
    p = marker.pose.position
    return np.array([p.x, p.y, p.z])


def test_the_pair_in_violation_and_every_obstacle_are_drawn():
    model = load_manipulator(example_config_path())
    scene = collision_scene(SCENE)  # no home-pose refusal: the ball is meant to hit leg 1
    cone = cone_of(projected_workspace(model, HOME, n_phi=36), model, scene)
    view = scene_view(model, np.eye(3), HOME, scene, cone=cone)
    assert view.closest.name == "leg 1 vs ball" and view.closest.violated
    markers = markers_of(view)
    assert markers[0].action == m.DELETEALL
    assert all(x.header.frame_id == "base" and x.header.stamp.sec == 7 for x in markers)
    by_ns = spaces(markers)
    assert set(by_ns) == set(m.NAMESPACES)
    # ids are unique per namespace (RViz replaces a marker of the same ns and id)
    for namespace, group in by_ns.items():
        assert len({x.id for x in group}) == len(group), namespace
    legs = {x.id: x for x in by_ns["legs"]}
    assert sorted(legs) == [1, 2, 3, 4, 5, 6]
    assert rgba(legs[1]) == m.VIOLATED and rgba(legs[2]) == m.LEG
    obstacles = by_ns["obstacles"]
    kinds = [x.type for x in obstacles]
    # ball, vise, column, bar (a capsule: a cylinder and two spheres)
    assert kinds == [m.SPHERE, m.CUBE, m.CYLINDER, m.CYLINDER, m.SPHERE, m.SPHERE]
    assert rgba(obstacles[0]) == m.VIOLATED and rgba(obstacles[1]) == m.OBSTACLE
    vise = obstacles[1]
    np.testing.assert_allclose([vise.scale.x, vise.scale.y, vise.scale.z], [0.3, 0.2, 0.1])
    np.testing.assert_allclose(centre_of(vise), [0.0, 0.0, -1.75], atol=1e-12)
    np.testing.assert_allclose(
        rotation_of(vise)[:, 0], [np.cos(0.3), np.sin(0.3), 0.0], atol=1e-12
    )  # yaw 0.3 rad
    column = obstacles[2]
    np.testing.assert_allclose(
        [column.scale.x, column.scale.y, column.scale.z], [0.2, 0.2, 1.2], atol=1e-12
    )
    bar_ends = sorted(centre_of(x)[2] for x in obstacles[4:])
    np.testing.assert_allclose(bar_ends, [-1.2, -0.8], atol=1e-12)
    assert [x.text for x in by_ns["labels"]] == ["ball", "vise", "column", "bar"]
    line, text = by_ns["closest_pair"]
    assert rgba(line) == m.VIOLATED and text.text.startswith("VIOLATED leg 1 vs ball: -")
    (platform,) = by_ns["platform"]
    assert platform.type == m.CYLINDER
    np.testing.assert_allclose(centre_of(platform), HOME + np.array([0.0, 0.0, 0.11]), atol=1e-12)
    tool = by_ns["tool"]
    assert [x.type for x in tool] == [m.CYLINDER, m.SPHERE, m.SPHERE]
    (cone_marker,) = by_ns["tool_directions"]
    assert cone_marker.type == m.TRIANGLE_LIST and len(cone_marker.points) == 3 * 36
    apexes = np.array([[p.x, p.y, p.z] for p in cone_marker.points[0::3]])
    np.testing.assert_allclose(apexes, np.broadcast_to(HOME, apexes.shape), atol=1e-12)


def test_legs_of_no_diameter_are_lines():
    model = dataclasses.replace(load_manipulator(example_config_path()), leg_diameter=0.0)
    view = scene_view(model, np.eye(3), HOME)
    assert view.closest is None
    by_ns = spaces(markers_of(view))
    (legs,) = by_ns["legs"]
    assert legs.type == m.LINE_LIST and len(legs.points) == 12
    assert "closest_pair" not in by_ns and "obstacles" not in by_ns
    (platform,) = by_ns["platform"]
    assert platform.type == m.LINE_STRIP and len(platform.points) == 7  # closed hexagon
