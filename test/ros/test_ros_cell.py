"""The machining cell on the node over real Fast DDS: tool and work frames, the tool table, feeds
on ~/check_path, ~/axis_limits.

The node runs from the install space (another process) with a cell parameters file; every
verdict is compared with the ROS-free core on the *platform* model at the platform pose the tool
pose denotes, computed here with plain 4x4 homogeneous transforms written from the definitions
(``T_OP = T_OC · T_PC⁻¹``, ``T_OC = T_OW · T_WC``), not with hexapod_workspace.core.cell.frames.
"""

from __future__ import annotations

import contextlib
import math
import time

import numpy as np
import pytest
from cli_support import run_main
from frames_reference import homogeneous, tt
from recording_support import read_with_rosbags
from ros_support import require_ros

require_ros()

from geometry_msgs.msg import Pose, PoseStamped  # noqa: E402
from hexapod_workspace_msgs.msg import (  # noqa: E402
    AxisLimits,
    CommandedPose,
    ReachabilityResult,
    TiltTorsion,
)
from hexapod_workspace_msgs.srv import CheckPath, CheckPoses, CheckPosesFlat  # noqa: E402
from rcl_interfaces.msg import Parameter as ParameterMsg  # noqa: E402
from rcl_interfaces.msg import ParameterType, ParameterValue  # noqa: E402
from rcl_interfaces.srv import GetParameters, SetParameters  # noqa: E402

from hexapod_workspace import check, check_path  # noqa: E402
from hexapod_workspace.core.base.rotations import (  # noqa: E402
    matrix_to_quaternion,
    matrix_to_tt,
)
from hexapod_workspace.core.cell.frames import cell_from_params_file, tool_model  # noqa: E402
from hexapod_workspace.core.cell.reach import AXES, axis_limits  # noqa: E402
from hexapod_workspace.core.evaluation.loading import load_manipulator  # noqa: E402
from hexapod_workspace.core.model.manipulator import Manipulator  # noqa: E402
from hexapod_workspace.core.motions.speeds import actuator_rates, feed_limits  # noqa: E402
from hexapod_workspace.ros.conversions import margins_by_name  # noqa: E402

NODE = "/hexapod_workspace"
CURRENT_POSE_TOPIC = "/cell_current_pose"
TOOL_OFFSET = [0.01, -0.015, -0.12]
TOOL_ANGLES = [0.3, 0.1, -0.2]
T2_OFFSET = [0.0, 0.0, -0.2]
T2_ANGLES = [0.0, 0.05, 0.0]
WORK_ORIGIN = [0.05, -0.03, -1.05]
WORK_ANGLES = [0.5, 0.08, 0.3]
SPEED_MAX = 0.01  # m/s
NODE_PARAMS = {
    "tool.offset": TOOL_OFFSET,
    "tool.orientation": TOOL_ANGLES,
    "tools.T1.offset": [0.0, 0.0, -0.1],
    "tools.T2.offset": T2_OFFSET,
    "tools.T2.orientation": T2_ANGLES,
    "work.origin": WORK_ORIGIN,
    "work.orientation": WORK_ANGLES,
    "work.frame_id": "part",
    "limits.actuator_speed_max": [SPEED_MAX],
    "motion.current_pose_topic": CURRENT_POSE_TOPIC,
    "axis_limits.rate": 4.0,
}


# ------------------------------------------------------------------ independent transforms
# (test/frames_reference.py)
def platform_of(t_oc: np.ndarray, offset, angles) -> np.ndarray:
    """T_OP = T_OC · T_PC⁻¹."""
    return t_oc @ np.linalg.inv(homogeneous(tt(*angles), offset))


def base_of(t_wc: np.ndarray) -> np.ndarray:
    """T_OC = T_OW · T_WC."""
    return homogeneous(tt(*WORK_ANGLES), WORK_ORIGIN) @ t_wc


