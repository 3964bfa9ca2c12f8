"""``replay`` of a node session: Pose-form checks, long sessions, atlas clouds, NaN requests.
Logs are written with the package's writer in the node's channel layout."""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import numpy as np

from hexapod_workspace import logs
from hexapod_workspace.cli.log_report import LIST_CAP
from hexapod_workspace.cli.replay import run_replay
from hexapod_workspace.core.evaluation import check as constraints
from hexapod_workspace.logs import messages
from hexapod_workspace.logs.paths import pose_fields

NODE = "/hexapod_workspace"
CHECK_REQUEST = messages.TYPES["check_poses"] + "_Request"
CHECK_RESPONSE = messages.TYPES["check_poses"] + "_Response"
ATLAS_FIELDS = ("x", "y", "z", "reference_reachable", "tilt_capability")


def replay(path: Path, **kwargs: object) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = run_replay(path, stdout=out, stderr=err, **kwargs)
    return code, out.getvalue(), err.getvalue()


def atlas_cloud_fields(columns: np.ndarray, stamp_ns: int) -> dict:
    """A ~/atlas cloud: float32 x, y, z, reference_reachable, tilt_capability (as the node's)."""
    step = 4 * len(ATLAS_FIELDS)
    return {
        "header": messages.header_fields(stamp_ns, "base"),
        "height": 1,
        "width": len(columns),
        "fields": [
            {"name": name, "offset": 4 * k, "datatype": 7, "count": 1}
            for k, name in enumerate(ATLAS_FIELDS)
        ],
        "is_bigendian": False,
        "point_step": step,
        "row_step": step * len(columns),
        "data": columns.astype("<f4").tobytes(),
        "is_dense": False,
    }


def test_a_node_session_is_summarised(tmp_path: Path, example) -> None:
    path = tmp_path / "session.mcap"
    angles = np.radians([[0.0, 0.0, 0.0], [30.0, 20.0, 5.0], [45.0, 80.0, 10.0], [0, 10, 0]])
    result = constraints.check(example, angles)  # 3 of these 4 are reachable
    assert int(result.reachable.sum()) == 3
    time_ns = 1
    with logs.LogWriter(path) as writer:

        def write(topic: str, type_: str, fields: dict) -> None:
            nonlocal time_ns
            writer.write_fields(topic, type_, fields, time_ns)
            time_ns += 1_000_000

        # the Pose form: poses each with its own position, no orientations
        pose_form = messages.check_poses_request_fields([0, 0, 0], np.zeros((0, 3)))
        pose_form["poses"] = [pose_fields([0, 0, -1.3], [0, 0, 0, 1])] * 4
        write(f"{NODE}/check_poses/request", CHECK_REQUEST, pose_form)
        write(
            f"{NODE}/check_poses/response",
            CHECK_RESPONSE,
            messages.check_poses_response_fields(result),
        )
        # a long session: many calls
        for _ in range(3 * LIST_CAP):
            request = messages.check_poses_request_fields([0, 0, -1.3], angles)
            write(f"{NODE}/check_poses/request", CHECK_REQUEST, request)
            response = messages.check_poses_response_fields(result)
            write(f"{NODE}/check_poses/response", CHECK_RESPONSE, response)
        # two atlas clouds
        for stamp in (7, 8):
            columns = np.array(
                [
                    [0.0, 0.0, -1.3, 1.0, math.radians(38.0)],
                    [0.1, 0.0, -1.3, 1.0, math.radians(30.0)],
                    [0.5, 0.0, -1.3, 0.0, math.nan],
                ]
            )
            write(
                f"{NODE}/atlas", "sensor_msgs/msg/PointCloud2", atlas_cloud_fields(columns, stamp)
            )
        # a failed request with a NaN position (as the node now records it)
        failed = messages.summary_fields(
            None, stamp_ns=9, frame_id="base", kind=1, position=[math.nan, 0.0, -1.3], message="x"
        )
        write(f"{NODE}/workspace_summary", messages.TYPES["workspace_summary"], failed)

    code, out, err = replay(path, as_json=True)
    assert code == 0, err
    report = json.loads(out)
    first = report["pose_checks"][0]
    # before: "3/0 reachable" (the poses were not counted)
    assert (first["n_poses"], first["n_reachable"], first["pose_form"]) == (4, 3, True)
    assert first["position"] is None
    assert len(report["pose_checks"]) == 1 + 3 * LIST_CAP  # JSON lists every call
    # before: "workspace results: 0" and nothing about the atlases
    assert [a["n_positions"] for a in report["atlases"]] == [3, 3]
    atlas = report["atlases"][0]
    assert atlas["n_reference_reachable"] == 2
    assert math.isclose(atlas["tilt_capability_max_deg"], 38.0, abs_tol=1e-4)
    assert atlas["extent_m"]["x"] == [0.0, 0.5]
    # before: (0, 0, -1.3) m, a position nobody asked for
    assert report["workspaces"][0]["position"] == [None, 0.0, -1.3]

    code, text, _ = replay(path)
    assert code == 0
    assert "4/3" not in text and "3/4 reachable (Pose form)" in text
    assert f"pose checks: {1 + 3 * LIST_CAP} ({4 + 12 * LIST_CAP} poses answered" in text
    assert f"... {1 + 3 * LIST_CAP - LIST_CAP} more pose checks (replay --json" in text
    check_lines = [x for x in text.splitlines() if x.startswith("  [") and "/check_poses/" in x]
    assert len(check_lines) == LIST_CAP  # capped: the first and the last ones
    assert "atlas results: 2" in text
    assert "3 positions" in text and "reference reachable at 2" in text
    assert "tilt capability up to 38.00 deg" in text
    assert "at (nan, 0, -1.3) m" in text
