"""Reading MCAP logs in the rosbag2 form: tolerant of interrupted files, never a traceback.

:func:`read_log` reads a finished or interrupted file as far as it is intact,
:func:`iter_log` streams it, :func:`recover_log` rewrites the intact part as a finished file.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mcap.records import Channel, Chunk, Footer, Message, Schema
from mcap.stream_reader import StreamReader, breakup_chunk

from hexapod_workspace.errors import LogReadError

from .typestore import MESSAGE_ENCODING, get_typestore, store_name
from .writer import LogWriter

if TYPE_CHECKING:
    pass


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
    damaged : bool
        True when something recorded could not be read: a truncated or corrupt stretch, a
        chunk failing its CRC, a message that does not decode. (A topic of a type unknown here
        is skipped with a note but is not damage.)
    start_ns, end_ns : int or None
        Span of the messages read.
    """

    path: Path
    files: list[Path] = field(default_factory=list)
    topics: dict[str, TopicInfo] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)
    finished: bool = True
    damaged: bool = False
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
                contents.damaged = True
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
                    contents.damaged = True
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
            contents.damaged = True


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
            contents.damaged = True
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
