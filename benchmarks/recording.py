"""Benchmark: recording one 10^6-point boundary cloud, against reference writers, same run.

Prints absolute times (median of --repeat runs) and ratios:
- ours: points -> PointCloud2 field dict -> CDR (rosbags) -> hexapod_workspace LogWriter -> disk
- rosbags: the same CDR bytes through rosbags' own rosbag2 writer (MCAP storage)
- mcap_ros2: mcap_ros2's writer (its own CDR encoder) on the same field dict
and the service-time impact: a workspace computation with and without recording its result.

Usage: python benchmarks/recording.py [--points 1000000] [--repeat 5] [--dir DIR]
Goal: <= 100 ms for 10^6 points, and no slowdown of the service that produced it.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from hexapod_workspace import logs
from hexapod_workspace.logs import messages

CLOUD = "sensor_msgs/msg/PointCloud2"


def timed(function: Callable[[int], object], repeat: int) -> float:
    """Median wall time of ``function(run_index)`` in ms (one warm-up run first)."""
    function(-1)
    times = []
    for index in range(repeat):
        start = time.perf_counter()
        function(index)
        times.append((time.perf_counter() - start) * 1e3)
    return statistics.median(times)


def drain_ms(recorder: Any, count: int) -> float:
    """How long the node's recorder thread still needs until ``count`` messages are written, ms."""
    start = time.perf_counter()
    deadline = start + 600.0
    while recorder.status().messages < count and time.perf_counter() < deadline:
        time.sleep(0.001)
    return (time.perf_counter() - start) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--dir", type=Path, default=None, help="where to write (default: tmp)")
    args = parser.parse_args()
    rng = np.random.default_rng(20261121)
    points = rng.normal(size=(args.points, 6))
    scratch = tempfile.TemporaryDirectory(prefix="bench-rec-", dir=args.dir)  # removed at exit
    workdir = Path(scratch.name)
    stamp = time.time_ns()

    def ours(index: int) -> None:
        fields = messages.pointcloud_fields(points, frame_id="base", stamp_ns=stamp)
        data = logs.serialize(CLOUD, fields)
        with logs.LogWriter(workdir / f"ours{index}.mcap", flush_interval=0) as writer:
            writer.add_channel("/hexapod_workspace/boundary", CLOUD, logs.RESULT_QOS)
            writer.write("/hexapod_workspace/boundary", data, stamp)

    def ours_write_only(
        index: int,
        data: bytes = logs.serialize(
            CLOUD, messages.pointcloud_fields(points, frame_id="base", stamp_ns=stamp)
        ),
    ) -> None:
        with logs.LogWriter(workdir / f"w{index}.mcap", flush_interval=0) as writer:
            writer.add_channel("/hexapod_workspace/boundary", CLOUD, logs.RESULT_QOS)
            writer.write("/hexapod_workspace/boundary", data, stamp)

    def rosbags_writer(index: int) -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer

        fields = messages.pointcloud_fields(points, frame_id="base", stamp_ns=stamp)
        data = logs.serialize(CLOUD, fields)
        store = logs.get_typestore()
        with Writer(
            workdir / f"rosbags{index}", version=9, storage_plugin=StoragePlugin.MCAP
        ) as writer:
            connection = writer.add_connection(
                "/hexapod_workspace/boundary", CLOUD, typestore=store
            )
            writer.write(connection, stamp, data)

    def mcap_ros2_writer(index: int) -> None:
        from mcap_ros2.writer import Writer

        fields = messages.pointcloud_fields(points, frame_id="base", stamp_ns=stamp)
        with (workdir / f"mcap_ros2_{index}.mcap").open("wb") as stream:
            writer = Writer(stream)
            schema = writer.register_msgdef(CLOUD, logs.message_definition(CLOUD))
            writer.write_message("/hexapod_workspace/boundary", schema, fields, stamp, stamp)
            writer.finish()

    n = args.points
    print(
        f"recording one {n}-point PointCloud2 ({24 * n / 1e6:.1f} MB), median of "
        f"{args.repeat}, into {workdir}"
    )
    t_ours = timed(ours, args.repeat)
    t_write = timed(ours_write_only, args.repeat)
    t_rosbags = timed(rosbags_writer, args.repeat)
    print(f"  ours (dict -> CDR -> MCAP, finished file): {t_ours:8.1f} ms")
    print(f"    of which LogWriter (CDR bytes -> disk):  {t_write:8.1f} ms")
    print(
        f"  rosbags rosbag2 Writer (same CDR bytes):   {t_rosbags:8.1f} ms   "
        f"ours/rosbags = {t_ours / t_rosbags:.2f}"
    )
    if n <= 100_000:
        t_mcap_ros2 = timed(mcap_ros2_writer, args.repeat)
        print(
            f"  mcap_ros2 Writer (its own CDR encoder):    {t_mcap_ros2:8.1f} ms   "
            f"ours/mcap_ros2 = {t_ours / t_mcap_ros2:.2f}"
        )
    else:
        start = time.perf_counter()
        mcap_ros2_writer(0)
        t_mcap_ros2 = (time.perf_counter() - start) * 1e3
        print(
            f"  mcap_ros2 Writer (its own CDR encoder, 1 run): {t_mcap_ros2:8.1f} ms   "
            f"ours/mcap_ros2 = {t_ours / t_mcap_ros2:.3f}"
        )

    service_impact(args.repeat, workdir)
    node_path(points, args.repeat, workdir)
    scratch.cleanup()


