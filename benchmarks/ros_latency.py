"""Round-trip time of ~/check_poses from a client in another process, idle and under load.

Starts workspace_node from the colcon install space (``make ros``) in its own process, in a
DDS domain of its own with ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, and measures from an rclpy
client in this process:

1. one pose per request (goal: median <= 2 ms), against the floor measured in the same run:
   the cheapest rclpy server of the same service type (single-threaded executor, constant
   answer) in another process, called alternately with the node;
2. 1000 poses per request, nested (``~/check_poses``) and flat (``~/check_poses_flat``), against
   the core's ``check`` of the same 1000 poses in this process (the ratio is the cost of ROS:
   messages, DDS, executor; goal for the flat form: <= 3x) and against the floor plus the core
   (what no ROS service can beat: one round trip and the check);
3. one pose per request while a 3-D orientation workspace is being computed by the node (goal:
   median <= 2 ms too), against the idle median of step 1.

Run it in the ROS environment::

    tools/with_ros_env.sh python benchmarks/ros_latency.py [--samples 500]

Prints medians and 95th percentiles in ms, and the ratios; exits 1 when a goal is missed.
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
from typing import Any

import numpy as np
from _node import (  # same folder
    first_answer,
    missing_install,
    ros_domain,
    start_node,
    start_python,
    stop,
)

GOAL_MS = 2.0
#: Goal for 1000 poses in the flat form, as a ratio to the in-process core.
GOAL_FLAT_CORE_RATIO = 3.0
NODE = "/hexapod_workspace"
FLOOR = "/latency_floor/check_poses"


def server_source(node_name: str, setup: str) -> str:
    """``python -c`` source of an rclpy node ``node_name`` spun by a single-threaded executor
    until SIGINT; ``setup`` (source text) creates its service on ``node``."""
    return f"""
import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
rclpy.init()
node = rclpy.create_node("{node_name}")
{setup}
executor = SingleThreadedExecutor()
executor.add_node(node)
try:
    executor.spin()
except (KeyboardInterrupt, ExternalShutdownException):
    pass
finally:
    node.destroy_node()
    rclpy.try_shutdown()
"""


def floor_server_source(service: str, node_name: str) -> str:
    """The reference measured in the same run: the cheapest rclpy server of the same service
    type (single-threaded executor, constant answer, no check), run as ``python -c SOURCE``."""
    return server_source(
        node_name,
        f"""
from hexapod_workspace_msgs.srv import CheckPoses
node.create_service(CheckPoses, "{service}", lambda request, response: CheckPoses.Response(
    success=True, message="1/1 reachable"))
