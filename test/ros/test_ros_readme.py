"""The README's interface table and the documentation's ROS facts are the node's,
checked against a real node built in this process with its extensions (as
``workspace_node`` runs it), over real rclpy:

* the parameters the documentation lists as the node's own (``docs/ros.md`` generates them from
  :func:`~hexapod_workspace.ros.parameters.parameter_specs`) are exactly the parameters the node
  declares besides the model's (those are the parameters file's), each with the node's default;
* the README's interface table lists exactly the topics the node publishes and subscribes to
  (rclpy's own graph, ``/rosout``, ``/parameter_events`` and action internals aside), with
  their types, and exactly the services and actions it offers, with their types;
* the node-session ``replay`` example (``docs/log_format.md``) lists exactly the channels of a
  real node log.
"""

from __future__ import annotations

import contextlib
import re
import time
from pathlib import Path

import pytest
from ros_support import require_ros

require_ros()

from rclpy.parameter import Parameter  # noqa: E402

from hexapod_workspace import logs  # noqa: E402
from hexapod_workspace.core.evaluation.loading import example_manipulator  # noqa: E402
from hexapod_workspace.ros.node import EXTENSIONS, NODE_NAME, WorkspaceNode  # noqa: E402
from hexapod_workspace.ros.parameters import MODEL_DESCRIPTIONS, parameter_specs  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")
ROS = README[README.index("\n## ROS 2 node\n") :]
LOG_PAGE = (ROOT / "docs" / "log_format.md").read_text(encoding="utf-8")
ROS_PAGE = (ROOT / "docs" / "ros.md").read_text(encoding="utf-8")
PREFIX = f"/{NODE_NAME}/"
#: The topic the test gives ``motion.current_pose_topic`` (the table names the parameter).
CURRENT_POSE = "/cell/current_pose"
#: rclpy's own services of every node.
_RCLPY_SERVICES = (
    "describe_parameters",
    "get_parameter_types",
    "get_parameters",
    "get_type_description",
    "list_parameters",
    "set_parameters",
    "set_parameters_atomically",
)


def table() -> list[list[str]]:
    """The cells of the interface table of the README's ROS section."""
    rows = []
    for line in ROS.splitlines()[1:]:
        if line.startswith("|"):
            rows.append([cell.strip() for cell in line.strip("|").split("|")])
        elif rows:
            break
    return rows[2:]  # the header and the rule


@pytest.fixture(scope="module")
def node(ros_context, tmp_path_factory):
    """The node as workspace_node builds it: default parameters (the log goes to a temporary
    folder), every extension, a current-pose topic so that its subscription exists."""
    directory = tmp_path_factory.mktemp("readme_node")
    node = WorkspaceNode(
        context=ros_context,
        parameter_overrides=[
            Parameter("recording.directory", value=str(directory)),
            Parameter("motion.current_pose_topic", value=CURRENT_POSE),
        ],
        extensions=EXTENSIONS,
    )
    node.log_directory = directory
    try:
        yield node
    finally:
        node.destroy_node()


def test_the_documented_node_parameters_are_what_the_node_declares(node):
    """``docs/ros.md`` lists the specs outside MODEL_DESCRIPTIONS (``:group: node``), each with
    its default, and names the parameters extensions declare; the configuration reference lists
    the model's."""
    specs = {
        name: spec for name, spec in parameter_specs().items() if name not in MODEL_DESCRIPTIONS
    }
    declared = node.get_parameters_by_prefix("")
    model = set(example_manipulator().to_parameters())
    rclpy_own = {"use_sim_time", "start_type_description_service"}
    own = set(declared) - model - rclpy_own
    assert set(specs) <= own
    # Parameters an extension declares (motion.current_pose_topic) are not in the generated
    # list: the page names each of them in its text.
    for name in own - set(specs):
        assert f"`{name}`" in ROS_PAGE, name
    overridden = {"recording.directory", "motion.current_pose_topic"}  # set by this test
    for name, spec in specs.items():
        if name not in overridden:
            assert declared[name].value == spec.default, name


