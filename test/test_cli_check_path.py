"""``check-path``: file formats, JSON keys, exit codes, plot and MCAP record."""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_support import run_cli
from recording_support import plain, read_with_mcap_ros2, read_with_rosbags

from hexapod_workspace import check_path
from hexapod_workspace.cli.main import main
from hexapod_workspace.core.base.rotations import approach_vector

WAYPOINT_KEYS = {
    "index",
    "position",
    "phi_deg",
    "theta_deg",
    "psi_deg",
    "reachable",
    "violated",
    "margins",
    "limiting_leg",
}
SEGMENT_KEYS = {
    "index",
    "ok",
    "first_violation_s",
    "first_violation_pose_deg",
    "position_at_violation",
    "violated",
    "limiting_leg",
    "min_relative_margin",
    "min_at_s",
}


def cone(count: int = 40) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Off-axis circle of tool-tip positions with tool axes on a 17° cone (the shape of the
    Motions page's example, fewer waypoints): ψ = 0 fails near φ = 130°, other torsions reach."""
    t = np.linspace(0.0, 2.0 * np.pi, count)
    positions = np.column_stack(
        [0.2 + 0.02 * np.cos(t), 0.2 + 0.02 * np.sin(t), np.full(count, -0.95)]
    )
    return positions, t, approach_vector(t, np.radians(17.0))


def write_csv(path: Path, header: str, rows: np.ndarray) -> Path:
    np.savetxt(path, rows, delimiter=",", header=header, comments="", fmt="%.17g")
    return path


def test_tool_axes_are_planned_json_plot_and_record(tmp_path, example):
    positions, _, axes = cone()
    source = write_csv(tmp_path / "axes.csv", "x,y,z,i,j,k", np.column_stack([positions, axes]))
    plot, log = tmp_path / "path.png", tmp_path / "path.mcap"
    done = run_cli("check-path", str(source), "--json", "--plot", str(plot), "--record", str(log))
    assert done.returncode == 0, done.stderr
    document = json.loads(done.stdout)
    assert document["ok"] is True and document["planned_torsion"] is True
    assert len(document["waypoints"]) == 40 and len(document["segments"]) == 39
    for waypoint in document["waypoints"]:
        assert set(waypoint) >= WAYPOINT_KEYS and waypoint["reachable"]
    for segment in document["segments"]:
        assert set(segment) >= SEGMENT_KEYS
        assert segment["ok"] and segment["first_violation_s"] is None
    baseline = document["psi_zero_baseline"]
    assert set(baseline) == {"waypoints_failed", "segments_failed"}
    assert baseline["waypoints_failed"]  # ψ ≡ 0 fails on this path
    # psi_deg is the planned torsion: re-checking those poses independently passes.
    angles = np.radians(
        [[w["phi_deg"], w["theta_deg"], w["psi_deg"]] for w in document["waypoints"]]
    )
    assert check_path(example, positions, angles=angles).ok
    assert plot.stat().st_size > 10_000
    # The record is a CheckPath call that rosbags and mcap_ros2 both read.
    for reader in (read_with_rosbags, read_with_mcap_ros2):
        records = reader(log)
        topics = [topic for topic, _, _ in records]
        assert topics == [
            "/hexapod_workspace/check_path/request",
            "/hexapod_workspace/check_path/response",
        ]
        response = plain(records[1][2])
        assert response["ok"] and response["planned_torsion"]
        assert len(response["poses"]) == 40 and len(response["segments"]) == 39
        assert list(response["psi_zero_waypoints_failed"]) == baseline["waypoints_failed"]
    replay = run_cli("replay", str(log), "--json")
    assert replay.returncode == 0, replay.stderr
    calls = json.loads(replay.stdout)["path_checks"]
    assert calls[0]["ok"] is True and calls[0]["n_waypoints"] == 40
    assert calls[0]["psi_zero_waypoints_failed"] == len(baseline["waypoints_failed"])


def test_fixed_orientations_with_psi_zero_fail_with_exit_1(tmp_path, capsys):
    positions, t, _ = cone()
    rows = np.column_stack([positions, np.degrees(t), np.full(40, 17.0), np.zeros(40)])
    # Columns in another order than the documented one are accepted by name.
    source = write_csv(
        tmp_path / "fixed.csv",
        "phi_deg,theta_deg,psi_deg,x,y,z",
        np.column_stack([rows[:, 3:], rows[:, :3]]),
    )
    out = io.StringIO()
    assert main(["check-path", str(source), "--json"], out=out) == 1
    document = json.loads(out.getvalue())
    assert document["ok"] is False and document["planned_torsion"] is False
    failed = [w["index"] for w in document["waypoints"] if not w["reachable"]]
    assert failed == document["psi_zero_baseline"]["waypoints_failed"]
    bad = [s for s in document["segments"] if not s["ok"]]
    assert bad and all(s["first_violation_s"] is not None for s in bad)
    assert all(len(s["first_violation_pose_deg"]) == 3 for s in bad)
    assert [w["phi_deg"] for w in document["waypoints"]] == pytest.approx(np.degrees(t).tolist())
    stderr = capsys.readouterr().err.strip().splitlines()
    assert len(stderr) == 1 and "unreachable waypoint" in stderr[0] and str(failed[0]) in stderr[0]
    # Text mode names the failing waypoints and moves.
    text = io.StringIO()
    assert main(["check-path", str(source)], out=text) == 1
    assert f"waypoint {failed[0]}: unreachable" in text.getvalue()


def test_no_plan_exit_1_names_the_breaking_waypoint(tmp_path, capsys):
    positions, _, axes = cone(6)
    axes[3] = approach_vector(0.0, np.radians(75.0))
    source = write_csv(tmp_path / "axes.csv", "x,y,z,i,j,k", np.column_stack([positions, axes]))
    out = io.StringIO()
    assert main(["check-path", str(source), "--json", "--psi-step-deg", "30"], out=out) == 1
    document = json.loads(out.getvalue())
    assert document["plan"]["found"] is False
    assert document["plan"]["breakpoint"]["kind"] == "waypoint"
    assert document["plan"]["breakpoint"]["index"] == 3
    assert "waypoint 3" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("header", "rows", "match"),
    [
        ("x,y,z,i,j,k", [[0.2, 0.2, -0.95, 0, 0, 1], [0.2, 0.2, -0.95, 0, 0, 0]], "zero"),
        ("x,y,z,i,j,k", [[0.2, 0.2, -0.95, 0, 0, 1], [0.2, 0.2, -0.95, 0, np.nan, 1]], "finite"),
        ("x,y,z,i,j,k", [[0.2, 0.2, -0.95, 0, 0, 1]], "at least 2"),
        ("x,y,z,phi_deg,theta_deg", [[0, 0, -1.3, 0, 0]] * 2, "expected a header"),
        ("x,y,z,i,j,k,extra", [[0, 0, -1.3, 0, 0, 1, 0]] * 2, "unknown column"),
        (None, [[0, 0, -1.3, 0, 0, 1]] * 2, "header"),
        ("x,y,z,phi_deg,theta_deg,psi_deg", [[1e300, 0, -1.3, 0, 0, 0]] * 2, "within"),
    ],
)
def test_bad_input_exit_2_with_one_line(tmp_path, capsys, header, rows, match):
    source = tmp_path / "bad.csv"
    body = "\n".join(",".join(repr(float(v)) for v in row) for row in rows)
    source.write_text((f"{header}\n" if header else "") + body + "\n", encoding="utf-8")
    assert main(["check-path", str(source), "--json"], out=io.StringIO()) == 2
    stderr = capsys.readouterr().err.strip().splitlines()
    assert len(stderr) == 1 and stderr[0].startswith("hexapod-workspace: error:")
    assert match in stderr[0]


