"""The node's health on ``/diagnostics`` (diagnostic_msgs/DiagnosticArray, 1 Hz).

One DiagnosticStatus named after the node, hardware_id the manipulator's frame (or the node's
name): level OK, WARN (commands answered "overloaded" or refused since the last report, or
recording failed while enabled) or ERROR (the worker process is not running when a job waits,
or an internal error since the last report), and the counts as key/value pairs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

from .recorder import RecorderStatus

__all__ = ["Counters", "Lifecycle", "diagnostic_array"]


@dataclass(frozen=True)
class Lifecycle:
    """The node's lifecycle state as the diagnostics report it."""

    state: str  # unconfigured, inactive, active, finalized (or a transition's label)
    active: bool
    configure_error: str = ""  # why the last configure failed ("" when it did not)


@dataclass
class Counters:
    """What the node counts (written by the executor thread, read by the diagnostics)."""

    commands_received: int = 0
    commands_answered: int = 0
    commands_refused: int = 0
    commands_overloaded: int = 0
    check_calls: int = 0
    check_refused: int = 0
    last_error: str = ""
    #: values at the previous report, to tell what happened since
    previous: dict[str, Any] = field(default_factory=dict)


def diagnostic_array(
    *,
    name: str,
    hardware_id: str,
    stamp: Any,
    counters: Counters,
    jobs_depth: int,
    worker_alive: bool,
    recorder: RecorderStatus,
    lifecycle: Lifecycle | None = None,
    extra: dict[str, str] | None = None,
) -> DiagnosticArray:
    """The node's DiagnosticArray: one status, level from what happened since the last call.

    Not active: WARN ("inactive ..."), or ERROR with the reason when configure failed.
    ``extra``: further key-value lines (the machining cell's frames and parameter changes)."""
    lifecycle = lifecycle or Lifecycle("active", True)
    now = {
        "lifecycle state": lifecycle.state,
        "commands received": counters.commands_received,
        "commands answered": counters.commands_answered,
        "commands refused": counters.commands_refused,
        "commands overloaded": counters.commands_overloaded,
        "check_poses calls": counters.check_calls,
        "check_poses refused": counters.check_refused,
        "workspace jobs queued or running": jobs_depth,
        "worker alive": worker_alive,
        "recording": "on" if recorder.enabled else "off",
        "recording path": recorder.path,
        "recorded messages": recorder.messages,
        "recorded bytes": recorder.bytes_written,
        "recorder queue depth": recorder.queued,
        "recorder lost messages": recorder.lost,
        "last error": counters.last_error or recorder.last_error,
    }
    before = counters.previous
    counters.previous = dict(now)

    def grew(key: str) -> bool:
        return now[key] > before.get(key, 0)

    level, message = DiagnosticStatus.OK, "serving"
    if grew("commands overloaded"):
        level, message = DiagnosticStatus.WARN, "overloaded: commands answered late"
    elif grew("recorder lost messages"):
        level, message = DiagnosticStatus.WARN, "recording cannot keep up: messages lost"
    elif recorder.last_error and not recorder.enabled:
        level, message = DiagnosticStatus.WARN, f"recording off: {recorder.last_error}"
    if counters.last_error and counters.last_error != before.get("last error"):
        level, message = DiagnosticStatus.ERROR, counters.last_error
    if jobs_depth and not worker_alive:
        level, message = DiagnosticStatus.ERROR, "the workspace worker process is not running"
    if not lifecycle.active:
        level = DiagnosticStatus.WARN
        message = f"inactive: lifecycle state {lifecycle.state}, commands answered 'inactive'"
        if lifecycle.configure_error and lifecycle.state == "unconfigured":
            level = DiagnosticStatus.ERROR
            message = f"unconfigured: configure failed: {lifecycle.configure_error}"
    status = DiagnosticStatus(
        level=level,
        name=name,
        message=message,
        hardware_id=hardware_id,
        values=[
            KeyValue(key=key, value=str(value)) for key, value in {**now, **(extra or {})}.items()
        ],
    )
    array = DiagnosticArray(status=[status])
    array.header.stamp = stamp
    return array
