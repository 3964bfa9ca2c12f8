"""Tests of hexapod_workspace.cli.replay: --record then replay, bad logs, plots, republishing."""

from __future__ import annotations

import contextlib
import dataclasses
import importlib.util
import io
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest
from cli_support import polar_labels_clear
from recording_support import plain, read_with_mcap_ros2, read_with_rosbags, write_foreign_log
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Rosbag2Writer
from test_messages import orientation_stub, projected_stub

from hexapod_workspace import logs
from hexapod_workspace.cli.replay import run_replay
from hexapod_workspace.core.evaluation import check as constraints
from hexapod_workspace.core.evaluation.loading import example_manipulator
from hexapod_workspace.core.workspaces.orientation import OrientationSlice
from hexapod_workspace.logs import messages
from hexapod_workspace.logs.record import record_results
from hexapod_workspace.logs.summary import summarize_log


def replay(*args: object, **kwargs: object) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = run_replay(*args, stdout=out, stderr=err, **kwargs)
    assert "Traceback" not in err.getvalue()
    return code, out.getvalue(), err.getvalue()


@pytest.fixture
def check_result(example) -> constraints.CheckResult:
    angles = np.radians([[0.0, 0.0, 0.0], [30.0, 20.0, 5.0], [45.0, 80.0, 10.0]])
    return constraints.check(example, angles)


def test_record_then_replay_check_and_stub_workspaces(tmp_path: Path, check_result) -> None:
    path = tmp_path / "cli.mcap"
    projected, orientation = projected_stub("exact"), orientation_stub()
    record_results(
        path,
        [check_result, projected, orientation],
        frame_id="base",
        request_id="study-1",
        stamp_ns=1_700_000_000_000_000_000,
    )
    code, out, err = replay(path, as_json=True)
    assert code == 0 and err == ""
    report = json.loads(out)
    assert report["finished"] and report["problems"] == []
    assert report["start"] == "2023-11-14T22:13:20.000Z"
    counts = {t["topic"]: t["count"] for t in report["topics"]}
    assert counts == {
        "/hexapod_workspace/check_poses/request": 1,
        "/hexapod_workspace/check_poses/response": 1,
        "/hexapod_workspace/workspace_request": 2,
        "/hexapod_workspace/workspace_summary": 2,
        "/hexapod_workspace/projected_workspace": 1,
        "/hexapod_workspace/orientation_workspace": 1,
    }
    (check,) = report["pose_checks"]
    assert check["n_poses"] == 3 and check["n_reachable"] == int(check_result.reachable.sum())
    exact, orient = report["workspaces"]
    assert exact["kind"] == "exact" and exact["request_id"] == "study-1"
    assert exact["tilt_max_deg"] == pytest.approx(math.degrees(projected.tilt_max))
    assert exact["psi_min_deg"] is None and exact["n_points"] == 36 and exact["boundary_recorded"]
    assert orient["kind"] == "orientation" and orient["n_points"] == 24
    assert orient["psi_max_deg"] == pytest.approx(math.degrees(0.1))
    code, text, _ = replay(path)
    assert code == 0
    assert "workspace results: 2" in text and "pose checks: 1" in text
    assert f"{int(check_result.reachable.sum())}/3 reachable" in text


def test_recorded_cli_messages_equal_what_was_built(tmp_path: Path, check_result) -> None:
    """The --record log decodes with rosbags and mcap_ros2 to the dicts messages.py built."""
    path = tmp_path / "cli.mcap"
    workspace = projected_stub()
    record_results(path, [check_result, workspace], frame_id="base", stamps_ns=[5_000, 7_000])
    points = messages.boundary_points(workspace)
    answered = 7_000 + round(workspace.elapsed * 1e9)  # the response, elapsed after the request
    expected = [
        messages.check_poses_request_fields(check_result.position, check_result.angles),
        messages.check_poses_response_fields(check_result),
        messages.compute_workspace_request_fields(workspace, stamp_ns=7_000, frame_id="base")[
            "request"
        ],
        messages.summary_fields(workspace, stamp_ns=answered, frame_id="base", n_points=36),
        messages.pointcloud_fields(points, frame_id="base", stamp_ns=answered),
    ]
    for reader in (read_with_rosbags, read_with_mcap_ros2):
        assert [plain(message) for _, _, message in reader(path)] == plain(expected)


