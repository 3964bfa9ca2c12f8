"""The node's parameter rules and request checks, in this process (rclpy, no other process).

As rclpy's own tests do (test_node.py), the node is built with ``parameter_overrides`` and its
methods are called directly: every refusal must name the parameter (or the request field) and
the value, and a refused update must leave the node's model as it was. The same rules seen
through the parameter services over DDS are in test_ros_node.py.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator

import numpy as np
import pytest
from ros_support import require_ros

require_ros()

from hexapod_workspace_msgs.msg import CommandedPose, TiltTorsion, WorkspaceRequest  # noqa: E402
from hexapod_workspace_msgs.srv import CheckPoses  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402

from hexapod_workspace import check  # noqa: E402
from hexapod_workspace._resources import example_config_path  # noqa: E402
from hexapod_workspace.core.evaluation.loading import (  # noqa: E402
    example_manipulator,
    load_manipulator,
)
from hexapod_workspace.errors import ConfigError  # noqa: E402
from hexapod_workspace.ros.node import WorkspaceNode  # noqa: E402
from hexapod_workspace.ros.parameters import command_line_override_names  # noqa: E402


def make_node(context, **overrides) -> WorkspaceNode:
    parameters = [Parameter("recording.enabled", value=False)]
    parameters += [Parameter(name, value=value) for name, value in overrides.items()]
    return WorkspaceNode(context=context, parameter_overrides=parameters)


@pytest.fixture(scope="module")
def node(ros_context):
    node = make_node(ros_context, **{"resolution.n_rays": 36})
    try:
        yield node
    finally:
        node.destroy_node()


@pytest.mark.parametrize(
    ("name", "value", "named"),
    [
        ("resolution.n_rays", "many", ["resolution.n_rays", "'many'", "integer"]),
        ("limits.leg_diameter", 1, ["limits.leg_diameter", "1", "double"]),
        ("resolution.n_rays", 2, ["resolution.n_rays", "2"]),
        ("resolution.tolerance", 1.0, ["resolution.tolerance", "1.0"]),
        ("limits.leg_diamter", 0.05, ["limits.leg_diamter", "0.05", "no such parameter"]),
        ("frame_id", "tool", ["frame_id", "'tool'", "read-only"]),
        ("check.max_poses", 5, ["check.max_poses", "5", "read-only"]),
        ("limits.leg_length_min", [2.0], ["limits.leg_length_min", "2"]),
        ("resolution.projected_method", "fastest", ["resolution.projected_method", "fastest"]),
        ("geometry.base_joints", [0.0, 1.0], ["geometry.base_joints"]),
    ],
    ids=[
        "str-for-int",
        "int-for-float",
        "range-int",
        "range-float",
        "unknown",
        "read-only",
        "read-only-int",
        "model",
        "method",
        "shape",
    ],
)
def test_a_refused_update_names_parameter_and_value_and_keeps_the_model(node, name, value, named):
    before = node.state
    (result,) = node.set_parameters([Parameter(name, value=value)])
    assert not result.successful
    for text in named:
        assert text in result.reason, result.reason
    assert node.state is before
    # the atomic form refuses the whole set for the one bad value
    atomic = node.set_parameters_atomically(
        [Parameter("resolution.n_phi", value=90), Parameter(name, value=value)]
    )
    assert not atomic.successful and name in atomic.reason
    assert node.get_parameter("resolution.n_phi").value == before.settings.n_phi


def test_an_accepted_update_changes_the_state(node):
    (result,) = node.set_parameters([Parameter("limits.leg_length_max", value=[1.4])])
    assert result.successful, result.reason
    assert np.allclose(node.state.manipulator.leg_length_max, 1.4)
    (result,) = node.set_parameters([Parameter("limits.leg_length_max", value=[1.45])])
    assert result.successful, result.reason


def test_rclpy_parameters_stay_settable(node):
    (result,) = node.set_parameters([Parameter("use_sim_time", value=False)])
    assert result.successful, result.reason


def example_model(**changes) -> dict:
    """The packaged example's whole model as overrides (empty axes left out), changed."""
    model = {k: v for k, v in example_manipulator().to_parameters().items() if v != []}
    model.pop("frame_id")
    return {**model, **changes}


@pytest.mark.parametrize(
    ("overrides", "named"),
    [
        (example_model(**{"limits.leg_length_min": [2.0]}), "limits.leg_length_min"),
        (example_model(**{"limits.leg_diameter": 0}), "limits.leg_diameter"),
        ({"resolution.projected_method": "fastest"}, "resolution.projected_method"),
        ({"check.max_command_age": -1.0}, "check.max_command_age"),
    ],
    ids=["model", "int-type", "method", "negative-age"],
)
def test_invalid_overrides_refuse_to_start(ros_context, overrides, named):
    with pytest.raises(ConfigError) as raised:
        make_node(ros_context, **overrides)
    assert named in str(raised.value)


