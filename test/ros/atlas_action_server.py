"""A node process serving only ``~/compute_atlas`` (what ``attach_atlas_action`` adds to the
workspace node), for test_ros_atlas_action.py: run as ``python atlas_action_server.py LOG``.

It records like the workspace node does (an MCAP log through LogWriter, CDR from rclpy) into
LOG, finished on SIGINT. Discovery stays on loopback (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
and ROS_DOMAIN_ID come from the test's environment).
"""

from __future__ import annotations

import sys

import rclpy
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.serialization import serialize_message

from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.logs import LogWriter
from hexapod_workspace.ros.atlas_action import attach_atlas_action


class Recorder:
    """The recorder interface the action expects, over a LogWriter."""

    def __init__(self, writer: LogWriter) -> None:
        self.writer = writer

    def add_channel(self, topic: str, msgtype: str, qos: str) -> None:
        self.writer.add_channel(topic, msgtype, qos)

    def write(self, topic: str, message) -> None:
        self.writer.write(topic, serialize_message(message))


def main() -> None:
    rclpy.init()
    manipulator = load_manipulator(example_config_path())
    writer = LogWriter(sys.argv[1]).open()
    node = rclpy.create_node("hexapod_workspace")
    executor = MultiThreadedExecutor(num_threads=3)
    try:
        attach_atlas_action(node, lambda: manipulator, recorder=Recorder(writer))
        executor.add_node(node)
        print("serving", flush=True)
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        writer.close()
        executor.shutdown(timeout_sec=10.0)
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
