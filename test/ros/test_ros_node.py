"""workspace_node over real Fast DDS: services, topics and parameters from another process.

The node runs from the colcon install space with a parameters file (see conftest.py); every
verdict is compared with the ROS-free core computed here from the same file.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from ros_support import require_ros

require_ros()

from hexapod_workspace_msgs.msg import CommandedPose, ReachabilityResult, TiltTorsion  # noqa: E402
from hexapod_workspace_msgs.srv import CheckPoses  # noqa: E402
from rcl_interfaces.msg import Parameter as ParameterMsg  # noqa: E402
from rcl_interfaces.msg import ParameterType, ParameterValue  # noqa: E402
from rcl_interfaces.srv import (  # noqa: E402
    DescribeParameters,
    ListParameters,
    SetParameters,
    SetParametersAtomically,
)

from hexapod_workspace import (  # noqa: E402
    check,
    logs,
)
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping  # noqa: E402
from hexapod_workspace.ros.conversions import margins_by_name  # noqa: E402

#: The constraints of a 6-UPS model: the names the node gives for the example (the rows of the
#: constraint table that apply to it), as before the leg architectures.
CONSTRAINT_NAMES = ("leg_length", "base_joint", "platform_joint", "leg_interference", "singularity")

NODE = "/hexapod_workspace"
#: Small resolutions keep the workspace computations of the tests short.
NODE_PARAMS = {
    "resolution.n_phi": 72,
    "resolution.n_rays": 24,
    "resolution.psi_step": 0.05,
    "resolution.tolerance": 1e-4,
    "check.max_poses": 2000,
}


def sample_angles(count: int, seed: int = 4) -> np.ndarray:
    """Seeded (φ, θ, ψ) poses, about half of them reachable for the example GPM at home."""
    rng = np.random.default_rng(seed)
    return np.column_stack(
        (
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(0.0, math.radians(60.0), count),
            rng.uniform(-math.radians(45.0), math.radians(45.0), count),
        )
    )


def check_request(angles: np.ndarray, position=(0.0, 0.0, -1.3)) -> CheckPoses.Request:
    request = CheckPoses.Request()
    request.position.x, request.position.y, request.position.z = (float(v) for v in position)
    request.orientations = [
        TiltTorsion(phi=float(p), theta=float(t), psi=float(s)) for p, t, s in angles
    ]
    return request


def assert_matches_core(response: CheckPoses.Response, expected) -> None:
    """Every field of every PoseCheck equals the core's verdict (float64 travels exactly)."""
    assert response.success, response.message
    assert len(response.results) == len(expected)
    got_reachable = np.array([r.reachable for r in response.results])
    np.testing.assert_array_equal(got_reachable, expected.reachable)
    assert [list(r.violated) for r in response.results] == expected.violated
    for result in response.results:
        assert list(result.constraint_names) == list(CONSTRAINT_NAMES)
    for name in CONSTRAINT_NAMES:
        got = np.array([margins_by_name(r)[name] for r in response.results])
        np.testing.assert_array_equal(got, expected.margins[name])
    got_legs = np.array([r.limiting_leg for r in response.results])
    np.testing.assert_array_equal(got_legs, expected.limiting_leg)
    reachable = int(np.count_nonzero(expected.reachable))
    assert response.message == f"{reachable}/{len(expected)} reachable"


# ---------------------------------------------------------------------------- check_poses


def test_check_poses_matches_core(client, model):
    angles = sample_angles(300)
    expected = check(model, angles, model.position)
    assert 0 < np.count_nonzero(expected.reachable) < len(expected), "need both verdicts"
    response = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles))
    assert_matches_core(response, expected)


