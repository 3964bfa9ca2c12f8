"""The colcon install space as a ROS user gets it: executables, launch file, layouts, interfaces.

``ros2 launch`` itself is not installable from the package index here (no ``launch`` wheels), so
the launch file is checked statically; the RViz layout's topics are checked against the topics
the running node really offers.
"""

from __future__ import annotations

import ast
import os

import pytest
import yaml
from ros_support import INSTALL, NODE_EXECUTABLE, require_ros, running_node

from hexapod_workspace.logs import interfaces, messages

require_ros()

SHARE = INSTALL / "hexapod_workspace" / "share" / "hexapod_workspace"
NODE = "/hexapod_workspace"  # the RViz layout and the launch file name it literally


def test_executables_are_installed_where_ros2_run_looks():
    assert NODE_EXECUTABLE.is_file()
    assert os.access(NODE_EXECUTABLE, os.X_OK)
    cli = NODE_EXECUTABLE.parent / "hexapod-workspace"
    assert cli.is_file()


def test_package_is_registered_in_the_ament_index():
    index = INSTALL / "hexapod_workspace" / "share" / "ament_index" / "resource_index"
    assert (index / "packages" / "hexapod_workspace").is_file()
    msgs = INSTALL / "hexapod_workspace_msgs" / "share" / "ament_index" / "resource_index"
    assert (msgs / "packages" / "hexapod_workspace_msgs").is_file()
    interfaces = (msgs / "rosidl_interfaces" / "hexapod_workspace_msgs").read_text()
    for name in (
        "msg/TiltTorsion.msg",
        "srv/CheckPoses.srv",
        "srv/CheckPosesFlat.srv",
        "srv/ComputeWorkspace.srv",
        "action/ComputeWorkspace.action",
    ):
        assert name in interfaces.split()


def test_launch_file_names_installed_files():
    launch_file = SHARE / "launch" / "workspace.launch.py"
    tree = ast.parse(launch_file.read_text(encoding="utf-8"))
    functions = {node.name for node in ast.walk(tree) if isinstance(node, ast.FunctionDef)}
    assert "generate_launch_description" in functions
    strings = {
        node.value
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str)
    }
    assert {"hexapod_workspace", "workspace_node", "example_gpm.yaml", "workspace.rviz"} <= strings
    assert (SHARE / "config" / "example_gpm.yaml").is_file()
    assert (SHARE / "config" / "workspace.rviz").is_file()


@pytest.fixture(scope="module")
def node_graph(ros_client, tmp_path_factory):
    """Topic and service name -> types offered by a running node (seen from this process), and
    topic name -> the QoS (reliability, durability) of the node's own endpoints on it."""
    with running_node(tmp_path_factory.mktemp("install_node")) as node:
        wanted = messages.TOPICS["orientation_workspace"]

        def offered() -> dict:
            return {
                **dict(ros_client.node.get_topic_names_and_types()),
                **dict(ros_client.node.get_service_names_and_types()),
            }

        # Every unconditional row of the table, subscriptions included: discovery announces a
        # node's endpoints one by one, so waiting for a few of them raced the rest under load.
        expected = {
            f"{r.name}/_action/send_goal" if r.kind == "action" else r.name
            for r in interfaces.INTERFACES
            if not r.condition
        }
        ros_client.spin_until(
            lambda: {wanted, "/diagnostics", *expected} <= set(offered()),
            what="the node's interfaces",
            timeout=60.0,
        )
        topics = offered()
        rows = [
            r
            for r in interfaces.INTERFACES
            if r.kind in ("publisher", "subscription") and not r.condition
        ]

        def endpoints_of(row: interfaces.Interface) -> list[tuple[str, str]]:
            info = (
                ros_client.node.get_publishers_info_by_topic
                if row.kind == "publisher"
                else ros_client.node.get_subscriptions_info_by_topic
            )(row.name)
            return [
                (e.qos_profile.reliability.name.lower(), e.qos_profile.durability.name.lower())
                for e in info
                # the node's own endpoints, and the clouds its worker publishes from a node of
                # its own (``<node>_clouds``: large results stay off the command path)
                if e.node_name in (NODE.lstrip("/"), NODE.lstrip("/") + "_clouds")
            ]

        # endpoint details arrive with discovery, after the names: wait for every row's
        ros_client.spin_until(
            lambda: all(endpoints_of(row) for row in rows),
            what="the node's publishers and subscriptions",
            timeout=60.0,
        )
        endpoints = {row.name: endpoints_of(row) for row in rows}
        node.stop()
    return topics, endpoints


