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

3. the floor of the command stream, under the same load: the same commander, clients and goals
   again, but the commander's stream goes to the cheapest rclpy node that answers each
   ``CommandedPose`` with a prebuilt ``ReachabilityResult`` of the node's size (its own
   process, single-threaded executor, same QoS, taking the commands queued behind one in the
   same callback as the node does): what the machine, rclpy and DDS cost a command at that
   moment, with no check and no recording (``--no-floor`` leaves it out).

Prints the commands published, answered, missing (loss) and refused as overloaded, the
publish-to-result latency percentiles (goal: zero loss, p99 <= 10 ms at 1000/s) and those of the
floor, the clients' call latencies, and the CPU seconds of each process over the loaded phase
(node, its worker, commander, clients). Run it in the ROS environment::

    tools/with_ros_env.sh python benchmarks/ros_load.py [--rate 1000] [--duration 10]
"""

from __future__ import annotations

import argparse
import itertools
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
    first_answer,
    missing_install,
    print_failures,
    ros_domain,
    start_node,
    start_python,
    stop,
)
from ros_latency import (  # same folder
    check_requests,
    floor_server_source,
    server_source,
    timed_call,
)

NODE = "/hexapod_workspace"
FLOOR = "/load_floor/check_poses"
FLOOR_SERVER = floor_server_source(FLOOR, "load_floor")
_ROLE_NUMBERS = itertools.count()
#: Namespace of the command stream's floor (a node that echoes a prebuilt result).
COMMAND_FLOOR = "/load_command_floor"
COMMAND_FLOOR_SERVER = server_source(
    "command_floor",
    f"""
from hexapod_workspace_msgs.msg import CommandedPose, ReachabilityResult
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
# a result of the size the node sends for the example machine (6-UPS, five constraints)
answer = ReachabilityResult(success=True, message="reachable")
answer.header.frame_id = "base"
answer.check.reachable = True
answer.check.constraint_names = [
    "leg_length", "base_joint", "platform_joint", "leg_interference", "singularity"]
answer.check.margins = [0.01, 0.2, 0.3, 0.04, 0.5]
answer.check.limiting_leg = 3
publisher = node.create_publisher(ReachabilityResult, "{COMMAND_FLOOR}/reachability", QoSProfile(
    history=HistoryPolicy.KEEP_LAST, depth=1000, reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL))

def echo(command):  # and those queued behind it, as the node takes them (one executor pass)
    batch = [command]
    with subscription.handle:
        while len(batch) < 256:
            taken = subscription.handle.take_message(CommandedPose, False)
            if taken is None:
                break
            batch.append(taken[0])
    for command in batch:
        answer.request_id = command.request_id
        answer.header.stamp = command.header.stamp
        answer.position, answer.orientation = command.position, command.orientation
        publisher.publish(answer)

subscription = node.create_subscription(
    CommandedPose, "{COMMAND_FLOOR}/commanded_pose", echo,
    QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE))
""",
)
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


def commander(rate: float, duration: float, target: str = NODE) -> dict:
    """Publish CommandedPose at ``rate`` Hz for ``duration`` s to the node ``target`` (its
    namespace and name); time each result."""
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

    node.create_subscription(ReachabilityResult, f"{target}/reachability", on_result, qos)
    publisher = node.create_publisher(CommandedPose, f"{target}/commanded_pose", qos)
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
    answered = ~np.isnan(received)
    latencies = (received - sent)[answered & ~overloaded]
    result = {
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
    return report_and_shut_down(result, executor, node)


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
    first_answer(client, request)
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
    result = {
        "calls": len(samples),
        "failures": failures,
        "reasons": sorted(reasons),
        "latency_ms": percentiles_ms(samples),
        "cpu_s": time.process_time(),
    }
    return report_and_shut_down(result, executor, node)


def report_and_shut_down(result: dict, executor: object, node: object) -> dict:
    """Print a role's ``result`` (its JSON line), then shut rclpy down: a crash while rclpy
    shuts down (seen under load: "terminate called without an active exception") must not
    lose the figures."""
    import rclpy

    print(json.dumps(result), flush=True)
    executor.shutdown()  # type: ignore[attr-defined]
    node.destroy_node()  # type: ignore[attr-defined]
    rclpy.try_shutdown()
    return result


# ----------------------------------------------------------------------------- orchestration


def spawn_role(
    role: str, args: argparse.Namespace, out_dir: Path, target: str = NODE
) -> subprocess.Popen:
    command = [*priority_prefix(args, role), sys.executable, __file__, "--role", role]
    command += ["--target", target]
    command += ["--rate", str(args.rate), "--duration", str(args.duration)]
    errors = out_dir / f"{role}-{next(_ROLE_NUMBERS)}.err"
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=errors.open("wb"), text=True)
    process.errors = errors  # type: ignore[attr-defined]
    return process


def priority_prefix(args: argparse.Namespace, role: str = "node") -> list[str]:
    """``chrt --fifo N`` for the node and the floor that stands in for it (``--priority N``)
    and for the commander (``--commander-priority N``); nothing for the other roles. With
    ``--node-session``, ``setsid`` first for the node and its floor."""
    priority = args.commander_priority if role == "commander" else args.priority
    session = session_prefix(args) if role == "node" else []
    if not priority or role not in ("node", "commander"):
        return session
    return [*session, "chrt", "--fifo", str(priority)]


def session_prefix(args: argparse.Namespace) -> list[str]:
    """``setsid`` for the node and its floor with ``--node-session``, else nothing."""
    return ["setsid"] if args.node_session else []


def role_result(process: subprocess.Popen, timeout: float, required: bool = True) -> dict:
    """What a role process printed (its JSON line). One that printed none: an error with its
    stderr, or (not ``required``: a client, which is only load) a result saying it crashed,
    printed with the run's figures."""
    output = process.communicate(timeout=timeout)[0]
    try:
        return json.loads(output)
    except json.JSONDecodeError:
        errors = process.errors.read_text(errors="replace")  # type: ignore[attr-defined]
        if required:
            raise RuntimeError(f"a load process failed: {output!r}\n{errors[-3000:]}") from None
        crashed = f"CRASHED (exit {process.returncode}): {errors.strip()[-300:]!r}"
        nothing = {"n": 0, "p50": math.nan, "p99": math.nan, "max": math.nan}
        return {"calls": 0, "failures": 0, "reasons": [crashed], "latency_ms": nothing, "cpu_s": 0}