def test_check_poses_huge_angles_get_the_verdict_of_their_principal_values(client, model):
    """At the node: phi = 1e300 rad is the orientation of its principal value."""
    huge = np.array([[1e300, 0.17, 2.6], [0.3, 0.2, -1e20], [1e20, 0.6, 1e20]])
    principal = np.arctan2(np.sin(huge), np.cos(huge))
    expected = check(model, principal, model.position)
    response = client.call(CheckPoses, f"{NODE}/check_poses", check_request(huge))
    assert response.success, response.message
    for name in CONSTRAINT_NAMES:
        got = np.array([margins_by_name(r)[name] for r in response.results])
        np.testing.assert_allclose(got, expected.margins[name], atol=1e-12)
    assert [r.reachable for r in response.results] == expected.reachable.tolist()


def test_check_poses_huge_position_is_refused_not_answered(client):
    """At the node: no NaN margins with success=true; a refusal with the reason."""
    request = check_request(np.zeros((1, 3)), (1e300, 0.0, 0.0))
    response = client.call(CheckPoses, f"{NODE}/check_poses", request)
    assert not response.success
    assert "at most 1e+06 m" in response.message
    assert list(response.results) == []


def test_check_poses_at_another_position(client, model):
    angles = sample_angles(50, seed=9)
    position = (0.2, 0.2, -0.95)
    expected = check(model, angles, position)
    response = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles, position))
    assert_matches_core(response, expected)


def test_check_poses_single_pose_at_the_singular_tilt(client, model):
    # theta = 0 merges phi and psi: the verdict must not depend on phi there
    angles = np.array([[0.0, 0.0, 0.1], [2.0, 0.0, 0.1]])
    response = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles))
    assert_matches_core(response, check(model, angles, model.position))
    assert response.results[0].reachable == response.results[1].reachable


@pytest.mark.parametrize(
    ("angles", "position", "reason"),
    [
        (np.zeros((0, 3)), (0.0, 0.0, -1.3), "at least one"),
        (np.array([[0.0, math.nan, 0.0]]), (0.0, 0.0, -1.3), "finite"),
        (np.array([[math.inf, 0.1, 0.0]]), (0.0, 0.0, -1.3), "finite"),
        (np.array([[0.0, 0.1, 0.0]]), (0.0, math.nan, -1.3), "finite"),
        (np.array([[0.0, 0.1, 0.0]]), (0.0, 0.0, -math.inf), "finite"),
        (np.zeros((2001, 3)), (0.0, 0.0, -1.3), "at most 2000"),
    ],
    ids=["empty", "nan-angle", "inf-angle", "nan-position", "inf-position", "too-many"],
)
def test_check_poses_refuses_bad_requests(client, angles, position, reason):
    response = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles, position))
    assert not response.success
    assert reason in response.message
    assert len(response.results) == 0


def test_node_survives_bad_requests(client, model):
    # after every refusal above (and here), ordinary requests are still served
    bad = check_request(np.array([[math.nan, math.nan, math.nan]]))
    assert not client.call(CheckPoses, f"{NODE}/check_poses", bad).success
    angles = sample_angles(5)
    response = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles))
    assert_matches_core(response, check(model, angles, model.position))


# ---------------------------------------------------------------------------- commanded_pose


def commanded(request_id: str, angles, position=(0.0, 0.0, -1.3)) -> CommandedPose:
    message = CommandedPose(request_id=request_id)
    message.position.x, message.position.y, message.position.z = (float(v) for v in position)
    phi, theta, psi = (float(v) for v in angles)
    message.orientation = TiltTorsion(phi=phi, theta=theta, psi=psi)
    return message