# ------------------------------------------- the model is the user's whole model or the example's
@pytest.mark.parametrize(
    ("overrides", "named"),
    [
        # the misspelt key used to be dropped with a warning, the example's
        # 1.45 m stood in and z = -1.45 m was answered reachable
        (
            {**example_model(), "limits.leg_lenght_max": [1.30]},
            "limits.leg_lenght_max: unknown parameter",
        ),
        (
            {**example_model(), "limit.leg_length_max": [1.30]},
            "limit: unknown section",
        ),
        ({"resolution.n_rayz": 36}, "resolution.n_rayz: unknown parameter"),
    ],
    ids=["misspelt-key", "misspelt-section", "misspelt-setting"],
)
def test_an_unknown_parameter_stops_the_node_with_its_name(ros_context, overrides, named):
    with pytest.raises(ConfigError) as raised:
        make_node(ros_context, **overrides)
    assert named in str(raised.value)


def test_a_partial_model_is_refused_not_completed_from_the_example(ros_context):
    # only leg_length_max: before, the example's joints and other limits filled in the rest
    with pytest.raises(ConfigError) as raised:
        make_node(ros_context, **{"limits.leg_length_max": [1.30]})
    text = str(raised.value)
    assert "geometry.base_joints: required parameter is missing" in text
    assert "limits.leg_length_max" in text and "whole model" in text
    with pytest.raises(ConfigError, match="missing .*geometry.home_position.* given pose.position"):
        make_node(ros_context, **{"pose.position": [0.0, 0.0, -1.2]})


def test_optional_model_parameters_take_the_model_defaults_not_the_example(ros_context):
    overrides = example_model(**{"limits.leg_length_max": [1.30]})
    del overrides["limits.leg_diameter"], overrides["pose.position"]
    node = make_node(ros_context, **overrides)
    try:
        model = node.state.manipulator
        assert model.leg_diameter == 0.0  # the example's is 0.05 m
        np.testing.assert_array_equal(model.position, model.home_position)
        assert node.get_parameter("limits.leg_diameter").value == 0.0
        # the verdict a user reported wrong: z = -1.45 m is out of reach of 1.30 m legs
        response = node._on_check_poses(
            check_request([(0.0, 0.0, 0.0)], (0.0, 0.0, -1.45)), CheckPoses.Response()
        )
        assert response.success and not response.results[0].reachable
    finally:
        node.destroy_node()


def test_no_model_parameter_uses_the_example_and_says_so(ros_context, capfd):
    node = make_node(ros_context)
    try:
        assert node.state.manipulator == example_manipulator()
    finally:
        node.destroy_node()
    logged = capfd.readouterr().err
    assert "no model parameter" in logged and str(example_config_path()) in logged, logged


# ------------------------------------------- degenerate machines: refused at start and at run time
DEGENERATE = [
    (
        {"geometry.base_joints": [0.0] * 18},
        "geometry.base_joints: expected at most three legs per joint centre, joints 1, 2, 3, 4, "
        "5 and 6 coincide",
    ),
    (
        {"geometry.platform_joints": [0.1, 0.0, 0.1] * 6},
        "geometry.platform_joints: expected at most three legs per joint centre",
    ),
    (
        # home + b_1 = a_1: leg 1 has zero length at the home pose
        {"geometry.home_position": [0.337242, 0.108592, -0.1]},
        "geometry.home_position: expected non-zero legs at the home pose, leg 1",
    ),
]


def singular_layout() -> dict:
    """Vertical legs (each platform joint under its base joint): six parallel lines, the
    Plücker matrix has rank 3 at home. The lengths fit the example's limits there."""
    base = np.reshape(example_manipulator().to_parameters()["geometry.base_joints"], (6, 3))
    platform = base.copy()
    platform[:, 2] = 0.1
    return {"geometry.platform_joints": platform.ravel().tolist()}


@pytest.mark.parametrize(
    ("changes", "reason"),
    [*DEGENERATE, (singular_layout(), "platform is singular at the home pose")],
    ids=["base-joints-at-one-point", "platform-joints-at-one-point", "zero-legs", "singular"],
)
def test_a_degenerate_machine_is_refused_at_run_time_and_at_start(
    node, ros_context, changes, reason
):
    before = node.state
    result = node.set_parameters_atomically(
        [Parameter(name, value=value) for name, value in changes.items()]
    )
    assert not result.successful
    assert reason in result.reason, result.reason
    assert node.state is before
    with pytest.raises(ConfigError, match=reason):
        make_node(ros_context, **example_model(**changes))