def wait_ready(process: subprocess.Popen) -> None:
    line = process.stdout.readline()
    if not line or not json.loads(line).get("ready"):
        raise RuntimeError(f"a load process did not start: {line!r}")


def idle_phase(samples: int) -> dict:
    """1-pose calls interleaved with the floor, and 1000-pose calls against the core."""
    import rclpy
    from hexapod_workspace_msgs.srv import CheckPoses
    from rclpy.executors import SingleThreadedExecutor

    from hexapod_workspace import check, load_manipulator
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
        for client in (checks, floor):
            first_answer(client, one)  # a cold numba cache: the node compiles first
        timed = timed_call  # timed(client, request)
        for _ in range(30):
            timed(checks, one)
            timed(floor, one)
        node_one, floor_one = [], []
        for _ in range(samples):
            node_one.append(timed(checks, one))
            floor_one.append(timed(floor, one))
        batched = [timed(checks, batch) for _ in range(max(10, samples // 10))]
        manipulator = load_manipulator(example_config_path())
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
        self.node = rclpy.create_node(f"load_compute_{os.getpid()}_{next(_ROLE_NUMBERS)}")
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


def loaded_phase(
    args: argparse.Namespace, node: subprocess.Popen, out_dir: Path, target: str = NODE
) -> dict:
    """The commander's stream to ``target`` while the clients call the node's check_poses and
    3-D goals compute in the node; what each process measured and the CPU split."""
    computations = Computations(args.compute_every)
    computations.start()
    time.sleep(1.0)  # the first computation is under way
    roles = [spawn_role("checker", args, out_dir) for _ in range(args.clients)]
    for process in roles:
        wait_ready(process)
    commander_process = spawn_role("commander", args, out_dir, target)
    wait_ready(commander_process)
    pids = {"node": [node.pid], "worker": children(node.pid)}
    before = {k: sum(cpu_seconds(p) for p in v) for k, v in pids.items()}
    load_before = os.getloadavg()[0]
    start = time.perf_counter()
    command = role_result(commander_process, args.duration + 120)
    elapsed = time.perf_counter() - start
    after = {k: sum(cpu_seconds(p) for p in v) for k, v in pids.items()}
    clients = [role_result(p, args.duration + 120, required=False) for p in roles]
    computations.close()
    # the roles report their own CPU time (whole life, setup included)
    before["commander"], after["commander"] = 0.0, command["cpu_s"]
    before["clients"], after["clients"] = 0.0, sum(c["cpu_s"] for c in clients)
    return {
        "command": command,
        "clients": clients,
        "computations": computations,
        "elapsed": elapsed,
        "cpu": {k: after[k] - before[k] for k in after},
        "load": (load_before, os.getloadavg()[0]),
    }


def run(args: argparse.Namespace, node: subprocess.Popen, out_dir: Path) -> int:
    import rclpy

    load_before = os.getloadavg()
    rclpy.init()
    try:
        idle = idle_phase(args.samples)
        loaded = loaded_phase(args, node, out_dir)
        floored = loaded_phase(args, node, out_dir, COMMAND_FLOOR) if args.floor else None
    finally:
        rclpy.try_shutdown()
    command, clients = loaded["command"], loaded["clients"]
    computations, elapsed = loaded["computations"], loaded["elapsed"]
    if args.timeline is not None:
        timeline = {
            "sent": command.pop("sent"),
            "latency": command.pop("latency"),
            "goal_results": computations.finished_at,
        }
        if floored is not None:
            timeline["floor_sent"] = floored["command"].pop("sent")
            timeline["floor_latency"] = floored["command"].pop("latency")
        args.timeline.write_text(json.dumps(timeline))

    one, floor, batch, core = idle["one"], idle["floor"], idle["batch"], idle["core"]
    print(f"node: {describe_node(args.node_source)}")
    if args.node_arg or args.node_option:
        print(f"node arguments: {' '.join([*args.node_option, *args.node_arg])}")
    if args.priority or args.commander_priority:
        print(
            f"SCHED_FIFO priority: node and floor {args.priority or 'none'}, commander "
            f"{args.commander_priority or 'none'} (0/none: normal scheduling)"
        )
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
    cpu = loaded["cpu"]
    split = ", ".join(f"{k} {v:.2f} s ({100 * v / elapsed:.0f}% core)" for k, v in cpu.items())
    print(f"CPU over {elapsed:.1f} s (2 cores = 200%): {split}; total {sum(cpu.values()):.2f} s")
    if floored is not None:
        floor_command = floored["command"]
        floor_latency = floor_command["latency_ms"]
        print(
            f"floor (the same load, the commands answered by a node that echoes a prebuilt "
            f"result; {floored['computations'].done} goals finished, load average "
            f"{floored['load'][0]:.2f}-{floored['load'][1]:.2f}): answered "
            f"{floor_command['answered']}, missing {floor_command['missing']}; publish -> "
            f"result p50 {floor_latency['p50']:.3f} ms  p99 {floor_latency['p99']:.3f} ms  "
            f"max {floor_latency['max']:.3f} ms"
        )
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
    parser.add_argument("--target", default=NODE, help=argparse.SUPPRESS)
    parser.add_argument(
        "--priority",
        type=int,
        default=0,
        metavar="N",
        help="run the node (its --realtime-priority=N; chrt for --node-source) and the "
        "command stream's floor with the real-time policy SCHED_FIFO at priority N: the node "
        "scheduled ahead of every other job on the machine; its worker runs at normal "
        "priority all the same (default 0: normal scheduling)",
    )
    parser.add_argument(
        "--node-session",
        action="store_true",
        help="start the node (and the command stream's floor) in a session of its own "
        "(setsid), as a node started by its own launch or service is: Linux's autogroup then "
        "shares the cores between that session and the benchmark's clients first, and the "
        "node's worker competes only with the node",
    )
    parser.add_argument(
        "--commander-priority",
        type=int,
        default=0,
        metavar="N",
        help="run the commander (the controller) under SCHED_FIFO at priority N (chrt)",
    )
    parser.add_argument(
        "--no-floor",
        dest="floor",
        action="store_false",
        help="leave out the command stream's floor (the same load with the commands answered "
        "by a node that echoes a prebuilt result)",
    )
    parser.add_argument(
        "--node-arg", action="append", default=[], metavar="ARG", help="extra --ros-args"
    )
    parser.add_argument(
        "--node-option",
        action="append",
        default=[],
        metavar="OPTION",
        help="the node's own option, before --ros-args (e.g. --node-option=--worker-scheduling="
        "idle: the worker under SCHED_IDLE instead of niceness 5)",
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
    if args.role == "commander":  # each role prints its figures itself
        commander(args.rate, args.duration, args.target)
        return 0
    if args.role == "checker":
        checker(args.duration + 2.0)
        return 0
    missing = missing_install()
    if missing:
        print(missing, file=sys.stderr)
        return 2
    with ros_domain(args.domain_id), tempfile.TemporaryDirectory() as tmp:
        out_dir = Path(tmp)
        prefix = priority_prefix(args)
        if args.node_source is None and args.priority:  # the node's own option
            options = [f"--realtime-priority={args.priority}", *args.node_option]
            node = start_node(out_dir, args.node_arg, prefix=session_prefix(args), options=options)
        else:  # another tree's node (which may not have the option): the same through chrt
            node = start_node(
                out_dir, args.node_arg, args.node_source, prefix=prefix, options=args.node_option
            )
        floors = [start_python(FLOOR_SERVER, out_dir / "node.log")]
        if args.floor:
            floors.append(start_python(COMMAND_FLOOR_SERVER, out_dir / "node.log", prefix))
        try:
            return run(args, node, out_dir)
        finally:
            stop((node, *floors))
            if print_failures([out_dir / "node.log"]):
                print("the node's log has a traceback (above): these figures are not valid")


if __name__ == "__main__":
    sys.exit(main())
