"""The collision scene on the node over real Fast DDS: ``collision.*`` read from the parameters
file the CLI reads (config/example_collision.yaml), the pair in every answer, obstacles changed
at run time (applied, or refused with the old model kept, and recorded), and the obstacles on
``~/markers``.

The expected margins and pairs come from the CLI (``check --config ... --json``) and from the
ROS-free core on a model built from the same parameters (``manipulator_from_mapping``), in
this process; the node runs from the install space in another.
"""

from __future__ import annotations

import json
import math
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from cli_support import run_main
from recording_support import read_with_foxglove, read_with_mcap_ros2, read_with_rosbags
from ros_support import REPO, require_ros, running_node

require_ros()

from geometry_msgs.msg import Pose  # noqa: E402
from hexapod_workspace_msgs.msg import TiltTorsion  # noqa: E402
from hexapod_workspace_msgs.srv import CheckPath, CheckPoses, CheckPosesFlat  # noqa: E402
from rcl_interfaces.msg import Parameter as ParameterMsg  # noqa: E402
from rcl_interfaces.msg import ParameterType, ParameterValue  # noqa: E402
from rcl_interfaces.srv import SetParameters  # noqa: E402
from visualization_msgs.msg import Marker, MarkerArray  # noqa: E402

from hexapod_workspace import Manipulator, check, check_path  # noqa: E402
from hexapod_workspace.core.base.params import flatten  # noqa: E402
from hexapod_workspace.core.base.rotations import matrix_to_quaternion, tt_to_matrix  # noqa: E402
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping  # noqa: E402
from hexapod_workspace.ros.conversions import margins_by_name  # noqa: E402

NODE = "/hexapod_workspace"
EXAMPLE = REPO / "config" / "example_collision.yaml"
#: The documented example (docs/collision.md): tilt 30 deg towards phi = 90 deg, psi = 0.
COLLIDING_DEG = (90.0, 30.0, 0.0)
POSITION = [0.0, 0.0, -1.3]


def example_parameters() -> dict:
    return yaml.safe_load(EXAMPLE.read_text(encoding="utf-8"))["hexapod_workspace"][
        "ros__parameters"
    ]


@pytest.fixture(scope="module")
def workspace_node(ros_domain, tmp_path_factory):
    """The node started with config/example_collision.yaml (recording into the test folder)."""
    directory = tmp_path_factory.mktemp("collision_node")
    document = yaml.safe_load(EXAMPLE.read_text(encoding="utf-8"))
    document["hexapod_workspace"]["ros__parameters"]["recording"] = {
        "directory": str(directory / "logs")
    }
    with running_node(directory, params_text=yaml.safe_dump(document, sort_keys=False)) as node:
        yield node


def model_with(changes: dict | None = None) -> Manipulator:
    """The core's model of the example with dotted-name ``changes`` (None: removed)."""
    flat = flatten(example_parameters())
    for name, value in (changes or {}).items():
        if value is None:
            flat.pop(name, None)
        else:
            flat[name] = value
    return manipulator_from_mapping(flat, warn=False)


def pose_request(*angles_deg: tuple[float, float, float]) -> CheckPoses.Request:
    request = CheckPoses.Request()
    request.position.x, request.position.y, request.position.z = POSITION
    request.orientations = [
        TiltTorsion(phi=math.radians(p), theta=math.radians(t), psi=math.radians(s))
        for p, t, s in angles_deg
    ]
    return request


def check_one(client, angles_deg=COLLIDING_DEG):
    response = client.call(CheckPoses, f"{NODE}/check_poses", pose_request(angles_deg))
    assert response.success, response.message
    return response.results[0]


