"""``~/loads`` over real Fast DDS, from another process: the loads at a tool pose with the
node's loads parameters are the core's (``loads_at`` on the tool model, the centre of mass
moved into the tool frame, computed here from the same file); a new payload set at run time
changes the answer, a bad one is refused naming it and leaves the previous answer; a loads
limit is refused; the calls and the changes are in the log as rosbags, mcap_ros2 and Foxglove's
libraries read it."""

from __future__ import annotations

import contextlib
import json
import math
import time

import numpy as np
import pytest
from cli_support import run_main
from recording_support import read_with_foxglove, read_with_mcap_ros2, read_with_rosbags
from ros_support import require_ros

require_ros()

from geometry_msgs.msg import Pose, PoseStamped  # noqa: E402
from hexapod_workspace_msgs.msg import (  # noqa: E402
    AxisLimits,
    CommandedPose,
    ReachabilityResult,
    TiltTorsion,
)
from hexapod_workspace_msgs.srv import (  # noqa: E402
    CheckPath,
    CheckPoses,
    CheckPosesFlat,
    Loads,
    SchedulePath,
)
from rcl_interfaces.msg import Parameter as ParameterMsg  # noqa: E402
from rcl_interfaces.msg import ParameterType, ParameterValue  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402
from test_ros_cell import double_array, set_parameters  # noqa: E402

from hexapod_workspace.core.base.rotations import (  # noqa: E402
    matrix_to_quaternion,
    quaternion_to_matrix,
    tt_to_matrix,
)
from hexapod_workspace.core.cell.frames import cell_from_params_file, tool_model  # noqa: E402
from hexapod_workspace.core.evaluation.check import check  # noqa: E402
from hexapod_workspace.core.evaluation.loading import load_manipulator  # noqa: E402
from hexapod_workspace.core.evaluation.loads import (  # noqa: E402
    load_case_from_mapping,
    load_rows,
    loads_at,
)

NODE = "/hexapod_workspace"
SERVICE = f"{NODE}/loads"
TOOL_OFFSET = [0.0, 0.0, -0.12]
CENTER = [0.01, 0.0, -0.08]  # m, platform frame
NODE_PARAMS = {
    "tool.offset": TOOL_OFFSET,
    "work.origin": [0.0, 0.0, -1.1],
    "work.frame_id": "part",
    "load.mass": 40.0,
    "load.center_of_mass": CENTER,
    "process.wrench": [0.0, 0.0, -50.0, 0.0, 0.0, 0.0],
    "process.wrench_range": [300.0, 300.0, 300.0, 0.0, 0.0, 0.0],
    "stiffness.actuator": [2.0e7],
    "accuracy.actuator_error": [5.0e-6],
    "limits.actuator_force_max": [800.0],
    "limits.deflection_max": 1.5e-4,
    "motion.current_pose_topic": "/loads_current_pose",
    "axis_limits.rate": 4.0,
}


def double(name: str, value: float) -> ParameterMsg:
    return ParameterMsg(
        name=name, value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=value)
    )


def tool_pose(angles_deg, position) -> tuple[Pose, np.ndarray]:
    rotation = quaternion_to_matrix(
        matrix_to_quaternion(tt_to_matrix(np.radians([angles_deg]))[0])[None, :]
    )[0]
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = (float(v) for v in position)
    x, y, z, w = (float(v) for v in matrix_to_quaternion(rotation))
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = x, y, z, w
    return pose, rotation


def tool_setup(params_path, **changes):
    """The tool model and the loads (centre of mass in the tool frame) of the node's
    parameters file, with ``changes``."""
    import yaml

    platform = load_manipulator(params_path, loads_read=True)
    cell = cell_from_params_file(params_path)
    tree = yaml.safe_load(params_path.read_text(encoding="utf-8"))
    flat = {**tree["hexapod_workspace"]["ros__parameters"], **changes}
    case = load_case_from_mapping(flat).in_tool_frame(cell.tool.offset, cell.tool.rotation)
    return tool_model(platform, cell.tool), case