def tool_poses(count: int, seed: int) -> list[np.ndarray]:
    """Tool poses (4x4, base frame) near the workspace, some reachable, some not."""
    rng = np.random.default_rng(seed)
    poses = []
    for _ in range(count):
        angles = (rng.uniform(-math.pi, math.pi), rng.uniform(0.0, 0.45), rng.uniform(-0.4, 0.4))
        position = np.array([0.0, 0.0, -1.3]) + rng.uniform(-0.12, 0.12, 3)
        poses.append(homogeneous(tt(*angles), position))
    return poses


def assert_platform_verdict(result, platform: Manipulator, t_op: np.ndarray) -> None:
    """A PoseCheck has the verdict and margins of the platform pose t_op."""
    expected = check(platform, matrix_to_tt(t_op[:3, :3]), t_op[:3, 3])
    assert result.reachable == bool(expected.reachable[0])
    margins = margins_by_name(result)
    for name, values in expected.margins.items():
        if math.isfinite(values[0]):
            assert margins[name] == pytest.approx(values[0], abs=1e-9), name


def ros_pose(t: np.ndarray) -> Pose:
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = (float(v) for v in t[:3, 3])
    x, y, z, w = (float(v) for v in matrix_to_quaternion(t[:3, :3]))
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = x, y, z, w
    return pose


def tilt_torsion(t: np.ndarray) -> TiltTorsion:
    phi, theta, psi = (float(v) for v in matrix_to_tt(t[:3, :3]))
    return TiltTorsion(phi=phi, theta=theta, psi=psi)


def double_array(name: str, values) -> ParameterMsg:
    return ParameterMsg(
        name=name,
        value=ParameterValue(
            type=ParameterType.PARAMETER_DOUBLE_ARRAY, double_array_value=[float(v) for v in values]
        ),
    )


def integer(name: str, value: int) -> ParameterMsg:
    return ParameterMsg(
        name=name, value=ParameterValue(type=ParameterType.PARAMETER_INTEGER, integer_value=value)
    )


def set_parameters(client, *parameters: ParameterMsg):
    request = SetParameters.Request(parameters=list(parameters))
    return client.call(SetParameters, f"{NODE}/set_parameters", request).results


@pytest.fixture(scope="module")
def platform(workspace_node) -> Manipulator:
    return load_manipulator(workspace_node.params_path)


@pytest.fixture
def tool_number_reset(client):
    yield
    (result,) = set_parameters(client, integer("tool.number", 0))
    assert result.successful, result.reason


# ------------------------------------------------------------------ frames round trip
def test_cell_parameters_round_trip_through_the_node(client, workspace_node):
    """The node holds the file's cell parameters as the CLI reads them (--config), and every
    result says which tool and work frame it was computed with."""
    cell = cell_from_params_file(workspace_node.params_path)
    names = ["tool.offset", "tool.orientation", "tool.number", "work.origin"]
    names += ["work.orientation", "work.frame_id", "tools.T2.offset", "tools.T2.orientation"]
    names += ["tools.T1.offset", "tools.T1.orientation", "limits.actuator_speed_max"]
    names += ["limits.actuator_accel_max"]
    values = client.call(
        GetParameters, f"{NODE}/get_parameters", GetParameters.Request(names=names)
    ).values
    got = dict(zip(names, values, strict=True))
    np.testing.assert_array_equal(got["tool.offset"].double_array_value, cell.tool.offset)
    np.testing.assert_array_equal(got["tool.orientation"].double_array_value, TOOL_ANGLES)
    assert got["tool.number"].integer_value == 0
    np.testing.assert_array_equal(got["work.origin"].double_array_value, cell.work.origin)
    np.testing.assert_array_equal(got["work.orientation"].double_array_value, WORK_ANGLES)
    assert got["work.frame_id"].string_value == cell.work.frame_id == "part"
    np.testing.assert_array_equal(got["tools.T2.offset"].double_array_value, cell.tools[2].offset)
    np.testing.assert_array_equal(got["tools.T2.orientation"].double_array_value, T2_ANGLES)
    np.testing.assert_array_equal(got["tools.T1.orientation"].double_array_value, [0.0] * 3)
    assert list(got["limits.actuator_speed_max"].double_array_value) == [SPEED_MAX]
    assert list(got["limits.actuator_accel_max"].double_array_value) == [0.0]  # the default

    t_oc = tool_poses(1, seed=1)[0]
    response = client.call(
        CheckPoses, f"{NODE}/check_poses", CheckPoses.Request(poses=[ros_pose(t_oc)])
    )
    frames = response.frames
    assert frames.tool_number == 0 and frames.work_frame_id == "part"
    offset = frames.tool_offset
    assert [offset.x, offset.y, offset.z] == TOOL_OFFSET
    orientation = frames.tool_orientation
    assert [orientation.phi, orientation.theta, orientation.psi] == TOOL_ANGLES
    origin = frames.work_origin
    assert [origin.x, origin.y, origin.z] == WORK_ORIGIN
    assert frames.request_frame_id == ""


