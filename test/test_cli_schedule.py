"""``hexapod-workspace schedule``: the certified schedule through the CLI (CSV and CL files,
text, JSON, plot), against the core and the JSON's own grid; bad input exits 2 in one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from cli_support import one_error_line, run_main
from test_cli_cam import POCKET, cell_config

from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.loading import example_manipulator
from hexapod_workspace.core.motions.schedule import schedule_path

LIMITS = "      actuator_speed_max: [0.02]\n      actuator_accel_max: [0.2]\n"
WAYPOINTS = np.array(
    [
        [0.0, 0.0, -1.3, 0.0, 0.0, 0.0],
        [0.05, 0.0, -1.3, 0.0, 10.0, 0.0],
        [0.05, 0.05, -1.3, 0.0, 10.0, 0.0],
        [0.10, 0.05, -1.3, 0.0, 10.0, 0.0],
        [0.13, 0.05, -1.3, 0.0, 10.0, 0.0],  # collinear with the move before: runs through
    ]
)


@pytest.fixture
def csv_path(tmp_path: Path) -> Path:
    path = tmp_path / "square.csv"
    np.savetxt(
        path,
        WAYPOINTS,
        delimiter=",",
        header="x,y,z,phi_deg,theta_deg,psi_deg",
        comments="",
        fmt="%.17g",
    )
    return path


def test_csv_schedule_json_matches_the_core_and_its_own_grid(tmp_path, csv_path):
    config = cell_config(tmp_path, "", LIMITS)
    code, out, _ = run_main(
        "schedule", str(csv_path), "--config", str(config), "--feed-mm-min", "1200", "--json"
    )
    assert code == 0
    report = json.loads(out)
    core = schedule_path(
        example_manipulator(),
        WAYPOINTS[:, :3],
        tt_to_matrix(np.radians(WAYPOINTS[:, 3:])),
        speed_limits=[0.02],
        accel_limits=[0.2],
        feeds=np.full(4, 0.02),
    )
    assert report["duration_s"] == pytest.approx(core.duration, rel=1e-12)
    assert report["programmed_duration_s"] == pytest.approx(0.18 / 0.02, rel=1e-9)
    assert report["duration_s"] > report["programmed_duration_s"]  # rest at ends and corners
    assert report["path_ok"] is True and report["actuator_unit"] == "m"
    assert report["actuator_accel_max"] == [0.2] * 6
    # the grid as documented: ṡ² linear in s between two nodes of one move, so each interval
    # lasts 2Δs/(ṡ_a + ṡ_b); summed, the duration
    s = np.array([g["s"] for g in report["grid"]])
    sdot = np.array([g["sdot"] for g in report["grid"]])
    step = np.diff(s)
    inside = step > 0.0
    assert np.all(step >= 0.0) and sdot[0] == 0.0 and sdot[-1] == 0.0
    total = np.sum(2.0 * step[inside] / (sdot[:-1] + sdot[1:])[inside])
    assert total == pytest.approx(report["duration_s"], rel=1e-9)
    # corners at waypoints 1 and 2 stop; waypoint 3 (collinear moves) runs through
    assert report["stops"] == [0, 1, 2, 4]
    moves = report["moves"]
    assert len(moves) == 4 and moves[-1]["t_end_s"] == pytest.approx(report["duration_s"])
    for move in moves:
        assert move["feed_peak_mm_min"] <= 1200.0 * (1 + 1e-9)
        assert max(move["actuator_speed_peak"]) <= 0.02 * (1 + 1e-12)
        assert max(move["actuator_accel_peak"]) <= 0.2 * (1 + 1e-12)
        assert move["limited_by"] == {"kind": "feed", "actuator": None}
    # a ceiling below every actuator limit's feed: the ceiling binds and the time grows
    code, out, _ = run_main(
        "schedule",
        str(csv_path),
        "--config",
        str(config),
        "--feed-mm-min",
        "1200",
        "--feed-max-mm-min",
        "600",
        "--json",
    )
    slower = json.loads(out)
    assert code == 0 and slower["duration_s"] > 1.9 * report["duration_s"]
    assert all(m["feed_ceiling_mm_min"] == pytest.approx(600.0) for m in slower["moves"])


def test_actuator_limits_below_the_feed_name_the_actuator_in_text(tmp_path, csv_path):
    config = cell_config(tmp_path, "", "      actuator_speed_max: [0.004]\n")
    code, out, err = run_main(
        "schedule", str(csv_path), "--config", str(config), "--feed-mm-min", "1200"
    )
    assert code == 0, err
    assert out.startswith("schedule: ")
    assert "at the programmed feeds" in out
    assert "below the programmed feed: 4 move(s)" in out
    assert "limited by actuator" in out and "velocity" in out
    assert "acceleration 0 m/s²" in out  # no acceleration limit configured


def test_cl_file_schedule_per_tool_with_lines_and_plot(tmp_path):
    cell = Path(__file__).resolve().parents[1] / "examples" / "cell_gpm.yaml"
    text = cell.read_text(encoding="utf-8").replace(
        "      actuator_speed_max: [0.05]\n",
        "      actuator_speed_max: [0.05]\n      actuator_accel_max: [0.5]\n",
    )
    assert text != cell.read_text(encoding="utf-8")
    config = tmp_path / "cell.yaml"
    config.write_text(text, encoding="utf-8")
    plot = tmp_path / "schedule.png"
    code, out, err = run_main(
        "schedule",
        str(POCKET),
        "--config",
        str(config),
        "--rapid-feed-mm-min",
        "3000",
        "--rotary-feed-deg-min",
        "3600",
        "--plot",
        str(plot),
        "--json",
    )
    assert code == 0, err
    report = json.loads(out)
    assert len(report["parts"]) == 2  # LOADTL: a tool change, a rest
    assert report["duration_s"] == pytest.approx(sum(p["duration_s"] for p in report["parts"]))
    assert report["programmed_duration_s"] is not None  # every move has a feed
    lines = [m["line"] for p in report["parts"] for m in p["moves"]]
    assert lines == sorted(lines) and all(isinstance(n, int) for n in lines)
    kinds = {m["limited_by"]["kind"] for p in report["parts"] for m in p["moves"]}
    assert "feed" in kinds and "velocity" in kinds
    assert plot.stat().st_size > 10_000
    for part in report["parts"]:
        assert part["grid"][0]["sdot"] == 0.0 and part["grid"][-1]["sdot"] == 0.0


def test_bad_input_exits_2_in_one_line(tmp_path, csv_path):
    bad = cell_config(tmp_path, "", "      actuator_accel_max: [-1.0]\n")
    code, _, err = run_main("schedule", str(csv_path), "--config", str(bad))
    assert code == 2
    assert "limits.actuator_accel_max: expected values >= 0" in one_error_line(err)
    code, _, err = run_main("schedule", str(csv_path), "--feed-max-mm-min", "0")
    assert code == 2
    assert "--feed-max-mm-min: expected a value > 0" in one_error_line(err)
    # no feed and no actuator limit: nothing bounds the speed
    unlimited = cell_config(tmp_path, "", "")
    code, _, err = run_main("schedule", str(csv_path), "--config", str(unlimited))
    assert code == 2
    assert "move 1: no limit bounds its speed" in one_error_line(err)


APPROACH = """UNITS / MM
MULTAX / ON
RAPID
GOTO / 0.0, 0.0, 25.0, 0.0, 0.0, 1.0
RAPID
GOTO / 0.0, 0.0, 5.0, 0.0, 0.0, 1.0
FEDRAT / 250.0, MMPM
GOTO / 0.0, 0.0, -4.0, 0.0, 0.0, 1.0
GOTO / 10.0, 0.0, -4.0, 0.0, 0.0, 1.0
"""


def test_stop_at_rapids_rests_where_rapid_runs_begin_and_end(tmp_path):
    """A rapid approach straight into a plunge along the same line: the schedule runs through
    their waypoint, and rests there with --stop-at-rapids."""
    path = tmp_path / "approach.cl"
    path.write_text(APPROACH, encoding="utf-8")
    cell = Path(__file__).resolve().parents[1] / "examples" / "cell_gpm.yaml"
    arguments = ["schedule", str(path), "--config", str(cell), "--json"]
    arguments += ["--rapid-feed-mm-min", "3000"]
    code, out, err = run_main(*arguments)
    assert code == 0, err
    plain = json.loads(out)
    assert [m["rapid"] for m in plain["moves"]] == [True, False, False]
    assert plain["stops"] == [0, 2, 3]  # run through waypoint 1; the corner at 2 rests
    code, out, err = run_main(*arguments, "--stop-at-rapids")
    assert code == 0, err
    stopped = json.loads(out)
    assert stopped["stops"] == [0, 1, 2, 3]
    assert stopped["duration_s"] > plain["duration_s"]