def test_override_names_from_the_command_line(tmp_path):
    params = tmp_path / "p.yaml"
    params.write_text(
        "hexapod_workspace:\n  ros__parameters:\n    limits:\n      leg_diamter: 0.05\n"
        "other_node:\n  ros__parameters:\n    x: 1\n"
        "/**:\n  ros__parameters:\n    frame_id: base\n"
    )
    argv = ["node", "--ros-args", "-p", "resolution.n_rays:=12", "--params-file", str(params)]
    names = command_line_override_names(argv, "hexapod_workspace")
    assert sorted(names) == ["frame_id", "limits.leg_diamter", "resolution.n_rays"]


# ---------------------------------------------------------------------------- request checks


def check_request(angles, position=(0.0, 0.0, -1.3)) -> CheckPoses.Request:
    request = CheckPoses.Request()
    request.position.x, request.position.y, request.position.z = position
    request.orientations = [TiltTorsion(phi=p, theta=t, psi=s) for p, t, s in angles]
    return request


@pytest.mark.parametrize(
    ("angles", "position", "reason"),
    [
        ([], (0.0, 0.0, -1.3), "at least one"),
        ([(0.0, math.nan, 0.0)], (0.0, 0.0, -1.3), "finite"),
        ([(0.0, 0.1, 0.0)], (0.0, math.inf, -1.3), "position"),
    ],
    ids=["empty", "nan-angle", "inf-position"],
)
def test_check_poses_refusals(node, angles, position, reason):
    response = node._on_check_poses(check_request(angles, position), CheckPoses.Response())
    assert not response.success and reason in response.message
    assert len(response.results) == 0


def test_check_poses_matches_the_core(node):
    rng = np.random.default_rng(4)
    angles = np.column_stack(
        (rng.uniform(-np.pi, np.pi, 50), rng.uniform(0, 0.8, 50), rng.uniform(-0.4, 0.4, 50))
    )
    response = node._on_check_poses(check_request(angles.tolist()), CheckPoses.Response())
    expected = check(node.state.manipulator, angles, (0.0, 0.0, -1.3))
    assert [r.reachable for r in response.results] == expected.reachable.tolist()


def workspace_request(**fields) -> WorkspaceRequest:
    request = WorkspaceRequest(kind=fields.pop("kind", WorkspaceRequest.PROJECTED_TORSION_ZERO))
    request.position.z = -1.3
    for name, value in fields.items():
        setattr(request, name, value)
    return request


@pytest.mark.parametrize(
    ("fields", "reason"),
    [
        ({"kind": 7}, "kind: expected 0 (orientation), 1 (torsion_zero) or 2 (exact), got 7"),
        ({"n_rays": 2}, "n_rays: expected 3..7200, got 2"),
        ({"tolerance": -1.0}, "tolerance: expected a finite value >= 0"),
        ({"psi_step": math.inf}, "psi_step: expected a finite value >= 0"),
    ],
)
def test_workspace_request_refusals_name_the_field_and_value(node, fields, reason):
    refused = node.workspaces.job(workspace_request(**fields))
    assert reason in refused.reason


def test_a_valid_request_gets_the_node_resolution(node):
    job = node.workspaces.job(workspace_request(kind=WorkspaceRequest.ORIENTATION))
    assert job.n_rays == 36
    assert job.tolerance == node.state.settings.tolerance


@contextlib.contextmanager
def collected(stream) -> Iterator[list]:
    """The results ``stream`` publishes while in the block, collected in a list instead."""
    published: list = []
    publisher = stream._publisher
    stream._publisher = type("Collect", (), {"publish": published.append, "topic_name": "/x"})()
    try:
        yield published
    finally:
        stream._publisher = publisher


def test_commands_in_a_batch_are_answered_one_each_in_order(node):
    """One batch with valid, invalid and stale commands: one result each, in order."""
    stream = node._commands
    with collected(stream) as published:
        commands = []
        for k, theta in enumerate([0.1, math.nan, 0.2, 0.3]):
            command = CommandedPose(request_id=f"b{k}")
            command.position.z = -1.3 if k != 3 else -1.25
            command.orientation.theta = theta
            commands.append(command)
        stale = CommandedPose(request_id="stale")
        stale.position.z = -1.3
        stale.header.stamp.sec = 1  # 1970: far older than check.max_command_age
        stream.answer([*commands, stale])
    assert [r.request_id for r in published] == ["b0", "b1", "b2", "b3", "stale"]
    assert [r.success for r in published] == [True, False, True, True, False]
    assert "theta" in published[1].message or "finite" in published[1].message
    assert published[4].message.startswith("overloaded")
    model = load_manipulator(example_config_path())
    expected = check(model, [[0.0, 0.2, 0.0]], (0.0, 0.0, -1.3))
    assert published[2].check.reachable == bool(expected.reachable[0])