def expected_loads(params_path, rotation, position, **changes):
    """The core's loads at the tool pose, from the node's parameters file (and ``changes``)."""
    model, case = tool_setup(params_path, **changes)
    return loads_at(model, case, rotation, np.asarray(position))


POSITION = [0.0, 0.0, -1.42]  # the tool centre point, base frame, m
ANGLES = np.radians([[phi, theta, 0.0] for phi in (0.0, 90.0) for theta in range(0, 45, 5)])


def test_pose_verdicts_carry_the_loads_rows_and_the_rest_refuses(
    client, ros_client, workspace_node
):
    model, case = tool_setup(workspace_node.params_path)
    geometric = check(model, ANGLES, np.asarray(POSITION))
    rows = load_rows(model, case, tt_to_matrix(ANGLES), np.asarray(POSITION))
    held = geometric.reachable & rows.holds
    assert np.any(geometric.reachable & ~rows.holds), "need a pose only the loads refuse"
    assert any("deflection" in v for v in rows.violated) and any(held)
    names = [*geometric.margins, "actuator_force", "deflection"]
    expected = np.column_stack([*geometric.margins.values(), *rows.margins.values()])

    def assert_checks(checks) -> None:
        assert [c.reachable for c in checks] == held.tolist()
        for k, pose_check in enumerate(checks):
            assert list(pose_check.constraint_names) == names
            np.testing.assert_allclose(pose_check.margins, expected[k], rtol=1e-9, atol=1e-12)
            assert list(pose_check.violated) == geometric.violated[k] + rows.violated[k]

    request = CheckPoses.Request(
        orientations=[TiltTorsion(phi=p, theta=t, psi=s) for p, t, s in ANGLES.tolist()]
    )
    request.position.x, request.position.y, request.position.z = POSITION
    answer = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert answer.success, answer.message
    assert answer.message == f"{int(held.sum())}/{len(held)} reachable (loads' limits included)"
    assert_checks(answer.results)
    # the Pose form
    poses = [tool_pose(np.degrees(a), POSITION)[0] for a in ANGLES]
    assert_checks(
        client.call(CheckPoses, f"{NODE}/check_poses", CheckPoses.Request(poses=poses)).results
    )
    # the flat form: the rows as columns
    flat = CheckPosesFlat.Request(angles=ANGLES.reshape(-1).tolist())
    flat.position.x, flat.position.y, flat.position.z = POSITION
    answer = client.call(CheckPosesFlat, f"{NODE}/check_poses_flat", flat)
    assert list(answer.constraint_names) == names
    assert list(answer.reachable) == held.tolist()
    np.testing.assert_allclose(
        np.reshape(answer.margins, expected.shape), expected, rtol=1e-9, atol=1e-12
    )
    # a current pose: the axis limits are published as failed, naming the limits
    limits = "limits.actuator_force_max, limits.deflection_max: "
    published = ros_client.collect(AxisLimits, f"{NODE}/axis_limits", transient_local=True)
    current = PoseStamped(pose=poses[0])
    current.header.stamp.sec = 23
    for _ in range(30):  # until the subscription is matched and the limits published
        ros_client.publisher(PoseStamped, "/loads_current_pose").publish(current)
        with contextlib.suppress(AssertionError):
            ros_client.spin_until(
                lambda: any(m.header.stamp.sec == 23 for m in published),
                what="axis limits",
                timeout=2.0,
            )
        if any(m.header.stamp.sec == 23 for m in published):
            break
    axes = [m for m in published if m.header.stamp.sec == 23][-1]
    assert not axes.success and axes.message.startswith(limits + "the axis limits")

    # a commanded pose that only the loads refuse; its move is not checked
    only = int(np.flatnonzero(geometric.reachable & ~rows.holds)[0])
    results = ros_client.collect(ReachabilityResult, f"{NODE}/reachability")
    command = CommandedPose(
        request_id="loads-1",
        orientation=TiltTorsion(phi=float(ANGLES[only, 0]), theta=float(ANGLES[only, 1]), psi=0.0),
    )
    command.position.x, command.position.y, command.position.z = POSITION
    ros_client.publisher(CommandedPose, f"{NODE}/commanded_pose").publish(command)
    ros_client.spin_until(
        lambda: any(r.request_id == "loads-1" for r in results), what="the command's verdict"
    )
    (verdict,) = [r for r in results if r.request_id == "loads-1"]
    assert verdict.success and not verdict.check.reachable
    assert verdict.message.startswith("unreachable: " + ", ".join(rows.violated[only]) + "; ")
    assert f"move not checked: {limits}the move from the current pose" in verdict.message
    assert not verdict.motion_checked
    assert list(verdict.check.margins)[-2:] == pytest.approx(list(expected[only, -2:]))

    # what certifies more than poses refuses, naming the limits
    path = client.call(CheckPath, f"{NODE}/check_path", CheckPath.Request(poses=poses[:3]))
    assert not path.success and path.message.startswith(limits + "a path is not certified")
    schedule = client.call(
        SchedulePath, f"{NODE}/schedule_path", SchedulePath.Request(poses=poses[:3])
    )
    assert not schedule.success and schedule.message.startswith(limits + "a schedule")
    workspace = client.call(Trigger, f"{NODE}/compute_projected_workspace", Trigger.Request())
    assert not workspace.success and limits + "a workspace" in workspace.message
    # without the limits the same path is checked again
    for result in set_parameters(
        client, double_array("limits.actuator_force_max", []), double("limits.deflection_max", 0.0)
    ):
        assert result.successful, result.reason
    path = client.call(CheckPath, f"{NODE}/check_path", CheckPath.Request(poses=poses[:3]))
    assert path.success, path.message
    answer = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert list(answer.results[0].constraint_names) == list(geometric.margins)
    for result in set_parameters(
        client,
        double_array("limits.actuator_force_max", [800.0]),
        double("limits.deflection_max", 1.5e-4),
    ):
        assert result.successful, result.reason