def test_commanded_pose_gets_a_reachability_result(client, model):
    received = client.collect(ReachabilityResult, f"{NODE}/reachability")
    publisher = client.publisher(CommandedPose, f"{NODE}/commanded_pose")
    angles = sample_angles(6, seed=21)
    expected = check(model, angles, model.position)
    for k, pose in enumerate(angles):
        publisher.publish(commanded(f"cmd-{k}", pose))
    bad = commanded("cmd-nan", (0.0, math.nan, 0.0))
    publisher.publish(bad)
    client.spin_until(lambda: len(received) >= 7, what="7 reachability results")
    by_id = {result.request_id: result for result in received}
    for k in range(6):
        result = by_id[f"cmd-{k}"]
        assert result.success
        assert result.header.frame_id == model.frame_id
        assert result.check.reachable == bool(expected.reachable[k])
        assert list(result.check.violated) == expected.violated[k]
        assert margins_by_name(result.check)["leg_length"] == expected.margins["leg_length"][k]
        assert result.check.limiting_leg == expected.limiting_leg[k]
        assert result.orientation.theta == angles[k, 1]
        assert result.message == (
            "reachable"
            if expected.reachable[k]
            else "unreachable: " + ", ".join(expected.violated[k])
        )
    failed = by_id["cmd-nan"]
    assert not failed.success
    assert "finite" in failed.message
    # The model's rows (as for a checked command), every margin NaN: nothing was checked.
    assert list(failed.check.constraint_names) == list(CONSTRAINT_NAMES)
    assert all(math.isnan(margin) for margin in failed.check.margins)


# ---------------------------------------------------------------------------- parameters


def double_array(name: str, values) -> ParameterMsg:
    return ParameterMsg(
        name=name,
        value=ParameterValue(
            type=ParameterType.PARAMETER_DOUBLE_ARRAY, double_array_value=[float(v) for v in values]
        ),
    )


def set_parameters(client, *parameters: ParameterMsg):
    request = SetParameters.Request(parameters=list(parameters))
    return client.call(SetParameters, f"{NODE}/set_parameters", request).results


def test_invalid_parameter_update_is_refused_and_verdicts_kept(client, model):
    angles = sample_angles(200, seed=5)
    before = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles))
    assert_matches_core(before, check(model, angles, model.position))

    # leg_length_min above the current leg_length_max: the whole set is invalid
    (result,) = set_parameters(client, double_array("limits.leg_length_min", [1.6]))
    assert not result.successful
    assert "limits.leg_length_min" in result.reason
    # wrong length of a joint array
    (result,) = set_parameters(client, double_array("geometry.base_joints", [0.0] * 17))
    assert not result.successful
    assert "geometry.base_joints" in result.reason
    # wrong type (descriptor) and read-only parameters are refused by rclpy itself
    text = ParameterMsg(
        name="limits.leg_diameter",
        value=ParameterValue(type=ParameterType.PARAMETER_STRING, string_value="thick"),
    )
    (result,) = set_parameters(client, text)
    assert not result.successful
    frame = ParameterMsg(
        name="frame_id",
        value=ParameterValue(type=ParameterType.PARAMETER_STRING, string_value="world"),
    )
    (result,) = set_parameters(client, frame)
    assert not result.successful
    # an atomic update with one bad member changes nothing
    atomic = SetParametersAtomically.Request(
        parameters=[
            double_array("limits.leg_length_max", [1.45]),
            double_array("limits.leg_length_min", [1.5]),
        ]
    )
    result = client.call(
        SetParametersAtomically, f"{NODE}/set_parameters_atomically", atomic
    ).result
    assert not result.successful
    assert "leg_length" in result.reason

    after = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles))
    assert_matches_core(after, check(model, angles, model.position))


def test_valid_parameter_update_changes_verdicts_and_back(client, model):
    angles = sample_angles(200, seed=6)
    shorter = manipulator_from_mapping(
        {**model.to_parameters(), "limits.leg_length_max": [1.40]}, warn=False
    )
    expected = check(shorter, angles, model.position)
    assert not np.array_equal(expected.reachable, check(model, angles, model.position).reachable)
    try:
        (result,) = set_parameters(client, double_array("limits.leg_length_max", [1.40]))
        assert result.successful, result.reason
        response = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles))
        assert_matches_core(response, expected)
    finally:
        original = model.to_parameters()["limits.leg_length_max"]
        (result,) = set_parameters(client, double_array("limits.leg_length_max", original))
        assert result.successful, result.reason
    response = client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles))
    assert_matches_core(response, check(model, angles, model.position))


