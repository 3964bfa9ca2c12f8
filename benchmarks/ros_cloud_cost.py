"""Where a large boundary cloud costs the node: time and interpreter stalls of each step.

A 3-D orientation workspace of the ros_load benchmark (360 rays, Δψ 0.005, tolerance 1e-7) has
about 274k boundary points: a 6.6 MB PointCloud2. Each step the node takes with it is run here in
one rclpy process, with a ticker thread that sleeps 0.5 ms in a loop; the longest gap the ticker
sees while a step runs is how long that step keeps every other thread of the process (the
executor answering commands) from running. Steps: the pipe from the worker (pickle), the
message (``to_message``), CDR serialisation (what the recorder does), ``publish`` to a
transient-local topic with a subscriber in another process, the action result's message, and
the recorder's MCAP write of the serialised bytes, and the bounded result the node now sends.
Before the clouds moved to the worker, the node's own process took: publish, two
serialisations (cloud and recorded result) and the full action result; now the worker process
builds, serialises and publishes the cloud, and the node only unpickles its bytes, writes them
to the log and sends the bounded result. Run it in the ROS environment::

    tools/with_ros_env.sh python benchmarks/ros_cloud_cost.py [--points 274000] [--repeat 5]
"""

from __future__ import annotations

import argparse
import os
import pickle
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

SWITCH_INTERVAL = 2e-4  # the node's (hexapod_workspace.ros.node.SWITCH_INTERVAL)
TOPIC = "/cloud_cost/orientation_workspace"
SUBSCRIBER = f"""
import contextlib, rclpy, time
from rclpy.executors import ExternalShutdownException
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import PointCloud2
rclpy.init()
node = rclpy.create_node("cloud_cost_reader")
qos = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                 durability=DurabilityPolicy.TRANSIENT_LOCAL)
node.create_subscription(PointCloud2, "{TOPIC}", lambda m: None, qos)
end = time.monotonic() + 120
with contextlib.suppress(KeyboardInterrupt, ExternalShutdownException):
    while rclpy.ok() and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
"""


class Ticker:
    """A thread that sleeps ``period`` s in a loop; ``worst()`` is its longest gap since
    :meth:`reset`, s."""

    def __init__(self, period: float = 5e-4) -> None:
        self.period = period
        self._last = time.perf_counter()
        self._worst = 0.0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            time.sleep(self.period)
            now = time.perf_counter()
            self._worst = max(self._worst, now - self._last)
            self._last = now

    def reset(self) -> None:
        time.sleep(0.01)
        self._last = time.perf_counter()
        self._worst = 0.0

    def worst(self) -> float:
        time.sleep(2 * self.period)
        return self._worst

    def stop(self) -> None:
        self._stop.set()


def measure(ticker: Ticker, step: Callable[[], object], repeat: int) -> tuple[float, float]:
    """Median wall time and median worst ticker gap of ``step``, ms."""
    times, stalls = [], []
    for _ in range(repeat):
        ticker.reset()
        start = time.perf_counter()
        step()
        times.append(time.perf_counter() - start)
        stalls.append(ticker.worst())
    return 1e3 * float(np.median(times)), 1e3 * float(np.median(stalls))


def _write(writer: object, data: bytes) -> None:
    writer.write(TOPIC, data, 1)  # type: ignore[attr-defined]
    writer.flush()  # type: ignore[attr-defined]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=274_000, help="points in the cloud")
    parser.add_argument("--repeat", type=int, default=5, help="runs of each step")
    args = parser.parse_args(argv)
    sys.setswitchinterval(SWITCH_INTERVAL)

    import domain_coordinator
    import rclpy
    from hexapod_workspace_msgs.action import ComputeWorkspace
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import PointCloud2

    from hexapod_workspace.logs import LogWriter, messages
    from hexapod_workspace.ros.clouds import RESULT_MAX_POINTS, decimated_cloud_fields
    from hexapod_workspace.ros.conversions import to_message

    rng = np.random.default_rng(3)
    points = rng.uniform(-1.0, 1.0, (args.points, 6))
    fields = messages.pointcloud_fields(points, frame_id="base", stamp_ns=1)
    summary = messages.summary_fields(
        None, stamp_ns=1, frame_id="base", message="x", kind=0, position=np.zeros(3)
    )
    with domain_coordinator.domain_id() as domain, tempfile.TemporaryDirectory() as tmp:
        os.environ["ROS_DOMAIN_ID"] = str(domain)
        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
        reader = subprocess.Popen([sys.executable, "-c", SUBSCRIBER], env=dict(os.environ))
        rclpy.init()
        node = rclpy.create_node("cloud_cost")
        qos = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        publisher = node.create_publisher(PointCloud2, TOPIC, qos)
        deadline = time.monotonic() + 30
        while publisher.get_subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        writer = LogWriter(Path(tmp) / "cost.mcap")
        writer.open()
        writer.add_channel(TOPIC, "sensor_msgs/msg/PointCloud2", "")
        ticker = Ticker()
        cloud = to_message(PointCloud2, fields)
        data = serialize_message(cloud)
        pickled = pickle.dumps(fields, protocol=pickle.HIGHEST_PROTOCOL)
        result_fields = messages.compute_workspace_response_fields(
            None, stamp_ns=1, frame_id="base", summary=summary, boundary=cloud
        )
        bounded_fields = messages.compute_workspace_response_fields(
            None,
            stamp_ns=1,
            frame_id="base",
            summary=summary,
            boundary=decimated_cloud_fields(fields, RESULT_MAX_POINTS),
        )
        steps: list[tuple[str, Callable[[], object]]] = [
            ("idle (ticker alone)", lambda: time.sleep(0.05)),
            ("pickle.loads (pipe from the worker)", lambda: pickle.loads(pickled)),
            ("to_message(PointCloud2)", lambda: to_message(PointCloud2, fields)),
            ("serialize_message (recorder)", lambda: serialize_message(cloud)),
            ("publish (subscriber in another process)", lambda: publisher.publish(cloud)),
            (
                "action Result message + serialize",
                lambda: serialize_message(to_message(ComputeWorkspace.Result, result_fields)),
            ),
            ("MCAP write of the bytes + flush", lambda: _write(writer, data)),
            (
                f"action Result, {RESULT_MAX_POINTS} points (bounded)",
                lambda: serialize_message(to_message(ComputeWorkspace.Result, bounded_fields)),
            ),
        ]
        try:
            print(
                f"{args.points} points, {len(data) / 1e6:.1f} MB serialised; median of "
                f"{args.repeat}; load average {os.getloadavg()[0]:.2f}"
            )
            print(f"{'step':45s} {'wall ms':>9s} {'stall ms':>9s}")
            for name, step in steps:
                wall, stall = measure(ticker, step, args.repeat)
                print(f"{name:45s} {wall:9.2f} {stall:9.2f}")
        finally:
            ticker.stop()
            writer.finish()
            node.destroy_node()
            rclpy.try_shutdown()
            reader.terminate()
            reader.wait(timeout=10)
    return 0


if __name__ == "__main__":
    sys.exit(main())
