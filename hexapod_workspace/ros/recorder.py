"""The node's MCAP log: one queue between the callbacks and the disk, one thread that owns it.

Callbacks (any thread) only append ``(topic, message, time)`` to a queue: no lock, no CDR, no
disk. The recorder's thread is the only one that touches the
:class:`~hexapod_workspace.logs.LogWriter`: it serialises each message, writes it, opens and
finishes logs (requests to do so travel through the same queue, so they keep their order with
the messages), flushes, and turns recording off on the first write failure.

Flush bound (end to end, for the node): the thread writes a message :data:`BATCH_DELAY` s after
it arrives (with everything queued behind it: the callback that queued it has finished by then
and does not wait for the interpreter while the thread writes) and flushes whatever has been
pending for :data:`FLUSH_INTERVAL` s, waking at least every :data:`WAKE_INTERVAL` s; so a
message is in the file (the operating system's hands; a SIGKILL of the node does not lose it) at
most about ``BATCH_DELAY + FLUSH_INTERVAL + WAKE_INTERVAL`` s after the callback queued it.
:data:`FLUSH_BOUND` is the bound docs/log_format.md states and ``test_node_recording`` proves
under a 200 Hz stream with some margin for a loaded machine.

Rotation (:class:`Rotation`, the ``recording.max_*`` parameters), as rosbag2 splits a bag: the
current log is finished and a new one started (named by its own start time, in the same folder)
once the messages written to it reach ``max_file_bytes`` or it is ``max_file_seconds`` old (checked
at each message); after each start, the oldest ``hexapod_workspace_*.mcap`` logs of the folder
(earlier runs included, never the current one) are removed until the folder's logs take at most
``max_total_bytes``. Every split and removal is logged.
"""

from __future__ import annotations

import contextlib
import queue
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rclpy.serialization import serialize_message

from hexapod_workspace.errors import RecordingError
from hexapod_workspace.logs import LogWriter, run_log_path

__all__ = [
    "BATCH_DELAY",
    "FLUSH_BOUND",
    "FLUSH_INTERVAL",
    "LOG_PREFIX",
    "MAX_QUEUED",
    "Recorder",
    "RecorderStatus",
    "Rotation",
]

#: Seconds a written message may stay in memory before the writer flushes it.
FLUSH_INTERVAL = 0.1
#: Seconds between two looks at the writer when nothing arrives.
WAKE_INTERVAL = 0.05
#: Seconds the recorder waits after a message arrives before it writes it and those queued
#: behind it (well inside the flush bound).
BATCH_DELAY = 0.002
#: What the node promises: everything acknowledged this many seconds before a SIGKILL is in
#: the log.
FLUSH_BOUND = 0.5
#: Messages the queue may hold before new ones are not recorded (counted as lost; the disk
#: cannot keep up): bounds the node's memory, never blocks a callback.
MAX_QUEUED = 200_000

_OPEN, _CLOSE, _STOP = "open", "close", "stop"
#: Logs of this node are named ``<LOG_PREFIX>_<start time>.mcap``; rotation removes only those.
LOG_PREFIX = "hexapod_workspace"


@dataclass(frozen=True)
class Rotation:
    """When the node's log is split and old logs removed (0 = no such limit).

    Attributes
    ----------
    max_file_bytes : int
        Split once the messages written to the current log reach this many bytes (the file is a
        little larger: MCAP records and index).
    max_file_seconds : float
        Split once the current log is this old (s), at its next message.
    max_total_bytes : int
        Remove the oldest logs of the folder until all take at most this many bytes.
    """

    max_file_bytes: int = 0
    max_file_seconds: float = 0.0
    max_total_bytes: int = 0


@dataclass(frozen=True)
class _Serialized:
    """A message queued as its CDR bytes."""

    data: bytes


@dataclass(frozen=True)
class RecorderStatus:
    """What the diagnostics report about recording (a snapshot)."""

    enabled: bool
    path: str
    messages: int
    bytes_written: int
    queued: int
    lost: int
    last_error: str


