"""Launch workspace_node with a parameters file, optionally with RViz2 showing the clouds.

    ros2 launch hexapod_workspace workspace.launch.py
    ros2 launch hexapod_workspace workspace.launch.py params_file:=/path/to/my_gpm.yaml rviz:=true

Arguments
---------
params_file
    ROS 2 parameters file of the node (default: the packaged example GPM,
    ``share/hexapod_workspace/config/example_gpm.yaml``).
autostart
    ``true`` (default) configures and activates the managed node at once; ``false`` leaves it
    unconfigured until a ``lifecycle_msgs`` ``configure`` and ``activate`` (``ros2 lifecycle
    set /hexapod_workspace configure``).
realtime_priority
    ``0`` (default): normal scheduling; 1..99: the node's threads run under SCHED_FIFO at that
    priority, ahead of other jobs on the machine (its worker stays at normal priority; needs
    an rtprio limit or CAP_SYS_NICE; see docs/ros.md, "Threads, load and latency").
worker_scheduling
    ``normal`` (default: niceness 5), ``idle`` (SCHED_IDLE) or ``batch`` (SCHED_BATCH, niceness
    19): the scheduling policy of the node's long computations (the worker process's workspaces,
    the axis-limits process); ``idle`` puts the node's answers first but starves the
    computations while the session keeps the cores busy; unprivileged (docs/ros.md, "Threads,
    load and latency").
rviz
    ``true`` also starts rviz2 with ``share/hexapod_workspace/config/workspace.rviz``.

DDS discovery follows the environment of the caller (ROS_DOMAIN_ID,
ROS_AUTOMATIC_DISCOVERY_RANGE); set ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST to keep traffic on
this machine.
"""

from __future__ import annotations

from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution


def generate_launch_description() -> LaunchDescription:
    """The node ``hexapod_workspace`` (and rviz2 when ``rviz:=true``)."""
    share = FindPackageShare("hexapod_workspace")
    params_file = LaunchConfiguration("params_file")
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "params_file",
                default_value=PathJoinSubstitution([share, "config", "example_gpm.yaml"]),
                description="Parameters file of workspace_node (geometry, limits, pose, ...).",
            ),
            DeclareLaunchArgument(
                "autostart",
                default_value="true",
                description="Configure and activate the lifecycle node at start.",
            ),
            DeclareLaunchArgument(
                "realtime_priority",
                default_value="0",
                description="SCHED_FIFO priority of the node's threads (0: normal scheduling).",
            ),
            DeclareLaunchArgument(
                "worker_scheduling",
                default_value="normal",
                description="Policy of the long computations: normal (niceness 5), idle "
                "(SCHED_IDLE) or batch (SCHED_BATCH, niceness 19).",
            ),
            DeclareLaunchArgument(
                "rviz", default_value="false", description="Start rviz2 with the layout."
            ),
            Node(
                package="hexapod_workspace",
                executable="workspace_node",
                name="hexapod_workspace",
                output="screen",
                emulate_tty=True,
                arguments=[
                    ["--autostart=", LaunchConfiguration("autostart")],
                    ["--realtime-priority=", LaunchConfiguration("realtime_priority")],
                    ["--worker-scheduling=", LaunchConfiguration("worker_scheduling")],
                ],
                parameters=[params_file],
            ),
            Node(
                package="rviz2",
                executable="rviz2",
                name="rviz2",
                arguments=["-d", PathJoinSubstitution([share, "config", "workspace.rviz"])],
                condition=IfCondition(LaunchConfiguration("rviz")),
            ),
        ]
    )
