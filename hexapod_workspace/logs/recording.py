"""MCAP logs in the rosbag2 form, written and read without ROS.

A log is one bare ``.mcap`` file laid out the way ``rosbag2_storage_mcap`` (ROS 2 Jazzy) writes
it: profile ``ros2``, one schema per type with encoding ``ros2msg`` and the full concatenated
definition (dependencies after lines of 80 ``=`` and ``MSG: pkg/Type``), message encoding
``cdr``, channel metadata ``offered_qos_profiles`` (rosbag2 v9 YAML) and ``topic_type_hash``
(RIHS01), a ``rosbag2`` metadata record, and, once finished, the summary with its Statistics
record. ``ros2 bag play``/``ros2 bag info`` (Jazzy), Foxglove, ``rosbags`` (>= 0.11) and
``mcap_ros2`` read it.

Service calls are recorded as two messages of the generated types: the request
(``<pkg>/srv/<Name>_Request``) on ``<service>/request`` when it arrives and the response
(``<pkg>/srv/<Name>_Response``) on ``<service>/response`` when it is sent; the n-th response
answers the n-th request. (Jazzy's ``_service_event`` form nests ``pkg/srv/...`` types inside
the event, which the ``ros2msg`` schema parsers of mcap_ros2 and Foxglove reject.)

Durability: messages are collected in MCAP chunks and a chunk is written and the file flushed
when ``flush_messages`` messages are pending, when the oldest pending message is
``flush_interval`` seconds old (a background thread), when a chunk reaches ``chunk_size`` bytes,
or on :meth:`LogWriter.flush`/:meth:`LogWriter.close`. Everything flushed survives a SIGKILL of
the writing process (it is in the operating system's hands; ``fsync`` is not called, so a power
cut may lose more). An interrupted file has no summary; :func:`read_log` reads it as far as it
is intact, and :func:`recover_log` (or ``mcap recover``) makes it a finished file again.

The type store (:func:`get_typestore`) is rosbags' Jazzy store plus the package's own
interfaces (``hexapod_workspace_msgs``, parsed from the shipped ``.msg``/``.srv`` files) plus
``std_srvs/srv/Trigger``; it provides schema text, type hashes and CDR (de)serialisation.
"""

from __future__ import annotations

import atexit
import contextlib
import dataclasses
import functools
import queue
import threading
import time
import weakref
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from mcap.records import Channel, Chunk, Footer, Message, Schema
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from rosbags.interfaces import (
    Nodetype,
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2.metadata import dump_qos_v9
from rosbags.typesys import Stores, get_types_from_msg
from rosbags.typesys import get_typestore as _rosbags_typestore
from rosbags.typesys.msg import normalize_msgtype

from hexapod_workspace._resources import data_dir
from hexapod_workspace.errors import LogReadError, RecordingError

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosbags.typesys.store import Typestore

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "DEFAULT_FLUSH_INTERVAL",
    "DEFAULT_FLUSH_MESSAGES",
    "INTERFACE_PACKAGE",
    "REQUEST_QOS",
    "RESULT_QOS",
    "SERVICE_QOS",
    "LogContents",
    "LogMessage",
    "LogWriter",
    "TopicInfo",
    "build_message",
    "deserialize",
    "get_typestore",
    "iter_log",
    "message_definition",
    "message_to_fields",
    "qos_profile_text",
    "read_log",
    "recover_log",
    "run_log_path",
    "serialize",
    "service_topics",
    "store_name",
    "type_hash",
]

INTERFACE_PACKAGE = "hexapod_workspace_msgs"
SCHEMA_ENCODING = "ros2msg"
MESSAGE_ENCODING = "cdr"
PROFILE = "ros2"
ROS_DISTRO = "jazzy"
#: Seconds after which a pending message is written out by the background flusher.
DEFAULT_FLUSH_INTERVAL = 0.5
#: Pending messages that trigger a write-out at once.
DEFAULT_FLUSH_MESSAGES = 64
#: Bytes of pending messages that close a chunk (rosbag2_storage_mcap's default is 768 KiB).
DEFAULT_CHUNK_SIZE = 1024 * 1024