# ------------------------------------------------------------------ tool and work frames
def test_a_tool_pose_gets_the_verdict_of_the_platform_pose_it_denotes(client, platform):
    poses = tool_poses(40, seed=2)
    # the Pose form and the T&T form at one position, base frame
    response = client.call(
        CheckPoses, f"{NODE}/check_poses", CheckPoses.Request(poses=[ros_pose(t) for t in poses])
    )
    assert response.success, response.message
    for result, t_oc in zip(response.results, poses, strict=True):
        assert_platform_verdict(result, platform, platform_of(t_oc, TOOL_OFFSET, TOOL_ANGLES))
    reachable = sum(r.reachable for r in response.results)
    assert 0 < reachable < len(poses)  # both verdicts are exercised

    position = poses[0][:3, 3]
    same_position = [homogeneous(t[:3, :3], position) for t in poses]
    request = CheckPoses.Request(orientations=[tilt_torsion(t) for t in same_position])
    request.position.x, request.position.y, request.position.z = (float(v) for v in position)
    response = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert response.success, response.message
    for result, t_oc in zip(response.results, same_position, strict=True):
        assert_platform_verdict(result, platform, platform_of(t_oc, TOOL_OFFSET, TOOL_ANGLES))


def test_work_frame_poses_on_every_interface(client, ros_client, platform):
    """check_poses (both forms), the flat check, check_path and commanded_pose take poses in
    the work frame (header.frame_id = work.frame_id)."""
    t_ow = homogeneous(tt(*WORK_ANGLES), WORK_ORIGIN)
    local = [np.linalg.inv(t_ow) @ t for t in tool_poses(40, seed=2)]
    expected = [platform_of(base_of(t), TOOL_OFFSET, TOOL_ANGLES) for t in local]

    request = CheckPoses.Request(poses=[ros_pose(t) for t in local])
    request.header.frame_id = "part"
    response = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert response.success, response.message
    assert response.frames.request_frame_id == "part"
    for result, t_op in zip(response.results, expected, strict=True):
        assert_platform_verdict(result, platform, t_op)
    assert 0 < sum(r.reachable for r in response.results) < len(local)

    # T&T at one position (the nested and the flat form)
    position = local[0][:3, 3]
    at_one = [homogeneous(t[:3, :3], position) for t in local]
    expected_one = [platform_of(base_of(t), TOOL_OFFSET, TOOL_ANGLES) for t in at_one]
    nested = CheckPoses.Request(orientations=[tilt_torsion(t) for t in at_one])
    nested.header.frame_id = "part"
    nested.position.x, nested.position.y, nested.position.z = (float(v) for v in position)
    response = client.call(CheckPoses, f"{NODE}/check_poses", nested)
    assert response.success, response.message
    for result, t_op in zip(response.results, expected_one, strict=True):
        assert_platform_verdict(result, platform, t_op)
    flat = CheckPosesFlat.Request()
    flat.header.frame_id = "part"
    flat.position = nested.position
    flat.angles = [float(v) for t in at_one for v in matrix_to_tt(t[:3, :3])]
    answer = client.call(CheckPosesFlat, f"{NODE}/check_poses_flat", flat)
    assert answer.success, answer.message
    assert answer.frames.request_frame_id == "part"
    columns = list(answer.constraint_names)
    margins = np.array(answer.margins).reshape(len(at_one), len(columns))
    for k, t_op in enumerate(expected_one):
        truth = check(platform, matrix_to_tt(t_op[:3, :3]), t_op[:3, 3])
        assert answer.reachable[k] == bool(truth.reachable[0])
        for j, name in enumerate(columns):
            if math.isfinite(truth.margins[name][0]):
                assert margins[k, j] == pytest.approx(truth.margins[name][0], abs=1e-9)

    # check_path: the moves of the work-frame path are those of its base-frame path
    path = [homogeneous(tt(0.2 * k, 0.1, 0.0), [0.01 * k, 0.0, -0.3]) for k in range(5)]
    request = CheckPath.Request(poses=[ros_pose(t) for t in path])
    request.header.frame_id = "part"
    response = client.call(CheckPath, f"{NODE}/check_path", request)
    assert response.success, response.message
    base = [base_of(t) for t in path]
    model = tool_model(platform, cell_tool())
    truth = check_path(
        model,
        np.array([t[:3, 3] for t in base]),
        rotations=np.array([t[:3, :3] for t in base]),
    )
    assert [w.reachable for w in response.waypoints] == truth.waypoints.reachable.tolist()
    assert [s.ok for s in response.segments] == truth.segments.ok.tolist()
    np.testing.assert_allclose(
        [[p.position.x, p.position.y, p.position.z] for p in response.poses],
        [t[:3, 3] for t in base],
        atol=1e-12,
    )
    for result, t_oc in zip(response.waypoints, base, strict=True):
        assert_platform_verdict(result, platform, platform_of(t_oc, TOOL_OFFSET, TOOL_ANGLES))

    # commanded_pose in the work frame
    results = ros_client.collect(ReachabilityResult, f"{NODE}/reachability")
    publisher = ros_client.publisher(CommandedPose, f"{NODE}/commanded_pose")
    for k, t in enumerate(local[:4]):
        command = CommandedPose(request_id=f"cell-{k}", use_pose=True, pose=ros_pose(t))
        command.header.frame_id = "part"
        publisher.publish(command)
    ros_client.spin_until(
        lambda: len([r for r in results if r.request_id.startswith("cell-")]) >= 4,
        what="the work-frame commands' results",
    )
    for result in results:
        if result.request_id.startswith("cell-"):
            k = int(result.request_id.split("-")[1])
            assert result.success, result.message
            assert result.frames.request_frame_id == "part"
            assert_platform_verdict(result.check, platform, expected[k])


