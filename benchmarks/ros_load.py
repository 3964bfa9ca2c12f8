"""The node under a real command stream: loss, latency and CPU at a commanded rate.

Starts workspace_node from the colcon install space (``make ros``) in a DDS domain of its own
(ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST) and drives it the way a machining cell would:

1. idle, interleaved: ``check_poses`` with 1 pose against the floor (the cheapest rclpy server
   of the same service type, single-threaded, constant answer, its own process), and with 1000
   poses against the core's ``check`` in this process (goals: <= 1.3x and <= 3x);
2. under load: one commander process publishes ``CommandedPose`` at ``--rate`` Hz for
   ``--duration`` s (reliable, KEEP_ALL, what docs/ros.md asks of a publisher) and receives
   the ``ReachabilityResult`` of each; ``--clients`` processes call ``check_poses`` (1 pose)
   back to back; this process keeps a 3-D orientation workspace computing (the
   ``~/compute_workspace`` action, or the old service when the node has no action).

Prints the commands published, answered, missing (loss) and refused as overloaded, the
publish-to-result latency percentiles (goal: zero loss, p99 <= 10 ms at 1000/s), the clients'
call latencies, and the CPU seconds of each process over the loaded phase (node, its worker,
commander, clients). Run it in the ROS environment::

    tools/with_ros_env.sh python benchmarks/ros_load.py [--rate 1000] [--duration 10]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from _node import (
    describe_node,
    missing_install,
    print_failures,
    ros_domain,
    start_node,
    start_python,
    stop,
)
from ros_latency import check_requests, floor_server_source, timed_call  # same folder

NODE = "/hexapod_workspace"
FLOOR = "/load_floor/check_poses"
FLOOR_SERVER = floor_server_source(FLOOR, "load_floor")
#: The node's goals under load (zero loss, latency, check_poses against the floor).
GOAL_P99_MS = 10.0
GOAL_FLOOR_RATIO = 1.3
GOAL_CORE_RATIO = 3.0


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process (and of its reaped children), s, from /proc."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return math.nan
    ticks = os.sysconf("SC_CLK_TCK")
    return sum(int(value) for value in fields[11:13]) / ticks


def children(pid: int) -> list[int]:
    pids: list[int] = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        pids += [int(p) for p in (task / "children").read_text().split()]
    return pids


def percentiles_ms(samples_s: list[float] | np.ndarray) -> dict[str, float]:
    values = np.asarray(samples_s, dtype=float) * 1e3
    if values.size == 0:
        return {"n": 0, "p50": math.nan, "p99": math.nan, "max": math.nan}
    return {
        "n": int(values.size),
        "p50": float(np.percentile(values, 50)),
        "p99": float(np.percentile(values, 99)),
        "max": float(values.max()),
    }


# ----------------------------------------------------------------------------- roles


def commander(rate: float, duration: float) -> dict:
    """Publish CommandedPose at ``rate`` Hz for ``duration`` s; time each result."""
    import rclpy
    from hexapod_workspace_msgs.msg import CommandedPose, ReachabilityResult, TiltTorsion
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

    rclpy.init()
    node = rclpy.create_node(f"load_commander_{os.getpid()}")
    qos = QoSProfile(
        history=HistoryPolicy.KEEP_ALL, depth=1, reliability=ReliabilityPolicy.RELIABLE
    )
    count = int(rate * duration)
    sent = np.full(count, np.nan)
    received = np.full(count, np.nan)
    overloaded = np.zeros(count, dtype=bool)
    duplicates = [0]
    prefix = f"c{os.getpid()}-"

    def on_result(message: ReachabilityResult) -> None:
        now = time.perf_counter()
        if not message.request_id.startswith(prefix):
            return
        index = int(message.request_id[len(prefix) :])
        if not math.isnan(received[index]):
            duplicates[0] += 1
        received[index] = now
        overloaded[index] = not message.success and "overloaded" in message.message

    node.create_subscription(ReachabilityResult, f"{NODE}/reachability", on_result, qos)
    publisher = node.create_publisher(CommandedPose, f"{NODE}/commanded_pose", qos)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    deadline = time.monotonic() + 60
    while publisher.get_subscription_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(1.0)  # the node's reachability writer must have matched our reader too
    rng = np.random.default_rng(7)
    angles = np.column_stack(
        (
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(0.0, 0.6, count),
            rng.uniform(-0.3, 0.3, count),
        )
    ).tolist()
    messages = []
    for index, (phi, theta, psi) in enumerate(angles):
        message = CommandedPose(request_id=f"{prefix}{index}")
        message.orientation = TiltTorsion(phi=phi, theta=theta, psi=psi)
        message.position.z = -1.3
        messages.append(message)
    print(json.dumps({"ready": True}), flush=True)
    clock = node.get_clock()
    start = time.perf_counter()
    for index, message in enumerate(messages):
        target = start + index / rate
        pause = target - time.perf_counter()
        if pause > 0:
            time.sleep(pause)
        sent[index] = time.perf_counter()
        message.header.stamp = clock.now().to_msg()  # the node answers stale ones "overloaded"
        publisher.publish(message)
    publish_span = time.perf_counter() - start
    wait_until = time.monotonic() + 10.0
    last = (-1, time.monotonic())
    while np.isnan(received).any() and time.monotonic() < wait_until:
        time.sleep(0.05)
        answered_now = int((~np.isnan(received)).sum())
        if answered_now != last[0]:
            last = (answered_now, time.monotonic())
        elif time.monotonic() - last[1] > 2.0:  # nothing more is coming
            break
    cpu = time.process_time()
    executor.shutdown()
    node.destroy_node()
    rclpy.try_shutdown()
    answered = ~np.isnan(received)
    latencies = (received - sent)[answered & ~overloaded]
    return {
        "published": count,
        "publish_rate": count / publish_span,
        "answered": int(answered.sum()),
        "missing": int((~answered).sum()),
        "overloaded": int(overloaded.sum()),
        "duplicates": duplicates[0],
        "latency_ms": percentiles_ms(latencies),
        "cpu_s": cpu,
        # the timeline (CLOCK_MONOTONIC, shared by the processes): send time, latency (NaN:
        # missing or overloaded)
        "sent": sent.tolist(),
        "latency": np.where(answered & ~overloaded, received - sent, np.nan).tolist(),
    }


def checker(duration: float) -> dict:
    """Call check_poses (1 pose) back to back for ``duration`` s."""
    import rclpy
    from hexapod_workspace_msgs.msg import TiltTorsion
    from hexapod_workspace_msgs.srv import CheckPoses
    from rclpy.executors import SingleThreadedExecutor

    rclpy.init()
    node = rclpy.create_node(f"load_checker_{os.getpid()}")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    client = node.create_client(CheckPoses, f"{NODE}/check_poses")
    client.wait_for_service(timeout_sec=60)
    request = CheckPoses.Request(orientations=[TiltTorsion(phi=0.3, theta=0.2, psi=0.1)])
    request.position.z = -1.3
    for _ in range(20):
        client.call(request, timeout_sec=30)
    print(json.dumps({"ready": True}), flush=True)
    samples, failures, reasons = [], 0, set()
    end = time.perf_counter() + duration
    while time.perf_counter() < end:
        start = time.perf_counter()
        response = client.call(request, timeout_sec=30)
        samples.append(time.perf_counter() - start)
        if response is None or not response.success:
            failures += 1
            reasons.add("no answer in 30 s" if response is None else response.message)
    cpu = time.process_time()
    executor.shutdown()
    node.destroy_node()
    rclpy.try_shutdown()
    return {
        "calls": len(samples),
        "failures": failures,
        "reasons": sorted(reasons),
        "latency_ms": percentiles_ms(samples),
        "cpu_s": cpu,
    }


# ----------------------------------------------------------------------------- orchestration


def spawn_role(role: str, args: argparse.Namespace, out_dir: Path) -> subprocess.Popen:
    command = [sys.executable, __file__, "--role", role]
    command += ["--rate", str(args.rate), "--duration", str(args.duration)]
    return subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=(out_dir / f"{role}.err").open("wb"), text=True
    )


def wait_ready(process: subprocess.Popen) -> None:
    line = process.stdout.readline()
    if not line or not json.loads(line).get("ready"):
        raise RuntimeError(f"a load process did not start: {line!r}")


def idle_phase(samples: int) -> dict:
    """1-pose calls interleaved with the floor, and 1000-pose calls against the core."""
    import rclpy
    from hexapod_workspace_msgs.srv import CheckPoses
    from rclpy.executors import SingleThreadedExecutor

    from hexapod_workspace import Manipulator, check
    from hexapod_workspace._resources import example_config_path

    node = rclpy.create_node(f"load_idle_{os.getpid()}")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    checks = node.create_client(CheckPoses, f"{NODE}/check_poses")
    floor = node.create_client(CheckPoses, FLOOR)
    try:
        for client in (checks, floor):
            if not client.wait_for_service(timeout_sec=60):
                raise RuntimeError("services not discovered within 60 s")

        one, batch, angles = check_requests()
        timed = timed_call  # timed(client, request)
        for _ in range(30):
            timed(checks, one)
            timed(floor, one)
        node_one, floor_one = [], []
        for _ in range(samples):
            node_one.append(timed(checks, one))
            floor_one.append(timed(floor, one))
        batched = [timed(checks, batch) for _ in range(max(10, samples // 10))]
        manipulator = Manipulator.from_params_file(example_config_path())
        core = []
        for _ in range(len(batched)):
            start = time.perf_counter()
            check(manipulator, angles, (0.0, 0.0, -1.3))
            core.append(time.perf_counter() - start)
    finally:
        executor.shutdown()
        spinner.join(timeout=10)
        node.destroy_node()
    return {
        "one": percentiles_ms(node_one),
        "floor": percentiles_ms(floor_one),
        "batch": percentiles_ms(batched),
        "core": percentiles_ms(core),
    }


class Computations:
    """Keeps a 3-D orientation workspace computing in the node (action, or the old service)."""

    def __init__(self, every: float = 0.0) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        self.every = every  # s between goal starts (0: back to back)
        self.node = rclpy.create_node(f"load_compute_{os.getpid()}")
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.spinner = threading.Thread(target=self.executor.spin, daemon=True)
        self.spinner.start()
        self.stop = threading.Event()
        self.done = 0
        self.finished_at: list[float] = []  # time.perf_counter() of each result
        self.failures: list[str] = []  # messages of the goals that did not succeed
        self.lost_goals = 0  # goals sent again after 5 s without an answer
        self.kind = ""
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _request(self):
        from hexapod_workspace_msgs.msg import WorkspaceRequest

        request = WorkspaceRequest(
            kind=WorkspaceRequest.ORIENTATION, n_rays=360, psi_step=0.005, tolerance=1e-7
        )
        request.position.z = -1.3
        return request

    def start(self) -> None:
        try:
            from hexapod_workspace_msgs.action import ComputeWorkspace
            from rclpy.action import ActionClient

            client = ActionClient(self.node, ComputeWorkspace, f"{NODE}/compute_workspace")
            if client.wait_for_server(timeout_sec=10):
                self.kind, self.client = "action", client
                time.sleep(1.0)  # the server's answer writers must have matched our readers
        except ImportError:
            pass
        if not self.kind:
            from hexapod_workspace_msgs.srv import ComputeWorkspace

            self.client = self.node.create_client(ComputeWorkspace, f"{NODE}/compute_workspace")
            self.client.wait_for_service(timeout_sec=60)
            self.kind = "service"
        self.thread.start()

    def _run(self) -> None:
        while not self.stop.is_set():
            started = time.monotonic()
            if self.kind == "action":
                from hexapod_workspace_msgs.action import ComputeWorkspace

                goal = ComputeWorkspace.Goal(request=self._request())
                handle_future = self.client.send_goal_async(goal)
                sent = time.monotonic()
                while not handle_future.done():
                    if time.monotonic() - sent > 5.0:
                        # discovery race: the goal (or its answer) was lost; ask again
                        self.lost_goals += 1
                        handle_future = self.client.send_goal_async(goal)
                        sent = time.monotonic()
                    time.sleep(0.01)
                handle = handle_future.result()
                result_future = handle.get_result_async()
                while not result_future.done():
                    if self.stop.is_set():
                        cancel = handle.cancel_goal_async()
                        while not cancel.done():
                            time.sleep(0.01)
                        self.stop.clear()  # wait for the canceled result
                        self.stop_after = True
                    time.sleep(0.01)
                if getattr(self, "stop_after", False):
                    return
                result = result_future.result().result
                if not result.summary.success:
                    self.failures.append(result.summary.message)
            else:
                from hexapod_workspace_msgs.srv import ComputeWorkspace

                future = self.client.call_async(ComputeWorkspace.Request(request=self._request()))
                while not future.done():
                    time.sleep(0.01)
            self.done += 1
            self.finished_at.append(time.perf_counter())
            self.stop.wait(max(0.0, self.every - (time.monotonic() - started)))

    def close(self) -> None:
        self.stop.set()
        # the action is canceled and its result awaited; the old service cannot be canceled
        self.thread.join(timeout=30 if self.kind == "action" else 0.1)
        self.executor.shutdown()
        self.node.destroy_node()


def run(args: argparse.Namespace, node: subprocess.Popen, out_dir: Path) -> int:
    import rclpy

    load_before = os.getloadavg()
    rclpy.init()
    try:
        idle = idle_phase(args.samples)
        computations = Computations(args.compute_every)
        computations.start()
        time.sleep(1.0)  # the first computation is under way
        roles = [spawn_role("checker", args, out_dir) for _ in range(args.clients)]
        for process in roles:
            wait_ready(process)
        commander_process = spawn_role("commander", args, out_dir)
        wait_ready(commander_process)
        pids = {"node": [node.pid], "worker": children(node.pid)}
        before = {k: sum(cpu_seconds(p) for p in v) for k, v in pids.items()}
        start = time.perf_counter()
        command = json.loads(commander_process.communicate(timeout=args.duration + 120)[0])
        elapsed = time.perf_counter() - start
        after = {k: sum(cpu_seconds(p) for p in v) for k, v in pids.items()}
        clients = [json.loads(p.communicate(timeout=args.duration + 120)[0]) for p in roles]
        computations.close()
        if args.timeline is not None:
            args.timeline.write_text(
                json.dumps(
                    {
                        "sent": command.pop("sent"),
                        "latency": command.pop("latency"),
                        "goal_results": computations.finished_at,
                    }
                )
            )
        # the roles report their own CPU time (whole life, setup included)
        before["commander"], after["commander"] = 0.0, command["cpu_s"]
        before["clients"], after["clients"] = 0.0, sum(c["cpu_s"] for c in clients)
    finally:
        rclpy.try_shutdown()

    one, floor, batch, core = idle["one"], idle["floor"], idle["batch"], idle["core"]
    print(f"node: {describe_node(args.node_source)}")
    if args.node_arg:
        print(f"node arguments: {' '.join(args.node_arg)}")
    floor_ratio = one["p50"] / floor["p50"]
    core_ratio = batch["p50"] / core["p50"]
    latency = command["latency_ms"]
    print(f"idle: check_poses 1 pose   p50 {one['p50']:7.3f} ms  p99 {one['p99']:7.3f} ms")
    print(f"idle: floor server         p50 {floor['p50']:7.3f} ms  p99 {floor['p99']:7.3f} ms")
    print(
        f"idle: ratio to the floor   {floor_ratio:.2f}x   (goal <= {GOAL_FLOOR_RATIO}x)"
        f"\nidle: check_poses 1000     p50 {batch['p50']:7.3f} ms; core {core['p50']:.3f} ms;"
        f" ratio {core_ratio:.2f}x (goal <= {GOAL_CORE_RATIO}x)"
    )
    print(
        f"load: {args.clients} check_poses clients, 3-D computations ({computations.kind}, "
        f"{computations.done} finished, {len(computations.failures)} failed, "
        f"{computations.lost_goals} sent again, every "
        f"{args.compute_every:g} s), commands at "
        f"{args.rate:g}/s for {args.duration:g} s"
    )
    print(
        f"commands: published {command['published']} (at {command['publish_rate']:.0f}/s), "
        f"answered {command['answered']}, missing {command['missing']}, "
        f"overloaded {command['overloaded']}, duplicates {command['duplicates']}"
    )
    print(
        f"publish -> result: p50 {latency['p50']:.3f} ms  p99 {latency['p99']:.3f} ms  "
        f"max {latency['max']:.3f} ms  (goal p99 <= {GOAL_P99_MS} ms)"
    )
    for index, client in enumerate(clients):
        lat = client["latency_ms"]
        print(
            f"client {index}: {client['calls']} check_poses calls ({client['failures']} failed), "
            f"p50 {lat['p50']:.3f} ms  p99 {lat['p99']:.3f} ms"
            + "".join(f"\n  failed: {reason}" for reason in client["reasons"])
        )
    total = sum(after[k] - before[k] for k in after)
    split = ", ".join(
        f"{k} {after[k] - before[k]:.2f} s ({100 * (after[k] - before[k]) / elapsed:.0f}% core)"
        for k in after
    )
    print(f"CPU over {elapsed:.1f} s (2 cores = 200%): {split}; total {total:.2f} s")
    ok = (
        command["missing"] == 0
        and command["overloaded"] == 0
        and latency["p99"] <= GOAL_P99_MS
        and floor_ratio <= GOAL_FLOOR_RATIO
        and core_ratio <= GOAL_CORE_RATIO
    )
    load_after = os.getloadavg()
    print(
        "load average (1, 5, 15 min; other jobs on the machine included): before "
        + "/".join(f"{v:.2f}" for v in load_before)
        + ", after "
        + "/".join(f"{v:.2f}" for v in load_after)
    )
    for message in sorted(set(computations.failures)):
        print(f"failed goal: {message}")
    print(f"goals: {'met' if ok else 'MISSED'}")
    return 0 if ok else 1


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark (or one of its client roles); return 0 when every goal is met."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=float, default=1000.0, help="commanded poses per second")
    parser.add_argument("--duration", type=float, default=10.0, help="seconds of commands")
    parser.add_argument("--clients", type=int, default=2, help="check_poses client processes")
    parser.add_argument("--samples", type=int, default=300, help="idle 1-pose calls")
    parser.add_argument(
        "--compute-every",
        type=float,
        default=0.0,
        metavar="S",
        help="start a 3-D workspace goal every S s (default 0: back to back; each publishes and "
        "records its 274k-point cloud)",
    )
    parser.add_argument("--role", choices=("commander", "checker"), help=argparse.SUPPRESS)
    parser.add_argument(
        "--node-arg", action="append", default=[], metavar="ARG", help="extra --ros-args"
    )
    parser.add_argument(
        "--node-source",
        type=Path,
        metavar="DIR",
        help="run the node of another source tree (a checkout, or `git archive` of a whole "
        "commit: the node reads config/ and msg_defs/ beside the package) instead of the "
        "install space's, for a before/after comparison in the same conditions",
    )
    parser.add_argument(
        "--timeline",
        type=Path,
        metavar="JSON",
        help="write each command's send time and latency and each goal's result time (s, "
        "CLOCK_MONOTONIC) to this file",
    )
    parser.add_argument(
        "--domain-id",
        type=int,
        metavar="ID",
        help="DDS domain of the run (default: a free one, picked by domain_coordinator)",
    )
    args = parser.parse_args(argv)
    if args.role == "commander":
        print(json.dumps(commander(args.rate, args.duration)), flush=True)
        return 0
    if args.role == "checker":
        print(json.dumps(checker(args.duration + 2.0)), flush=True)
        return 0
    missing = missing_install()
    if missing:
        print(missing, file=sys.stderr)
        return 2
    with ros_domain(args.domain_id), tempfile.TemporaryDirectory() as tmp:
        out_dir = Path(tmp)
        node = start_node(out_dir, args.node_arg, args.node_source)
        floor = start_python(FLOOR_SERVER, out_dir / "node.log")
        try:
            return run(args, node, out_dir)
        finally:
            stop((node, floor))
            if print_failures([out_dir / "node.log"]):
                print("the node's log has a traceback (above): these figures are not valid")


if __name__ == "__main__":
    sys.exit(main())
