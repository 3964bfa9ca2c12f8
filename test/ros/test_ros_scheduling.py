"""``workspace_node --realtime-priority=N``: the node's threads under SCHED_FIFO, its worker
process back under the normal policy; ``--worker-scheduling=POLICY``: the worker's computing
thread at niceness 5 (default), under SCHED_IDLE or SCHED_BATCH, without privileges; from a
real node process over real Fast DDS.

What the option buys (the tail of the command latency on a busy machine) is measured in
``benchmarks/ros_load.py --priority N``, not asserted here.
"""

from __future__ import annotations

import multiprocessing
import os
import resource
from pathlib import Path
from typing import Any

import pytest
from ros_support import require_ros, running_node

require_ros()

from hexapod_workspace_msgs.msg import TiltTorsion, WorkspaceRequest  # noqa: E402
from hexapod_workspace_msgs.srv import CheckPoses  # noqa: E402

from hexapod_workspace.errors import ConfigError  # noqa: E402
from hexapod_workspace.ros.scheduling import (  # noqa: E402
    background,
    realtime_priority_from_argv,
    worker_policy_from_argv,
)

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


def _computed_in_worker(ros_client: Any, node: Any) -> dict[int, dict[int, tuple]]:
    """Compute a small workspace (so the worker runs); the policies of the worker's threads."""
    # a call first (resent if its answer is lost while the node's writers still match ours):
    # a goal sent right after the start may lose its response the same way
    request = CheckPoses.Request(orientations=[TiltTorsion(phi=0.3, theta=0.2, psi=0.1)])
    request.position.z = -1.3
    assert ros_client.call(CheckPoses, f"{NODE}/check_poses", request).success
    goal = WorkspaceRequest(kind=WorkspaceRequest.PROJECTED_TORSION_ZERO, n_rays=36)
    goal.position.z = -1.3
    assert ros_client.compute(f"{NODE}/compute_workspace", goal).success
    workers = _workers(node.process.pid)
    assert workers, "the node's worker process is not running"
    return {pid: _policies(pid) for pid in workers}


def test_default_node_normal_worker_niceness_5(ros_domain, ros_client, tmp_path):
    with running_node(tmp_path) as node:
        workers = _computed_in_worker(ros_client, node)
        threads = _policies(node.process.pid)
        nice = {pid: os.getpriority(os.PRIO_PROCESS, pid) for pid in workers}
    assert {policy for policy, _ in threads.values()} == {os.SCHED_OTHER}, threads
    for pid, policies in workers.items():
        assert {policy for policy, _ in policies.values()} == {os.SCHED_OTHER}, policies
        assert nice[pid] == 5, nice  # the computing thread


@pytest.mark.parametrize(
    ("option", "policy", "niceness"), [("idle", os.SCHED_IDLE, 0), ("batch", os.SCHED_BATCH, 19)]
)
def test_worker_scheduling_option(ros_domain, ros_client, tmp_path, option, policy, niceness):
    options = [f"--worker-scheduling={option}"]
    with running_node(tmp_path, node_options=options) as node:
        workers = _computed_in_worker(ros_client, node)
        nice = {pid: os.getpriority(os.PRIO_PROCESS, pid) for pid in workers}
    for pid, policies in workers.items():
        assert policies[pid][0] == policy, (pid, policies)
        assert nice[pid] == niceness, nice
        # the cloud publisher's DDS threads, started before, keep the normal policy
        assert os.SCHED_OTHER in {policy for policy, _ in policies.values()}, policies


def _background_unprivileged(policy: str, answer: Any) -> None:
    """In a child process: drop root (when run as root), step aside under ``policy``, report
    the thread's policy and niceness (or the error)."""
    try:
        if os.geteuid() == 0:
            os.setgid(65534)
            os.setuid(65534)  # nobody: no CAP_SYS_NICE
        background(policy)
        answer.put((os.geteuid(), os.sched_getscheduler(0), os.getpriority(os.PRIO_PROCESS, 0)))
    except Exception as error:
        answer.put(repr(error))


@pytest.mark.parametrize(
    ("option", "policy", "niceness"),
    [("idle", os.SCHED_IDLE, 0), ("batch", os.SCHED_BATCH, 19), ("normal", os.SCHED_OTHER, 5)],
)
def test_worker_policies_need_no_privilege(option, policy, niceness):
    context = multiprocessing.get_context("fork")
    answer = context.Queue()
    child = context.Process(target=_background_unprivileged, args=(option, answer))
    child.start()
    got = answer.get(timeout=30)
    child.join(timeout=30)
    uid, found, nice = got if isinstance(got, tuple) else (None, got, None)
    assert uid != 0, got
    assert (found, nice) == (policy, niceness), got


def test_worker_scheduling_option_is_read_before_ros_args_only():
    argv = ["workspace_node", "--worker-scheduling=Batch", "--ros-args", "-p", "a:=1"]
    kept = ["workspace_node", "--ros-args", "-p", "a:=1"]
    assert worker_policy_from_argv(argv) == ("batch", kept)
    assert worker_policy_from_argv(["workspace_node"]) == ("normal", ["workspace_node"])
    after = ["workspace_node", "--ros-args", "--worker-scheduling=batch"]  # ROS's, not ours
    assert worker_policy_from_argv(after) == ("normal", after)
    with pytest.raises(ConfigError, match="expected one of normal, idle, batch, got 'fifo'"):
        worker_policy_from_argv(["workspace_node", "--worker-scheduling=fifo"])


def test_bad_worker_scheduling_exits_2_naming_the_option(ros_domain, tmp_path):
    with running_node(tmp_path, node_options=["--worker-scheduling=fast"]) as node:
        status = node.process.wait(timeout=60)
        output = node.output()
    assert status == 2, output
    assert "--worker-scheduling: expected one of normal, idle, batch, got 'fast'" in output, output


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