def test_parameters_have_descriptors(client):
    names = ["limits.leg_diameter", "resolution.n_rays", "check.max_poses", "frame_id"]
    request = DescribeParameters.Request(names=names)
    descriptors = client.call(DescribeParameters, f"{NODE}/describe_parameters", request)
    by_name = {d.name: d for d in descriptors.descriptors}
    assert set(by_name) == set(names)
    assert all(d.description for d in by_name.values())
    assert by_name["limits.leg_diameter"].floating_point_range[0].from_value == 0.0
    assert by_name["resolution.n_rays"].integer_range[0].to_value == 7200
    assert by_name["check.max_poses"].read_only
    assert by_name["frame_id"].read_only


def test_a_parameters_file_check_knows_every_parameter_of_the_node(client):
    """The CLI refuses unknown names in a parameters file, so it must know every name
    the node declares (core.base.params.NODE_PARAMETERS + the model's + the machining cell's + ROS's
    own), and no more."""
    from hexapod_workspace.core.base.params import (
        CELL_PARAMETERS,
        NODE_PARAMETERS,
        ROS_PARAMETERS,
        unknown_parameter,
    )
    from hexapod_workspace.core.evaluation.loads import LOAD_PARAMETERS
    from hexapod_workspace.core.model.manipulator import PARAMETER_DEFAULTS

    listed = client.call(ListParameters, f"{NODE}/list_parameters", ListParameters.Request())
    names = set(listed.result.names)
    known = (
        *PARAMETER_DEFAULTS,
        *NODE_PARAMETERS,
        *CELL_PARAMETERS,
        *LOAD_PARAMETERS,
        *ROS_PARAMETERS,
    )
    assert unknown_parameter(names, known) is None
    assert set(NODE_PARAMETERS) <= names


# ---------------------------------------------------------------------------- recording


def boolean(name: str, value: bool) -> ParameterMsg:
    return ParameterMsg(
        name=name, value=ParameterValue(type=ParameterType.PARAMETER_BOOL, bool_value=value)
    )


def test_recording_switched_off_finishes_the_log_and_on_starts_a_new_one(client, workspace_node):
    angles = sample_angles(3, seed=8)
    assert client.call(CheckPoses, f"{NODE}/check_poses", check_request(angles)).success
    (first,) = sorted(workspace_node.record_dir.glob("*.mcap"))
    (result,) = set_parameters(client, boolean("recording.enabled", False))
    assert result.successful, result.reason
    contents = logs.read_log(first)
    assert contents.finished, contents.problems
    assert contents.topics[f"{NODE}/check_poses/request"].count > 0
    assert contents.topics[f"{NODE}/check_poses/response"].count > 0
    (result,) = set_parameters(client, boolean("recording.enabled", True))
    assert result.successful, result.reason
    log_files = sorted(workspace_node.record_dir.glob("*.mcap"))
    assert len(log_files) == 2 and first in log_files


# ---------------------------------------------------------------------------- diagnostics


def test_diagnostics_report_the_counts_at_1_hz(client, model):
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

    arrays = client.collect(DiagnosticArray, "/diagnostics")
    publisher = client.publisher(CommandedPose, f"{NODE}/commanded_pose")
    publisher.publish(commanded("diag-ok", (0.0, 0.1, 0.0)))
    publisher.publish(commanded("diag-bad", (0.0, math.nan, 0.0)))

    def values(array) -> dict[str, str]:
        return {kv.key: kv.value for kv in array.status[0].values}

    client.spin_until(
        lambda: any(int(values(a)["commands answered"]) >= 2 for a in arrays),
        what="diagnostics counting both commands",
    )
    latest = values(arrays[-1])
    status = arrays[-1].status[0]
    assert status.name == NODE and status.hardware_id == model.frame_id
    assert status.level in (DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR)
    assert int(latest["commands received"]) == int(latest["commands answered"]) >= 2
    assert int(latest["commands refused"]) >= 1
    assert latest["worker alive"] == "True"
    assert latest["recording"] == "on" and int(latest["recorded bytes"]) > 0
    for key in ("commands overloaded", "recorder queue depth", "last error"):
        assert key in latest