def value(name: str, given) -> ParameterMsg:
    if isinstance(given, str):
        parameter = ParameterValue(type=ParameterType.PARAMETER_STRING, string_value=given)
    elif given is None:
        parameter = ParameterValue(type=ParameterType.PARAMETER_NOT_SET)
    elif isinstance(given, list) and given and isinstance(given[0], str):
        parameter = ParameterValue(
            type=ParameterType.PARAMETER_STRING_ARRAY, string_array_value=given
        )
    elif isinstance(given, list):
        parameter = ParameterValue(
            type=ParameterType.PARAMETER_DOUBLE_ARRAY, double_array_value=[float(v) for v in given]
        )
    else:
        parameter = ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=float(given))
    return ParameterMsg(name=name, value=parameter)


def set_atomically(client, changes: dict):
    """Set ``changes`` in one ``set_parameters_atomically`` call (all applied or none)."""
    from rcl_interfaces.srv import SetParametersAtomically

    request = SetParametersAtomically.Request(
        parameters=[value(name, given) for name, given in changes.items()]
    )
    return client.call(SetParametersAtomically, f"{NODE}/set_parameters_atomically", request).result


# ------------------------------------------------------------------ the scene in every answer
def test_the_node_answers_what_the_cli_says_with_the_pair(client):
    code, out, _ = run_main(
        "check", "--config", str(EXAMPLE), "--json", "--pose", *map(str, COLLIDING_DEG)
    )
    assert code == 1, out  # the pose collides
    expected = json.loads(out)["poses"][0]
    assert expected["collision_pair"] == "tool vs leg 3"

    result = check_one(client)
    margins = margins_by_name(result)
    assert margins["collision"] == pytest.approx(expected["margins"]["collision"], abs=1e-12)
    assert margins["collision"] < 0.0 and "collision" in result.violated
    assert result.collision_pair == "tool vs leg 3"
    assert not result.reachable

    # the flat form: one pair per pose
    request = CheckPosesFlat.Request(angles=[math.radians(v) for v in (*COLLIDING_DEG, 0, 0, 0)])
    request.position.x, request.position.y, request.position.z = POSITION
    flat = client.call(CheckPosesFlat, f"{NODE}/check_poses_flat", request)
    assert flat.success, flat.message
    column = list(flat.constraint_names).index("collision")
    width = len(flat.constraint_names)
    assert flat.margins[column] == margins["collision"]
    core = check(model_with(), np.radians([COLLIDING_DEG, (0, 0, 0)]), POSITION)
    assert list(flat.collision_pair) == core.collision_pair
    assert flat.margins[width + column] == pytest.approx(core.margins["collision"][1], abs=1e-12)
    # a refused flat call (every array empty) is recorded too: the log test decodes it
    refused = client.call(
        CheckPosesFlat, f"{NODE}/check_poses_flat", CheckPosesFlat.Request(angles=[0.1, 0.2])
    )
    assert not refused.success and not refused.collision_pair


def test_check_path_names_the_pair_at_the_first_violation(client):
    """A move from the home orientation to the colliding tilt: the segment's pair is the
    core's at its first violation; the waypoints carry their closest pairs."""
    request = CheckPath.Request()
    poses = []
    for angles in ((90.0, 0.0, 0.0), COLLIDING_DEG):
        pose = Pose()
        pose.position.x, pose.position.y, pose.position.z = POSITION
        q = matrix_to_quaternion(tt_to_matrix(np.radians(angles)))
        o = pose.orientation
        o.x, o.y, o.z, o.w = (float(v) for v in q)
        poses.append(pose)
    request.poses = poses
    response = client.call(CheckPath, f"{NODE}/check_path", request)
    assert response.success, response.message
    assert not response.ok
    (segment,) = response.segments
    assert not segment.ok
    expected = check_path(
        model_with(),
        np.array([POSITION, POSITION]),
        angles=np.radians([(90.0, 0.0, 0.0), COLLIDING_DEG]),
    )
    assert expected.segments.collision_pair[0] == segment.collision_pair != ""
    assert "collision" in segment.violated
    assert [w.collision_pair for w in response.waypoints] == list(expected.waypoints.collision_pair)
    assert response.waypoints[1].collision_pair == "tool vs leg 3"


