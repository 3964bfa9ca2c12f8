#!/usr/bin/env python3
"""The node's first answer after a plain ``colcon build``: seconds from its start to the first
``~/check_poses`` answer, with an empty numba cache (what a build leaves: the install space's
package has no compiled kernels) and again with the cache it filled.

The node runs from the colcon install space (``make ros``) with ``NUMBA_CACHE_DIR`` pointing
to a new, empty folder, so it compiles the kernels of its model while it configures, exactly as
after a user's ``colcon build``; a client in this process asks ``check_poses`` for one pose
every 0.2 s (each call waits up to 1 s) from the moment the node is started, on loopback, in a
DDS domain of its own. Goal: within 15 s on a quiet machine.

Usage: python benchmarks/node_cold.py [--runs N]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _node import missing_install, ros_domain, start_node, stop

GOAL_S = 15.0
LIMIT_S = 300.0


def first_answer_after_start(folder: Path, cache: Path) -> tuple[float, float]:
    """(seconds to the first answer, the node's CPU seconds until then)."""
    import rclpy
    from hexapod_workspace_msgs.msg import TiltTorsion
    from hexapod_workspace_msgs.srv import CheckPoses

    request = CheckPoses.Request(orientations=[TiltTorsion(phi=0.3, theta=0.2, psi=0.1)])
    request.position.z = -1.3
    os.environ["NUMBA_CACHE_DIR"] = str(cache)
    started = time.monotonic()
    node = start_node(folder)
    try:
        rclpy.init(domain_id=int(os.environ["ROS_DOMAIN_ID"]))
        client_node = rclpy.create_node(f"cold_client_{os.getpid()}")
        client = client_node.create_client(CheckPoses, "/hexapod_workspace/check_poses")
        while time.monotonic() - started < LIMIT_S:
            if client.wait_for_service(timeout_sec=0.2):
                future = client.call_async(request)
                rclpy.spin_until_future_complete(client_node, future, timeout_sec=1.0)
                if future.done() and future.result() is not None:
                    break
            time.sleep(0.2)
        else:
            raise SystemExit(f"no answer within {LIMIT_S:.0f} s (see {folder / 'node.log'})")
        seconds = time.monotonic() - started
        with open(f"/proc/{node.pid}/stat", encoding="ascii") as stat:
            fields = stat.read().rsplit(")", 1)[1].split()
        cpu = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
        client_node.destroy_node()
        rclpy.try_shutdown()
        return seconds, cpu
    finally:
        stop([node])
        os.environ.pop("NUMBA_CACHE_DIR", None)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=1, help="cold starts (each: a new cache)")
    options = parser.parse_args()
    if reason := missing_install():
        raise SystemExit(reason)
    print(f"node cold start, load average {os.getloadavg()[0]:.1f}")
    with ros_domain(), tempfile.TemporaryDirectory(prefix="hexapod-node-cold-") as scratch:
        for run in range(options.runs):
            cache = Path(scratch) / f"cache{run}"
            cold = first_answer_after_start(Path(scratch) / f"cold{run}", cache)
            warm = first_answer_after_start(Path(scratch) / f"warm{run}", cache)
            for name, (seconds, cpu) in (("empty cache", cold), ("cache filled", warm)):
                met = "met" if seconds <= GOAL_S else "NOT met"
                print(
                    f"  first check_poses answer, {name}: {seconds:.1f} s after start "
                    f"(node CPU {cpu:.1f} s; goal <= {GOAL_S:g} s: {met})"
                )
    print(f"load average at the end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