def cell_tool():
    from hexapod_workspace.core.cell.frames import Tool

    return Tool(np.array(TOOL_OFFSET), np.array(TOOL_ANGLES))


def test_a_pose_in_another_frame_is_refused_with_the_reason(client, ros_client):
    t = tool_poses(1, seed=4)[0]
    reason = "header.frame_id"
    request = CheckPoses.Request(poses=[ros_pose(t)])
    request.header.frame_id = "world"
    response = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert not response.success and reason in response.message and "'world'" in response.message
    assert "'part'" in response.message  # names the frames it takes
    flat = CheckPosesFlat.Request(angles=[0.0, 0.0, 0.0])
    flat.header.frame_id = "world"
    answer = client.call(CheckPosesFlat, f"{NODE}/check_poses_flat", flat)
    assert not answer.success and reason in answer.message
    path = CheckPath.Request(poses=[ros_pose(t), ros_pose(t)])
    path.header.frame_id = "world"
    response = client.call(CheckPath, f"{NODE}/check_path", path)
    assert not response.success and reason in response.message
    results = ros_client.collect(ReachabilityResult, f"{NODE}/reachability")
    command = CommandedPose(request_id="wrong-frame", use_pose=True, pose=ros_pose(t))
    command.header.frame_id = "world"
    ros_client.publisher(CommandedPose, f"{NODE}/commanded_pose").publish(command)
    ros_client.spin_until(
        lambda: any(r.request_id == "wrong-frame" for r in results), what="the refusal"
    )
    (refused,) = [r for r in results if r.request_id == "wrong-frame"]
    assert not refused.success and reason in refused.message