@pytest.fixture(scope="module")
def node_topics(node_graph):
    return node_graph[0]


def test_the_interface_table_is_what_the_node_offers(node_graph):
    """Every row of logs.interfaces.INTERFACES, with its type and QoS (history depth is not
    discovered across processes, so only reliability and durability are compared)."""
    topics, endpoints = node_graph
    for row in interfaces.INTERFACES:
        if row.condition:  # e.g. ~/axis_limits: only with motion.current_pose_topic set
            assert row.name not in topics, row.key
            continue
        if row.kind == "action":
            goal = f"{row.name}/_action/send_goal"
            action_type = row.type.replace("/srv/", "/action/")
            assert topics.get(goal) == [f"{action_type}_SendGoal"], row.key
        else:
            assert topics.get(row.name) == [row.type], row.key
        if row.kind in ("publisher", "subscription"):
            assert endpoints[row.name] == [(row.reliability, row.durability)], row.key


def test_rviz_layout_shows_the_node_clouds(node_topics):
    layout = yaml.safe_load((SHARE / "config" / "workspace.rviz").read_text(encoding="utf-8"))
    displays = layout["Visualization Manager"]["Displays"]
    clouds = [d for d in displays if d["Class"] == "rviz_default_plugins/PointCloud2"]
    assert {d["Topic"]["Value"] for d in clouds} == {
        f"{NODE}/orientation_workspace",
        f"{NODE}/projected_workspace",
    }
    for display in clouds:
        assert node_topics[display["Topic"]["Value"]] == ["sensor_msgs/msg/PointCloud2"]
        assert display["Topic"]["Durability Policy"] == "Transient Local"
        assert display["Channel Name"] in {"phi", "theta", "psi"}
    assert layout["Visualization Manager"]["Global Options"]["Fixed Frame"] == "base"
    (scene,) = [d for d in displays if d["Class"] == "rviz_default_plugins/MarkerArray"]
    assert node_topics[scene["Topic"]["Value"]] == ["visualization_msgs/msg/MarkerArray"]
    assert scene["Topic"]["Durability Policy"] == "Transient Local"
    from hexapod_workspace.logs.markers import NAMESPACES

    assert set(scene["Namespaces"]) == set(NAMESPACES)


def test_node_offers_every_interface_of_the_issue(node_topics):
    expected = {
        "orientation_workspace": "sensor_msgs/msg/PointCloud2",
        "projected_workspace": "sensor_msgs/msg/PointCloud2",
        "workspace_summary": "hexapod_workspace_msgs/msg/WorkspaceSummary",
        "reachability": "hexapod_workspace_msgs/msg/ReachabilityResult",
        "workspace_request": "hexapod_workspace_msgs/msg/WorkspaceRequest",
        "commanded_pose": "hexapod_workspace_msgs/msg/CommandedPose",
        "check_poses": "hexapod_workspace_msgs/srv/CheckPoses",
        "check_poses_flat": "hexapod_workspace_msgs/srv/CheckPosesFlat",
        "compute_orientation_workspace": "std_srvs/srv/Trigger",
        "compute_projected_workspace": "std_srvs/srv/Trigger",
    }
    assert set(expected) | {"compute_workspace"} == set(messages.TOPICS)
    for key, type_name in expected.items():
        assert node_topics.get(messages.TOPICS[key]) == [type_name], key
    # ~/compute_workspace is an action: its hidden services and topics
    action = messages.TOPICS["compute_workspace"] + "/_action"
    package = "hexapod_workspace_msgs/action/ComputeWorkspace"
    assert node_topics.get(f"{action}/send_goal") == [f"{package}_SendGoal"]
    assert node_topics.get(f"{action}/get_result") == [f"{package}_GetResult"]
    assert node_topics.get(f"{action}/feedback") == [f"{package}_FeedbackMessage"]
    assert node_topics.get("/diagnostics") == ["diagnostic_msgs/msg/DiagnosticArray"]
    # the extensions: ~/check_path (ros/paths.py) and ~/compute_atlas (ros/atlas_action.py)
    assert node_topics.get(f"{NODE}/check_path") == ["hexapod_workspace_msgs/srv/CheckPath"]
    assert node_topics.get(f"{NODE}/compute_atlas/_action/send_goal") == [
        "hexapod_workspace_msgs/action/ComputeAtlas_SendGoal"
    ]
