"""MCAP logs in the rosbag2 form, written and read without ROS.

A log is one bare ``.mcap`` file laid out the way ``rosbag2_storage_mcap`` (ROS 2 Jazzy) writes
it: profile ``ros2``, one schema per type with encoding ``ros2msg`` and the full concatenated
definition (dependencies after lines of 80 ``=`` and ``MSG: pkg/Type``), message encoding
``cdr``, channel metadata ``offered_qos_profiles`` (rosbag2 v9 YAML) and ``topic_type_hash``
(RIHS01), a ``rosbag2`` metadata record, and, once finished, the summary with its Statistics
record. ``ros2 bag play``/``ros2 bag info`` (Jazzy), Foxglove, ``rosbags`` (>= 0.11) and
``mcap_ros2`` read it.

Service calls are recorded as two messages: the request on ``<service>/request`` when it arrives
and the response on ``<service>/response`` when it is sent; the n-th response answers the n-th
request. Their types are the message twins of the service parts (``<pkg>/msg/<Name>Request`` for
``<pkg>/srv/<Name>_Request``, ``std_msgs/msg/Empty`` for an empty part;
:func:`~hexapod_workspace.logs.typestore.recorded_type`), because rosbags files a ``srv`` part
under another name than the one a reader looks up. (Jazzy's ``_service_event`` form nests
``pkg/srv/...`` types inside the event, which the ``ros2msg`` schema parsers of mcap_ros2 and
Foxglove reject.)

Durability: messages are collected in MCAP chunks; a chunk is written and the file flushed when
``flush_messages`` messages are pending, when a :meth:`LogWriter.write` or
:meth:`LogWriter.flush_if_due` finds the oldest pending message ``flush_interval`` seconds old,
when a chunk reaches ``chunk_size`` bytes, or on :meth:`LogWriter.flush`/:meth:`LogWriter.finish`.
Everything flushed survives a SIGKILL of the writing process (it is in the operating system's
hands; ``fsync`` is not called, so a power cut may lose more). An interrupted file has no summary;
:func:`read_log` reads it as far as it is intact, and :func:`recover_log` (or ``mcap recover``)
makes it a finished file again.

The writer has no thread and no queue of its own: it belongs to one thread at a time (like
``mcap.writer.Writer`` and rosbags' ``Writer``). A process that records from several threads
puts one queue in front of it and one thread behind it, as the node's recorder does
(:mod:`hexapod_workspace.ros.recorder`); that thread calls :meth:`LogWriter.flush_if_due` when
idle, which makes ``flush_interval`` the bound on how long a written message stays in memory.

The type store (:func:`get_typestore`) is rosbags' Jazzy store plus the package's own
interfaces (``hexapod_workspace_msgs``, parsed from the shipped ``.msg``/``.srv`` files) plus
``std_srvs/srv/Trigger``; it provides schema text, type hashes and CDR (de)serialisation.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Mapping
from importlib.metadata import version
from pathlib import Path
from typing import Any

from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter

from hexapod_workspace._version import __version__
from hexapod_workspace.errors import RecordingError

from .fields import serialize
from .typestore import (
    MESSAGE_ENCODING,
    PROFILE,
    REQUEST_QOS,
    ROS_DISTRO,
    SCHEMA_ENCODING,
    message_definition,
    type_hash,
)

#: The MCAP header's library string: who wrote the file, with versions (as mcap's own writer
#: and rosbag2_storage_mcap name themselves), so a reader can tell which writer made a log.
LIBRARY = f"hexapod_workspace {__version__}; mcap {version('mcap')}"
#: Seconds after which a pending message is written out by the background flusher.
DEFAULT_FLUSH_INTERVAL = 0.5
#: Pending messages that trigger a write-out at once.
DEFAULT_FLUSH_MESSAGES = 64
#: Bytes of pending messages that close a chunk (rosbag2_storage_mcap's default is 768 KiB).
DEFAULT_CHUNK_SIZE = 1024 * 1024


def run_log_path(
    directory: str | Path, *, prefix: str = "hexapod_workspace", start_ns: int | None = None
) -> Path:
    """Return a fresh log path named by a start time, e.g.
    ``<directory>/hexapod_workspace_20261121T210512.123Z.mcap`` (UTC)."""
    start_ns = time.time_ns() if start_ns is None else start_ns
    seconds, rest = divmod(start_ns, 1_000_000_000)
    stamp = time.strftime("%Y%m%dT%H%M%S", time.gmtime(seconds)) + f".{rest // 1_000_000:03d}Z"
    candidate = Path(directory) / f"{prefix}_{stamp}.mcap"
    index = 1
    while candidate.exists():
        candidate = Path(directory) / f"{prefix}_{stamp}_{index}.mcap"
        index += 1
    return candidate


class LogWriter:
    """Write one MCAP log in the rosbag2 form; a context manager; one owning thread.

    Created closed: :meth:`open` (or ``with``) creates the file, :meth:`finish` (idempotent,
    also on leaving ``with``) writes the summary and closes it.

    Parameters
    ----------
    path : str or Path
        The ``.mcap`` file to create (parent folders are created; an existing file is replaced).
    flush_interval : float
        Seconds: a pending message is flushed by the first :meth:`write` or
        :meth:`flush_if_due` after it is this old (0: only by count, size or :meth:`flush`).
    flush_messages : int
        Pending messages that trigger a write-out at once (>= 1).
    chunk_size : int
        Bytes of pending messages that close a chunk at once (>= 1).

    Raises
    ------
    RecordingError
        A flush setting out of range.
    """

    def __init__(
        self,
        path: str | Path,
        *,
        flush_interval: float = DEFAULT_FLUSH_INTERVAL,
        flush_messages: int = DEFAULT_FLUSH_MESSAGES,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
    ) -> None:
        if not (flush_messages >= 1 and flush_interval >= 0 and chunk_size >= 1):
            msg = (
                f"flush_messages must be >= 1, flush_interval >= 0, chunk_size >= 1; got "
                f"{flush_messages}, {flush_interval}, {chunk_size}"
            )
            raise RecordingError(msg)
        self.path = Path(path)
        self.flush_interval = float(flush_interval)
        self.flush_messages = int(flush_messages)
        self._chunk_size = int(chunk_size)
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, tuple[int, str]] = {}
        self._qos: dict[str, str] = {}
        self._counts: dict[str, int] = {}
        self._pending = 0
        self._oldest_pending = 0.0
        self._first_ns: int | None = None
        self._last_ns = 0
        self._opened = False
        self._closed = False
        self.error: RecordingError | None = None
        self._file: Any = None
        self._mcap: Any = None

    def open(self) -> LogWriter:
        """Create the file and write the MCAP header; returns ``self``.

        Raises
        ------
        RecordingError
            The file cannot be created, or the writer was opened before.
        """
        if self._opened:
            msg = f"MCAP log {self.path} is already open (a LogWriter opens once)"
            raise RecordingError(msg)
        self._opened = True
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = self.path.open("wb")
            self._mcap = McapWriter(
                self._file, chunk_size=self._chunk_size, compression=CompressionType.NONE
            )
            self._mcap.start(profile=PROFILE, library=LIBRARY)
            self._file.flush()
        except OSError as err:
            self._closed = True
            if self._file is not None:
                self._close_file_quietly()
            reason = err.strerror or str(err)
            if isinstance(err, FileExistsError):  # mkdir met a file where a folder should be
                reason = "a file is in the way of its folder"
            msg = f"cannot create MCAP log {self.path}: {reason}"
            raise RecordingError(msg) from err
        return self

    # -- channels and messages

    def add_channel(self, topic: str, msgtype: str, qos: str = REQUEST_QOS) -> int:
        """Register a topic (idempotent) and return its channel id.

        Parameters
        ----------
        topic : str
            Fully qualified topic name, e.g. ``"/hexapod_workspace/workspace_summary"``.
        msgtype : str
            ROS type name, e.g. ``"hexapod_workspace_msgs/msg/WorkspaceSummary"``.
        qos : str
            ``offered_qos_profiles`` text (:func:`qos_profile_text`, :data:`RESULT_QOS`, ...).

        Raises
        ------
        RecordingError
            Unknown type, topic already registered with another type, writer not open, closed
            or failed.
        """
        if topic in self._channels:
            channel_id, known_type = self._channels[topic]
            if known_type != msgtype:
                msg = f"topic {topic} is recorded as {known_type}, not {msgtype}"
                raise RecordingError(msg)
            return channel_id
        self._check_open()
        try:
            schema_text = message_definition(msgtype)
        except KeyError as err:
            msg = f"cannot record {topic}: unknown message type {msgtype!r}"
            raise RecordingError(msg) from err
        if msgtype not in self._schemas:
            self._schemas[msgtype] = self._mcap.register_schema(
                name=msgtype, encoding=SCHEMA_ENCODING, data=schema_text.encode()
            )
        channel_id = self._mcap.register_channel(
            topic=topic,
            message_encoding=MESSAGE_ENCODING,
            schema_id=self._schemas[msgtype],
            metadata={"offered_qos_profiles": qos, "topic_type_hash": type_hash(msgtype)},
        )
        self._channels[topic] = (channel_id, msgtype)
        self._qos[topic] = qos
        self._counts[topic] = 0
        return channel_id

    def write(
        self,
        topic: str,
        data: bytes | bytearray | memoryview,
        log_time_ns: int | None = None,
        *,
        publish_time_ns: int | None = None,
    ) -> None:
        """Append one serialised (CDR) message to a registered topic.

        Parameters
        ----------
        topic : str
            A topic registered with :meth:`add_channel`.
        data : bytes-like
            The CDR bytes (e.g. ``rclpy.serialization.serialize_message(msg)``).
        log_time_ns : int, optional
            Receive/record time, ns since the epoch; default now.
        publish_time_ns : int, optional
            Default ``log_time_ns``.

        Raises
        ------
        RecordingError
            Topic not registered, writer not open or closed, or the file could not be written
            (disk full, ...; the writer is then closed).
        """
        log_time_ns = time.time_ns() if log_time_ns is None else int(log_time_ns)
        publish_time_ns = log_time_ns if publish_time_ns is None else int(publish_time_ns)
        self._check_open()
        channel = self._channels.get(topic)
        if channel is None:
            msg = f"topic {topic!r} is not registered (call add_channel first)"
            raise RecordingError(msg)
        try:
            self._mcap.add_message(
                channel_id=channel[0],
                log_time=log_time_ns,
                data=data,  # copied into the chunk at once: no bytes() copy here
                publish_time=publish_time_ns,
                sequence=self._counts[topic],
            )
        except OSError as err:
            raise self._fail(err) from err
        self._counts[topic] += 1
        self._first_ns = log_time_ns if self._first_ns is None else min(self._first_ns, log_time_ns)
        self._last_ns = max(self._last_ns, log_time_ns)
        if self._pending == 0:
            self._oldest_pending = time.monotonic()
        self._pending += 1
        if self._pending >= self.flush_messages:
            self._flush_pending()
        else:
            self.flush_if_due()

    def write_fields(
        self,
        topic: str,
        msgtype: str,
        fields: Mapping[str, Any] | Any,
        log_time_ns: int | None = None,
        *,
        qos: str = REQUEST_QOS,
    ) -> memoryview:
        """Register the topic if needed, serialise ``fields`` (dict or rosbags message) and
        write it. Returns the CDR bytes written."""
        data = serialize(msgtype, fields)
        self.add_channel(topic, msgtype, qos)
        self.write(topic, data, log_time_ns)
        return data

    # -- flushing and closing

    def flush(self) -> None:
        """Write pending messages out as a chunk and flush the file (no fsync).

        Raises
        ------
        RecordingError
            Not open, closed, or the file could not be written (the writer is then closed).
        """
        self._check_open()
        self._flush_pending()

    def flush_if_due(self) -> bool:
        """Flush when the oldest pending message is ``flush_interval`` s old; True if flushed.

        Raises
        ------
        RecordingError
            The file could not be written (the writer is then closed).
        """
        if self._pending == 0 or self.flush_interval <= 0 or self._closed:
            return False
        if time.monotonic() - self._oldest_pending < self.flush_interval:
            return False
        self._flush_pending()
        return True

    def _flush_pending(self) -> None:
        if self._pending == 0:
            return
        try:
            self._mcap.flush()
        except OSError as err:
            raise self._fail(err) from err
        self._pending = 0

    def _check_open(self) -> None:
        if self.error is not None:
            raise self.error
        if not self._opened:
            msg = f"MCAP log {self.path} is not open (call open() or use `with`)"
            raise RecordingError(msg)
        if self._closed:
            msg = f"MCAP log {self.path} is closed"
            raise RecordingError(msg)

    def _fail(self, err: OSError) -> RecordingError:
        """Close the file without finishing it and remember why."""
        self.error = RecordingError(f"writing MCAP log {self.path} failed: {err.strerror or err}")
        self._closed = True
        self._close_file_quietly()
        return self.error

    def _close_file_quietly(self) -> None:
        # The buffered bytes may not be writable either; the reason is already recorded.
        with contextlib.suppress(OSError):
            self._file.close()

    @property
    def closed(self) -> bool:
        """True after :meth:`finish` or a write failure (False before :meth:`open`)."""
        return self._closed

    @property
    def pending(self) -> int:
        """Messages written but not yet flushed to the file."""
        return self._pending

    @property
    def message_counts(self) -> dict[str, int]:
        """Messages written per topic."""
        return dict(self._counts)

    def finish(self) -> None:
        """Finish the log (summary, Statistics, footer) and close the file. Idempotent; a
        writer that never opened or that failed has nothing to finish.

        Raises
        ------
        RecordingError
            When finishing fails (disk full); the file then stays readable up to its last chunk.
        """
        if self._closed or not self._opened:
            self._closed = True
            return
        self._closed = True
        try:
            self._mcap.add_metadata("rosbag2", self._rosbag2_metadata())
            self._mcap.finish()
            self._file.close()
        except OSError as err:
            raise self._fail(err) from err

    close = finish

    def _rosbag2_metadata(self) -> dict[str, str]:
        """The ``rosbag2`` metadata record rosbag2_storage_mcap writes on close."""
        import yaml

        start = self._first_ns or 0
        duration = max(0, self._last_ns - start)
        count = sum(self._counts.values())
        info = {
            "version": 9,
            "storage_identifier": "mcap",
            "relative_file_paths": [self.path.name],
            "duration": {"nanoseconds": duration},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": count,
            "topics_with_message_count": [
                {
                    "topic_metadata": {
                        "name": topic,
                        "type": msgtype,
                        "serialization_format": MESSAGE_ENCODING,
                        "offered_qos_profiles": yaml.safe_load(self._qos[topic]) or [],
                        "type_description_hash": type_hash(msgtype),
                    },
                    "message_count": self._counts[topic],
                }
                for topic, (_, msgtype) in self._channels.items()
            ],
            "compression_format": "",
            "compression_mode": "",
            "files": [
                {
                    "path": self.path.name,
                    "starting_time": {"nanoseconds_since_epoch": start},
                    "duration": {"nanoseconds": duration},
                    "message_count": count,
                }
            ],
            "custom_data": {},
            "ros_distro": ROS_DISTRO,
        }
        return {
            "serialized_metadata": yaml.safe_dump(info, sort_keys=False),
            "ros_distro": ROS_DISTRO,
        }

    def __enter__(self) -> LogWriter:
        if not self._opened:
            self.open()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.finish()
