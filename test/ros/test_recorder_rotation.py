"""The node's log folder stays bounded: the recorder splits its log by size
and by age, as rosbag2 splits a bag, and removes the oldest logs beyond a total size.

The recorder is the node's own (rclpy serialisation, its thread, real files); every log it
leaves is read back with rosbags' documented API and must be finished and whole.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from ros_support import require_ros

require_ros()

from rclpy.logging import get_logger  # noqa: E402
from std_msgs.msg import String  # noqa: E402

from hexapod_workspace import logs  # noqa: E402
from hexapod_workspace.ros.recorder import LOG_PREFIX, Recorder, Rotation  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # test/recording_support.py
from recording_support import read_with_rosbags  # noqa: E402

TOPIC = "/hexapod_workspace/rotation_test"
QOS = logs.REQUEST_QOS


def record(folder: Path, rotation: Rotation, texts: list[str], pause: float = 0.0) -> None:
    recorder = Recorder(get_logger("rotation_test"))
    recorder.add_channel(TOPIC, "std_msgs/msg/String", QOS)
    try:
        recorder.open(folder, rotation)
        for text in texts:
            recorder.write(TOPIC, String(data=text))
            if pause:
                time.sleep(pause)
    finally:
        recorder.shutdown()


def recorded(folder: Path) -> tuple[list[Path], list[str]]:
    files = sorted(folder.glob(f"{LOG_PREFIX}_*.mcap"))
    texts = []
    for path in files:
        assert logs.read_log(path).finished, path
        texts += [message.data for _, _, message in read_with_rosbags(path)]
    return files, texts


def test_a_log_is_split_by_size_and_the_folder_kept_under_its_limit(tmp_path):
    texts = [f"{k:05d}" + "x" * 1000 for k in range(300)]  # about 300 kB of messages
    old = tmp_path / f"{LOG_PREFIX}_20000101T000000.000Z.mcap"  # an earlier run's log
    old.write_bytes(b"\x89MCAP0\r\n" + b"\0" * 50_000)
    keep = tmp_path / "notes.mcap"  # not one of ours: never removed
    keep.write_bytes(b"x")
    record(tmp_path, Rotation(max_file_bytes=20_000, max_total_bytes=100_000), texts)
    files, got = recorded(tmp_path)
    assert not old.exists() and keep.exists()
    assert 3 <= len(files) <= 6  # ~20 kB each, about 100 kB kept
    assert sum(f.stat().st_size for f in files) <= 100_000 + 25_000  # the last one may grow
    # what is kept is the most recent messages, in order, without a gap
    assert got == texts[-len(got) :]
    assert len(got) >= 60


def test_a_log_is_split_by_age(tmp_path):
    record(tmp_path, Rotation(max_file_seconds=0.2), ["a", "b", "c"], pause=0.3)
    files, got = recorded(tmp_path)
    assert got == ["a", "b", "c"]
    assert len(files) >= 2


def test_no_limits_one_log(tmp_path):
    record(tmp_path, Rotation(), [str(k) for k in range(100)])
    files, got = recorded(tmp_path)
    assert len(files) == 1 and len(got) == 100