class Recorder:
    """The node's log: ``write`` from any thread; one thread owns the writer.

    Parameters
    ----------
    logger : rclpy logger
        Where recording starts, stops and fails are reported.
    """

    def __init__(self, logger: Any) -> None:
        self._logger = logger
        self._queue: queue.SimpleQueue[tuple[Any, ...]] = queue.SimpleQueue()
        self._channels: dict[str, tuple[str, str]] = {}
        # written by the recorder thread only, read by the diagnostics (atomic reads)
        self._writer: LogWriter | None = None
        self._messages = 0
        self._bytes = 0
        self._lost = 0
        self._last_error = ""
        self._accepting = False  # a log is open or being opened: callbacks queue messages
        # rotation state, recorder thread only
        self._directory: Path | None = None
        self._rotation = Rotation()
        self._file_bytes = 0
        self._file_started = 0.0
        self._file_messages = 0
        self._thread = threading.Thread(
            target=self._run, name="hexapod_workspace_recorder", daemon=True
        )
        self._thread.start()

    # ------------------------------------------------------------------ any thread
    def add_channel(self, topic: str, msgtype: str, qos: str) -> None:
        """Declare a topic recorded in every log (before the first :meth:`open`)."""
        self._channels[topic] = (msgtype, qos)

    @property
    def recording(self) -> bool:
        """True while messages given to :meth:`write` are recorded (a log is open or opening):
        a caller that has the CDR bytes anyway (it publishes them) hands those instead."""
        return self._accepting

    def write(self, topic: str, message: Any, log_time_ns: int | None = None) -> None:
        """Queue one rclpy message for ``topic`` when recording (never blocks, never raises);
        logged at ``log_time_ns`` (default now, ns since the epoch)."""
        if not self._accepting:
            return
        if self._queue.qsize() >= MAX_QUEUED:
            self._lost += 1
            return
        self._queue.put((topic, message, time.time_ns() if log_time_ns is None else log_time_ns))

    def write_serialized(self, topic: str, data: bytes, log_time_ns: int | None = None) -> None:
        """Queue CDR bytes already serialised (by the node that publishes them, the
        subscription that took them, or the worker process) for ``topic``; written as they are
        (never blocks, never raises)."""
        self.write(topic, _Serialized(data), log_time_ns)

    def open(
        self, directory: Path, rotation: Rotation | None = None, timeout: float = 10.0
    ) -> None:
        """Start a new log in ``directory`` (named by its start time), split and pruned as
        ``rotation`` says; no-op when open. Returns once the file exists (or after
        ``timeout``)."""
        self._accepting = True
        done = threading.Event()
        self._queue.put((_OPEN, Path(directory), done, rotation or Rotation()))
        done.wait(timeout)

    def close(self, timeout: float = 10.0) -> None:
        """Write what is queued and finish the log; returns when done (or after ``timeout``)."""
        self._accepting = False
        done = threading.Event()
        self._queue.put((_CLOSE, done))
        done.wait(timeout)

    def shutdown(self, timeout: float = 10.0) -> None:
        """:meth:`close` and end the thread (the node is being destroyed)."""
        self.close(timeout)
        self._queue.put((_STOP,))
        self._thread.join(timeout)

    def status(self) -> RecorderStatus:
        writer = self._writer
        return RecorderStatus(
            enabled=writer is not None,
            path=str(writer.path) if writer is not None else "",
            messages=self._messages,
            bytes_written=self._bytes,
            queued=self._queue.qsize(),
            lost=self._lost,
            last_error=self._last_error,
        )

    # ------------------------------------------------------------------ recorder thread
    def _run(self) -> None:
        while True:
            try:
                item = self._queue.get(timeout=WAKE_INTERVAL)
            except queue.Empty:
                item = None
            if item is not None and item[0] not in (_OPEN, _CLOSE, _STOP):
                # A message arrives while its callback still runs (a request is queued before
                # the answer is computed): wait for the callback to finish, then write
                # everything queued meanwhile in one go, instead of taking the interpreter
                # from the executor message by message.
                time.sleep(BATCH_DELAY)
            while item is not None:
                if item[0] == _STOP:
                    return
                self._handle(item)
                try:
                    item = self._queue.get_nowait()
                except queue.Empty:
                    item = None
            writer = self._writer
            if writer is not None:
                try:
                    writer.flush_if_due()
                except RecordingError as error:
                    self._failed(error)

    def _handle(self, item: tuple[Any, ...]) -> None:
        kind = item[0]
        if kind == _OPEN:
            if self._writer is None:
                self._directory, self._rotation = item[1], item[3]
                self._open(item[1])
            item[2].set()
        elif kind == _CLOSE:
            self._finish()
            item[1].set()
        elif self._writer is not None:
            topic, message, stamp_ns = item
            data = message.data if isinstance(message, _Serialized) else serialize_message(message)
            try:
                self._writer.write(topic, data, log_time_ns=stamp_ns)
            except RecordingError as error:
                self._failed(error)
                return
            self._messages += 1
            self._bytes += len(data)
            self._file_messages += 1
            self._file_bytes += len(data)
            if self._split_due():
                self._split()

    def _split_due(self) -> bool:
        rotation = self._rotation
        return bool(
            (rotation.max_file_bytes and self._file_bytes >= rotation.max_file_bytes)
            or (
                rotation.max_file_seconds
                and time.monotonic() - self._file_started >= rotation.max_file_seconds
            )
        )

    def _split(self) -> None:
        """Finish the current log and go on in a new one (rotation)."""
        self._finish()
        if self._directory is not None:
            self._open(self._directory)

    def _prune(self, current: Path) -> None:
        """Remove the oldest logs of the folder beyond ``max_total_bytes`` (never ``current``)."""
        limit = self._rotation.max_total_bytes
        if not limit:
            return
        try:
            logs = sorted(current.parent.glob(f"{LOG_PREFIX}_*.mcap"))  # names sort by time
            sizes = {log: log.stat().st_size for log in logs}
        except OSError as error:
            self._logger.warning(f"could not list the logs in {current.parent}: {error}")
            return
        total = sum(sizes.values())
        for log in logs:
            if total <= limit:
                break
            if log == current:
                continue
            try:
                log.unlink()
            except OSError as error:
                self._logger.warning(f"could not remove the old log {log}: {error}")
                continue
            total -= sizes[log]
            self._logger.info(
                f"removed the old log {log} ({sizes[log] / 1e6:.1f} MB): the logs in "
                f"{current.parent} are kept under {limit / 1e6:g} MB (recording.max_total_mb)"
            )

    def _open(self, directory: Path) -> None:
        if self._writer is not None:
            return
        writer = LogWriter(run_log_path(directory), flush_interval=FLUSH_INTERVAL)
        try:
            writer.open()
            for topic, (msgtype, qos) in self._channels.items():
                writer.add_channel(topic, msgtype, qos)
        except RecordingError as error:
            self._failed(error, writer)
            return
        self._writer = writer
        self._file_bytes, self._file_messages = 0, 0
        self._file_started = time.monotonic()
        self._logger.info(f"recording to {writer.path}")
        self._prune(writer.path)

    def _finish(self) -> None:
        writer, self._writer = self._writer, None
        if writer is None:
            return
        try:
            writer.finish()
        except RecordingError as error:
            self._last_error = str(error)
            self._logger.error(f"could not finish the log {writer.path}: {error}")
            return
        self._logger.info(
            f"log finished: {writer.path} ({self._file_messages} messages, "
            f"{self._file_bytes / 1e6:.2f} MB of messages)"
        )

    def _failed(self, error: RecordingError, writer: LogWriter | None = None) -> None:
        """A write failed: recording off (the node keeps serving)."""
        writer = writer or self._writer
        self._writer = None
        self._accepting = False
        self._last_error = str(error)
        self._logger.error(f"recording off: {error}")
        if writer is not None:
            with contextlib.suppress(RecordingError):  # the reason is already reported
                writer.finish()
