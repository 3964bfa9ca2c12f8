"""Command latency while ~/markers follows a moving current pose, against a pose standing still.

Starts workspace_node from the colcon install space (``make ros``) with
``motion.current_pose_topic`` set, in a DDS domain of its own (LOCALHOST discovery), and from an
rclpy client in this process calls ``~/check_poses`` (one pose per call) back to back while a
thread publishes the current pose at 50 Hz: in the *still* phases the pose never changes (the
markers are not rebuilt), in the *moving* phases it moves on a circle (the node rebuilds the
scene and the cone of tool directions at most 5 times a second, in its markers thread).
Phases alternate, so both see the same machine load. Prints p50/p95/p99 of each kind of phase
(ms), their ratio, the scenes received, and the load average.

    tools/with_ros_env.sh python benchmarks/ros_markers.py [--phase-seconds 4] [--rounds 3]

With ``--node-source DIR`` the node runs from another source tree (a ``git archive`` of the
commit before ``~/markers``): the same phases against a node without markers, for a same-machine
before/after.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from _node import missing_install, ros_domain, start_node, stop  # same folder

NODE = "/hexapod_workspace"
CURRENT_POSE = "/bench_current_pose"
POSE_RATE = 50.0


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; 0 when it ran."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phase-seconds", type=float, default=4.0, help="length of a phase, s")
    parser.add_argument("--rounds", type=int, default=3, help="still + moving pairs")
    parser.add_argument(
        "--node-source",
        type=Path,
        metavar="DIR",
        help="run the node from this source tree instead of the install space (e.g. a "
        "`git archive` of the commit before ~/markers, for a same-machine before/after)",
    )
    args = parser.parse_args(argv)
    missing = missing_install()
    if missing:
        print(missing, file=sys.stderr)
        return 2
    with ros_domain() as domain, tempfile.TemporaryDirectory() as tmp:
        node = start_node(
            Path(tmp), ["-p", f"motion.current_pose_topic:={CURRENT_POSE}"], args.node_source
        )
        try:
            return run(args, domain)
        finally:
            stop([node])


def run(args: argparse.Namespace, domain: int) -> int:
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from hexapod_workspace_msgs.msg import TiltTorsion
    from hexapod_workspace_msgs.srv import CheckPoses
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from visualization_msgs.msg import MarkerArray

    rclpy.init(domain_id=domain)
    client = rclpy.create_node(f"markers_bench_{os.getpid()}")
    executor = SingleThreadedExecutor()
    executor.add_node(client)
    threading.Thread(target=executor.spin, name="client-spin", daemon=True).start()
    checks = client.create_client(CheckPoses, f"{NODE}/check_poses")
    poses = client.create_publisher(PoseStamped, CURRENT_POSE, 10)
    scenes: list[float] = []
    qos = QoSProfile(
        depth=10,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    client.create_subscription(
        MarkerArray, f"{NODE}/markers", lambda _: scenes.append(time.monotonic()), qos
    )
    moving = threading.Event()
    stop = threading.Event()

    def stream() -> None:
        k = 0
        while not stop.wait(1.0 / POSE_RATE):
            message = PoseStamped()
            message.header.frame_id = "base"
            angle = 0.05 * k if moving.is_set() else 0.0
            message.pose.position.x = 0.05 * math.cos(angle)
            message.pose.position.y = 0.05 * math.sin(angle)
            message.pose.position.z = -1.3
            message.pose.orientation.w = 1.0
            poses.publish(message)
            k += 1

    streamer = threading.Thread(target=stream, name="poses", daemon=True)
    try:
        if not checks.wait_for_service(timeout_sec=120):  # a fresh source tree compiles first
            print("check_poses not discovered within 120 s", file=sys.stderr)
            return 2
        streamer.start()
        request = CheckPoses.Request()
        request.position.z = -1.3
        request.orientations = [TiltTorsion(phi=0.1, theta=0.2, psi=0.0)]
        for _ in range(50):  # warm-up
            checks.call(request)
        times: dict[str, list[float]] = {"still": [], "moving": []}
        counts: dict[str, int] = {"still": 0, "moving": 0}
        for _ in range(args.rounds):
            for phase in ("still", "moving"):
                moving.set() if phase == "moving" else moving.clear()
                time.sleep(0.5)  # the node sees the new kind of pose
                started = time.monotonic()
                before = len(scenes)
                while time.monotonic() - started < args.phase_seconds:
                    t0 = time.perf_counter()
                    checks.call(request)
                    times[phase].append(1e3 * (time.perf_counter() - t0))
                counts[phase] += len(scenes) - before
        load = os.getloadavg()
        print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
        seconds = args.rounds * args.phase_seconds
        for phase, values in times.items():
            ms = np.array(values)
            print(
                f"{phase:6s} {len(ms):6d} calls  p50 {np.median(ms):.3f}  "
                f"p95 {np.percentile(ms, 95):.3f}  p99 {np.percentile(ms, 99):.3f} ms; "
                f"{counts[phase] / seconds:.1f} scenes/s received"
            )
        ratio = np.median(times["moving"]) / np.median(times["still"])
        print(f"moving / still, median: {ratio:.3f}")
        return 0
    finally:
        stop.set()
        executor.shutdown()
        client.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
