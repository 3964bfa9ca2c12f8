"""Tests of hexapod_workspace.logs: rosbag2-form MCAP writing, durability, tolerant reading.

Every recorded message is decoded by two independent readers (rosbags' AnyReader with the log's
own schemas, and mcap + mcap_ros2) and compared with what was written, after decoding.
"""

from __future__ import annotations

import io
import signal
import subprocess
import sys
import textwrap
import threading
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader
from recording_support import (
    foxglove_form,
    plain,
    read_with_foxglove,
    read_with_mcap_ros2,
    read_with_rosbags,
    read_with_rosbags_documented,
    write_foreign_log,
)
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Rosbag2Writer
from rosbags.rosbag2.metadata import parse_qos

from hexapod_workspace import logs
from hexapod_workspace._resources import data_dir, example_config_path
from hexapod_workspace.cli.replay import run_replay
from hexapod_workspace.core.evaluation import check as constraints
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.errors import LogReadError, RecordingError
from hexapod_workspace.logs import messages

SUMMARY = "hexapod_workspace_msgs/msg/WorkspaceSummary"
CLOUD = "sensor_msgs/msg/PointCloud2"


def sample_messages() -> list[tuple[str, str, str, dict]]:
    """(topic, type, qos, fields) of every topic and every service the node records, in the
    recorded form (service parts as their message twins), from real check results."""
    manipulator = load_manipulator(example_config_path())
    angles = np.radians([[0.0, 0.0, 0.0], [30.0, 20.0, 5.0], [45.0, 80.0, 10.0]])
    result = constraints.check(manipulator, angles)
    rng = np.random.default_rng(7)
    points = rng.normal(size=(50, 6))
    summary = messages.summary_fields(
        None,
        stamp_ns=10,
        frame_id="base",
        kind=1,
        position=[0, 0, 1],
        reference_reachable=False,
        message="reference orientation unreachable",
    )
    topics, types = messages.TOPICS, messages.TYPES
    check_req, check_resp = logs.service_topics(topics["check_poses"])
    cw_req, cw_resp = logs.service_topics(topics["compute_workspace"])
    return [
        (
            topics["commanded_pose"],
            types["commanded_pose"],
            logs.REQUEST_QOS,
            messages.commanded_pose_fields(angles[1], result.position, request_id="c1"),
        ),
        (
            topics["reachability"],
            types["reachability"],
            logs.RESULT_QOS,
            messages.reachability_result_fields(
                result,
                position=result.position,
                angles=angles[1],
                stamp_ns=11,
                frame_id="base",
                request_id="c1",
                index=1,
            ),
        ),
        (
            topics["workspace_request"],
            types["workspace_request"],
            logs.REQUEST_QOS,
            messages.workspace_request_fields(1, [0, 0, 1], request_id="w1", n_rays=36),
        ),
        (topics["workspace_summary"], types["workspace_summary"], logs.RESULT_QOS, summary),
        (
            topics["projected_workspace"],
            types["projected_workspace"],
            logs.RESULT_QOS,
            messages.pointcloud_fields(points, frame_id="base", stamp_ns=10),
        ),
        (
            topics["orientation_workspace"],
            types["orientation_workspace"],
            logs.RESULT_QOS,
            messages.pointcloud_fields(points[:20], frame_id="base", stamp_ns=12),
        ),
        (
            check_req,
            logs.recorded_type(types["check_poses"] + "_Request"),
            logs.SERVICE_QOS,
            messages.check_poses_request_fields(result.position, angles),
        ),
        (
            check_resp,
            logs.recorded_type(types["check_poses"] + "_Response"),
            logs.SERVICE_QOS,
            messages.check_poses_response_fields(result),
        ),
        *(
            item
            for service in ("compute_projected_workspace", "compute_orientation_workspace")
            for item in (
                (
                    logs.service_topics(topics[service])[0],
                    logs.recorded_type("std_srvs/srv/Trigger_Request"),
                    logs.SERVICE_QOS,
                    {},
                ),
                (
                    logs.service_topics(topics[service])[1],
                    logs.recorded_type("std_srvs/srv/Trigger_Response"),
                    logs.SERVICE_QOS,
                    {"success": True, "message": f"{service}: done"},
                ),
            )
        ),
        (
            cw_req,
            logs.recorded_type(types["compute_workspace"] + "_Request"),
            logs.SERVICE_QOS,
            {"request": messages.workspace_request_fields(2, [0, 0, 1])},
        ),
        (
            cw_resp,
            logs.recorded_type(types["compute_workspace"] + "_Response"),
            logs.SERVICE_QOS,
            messages.compute_workspace_response_fields(
                None, stamp_ns=10, frame_id="base", summary=summary
            ),
        ),
    ]


