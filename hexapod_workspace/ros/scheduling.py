"""Where the node's threads and processes stand in the operating system's scheduler.

A controller that waits for each verdict needs the node's answer within a few ms, every time.
On a machine whose cores are shared with other work, what decides the tail is not the node's
own cost but how long its threads wait for a core: on the 2-core test machine, at a load
average of 4-7, a node that echoes a prebuilt result (no check at all) answered 1 % of the
commands more than 20-250 ms late (``benchmarks/ros_load.py``, its floor; docs/ros.md, "Threads,
load and latency"). The cure Linux offers is a real-time policy for the control loop, as
ros2_control's controller manager does with its ``thread_priority``: under ``SCHED_FIFO`` a
thread runs as soon as it is runnable, ahead of every time-sharing thread of the machine.

``workspace_node --realtime-priority=N`` (1..99; launch argument ``realtime_priority``) puts
the node's threads under ``SCHED_FIFO`` at priority ``N`` before rclpy starts, so every thread
the node then starts (DDS, the executor, the recorder, the job queue) inherits it: the command
path runs ahead of other jobs. The long computations must not: the worker process and
the axis-limits process put themselves back under the normal time-sharing policy at start
(:func:`time_sharing`), before they start any thread, so a 3-D workspace of seconds never
holds a core ahead of the rest of the machine (and then steps aside further, below).

The option needs the privilege (root, ``CAP_SYS_NICE``, or an ``rtprio`` limit such as
``@realtime - rtprio 98`` in ``/etc/security/limits.conf``, the usual set-up for ros2_control).
Without it the node refuses to start with the reason rather than run at a priority it was not
given. Linux only. Real-time threads that never sleep could starve the machine; the kernel's
real-time throttling (``/proc/sys/kernel/sched_rt_runtime_us``, 95 % by default) bounds them,
and the node's threads block on DDS between commands.

Without privileges: the heavy work steps aside
----------------------------------------------
Raising a thread's priority needs the privilege; lowering one does not. The long computations
(the worker process's workspaces, the axis-limits process) run under the policy chosen with
``workspace_node --worker-scheduling=POLICY`` (launch argument ``worker_scheduling``):

``normal`` (default)
    ``SCHED_OTHER`` at niceness 5 (weight 335 against 1024 for niceness 0): the computation
    keeps about a quarter of a core against each busy thread of niceness 0.
``idle``
    ``SCHED_IDLE``: the computation gets a core only when no normal thread of its group (the
    session, see autogroup below; the whole machine without autogroup) wants it, and any thread
    of the node that wakes (a command arriving) preempts it at once. On cores kept busy by
    such threads it starves: a workspace goal or an axis-limits computation then waits until
    they pause, and so does the node's exit, which waits for the axis-limits process to finish
    its computation (seen in the test suite on the loaded test machine: no exit within 30 s).
    For a node whose session leaves the cores idle now and then.
``batch``
    ``SCHED_BATCH`` at niceness 19: a CPU-bound job whose own wake-ups never preempt another
    thread, with the smallest time-sharing weight (15 against 1024), so it starves almost as
    ``idle`` does.

Each is unprivileged on Linux (sched(7): a thread may always move itself to ``SCHED_IDLE`` or
``SCHED_BATCH`` and raise its niceness). The worker's DDS threads, which publish the clouds,
start before the policy is applied and keep the normal one, so a cloud's delivery does not wait
behind the next computation.

What it does and does not buy: Linux's autogroup (``/proc/sys/kernel/sched_autogroup_enabled``,
on by default in most distributions) first shares the cores equally between *sessions* (a
terminal, a ``ros2 launch``, a service) and only then between the threads of a session by
their policy and niceness. So ``idle`` gives the node the worker's share of the node's own
session (the node, its worker, and whatever else that launch started), not other sessions'
share: against another user's job only the real-time policy above helps. The figures (``idle``
lowered the median, not the p99, under other sessions' load) are in docs/ros.md ("Threads, load
and latency").
"""

from __future__ import annotations

import contextlib
import os

from hexapod_workspace.errors import ConfigError

__all__ = [
    "REALTIME_OPTION",
    "WORKER_POLICIES",
    "WORKER_SCHEDULING_OPTION",
    "background",
    "realtime_priority_from_argv",
    "set_realtime",
    "set_worker_policy",
    "time_sharing",
    "worker_policy",
    "worker_policy_from_argv",
]

#: Command-line option of ``workspace_node`` (before ``--ros-args``): SCHED_FIFO priority.
REALTIME_OPTION = "--realtime-priority"
#: Command-line option of ``workspace_node`` (before ``--ros-args``): the policy of the worker
#: and axis-limits processes, one of :data:`WORKER_POLICIES`.
WORKER_SCHEDULING_OPTION = "--worker-scheduling"
#: Policies of the long computations (module docstring), the default first.
WORKER_POLICIES = ("normal", "idle", "batch")
#: Niceness of the ``batch`` and ``normal`` policies.
_NICENESS = {"idle": 0, "batch": 19, "normal": 5}
_worker_policy = [WORKER_POLICIES[0]]  # this process's choice (set by workspace_node's main)


