"""The README's ROS tables are the node's (issue 16, item 14), checked against a real node built
in this process with its extensions (as ``workspace_node`` runs it), over real rclpy:

* the *Parameters* table lists exactly the parameters the node declares besides the model's
  (those are the parameters file's), each with the node's default;
* the *Topics* table lists exactly the topics the node publishes and subscribes to (rclpy's
  own graph, ``/rosout``, ``/parameter_events`` and action internals aside), with their types;
  every service and action the node offers is named with its type;
* the node-session ``replay`` example lists exactly the channels of a real node log.
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest
from ros_support import require_ros

require_ros()

from rclpy.parameter import Parameter  # noqa: E402

from hexapod_workspace import Manipulator, logs  # noqa: E402
from hexapod_workspace.ros.node import EXTENSIONS, NODE_NAME, WorkspaceNode  # noqa: E402
from hexapod_workspace.ros.parameters import parameter_specs  # noqa: E402

README = (Path(__file__).resolve().parents[2] / "README.md").read_text(encoding="utf-8")
ROS = README[README.index("\n## ROS 2 node\n") : README.index("<!-- ros:end -->")]
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


def table(title: str) -> list[list[str]]:
    """The cells of the first Markdown table after the heading ``title`` of the ROS section."""
    text = ROS[ROS.index(f"\n{title}\n") :]
    rows = []
    for line in text.splitlines()[1:]:
        if line.startswith("|"):
            rows.append([cell.strip() for cell in line.strip("|").split("|")])
        elif rows:
            break
    return rows[2:]  # the header and the rule


def shown_default(cell: str) -> object:
    """The default in a 'type, default (range), read-only' cell: the first literal in it."""
    for token in re.sub(r"\([^)]*\)", "", cell).split(","):
        token = token.strip()
        if token in ("true", "false"):
            return token == "true"
        if token == '""':
            return ""
        if token.startswith("`") and token.endswith("`"):
            return token.strip("`")
        for kind in (int, float):
            try:
                return kind(token)
            except ValueError:
                pass
    msg = f"no default in {cell!r}"
    raise AssertionError(msg)


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


def test_the_parameters_table_is_what_the_node_declares(node):
    rows = {row[0].strip("`"): row[1] for row in table("### Parameters")}
    declared = node.get_parameters_by_prefix("")
    model = set(Manipulator.example().to_parameters())
    rclpy_own = {"use_sim_time", "start_type_description_service"}
    assert set(rows) == set(declared) - model - rclpy_own
    overridden = {
        "recording.directory": parameter_specs()["recording.directory"].default,
        "motion.current_pose_topic": "",
    }
    for name, cell in rows.items():
        default = overridden.get(name, declared[name].value)
        shown = shown_default(cell)
        if isinstance(default, float):
            assert shown == pytest.approx(default, rel=1e-3), (name, cell, default)
        else:
            assert shown == default, (name, cell, default)


def _graph(node) -> tuple[dict, dict]:
    """(topics, services) of the node by name, with their types, once its topics are listed."""
    deadline = time.monotonic() + 10.0
    while True:
        topics = {}
        for lister in (
            node.get_publisher_names_and_types_by_node,
            node.get_subscriber_names_and_types_by_node,
        ):
            topics.update(dict(lister(NODE_NAME, "/")))
        if f"{PREFIX}reachability" in topics or time.monotonic() > deadline:
            break
        time.sleep(0.1)
    services = dict(node.get_service_names_and_types_by_node(NODE_NAME, "/"))
    return topics, services


def test_the_topics_table_is_every_topic_of_the_node(node):
    topics, _ = _graph(node)
    offered = {
        name: tuple(types)
        for name, types in topics.items()
        if "/_action/" not in name and name not in ("/rosout", "/parameter_events")
    }
    shown = {}
    for row in table("### Topics"):
        name = row[0].strip("`")
        if name.startswith("~/"):
            name = PREFIX + name[2:]
        elif "motion.current_pose_topic" in name:
            name = CURRENT_POSE
        shown[name] = (row[1].strip("`"),)
    assert shown == offered


def test_every_service_and_action_is_named_with_its_type(node):
    _, services = _graph(node)
    named = {}
    for name, (kind,) in services.items():
        short = name.removeprefix(PREFIX)
        if short.endswith("/_action/send_goal"):  # an action: pkg/action/X_SendGoal
            named[short.split("/_action/")[0]] = kind.removesuffix("_SendGoal")
        elif "/_action/" not in short and short not in _RCLPY_SERVICES:
            named[short] = kind
    assert {"check_poses", "compute_workspace", "check_path", "compute_atlas"} <= set(named)
    for short, kind in named.items():
        assert f"`~/{short}`" in README, short
        assert f"`{kind}" in README, (short, kind)


def test_the_replay_example_lists_the_channels_of_a_real_node_log(node):
    example = ROS_REPLAY = README[README.index("A node session (") :]
    block = ROS_REPLAY[ROS_REPLAY.index("```\n") + 4 :]
    block = block[: block.index("```")]
    assert "$ hexapod-workspace replay" in example
    shown = set(re.findall(r"^  (/\S+)\s+(\S+/msg/\S+)\s+\d+$", block, re.MULTILINE))
    node.recorder.shutdown()  # finishes the log (destroy_node shuts it down again: a no-op)
    (path,) = sorted(Path(node.log_directory).glob("*.mcap"))
    contents = logs.read_log(path)
    recorded = {(topic, info.msgtype) for topic, info in contents.topics.items()}
    recorded.discard((CURRENT_POSE, "geometry_msgs/msg/PoseStamped"))  # set only in this test
    assert shown == recorded
