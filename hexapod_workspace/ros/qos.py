"""The node's rclpy QoS profiles, in a module of their own so that every part of the node
(``node``, ``paths``, extensions) creates its services and subscriptions with the same ones
without importing :mod:`~hexapod_workspace.ros.node`.
"""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

__all__ = ["COMMAND_QOS", "FEEDBACK_QOS_PROFILE", "SERVICE_QOS_PROFILE"]

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
#: The workspace action's feedback: reliable, volatile, the last 200 kept. A goal reports at
#: most about 105 feedback messages (the stages and every 1 % of progress); with rmw's default
#: depth of 10 a client whose executor lags (a loaded machine) loses the first ones, "queued"
#: among them, because a KEEP_LAST writer replaces samples not yet acknowledged.
FEEDBACK_QOS_PROFILE = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=200,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