# std_srvs ships no .msg/.srv files in the pip wheels and rosbags' stores hold no services.
_EXTRA_SERVICES = {"std_srvs/srv/Trigger": "---\nbool success\nstring message\n"}
_EMPTY_FIELD = "structure_needs_at_least_one_member"
_DTYPES = {
    "bool": np.bool_,
    "byte": np.uint8,
    "char": np.uint8,
    "int8": np.int8,
    "uint8": np.uint8,
    "int16": np.int16,
    "uint16": np.uint16,
    "int32": np.int32,
    "uint32": np.uint32,
    "int64": np.int64,
    "uint64": np.uint64,
    "float32": np.float32,
    "float64": np.float64,
}


# --------------------------------------------------------------------------- type store


def service_topics(service_name: str) -> tuple[str, str]:
    """Return the topics a service's requests and responses are recorded on.

    Parameters
    ----------
    service_name : str
        Fully qualified, e.g. ``"/hexapod_workspace/check_poses"``.

    Returns
    -------
    (str, str)
        ``("<service>/request", "<service>/response")``; their types are the generated
        ``<pkg>/srv/<Name>_Request`` and ``<pkg>/srv/<Name>_Response``.
    """
    return f"{service_name}/request", f"{service_name}/response"


def _service_types(service_type: str, text: str) -> dict[str, Any]:
    """Parse a ``.srv`` text into its ``_Request`` and ``_Response`` type definitions.

    Keys are rosbags' normalised names (``pkg/srv/msg/Name_Request``), which its schema
    generator turns back into ROS names (``pkg/srv/Name_Request``).
    """
    lines = text.splitlines()
    split = next((i for i, line in enumerate(lines) if line.strip() == "---"), len(lines))
    parts = {
        "Request": "\n".join(lines[:split]),
        "Response": "\n".join(lines[split + 1 :]),
    }
    types: dict[str, Any] = {}
    for suffix, part in parts.items():
        for name, (consts, fields, *rest) in get_types_from_msg(
            part, f"{service_type}_{suffix}"
        ).items():
            if not fields:  # rosidl gives an empty structure one uint8 member on the wire
                fields = [(_EMPTY_FIELD, (Nodetype.BASE, ("uint8", 0)))]
            own = {store_name(f"{service_type}_{x}") for x in parts}
            fields = [(fname, _package_relative(desc, own)) for fname, desc in fields]
            types[name] = (consts, fields, *rest)
    return types


def _package_relative(desc: tuple[int, Any], own: set[str]) -> tuple[int, Any]:
    """Resolve a relative type of a .srv (``TiltTorsion``) in ``pkg/msg`` as rosidl does; rosbags
    resolves it next to the service (``pkg/srv/msg/TiltTorsion``)."""
    nodetype, detail = desc
    if nodetype == Nodetype.NAME:
        if "/srv/msg/" in detail and detail not in own:
            return (nodetype, detail.replace("/srv/msg/", "/msg/"))
        return desc
    if nodetype in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        subdesc, length = detail
        return (nodetype, (_package_relative(subdesc, own), length))
    return desc


def store_name(msgtype: str) -> str:
    """Return the type store's key for a ROS type name (``pkg/srv/X`` -> ``pkg/srv/msg/X``)."""
    return normalize_msgtype(msgtype)


@functools.cache
def get_typestore() -> Typestore:
    """Return the type store used for every log: Jazzy + hexapod_workspace_msgs + std_srvs.

    Returns
    -------
    rosbags.typesys.store.Typestore
        Shared, built once per process. Holds ``hexapod_workspace_msgs/msg/*``, the services'
        ``/srv/<Name>_Request`` and ``_Response`` types, and
        ``std_srvs/srv/Trigger_*``.
    """
    store = _rosbags_typestore(Stores.ROS2_JAZZY)
    types: dict[str, Any] = {}
    for path in sorted(data_dir("msg").glob("*.msg")):
        types.update(
            get_types_from_msg(
                path.read_text(encoding="utf-8"), f"{INTERFACE_PACKAGE}/msg/{path.stem}"
            )
        )
    store.register(types)
    services: dict[str, Any] = {}
    for path in sorted(data_dir("srv").glob("*.srv")):
        text = path.read_text(encoding="utf-8")
        services.update(_service_types(f"{INTERFACE_PACKAGE}/srv/{path.stem}", text))
    for service_type, text in _EXTRA_SERVICES.items():
        services.update(_service_types(service_type, text))
    store.register(services)
    return store