@pytest.fixture(scope="module")
def finished_log(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list]:
    path = tmp_path_factory.mktemp("log") / "session.mcap"
    written = []
    with logs.LogWriter(path) as writer:
        for i, (topic, msgtype, qos, fields) in enumerate(sample_messages()):
            writer.write_fields(topic, msgtype, fields, 1_000_000_000 + i, qos=qos)
            written.append((topic, msgtype, plain(fields)))
    return path, written


def test_typestore_has_every_interface_with_full_definitions() -> None:
    for path in data_dir("msg").glob("*.msg"):
        text = logs.message_definition(f"hexapod_workspace_msgs/msg/{path.stem}")
        assert text.strip() or path.stem == "Empty"
    text = logs.message_definition("hexapod_workspace_msgs/srv/CheckPoses_Request")
    assert "=" * 80 + "\nMSG: hexapod_workspace_msgs/TiltTorsion\n" in text
    assert "MSG: geometry_msgs/Point" in text
    summary = logs.message_definition(SUMMARY)
    assert "MSG: builtin_interfaces/Time" in summary  # ROS 2 form, not ROS 1 "time"
    assert logs.type_hash(SUMMARY).startswith("RIHS01_")
    with pytest.raises(KeyError, match="unknown ROS type"):
        logs.message_definition("nope_msgs/msg/Nope")


def test_every_message_decodes_with_rosbags_and_mcap_ros2(finished_log) -> None:
    path, written = finished_log
    expected = [(topic, msgtype, fields) for topic, msgtype, fields in written]
    by_rosbags = [(t, m, plain(msg)) for t, m, msg in read_with_rosbags(path)]
    by_mcap_ros2 = [(t, m, plain(msg)) for t, m, msg in read_with_mcap_ros2(path)]
    ours = [(m.topic, m.msgtype, plain(m.message)) for m in logs.read_log(path).messages]
    assert by_rosbags == expected
    assert by_mcap_ros2 == expected
    assert ours == expected


def test_rosbag2_form_schemas_channels_statistics_metadata(finished_log) -> None:
    path, written = finished_log
    with path.open("rb") as stream:
        reader = make_reader(stream)
        header = reader.get_header()
        summary = reader.get_summary()
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    assert header.profile == "ros2"
    assert summary.statistics.message_count == len(written)
    assert summary.statistics.channel_count == len({t for t, _, _ in written})
    assert all(s.encoding == "ros2msg" for s in summary.schemas.values())
    for channel in summary.channels.values():
        assert channel.message_encoding == "cdr"
        qos = parse_qos(channel.metadata["offered_qos_profiles"])
        assert len(qos) == 1
        schema = summary.schemas[channel.schema_id]
        assert channel.metadata["topic_type_hash"] == logs.type_hash(schema.name)
    result_channel = next(
        c for c in summary.channels.values() if c.topic.endswith("/workspace_summary")
    )
    assert parse_qos(result_channel.metadata["offered_qos_profiles"])[0].durability.name == (
        "TRANSIENT_LOCAL"
    )
    info = yaml.safe_load(metadata["rosbag2"]["serialized_metadata"])
    assert info["message_count"] == len(written) and info["storage_identifier"] == "mcap"
    assert metadata["rosbag2"]["ros_distro"] == "jazzy"


def test_bag_directory_written_by_rosbags_is_read(tmp_path: Path) -> None:
    """The other rosbag2 form (directory + metadata.yaml), written by an independent writer."""
    bag = tmp_path / "bag"
    store = logs.get_typestore()
    fields = messages.summary_fields(
        None, stamp_ns=3, frame_id="base", kind=0, position=[0, 0, 1], message="bad"
    )
    with Rosbag2Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection("/hexapod_workspace/summary", SUMMARY, typestore=store)
        writer.write(connection, 5, logs.serialize(SUMMARY, fields))
    contents = logs.read_log(bag)
    assert [plain(m.message) for m in contents.messages] == [plain(fields)]
    assert contents.finished and not contents.problems
    (bag / "metadata.yaml").unlink()  # a killed `ros2 bag record` leaves no metadata.yaml
    assert len(logs.read_log(bag).messages) == 1


