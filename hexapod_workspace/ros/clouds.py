"""Boundary clouds published by the worker process, out of the node's interpreter.

A 3-D orientation workspace has hundreds of thousands of boundary points (274k, 6.6 MB, for 360
rays and Δψ 0.005). Building that PointCloud2, serialising it and publishing it holds the
interpreter of the process that does it for tens of milliseconds (``benchmarks/
ros_cloud_cost.py`` measures each step); in the node's process that stalls the executor that
answers the commands. So the worker process that computed the points also publishes them: it runs
a node of its own, ``<node>_clouds`` in the node's namespace, with one reliable,
transient-local, depth-1 publisher per cloud topic of the node (``~/orientation_workspace``,
``~/projected_workspace``, the names resolved, remappings included, by the node). It serialises a
cloud once, publishes those bytes and hands them back to the node, whose recorder writes them to
the MCAP log as they are (no second serialisation), together with a bounded cloud for the
action's ``result.boundary`` (:func:`decimated_cloud_fields`).

Nothing here runs in the node's process except :class:`CloudTopics` (what the node tells the
worker) and :func:`decimated_cloud_fields` (numpy only).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "RESULT_MAX_POINTS",
    "CloudPublisher",
    "CloudTopics",
    "PublishedCloud",
    "decimated_cloud_fields",
]

#: Most boundary points in a ``~/compute_workspace`` result: 20k points (480 kB) draw a boundary
#: densely enough for a display and cost the node's executor about a millisecond to send; the
#: full cloud is on the cloud topic (transient local: any subscriber, any time) and in the log.
RESULT_MAX_POINTS = 20_000


@dataclass(frozen=True)
class CloudTopics:
    """Where the worker publishes the clouds (picklable: sent to the spawned process).

    Attributes
    ----------
    node_name, namespace : str
        The worker's node is ``<node_name>_clouds`` in ``namespace``.
    topics : dict of int to str
        Fully qualified cloud topic of each workspace kind (``WorkspaceKind`` value).
    domain_id : int
        The node's DDS domain.
    """

    node_name: str
    namespace: str
    topics: dict[int, str]
    domain_id: int


@dataclass(frozen=True)
class PublishedCloud:
    """What the worker tells the node about a cloud it published.

    Attributes
    ----------
    topic : str
        Fully qualified topic it was published on.
    data : bytes
        What the node's log records: the CDR bytes published, or those of the same cloud
        bounded to ``recording.cloud_points`` points (the same header, fields and stamp; evenly
        spaced points), so that the node's process never handles a multi-megabyte cloud.
    log_time_ns : int
        When it was published, ns since the epoch.
    """

    topic: str
    data: bytes
    log_time_ns: int


def decimated_cloud_fields(fields: dict[str, Any], max_points: int) -> dict[str, Any]:
    """A PointCloud2 field dict with at most ``max_points`` of the points of ``fields``.

    Parameters
    ----------
    fields : dict
        Unorganised cloud (height 1) as :func:`hexapod_workspace.logs.messages.pointcloud_fields`
        builds it (``data`` bytes, ``point_step`` bytes per point).
    max_points : int
        Most points kept; 0 keeps all.

    Returns
    -------
    dict
        ``fields`` itself when it has no more than ``max_points`` points; otherwise a copy
        holding ``max_points`` points evenly spaced in the cloud's order (the first and the last
        included; for an orientation workspace the order is slice by slice, ray by ray, so every
        slice keeps its share of points).
    """
    count = int(fields["width"]) * int(fields["height"])
    if max_points <= 0 or count <= max_points:
        return fields
    step = int(fields["point_step"])
    rows = np.frombuffer(fields["data"], dtype=np.uint8)[: count * step].reshape(count, step)
    keep = np.unique(np.linspace(0, count - 1, max_points).round().astype(np.int64))
    return {
        **fields,
        "height": 1,
        "width": int(keep.size),
        "row_step": step * int(keep.size),
        "data": rows[keep].tobytes(),
    }


class CloudPublisher:
    """The worker's node and its cloud publishers (created in the worker process).

    Parameters
    ----------
    topics : CloudTopics
    """

    def __init__(self, topics: CloudTopics) -> None:
        import rclpy
        from rclpy.context import Context
        from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
        from sensor_msgs.msg import PointCloud2

        self._context = Context()
        rclpy.init(context=self._context, domain_id=topics.domain_id)
        self._node = rclpy.create_node(
            f"{topics.node_name}_clouds",
            namespace=topics.namespace,
            context=self._context,
            start_parameter_services=False,
        )
        qos = QoSProfile(
            history=HistoryPolicy.KEEP_LAST,
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        # one publisher per topic (two kinds share ~/projected_workspace): a late subscriber
        # then gets the topic's last cloud, not the last of each kind
        self._publishers = {
            topic: self._node.create_publisher(PointCloud2, topic, qos)
            for topic in sorted(set(topics.topics.values()))
        }
        self._topics = dict(topics.topics)
        self._message_class = PointCloud2

    def publish(
        self, kind: int, fields: dict[str, Any], record_points: int | None = 0
    ) -> PublishedCloud | None:
        """Build, serialise once and publish the cloud ``fields`` of a ``kind`` workspace.

        Returns what the node's log records: the published bytes (``record_points`` 0, or a
        cloud no larger), the CDR bytes of a cloud of at most ``record_points`` points
        (:func:`decimated_cloud_fields`), or None (``record_points`` None: not recorded).
        """
        from rclpy.serialization import serialize_message

        from .conversions import to_message

        data = serialize_message(to_message(self._message_class, fields))
        log_time_ns = time.time_ns()
        topic = self._topics[kind]
        self._publishers[topic].publish(data)  # rclpy publishes serialised bytes as they are
        if record_points is None:
            return None
        recorded = decimated_cloud_fields(fields, record_points)
        if recorded is not fields:
            data = serialize_message(to_message(self._message_class, recorded))
        return PublishedCloud(topic, data, log_time_ns)

    def close(self) -> None:
        """Destroy the node and end its context (idempotent)."""
        import rclpy

        if self._context.ok():
            self._node.destroy_node()
            rclpy.try_shutdown(context=self._context)