@functools.cache
def message_definition(msgtype: str) -> str:
    """Return the full ``ros2msg`` schema text of a type, dependencies concatenated.

    Raises
    ------
    KeyError
        When the type is not in :func:`get_typestore`.
    """
    store = get_typestore()
    if store_name(msgtype) not in store.fielddefs:
        msg = f"unknown ROS type {msgtype!r}"
        raise KeyError(msg)
    return store.generate_msgdef(store_name(msgtype), ros_version=2)[0]


@functools.cache
def _hash_store() -> Typestore:
    """A store whose service types carry their ROS names (``pkg/srv/X_Request``): the RIHS01
    hash includes the type name, and :func:`get_typestore` keys them ``pkg/srv/msg/X_Request``."""
    store = _rosbags_typestore(Stores.ROS2_JAZZY)
    fielddefs = get_typestore().fielddefs
    store.register(
        {k: v for k, v in fielddefs.items() if k.startswith(f"{INTERFACE_PACKAGE}/msg/")}
    )
    store.register(
        {k.replace("/srv/msg/", "/srv/"): v for k, v in fielddefs.items() if "/srv/msg/" in k}
    )
    return store


@functools.cache
def type_hash(msgtype: str) -> str:
    """Return the type's RIHS01 hash (``RIHS01_<64 hex>``), as rosbag2 Jazzy stores it (the
    same value rclpy reports as ``topic_type_hash``)."""
    message_definition(msgtype)  # same KeyError for unknown types
    return _hash_store().hash_rihs01(msgtype)


def qos_profile_text(
    *,
    reliability: str = "reliable",
    durability: str = "volatile",
    history: str = "keep_last",
    depth: int = 10,
) -> str:
    """Return the ``offered_qos_profiles`` channel metadata text for one publisher.

    Parameters
    ----------
    reliability : {"reliable", "best_effort"}
    durability : {"volatile", "transient_local"}
    history : {"keep_last", "keep_all"}
    depth : int
        History depth.

    Returns
    -------
    str
        YAML list with one profile in the rosbag2 v9 layout (as ``ros2 bag record`` stores it).
    """
    import yaml

    infinite = QosTime(0x7FFFFFFF, 0xFFFFFFFF)  # rmw's "infinite" duration in rosbag2 metadata
    profile = Qos(
        QosHistory[history.upper()],
        depth,
        QosReliability[reliability.upper()],
        QosDurability[durability.upper()],
        infinite,
        infinite,
        QosLiveliness.AUTOMATIC,
        infinite,
        False,
    )
    return yaml.safe_dump(dump_qos_v9([profile]), sort_keys=False).strip()


#: Request topics (commands coming in): reliable, volatile, depth 10.
REQUEST_QOS = qos_profile_text()
#: Result topics (summaries, boundaries, reachability): reliable, transient local, depth 1.
RESULT_QOS = qos_profile_text(durability="transient_local", depth=1)
#: Service request/response topics (rmw's services default: reliable, volatile, depth 10).
SERVICE_QOS = qos_profile_text()


# --------------------------------------------------------------------------- dicts <-> messages


def _default(desc: tuple[int, Any], store: Typestore) -> Any:
    nodetype, detail = desc
    if nodetype == Nodetype.BASE:
        typename = detail[0]
        return "" if typename == "string" else _DTYPES[typename](0).item()
    if nodetype == Nodetype.NAME:
        return build_message(detail, {}, store=store)
    (subtype, subdetail), length = detail
    if nodetype == Nodetype.ARRAY:
        if subtype == Nodetype.BASE and subdetail[0] != "string":
            return np.zeros(length, dtype=_DTYPES[subdetail[0]])
        return [_default((subtype, subdetail), store) for _ in range(length)]
    if subtype == Nodetype.BASE and subdetail[0] != "string":
        return np.zeros(0, dtype=_DTYPES[subdetail[0]])
    return []