# ------------------------------------------------------------------ run-time changes
def test_a_tool_change_selects_the_table_entry_and_bad_changes_leave_it(
    client, platform, tool_number_reset
):
    t_oc = tool_poses(1, seed=5)[0]
    request = CheckPoses.Request(poses=[ros_pose(t_oc)])
    (result,) = set_parameters(client, integer("tool.number", 2))
    assert result.successful, result.reason
    response = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert response.frames.tool_number == 2
    assert_platform_verdict(response.results[0], platform, platform_of(t_oc, T2_OFFSET, T2_ANGLES))

    # refused, each naming the parameter and the value; tool 2 stays in force
    for parameter, words in (
        (integer("tool.number", 7), ["tool.number", "7", "T1, T2"]),
        (double_array("tools.T2.offset", [math.nan, 0.0, 0.0]), ["tools.T2.offset", "nan"]),
        (double_array("work.origin", [0.0, math.inf, 0.0]), ["work.origin", "inf"]),
        (double_array("tools.T9.orientation", [0.0, 0.0, 0.0]), ["tools.T9.offset", "missing"]),
        (double_array("limits.actuator_speed_max", [-1.0]), ["actuator_speed_max", "-1"]),
        (double_array("limits.actuator_accel_max", [0.5, 0.5]), ["actuator_accel_max", "1 or 6"]),
    ):
        (result,) = set_parameters(client, parameter)
        assert not result.successful, parameter.name
        for word in words:
            assert word.lower() in result.reason.lower(), (word, result.reason)
        response = client.call(CheckPoses, f"{NODE}/check_poses", request)
        assert response.frames.tool_number == 2
        offset = response.frames.tool_offset
        assert [offset.x, offset.y, offset.z] == T2_OFFSET
    # a tool added at run time, then selected
    (result,) = set_parameters(client, double_array("tools.T5.offset", [0.0, 0.01, -0.05]))
    assert result.successful, result.reason
    (result,) = set_parameters(client, integer("tool.number", 5))
    assert result.successful, result.reason
    response = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert response.frames.tool_number == 5
    assert_platform_verdict(
        response.results[0], platform, platform_of(t_oc, [0.0, 0.01, -0.05], [0.0, 0.0, 0.0])
    )