def test_finish_is_idempotent_and_misuse_raises_recording_error(tmp_path: Path) -> None:
    writer = logs.LogWriter(tmp_path / "a.mcap")
    assert not (tmp_path / "a.mcap").exists(), "the constructor must not create the file"
    with pytest.raises(RecordingError, match="not open"):
        writer.write_fields("/t", SUMMARY, {})
    writer.open()
    with pytest.raises(RecordingError, match="already open"):
        writer.open()
    writer.write_fields("/t", SUMMARY, {"request_id": "x"})
    with pytest.raises(RecordingError, match="not registered"):
        writer.write("/never-added", b"")
    with pytest.raises(RecordingError, match="recorded as"):
        writer.add_channel("/t", "hexapod_workspace_msgs/msg/CommandedPose")
    with pytest.raises(RecordingError, match="unknown message type"):
        writer.add_channel("/u", "no_such_pkg/msg/Nothing")
    writer.finish()
    writer.finish()
    assert writer.closed
    with pytest.raises(RecordingError, match="closed"):
        writer.write_fields("/t", SUMMARY, {})
    with pytest.raises(RecordingError, match="flush_messages"):
        logs.LogWriter(tmp_path / "b.mcap", flush_messages=0)
    logs.LogWriter(tmp_path / "never_opened.mcap").finish()  # nothing to finish, no error
    assert [m.message.request_id for m in logs.read_log(tmp_path / "a.mcap").messages] == ["x"]


def test_unwritable_directory_raises_recording_error(tmp_path: Path) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    with pytest.raises(RecordingError, match="cannot create MCAP log"):
        logs.LogWriter(blocker / "logs" / "x.mcap").open()


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full (Linux)")
def test_full_disk_at_creation_raises_recording_error() -> None:
    with pytest.raises(RecordingError, match="No space left on device"):
        logs.LogWriter("/dev/full").open()


# A file-size limit makes the disk "full" in the middle of a log, in a child process only.
FULL_DISK_CHILD = textwrap.dedent(
    """
    import resource, signal, sys, time
    from hexapod_workspace import logs
    from hexapod_workspace.errors import RecordingError
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, 200_000))
    path, mode = sys.argv[1], sys.argv[2]
    writer = logs.LogWriter(path, flush_interval=0.01 if mode == "due" else 0).open()
    writer.add_channel("/t", "sensor_msgs/msg/PointCloud2")
    data = logs.serialize("sensor_msgs/msg/PointCloud2", {"data": bytes(300_000)})
    writer.write("/t", data)
    try:
        if mode == "due":
            time.sleep(0.02)
            writer.flush_if_due()
        else:
            writer.flush()
    except RecordingError as error:
        print("raised", error, flush=True)
    print("closed", writer.closed, flush=True)
    try:
        writer.write("/t", data)
    except RecordingError:
        print("refused", flush=True)
    writer.finish()
    print("done", flush=True)
    """
)


@pytest.mark.parametrize("mode", ["flush", "due"])
def test_disk_full_mid_log_raises_and_closes(tmp_path: Path, mode: str) -> None:
    child = subprocess.run(
        [sys.executable, "-c", FULL_DISK_CHILD, str(tmp_path / "full.mcap"), mode],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert child.returncode == 0, child.stderr
    lines = child.stdout.splitlines()
    assert lines[0].startswith("raised writing MCAP log") and "File too large" in lines[0]
    assert lines[1:] == ["closed True", "refused", "done"]
    assert "Traceback" not in child.stderr
    logs.read_log(tmp_path / "full.mcap")  # what reached the disk is still readable


def test_run_log_path_is_named_by_start_time_and_unique(tmp_path: Path) -> None:
    start = 1_763_758_800_123_000_000  # 2025-11-21T21:00:00.123Z
    first = logs.run_log_path(tmp_path, start_ns=start)
    assert first.name == "hexapod_workspace_20251121T210000.123Z.mcap"
    first.touch()
    assert logs.run_log_path(tmp_path, start_ns=start) != first


# --------------------------------------------------------------------------- durability

CHILD = textwrap.dedent(
    """
    import sys, time
    from hexapod_workspace import logs
    path, mode = sys.argv[1], sys.argv[2]
    kwargs = {"count": dict(flush_interval=0, flush_messages=5),
              "timer": dict(flush_interval=0.05, flush_messages=10_000)}[mode]
    with logs.LogWriter(path, **kwargs) as writer:
        total = 12 if mode == "count" else 3
        for i in range(total):
            writer.write_fields("/hexapod_workspace/summary",
                                "hexapod_workspace_msgs/msg/WorkspaceSummary",
                                {"request_id": f"r{i}", "n_points": i}, 1_000 + i)
        print("written", flush=True)
        while True:  # the owner's idle loop, as the node's recorder thread
            time.sleep(0.05)
            writer.flush_if_due()
    """
)


def start_child(path: Path, mode: str) -> subprocess.Popen:
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(path), mode], stdout=subprocess.PIPE, text=True
    )
    assert child.stdout.readline().strip() == "written"
    return child


