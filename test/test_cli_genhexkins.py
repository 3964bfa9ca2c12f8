"""``import-genhexkins``: LinuxCNC's hexapod simulation (test/data/linuxcnc/SOURCES.md) as a
parameters file, checked against genhexkins's own inverse kinematics written in plain numpy
from ``genhexkins_math.c`` (strut_i = q + R·(a_i + o·z) − (b_i + o·z), R = Rz(C)·Ry(B)·Rx(A),
a_i the platform joints, b_i the base joints, o = spindle-offset + tool-offset)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_support import run_main
from test_paired_joints import LINUXCNC_BASE, LINUXCNC_PLATFORM

from hexapod_workspace.core.base.rotations import xyz_fixed_to_matrix
from hexapod_workspace.core.evaluation.check import inverse_kinematics
from hexapod_workspace.core.evaluation.loading import load_manipulator

SIM = Path(__file__).parent / "data" / "linuxcnc" / "hexapod-sim"
INCH = 0.0254
ARGS = ("--leg-length", "25", "35", "--joint-max-angle-deg", "40", "--leg-diameter", "1.5")


def genhex_struts(pose: np.ndarray, offset: float) -> np.ndarray:
    """genhexkins's strut lengths (inches) of pose (x, y, z in inches, A, B, C in degrees)."""
    a, b, c = np.radians(pose[3:])

    def rx(t: float) -> np.ndarray:
        return np.array([[1, 0, 0], [0, math.cos(t), -math.sin(t)], [0, math.sin(t), math.cos(t)]])

    def ry(t: float) -> np.ndarray:
        return np.array([[math.cos(t), 0, math.sin(t)], [0, 1, 0], [-math.sin(t), 0, math.cos(t)]])

    def rz(t: float) -> np.ndarray:
        return np.array([[math.cos(t), -math.sin(t), 0], [math.sin(t), math.cos(t), 0], [0, 0, 1]])

    rotation = rz(c) @ ry(b) @ rx(a)
    shift = np.array([0.0, 0.0, offset])
    struts = pose[:3] + (rotation @ (LINUXCNC_PLATFORM + shift).T).T - (LINUXCNC_BASE + shift)
    return np.linalg.norm(struts, axis=1)


def _import(tmp_path: Path, *extra: str, hal: tuple[Path, ...] = (SIM / "kinematics.hal",)):
    output = tmp_path / "machine.yaml"
    halargs = [arg for path in hal for arg in ("--hal", str(path))]
    code, out, err = run_main(
        "import-genhexkins", "--ini", str(SIM / "hexapod.ini"), *halargs, *extra, "-o", str(output)
    )
    return code, out, err, output


def test_the_simulation_converts_and_its_struts_are_linuxcnc_s(tmp_path):
    code, out, err, output = _import(tmp_path, *ARGS, "--paired-joint-length", "4")
    assert code == 0, err
    assert "legs sharing a joint: 3 pair(s) (1 and 6, 2 and 3, 4 and 5)" in out
    assert "passed over (cannot change a strut length): genhexkins.max-error (1)" in out
    model = load_manipulator(output)
    np.testing.assert_allclose(model.base_joints, LINUXCNC_BASE * INCH, atol=1e-15)
    np.testing.assert_allclose(model.home_position, [0.0, 0.0, 20 * INCH], atol=1e-15)
    assert model.paired_joint_length == pytest.approx(4 * INCH)
    rng = np.random.default_rng(4)
    poses = np.column_stack(
        [rng.uniform(-3, 3, (50, 2)), rng.uniform(17, 23, 50), rng.uniform(-15, 15, (50, 3))]
    )
    for pose in poses:
        legs = inverse_kinematics(
            model, xyz_fixed_to_matrix(np.radians(pose[3:]))[None], pose[:3] * INCH
        )
        np.testing.assert_allclose(legs.lengths[0] / INCH, genhex_struts(pose, 0.0), atol=1e-9)
    # The written file answers check in LinuxCNC's A, B, C.
    code, out, err = run_main(
        "--config", str(output), "--json", "check", "--angles", "xyz-fixed", "--pose", "5", "0", "0"
    )
    assert code == 0, err
    assert json.loads(out)["poses"][0]["reachable"] is True