def _convert(desc: tuple[int, Any], value: Any, store: Typestore) -> Any:
    nodetype, detail = desc
    if nodetype == Nodetype.BASE:
        return value
    if nodetype == Nodetype.NAME:
        return (
            value if not isinstance(value, Mapping) else build_message(detail, value, store=store)
        )
    (subtype, subdetail), _ = detail
    if subtype == Nodetype.BASE and subdetail[0] != "string":
        if isinstance(value, bytes | bytearray | memoryview):
            return np.frombuffer(value, dtype=_DTYPES[subdetail[0]])
        return np.asarray(value, dtype=_DTYPES[subdetail[0]])
    return [_convert((subtype, subdetail), item, store) for item in value]


def build_message(
    msgtype: str, fields: Mapping[str, Any], *, store: Typestore | None = None
) -> Any:
    """Build a rosbags message object from a nested dict keyed by ROS field names.

    Missing fields take ROS defaults (0, "", empty arrays, default sub-messages). Nested
    messages are dicts, message arrays are lists of dicts, numeric arrays anything
    :func:`numpy.asarray` takes (``bytes`` for ``uint8[]``).

    Parameters
    ----------
    msgtype : str
        E.g. ``"hexapod_workspace_msgs/msg/WorkspaceSummary"``.
    fields : mapping
        Field values by name.
    store : Typestore, optional
        Defaults to :func:`get_typestore`.

    Raises
    ------
    KeyError
        Unknown type or a field the type does not have.
    """
    store = store if store is not None else get_typestore()
    msgtype = store_name(msgtype)
    if msgtype not in store.fielddefs:
        msg = f"unknown ROS type {msgtype!r}"
        raise KeyError(msg)
    field_descs = store.fielddefs[msgtype][1]
    known = {name for name, _ in field_descs}
    unknown = set(fields) - known
    if unknown:
        msg = f"{msgtype} has no field(s) {sorted(unknown)}; fields are {sorted(known)}"
        raise KeyError(msg)
    values = {
        name: _convert(desc, fields[name], store) if name in fields else _default(desc, store)
        for name, desc in field_descs
    }
    return store.types[msgtype](**values)


def serialize(msgtype: str, fields: Mapping[str, Any] | Any) -> memoryview:
    """Serialise a message (a field dict or a rosbags message object) to little-endian CDR.

    Returns a read-only bytes-like view (no copy of large payloads); ``bytes(...)`` it to keep.
    """
    store = get_typestore()
    message = build_message(msgtype, fields, store=store) if isinstance(fields, Mapping) else fields
    return store.serialize_cdr(message, store_name(msgtype)).toreadonly()


def deserialize(msgtype: str, data: bytes | memoryview) -> Any:
    """Decode CDR bytes into a rosbags message object (dataclass with numpy arrays)."""
    return get_typestore().deserialize_cdr(data, store_name(msgtype))


def message_to_fields(message: Any) -> Any:
    """Turn a decoded message (rosbags dataclass, or anything with ``get_fields_and_field_types``)
    into nested dicts and lists; numeric arrays stay numpy arrays."""
    if dataclasses.is_dataclass(message) and not isinstance(message, type):
        return {
            f.name: message_to_fields(getattr(message, f.name))
            for f in dataclasses.fields(message)
            # constants are upper case; rosbags adds __msgtype__
            if f.name != _EMPTY_FIELD and not f.name.startswith("__") and not f.name.isupper()
        }
    if hasattr(message, "get_fields_and_field_types"):  # an rclpy message
        return {
            name: message_to_fields(getattr(message, name))
            for name in message.get_fields_and_field_types()
        }
    if isinstance(message, list | tuple):
        return [message_to_fields(item) for item in message]
    return message


