"""``workspace_node --realtime-priority=N``: the node's threads under SCHED_FIFO, its worker
process back under the normal policy, from a real node process over real Fast DDS.

What the option buys (the tail of the command latency on a busy machine) is measured in
``benchmarks/ros_load.py --priority N``, not asserted here.
"""

from __future__ import annotations

import os
import resource
from pathlib import Path

import pytest
from ros_support import require_ros, running_node

require_ros()

from hexapod_workspace_msgs.msg import TiltTorsion, WorkspaceRequest  # noqa: E402
from hexapod_workspace_msgs.srv import CheckPoses  # noqa: E402

from hexapod_workspace.errors import ConfigError  # noqa: E402
from hexapod_workspace.ros.scheduling import realtime_priority_from_argv  # noqa: E402

NODE = "/hexapod_workspace"
PRIORITY = 10


def _may_use_fifo() -> bool:
    """Root (CAP_SYS_NICE) or an rtprio limit that covers PRIORITY."""
    soft = resource.getrlimit(resource.RLIMIT_RTPRIO)[0]
    return os.geteuid() == 0 or soft == resource.RLIM_INFINITY or soft >= PRIORITY


def _policies(pid: int) -> dict[int, tuple[int, int]]:
    """(policy, priority) of every thread of process ``pid``."""
    found = {}
    for name in os.listdir(f"/proc/{pid}/task"):
        tid = int(name)
        try:
            found[tid] = (os.sched_getscheduler(tid), os.sched_getparam(tid).sched_priority)
        except OSError:  # the thread ended meanwhile
            continue
    return found


def _workers(pid: int) -> list[int]:
    """The processes the node spawned to compute (multiprocessing's resource tracker, which
    only waits on a pipe, left out)."""
    pids: list[int] = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        pids += [int(p) for p in (task / "children").read_text().split()]
    return [p for p in pids if b"resource_tracker" not in Path(f"/proc/{p}/cmdline").read_bytes()]


@pytest.mark.skipif(not _may_use_fifo(), reason="SCHED_FIFO needs root or an rtprio limit")
def test_realtime_node_threads_fifo_worker_time_sharing(ros_domain, ros_client, tmp_path):
    options = [f"--realtime-priority={PRIORITY}"]
    with running_node(tmp_path, node_options=options) as node:
        request = CheckPoses.Request(orientations=[TiltTorsion(phi=0.3, theta=0.2, psi=0.1)])
        request.position.z = -1.3
        response = ros_client.call(CheckPoses, f"{NODE}/check_poses", request)
        assert response.success, response.message
        goal = WorkspaceRequest(kind=WorkspaceRequest.PROJECTED_TORSION_ZERO, n_rays=36)
        goal.position.z = -1.3
        assert ros_client.compute(f"{NODE}/compute_workspace", goal).success  # in the worker
        threads = _policies(node.process.pid)
        workers = _workers(node.process.pid)
        worker_threads = {pid: _policies(pid) for pid in workers}
    assert len(threads) > 5  # the executor, DDS's, the recorder, the job queue, ...
    assert set(threads.values()) == {(os.SCHED_FIFO, PRIORITY)}, threads
    assert workers, "the node's worker process is not running"
    for pid, policies in worker_threads.items():
        assert {policy for policy, _ in policies.values()} == {os.SCHED_OTHER}, (pid, policies)


def test_default_is_normal_scheduling(ros_domain, ros_client, tmp_path):
    with running_node(tmp_path) as node:
        request = CheckPoses.Request(orientations=[TiltTorsion(phi=0.3, theta=0.2, psi=0.1)])
        request.position.z = -1.3
        assert ros_client.call(CheckPoses, f"{NODE}/check_poses", request).success
        threads = _policies(node.process.pid)
    assert {policy for policy, _ in threads.values()} == {os.SCHED_OTHER}, threads


@pytest.mark.parametrize("value", ["100", "-1", "high"])
def test_bad_realtime_priority_exits_2_naming_the_option(ros_domain, tmp_path, value):
    with running_node(tmp_path, node_options=[f"--realtime-priority={value}"]) as node:
        status = node.process.wait(timeout=60)
        output = node.output()
    assert status == 2, output
    assert (
        f"--realtime-priority: expected an integer in 0..99 (0: normal scheduling), got '{value}'"
        in output
    ), output


def test_realtime_option_is_read_before_ros_args_only():
    argv = ["workspace_node", "--realtime-priority=20", "--ros-args", "-p", "a:=1"]
    assert realtime_priority_from_argv(argv) == (20, ["workspace_node", "--ros-args", "-p", "a:=1"])
    assert realtime_priority_from_argv(["workspace_node"]) == (0, ["workspace_node"])
    after = ["workspace_node", "--ros-args", "--realtime-priority=20"]  # ROS's, not ours
    assert realtime_priority_from_argv(after) == (0, after)
    with pytest.raises(ConfigError, match="got '99.5'"):
        realtime_priority_from_argv(["workspace_node", "--realtime-priority=99.5"])