def test_spindle_and_tool_offsets_move_both_joint_sets(tmp_path):
    hal = tmp_path / "offsets.hal"
    hal.write_text(
        "setp genhexkins.spindle-offset 2.0\n"
        "net tool-offset motion.tooloffset.z => genhexkins.tool-offset\n"
    )
    hals = (SIM / "kinematics.hal", hal)
    code, _, err, _ = _import(tmp_path, *ARGS, "--paired-joint-length", "4", hal=hals)
    assert code == 2
    assert "genhexkins.tool-offset: driven by a 'net'" in err
    code, out, err, output = _import(
        tmp_path, *ARGS, "--paired-joint-length", "4", "--tool-offset", "3", hal=hals
    )
    assert code == 0, err
    assert "offset added to the joints' z: 5 inch" in out
    code, out, err, _ = _import(
        tmp_path, *ARGS, "--paired-joint-length", "4", "--tool-offset", "3", "--json", hal=hals
    )
    assert code == 0, err
    summary = json.loads(out)
    assert summary["joint_z_offset"] == 5.0 and summary["linear_unit"] == "inch"
    assert summary["legs_sharing_a_joint"] == [[1, 6], [2, 3], [4, 5]]
    model = load_manipulator(output)
    pose = np.array([1.0, -2.0, 21.0, 8.0, -6.0, 20.0])
    legs = inverse_kinematics(
        model, xyz_fixed_to_matrix(np.radians(pose[3:]))[None], pose[:3] * INCH
    )
    np.testing.assert_allclose(legs.lengths[0] / INCH, genhex_struts(pose, 5.0), atol=1e-9)
    # Tilted, the offset matters (at A = B = 0 it would not).
    assert np.max(np.abs(genhex_struts(pose, 5.0) - genhex_struts(pose, 0.0))) > 0.1


@pytest.mark.parametrize(
    ("hal_text", "extra", "message"),
    [
        (
            "",
            ("--joint-max-angle-deg", "40"),
            "[JOINT_0] MIN_LIMIT = -1000: expected the shortest strut length",
        ),
        ("setp genhexkins.screw-lead 5\n", ARGS, "genhexkins.screw-lead 5: the strut length"),
        ("setp genhexkins.gui.x 1\n", ARGS, "genhexkins.gui.x: not a pin this reader knows"),
        ("setp genhexkins.base.0.x 1 2\n", ARGS, "expected 'setp PIN VALUE'"),
        ("setp genhexkins.base.0.x one\n", ARGS, "expected a number, got 'one'"),
        ("", (*ARGS, "--tool-offset", "1"), "no 'net' drives genhexkins.tool-offset"),
        ("", ARGS, "geometry.paired_joint_length: required when legs share a joint"),
    ],
)
def test_refusals_name_the_line_pin_or_key(tmp_path, hal_text, extra, message):
    hal = tmp_path / "extra.hal"
    hal.write_text(hal_text)
    code, out, err, output = _import(tmp_path, *extra, hal=(SIM / "kinematics.hal", hal))
    assert code == 2
    assert message in err, err
    assert err.count("\n") == 1 and out == ""
    assert not output.exists()


def test_a_machine_without_a_pin_is_refused(tmp_path):
    hal = tmp_path / "short.hal"
    hal.write_text(
        "\n".join(
            line
            for line in (SIM / "kinematics.hal").read_text().splitlines()
            if "platform.5.z" not in line
        )
    )
    code, _, err, _ = _import(tmp_path, *ARGS, hal=(hal,))
    assert code == 2
    assert "genhexkins.platform.5.z: not set by a 'setp' line" in err