def assert_answer(response, expected) -> None:
    assert response.success, response.message
    np.testing.assert_allclose(response.actuator_force, expected.actuator_force, rtol=1e-12)
    np.testing.assert_allclose(
        response.actuator_force_worst, expected.actuator_force_worst, rtol=1e-12
    )
    np.testing.assert_allclose(
        np.reshape(response.jacobian, (6, 6)), expected.jacobian, rtol=1e-12, atol=1e-15
    )
    np.testing.assert_allclose(
        np.reshape(response.stiffness, (6, 6)), expected.stiffness, rtol=1e-9, atol=1e-6
    )
    assert response.deflection_m == pytest.approx(expected.deflection_m, rel=1e-9)
    assert response.accuracy_m == pytest.approx(expected.accuracy_m, rel=1e-9)
    assert response.force_margin == pytest.approx(expected.force_margin, rel=1e-12)
    assert response.payload_capacity_kg == pytest.approx(expected.payload_capacity, rel=1e-12)
    assert response.limiting_actuator == expected.limiting_actuator


def test_loads_at_a_tool_pose_follow_the_parameters(client, workspace_node):
    position = [0.02, -0.01, -1.42]
    pose, rotation = tool_pose([30.0, 12.0, 5.0], position)
    response = client.call(Loads, SERVICE, Loads.Request(pose=pose))
    expected = expected_loads(workspace_node.params_path, rotation, position)
    assert_answer(response, expected)
    assert response.mass_kg == 40.0 and response.force_unit == "N"
    assert math.isfinite(response.force_margin) and math.isfinite(response.payload_capacity_kg)
    assert not response.singular
    assert response.frames.tool_offset.z == pytest.approx(-0.12)
    assert np.max(np.abs(response.actuator_force)) > 10.0  # 40 kg on six legs
    # the same pose given in the work frame (origin 1.1 m below the base, axes the base's)
    in_work = Loads.Request(pose=tool_pose([30.0, 12.0, 5.0], [0.02, -0.01, -0.32])[0])
    in_work.header.frame_id = "part"
    assert_answer(client.call(Loads, SERVICE, in_work), expected)

    # a new payload at run time: the answer follows
    (result,) = set_parameters(client, double("load.mass", 0.0))
    assert result.successful, result.reason
    unloaded = client.call(Loads, SERVICE, Loads.Request(pose=pose))
    assert_answer(
        unloaded, expected_loads(workspace_node.params_path, rotation, position, **{"load.mass": 0})
    )
    assert unloaded.mass_kg == 0.0
    # refused: named, the previous state kept
    for bad, named in [
        (double("load.mass", -1.0), "load.mass: expected one number >= 0"),
        (double_array("load.center_of_mass", [0.0, 0.0, -80.0]), "load.center_of_mass"),
        (double_array("stiffness.actuator", [0.0]), "stiffness.actuator: expected values > 0"),
        (double_array("limits.actuator_force_min", [950.0]), "limits.actuator_force_min"),
        (double_array("stiffness.actuator", []), "limits.deflection_max: needs stiffness"),
    ]:
        (result,) = set_parameters(client, bad)
        assert not result.successful
        assert result.reason.startswith(named.split(":")[0]) and named in result.reason
        again = client.call(Loads, SERVICE, Loads.Request(pose=pose))
        assert list(again.actuator_force) == list(unloaded.actuator_force)
    (result,) = set_parameters(client, double("load.mass", 40.0))
    assert result.successful

    # bad requests: named, one line
    nowhere = Loads.Request(pose=pose)
    nowhere.header.frame_id = "elsewhere"
    nan_pose, _ = tool_pose([0.0, 0.0, 0.0], [math.nan, 0.0, -1.4])
    for bad, named in [(nowhere, "elsewhere"), (Loads.Request(pose=nan_pose), "pose: expected")]:
        answer = client.call(Loads, SERVICE, bad)
        assert not answer.success and named in answer.message and "\n" not in answer.message

    # singular (the legs in the base plane: platform joints 0.1 m above the platform origin,
    # the tool 0.12 m below it): +inf forces, never a finite wrong value
    far, _ = tool_pose([0.0, 0.0, 0.0], [0.0, 0.0, -0.22])
    singular = client.call(Loads, SERVICE, Loads.Request(pose=far))
    assert singular.success and singular.singular
    assert np.all(np.isinf(singular.actuator_force_worst))

    time.sleep(1.0)  # the recorder thread writes within its flush interval
    workspace_node.stop()
    (log,) = sorted(workspace_node.record_dir.glob("*.mcap"))
    for read in (read_with_rosbags, read_with_mcap_ros2):
        messages = read(log)
        answers = [m for topic, _, m in messages if topic == f"{SERVICE}/response"]
        assert len(answers) == 11, read.__name__
        assert list(answers[0].actuator_force) == list(response.actuator_force)
        changes = [m for topic, _, m in messages if topic == f"{NODE}/parameter_changes"]
        assert any(m.accepted and list(m.names) == ["load.mass"] for m in changes)
        assert any(not m.accepted and "load.mass" in m.reason for m in changes)
    foxglove = read_with_foxglove(log, workspace_node.record_dir)[f"{SERVICE}/response"]
    assert foxglove["count"] == 11
    assert foxglove["messages"][0]["actuator_force"] == list(response.actuator_force)
    # replay lists every call: the pose asked, the payload, the answer
    code, out, _ = run_main("replay", str(log), "--json")
    assert code == 0
    calls = json.loads(out)["loads"]
    assert len(calls) == 11
    assert calls[0]["position"] == position and calls[0]["mass_kg"] == 40.0
    assert calls[1]["frame_id"] == "part"
    assert calls[0]["actuator_force_worst"] == list(response.actuator_force_worst)
    assert not calls[-3]["success"] and "elsewhere" in calls[-3]["message"]
    assert calls[-1]["singular"] and calls[-1]["actuator_force_worst"] == [None] * 6
    code, text, _ = run_main("replay", str(log))
    assert code == 0
    assert f"at (0.02, -0.01, -1.42) m: {response.message}" in text
