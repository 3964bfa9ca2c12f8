"""Starting and stopping the node for the ROS benchmarks (shared by ``ros_*.py``).

Every benchmark runs ``workspace_node`` from the colcon install space (``make ros``), or with
``--node-source DIR`` the node of another source tree (a ``git archive`` of an older commit),
for a before/after comparison in the same minutes on the same machine. The node runs in a
DDS domain of the benchmark's own, on loopback only, in a folder of its own (its recording goes
there), and is stopped with SIGINT (then SIGKILL after 30 s).
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
NODE_EXECUTABLE = (
    REPO / "install" / "hexapod_workspace" / "lib" / "hexapod_workspace" / "workspace_node"
)
#: The parameter file every benchmark node reads.
PARAMS_FILE = REPO / "config" / "example_gpm.yaml"
#: How a node of another source tree is started: ``python -c`` puts the working directory
#: first on sys.path, before PYTHONPATH, so the node runs in its own folder, not this checkout.
_FROM_SOURCE = "import sys; from hexapod_workspace.ros import main; sys.exit(main(sys.argv))"


def first_answer(client: Any, request: Any, timeout_s: float = 600.0) -> Any:
    """The first answer of ``client`` to ``request``, asked again every 30 s for ``timeout_s``.

    A node whose numba cache is cold (the first start after ``make ros`` copied the package, or
    a ``--node-source`` tree) compiles its kernels while configuring, for up to a few minutes
    on a loaded 2-core machine; its services are discovered before it answers. The benchmarks
    wait for this answer before timing anything (RuntimeError when none comes).
    """
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        response = client.call(
            request, timeout_sec=min(30.0, max(deadline - time.monotonic(), 1.0))
        )
        if response is not None:
            return response
    raise RuntimeError(f"{client.srv_name}: no answer within {timeout_s:.0f} s")


def missing_install() -> str | None:
    """The line to print when the install space is not built (None when it is)."""
    if NODE_EXECUTABLE.is_file():
        return None
    return f"{NODE_EXECUTABLE} missing: run `make ros` first"


@contextlib.contextmanager
def ros_domain(domain_id: int | None = None) -> Iterator[int]:
    """Set ROS_DOMAIN_ID (``domain_id``, or a free one from domain_coordinator) and loopback
    discovery in this process's environment (inherited by every process it starts)."""
    import domain_coordinator

    chosen = (
        contextlib.nullcontext(domain_id)
        if domain_id is not None
        else domain_coordinator.domain_id()
    )
    with chosen as domain:
        os.environ["ROS_DOMAIN_ID"] = str(domain)
        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
        yield domain


def start_node(
    folder: Path,
    ros_args: Sequence[str] = (),
    source: Path | None = None,
    log: Path | None = None,
    prefix: Sequence[str] = (),
    options: Sequence[str] = (),
) -> subprocess.Popen:
    """Start the node with the example parameters, recording into ``folder``.

    Parameters
    ----------
    folder : Path
        The node's working directory and ``recording.directory``.
    ros_args : sequence of str
        Further ``--ros-args`` (``-p name:=value``, ``-r __ns:=/x``).
    source : Path, optional
        A source tree whose ``hexapod_workspace`` package runs instead of the install space's.
    log : Path, optional
        File for the node's stdout and stderr (default ``folder / "node.log"``).
    prefix : sequence of str
        A command that runs the node (``chrt --fifo 50``: a real-time scheduling policy).
    options : sequence of str
        The node's own options, before ``--ros-args`` (``--realtime-priority=50``).
    """
    env = dict(os.environ)
    command = [str(NODE_EXECUTABLE)]
    if source is not None:
        env["PYTHONPATH"] = f"{source.resolve()}:{env.get('PYTHONPATH', '')}"
        command = [sys.executable, "-c", _FROM_SOURCE]
    folder.mkdir(parents=True, exist_ok=True)
    with (log or folder / "node.log").open("wb") as out:
        return subprocess.Popen(
            [
                *prefix,
                *command,
                *options,
                "--ros-args",
                "--params-file",
                str(PARAMS_FILE),
                "-p",
                f"recording.directory:={folder}",
                *ros_args,
            ],
            stdout=out,
            stderr=subprocess.STDOUT,
            env=env,
            cwd=folder,
        )


def start_python(source: str, log: Path, prefix: Sequence[str] = ()) -> subprocess.Popen:
    """Run ``python -c source`` (a floor server), output appended to ``log``, through the
    command ``prefix`` (as :func:`start_node`)."""
    with log.open("ab") as out:
        return subprocess.Popen(
            [*prefix, sys.executable, "-c", source], stdout=out, stderr=subprocess.STDOUT
        )


def stop(processes: Iterable[subprocess.Popen], timeout: float = 30.0) -> None:
    """SIGINT each process still running; SIGKILL the ones not gone after ``timeout`` s."""
    for process in processes:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)
            try:
                process.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


def print_failures(logs: Iterable[Path], words: Sequence[str] = ("Traceback",)) -> bool:
    """Print the end of each log that contains one of ``words`` to stderr; True if one did."""
    failed = False
    for log in logs:
        text = log.read_text(errors="replace") if log.is_file() else ""
        if any(word in text for word in words):
            print(f"---- {log.name}:\n{text[-3000:]}", file=sys.stderr)
            failed = True
    return failed


def describe_node(source: Path | None) -> str:
    """Which node a benchmark runs, for its printout: the source tree (with its git commit when
    it is a checkout) or this checkout's install space."""
    tree = REPO if source is None else source.resolve()
    try:
        commit = subprocess.run(
            ["git", "-C", str(tree), "describe", "--always", "--dirty"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = "not a git checkout"
    if source is None:
        return f"install space of {REPO} ({commit}; `make ros` copies the package there)"
    return f"source tree {tree} ({commit})"
