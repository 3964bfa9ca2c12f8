"""The ROS 2 face of hexapod_workspace: the only subpackage that imports rclpy.

:mod:`hexapod_workspace.ros.node` holds the node ``hexapod_workspace`` (executable
``workspace_node``); :mod:`hexapod_workspace.ros.conversions` fills rclpy messages from the
ROS-free field dicts of :mod:`hexapod_workspace.messages`. Nothing here is imported by the core.
"""