def service_impact(repeat: int, workdir: Path) -> None:
    """Service time with and without recording, the way the node records (same run).

    Both variants compute the result and build its message objects (rosbags objects stand in for
    the rclpy messages the node publishes anyway). Recording adds serialising them (rclpy's
    serialize_message in the node's recorder thread, rosbags' serialize_cdr here) and
    LogWriter.write, here in the calling thread (the CLI's path; the node's callbacks only queue,
    see node_path). Uses the projected workspace when the core has it, else a CheckPoses batch
    of 10^4 poses.
    """
    from hexapod_workspace._resources import example_config_path
    from hexapod_workspace.core.evaluation import check as constraints
    from hexapod_workspace.core.evaluation.loading import load_manipulator

    manipulator = load_manipulator(example_config_path())
    store = logs.get_typestore()
    stamp = time.time_ns()
    try:
        from hexapod_workspace.core.workspaces.projected import projected_workspace
    except ImportError:
        projected_workspace = None
    rng = np.random.default_rng(5)
    angles = np.column_stack(
        (
            rng.uniform(-np.pi, np.pi, 10_000),
            rng.uniform(0, 0.6, 10_000),
            rng.uniform(-0.3, 0.3, 10_000),
        )
    )

    def outputs() -> list[tuple[str, str, dict]]:
        if projected_workspace is not None:
            workspace = projected_workspace(manipulator, method="torsion_zero", n_phi=360)
            points = messages.boundary_points(workspace)
            return [
                (
                    "/hexapod_workspace/summary",
                    "hexapod_workspace_msgs/msg/WorkspaceSummary",
                    messages.summary_fields(workspace, stamp_ns=stamp, frame_id="base"),
                ),
                (
                    "/hexapod_workspace/boundary",
                    CLOUD,
                    messages.pointcloud_fields(points, frame_id="base", stamp_ns=stamp),
                ),
            ]
        result = constraints.check(manipulator, angles)
        return [
            (
                "/hexapod_workspace/check_poses/response",
                "hexapod_workspace_msgs/srv/CheckPoses_Response",
                messages.check_poses_response_fields(result),
            )
        ]

    def serve(writer: logs.LogWriter | None, produce: Callable[[], list]) -> None:
        built = [
            (topic, msgtype, logs.build_message(msgtype, fields))
            for topic, msgtype, fields in produce()
        ]
        if writer is not None:
            for topic, msgtype, message in built:
                writer.add_channel(topic, msgtype, logs.RESULT_QOS)
                writer.write(topic, store.serialize_cdr(message, logs.store_name(msgtype)))

    name = (
        "projected torsion_zero, 360 rays"
        if projected_workspace is not None
        else "check of 10^4 poses; projected workspace not in the core yet"
    )
    for label, produce in ((name, outputs),):  # the 10^6-point cloud: node_path() below
        without = timed(lambda _, make=produce: serve(None, make), repeat)
        with logs.LogWriter(workdir / "node_run.mcap") as writer:
            with_recording = timed(lambda _, make=produce: serve(writer, make), repeat)
        print(
            f"service ({label}): {without:7.1f} ms without recording, {with_recording:7.1f} ms"
            f" with (written in the calling thread): ratio {with_recording / without:.3f}"
        )


def node_path(points: np.ndarray, repeat: int, workdir: Path) -> None:
    """The node's own path when rclpy is importable (ROS venv): an rclpy PointCloud2 handed to
    the node's Recorder (ros/recorder.py: the callback only queues; its thread serialises and
    writes), i.e. what recording adds to a callback that publishes the cloud anyway."""
    try:
        import array
        import logging

        from rclpy.serialization import serialize_message
        from sensor_msgs.msg import PointCloud2, PointField

        from hexapod_workspace.ros.recorder import Recorder
    except ImportError as error:
        print(f"node path (rclpy): skipped ({error}); run under the ROS venv for it")
        return
    fields = messages.pointcloud_fields(points, frame_id="base", stamp_ns=time.time_ns())
    cloud = PointCloud2(
        height=1,
        width=fields["width"],
        is_bigendian=False,
        point_step=24,
        row_step=fields["row_step"],
        is_dense=fields["is_dense"],
        fields=[PointField(**f) for f in fields["fields"]],
    )
    cloud.data = array.array("B", fields["data"])
    topic = "/hexapod_workspace/projected_workspace"
    recorder = Recorder(logging.getLogger("bench-recorder"))
    recorder.add_channel(topic, CLOUD, logs.RESULT_QOS)
    recorder.open(workdir / "node_path")
    try:
        serialize_ms = timed(lambda _: serialize_message(cloud), repeat)
        record_ms = timed(lambda _: recorder.write(topic, cloud), repeat)
        drain = drain_ms(recorder, repeat)
    finally:
        recorder.shutdown()
    print(
        f"node path (rclpy, 10^6 points): serialize_message {serialize_ms:.1f} ms; the "
        f"callback's part (queue) {record_ms:.3f} ms; the recorder thread then needed "
        f"{drain:.1f} ms more to serialise and write"
    )


if __name__ == "__main__":
    main()