def realtime_priority_from_argv(argv: list[str]) -> tuple[int, list[str]]:
    """The ``--realtime-priority=N`` of ``argv`` (0 when absent: normal scheduling) and
    ``argv`` without it. Only arguments before ``--ros-args`` are looked at.

    Raises
    ------
    ConfigError
        The value is not an integer in 0..99.
    """
    end = argv.index("--ros-args") if "--ros-args" in argv else len(argv)
    priority, kept = 0, []
    for index, argument in enumerate(argv):
        if index < end and argument.startswith(f"{REALTIME_OPTION}="):
            value = argument.split("=", 1)[1].strip()
            if not value.isdigit() or not 0 <= int(value) <= 99:
                msg = f"{REALTIME_OPTION}: expected an integer in 0..99 (0: normal scheduling), "
                raise ConfigError(msg + f"got {value!r}")
            priority = int(value)
        else:
            kept.append(argument)
    return priority, kept


def worker_policy_from_argv(argv: list[str]) -> tuple[str, list[str]]:
    """The ``--worker-scheduling=POLICY`` of ``argv`` (``normal`` when absent) and ``argv``
    without it. Only arguments before ``--ros-args`` are looked at.

    Raises
    ------
    ConfigError
        The value is not one of :data:`WORKER_POLICIES`.
    """
    end = argv.index("--ros-args") if "--ros-args" in argv else len(argv)
    policy, kept = WORKER_POLICIES[0], []
    for index, argument in enumerate(argv):
        if index < end and argument.startswith(f"{WORKER_SCHEDULING_OPTION}="):
            policy = argument.split("=", 1)[1].strip().lower()
            if policy not in WORKER_POLICIES:
                given = argument.split("=", 1)[1]
                msg = f"{WORKER_SCHEDULING_OPTION}: expected one of {', '.join(WORKER_POLICIES)}"
                raise ConfigError(f"{msg}, got {given!r}")
        else:
            kept.append(argument)
    return policy, kept


def set_worker_policy(policy: str) -> None:
    """Choose the policy of the worker and axis-limits processes this process starts later
    (one of :data:`WORKER_POLICIES`; ``ValueError`` otherwise)."""
    if policy not in WORKER_POLICIES:
        raise ValueError(f"worker policy: expected one of {WORKER_POLICIES}, got {policy!r}")
    _worker_policy[0] = policy


def worker_policy() -> str:
    """The policy chosen with :func:`set_worker_policy` (default ``normal``)."""
    return _worker_policy[0]


def background(policy: str) -> None:
    """Put the calling thread (and the threads it starts later) under ``policy`` (one of
    :data:`WORKER_POLICIES`): what a worker process's computing thread calls once its
    publisher's threads have started. Only ever lowers the priority, so no privilege is needed;
    where the operating system has no such policy (not Linux) it leaves the thread as it is."""
    with contextlib.suppress(OSError, AttributeError):
        if policy == "idle":
            os.sched_setscheduler(0, os.SCHED_IDLE, os.sched_param(0))
        elif policy == "batch":
            os.sched_setscheduler(0, os.SCHED_BATCH, os.sched_param(0))
    with contextlib.suppress(OSError):
        # Linux: the niceness of the calling thread (inherited by the threads it starts)
        raise_by = _NICENESS[policy] - os.getpriority(os.PRIO_PROCESS, 0)
        if raise_by > 0:
            os.nice(raise_by)


def set_realtime(priority: int) -> None:
    """Put every thread of this process under ``SCHED_FIFO`` at ``priority`` (threads started
    later inherit it); 0 does nothing.

    Raises
    ------
    ConfigError
        The operating system refused (no privilege) or has no SCHED_FIFO; the message says what
        to grant.
    """
    if priority == 0:
        return
    try:
        for thread in _threads():  # those already started too (numpy's BLAS pool, ...)
            os.sched_setscheduler(thread, os.SCHED_FIFO, os.sched_param(priority))
    except (OSError, AttributeError) as error:
        msg = (
            f"{REALTIME_OPTION}={priority}: SCHED_FIFO refused ({error}); run as a user with "
            "an rtprio limit of at least the priority (/etc/security/limits.conf) or "
            f"CAP_SYS_NICE, or leave {REALTIME_OPTION} out for normal scheduling"
        )
        raise ConfigError(msg) from error


def time_sharing(policy: str | None = None) -> None:
    """Put every thread of this process (and those it starts) under the normal time-sharing
    policy where they inherited another one: the worker and axis-limits processes of a node
    started with :data:`REALTIME_OPTION` call it first, so their computations of seconds never
    hold a core ahead of the rest of the machine. With ``policy``, the calling thread then
    steps aside under it (:func:`background`): the axis-limits process's initializer."""
    with contextlib.suppress(OSError, AttributeError):  # not Linux: nothing was inherited
        for thread in _threads():  # numpy's BLAS pool started at import inherited it too
            if os.sched_getscheduler(thread) != os.SCHED_OTHER:
                os.sched_setscheduler(thread, os.SCHED_OTHER, os.sched_param(0))
    if policy is not None:
        background(policy)


def _threads() -> list[int]:
    """Ids of this process's threads (Linux: /proc/self/task; elsewhere the calling one, 0)."""
    try:
        return sorted(int(name) for name in os.listdir("/proc/self/task"))
    except OSError:
        return [0]
