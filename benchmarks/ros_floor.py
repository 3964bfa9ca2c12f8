"""Where a do-nothing rclpy service round trip goes: wall time, client and server CPU per call,
(de)serialisation, and the operating system's own floor.

The floor of ``benchmarks/ros_latency.py`` (a server answering a prebuilt answer) bounds what
any rclpy service can do on this machine. This splits it: a client in this process (its
executor spinning in a thread, calling synchronously, as ``ros_latency.py`` does) calls a
do-nothing ``CheckPoses`` server (1 pose) and a do-nothing ``CheckPosesFlat`` server (1000
poses: 24 kB in, 45 kB out) in another process, and prints per call the median and 95th
percentile wall time and the CPU time each process spent (client: ``time.process_time``,
server: ``/proc``); then rclpy's in-process (de)serialisation of the flat messages, and a byte
bounced through two pipes between two Python processes (what the operating system needs to
wake another process). Fast DDS settings are taken from the environment, e.g.
``RMW_FASTRTPS_PUBLICATION_MODE=ASYNCHRONOUS`` or ``FASTRTPS_DEFAULT_PROFILES_FILE=profile.xml``.

``--executor events`` spins the server (``--client-executor events`` the client) with rclpy's
C++ ``rclpy.experimental.EventsExecutor`` instead (each call then has a 3 s timeout; a server
that does not answer is reported, not waited for)::

    tools/with_ros_env.sh python benchmarks/ros_floor.py [--calls 400] [--executor events]
        [--client-executor events]
"""

from __future__ import annotations

import argparse
import array
import os
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from _node import missing_install, ros_domain, start_python, stop  # same folder
from ros_latency import flat_floor_server_source

FLAT = "/floor_split/check_poses_flat"
ONE = "/floor_split/check_poses"
_PONG = """
import os, sys
r, w = int(sys.argv[1]), int(sys.argv[2])
while (b := os.read(r, 1)):
    os.write(w, b)
"""


def servers_source(executor: str) -> str:
    """Both do-nothing servers in one node, spun by ``executor`` (single or events)."""
    source = flat_floor_server_source(FLAT, "floor_split")
    source = source.replace(
        "node.create_service(CheckPosesFlat",
        "from hexapod_workspace_msgs.srv import CheckPoses\n"
        f'node.create_service(CheckPoses, "{ONE}", lambda request, response: '
        'CheckPoses.Response(success=True, message="1/1 reachable"))\n'
        "node.create_service(CheckPosesFlat",
    )
    if executor == "events":
        source = source.replace(
            "executor = SingleThreadedExecutor()",
            "from rclpy.experimental import EventsExecutor\nexecutor = EventsExecutor()",
        )
    return source


