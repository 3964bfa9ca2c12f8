"""``~/loads`` over real Fast DDS, from another process: the loads at a tool pose with the
node's loads parameters are the core's (``loads_at`` on the tool model, the centre of mass
moved into the tool frame, computed here from the same file); a new payload set at run time
changes the answer, a bad one is refused naming it and leaves the previous answer; a loads
limit is refused; the calls and the changes are in the log as rosbags, mcap_ros2 and Foxglove's
libraries read it."""

from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest
from cli_support import run_main
from recording_support import read_with_foxglove, read_with_mcap_ros2, read_with_rosbags
from ros_support import require_ros

require_ros()

from geometry_msgs.msg import Pose  # noqa: E402
from hexapod_workspace_msgs.srv import Loads  # noqa: E402
from rcl_interfaces.msg import Parameter as ParameterMsg  # noqa: E402
from rcl_interfaces.msg import ParameterType, ParameterValue  # noqa: E402
from test_ros_cell import double_array, set_parameters  # noqa: E402

from hexapod_workspace.core.base.rotations import (  # noqa: E402
    matrix_to_quaternion,
    quaternion_to_matrix,
    tt_to_matrix,
)
from hexapod_workspace.core.cell.frames import cell_from_params_file, tool_model  # noqa: E402
from hexapod_workspace.core.evaluation.loading import load_manipulator  # noqa: E402
from hexapod_workspace.core.evaluation.loads import (  # noqa: E402
    load_case_from_mapping,
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


def expected_loads(params_path, rotation, position, **changes):
    """The core's loads at the tool pose, from the node's parameters file (and ``changes``)."""
    import yaml

    platform = load_manipulator(params_path)
    cell = cell_from_params_file(params_path)
    tree = yaml.safe_load(params_path.read_text(encoding="utf-8"))
    flat = {**tree["hexapod_workspace"]["ros__parameters"], **changes}
    case = load_case_from_mapping(flat).in_tool_frame(cell.tool.offset, cell.tool.rotation)
    return loads_at(tool_model(platform, cell.tool), case, rotation, np.asarray(position))


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
    assert math.isnan(response.force_margin) and math.isnan(response.payload_capacity_kg)
    assert response.limiting_actuator == expected.limiting_actuator


def test_loads_at_a_tool_pose_follow_the_parameters(client, workspace_node):
    position = [0.02, -0.01, -1.42]
    pose, rotation = tool_pose([30.0, 12.0, 5.0], position)
    response = client.call(Loads, SERVICE, Loads.Request(pose=pose))
    expected = expected_loads(workspace_node.params_path, rotation, position)
    assert_answer(response, expected)
    assert response.mass_kg == 40.0 and response.force_unit == "N"
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
        (double_array("limits.actuator_force_max", [700.0]), "limits.actuator_force_max: a loads"),
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
        assert len(answers) == 10, read.__name__
        assert list(answers[0].actuator_force) == list(response.actuator_force)
        changes = [m for topic, _, m in messages if topic == f"{NODE}/parameter_changes"]
        assert any(m.accepted and list(m.names) == ["load.mass"] for m in changes)
        assert any(not m.accepted and "load.mass" in m.reason for m in changes)
    foxglove = read_with_foxglove(log, workspace_node.record_dir)[f"{SERVICE}/response"]
    assert foxglove["count"] == 10
    assert foxglove["messages"][0]["actuator_force"] == list(response.actuator_force)
    # replay lists every call: the pose asked, the payload, the answer
    code, out, _ = run_main("replay", str(log), "--json")
    assert code == 0
    calls = json.loads(out)["loads"]
    assert len(calls) == 10
    assert calls[0]["position"] == position and calls[0]["mass_kg"] == 40.0
    assert calls[1]["frame_id"] == "part"
    assert calls[0]["actuator_force_worst"] == list(response.actuator_force_worst)
    assert not calls[-3]["success"] and "elsewhere" in calls[-3]["message"]
    assert calls[-1]["singular"] and calls[-1]["actuator_force_worst"] == [None] * 6
    code, text, _ = run_main("replay", str(log))
    assert code == 0
    assert f"at (0.02, -0.01, -1.42) m: {response.message}" in text