def test_degrees_beyond_float_resolution_keep_their_principal_value(tmp_path):
    # 1e20 + 180 rounds to 1e20 in floating point: reducing "(d + 180) mod 360 - 180" would land
    # 180° away. fmod(d, 360) is exact, so the expected row is the exact principal value.
    principal = math.fmod(1e20, 360.0)
    principal = principal - 360.0 if principal > 180.0 else principal
    rows = np.array([[0.0, 0.0, -1.3, 1e20, 20.0, 10.0], [0.0, 0.0, -1.3, principal, 20.0, 10.0]])
    source = write_csv(tmp_path / "huge.csv", "x,y,z,phi_deg,theta_deg,psi_deg", rows)
    out = io.StringIO()
    main(["check-path", str(source), "--json"], out=out)
    first, second = json.loads(out.getvalue())["waypoints"]
    assert first["margins"] == pytest.approx(second["margins"], abs=1e-12)
    assert first["reachable"] == second["reachable"]


def test_huge_angles_are_their_principal_values(tmp_path):
    rows = np.array(
        [[0.0, 0.0, -1.3, 360.0 * 1e12 + 30.0, 10.0, -720.0], [0.0, 0.0, -1.3, 30, 10, 0]]
    )
    source = write_csv(tmp_path / "big.csv", "x,y,z,phi_deg,theta_deg,psi_deg", rows)
    out = io.StringIO()
    assert main(["check-path", str(source), "--json"], out=out) == 0
    first, second = json.loads(out.getvalue())["waypoints"]
    assert first["margins"] == second["margins"]