# ------------------------------------------------------------------ run-time changes
def set_one(client, name: str, given) -> None:
    (result,) = client.call(
        SetParameters,
        f"{NODE}/set_parameters",
        SetParameters.Request(parameters=[value(name, given)]),
    ).results
    assert result.successful, result.reason


def test_an_obstacle_moved_at_run_time_is_applied(client):
    name = "collision.obstacles.ball.position"
    moved = [-0.45, -0.2, -1.0]  # the ball next to leg 5: the closest pair at ANGLES
    angles = (90.0, 12.0, 0.0)
    before = check_one(client, angles)
    assert before.collision_pair == "tool vs vise"
    set_one(client, name, moved)
    after = check_one(client, angles)
    expected = check(model_with({name: moved}), np.radians([angles]), POSITION)
    assert margins_by_name(after)["collision"] == pytest.approx(
        expected.margins["collision"][0], abs=1e-12
    )
    assert after.collision_pair == expected.collision_pair[0] == "leg 5 vs ball"
    # back where the file has it
    set_one(client, name, example_parameters()["collision"]["obstacles"]["ball"]["position"])
    assert margins_by_name(check_one(client, angles)) == margins_by_name(before)


@pytest.mark.parametrize(
    ("changes", "reason"),
    [
        (
            {"collision.obstacles.vise.shape": "cone"},
            "collision.obstacles.vise.shape: expected one of box, cylinder, sphere, capsule, "
            "got 'cone'",
        ),
        (
            {"collision.obstacles.column.radius": -0.1},
            "collision.obstacles.column.radius: expected a positive length (m), got -0.1",
        ),
        (
            {"collision.obstacles.ball.position": [-0.42, -0.15, -1.05]},
            "collision: leg 5 vs ball collide at the home pose",
        ),
        (
            {"collision.obstacles.names": ["vise", "column", "ball", "clamp"]},
            "collision.obstacles.clamp: listed in collision.obstacles.names but not given",
        ),
        (
            {"collision.obstacles.vise.frame": "table"},
            "collision.obstacles.vise.frame: expected one of base, work, got 'table'",
        ),
    ],
)
def test_a_bad_obstacle_is_refused_and_the_old_scene_kept(client, changes, reason):
    before = check_one(client)
    result = set_atomically(client, changes)
    assert not result.successful
    assert reason in result.reason, result.reason
    after = check_one(client)
    assert margins_by_name(after) == margins_by_name(before)
    assert after.collision_pair == before.collision_pair


def test_an_obstacle_added_and_removed_at_run_time(client):
    clamp = {
        "collision.obstacles.names": ["vise", "column", "ball", "clamp"],
        "collision.obstacles.clamp.shape": "sphere",
        "collision.obstacles.clamp.position": [-0.2, 0.55, -0.95],
        "collision.obstacles.clamp.radius": 0.05,
    }
    result = set_atomically(client, clamp)
    assert result.successful, result.reason
    angles = (90.0, 12.0, 0.0)
    expected = check(model_with(clamp), np.radians([angles]), POSITION)
    added = check_one(client, angles)
    assert margins_by_name(added)["collision"] == pytest.approx(
        expected.margins["collision"][0], abs=1e-12
    )
    assert added.collision_pair == expected.collision_pair[0]
    # removed: off the list, its group unset (deleted) in the same call
    removed = {name: None for name in clamp if name.startswith("collision.obstacles.clamp.")}
    removed["collision.obstacles.names"] = ["vise", "column", "ball"]
    result = set_atomically(client, removed)
    assert result.successful, result.reason
    expected = check(model_with(), np.radians([angles]), POSITION)
    assert margins_by_name(check_one(client, angles))["collision"] == pytest.approx(
        expected.margins["collision"][0], abs=1e-12
    )


