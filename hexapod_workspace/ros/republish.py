"""Republish a recorded log on its topics (``hexapod-workspace replay LOG --publish``).

The recorded CDR bytes go out unchanged, at the recorded pace times a rate factor. DDS stays on
this machine: ``ROS_AUTOMATIC_DISCOVERY_RANGE`` is set to ``LOCALHOST`` for this process when it
is unset, and any other value is refused unless the caller allows the network.
"""

from __future__ import annotations

import os
import time
from typing import IO, TYPE_CHECKING, Any

import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from hexapod_workspace.logs.summary import LogSummary

if TYPE_CHECKING:
    from collections.abc import Sequence

    from hexapod_workspace.logs import LogMessage

from .conversions import message_class

_DISCOVERY = "ROS_AUTOMATIC_DISCOVERY_RANGE"


def _qos(text: str) -> Any:
    transient = "transient_local" in text
    return QoSProfile(
        depth=1 if transient else 10,
        reliability=ReliabilityPolicy.BEST_EFFORT
        if "best_effort" in text
        else ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if transient else DurabilityPolicy.VOLATILE,
    )


def publish_log(
    summary: LogSummary,
    kept: Sequence[LogMessage],
    rate: float,
    err: IO[str],
    *,
    allow_network: bool,
    wait_for_subscribers: float,
) -> int:
    """Republish the recorded bytes on their topics at ``rate`` × the recorded pace.

    Parameters
    ----------
    summary : LogSummary
        The log, as :func:`hexapod_workspace.logs.summary.summarize_log` read it.
    kept : sequence of LogMessage
        Its messages (``summarize_log(..., keep_messages=True)``).
    rate : float
        Playback speed factor (1 = recorded pace, 0 = as fast as possible).
    err : text stream
        Where notes and the closing count go.
    allow_network : bool
        Publish even when ``ROS_AUTOMATIC_DISCOVERY_RANGE`` is set to something else than LOCALHOST.
    wait_for_subscribers : float
        Seconds to wait for every topic to have a subscriber.

    Returns
    -------
    int
        0 when published, 2 when refused (one line on ``err``).
    """
    value = os.environ.get(_DISCOVERY)
    if value is None:
        os.environ[_DISCOVERY] = "LOCALHOST"
    elif value != "LOCALHOST" and not allow_network:
        err.write(
            f"replay --publish: refusing to publish with {_DISCOVERY}={value}; "
            "set it to LOCALHOST (or unset it)\n"
        )
        return 2
    usable = [m for m in kept if m.message is not None]
    classes: dict[str, Any] = {}
    for info in summary.contents.topics.values():
        try:
            classes[info.topic] = message_class(info.msgtype)
        except (ImportError, AttributeError, ValueError):
            count = sum(1 for m in usable if m.topic == info.topic)
            err.write(
                f"note: {info.topic}: type {info.msgtype} is not available in this ROS "
                f"environment; its {count} message(s) are not republished\n"
            )
    published = 0
    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        node = Node("hexapod_workspace_replay", context=context)
        publishers = {
            topic: node.create_publisher(cls, topic, _qos(summary.contents.topics[topic].qos))
            for topic, cls in classes.items()
        }
        deadline = time.monotonic() + wait_for_subscribers
        while any(p.get_subscription_count() == 0 for p in publishers.values()):
            if time.monotonic() >= deadline:
                break
            time.sleep(0.01)
        start_wall = time.monotonic()
        start_log = usable[0].log_time_ns if usable else 0
        for item in usable:
            publisher = publishers.get(item.topic)
            if publisher is None:
                continue
            if rate > 0:
                due = start_wall + (item.log_time_ns - start_log) / 1e9 / rate
                delay = due - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
            publisher.publish(item.data)  # serialized bytes go out unchanged
            published += 1
        for publisher in publishers.values():  # let reliable subscribers receive everything
            publisher.wait_for_all_acked(Duration(seconds=5))
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    topics = len({m.topic for m in usable if m.topic in classes})
    skipped = len(usable) - published
    note = f" ({skipped} not republished, see the notes above)" if skipped else ""
    err.write(f"republished {published} of {len(usable)} messages on {topics} topics{note}\n")
    return 0