#: The lifecycle interfaces every managed node has (lifecycle_msgs; the README names them in
#: its text, the table lists the node's own).
_LIFECYCLE_SERVICES = (
    "change_state",
    "get_available_states",
    "get_available_transitions",
    "get_state",
    "get_transition_graph",
)
_LIFECYCLE_TOPICS = (f"{PREFIX}transition_event",)


def _graph(node) -> tuple[dict, dict]:
    """(topics, services) of the node by name, with their types, once its topics are listed.
    The boundary clouds come from the worker's node (``<node>_clouds``): they count as the
    node's."""
    deadline = time.monotonic() + 30.0
    while True:
        topics = {}
        for owner in (NODE_NAME, f"{NODE_NAME}_clouds"):
            for lister in (
                node.get_publisher_names_and_types_by_node,
                node.get_subscriber_names_and_types_by_node,
            ):
                with contextlib.suppress(Exception):  # the clouds node not discovered yet
                    topics.update(dict(lister(owner, "/")))
        wanted = {f"{PREFIX}reachability", f"{PREFIX}orientation_workspace"}
        if wanted <= set(topics) or time.monotonic() > deadline:
            break
        time.sleep(0.1)
    services = dict(node.get_service_names_and_types_by_node(NODE_NAME, "/"))
    return topics, services


def _rows(kind: str) -> dict[str, str]:
    """Absolute name -> type of the README table's rows of ``kind`` (topic, service, action)."""
    rows = {}
    for name, where, type_name in table():
        name = name.strip("`")
        if name.startswith("~/"):
            name = PREFIX + name[2:]
        elif "motion.current_pose_topic" in name:
            name = CURRENT_POSE
        if where.split(",")[0] == kind:
            rows[name] = type_name.strip("`")
    return rows


def test_the_interface_table_lists_every_topic_of_the_node(node):
    topics, _ = _graph(node)
    offered = {
        name: tuple(types)
        for name, types in topics.items()
        if "/_action/" not in name
        and name not in ("/rosout", "/parameter_events", *_LIFECYCLE_TOPICS)
    }
    shown = {name: (type_name,) for name, type_name in _rows("topic").items()}
    assert shown == offered


def test_the_interface_table_lists_every_service_and_action_with_its_type(node):
    _, services = _graph(node)
    named = {}
    for name, (kind,) in services.items():
        short = name.removeprefix(PREFIX)
        if short.endswith("/_action/send_goal"):  # an action: pkg/action/X_SendGoal
            named[("action", PREFIX + short.split("/_action/")[0])] = kind.removesuffix("_SendGoal")
        elif "/_action/" not in short and short not in (*_RCLPY_SERVICES, *_LIFECYCLE_SERVICES):
            named[("service", name)] = kind
    assert {"check_poses", "compute_workspace", "check_path", "compute_atlas"} <= {
        name.removeprefix(PREFIX) for _, name in named
    }
    shown = {
        (kind, name): type_name
        for kind in ("service", "action")
        for name, type_name in _rows(kind).items()
    }
    assert shown == named


def test_the_replay_example_lists_the_channels_of_a_real_node_log(node):
    example = ROS_REPLAY = LOG_PAGE[LOG_PAGE.index("A node session (") :]
    block = ROS_REPLAY[ROS_REPLAY.index("```\n") + 4 :]
    block = block[: block.index("```")]
    assert "$ hexapod-workspace replay" in example
    shown = set(re.findall(r"^  (/\S+)\s+(\S+/msg/\S+)\s+\d+$", block, re.MULTILINE))
    node.recorder.shutdown()  # finishes the log (destroy_node shuts it down again: a no-op)
    (path,) = sorted(Path(node.log_directory).glob("*.mcap"))
    contents = logs.read_log(path)
    recorded = {(topic, info.msgtype) for topic, info in contents.topics.items()}
    recorded.discard((CURRENT_POSE, "geometry_msgs/msg/PoseStamped"))  # set only in this test
    # published only with motion.current_pose_topic set (as in this test)
    recorded.discard((f"{PREFIX}axis_limits", "hexapod_workspace_msgs/msg/AxisLimits"))
    assert shown == recorded