# ------------------------------------------------------------------ feeds on ~/check_path
def test_check_path_reports_actuator_speeds_and_feed_max(client, platform):
    path = [
        homogeneous(tt(0.3 * k, 0.05 + 0.02 * k, 0.0), [0.02 * k, -0.01 * k, -1.3])
        for k in range(5)
    ]
    path.append(homogeneous(tt(1.2, 0.2, 0.3), path[-1][:3, 3]))  # a rotation on the spot
    positions = np.array([t[:3, 3] for t in path])
    rotations = np.array([t[:3, :3] for t in path])
    feeds = [600.0, 1200.0, math.nan, 3000.0, 500.0]
    request = CheckPath.Request(
        poses=[ros_pose(t) for t in path],
        feeds_mm_min=feeds,
        rapid=[False, False, False, True, False],
        rapid_feed_mm_min=8000.0,
        rotary_feed_deg_min=900.0,
    )
    response = client.call(CheckPath, f"{NODE}/check_path", request)
    assert response.success, response.message
    model = tool_model(platform, cell_tool())
    rates = actuator_rates(model, positions, rotations, speed_limits=[SPEED_MAX] * 6)
    used = np.array([600.0, 1200.0, math.nan, 8000.0, math.nan]) * 1e-3 / 60.0
    rotary = np.full(5, math.radians(900.0) / 60.0)
    truth = feed_limits(rates, used, rotary, [SPEED_MAX] * 6)
    assert list(response.actuator_speed_max) == [SPEED_MAX] * 6
    assert len(response.speeds) == 5
    for k, speed in enumerate(response.speeds):
        checked = truth.speed_ok[k] is not None
        assert speed.speed_checked == checked, k
        if not checked:  # move 2: no feed given
            assert math.isnan(speed.duration_s) and math.isnan(speed.actuator_speed_peak)
            continue
        assert speed.speed_ok == truth.speed_ok[k]
        assert speed.duration_s == pytest.approx(truth.duration[k], rel=1e-12)
        assert speed.actuator_speed_peak == pytest.approx(truth.speed_peak[k], rel=1e-12)
    assert response.speeds[3].rapid and response.speeds[3].feed_mm_min == pytest.approx(8000.0)
    assert response.speeds[4].rotary
    assert response.speeds[4].feed_deg_min == pytest.approx(900.0)
    assert response.speeds[4].feed_max_deg_min == pytest.approx(
        truth.feed_max[4] / (math.radians(1.0) / 60.0), rel=1e-12
    )
    assert math.isnan(response.speeds[4].feed_max_mm_min)
    assert response.speeds[0].feed_max_mm_min == pytest.approx(
        truth.feed_max[0] / (1e-3 / 60.0), rel=1e-12
    )
    assert any(not s.speed_ok for s in response.speeds if s.speed_checked)  # the limit bites
    slow = [k for k, s in enumerate(response.speeds) if s.speed_checked and not s.speed_ok]
    assert (
        not response.ok and f"moves {', '.join(map(str, slow))} must slow down" in response.message
    )

    # the same moves given their durations: the same speeds
    durations = [float(d) for d in truth.duration]
    durations[2], durations[4] = 1.0, 2.0
    timed = CheckPath.Request(poses=[ros_pose(t) for t in path], durations_s=durations)
    response = client.call(CheckPath, f"{NODE}/check_path", timed)
    assert response.success, response.message
    for k in (0, 1, 3):
        assert response.speeds[k].actuator_speed_peak == pytest.approx(
            truth.speed_peak[k], rel=1e-9
        )
        assert response.speeds[k].duration_s == pytest.approx(durations[k], rel=1e-12)
    assert response.speeds[4].duration_s == pytest.approx(2.0)

    # bad feeds: refused with the field and the value
    good = [ros_pose(t) for t in path]
    for bad, words in (
        (CheckPath.Request(poses=good, feeds_mm_min=[-5.0]), ["feeds_mm_min[0]", "got -5.0"]),
        (CheckPath.Request(poses=good, feeds_mm_min=[1.0, 2.0]), ["feeds_mm_min", "2"]),
        (
            CheckPath.Request(poses=good, feeds_mm_min=[100.0], durations_s=[1.0] * 5),
            ["not both"],
        ),
        (CheckPath.Request(poses=good, durations_s=[1.0, 0.0, 1.0, 1.0, 1.0]), ["durations_s[1]"]),
        (CheckPath.Request(poses=good, rapid_feed_mm_min=math.inf), ["rapid_feed_mm_min"]),
        (
            CheckPath.Request(poses=good, feeds_mm_min=[100.0], interpolation=1),
            ["SLERP"],
        ),
    ):
        response = client.call(CheckPath, f"{NODE}/check_path", bad)
        assert not response.success
        for word in words:
            assert word in response.message, (word, response.message)
    # no feed: no speeds, as before
    response = client.call(CheckPath, f"{NODE}/check_path", CheckPath.Request(poses=good))
    assert response.success and len(response.speeds) == 0