def test_sigkill_keeps_every_flushed_message(tmp_path: Path) -> None:
    """flush_messages=5: after 12 writes exactly 10 are on disk; a SIGKILL loses only the 2."""
    path = tmp_path / "killed.mcap"
    child = start_child(path, "count")
    child.send_signal(signal.SIGKILL)
    child.wait()
    contents = logs.read_log(path)
    assert [m.message.request_id for m in contents.messages] == [f"r{i}" for i in range(10)]
    assert not contents.finished and contents.problems
    by_mcap_ros2 = read_with_mcap_ros2(path)
    assert [m.request_id for _, _, m in by_mcap_ros2] == [f"r{i}" for i in range(10)]
    store_decoded = [logs.deserialize(m.msgtype, m.data) for m in contents.messages]
    assert [plain(m) for m in store_decoded] == [plain(m.message) for m in contents.messages]
    recovered = logs.recover_log(path, tmp_path / "recovered.mcap")
    assert recovered.problems == contents.problems
    by_rosbags = read_with_rosbags(tmp_path / "recovered.mcap")  # needs a finished file
    assert [plain(m) for _, _, m in by_rosbags] == [plain(m.message) for m in contents.messages]
    again = logs.read_log(tmp_path / "recovered.mcap")
    assert again.finished and not again.problems
    assert [m.log_time_ns for m in again.messages] == [m.log_time_ns for m in contents.messages]


def test_sigkill_after_the_flush_interval_keeps_messages(tmp_path: Path) -> None:
    """The owner's idle calls of flush_if_due write pending messages out (no further writes)."""
    path = tmp_path / "timer.mcap"
    child = start_child(path, "timer")
    try:
        # Wait (no timed assertion) until the 3 messages are written out.
        for _ in range(1200):
            if len(logs.read_log(path).messages) == 3:
                break
            threading.Event().wait(0.05)
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait()
    assert [m.message.n_points for m in logs.read_log(path).messages] == [0, 1, 2]


def test_sigint_finishes_a_playable_log(tmp_path: Path) -> None:
    path = tmp_path / "interrupted.mcap"
    child = start_child(path, "count")
    child.send_signal(signal.SIGINT)
    child.wait()
    contents = logs.read_log(path)
    assert contents.finished and not contents.problems
    assert len(contents.messages) == 12
    assert [m.request_id for _, _, m in read_with_rosbags(path)] == [f"r{i}" for i in range(12)]


# --------------------------------------------------------------------------- damaged logs


def test_truncation_anywhere_reads_an_intact_prefix(tmp_path: Path) -> None:
    source = tmp_path / "full.mcap"
    with logs.LogWriter(source, flush_messages=1) as writer:
        for i in range(6):
            writer.write_fields("/s", SUMMARY, {"request_id": f"r{i}"}, 100 + i)
    data = source.read_bytes()
    seen_counts = set()
    for cut in range(0, len(data), 7):
        damaged = tmp_path / "cut.mcap"
        damaged.write_bytes(data[:cut])
        try:
            contents = logs.read_log(damaged)
        except LogReadError:
            assert cut < 8  # not even the magic is there
            continue
        ids = [m.message.request_id for m in contents.messages]
        assert ids == [f"r{i}" for i in range(len(ids))]
        assert contents.problems and not contents.finished
        seen_counts.add(len(ids))
    assert seen_counts == set(range(7))  # every prefix length occurs