def test_summary_and_cloud_of_one_computation_are_paired(tmp_path: Path) -> None:
    """A ComputeWorkspace response and the topic summary of the same computation are one
    result; a cloud arriving before its summary is still attached."""
    path = tmp_path / "node.mcap"
    workspace = projected_stub()
    summary = messages.summary_fields(workspace, stamp_ns=9, frame_id="base")
    cloud = messages.pointcloud_fields(
        messages.boundary_points(workspace), frame_id="base", stamp_ns=9
    )
    with logs.LogWriter(path) as writer:
        writer.write_fields("/n/projected_workspace", "sensor_msgs/msg/PointCloud2", cloud, 1)
        writer.write_fields("/n/workspace_summary", messages.TYPES["workspace_summary"], summary, 2)
        writer.write_fields(
            "/n/compute_workspace/response",
            "hexapod_workspace_msgs/srv/ComputeWorkspace_Response",
            messages.compute_workspace_response_fields(
                workspace, stamp_ns=9, frame_id="base", summary=summary, boundary=cloud
            ),
            3,
        )
    log_summary, _ = summarize_log(path)
    (record,) = log_summary.workspaces
    assert record.sources == ["/n/workspace_summary", "/n/compute_workspace/response"]
    np.testing.assert_array_equal(record.points, messages.pointcloud_to_array(cloud))


def test_record_real_workspaces_replay_and_plot(tmp_path: Path, example) -> None:
    from hexapod_workspace.core.workspaces.orientation import orientation_workspace
    from hexapod_workspace.core.workspaces.projected import projected_workspace

    results = [
        projected_workspace(example, method="torsion_zero", n_phi=72),
        projected_workspace(example, method="exact", n_phi=72),
        orientation_workspace(example, n_rays=36, psi_step=math.radians(5)),
    ]
    path = record_results(tmp_path / "real.mcap", results, frame_id=example.frame_id)
    code, out, _ = replay(path, as_json=True, plot_dir=tmp_path / "plots")
    assert code == 0
    report = json.loads(out)
    assert [w["kind"] for w in report["workspaces"]] == ["torsion_zero", "exact", "orientation"]
    assert report["workspaces"][0]["tilt_min_deg"] == pytest.approx(
        math.degrees(results[0].tilt_min)
    )
    assert report["workspaces"][2]["volume"] == pytest.approx(results[2].volume)
    plots = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert plots == ["workspace_001_projected.png", "workspace_003_orientation.png"]


def test_cli_record_then_replay(tmp_path: Path) -> None:
    """The console script end to end: projected --record, then replay (text, JSON, plots)."""
    from cli_support import run_cli

    log = tmp_path / "study.mcap"
    recorded = run_cli(
        "--json", "projected", "--method", "exact", "--n-phi", "48", "--record", str(log)
    )
    assert recorded.returncode == 0, recorded.stderr
    live = json.loads(recorded.stdout)
    replayed = run_cli("replay", str(log), "--json", "--plot", str(tmp_path / "plots"))
    assert replayed.returncode == 0, replayed.stderr
    assert "Traceback" not in replayed.stderr
    (workspace,) = json.loads(replayed.stdout)["workspaces"]
    assert workspace["kind"] == "exact" and workspace["n_points"] == 48
    assert workspace["tilt_min_deg"] == pytest.approx(live["tilt_min_deg"])
    assert workspace["tilt_max_deg"] == pytest.approx(live["tilt_max_deg"])
    assert workspace["position"] == pytest.approx(live["position"])
    assert (tmp_path / "plots" / "workspace_001_projected.png").stat().st_size > 0
    text = run_cli("replay", str(log))
    assert text.returncode == 0 and "exact: tilt" in text.stdout
    broken = run_cli("replay", str(tmp_path / "missing.mcap"))
    assert broken.returncode == 2 and broken.stdout == ""
    assert "Traceback" not in broken.stderr and len(broken.stderr.splitlines()) == 1


