"""The node's rclpy QoS profiles, in a module of their own so that every part of the node
(``node``, ``paths``, extensions) creates its services and subscriptions with the same ones
without importing :mod:`~hexapod_workspace.ros.node`.
"""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

__all__ = ["COMMAND_QOS", "SERVICE_QOS_PROFILE"]

#: The commanded-pose subscription: nothing is dropped on the node's side.
COMMAND_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_ALL, depth=1, reliability=ReliabilityPolicy.RELIABLE
)
#: The services' answers: reliable, volatile, the last 1000 kept until every client has them.
#: rmw's default keeps 10: under load a client whose answer was lost in transport (a full
#: shared-memory port) asks again once it sees the gap, and when the node has answered ten other
#: calls meanwhile the answer is gone and the client waits forever. Fast DDS drops a volatile
#: writer's sample once every reader has acknowledged it, so the depth costs memory only while
#: a client lags.
SERVICE_QOS_PROFILE = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1000,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