# ------------------------------------------------------------------ curved moves
def test_check_path_takes_arcs_and_bezier_moves_in_the_work_frame(client, platform):
    """A CIRCLE move and a Bézier move given in the work frame are checked along their curves:
    the node's answer is the core's on the base-frame curves, mapped here with a plain 4x4
    transform (points as points, the arc's axis as a vector)."""
    rotation = tt(0.0, 0.0, 0.0)
    ends = [[0.03, 0.0, -0.25], [-0.03, 0.0, -0.25], [0.03, 0.01, -0.26]]
    path = [homogeneous(rotation, end) for end in ends]
    arc = [0.0, 0.0, -0.25, 0.0, 0.0, 1.0, math.pi]  # half a turn about the part's z
    inner = [0.0, 0.04, -0.25, 0.02, 0.05, -0.26]  # the Bézier move's b1, b2
    nan7, nan6 = [math.nan] * 7, [math.nan] * 6
    feeds = [600.0, 900.0]
    request = CheckPath.Request(
        poses=[ros_pose(t) for t in path],
        arcs=[*arc, *nan7],
        beziers=[*nan6, *inner],
        feeds_mm_min=feeds,
    )
    request.header.frame_id = "part"
    response = client.call(CheckPath, f"{NODE}/check_path", request)
    assert response.success, response.message
    t_ow = homogeneous(tt(*WORK_ANGLES), WORK_ORIGIN)

    def point(p):
        return (t_ow @ np.r_[p, 1.0])[:3]

    base = [base_of(t) for t in path]
    arcs = np.array([[*point(arc[:3]), *(t_ow[:3, :3] @ arc[3:6]), arc[6]], nan7])
    beziers = np.array([nan6, [*point(inner[:3]), *point(inner[3:])]])
    model = tool_model(platform, cell_tool())
    positions = np.array([t[:3, 3] for t in base])
    rotations = np.array([t[:3, :3] for t in base])
    truth = check_path(model, positions, rotations=rotations, arcs=arcs, beziers=beziers)
    straight = check_path(model, positions, rotations=rotations)
    assert [s.ok for s in response.segments] == truth.segments.ok.tolist()
    for segment, bound in zip(
        response.segments, truth.segments.min_relative_margin_bound, strict=True
    ):
        assert segment.min_relative_margin_bound == pytest.approx(bound, rel=1e-9)
    # the curves are not the chords: their certified margins differ
    assert not np.allclose(
        truth.segments.min_relative_margin_bound, straight.segments.min_relative_margin_bound
    )
    rates = actuator_rates(
        model, positions, rotations, speed_limits=[SPEED_MAX] * 6, arcs=arcs, beziers=beziers
    )
    used = np.array(feeds) * 1e-3 / 60.0
    speeds = feed_limits(rates, used, np.full(2, math.nan), [SPEED_MAX] * 6)
    for k, speed in enumerate(response.speeds):
        assert speed.actuator_speed_peak == pytest.approx(speeds.speed_peak[k], rel=1e-12)
        assert speed.duration_s == pytest.approx(speeds.duration[k], rel=1e-12)
    assert response.speeds[0].duration_s == pytest.approx(
        math.pi * 0.03 / (600.0 * 1e-3 / 60.0), rel=1e-12
    )
    # rows of the wrong length are refused with the field
    for bad, word in (
        (CheckPath.Request(poses=request.poses, arcs=arc), "arcs: expected none or 7 values"),
        (CheckPath.Request(poses=request.poses, beziers=inner), "beziers: expected none or 6"),
    ):
        answer = client.call(CheckPath, f"{NODE}/check_path", bad)
        assert not answer.success and word in answer.message, answer.message


# ------------------------------------------------------------------ ~/axis_limits
def test_axis_limits_follow_the_current_pose(ros_client, client, platform):
    limits = ros_client.collect(AxisLimits, f"{NODE}/axis_limits", transient_local=True)
    publisher = ros_client.publisher(PoseStamped, CURRENT_POSE_TOPIC)
    t_oc = homogeneous(tt(0.4, 0.15, 0.1), [0.02, 0.01, -1.25])
    stamped = PoseStamped(pose=ros_pose(t_oc))
    stamped.header.frame_id = "base"
    stamped.header.stamp.sec = 17

    def ours() -> list:
        return [m for m in limits if m.header.stamp.sec == 17]

    for _ in range(30):  # until the subscription is matched and the limits computed
        publisher.publish(stamped)
        with contextlib.suppress(AssertionError):
            ros_client.spin_until(lambda: bool(ours()), what="axis limits", timeout=2.0)
        if ours():
            break
    message = ours()[-1]
    assert message.success, message.message
    assert list(message.axes) == list(AXES) and message.frame == "base"
    model = tool_model(platform, cell_tool())
    truth = axis_limits(model, t_oc[:3, :3], t_oc[:3, 3], frame="base")
    for k, name in enumerate(AXES):
        assert message.plus[k] == pytest.approx(truth[name].plus, rel=1e-12), name
        assert message.minus[k] == pytest.approx(truth[name].minus, rel=1e-12), name
        assert message.limited_by_plus[k] == ",".join(truth[name].limited_by_plus)
    assert any(p < t for p, t in zip(message.plus, message.t_max, strict=True))
    assert message.frames.work_frame_id == "part"


