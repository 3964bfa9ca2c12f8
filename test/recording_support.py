"""Helpers shared by the recording tests: independent decoding and comparison after decoding.

Compare decoded messages, never raw bytes (Fast-CDR does not zero its padding).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys.msg import normalize_msgtype

NAN = "nan"
EMPTY_MEMBER = "structure_needs_at_least_one_member"  # rosidl's filler of empty messages


def plain(value: Any) -> Any:
    """Turn a message (dict, rosbags dataclass, mcap_ros2 or rclpy object) into comparable
    nested dicts/lists; uint8 arrays become bytes, NaN becomes the string "nan"."""
    if isinstance(value, Mapping):
        return {k: plain(v) for k, v in value.items() if _is_field(k)}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {
            f.name: plain(getattr(value, f.name))
            for f in dataclasses.fields(value)
            if _is_field(f.name)
        }
    if hasattr(value, "get_fields_and_field_types"):  # rclpy
        return {k: plain(getattr(value, k)) for k in value.get_fields_and_field_types()}
    if hasattr(value, "__slots__") and not isinstance(value, (str, bytes)):  # mcap_ros2
        return {k: plain(getattr(value, k)) for k in value.__slots__ if _is_field(k)}
    if isinstance(value, (bytes, bytearray, memoryview)):
        return bytes(value)
    if isinstance(value, np.ndarray):
        if value.dtype == np.uint8:
            return value.tobytes()
        return [plain(v) for v in value.tolist()]
    if hasattr(value, "typecode"):  # array.array of an rclpy message
        return value.tobytes() if value.typecode == "B" else [plain(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, float) and math.isnan(value):
        return NAN
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        return plain(value.item())
    return value


def _is_field(name: str) -> bool:
    return not name.startswith("_") and not name.isupper() and name != EMPTY_MEMBER


def read_with_rosbags_documented(path: Path) -> list[tuple[str, str, Any]]:
    """(topic, type, decoded) as rosbags' documentation reads a bag: ``AnyReader`` with the
    default typestore (ROS 2 Jazzy) plus the log's own definitions, then
    ``reader.deserialize(raw, connection.msgtype)``, nothing else."""
    from rosbags.typesys import Stores, get_typestore

    out = []
    with AnyReader([Path(path)], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        for connection, _, raw in reader.messages():
            out.append(
                (connection.topic, connection.msgtype, reader.deserialize(raw, connection.msgtype))
            )
    return out


FOXGLOVE = Path(__file__).resolve().parent / "foxglove"


def read_with_foxglove(path: Path, tmp_path: Path) -> dict[str, Any]:
    """{topic: {schema, count, messages}} as Foxglove's own libraries read the log
    (``test/foxglove/check_log.mjs``: @mcap/core, @foxglove/rosmsg,
    @foxglove/rosmsg2-serialization, pinned by test/foxglove/package-lock.json).

    Fails the test when a channel is refused or a message does not decode. Skips when the
    npm packages are not installed, unless ``HEXAPOD_REQUIRE_FOXGLOVE`` is set (``make test``
    sets it after ``npm ci``).
    """
    import json
    import os
    import shutil
    import subprocess

    import pytest

    node = shutil.which("node")
    if node is None or not (FOXGLOVE / "node_modules" / "@mcap" / "core").is_dir():
        if os.environ.get("HEXAPOD_REQUIRE_FOXGLOVE"):
            pytest.fail("node or test/foxglove/node_modules missing (run npm ci in test/foxglove)")
        pytest.skip("Foxglove's libraries not installed (npm ci in test/foxglove)")
    out = tmp_path / "foxglove.json"
    done = subprocess.run(
        [node, str(FOXGLOVE / "check_log.mjs"), str(path), str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(out.read_text())


def foxglove_form(value: Any) -> Any:
    """What :func:`plain` gives, in the JSON form check_log.mjs writes: bytes as lists of ints,
    non-finite floats as strings."""
    if isinstance(value, dict):
        return {k: foxglove_form(v) for k, v in value.items()}
    if isinstance(value, list):
        return [foxglove_form(v) for v in value]
    if isinstance(value, bytes):
        return list(value)
    if isinstance(value, float) and math.isinf(value):
        return "infinity" if value > 0 else "-infinity"
    return value


def read_with_rosbags(path: Path) -> list[tuple[str, str, Any]]:
    """(topic, type, decoded) of a finished log with rosbags' AnyReader and the log's own
    schemas (an independent typestore). Channels of the old form (``pkg/srv/X_Request``,
    which rosbags files under ``pkg/srv/msg/X_Request``) are looked up under rosbags' name;
    :func:`read_with_rosbags_documented` is what a user following rosbags' documentation
    does."""
    out = []
    with AnyReader([Path(path)]) as reader:
        for connection, _, raw in reader.messages():
            message = reader.typestore.deserialize_cdr(raw, normalize_msgtype(connection.msgtype))
            out.append((connection.topic, connection.msgtype, message))
    return out


def read_with_mcap_ros2(path: Path) -> list[tuple[str, str, Any]]:
    """(topic, schema name, decoded) with mcap's streaming reader and mcap_ros2's decoder;
    stops quietly where a killed file ends."""
    out = []
    with Path(path).open("rb") as stream:
        reader = NonSeekingReader(stream, decoder_factories=[DecoderFactory()])
        try:
            for schema, channel, _, decoded in reader.iter_decoded_messages(log_time_order=False):
                out.append((channel.topic, schema.name, decoded))
        except (McapError, EOFError, ValueError):
            pass
    return out


def write_foreign_log(path: Path, ours: list[tuple[str, str, bytes]] = ()) -> None:
    """A finished MCAP log with one message of a type nobody here knows (/foo,
    foo_msgs/msg/Bar), then ``ours``: (topic, type, CDR bytes) written with full schemas."""
    from mcap.writer import Writer

    from hexapod_workspace.logs import message_definition

    with Path(path).open("wb") as stream:
        writer = Writer(stream)
        writer.start(profile="ros2")
        foreign = writer.register_schema("foo_msgs/msg/Bar", "ros2msg", b"int32 a\n")
        channel = writer.register_channel("/foo", "cdr", foreign)
        writer.add_message(channel, 1, b"\x00\x01\x00\x00\x07\x00\x00\x00", 1)
        for time_ns, (topic, msgtype, data) in enumerate(ours, start=2):
            schema = writer.register_schema(
                msgtype, "ros2msg", message_definition(msgtype).encode()
            )
            writer.add_message(
                writer.register_channel(topic, "cdr", schema), time_ns, bytes(data), time_ns
            )
        writer.finish()