""",
    )


FLOOR_SERVER = floor_server_source(FLOOR, "latency_floor")
FLAT_FLOOR = "/latency_floor/check_poses_flat"


def flat_floor_server_source(service: str, node_name: str, poses: int = 1000) -> str:
    """The floor of the flat form: the cheapest rclpy server of CheckPosesFlat answering every
    request with the same prebuilt answer of ``poses`` poses (every array as large as the
    node's, no check), run as ``python -c SOURCE``: what moving those bytes through rclpy and
    DDS costs."""
    return server_source(
        node_name,
        f"""
import array
from hexapod_workspace.core.evaluation.check import CONSTRAINT_NAMES
from hexapod_workspace_msgs.srv import CheckPosesFlat
count, names = {poses}, list(CONSTRAINT_NAMES)
answer = CheckPosesFlat.Response(success=True, message=f"{{count}}/{{count}} reachable")
answer.constraint_names = names
answer.margins = array.array("d", [0.5]) * (count * len(names))
answer.reachable = [True] * count
answer.limiting_leg = array.array("i", [0]) * count
node.create_service(CheckPosesFlat, "{service}", lambda request, response: answer)
""",
    )


FLAT_FLOOR_SERVER = flat_floor_server_source(FLAT_FLOOR, "latency_flat_floor")


def check_requests(count: int = 1000, seed: int = 1) -> tuple[Any, Any, np.ndarray]:
    """CheckPoses requests at (0, 0, -1.3) m: one pose, and ``count`` seeded random poses
    (returned too, shape (count, 3), rad, for the in-process core in the same run)."""
    from hexapod_workspace_msgs.msg import TiltTorsion
    from hexapod_workspace_msgs.srv import CheckPoses

    one = CheckPoses.Request(orientations=[TiltTorsion(phi=0.3, theta=0.2, psi=0.1)])
    one.position.z = -1.3
    rng = np.random.default_rng(seed)
    angles = np.column_stack(
        (
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(0.0, 0.8, count),
            rng.uniform(-0.5, 0.5, count),
        )
    )
    batch = CheckPoses.Request(
        orientations=[TiltTorsion(phi=p, theta=t, psi=s) for p, t, s in angles.tolist()]
    )
    batch.position.z = -1.3
    return one, batch, angles


def flat_request(
    angles: np.ndarray, position: tuple[float, float, float] = (0.0, 0.0, -1.3)
) -> Any:
    """The CheckPosesFlat request of ``angles`` (N, 3) rad at ``position`` m."""
    import array

    from hexapod_workspace_msgs.srv import CheckPosesFlat

    request = CheckPosesFlat.Request()
    request.position.x, request.position.y, request.position.z = position
    values = array.array("d")
    values.frombytes(np.ascontiguousarray(angles, dtype=np.float64).tobytes())
    request.angles = values
    return request


def timed_call(client: Any, request: Any) -> float:
    """Seconds one successful CheckPoses call takes (RuntimeError when it fails)."""
    start = time.perf_counter()
    response = client.call(request, timeout_sec=60.0)
    elapsed = time.perf_counter() - start
    if response is None or not response.success:
        raise RuntimeError(f"check_poses failed: {response}")
    return elapsed


def percentiles(samples_s: list[float]) -> tuple[float, float]:
    """Median and 95th percentile in ms."""
    values = np.asarray(samples_s) * 1e3
    return float(np.median(values)), float(np.percentile(values, 95))


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; return 0 when every goal is met."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=500, help="1-pose calls per phase")
    parser.add_argument("--batch-samples", type=int, default=50, help="1000-pose calls")
    parser.add_argument(
        "--node-arg",
        action="append",
        default=[],
        metavar="ARG",
        help="extra --ros-args argument of the node, e.g. --node-arg=-p "
        "--node-arg=recording.enabled:=false",
    )
    parser.add_argument(
        "--domain-id",
        type=int,
        metavar="ID",
        help="DDS domain of the run (default: a free one, picked by domain_coordinator)",
    )
    args = parser.parse_args(argv)
    missing = missing_install()
    if missing:
        print(missing, file=sys.stderr)
        return 2
    with ros_domain(args.domain_id) as domain, tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        node = start_node(folder, args.node_arg)
        floors = [
            start_python(source, folder / "node.log")
            for source in (FLOOR_SERVER, FLAT_FLOOR_SERVER)
        ]
        try:
            return run(args, domain)
        finally:
            stop((node, *floors))


def run(args: argparse.Namespace, domain: int) -> int:
    import rclpy
    from hexapod_workspace_msgs.action import ComputeWorkspace
    from hexapod_workspace_msgs.msg import WorkspaceRequest
    from hexapod_workspace_msgs.srv import CheckPoses, CheckPosesFlat
    from rclpy.action import ActionClient
    from rclpy.executors import SingleThreadedExecutor

    from hexapod_workspace import check, load_manipulator
    from hexapod_workspace._resources import example_config_path

    rclpy.init(domain_id=domain)
    client_node = rclpy.create_node(f"latency_client_{os.getpid()}")
    # The client spins in a thread of its own and calls synchronously, as a controller would
    # (spin_until_future_complete per call adds several ms of client-side overhead in rclpy).
    executor = SingleThreadedExecutor()
    executor.add_node(client_node)
    spinner = threading.Thread(target=executor.spin, name="client-spin", daemon=True)
    spinner.start()
    checks = client_node.create_client(CheckPoses, f"{NODE}/check_poses")
    flat_checks = client_node.create_client(CheckPosesFlat, f"{NODE}/check_poses_flat")
    computes = ActionClient(client_node, ComputeWorkspace, f"{NODE}/compute_workspace")
    floor_checks = client_node.create_client(CheckPoses, FLOOR)
    flat_floor_checks = client_node.create_client(CheckPosesFlat, FLAT_FLOOR)
    try:
        clients = (checks, flat_checks, floor_checks, flat_floor_checks)
        if not all(client.wait_for_service(timeout_sec=60) for client in clients) or not (
            computes.wait_for_server(timeout_sec=60)
        ):
            print("services not discovered within 60 s", file=sys.stderr)
            return 2

        one, batch, angles = check_requests()
        for client in (checks, floor_checks):
            first_answer(client, one)  # a cold numba cache: the node compiles first

        def timed(request: Any, client: Any = checks) -> float:
            return timed_call(client, request)

        for _ in range(50):  # warm-up (discovery of the reply path, first allocations)
            timed(one)
            timed(one, floor_checks)
        idle, reference = [], []
        for _ in range(args.samples):  # interleaved: both see the same machine load
            idle.append(timed(one))
            reference.append(timed(one, floor_checks))
        batched = [timed(batch) for _ in range(args.batch_samples)]
        flat = flat_request(angles)
        for _ in range(10):
            timed(flat, flat_checks)
            timed(flat, flat_floor_checks)
        flat_batched, flat_floor = [], []
        for _ in range(args.batch_samples):  # interleaved with its floor
            flat_batched.append(timed(flat, flat_checks))
            flat_floor.append(timed(flat, flat_floor_checks))
        manipulator = load_manipulator(example_config_path())
        core = []
        for _ in range(args.batch_samples):
            start = time.perf_counter()
            check(manipulator, angles, (0.0, 0.0, -1.3))
            core.append(time.perf_counter() - start)

        # a 3-D orientation workspace, fine enough to take several seconds
        request = WorkspaceRequest(
            kind=WorkspaceRequest.ORIENTATION, n_rays=360, psi_step=0.005, tolerance=1e-7
        )
        request.position.z = -1.3
        goal = computes.send_goal_async(ComputeWorkspace.Goal(request=request))
        while not goal.done():
            time.sleep(0.01)
        long_call = goal.result().get_result_async()
        time.sleep(0.5)  # let the computation start
        loaded: list[float] = []
        while not long_call.done() and len(loaded) < args.samples:
            sample = timed(one)
            if not long_call.done():
                loaded.append(sample)
        computing_start = time.perf_counter()
        deadline = computing_start + 900.0
        while not long_call.done() and time.perf_counter() < deadline:
            time.sleep(0.05)
        remaining = time.perf_counter() - computing_start
        summary = long_call.result().result.summary if long_call.done() else None
    finally:
        executor.shutdown()
        spinner.join(timeout=10)
        client_node.destroy_node()
        rclpy.try_shutdown()

    idle_med, idle_p95 = percentiles(idle)
    floor_med, floor_p95 = percentiles(reference)
    batch_med, batch_p95 = percentiles(batched)
    core_med, _ = percentiles(core)
    flat_med, flat_p95 = percentiles(flat_batched)
    flat_floor_med, flat_floor_p95 = percentiles(flat_floor)
    print(
        f"check_poses, 1 pose, idle:        median {idle_med:7.3f} ms  p95 {idle_p95:7.3f} ms"
        f"  (ratio to the floor {idle_med / floor_med:.2f}x)"
    )
    print(
        f"floor: minimal rclpy server:      median {floor_med:7.3f} ms  p95 {floor_p95:7.3f} ms"
        "  (same service type, single-threaded, no work)"
    )
    print(
        f"check_poses, 1000 poses, idle:    median {batch_med:7.3f} ms  p95 {batch_p95:7.3f} ms"
        f"  (core check in-process {core_med:.3f} ms; ratio {batch_med / core_med:.1f}x)"
    )
    print(
        f"check_poses_flat, 1000 poses:     median {flat_med:7.3f} ms  p95 {flat_p95:7.3f} ms"
        f"  (ratio to the core {flat_med / core_med:.1f}x, goal <= {GOAL_FLAT_CORE_RATIO:g}x; "
        f"to floor + core {flat_med / (floor_med + core_med):.2f}x; "
        f"{batch_med / flat_med:.1f}x faster than nested)"
    )
    print(
        f"floor: flat, 1000 poses, no work: median {flat_floor_med:7.3f} ms  p95 "
        f"{flat_floor_p95:7.3f} ms  (same arrays both ways, prebuilt answer; the node's flat "
        f"call is {flat_med / (flat_floor_med + core_med):.2f}x this floor + the core)"
    )
    goal_ms = GOAL_FLAT_CORE_RATIO * core_med
    if min(floor_med, flat_floor_med) > goal_ms:
        print(
            f"the flat goal ({GOAL_FLAT_CORE_RATIO:g}x the core = {goal_ms:.3f} ms) is below "
            f"the round trip of a server that does nothing ({floor_med:.3f} ms with one pose, "
            f"{flat_floor_med:.3f} ms with the 1000-pose arrays): no rclpy service can meet it "
            "on this machine"
        )
    print(f"load average {'/'.join(f'{v:.2f}' for v in os.getloadavg())} (1, 5, 15 min)")
    ok = idle_med <= GOAL_MS and flat_med <= GOAL_FLAT_CORE_RATIO * core_med
    if loaded:
        load_med, load_p95 = percentiles(loaded)
        print(
            f"check_poses, 1 pose, during 3-D:  median {load_med:7.3f} ms  p95 {load_p95:7.3f} ms"
            f"  ({len(loaded)} calls; ratio to idle {load_med / idle_med:.2f}x)"
        )
        ok = ok and load_med <= GOAL_MS
    else:
        print("check_poses during 3-D: the computation ended before the first check")
    if summary is not None:
        print(
            f"3-D workspace: {summary.message} (success={summary.success}, "
            f"{summary.elapsed:.1f} s in the node; {remaining:.1f} s left after the checks)"
        )
    print(
        f"goals (median <= {GOAL_MS} ms idle and during 3-D; flat 1000 <= "
        f"{GOAL_FLAT_CORE_RATIO:g}x core): {'met' if ok else 'MISSED'}"
    )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
