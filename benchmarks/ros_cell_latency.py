"""Command-path latency with the machining cell: before/after, and while ~/axis_limits computes.

Four workspace_node processes run side by side in one DDS domain (LOCALHOST discovery), each in
a namespace of its own, all with the packaged example and recording on:

* ``before``: the node of another checkout (``--node-source DIR``, e.g. ``git archive`` of the
  commit before the cell reached the node), run against this install's messages;
* ``after``: this install's node, with a current-pose topic nobody publishes on (no axis limits
  computed);
* ``pose``: this install's node with a current-pose topic that this script publishes on at
  ``--pose-rate`` Hz and ``axis_limits.rate`` 0: every command is also checked as a move from
  the current pose (the motions feature, already there before the cell), no axis limits;
* ``axis``: the same with ``axis_limits.rate`` high enough that axis limits are computed back
  to back (12 certified reaches, 0.3-0.5 s each, in the node's axis-limits process) for the
  whole run.

From an rclpy client in this process it measures, interleaved so that every node sees the same
machine load: the round trip of a 1-pose ``~/check_poses`` call, and of a ``CommandedPose`` to its
``ReachabilityResult``. Prints median, 95th and 99th percentiles in ms per node and the ratios
after/before and axis/pose of the medians (same run): the cost of the cell on the command path,
and of computing axis limits beside it. No goal is asserted: the figures are for
the documentation.

    git archive <commit> hexapod_workspace | tar -x -C /tmp/before
    tools/with_ros_env.sh python benchmarks/ros_cell_latency.py --node-source /tmp/before
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
from _node import missing_install, print_failures, ros_domain, start_node, stop  # same folder

NODES = ("before", "after", "pose", "axis")
STREAMED = ("pose", "axis")


def start_named(name: str, source: Path | None, folder: Path) -> subprocess.Popen:
    """Start the node ``name`` (its namespace) in ``folder / name``."""
    args = ["-r", f"__ns:=/{name}"]
    if name != "before":
        args += ["-p", f"motion.current_pose_topic:=/{name}/current_pose"]
    if name in STREAMED:
        args += ["-p", f"axis_limits.rate:={100.0 if name == 'axis' else 0.0}"]
    return start_node(
        folder / name,
        args,
        source if name == "before" else None,
        log=folder / f"{name}.log",
    )


def stats(samples: list[float]) -> tuple[float, float, float]:
    values = np.asarray(samples) * 1e3
    return (
        float(np.median(values)),
        float(np.percentile(values, 95)),
        float(np.percentile(values, 99)),
    )


def run(args: argparse.Namespace, domain: int) -> int:
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from hexapod_workspace_msgs.msg import CommandedPose, ReachabilityResult, TiltTorsion
    from hexapod_workspace_msgs.srv import CheckPoses
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    rclpy.init(domain_id=domain)
    node = rclpy.create_node(f"cell_latency_client_{os.getpid()}")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    reliable = QoSProfile(
        history=HistoryPolicy.KEEP_ALL, depth=1, reliability=ReliabilityPolicy.RELIABLE
    )
    results_qos = QoSProfile(
        depth=1000,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    checks, commands, arrived = {}, {}, {}
    events: dict[str, threading.Event] = {}
    for name in NODES:
        checks[name] = node.create_client(CheckPoses, f"/{name}/hexapod_workspace/check_poses")
        commands[name] = node.create_publisher(
            CommandedPose, f"/{name}/hexapod_workspace/commanded_pose", reliable
        )
        events[name] = threading.Event()

        def received(message: Any, name: str = name) -> None:
            arrived[(name, message.request_id)] = time.perf_counter()
            events[name].set()

        node.create_subscription(
            ReachabilityResult, f"/{name}/hexapod_workspace/reachability", received, results_qos
        )
    poses = [node.create_publisher(PoseStamped, f"/{name}/current_pose", 10) for name in STREAMED]
    stop = threading.Event()

    def stream() -> None:  # the platform moving: a new current pose every 1/rate s
        k = 0
        while not stop.is_set():
            message = PoseStamped()
            message.header.frame_id = "base"
            message.pose.position.z = -1.3 + 0.01 * np.sin(0.1 * k)
            message.pose.orientation.w = 1.0
            for publisher in poses:
                publisher.publish(message)
            k += 1
            stop.wait(1.0 / args.pose_rate)

    try:
        if not all(c.wait_for_service(timeout_sec=120) for c in checks.values()):
            print("services not discovered within 120 s", file=sys.stderr)
            return 2
        one = CheckPoses.Request(orientations=[TiltTorsion(phi=0.3, theta=0.2, psi=0.1)])
        one.position.z = -1.3

        def call(name: str) -> float:
            start = time.perf_counter()
            response = checks[name].call(one, timeout_sec=60.0)
            if response is None or not response.success:
                raise RuntimeError(f"{name}: check_poses failed: {response}")
            return time.perf_counter() - start

        def command(name: str, k: int) -> float:
            message = CommandedPose(request_id=f"{name}-{k}")
            message.position.z = -1.3
            message.orientation = TiltTorsion(phi=0.3, theta=0.2, psi=0.1)
            events[name].clear()
            start = time.perf_counter()
            commands[name].publish(message)
            deadline = start + 30.0
            while (name, message.request_id) not in arrived:
                if not events[name].wait(max(0.0, deadline - time.perf_counter())):
                    raise RuntimeError(f"{name}: no ReachabilityResult within 30 s")
                events[name].clear()
            return arrived[(name, message.request_id)] - start

        for k in range(30):  # warm-up: discovery of reply paths, first allocations
            for name in NODES:
                call(name)
                command(name, -1 - k)
        streamer = threading.Thread(target=stream, daemon=True)
        streamer.start()
        time.sleep(2.0)  # the axis node's thread is computing from here on
        service: dict[str, list[float]] = {name: [] for name in NODES}
        topic: dict[str, list[float]] = {name: [] for name in NODES}
        for k in range(args.samples):
            for name in NODES:
                service[name].append(call(name))
                topic[name].append(command(name, k))
        stop.set()
        print(f"{args.samples} samples per node, interleaved; load average {os.getloadavg()}")
        for label, samples in (("check_poses 1 pose", service), ("commanded_pose", topic)):
            print(f"{label}: median / p95 / p99 ms")
            for name in NODES:
                median, p95, p99 = stats(samples[name])
                print(f"  {name:7s} {median:7.3f} / {p95:7.3f} / {p99:7.3f}")
            medians = {name: stats(samples[name])[0] for name in NODES}
            print(
                f"  ratio after/before {medians['after'] / medians['before']:.3f}, "
                f"axis/pose {medians['axis'] / medians['pose']:.3f}"
            )
        return 0
    finally:
        stop.set()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=300, help="calls and commands per node")
    parser.add_argument("--pose-rate", type=float, default=20.0, help="current poses per second")
    parser.add_argument(
        "--node-source",
        type=Path,
        required=True,
        metavar="DIR",
        help="a checkout (or git archive) of the node before the change",
    )
    args = parser.parse_args(argv)
    missing = missing_install()
    if missing:
        print(missing, file=sys.stderr)
        return 2
    with ros_domain() as domain, tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        processes = [start_named(name, args.node_source, folder) for name in NODES]
        try:
            return run(args, domain)
        finally:
            stop(processes)
            print_failures([folder / f"{name}.log" for name in NODES], ("Traceback", "rror"))


if __name__ == "__main__":
    sys.exit(main())
