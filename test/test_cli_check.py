"""The ``check`` command: output formats, exit codes, absurd input, the poses CSV.

In-process through ``main(argv, out=, err=)``; the console script itself is smoke-tested in
``test_cli_smoke.py``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_support import one_error_line, run_main

from hexapod_workspace import check

#: The constraints of a 6-UPS model (check --json keys them by name, as before the leg
#: architectures).
CONSTRAINT_NAMES = ("leg_length", "base_joint", "platform_joint", "leg_interference", "singularity")

#: What check --json lists for the example, which declares no collision scene.
REPORTED = tuple(name for name in CONSTRAINT_NAMES if name != "collision")


def test_check_json_all_reachable(example):
    code, out, err = run_main(
        "--json", "check", "--pose", "0", "0", "0", "--pose", "30", "20", "10"
    )
    assert code == 0, err
    document = json.loads(out)
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
        assert list(pose["margins"]) == list(REPORTED)
        for name in REPORTED:
            value = expected.margins[name][index]
            if np.isfinite(value):
                assert pose["margins"][name] == pytest.approx(value, rel=1e-11)
            else:  # not evaluated (the singularity margin with a limit of 0): null
                assert pose["margins"][name] is None
        assert pose["limiting_leg"] == expected.limiting_leg[index]


def test_unreachable_exit_1_reason_on_stderr_and_global_options_after_command():
    code, out, err = run_main(
        "check", "--json", "--pose", "0", "60", "0", "--position", "0", "0", "-1.3"
    )
    assert code == 1
    pose = json.loads(out)["poses"][0]
    assert pose["reachable"] is False
    assert pose["violated"] == ["leg_length", "platform_joint"]
    assert pose["margins"]["leg_length"] < 0
    # docs/cli.md: the reason for exit 1 goes to stderr.
    assert err == "hexapod-workspace: 1 of 1 poses unreachable\n"


def test_check_table_says_its_columns_are_margins():
    code, out, err = run_main("check", "--pose", "0", "0", "0", "--pose", "0", "60", "0")
    assert code == 1 and "1 of 2 poses unreachable" in err
    lines = out.splitlines()
    assert lines[0] == "position: (0.0000, 0.0000, -1.3000) m"
    assert "margin to each limit (>= 0 holds, < 0 violated)" in lines[1]
    assert "leg_length" in lines[2] and "limiting" in lines[2] and "[deg]" in lines[3]
    assert " yes " in lines[4] and " NO " in lines[5]
    assert lines[5].endswith("leg_length,platform_joint")
    assert lines[-1] == "1/2 poses reachable"


@pytest.mark.parametrize(
    ("architecture", "z", "unit", "factor"),
    [("pus", -0.80, "[mm]", 1e3), ("rus", 0.52, "[deg]", math.degrees(1.0))],
)
def test_check_table_gives_the_actuator_margin_in_the_architecture_unit(
    architecture, z, unit, factor
):
    """A slide's stroke left in mm, a crank's range left in deg; JSON stays SI."""
    config = str(Path(__file__).resolve().parents[1] / "config" / f"example_{architecture}.yaml")
    pose = ("--config", config, "check", "--position", "0", "0", str(z), "--pose", "0", "5", "10")
    code, out, _ = run_main(*pose)
    lines = out.splitlines()
    column = lines[2].split().index("actuator") - 1  # the unit row has no "reachable" heading
    assert code == 0 and lines[3].split()[column] == unit
    _, text, _ = run_main("--json", *pose)
    si = json.loads(text)["poses"][0]["margins"]["actuator"]
    value = float(lines[4].split()[column + 1])  # "yes" under "reachable"
    assert value == pytest.approx(si * factor, abs=1e-3)


def test_huge_angles_get_the_verdict_of_the_orientation_they_denote(example):
    """1e20 deg is 280 deg (1e20 mod 360, exact in floating point); the verdict and the
    margins are those of 280 deg, while the output echoes what the user typed."""
    assert math.fmod(1e20, 360.0) == 280.0
    code, out, _ = run_main(
        "--json", "check", "--pose", "1e20", "10", "150", "--pose", "280", "10", "150",
        "--pose", "0", "-350", "-1e300",
    )  # fmt: skip
    poses = json.loads(out)["poses"]
    assert poses[0]["phi_deg"] == 1e20
    assert poses[0]["margins"] == pytest.approx(poses[1]["margins"], rel=1e-12, abs=1e-12)
    assert poses[0]["reachable"] == poses[1]["reachable"]
    expected = check(example, np.radians([[0.0, 10.0, math.fmod(-1e300, 360.0)]]))
    for name in REPORTED:
        value = float(expected.margins[name][0])
        # Not evaluated margins (+inf: the singularity margin with a limit of 0) are null.
        wanted = pytest.approx(value, abs=1e-12) if math.isfinite(value) else None
        assert poses[2]["margins"][name] == wanted
    assert code == (0 if all(p["reachable"] for p in poses) else 1)


def test_huge_angles_in_the_table_keep_the_columns():
    _, out, _ = run_main("check", "--pose", "1e20", "10", "150", "--pose", "0", "10", "150")
    rows = out.splitlines()[4:6]
    assert rows[0].index("NO") == rows[1].index("NO")


def test_disabled_interference_is_null_in_json(tmp_path, example):
    parameters = example.to_parameters()
    parameters["limits.leg_diameter"] = 0.0
    config = tmp_path / "no_interference.yaml"
    config.write_text(
        "/**:\n  ros__parameters:\n"
        + "".join(f"    {name}: {value!r}\n" for name, value in parameters.items())
    )
    code, out, err = run_main("--config", str(config), "--json", "check", "--pose", "0", "10", "0")
    assert code == 0, err
    assert json.loads(out)["poses"][0]["margins"]["leg_interference"] is None


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["check"], "give at least one --pose"),
        (["check", "--pose", "0", "nan", "0"], "--pose: expected finite numbers (degrees)"),
        (["check", "--pose", "0", "0"], "--pose: expected 3 numbers PHI THETA PSI"),
        (["check", "--pose", "a", "0", "0"], "invalid float value"),
        (["check", "--bogus"], "unrecognized arguments: --bogus"),
        (["--position", "0", "inf", "0", "check", "--pose", "0", "0", "0"], "--position"),
        (["--config", "/nonexistent.yaml", "check", "--pose", "0", "0", "0"], "cannot read"),
        (["check", "--poses-file", "/nonexistent.csv"], "cannot read poses file"),
        (["frobnicate"], "invalid choice"),
        # Negative numbers in any notation are values, not options.
        (["check", "--pose", "0", "0", "-inf"], "--pose: expected finite numbers"),
        (
            ["check", "--pose", "0", "0", "0", "--position", "0", "0", "-1e300"],
            "--position: expected a distance from the base origin of at most 1e+06 m",
        ),
        # --record writes MCAP only, never over a file that is not a log.
        (["check", "--pose", "0", "0", "0", "--record", "poses.csv"], "ending in .mcap"),
        (["check", "--pose", "0", "0", "0", "--record", "/nope/x.mcap"], "folder /nope does not"),
    ],
)
def test_bad_input_exit_2_one_line(args, reason):
    code, out, err = run_main(*args)
    assert code == 2
    assert out == ""
    assert reason in one_error_line(err)


def test_negative_numbers_in_exponent_form_are_values():
    code, out, err = run_main(
        "--json", "check", "--pose", "-1.5e1", "1e1", "-0", "--position", "0", "0", "-1.3e0"
    )
    assert code == 0, err
    document = json.loads(out)
    assert document["position"] == [0.0, 0.0, -1.3]
    assert document["poses"][0]["phi_deg"] == -15.0


def test_huge_positions_are_refused_never_answered_with_nan(example):
    """A margin is a finite number, or the request is refused with a reason."""
    from hexapod_workspace.errors import InputError

    for position in ([1e300, 0, 0], [0, -1e200, 1e200], [2e6, 0, 0]):
        with pytest.raises(InputError, match="at most 1e\\+06 m"):
            check(example, [0.0, 0.0, 0.0], position)
    rng = np.random.default_rng(11)
    angles = np.column_stack(
        [rng.uniform(-1e9, 1e9, 200), rng.uniform(0, 3, 200), rng.uniform(-1e9, 1e9, 200)]
    )
    for scale in (1.0, 1e3, 9.9e5):
        position = rng.normal(size=3)
        position *= scale / np.linalg.norm(position)
        result = check(example, angles, position, singularity=True)  # every margin evaluated
        for name in REPORTED:
            assert np.all(np.isfinite(result.margins[name])), (scale, name)
        assert result.violated == [
            [n for n in CONSTRAINT_NAMES if result.margins[n][k] < 0] for k in range(len(result))
        ]


def test_record_refuses_to_overwrite_a_file_that_is_not_a_log(tmp_path):
    precious = tmp_path / "poses.mcap"
    precious.write_text("phi_deg,theta_deg,psi_deg\n1,2,3\n")
    code, _, err = run_main("check", "--pose", "0", "0", "0", "--record", str(precious))
    assert code == 2 and "is not an MCAP log; not replaced (use --force)" in one_error_line(err)
    assert precious.read_text().startswith("phi_deg")
    code, _, err = run_main("check", "--pose", "0", "0", "0", "--record", str(precious), "--force")
    assert code == 0, err
    assert precious.read_bytes().startswith(b"\x89MCAP0\r\n")
    # An existing log is ours to replace.
    code, _, err = run_main("check", "--pose", "0", "0", "0", "--record", str(precious))
    assert code == 0 and f"recorded 1 result(s) to {precious}" in err


# ---------------------------------------------------------------------------- poses CSV
def poses_run(tmp_path, content: str, *extra: str) -> tuple[int, str, str]:
    path = tmp_path / "poses.csv"
    path.write_text(content)
    return run_main("--json", "check", "--poses-file", str(path), *extra)


def test_poses_file_with_header_in_input_order(tmp_path, example):
    rng = np.random.default_rng(7)
    poses = np.column_stack(
        [rng.uniform(-180, 180, 500), rng.uniform(0, 50, 500), rng.uniform(-60, 60, 500)]
    ).round(6)
    path = tmp_path / "poses.csv"
    np.savetxt(
        path, poses, delimiter=",", fmt="%.6f", header="phi_deg,theta_deg,psi_deg", comments=""
    )
    code, out, _ = run_main("--json", "check", "--poses-file", str(path))
    document = json.loads(out)
    expected = check(example, np.radians(poses))
    assert code == (0 if expected.reachable.all() else 1)
    got = np.array([[p["phi_deg"], p["theta_deg"], p["psi_deg"]] for p in document["poses"]])
    np.testing.assert_allclose(got, poses, rtol=1e-11)
    assert [p["reachable"] for p in document["poses"]] == expected.reachable.tolist()
    assert [p["violated"] for p in document["poses"]] == expected.violated


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        # Errors name the line of the file (comments, blank lines and the header count).
        ("phi_deg,theta_deg,psi_deg\n1,2\n", "line 2: expected 3 values"),
        ("# poses\n\n1,2,3\n4,5\n", "line 4: expected 3 values phi_deg,theta_deg,psi_deg, got 2"),
        ("1,2,3,4\n", "line 1: expected 3 values phi_deg,theta_deg,psi_deg, got 4: '1,2,3,4'"),
        ("0,0,0\n1,nan,3\n", "line 2: expected finite numbers, got '1,nan,3'"),
        ("phi_deg,theta_deg,psi_deg\n", "no poses"),
        ("1,2,x\n", "line 1: 'x' is not a number"),
        ("1,5;2;3\n", "'1,5' is not a number (use a decimal point)"),
        # header names are read, never guessed
        ("tilt,phi_deg,psi_deg\n1,2,3\n", "line 1: unknown column 'tilt' (expected phi_deg or"),
        ("phi,theta,psi\n1,2,3\n", "line 1: column 'phi' names no unit (expected phi_deg or"),
        ("phi_grad,theta_deg,psi_deg\n1,2,3\n", "column 'phi_grad' has unit 'grad', not taken"),
        ("# c\nphi_deg,phi_rad,psi_deg\n1,2,3\n", "line 2: phi given twice"),
        ("phi_deg,theta_deg\n1,2\n", "line 1: no column for psi"),
    ],
)
def test_bad_poses_file_exit_2(tmp_path, content, reason):
    code, out, err = poses_run(tmp_path, content)
    assert (code, out) == (2, "")
    assert reason in one_error_line(err)
    assert "usecols" not in err


@pytest.mark.parametrize(
    ("header", "row"),
    [
        ("theta_deg,phi_deg,psi_deg", "60,0,0"),  # a user's file: read as phi = 60 before
        ("psi_deg;theta_deg;phi_deg", "0;60;0"),
        ("phi_rad,theta_rad,psi_rad", f"0,{math.radians(60.0)!r},0"),  # read as degrees before
        ("THETA_RAD psi_deg phi_deg", f"{math.radians(60.0)!r} 0 0"),
    ],
)
def test_poses_file_columns_are_read_by_name_and_unit(tmp_path, example, header, row):
    """Theta = 60 deg is unreachable whatever the column order or unit."""
    code, out, err = poses_run(tmp_path, f"{header}\n{row}\n")
    (pose,) = json.loads(out)["poses"]
    assert [pose["phi_deg"], pose["theta_deg"], pose["psi_deg"]] == pytest.approx([0, 60, 0])
    assert not check(example, np.radians([[0.0, 60.0, 0.0]])).reachable[0]
    assert (code, pose["reachable"]) == (1, False), err


def test_poses_file_first_numeric_row_is_data_and_separators(tmp_path):
    for content in ("10,20,5\n30,10,0\n", "10;20;5\n30;10;0\n", "10 20 5\n30\t10\t0\n"):
        code, out, err = poses_run(tmp_path, content)
        assert code == 0, err
        assert [p["phi_deg"] for p in json.loads(out)["poses"]] == [10, 30]


def test_poses_from_standard_input():
    code, out, err = run_main("--json", "check", "--poses-file", "-", stdin="10,20,5\n0,0,0\n")
    assert code == 0, err
    assert len(json.loads(out)["poses"]) == 2


def test_invalid_geometry_exit_2(tmp_path, example):
    parameters = example.to_parameters()
    parameters["limits.leg_length_min"] = [2.0]
    config = tmp_path / "bad.yaml"
    config.write_text(
        "hexapod_workspace:\n  ros__parameters:\n"
        + "".join(f"    {name}: {value!r}\n" for name, value in parameters.items())
    )
    code, _, err = run_main("--config", str(config), "check", "--pose", "0", "0", "0")
    assert code == 2
    assert "limits.leg_length_min: expected < limits.leg_length_max" in one_error_line(err)


def test_misspelt_section_is_named(tmp_path, example):
    """``limitz:`` is named, not reported as a missing limits parameter."""
    parameters = example.to_parameters()
    lines = ["hexapod_workspace:", "  ros__parameters:"]
    for group in ("geometry", "limitz", "pose"):
        lines.append(f"    {group}:")
        source = "limits" if group == "limitz" else group
        for name, value in parameters.items():
            if name.startswith(source + "."):
                lines.append(f"      {name.split('.', 1)[1]}: {value!r}")
    config = tmp_path / "typo.yaml"
    config.write_text("\n".join(lines) + "\n")
    code, _, err = run_main("--config", str(config), "check", "--pose", "0", "0", "0")
    assert code == 2
    assert "limitz: unknown section (expected one of" in one_error_line(err)
    assert "limits" in err


def test_unreachable_values_have_no_nan():
    code, out, _ = run_main("--json", "check", "--singularity", "--pose", "0", "170", "0")
    assert code == 1
    margins = json.loads(out)["poses"][0]["margins"]
    assert all(math.isfinite(v) for v in margins.values())


def test_check_record_then_replay(tmp_path):
    log = tmp_path / "check.mcap"
    code, _, err = run_main(
        "check", "--pose", "0", "10", "0", "--pose", "0", "70", "0", "--record", str(log)
    )
    assert code == 1, err
    code, out, err = run_main("replay", str(log))
    assert code == 0, err
    assert "/hexapod_workspace/check_poses/request" in out
    assert "1/2 reachable" in out


@pytest.mark.parametrize(
    ("changes", "hint"),
    [
        # leg limits in millimetres (it was a warning and "unreachable")
        ({"limits.leg_length_min": [800.0], "limits.leg_length_max": [1450.0]}, "limits"),
        ("geometry-mm", "geometry"),
    ],
    ids=["limits-in-mm", "geometry-in-mm"],
)
def test_a_model_in_millimetres_is_refused_with_the_unit_hint(tmp_path, example, changes, hint):
    parameters = example.to_parameters()
    if changes == "geometry-mm":
        changes = {
            name: [1000.0 * v for v in parameters[name]]
            for name in ("geometry.base_joints", "geometry.platform_joints")
        } | {"geometry.home_position": [0.0, 0.0, -1300.0], "pose.position": [0.0, 0.0, -1300.0]}
    parameters.update(changes)
    config = tmp_path / "mm.yaml"
    config.write_text(
        "hexapod_workspace:\n  ros__parameters:\n"
        + "".join(f"    {name}: {value!r}\n" for name, value in parameters.items())
    )
    code, out, err = run_main("--config", str(config), "check", "--pose", "0", "0", "0")
    assert (code, out) == (2, "")
    line = one_error_line(err)
    assert f"parameters file {config}:" in line
    if hint == "geometry":  # the limits alone are caught by the one unit rule, before the home
        assert "home pose" in line and "unreachable" in line
    assert f"{hint}" in line and "millimetres" in line and "divided by 1000" in line