def test_plot_redraws_overlaid_methods_and_degenerate_workspaces(tmp_path: Path) -> None:
    one = OrientationSlice(psi=0.0, center=np.zeros(2), phi=np.zeros(1), theta=np.full(1, 0.1))
    single_point = dataclasses.replace(orientation_stub(), slices=[one])
    path = record_results(
        tmp_path / "stubs.mcap",
        [projected_stub("exact"), projected_stub(), orientation_stub(), single_point],
    )
    code, out, err = replay(path, plot_dir=tmp_path / "plots")
    assert code == 0, err
    plots = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert plots == [
        "workspace_001_projected.png",
        "workspace_003_orientation.png",
        "workspace_004_orientation.png",
    ]
    assert out.count("plot: ") == 3


# --------------------------------------------------------------------------- bad logs


def test_missing_and_foreign_files_exit_2_with_one_line(tmp_path: Path) -> None:
    code, out, err = replay(tmp_path / "nope.mcap")
    assert (code, out) == (2, "") and err.count("\n") == 1 and "no such file" in err
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"definitely not MCAP")
    code, _, err = replay(junk)
    assert code == 2 and "not an MCAP file" in err
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    assert replay(empty)[0] == 2


def test_truncated_logs(tmp_path: Path, check_result) -> None:
    path = tmp_path / "cli.mcap"
    record_results(path, [check_result, projected_stub(), check_result], stamp_ns=1)
    data = path.read_bytes()
    head = tmp_path / "head.mcap"
    head.write_bytes(data[:40])  # magic and header only
    code, out, err = replay(head)
    assert code == 2 and out == "" and "nothing usable" in err.splitlines()[-1]
    half = tmp_path / "half.mcap"
    half.write_bytes(data[: len(data) // 2])
    code, out, err = replay(half, as_json=True)
    # A damaged log is reported as damaged, exit 1, after everything intact.
    assert code == 1 and err.startswith("note: half.mcap: unreadable from about byte")
    assert err.splitlines()[-1].endswith(
        "is damaged; everything intact was read (see the notes above)"
    )
    report = json.loads(out)
    assert not report["finished"] and report["damaged"] and report["problems"]
    assert report["message_count"] >= 2


def test_unknown_topics_are_skipped_with_a_note(tmp_path: Path) -> None:
    path = tmp_path / "mixed.mcap"
    write_foreign_log(path)
    code, _, err = replay(path)
    assert code == 2 and "foo_msgs/msg/Bar is unknown" in err and "nothing usable" in err
    summary = messages.summary_fields(projected_stub(), stamp_ns=1, frame_id="base")
    summary_type = messages.TYPES["workspace_summary"]
    write_foreign_log(path, [("/s", summary_type, logs.serialize(summary_type, summary))])
    code, out, err = replay(path)
    assert code == 0
    assert err == "note: /foo: type foo_msgs/msg/Bar is unknown here; 1 message(s) skipped\n"
    assert "/foo" in out and "workspace results: 1" in out


def test_bag_directory_and_bad_rate(tmp_path: Path) -> None:
    bag = tmp_path / "bag"
    fields = messages.summary_fields(orientation_stub(), stamp_ns=3, frame_id="base")
    with Rosbag2Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection(
            "/ws/summary", messages.TYPES["workspace_summary"], typestore=logs.get_typestore()
        )
        writer.write(connection, 5, logs.serialize(messages.TYPES["workspace_summary"], fields))
    code, out, _ = replay(bag)
    assert code == 0 and "orientation: psi -5.730..5.730 deg" in out
    assert replay(bag, rate=-1.0)[0] == 2


def test_rejected_requests_with_nan_replay_as_json(tmp_path: Path) -> None:
    """A node records bad requests too (NaN position): JSON output stays valid (null)."""
    path = tmp_path / "bad.mcap"
    nan = float("nan")
    with logs.LogWriter(path) as writer:
        writer.write_fields(
            "/n/check_poses/request",
            messages.TYPES["check_poses"] + "_Request",
            messages.check_poses_request_fields([nan, 0, 1], [[0, 0, 0]]),
            1,
        )
        writer.write_fields(
            "/n/check_poses/response",
            messages.TYPES["check_poses"] + "_Response",
            messages.check_poses_response_fields(None, message="NaN"),
            2,
        )
        writer.write_fields(
            "/n/workspace_summary",
            messages.TYPES["workspace_summary"],
            messages.summary_fields(
                None, stamp_ns=3, frame_id="base", kind=0, position=[nan, nan, nan], message="NaN"
            ),
            3,
        )
    code, out, err = replay(path, as_json=True)
    assert code == 0, err
    report = json.loads(out)
    assert report["pose_checks"][0]["position"] == [None, 0.0, 1.0]
    assert report["workspaces"][0]["position"] == [None, None, None]
    code, text, _ = replay(path)
    assert code == 0 and "failed: NaN" in text


def test_empty_finished_log_is_fine(tmp_path: Path) -> None:
    path = tmp_path / "idle.mcap"
    with logs.LogWriter(path) as writer:
        writer.add_channel("/hexapod_workspace/summary", messages.TYPES["workspace_summary"])
    code, out, err = replay(path)
    assert code == 0 and err == "" and "0 messages" in out


# --------------------------------------------------------------------------- republishing

HAVE_RCLPY = importlib.util.find_spec("rclpy") is not None


@pytest.mark.skipif(HAVE_RCLPY, reason="checks the message given when rclpy is missing")
def test_publish_without_rclpy_says_so(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("ROS_AUTOMATIC_DISCOVERY_RANGE", raising=False)
    path = tmp_path / "a.mcap"
    record_results(path, [projected_stub()])
    code, _, err = replay(path, publish=True)
    assert code == 2 and "needs rclpy" in err.splitlines()[-1]


@pytest.mark.skipif(not HAVE_RCLPY, reason="the refusal is the ROS layer's; needs rclpy")
def test_publish_refuses_network_discovery(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "SUBNET")
    path = tmp_path / "a.mcap"
    record_results(path, [projected_stub()])
    code, _, err = replay(path, publish=True)
    assert code == 2 and "refusing" in err


@pytest.mark.skipif(
    not HAVE_RCLPY,
    reason="rclpy not importable: run under the ROS venv (make test) to exercise replay --publish",
)
def test_publish_republishes_recorded_clouds(tmp_path: Path, monkeypatch) -> None:
    import threading

    import rclpy
    from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import PointCloud2

    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    assert os.environ.get("ROS_DOMAIN_ID"), "tests that start rclpy need a test ROS_DOMAIN_ID"
    path = tmp_path / "clouds.mcap"
    rng = np.random.default_rng(3)
    clouds = [
        messages.pointcloud_fields(rng.normal(size=(100 * (i + 1), 6)), frame_id="base", stamp_ns=i)
        for i in range(3)
    ]
    with logs.LogWriter(path) as writer:
        for i, cloud in enumerate(clouds):
            writer.write_fields(
                "/replay_test/boundary",
                "sensor_msgs/msg/PointCloud2",
                cloud,
                1_000_000 * i,
                qos=logs.REQUEST_QOS,
            )
    context = rclpy.Context()
    rclpy.init(context=context)
    received: list[PointCloud2] = []
    done = threading.Event()
    try:
        node = rclpy.create_node("replay_test_listener", context=context)

        def on_cloud(message: PointCloud2) -> None:
            received.append(message)
            if len(received) == len(clouds):
                done.set()

        qos = QoSProfile(
            depth=10, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE
        )
        node.create_subscription(PointCloud2, "/replay_test/boundary", on_cloud, qos)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)

        def spin() -> None:
            # The context is shut down at the end of the test, which ends spin() this way.
            with contextlib.suppress(ExternalShutdownException):
                executor.spin()

        spinner = threading.Thread(target=spin, daemon=True)
        spinner.start()
        code, _, err = replay(path, publish=True, rate=10.0, wait_for_subscribers=60.0)
        assert code == 0, err
        assert done.wait(timeout=60), f"received {len(received)} of {len(clouds)}"
        assert [plain(m) for m in received] == plain(clouds)
    finally:
        rclpy.try_shutdown(context=context)


@pytest.mark.skipif(
    not HAVE_RCLPY,
    reason="rclpy not importable: run under the ROS venv (make test) to exercise replay --publish",
)
def test_publish_counts_only_what_went_out(tmp_path: Path, monkeypatch) -> None:
    """Messages of a type this ROS environment lacks are named and not counted as
    republished (before: "12 not republished", then "republished 18 messages")."""
    import importlib

    with pytest.raises(ImportError):
        importlib.import_module("shape_msgs.msg")  # in rosbags' Jazzy store, not here
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    assert os.environ.get("ROS_DOMAIN_ID"), "tests that start rclpy need a test ROS_DOMAIN_ID"
    path = tmp_path / "mixed.mcap"
    cloud = messages.pointcloud_fields(np.zeros((3, 6)), frame_id="base", stamp_ns=1)
    status = {"coef": [0.0, 0.0, 1.0, 0.5]}
    with logs.LogWriter(path) as writer:
        for i in range(3):
            writer.write_fields("/mixed/cloud", "sensor_msgs/msg/PointCloud2", cloud, 10 + i)
        for i in range(2):
            writer.write_fields("/mixed/status", "shape_msgs/msg/Plane", status, 20 + i)
    code, _, err = replay(path, publish=True, rate=0.0)
    assert code == 0, err
    assert (
        "note: /mixed/status: type shape_msgs/msg/Plane is not available in this "
        "ROS environment; its 2 message(s) are not republished" in err
    )
    assert err.splitlines()[-1] == (
        "republished 3 of 5 messages on 1 topics (2 not republished, see the notes above)"
    )


def test_plotting_leaves_matplotlib_global_state_alone(tmp_path: Path) -> None:
    """No backend switch and no pyplot on import or use; axis beyond the curves."""
    import subprocess
    import sys

    script = f"""
import sys
import matplotlib
matplotlib.use("svg")
sys.path.insert(0, {str(Path(__file__).parent)!r})
from test_messages import orientation_stub, projected_stub
from hexapod_workspace.cli import plotting
plotting.plot_projected([projected_stub(), projected_stub("exact")], {str(tmp_path / "p.png")!r})
plotting.plot_orientation(orientation_stub(), {str(tmp_path / "o.png")!r})
print(matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules)
"""
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["svg", "False"]
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_projected_plot_radial_axis_clears_the_largest_tilt(tmp_path: Path) -> None:
    """The curves never lie on the frame; every ring is labelled, and no label covers a curve
    (checked on the drawn figure, in display coordinates), also where the curves hug a ring (on
    the axis: 38-39.5° against the 40° ring)."""
    from hexapod_workspace import projected_workspace
    from hexapod_workspace.cli import plotting

    example = example_manipulator()
    cases = {
        "stubs": [projected_stub(), projected_stub("exact")],
        "on the axis": [
            projected_workspace(example, [0, 0, -1.3], n_phi=72),
            projected_workspace(example, [0, 0, -1.3], n_phi=72, method="exact"),
        ],
    }
    for case, workspaces in cases.items():
        largest = max(np.degrees(w.theta).max() for w in workspaces)
        step = plotting._nice_step(largest, 5)
        top = step * math.ceil(largest * 1.1 / step)
        assert top >= 1.1 * largest
        ticks = np.arange(step, top - step / 2, step)
        figure = plotting.projected_figure(workspaces)
        (axes,) = figure.axes
        assert polar_labels_clear(figure, axes) == {f"{t:g}°" for t in ticks}, case
    assert plotting.plot_projected(cases["on the axis"], tmp_path / "p.png").stat().st_size > 10_000


def test_orientation_plot_labels_of_the_two_panels_stay_apart() -> None:
    """The 3-D panel's ψ label and the top view's θ sin φ label do not touch
    (measured on the drawn figure, on and off the axis)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from hexapod_workspace import orientation_workspace
    from hexapod_workspace.cli import plotting

    example = example_manipulator()
    for position in ([0, 0, -1.3], [0.2, 0.2, -0.95]):
        workspace = orientation_workspace(example, position, n_rays=36, psi_step=np.radians(5))
        figure = plotting.orientation_figure(workspace)
        renderer = FigureCanvasAgg(figure).get_renderer()
        figure.draw(renderer)
        surface, top = figure.axes[:2]
        psi_label = surface.zaxis.label.get_window_extent(renderer)
        tilt_label = top.yaxis.label.get_window_extent(renderer)
        assert psi_label.x1 + 10 < tilt_label.x0, (position, psi_label, tilt_label)