# --------------------------------------------------------------------------- writer


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


def _flusher(ref: weakref.ref[LogWriter], stop: threading.Event, interval: float) -> None:
    while not stop.wait(interval):
        writer = ref()
        if writer is None:
            return
        writer._flush_if_due()
        del writer


class LogWriter:
    """Write one MCAP log in the rosbag2 form; thread-safe; a context manager.

    Parameters
    ----------
    path : str or Path
        The ``.mcap`` file to create (parent folders are created; an existing file is replaced).
    flush_interval : float
        Seconds: a pending message is on disk at most this long after :meth:`write` returned
        (background thread; 0 disables the timer).
    flush_messages : int
        Pending messages that trigger a write-out at once (>= 1).
    chunk_size : int
        Bytes of pending messages that close a chunk at once.
    on_error : callable, optional
        Called with the :class:`RecordingError` when a background flush or a background write
        fails (the writer is then closed; the node uses it to turn recording off).
    background : bool
        :meth:`write` only queues the message; a worker thread writes it (in order). A service
        then does not wait for the disk. :meth:`flush` and :meth:`close` wait for the queue.

    Raises
    ------
    RecordingError
        When the file cannot be created.
    """

    def __init__(
        self,
        path: str | Path,
        *,
        flush_interval: float = DEFAULT_FLUSH_INTERVAL,
        flush_messages: int = DEFAULT_FLUSH_MESSAGES,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
        on_error: Callable[[RecordingError], None] | None = None,
        background: bool = False,
    ) -> None:
        if flush_messages < 1 or flush_interval < 0 or chunk_size < 1:
            msg = (
                f"flush_messages must be >= 1, flush_interval >= 0, chunk_size >= 1; got "
                f"{flush_messages}, {flush_interval}, {chunk_size}"
            )
            raise ValueError(msg)
        self.path = Path(path)
        self.flush_interval = float(flush_interval)
        self.flush_messages = int(flush_messages)
        self._on_error = on_error
        self._lock = threading.RLock()
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, tuple[int, str]] = {}
        self._qos: dict[str, str] = {}
        self._counts: dict[str, int] = {}
        self._pending = 0
        self._oldest_pending = 0.0
        self._first_ns: int | None = None
        self._last_ns = 0
        self._closed = False
        self.error: RecordingError | None = None
        self._file = None
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = self.path.open("wb")
            self._mcap = McapWriter(
                self._file, chunk_size=chunk_size, compression=CompressionType.NONE
            )
            self._mcap.start(profile=PROFILE, library="hexapod_workspace (python mcap)")
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
        self._queue: queue.Queue[Any] | None = queue.Queue() if background else None
        self._worker: threading.Thread | None = None
        if background:
            self._worker = threading.Thread(target=self._drain, name="mcap-log-writer", daemon=True)
            self._worker.start()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        if self.flush_interval > 0:
            self._thread = threading.Thread(
                target=_flusher,
                args=(weakref.ref(self), self._stop, self.flush_interval / 2),
                name="mcap-log-flusher",
                daemon=True,
            )
            self._thread.start()
        atexit.register(self.close)

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
        KeyError
            Unknown type. ValueError: topic already registered with another type.
        RecordingError
            The writer is closed or failed.
        """
        with self._lock:
            if topic in self._channels:
                channel_id, known_type = self._channels[topic]
                if known_type != msgtype:
                    msg = f"topic {topic} is recorded as {known_type}, not {msgtype}"
                    raise ValueError(msg)
                return channel_id
            self._check_open()
            schema_text = message_definition(msgtype)
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
        KeyError
            Topic not registered.
        RecordingError
            The file could not be written (disk full, ...); the writer is closed.
        """
        log_time_ns = time.time_ns() if log_time_ns is None else int(log_time_ns)
        publish_time_ns = log_time_ns if publish_time_ns is None else int(publish_time_ns)
        with self._lock:
            self._check_open()
            if topic not in self._channels:
                msg = f"topic {topic!r} is not registered (call add_channel first)"
                raise KeyError(msg)
            if self._queue is None:
                self._write_locked(topic, data, log_time_ns, publish_time_ns)
                return
        self._queue.put((topic, data, log_time_ns, publish_time_ns))

    def _write_locked(
        self,
        topic: str,
        data: bytes | bytearray | memoryview,
        log_time_ns: int,
        publish_time_ns: int,
    ) -> None:
        try:
            self._mcap.add_message(
                channel_id=self._channels[topic][0],
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
            self._flush_locked()

    def _drain(self) -> None:
        """Background mode: write queued messages in order until the stop sentinel."""
        assert self._queue is not None
        while True:
            item = self._queue.get()
            try:
                if item is None:
                    return
                with self._lock:
                    if self._closed:
                        continue  # failed earlier: what is still queued is dropped
                    try:
                        self._write_locked(*item)
                    except RecordingError as err:
                        if self._on_error is not None:
                            self._on_error(err)
            finally:
                self._queue.task_done()

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
            The file could not be written; the writer is closed.
        """
        if self._queue is not None:
            self._queue.join()
        with self._lock:
            self._check_open()
            self._flush_locked()

    def _flush_locked(self) -> None:
        if self._pending == 0:
            return
        try:
            self._mcap.flush()
        except OSError as err:
            raise self._fail(err) from err
        self._pending = 0

    def _flush_if_due(self) -> None:
        with self._lock:
            if self._closed or self._pending == 0:
                return
            if time.monotonic() - self._oldest_pending < self.flush_interval / 2:
                return
            try:
                self._flush_locked()
            except RecordingError as err:
                if self._on_error is not None:
                    self._on_error(err)

    def _check_open(self) -> None:
        if self.error is not None:
            raise self.error
        if self._closed:
            msg = f"MCAP log {self.path} is closed"
            raise RecordingError(msg)

    def _fail(self, err: OSError) -> RecordingError:
        """Close the file without finishing it and remember why."""
        self.error = RecordingError(f"writing MCAP log {self.path} failed: {err.strerror or err}")
        self._closed = True
        self._stop.set()
        self._close_file_quietly()
        return self.error

    def _close_file_quietly(self) -> None:
        # The buffered bytes may not be writable either; the reason is already recorded.
        with contextlib.suppress(OSError):
            self._file.close()

    @property
    def closed(self) -> bool:
        """True after :meth:`close` or a write failure."""
        return self._closed

    @property
    def message_counts(self) -> dict[str, int]:
        """Messages written per topic."""
        with self._lock:
            return dict(self._counts)

    def close(self) -> None:
        """Finish the log (summary, Statistics, footer) and close the file. Idempotent.

        Raises
        ------
        RecordingError
            When finishing fails (disk full); the file then stays readable up to its last chunk.
        """
        if self._worker is not None and self._worker is not threading.current_thread():
            self._queue.put(None)
            self._worker.join()
            self._worker = None
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._stop.set()
            atexit.unregister(self.close)
            try:
                self._mcap.add_metadata("rosbag2", self._rosbag2_metadata())
                self._mcap.finish()
                self._file.close()
            except OSError as err:
                raise self._fail(err) from err
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join()

    finish = close

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
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


# --------------------------------------------------------------------------- reader


@dataclass(frozen=True)
class LogMessage:
    """One recorded message.

    Attributes
    ----------
    topic, msgtype : str
    log_time_ns, publish_time_ns : int
        ns since the epoch.
    data : bytes
        The CDR bytes as recorded.
    message : object or None
        The decoded rosbags message (``None`` when ``decode=False``).
    """

    topic: str
    msgtype: str
    log_time_ns: int
    publish_time_ns: int
    data: bytes = field(repr=False)
    message: Any = field(default=None, repr=False)


@dataclass
class TopicInfo:
    """A recorded topic: type, QoS text and how many of its messages were read."""

    topic: str
    msgtype: str
    qos: str
    count: int = 0
    decoded: int = 0


@dataclass
class LogContents:
    """What :func:`iter_log` found; filled while iterating.

    Attributes
    ----------
    files : list of Path
        The MCAP files read.
    topics : dict
        Topic name -> :class:`TopicInfo`.
    problems : list of str
        One line per thing that could not be read (truncation, corruption, unknown types).
    finished : bool
        True when every file ended with a valid footer (a cleanly closed log).
    start_ns, end_ns : int or None
        Span of the messages read.
    """

    path: Path
    files: list[Path] = field(default_factory=list)
    topics: dict[str, TopicInfo] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    finished: bool = True
    start_ns: int | None = None
    end_ns: int | None = None
    messages: list[LogMessage] = field(default_factory=list)

    @property
    def message_count(self) -> int:
        """Messages read (decoded or not)."""
        return sum(info.count for info in self.topics.values())


def _log_files(path: Path, problems: list[str]) -> list[Path]:
    """The MCAP files of a bare file or a bag directory (metadata.yaml order, else by name)."""
    if path.is_file():
        return [path]
    if not path.is_dir():
        msg = f"{path}: no such file or directory"
        raise LogReadError(msg)
    metadata = path / "metadata.yaml"
    if metadata.is_file():
        import yaml

        try:
            info = yaml.safe_load(metadata.read_text(encoding="utf-8"))[
                "rosbag2_bagfile_information"
            ]
            names = list(info["relative_file_paths"])
            storage = info.get("storage_identifier", "mcap")
        except (yaml.YAMLError, KeyError, TypeError, OSError, UnicodeDecodeError) as err:
            problems.append(f"{metadata}: unreadable ({type(err).__name__}); reading *.mcap")
        else:
            if storage != "mcap":
                msg = f"{path}: storage {storage!r} is not supported (only mcap)"
                raise LogReadError(msg)
            files = [path / name for name in names]
            missing = [f.name for f in files if not f.is_file()]
            if missing:
                problems.append(f"{path}: files listed in metadata.yaml are missing: {missing}")
            return [f for f in files if f.is_file()]
    files = sorted(path.glob("*.mcap"))
    if not files:
        msg = f"{path}: a directory without metadata.yaml or .mcap files"
        raise LogReadError(msg)
    return files


def _records(path: Path, contents: LogContents) -> Iterator[Any]:
    """Records of one file in order; a chunk failing its CRC is skipped, reading stops at the
    first record that cannot be framed (truncation)."""
    with path.open("rb") as stream:
        reader = StreamReader(stream, emit_chunks=True, validate_crcs=False)
        records = reader.records
        saw_footer = False
        while True:
            offset = stream.tell()
            try:
                record = next(records)
            except StopIteration:
                break
            except Exception as err:  # any failure to frame or parse a record is damage
                contents.finished = False
                reason = str(err) or type(err).__name__
                contents.problems.append(
                    f"{path.name}: unreadable from about byte {offset} on ({reason}); "
                    "the log is truncated or corrupt there"
                )
                return
            if isinstance(record, Chunk):
                try:
                    yield from breakup_chunk(record, validate_crc=True)
                except Exception as err:  # any failure to frame or parse a record is damage
                    contents.problems.append(
                        f"{path.name}: a chunk of {record.uncompressed_size} bytes near byte "
                        f"{offset} is corrupt ({err}); its messages are skipped"
                    )
                continue
            if isinstance(record, Footer):
                saw_footer = True
            yield record
        if not saw_footer:
            contents.finished = False


def iter_log(
    path: str | Path, contents: LogContents | None = None, *, decode: bool = True
) -> Iterator[LogMessage]:
    """Iterate over the messages of a log in file order, tolerating damage.

    Parameters
    ----------
    path : str or Path
        A bare ``.mcap`` file or a rosbag2 bag directory (``metadata.yaml`` + ``.mcap`` files;
        without ``metadata.yaml`` every ``*.mcap`` in name order).
    contents : LogContents, optional
        Filled while iterating (topics, counts, problems, span); pass one to inspect them.
    decode : bool
        Decode messages with :func:`get_typestore`. Topics whose type the store does not know
        (or whose encoding is not cdr) are skipped with one note each.

    Yields
    ------
    LogMessage

    Raises
    ------
    LogReadError
        The path does not exist, is not a log, or a file cannot be opened.
    """
    path = Path(path)
    contents = contents if contents is not None else LogContents(path)
    contents.files = _log_files(path, contents.problems)
    store = get_typestore()
    for file in contents.files:
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        skipped: dict[str, int] = {}
        broken: dict[str, int] = {}
        try:
            with file.open("rb") as probe:
                if probe.read(8) != b"\x89MCAP0\r\n":
                    msg = f"{file}: not an MCAP file"
                    raise LogReadError(msg)
        except OSError as err:
            msg = f"{file}: cannot open ({err.strerror or err})"
            raise LogReadError(msg) from err
        for record in _records(file, contents):
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
                schema = schemas.get(record.schema_id)
                msgtype = schema.name if schema is not None else ""
                if record.topic not in contents.topics:
                    contents.topics[record.topic] = TopicInfo(
                        record.topic, msgtype, record.metadata.get("offered_qos_profiles", "")
                    )
            elif isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is None:
                    broken["<unknown channel>"] = broken.get("<unknown channel>", 0) + 1
                    continue
                info = contents.topics[channel.topic]
                info.count += 1
                contents.start_ns = min(contents.start_ns or record.log_time, record.log_time)
                contents.end_ns = max(contents.end_ns or record.log_time, record.log_time)
                message = None
                if decode:
                    if channel.message_encoding != MESSAGE_ENCODING or (
                        store_name(info.msgtype) not in store.fielddefs
                    ):
                        skipped[channel.topic] = skipped.get(channel.topic, 0) + 1
                        continue
                    try:
                        message = store.deserialize_cdr(record.data, store_name(info.msgtype))
                    except Exception:
                        broken[channel.topic] = broken.get(channel.topic, 0) + 1
                        continue
                    info.decoded += 1
                yield LogMessage(
                    channel.topic,
                    info.msgtype,
                    record.log_time,
                    record.publish_time,
                    bytes(record.data),
                    message,
                )
        for topic, count in skipped.items():
            info = contents.topics[topic]
            contents.problems.append(
                f"{topic}: type {info.msgtype or '(no schema)'} is unknown here; "
                f"{count} message(s) skipped"
            )
        for topic, count in broken.items():
            contents.problems.append(f"{topic}: {count} message(s) could not be decoded")


def read_log(path: str | Path, *, decode: bool = True) -> LogContents:
    """Read a whole log into memory (:attr:`LogContents.messages`); see :func:`iter_log`."""
    contents = LogContents(Path(path))
    contents.messages = list(iter_log(path, contents, decode=decode))
    return contents


def recover_log(source: str | Path, target: str | Path) -> LogContents:
    """Rewrite what is intact in a damaged or unfinished log as a finished one.

    A log cut short (SIGKILL, power loss, full disk) has no summary, so tools that need one
    (``ros2 bag play``, rosbags' readers) refuse it; :func:`read_log` and ``mcap_ros2``'s
    streaming reader read it as far as it is intact. This copies every readable message of a
    known type, unchanged (same bytes, times, topics, QoS metadata), into ``target`` and finishes
    it. Like ``mcap recover``, but in the rosbag2 form of :class:`LogWriter`.

    Parameters
    ----------
    source : str or Path
        The damaged log (bare ``.mcap`` or bag directory).
    target : str or Path
        The ``.mcap`` file to write (replaced if it exists).

    Returns
    -------
    LogContents
        What was read from ``source`` (topics, counts, problems).

    Raises
    ------
    LogReadError
        ``source`` cannot be read at all.
    RecordingError
        ``target`` cannot be written.
    """
    contents = LogContents(Path(source))
    with LogWriter(target, flush_interval=0) as writer:
        for item in iter_log(source, contents):
            writer.add_channel(item.topic, item.msgtype, contents.topics[item.topic].qos)
            writer.write(
                item.topic, item.data, item.log_time_ns, publish_time_ns=item.publish_time_ns
            )
    return contents
