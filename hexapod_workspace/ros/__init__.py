"""The ROS 2 face of hexapod_workspace: the only subpackage that imports rclpy.

:mod:`~hexapod_workspace.ros.node` wires the node ``hexapod_workspace`` (executable
``workspace_node``) and its callbacks; :mod:`~.parameters` declares and validates its
parameters; :mod:`~.commands` answers the CommandedPose stream; :mod:`~.workspaces` serves the
``~/compute_workspace`` action, the Trigger services and the request topic through the job queue
of :mod:`~.jobs`, which runs them in the worker process of :mod:`~.worker` (ROS-free);
:mod:`~.recorder` owns the MCAP log; :mod:`~.health` builds ``/diagnostics``;
:mod:`~.conversions` fills rclpy messages from the ROS-free field dicts of
:mod:`hexapod_workspace.logs.messages`; :mod:`~.republish` replays logs. Nothing here is
imported by the core.
"""

from __future__ import annotations

import sys

__all__ = ["main"]

#: Modules the node needs from a ROS 2 installation (apt ros-jazzy-* or the pip wheels) and from
#: the colcon build of msg_defs/.
_ROS_MODULES = {
    "rclpy",
    "rcl_interfaces",
    "action_msgs",
    "lifecycle_msgs",
    "diagnostic_msgs",
    "rosidl_parser",
    "sensor_msgs",
    "std_srvs",
    "hexapod_workspace_msgs",
}


def main(args: list[str] | None = None) -> int:
    """Entry point of ``workspace_node``: run the node, or explain what is missing.

    Returns
    -------
    int
        The node's exit status; 2 when ROS 2 or the interface package cannot be imported.
    """
    try:
        from .node import main as node_main
    except ImportError as error:
        if (error.name or "").split(".")[0] not in _ROS_MODULES:
            raise
        print(
            f"workspace_node needs ROS 2 Jazzy and the interface package hexapod_workspace_msgs "
            f"(cannot import {error.name}). Source /opt/ros/jazzy/setup.bash and the colcon "
            f"install space (install/setup.bash), or, in this repository, run "
            f"tools/with_ros_env.sh workspace_node.",
            file=sys.stderr,
        )
        return 2
    return node_main(args)
