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
holds a core ahead of the rest of the machine (the worker also lowers its niceness).

The option needs the privilege (root, ``CAP_SYS_NICE``, or an ``rtprio`` limit such as
``@realtime - rtprio 98`` in ``/etc/security/limits.conf``, the usual set-up for ros2_control).
Without it the node refuses to start with the reason rather than run at a priority it was not
given. Linux only. Real-time threads that never sleep could starve the machine; the kernel's
real-time throttling (``/proc/sys/kernel/sched_rt_runtime_us``, 95 % by default) bounds them,
and the node's threads block on DDS between commands.
"""

from __future__ import annotations

import contextlib
import os

from hexapod_workspace.errors import ConfigError

__all__ = ["REALTIME_OPTION", "realtime_priority_from_argv", "set_realtime", "time_sharing"]

#: Command-line option of ``workspace_node`` (before ``--ros-args``): SCHED_FIFO priority.
REALTIME_OPTION = "--realtime-priority"


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


def time_sharing() -> None:
    """Put every thread of this process (and those it starts) under the normal time-sharing
    policy where they inherited another one: the worker and axis-limits processes of a node
    started with :data:`REALTIME_OPTION` call it first, so their computations of seconds never
    hold a core ahead of the rest of the machine."""
    with contextlib.suppress(OSError, AttributeError):  # not Linux: nothing was inherited
        for thread in _threads():  # numpy's BLAS pool started at import inherited it too
            if os.sched_getscheduler(thread) != os.SCHED_OTHER:
                os.sched_setscheduler(thread, os.SCHED_OTHER, os.sched_param(0))


def _threads() -> list[int]:
    """Ids of this process's threads (Linux: /proc/self/task; elsewhere the calling one, 0)."""
    try:
        return sorted(int(name) for name in os.listdir("/proc/self/task"))
    except OSError:
        return [0]
