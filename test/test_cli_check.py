"""The ``check`` command through a real subprocess: output formats and exit codes."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from cli_support import run_cli

from hexapod_workspace import CONSTRAINT_NAMES, check


def test_check_json_all_reachable(example):
    done = run_cli("--json", "check", "--pose", "0", "0", "0", "--pose", "30", "20", "10")
    assert done.returncode == 0, done.stderr
    document = json.loads(done.stdout)
    assert document["position"] == [0.0, 0.0, -1.3]
    assert [p["theta_deg"] for p in document["poses"]] == [0, 20]
    expected = check(example, np.radians([[0, 0, 0], [30, 20, 10]]))
    for index, pose in enumerate(document["poses"]):
        assert set(pose) == {
            "phi_deg",
            "theta_deg",
            "psi_deg",
            "reachable",
            "violated",
            "margins",
            "limiting_leg",
        }
        assert pose["reachable"] is True
        assert pose["violated"] == []
        assert list(pose["margins"]) == list(CONSTRAINT_NAMES)
        for name in CONSTRAINT_NAMES:
            assert pose["margins"][name] == pytest.approx(expected.margins[name][index], rel=1e-11)
        assert pose["limiting_leg"] == expected.limiting_leg[index]


def test_check_some_unreachable_exit_1_and_global_options_after_command():
    done = run_cli("check", "--json", "--pose", "0", "60", "0", "--position", "0", "0", "-1.3")
    assert done.returncode == 1, done.stderr
    pose = json.loads(done.stdout)["poses"][0]
    assert pose["reachable"] is False
    assert pose["violated"] == ["leg_length", "platform_joint"]
    assert pose["margins"]["leg_length"] < 0


def test_check_table_is_readable():
    done = run_cli("check", "--pose", "0", "0", "0", "--pose", "0", "60", "0")
    assert done.returncode == 1
    lines = done.stdout.splitlines()
    assert lines[0] == "position: (0.0000, 0.0000, -1.3000) m"
    assert "leg_length" in lines[1] and "[deg]" in lines[2]
    assert " yes " in lines[3] and " NO " in lines[4]
    assert lines[4].endswith("leg_length,platform_joint")
    assert lines[-1] == "1/2 poses reachable"


def test_poses_file_with_header_in_input_order(tmp_path, example):
    rng = np.random.default_rng(7)
    poses = np.column_stack(
        [rng.uniform(-180, 180, 500), rng.uniform(0, 50, 500), rng.uniform(-60, 60, 500)]
    ).round(6)
    path = tmp_path / "poses.csv"
    np.savetxt(
        path, poses, delimiter=",", fmt="%.6f", header="phi_deg,theta_deg,psi_deg", comments=""
    )
    done = run_cli("--json", "check", "--poses-file", str(path))
    document = json.loads(done.stdout)
    expected = check(example, np.radians(poses))
    assert done.returncode == (0 if expected.reachable.all() else 1)
    got = np.array([[p["phi_deg"], p["theta_deg"], p["psi_deg"]] for p in document["poses"]])
    np.testing.assert_allclose(got, poses, rtol=1e-11)
    assert [p["reachable"] for p in document["poses"]] == expected.reachable.tolist()
    assert [p["violated"] for p in document["poses"]] == expected.violated


def test_disabled_interference_is_null_in_json(tmp_path, example):
    parameters = example.to_parameters()
    parameters["limits.leg_diameter"] = 0.0
    config = tmp_path / "no_interference.yaml"
    config.write_text(
        "/**:\n  ros__parameters:\n"
        + "".join(f"    {name}: {value!r}\n" for name, value in parameters.items())
    )
    done = run_cli("--config", str(config), "--json", "check", "--pose", "0", "10", "0")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["poses"][0]["margins"]["leg_interference"] is None


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["check"], "give at least one --pose"),
        (["check", "--pose", "0", "nan", "0"], "--pose: expected finite numbers"),
        (["check", "--pose", "0", "0"], "argument --pose: expected 3 arguments"),
        (["check", "--pose", "a", "0", "0"], "invalid float value"),
        (["check", "--bogus"], "unrecognized arguments: --bogus"),
        (["--position", "0", "inf", "0", "check", "--pose", "0", "0", "0"], "--position"),
        (["--config", "/nonexistent.yaml", "check", "--pose", "0", "0", "0"], "cannot read"),
        (["check", "--poses-file", "/nonexistent.csv"], "cannot read poses file"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_bad_input_exit_2_one_line(args, reason):
    done = run_cli(*args)
    assert done.returncode == 2
    assert done.stdout == ""
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("hexapod-workspace: error:")
    assert reason in lines[0]
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        ("phi_deg,theta_deg,psi_deg\n1,2\n", "expected 3 columns"),
        ("1,2,3\n4,5\n", "expected rows phi_deg,theta_deg,psi_deg"),
        ("1,2,3,4\n", "expected 3 columns"),
        ("1,nan,3\n", "expected finite numbers, row 1"),
        ("phi_deg,theta_deg,psi_deg\n", "no poses"),
        ("1,2,x\n", "expected rows"),
    ],
)
def test_bad_poses_file_exit_2(tmp_path, content, reason):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    done = run_cli("check", "--poses-file", str(path))
    assert done.returncode == 2
    assert reason in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_invalid_geometry_exit_2(tmp_path, example):
    parameters = example.to_parameters()
    parameters["limits.leg_length_min"] = [2.0]
    config = tmp_path / "bad.yaml"
    config.write_text(
        "hexapod_workspace:\n  ros__parameters:\n"
        + "".join(f"    {name}: {value!r}\n" for name, value in parameters.items())
    )
    done = run_cli("--config", str(config), "check", "--pose", "0", "0", "0")
    assert done.returncode == 2
    assert "limits.leg_length_min: expected < limits.leg_length_max" in done.stderr


def test_help_lists_the_commands():
    done = run_cli("--help")
    assert done.returncode == 0
    assert "check" in done.stdout


def test_unreachable_values_have_no_nan(example):
    done = run_cli("--json", "check", "--pose", "0", "170", "0")
    assert done.returncode == 1
    margins = json.loads(done.stdout)["poses"][0]["margins"]
    assert all(math.isfinite(v) for v in margins.values())


def test_check_record_then_replay(tmp_path):
    log = tmp_path / "check.mcap"
    done = run_cli(
        "check", "--pose", "0", "10", "0", "--pose", "0", "70", "0", "--record", str(log)
    )
    assert done.returncode == 1, done.stderr
    replay = run_cli("replay", str(log))
    assert replay.returncode == 0, replay.stderr
    assert "/hexapod_workspace/check_poses/request" in replay.stdout
    assert "1/2 reachable" in replay.stdout