# ------------------------------------------------------------------ markers, log
def test_the_markers_show_the_obstacles(client):
    received = client.collect(MarkerArray, f"{NODE}/markers", transient_local=True)

    def labels(array: MarkerArray) -> list[str]:
        return sorted(m.text for m in array.markers if m.ns == "labels")

    # the file's three (the clamp of the test above, removed, is gone once redrawn)
    client.spin_until(
        lambda: bool(received) and labels(received[-1]) == ["ball", "column", "vise"],
        what="the obstacles on ~/markers",
    )
    obstacles = [m for m in received[-1].markers if m.ns == "obstacles"]
    shapes = sorted(m.type for m in obstacles)
    assert shapes == sorted([Marker.CUBE, Marker.CYLINDER, Marker.SPHERE])
    (vise,) = [m for m in obstacles if m.type == Marker.CUBE]
    p = vise.pose.position
    np.testing.assert_allclose([p.x, p.y, p.z], [0.0, 0.0, -1.55], atol=1e-12)
    np.testing.assert_allclose([vise.scale.x, vise.scale.y, vise.scale.z], [0.3, 0.2, 0.1])
    (ball,) = [m for m in obstacles if m.type == Marker.SPHERE]
    np.testing.assert_allclose(ball.scale.x, 0.2, atol=1e-12)  # diameter


def test_the_log_records_the_obstacle_changes(client, workspace_node, tmp_path):
    time.sleep(1.0)  # the recorder thread writes within its flush interval
    assert workspace_node.stop() == 0
    (log,) = sorted(Path(workspace_node.record_dir).glob("*.mcap"))
    messages = read_with_rosbags(log)
    changes = [m for topic, _, m in messages if topic == f"{NODE}/parameter_changes"]
    assert any(
        m.accepted and list(m.names) == ["collision.obstacles.ball.position"] for m in changes
    )
    assert any(not m.accepted and "'cone'" in m.reason for m in changes)
    responses = [m for topic, _, m in messages if topic == f"{NODE}/check_poses/response"]
    assert any(r.results and r.results[0].collision_pair == "tool vs leg 3" for r in responses)
    # the new string fields keep every reader in step (CDR alignment): mcap_ros2 and Foxglove's
    # libraries decode the same pairs as rosbags
    topic = f"{NODE}/check_path/response"
    expected = [[s.collision_pair for s in m.segments] for name, _, m in messages if name == topic]
    assert expected and expected[0][0] != ""
    decoded = [m for name, _, m in read_with_mcap_ros2(log) if name == topic]
    assert [[s.collision_pair for s in m.segments] for m in decoded] == expected
    foxglove = read_with_foxglove(log, tmp_path)[topic]["messages"]
    assert [[s["collision_pair"] for s in m["segments"]] for m in foxglove] == expected
    flat = f"{NODE}/check_poses_flat/response"
    pairs = [list(m.collision_pair) for name, _, m in messages if name == flat]
    assert pairs and pairs[0][0] == "tool vs leg 3" and [] in pairs  # and the refusal
    fox_flat = read_with_foxglove(log, tmp_path)[flat]["messages"]
    assert [list(m["collision_pair"]) for m in fox_flat] == pairs


def test_a_bad_scene_in_the_file_stops_the_start_with_the_reason(ros_domain, tmp_path):
    document = yaml.safe_load(EXAMPLE.read_text(encoding="utf-8"))
    parameters = document["hexapod_workspace"]["ros__parameters"]
    parameters["recording"] = {"directory": str(tmp_path / "logs")}
    parameters["collision"]["obstacles"]["ball"]["shape"] = "cone"
    with running_node(tmp_path, params_text=yaml.safe_dump(document, sort_keys=False)) as node:
        try:
            code = node.process.wait(timeout=120.0)
        except subprocess.TimeoutExpired:
            pytest.fail(f"the node did not refuse to start:\n{node.output()}")
        assert code == 1
        assert (
            "collision.obstacles.ball.shape: expected one of box, cylinder, sphere, capsule, "
            "got 'cone'" in node.output()
        )