def test_the_tool_direction_plot_labels_every_ring_clear_of_the_curves(example):
    """The polar panel of the Motions page's toolpath figure (tool axes on a 17°
    cone off the axis) labels every ring, and no label covers a curve or a tool direction."""
    from cli_support import polar_labels_clear

    from hexapod_workspace import plan_torsion
    from hexapod_workspace.cli.check_path import path_figure

    positions, _, axes = cone()
    plan = plan_torsion(example, positions, axes, max_dpsi=np.radians(5.0))
    figure = path_figure(plan, plan.baseline, example)
    polar = next(a for a in figure.axes if a.name == "polar")
    labels = polar_labels_clear(figure, polar)
    ticks = polar.get_yticks()
    assert labels == {f"{t:g}°" for t in ticks} and len(labels) >= 3


def check_path_json(source: Path) -> tuple[int, dict]:
    out = io.StringIO()
    code = main(["check-path", str(source), "--json"], out=out)
    return code, json.loads(out.getvalue())


def test_columns_in_radians_and_millimetres_give_the_same_verdicts(tmp_path):
    """Every file reader takes the units its header names."""
    positions, t, _ = cone()
    angles = np.column_stack([np.degrees(t), np.full(40, 17.0), np.zeros(40)])
    degrees = write_csv(
        tmp_path / "deg.csv",
        "x,y,z,phi_deg,theta_deg,psi_deg",
        np.column_stack([positions, angles]),
    )
    other = write_csv(
        tmp_path / "rad.csv",
        "theta_rad,x_mm,y_m,z,psi_deg,phi_rad",
        np.column_stack(
            [np.radians(angles[:, 1]), positions[:, 0] * 1e3, positions[:, 1:], angles[:, 2], t]
        ),
    )
    code, expected = check_path_json(degrees)
    assert (code, expected["ok"]) == (1, False)  # psi = 0 fails somewhere on this cone
    code_other, got = check_path_json(other)
    assert code_other == code
    assert [w["reachable"] for w in got["waypoints"]] == [
        w["reachable"] for w in expected["waypoints"]
    ]
    for mine, theirs in zip(got["waypoints"], expected["waypoints"], strict=True):
        assert mine["theta_deg"] == pytest.approx(theirs["theta_deg"], abs=1e-9)
        assert mine["position"] == pytest.approx(theirs["position"], abs=1e-12)


@pytest.mark.parametrize(
    ("content", "match"),
    [
        # errors name the file line (comments and the header count), not numpy's text
        (
            "# path\nx,y,z,i,j,k\n0,0,-1.3,0,0,1\n\n0,0,-1.3\n",
            "line 5: expected 6 values x,y,z,i,j,k, got 3: '0,0,-1.3'",
        ),
        ("x,y,z,i,j,k\n0,0,-1.3,0,0,1\n0,0,-1.3,0,zero,1\n", "line 3: 'zero' is not a number"),
        ("x,y,z,i,j,k\n0,0,-1.3,0,0,1\n0,0,-1.3,0,nan,1\n", "line 3: expected finite numbers"),
        ("x_in,y,z,i,j,k\n0,0,-1.3,0,0,1\n0,0,-1.3,0,0,1\n", "column 'x_in' has unit 'in'"),
        ("x,y,z,phi,theta_deg,psi_deg\n0,0,-1.3,0,0,0\n" * 1, "column 'phi' names no unit"),
    ],
    ids=["short-line", "not-a-number", "nan", "unit", "no-unit"],
)
def test_line_errors_name_the_file_line(tmp_path, capsys, content, match):
    source = tmp_path / "bad.csv"
    source.write_text(content, encoding="utf-8")
    assert main(["check-path", str(source), "--json"], out=io.StringIO()) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert match in line and f"path file {source}" in line
    assert "usecols" not in line and "row" not in line.replace("first row", "")