def test_a_workspace_is_the_tool_centre_points_and_says_its_frames(client, platform):
    """The projected workspace at pose.position is the tool model's (the orientation workspace
    about the tool centre point), and its summary carries the frames."""
    from hexapod_workspace_msgs.msg import WorkspaceSummary
    from std_srvs.srv import Trigger

    from hexapod_workspace import projected_workspace
    from hexapod_workspace.core.base import resolution

    summaries = client.collect(WorkspaceSummary, f"{NODE}/workspace_summary")
    response = client.call(Trigger, f"{NODE}/compute_projected_workspace", Trigger.Request())
    assert response.success, response.message
    client.spin_until(
        lambda: any(s.message == response.message for s in summaries), what="the summary"
    )
    summary = next(s for s in summaries if s.message == response.message)
    assert summary.frames.work_frame_id == "part" and summary.frames.tool_number == 0
    offset = summary.frames.tool_offset
    assert [offset.x, offset.y, offset.z] == TOOL_OFFSET
    model = tool_model(platform, cell_tool())
    expected = projected_workspace(
        model,
        tuple(platform.position),
        n_phi=resolution.DEFAULT_N_PHI,
        tolerance=resolution.DEFAULT_TOLERANCE,
    )
    assert summary.tilt_max == pytest.approx(expected.tilt_max, abs=1e-12)
    assert summary.tilt_min == pytest.approx(expected.tilt_min, abs=1e-12)
    platform_only = projected_workspace(
        platform,
        tuple(platform.position),
        n_phi=resolution.DEFAULT_N_PHI,
        tolerance=resolution.DEFAULT_TOLERANCE,
    )
    assert abs(platform_only.tilt_max - expected.tilt_max) > 1e-3  # the tool changes it


def test_the_log_records_parameter_changes_and_the_frames(client, workspace_node):
    (result,) = set_parameters(client, integer("tool.number", 99))
    assert not result.successful
    response = client.call(
        CheckPoses,
        f"{NODE}/check_poses",
        CheckPoses.Request(poses=[ros_pose(tool_poses(1, seed=6)[0])]),
    )
    assert response.success
    time.sleep(1.0)  # the recorder thread writes within its flush interval
    workspace_node.stop()
    (log,) = sorted(workspace_node.record_dir.glob("*.mcap"))
    messages = read_with_rosbags(log)
    changes = [m for topic, _, m in messages if topic == f"{NODE}/parameter_changes"]
    refused = [m for m in changes if not m.accepted]
    assert any("tool.number" in m.reason and list(m.values) == ["99"] for m in refused)
    assert any(m.accepted and list(m.names) == ["tool.number"] for m in changes)
    assert any(m.accepted and list(m.names) == ["tools.T5.offset"] for m in changes)
    responses = [m for topic, _, m in messages if topic == f"{NODE}/check_poses/response"]
    assert responses and responses[-1].frames.work_frame_id == "part"
    limits = [m for topic, _, m in messages if topic == f"{NODE}/axis_limits"]
    assert limits and limits[-1].success
    # replay reports them
    code, out, _ = run_main("replay", str(log))
    assert code == 0
    assert "tool.number = 99: refused: tool.number: tool 99 is not in the tool table" in out
    assert "tools.T5.offset = [0.0, 0.01, -0.05]: applied" in out
    assert "axis limits: " in out and "(base frame; m, rad): x -" in out