def test_corrupt_chunk_is_skipped_and_reported(tmp_path: Path) -> None:
    path = tmp_path / "corrupt.mcap"
    with logs.LogWriter(path, flush_messages=1) as writer:
        for i in range(3):
            writer.write_fields("/s", SUMMARY, {"request_id": f"request-{i}"}, 100 + i)
    data = bytearray(path.read_bytes())
    where = data.find(b"request-1")
    data[where] ^= 0xFF
    path.write_bytes(bytes(data))
    contents = logs.read_log(path)
    assert [m.message.request_id for m in contents.messages] == ["request-0", "request-2"]
    assert any("corrupt" in p for p in contents.problems)
    # Finished (it has its footer), but damaged, and replay says so with exit 1.
    assert contents.finished and contents.damaged
    out, err = io.StringIO(), io.StringIO()
    assert run_replay(path, stdout=out, stderr=err) == 1
    assert out.getvalue().startswith(f"log: {path} (finished, but damaged: read as far as intact)")
    assert "is damaged; everything intact was read" in err.getvalue()


def test_unknown_types_are_skipped_with_a_note(tmp_path: Path) -> None:
    path = tmp_path / "foreign.mcap"
    write_foreign_log(path, [("/s", SUMMARY, logs.serialize(SUMMARY, {"request_id": "k"}))])
    contents = logs.read_log(path)
    assert [m.topic for m in contents.messages] == ["/s"]
    assert contents.topics["/foo"].count == 1 and contents.topics["/foo"].decoded == 0
    assert contents.problems == [
        "/foo: type foo_msgs/msg/Bar is unknown here; 1 message(s) skipped"
    ]


def test_not_a_log(tmp_path: Path) -> None:
    with pytest.raises(LogReadError, match="no such file"):
        logs.read_log(tmp_path / "missing.mcap")
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"this is not an mcap file")
    with pytest.raises(LogReadError, match="not an MCAP file"):
        logs.read_log(junk)
    empty_dir = tmp_path / "empty"
    empty_dir.mkdir()
    with pytest.raises(LogReadError, match="without metadata.yaml"):
        logs.read_log(empty_dir)


def test_every_channel_decodes_as_rosbags_documents_it(finished_log) -> None:
    """AnyReader with the default store plus the log's definitions, then
    ``reader.deserialize(raw, connection.msgtype)``: every channel, services included."""
    path, written = finished_log
    decoded = [(t, m, plain(msg)) for t, m, msg in read_with_rosbags_documented(path)]
    assert decoded == written
    assert not any("/srv/" in msgtype for _, msgtype, _ in decoded)


def test_every_channel_opens_in_foxglove(finished_log, tmp_path) -> None:
    """Foxglove's own libraries open every channel (no empty schema but
    std_msgs/Empty) and decode every message to what was written."""
    path, written = finished_log
    opened = read_with_foxglove(path, tmp_path)
    assert set(opened) == {topic for topic, _, _ in written}
    for topic, msgtype, _ in written:
        assert opened[topic]["schema"] == msgtype
    for topic in opened:
        expected = [foxglove_form(f) for t, _, f in written if t == topic]
        got = opened[topic]["messages"]
        assert len(got) == len(expected), topic
        for message, want in zip(got, expected, strict=True):
            message.pop("structure_needs_at_least_one_member", None)
            assert _close(message, want), (topic, message, want)


def _close(got: Any, want: Any) -> bool:
    """Equal, floats to 1e-6 relative (float32 fields come back as float32 in JS)."""
    if isinstance(want, dict):
        return set(got) == set(want) and all(_close(got[k], want[k]) for k in want)
    if isinstance(want, list):
        return len(got) == len(want) and all(_close(g, w) for g, w in zip(got, want, strict=True))
    if isinstance(want, float) and isinstance(got, (int, float)):
        return got == pytest.approx(want, rel=1e-6, abs=1e-12)
    return got == want


def test_service_parts_and_their_recorded_twins_have_the_same_bytes() -> None:
    """The node records the service's own CDR bytes under the message twin: same fields, same
    bytes, so recording needs no re-serialisation."""
    for part, twin in logs.typestore.RECORDED_TYPES.items():
        assert logs.service_part(twin) in (part, twin)
    for _, msgtype, _, fields in sample_messages():
        part = logs.service_part(msgtype)
        if part != msgtype:
            assert bytes(logs.serialize(part, fields)) == bytes(logs.serialize(msgtype, fields))
    empty = logs.serialize("std_srvs/srv/Trigger_Request", {})
    assert bytes(empty) == bytes(logs.serialize("std_msgs/msg/Empty", {}))
    # An empty structure other than std_msgs/Empty says what it is on the wire.
    assert logs.message_definition("std_srvs/srv/Trigger_Request") == (
        "uint8 structure_needs_at_least_one_member\n"
    )