def process_cpu(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` (all its threads), from /proc."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def pipe_round_trip(count: int = 2000) -> np.ndarray:
    """Seconds of each byte's round trip through two pipes to another Python process."""
    to_child, from_parent = os.pipe()
    from_child, to_parent = os.pipe()
    child = subprocess.Popen(
        [sys.executable, "-c", _PONG, str(to_child), str(to_parent)],
        pass_fds=(to_child, to_parent),
    )
    samples = []
    for index in range(count + 100):
        start = time.perf_counter()
        os.write(from_parent, b"x")
        os.read(from_child, 1)
        if index >= 100:
            samples.append(time.perf_counter() - start)
    os.close(from_parent)
    child.wait(timeout=10)
    return np.asarray(samples)


def serialisation_us() -> dict[str, float]:
    """Median µs of rclpy's (de)serialisation of the flat request and answer, in-process."""
    from hexapod_workspace_msgs.srv import CheckPosesFlat
    from rclpy.serialization import deserialize_message, serialize_message

    request, answer = flat_messages()
    request_bytes, answer_bytes = serialize_message(request), serialize_message(answer)

    def median_us(function: Callable[[], object]) -> float:
        samples = []
        for _ in range(300):
            start = time.perf_counter()
            function()
            samples.append(time.perf_counter() - start)
        return float(np.median(samples[20:])) * 1e6

    return {
        f"serialise the request ({len(request_bytes)} B, client)": median_us(
            lambda: serialize_message(request)
        ),
        "deserialise the request (server)": median_us(
            lambda: deserialize_message(request_bytes, CheckPosesFlat.Request)
        ),
        f"serialise the answer ({len(answer_bytes)} B, server)": median_us(
            lambda: serialize_message(answer)
        ),
        "deserialise the answer (client)": median_us(
            lambda: deserialize_message(answer_bytes, CheckPosesFlat.Response)
        ),
    }


def flat_messages() -> tuple[Any, Any]:
    """A 1000-pose CheckPosesFlat request and an answer of the node's size."""
    from hexapod_workspace_msgs.srv import CheckPosesFlat

    request = CheckPosesFlat.Request()
    request.angles = array.array("d", np.random.default_rng(1).uniform(0, 0.5, 3000).tolist())
    request.position.z = -1.3
    answer = CheckPosesFlat.Response(success=True, message="1000/1000 reachable")
    answer.constraint_names = ["leg_length", "base_joint", "platform_joint", "a", "b"]
    answer.margins = array.array("d", [0.5]) * 5000
    answer.reachable = [True] * 1000
    answer.limiting_leg = array.array("i", [0]) * 1000
    return request, answer


class Printed(list):
    """Lines printed as they are appended (a run that hangs later keeps them)."""

    def append(self, line: str) -> None:
        print(f"  {line}", flush=True)
        super().append(line)


def run(args: argparse.Namespace, server: subprocess.Popen) -> int:
    import rclpy
    from hexapod_workspace_msgs.msg import TiltTorsion
    from hexapod_workspace_msgs.srv import CheckPoses, CheckPosesFlat
    from rclpy.executors import SingleThreadedExecutor

    rclpy.init()
    node = rclpy.create_node(f"floor_split_client_{os.getpid()}")
    if args.client_executor == "events":
        from rclpy.experimental import EventsExecutor

        executor = EventsExecutor()
    else:
        executor = SingleThreadedExecutor()
    # the clients exist before the executor spins (rclpy 7.1.6's EventsExecutor deadlocks in
    # create_client while another thread spins it)
    one = CheckPoses.Request(orientations=[TiltTorsion(phi=0.3, theta=0.2, psi=0.1)])
    flat, _ = flat_messages()
    calls = [
        ("CheckPoses, 1 pose", node.create_client(CheckPoses, ONE), one),
        ("CheckPosesFlat, 1000 poses", node.create_client(CheckPosesFlat, FLAT), flat),
    ]
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    timeout = 3.0 if "events" in (args.executor, args.client_executor) else 30.0
    settings = {k: v for k, v in os.environ.items() if k.startswith(("RMW_", "FASTRTPS_"))}
    print(
        f"executor: server {args.executor}, client {args.client_executor}; Fast DDS settings "
        f"from the environment: {settings or '-'}"
    )
    print(f"do-nothing round trips, {args.calls} calls each (client in this process):")
    lines = Printed()
    try:
        for name, client, request in calls:
            if not client.wait_for_service(timeout_sec=60):
                lines.append(f"{name}: service not discovered within 60 s")
                continue
            if any(client.call(request, timeout_sec=timeout) is None for _ in range(50)):
                lines.append(f"{name}: a warm-up call had no answer within {timeout:g} s")
                continue
            client_cpu, server_cpu = time.process_time(), process_cpu(server.pid)
            samples = []
            for _ in range(args.calls):
                start = time.perf_counter()
                answer = client.call(request, timeout_sec=timeout)
                samples.append(time.perf_counter() - start)
                if answer is None:
                    raise RuntimeError(f"{name}: no answer within {timeout:g} s")
            client_cpu = (time.process_time() - client_cpu) / args.calls
            server_cpu = (process_cpu(server.pid) - server_cpu) / args.calls
            values = np.asarray(samples) * 1e3
            lines.append(
                f"{name}: median {np.median(values):.3f} ms  p95 "
                f"{np.percentile(values, 95):.3f} ms; CPU per call: client "
                f"{client_cpu * 1e3:.3f} ms, server {server_cpu * 1e3:.3f} ms"
            )
    finally:
        if args.client_executor == "events":  # its shutdown() hung here: end the context first
            rclpy.try_shutdown()
            spinner.join(timeout=5.0)
        else:
            executor.shutdown()
            node.destroy_node()
            rclpy.try_shutdown()
    print("rclpy (de)serialisation in-process, median:")
    for what, value in serialisation_us().items():
        print(f"  {what}: {value:.1f} us")
    pipe = pipe_round_trip() * 1e3
    print(
        f"a byte through two pipes to another process and back: median {np.median(pipe):.3f} "
        f"ms  p95 {np.percentile(pipe, 95):.3f} ms"
    )
    print(f"load average {'/'.join(f'{v:.2f}' for v in os.getloadavg())} (1, 5, 15 min)")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Run the measurement; 0 when every call was answered."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=400, help="timed calls per service")
    parser.add_argument(
        "--executor", choices=("single", "events"), default="single", help="the server's"
    )
    parser.add_argument(
        "--client-executor", choices=("single", "events"), default="single", help="the client's"
    )
    parser.add_argument("--domain-id", type=int, metavar="ID", help="DDS domain of the run")
    args = parser.parse_args(argv)
    missing = missing_install()
    if missing:
        print(missing, file=sys.stderr)
        return 2
    with ros_domain(args.domain_id), tempfile.TemporaryDirectory() as tmp:
        server = start_python(servers_source(args.executor), Path(tmp) / "server.log")
        try:
            return run(args, server)
        finally:
            stop([server], timeout=5.0)


if __name__ == "__main__":
    sys.exit(main())