@pytest.mark.parametrize("size", [6, 40])  # grouped in a dict (small) and by numpy.unique
def test_each_command_of_a_batch_is_checked_at_its_own_position(node, rng, size):
    """Commands at three positions, interleaved in one batch: each result has the margins of
    the core's check of its own pose at its own position, in the order sent."""
    stream = node._commands
    heights = np.array([-1.3, -1.25, -1.35])[rng.permutation(np.arange(size) % 3)]
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, size),
            rng.uniform(0.0, 0.6, size),
            rng.uniform(-0.5, 0.5, size),
        ]
    )
    with collected(stream) as published:
        commands = []
        for k in range(size):
            command = CommandedPose(request_id=f"p{k}")
            command.position.z = float(heights[k])
            command.orientation.phi, command.orientation.theta, command.orientation.psi = angles[k]
            commands.append(command)
        stream.answer(commands)
    assert [r.request_id for r in published] == [f"p{k}" for k in range(size)]
    model = load_manipulator(example_config_path())
    for k, result in enumerate(published):
        expected = check(model, angles[k : k + 1], (0.0, 0.0, heights[k]))
        assert result.position.z == heights[k]
        assert result.check.reachable == bool(expected.reachable[0])
        margins = dict(zip(result.check.constraint_names, result.check.margins, strict=True))
        for name, values in expected.margins.items():
            assert margins[name] == pytest.approx(float(values[0]), abs=1e-12, nan_ok=True)


def test_an_extension_attaches_with_one_call(ros_context):
    """What ros/paths.py or ros/atlas_action.py do: ``attach(node)`` wires a recorded service
    with the node's groups and reads the node's state."""
    from std_srvs.srv import Trigger

    seen = []

    def attach(node) -> None:
        def ping(request, response):
            return Trigger.Response(success=True, message=node.state.manipulator.frame_id)

        seen.append(node.recorded_service(Trigger, "~/ping", ping, node.check_group))

    node = WorkspaceNode(
        context=ros_context,
        parameter_overrides=[Parameter("recording.enabled", value=False)],
        extensions=[attach],
    )
    try:
        (service,) = seen
        assert node.resolve_service_name(service.srv_name) == "/hexapod_workspace/ping"
        assert node.jobs is node.workspaces.jobs and node.recorder is not None
    finally:
        node.destroy_node()


def test_a_blocking_extension_callback_runs_in_a_thread_while_the_executor_serves(ros_context):
    """in_thread: a blocking callback (the atlas action's execute) does not stop the
    single-threaded executor; its coroutine resumes with the callback's value (or error)."""
    import threading

    from rclpy.executors import SingleThreadedExecutor

    from hexapod_workspace.ros.jobs import in_thread

    node = make_node(ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    release = threading.Event()
    ticks: list[int] = []
    node.create_timer(0.01, lambda: ticks.append(1))

    def blocking(value):
        release.wait(10)
        if value == "bad":
            raise ValueError("bad value")
        return value * 2

    try:
        good = executor.create_task(in_thread(node, blocking), 21)
        bad = executor.create_task(in_thread(node, blocking), "bad")
        for _ in range(30):  # the timer keeps firing while both callbacks block
            executor.spin_once(timeout_sec=0.05)
        assert len(ticks) >= 5 and not good.done()
        release.set()
        with pytest.raises(ValueError, match="bad value"):  # rclpy re-raises a task's error
            executor.spin_until_future_complete(bad, timeout_sec=10)
        executor.spin_until_future_complete(good, timeout_sec=10)
        assert good.result() == 42
    finally:
        executor.shutdown()
        node.destroy_node()


def test_the_answering_services_keep_1000_answers_for_a_lagging_client(node):
    """~/check_path is created outside node.py; its answers must be kept as long as the other
    services' (rmw's default history keeps 10: a client whose answer was lost in transport
    would wait forever once ten other calls were answered)."""
    from hexapod_workspace.ros.qos import SERVICE_QOS_PROFILE

    profiles = {service.srv_name: service.qos_profile for service in node.services}
    for name in ("check_path", "check_poses", "check_poses_flat"):
        (profile,) = [p for n, p in profiles.items() if n.endswith(f"/{name}")]
        assert profile.depth == SERVICE_QOS_PROFILE.depth == 1000, name
        assert profile.history == SERVICE_QOS_PROFILE.history, name
