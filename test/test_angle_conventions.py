"""Poses in the controllers' conventions (``--angles``, the files' columns; issue #35 item 8).

The worked examples of docs/configuration.md are checked against rotation matrices written out
here from the vendors' definitions (not from the package's functions), and through the CLI; the
conversions of :mod:`hexapod_workspace.core.base.rotations` against the same matrices on random
angles; the files' columns and ``--angles`` for being unambiguous.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from cli_support import one_error_line, run_main

from hexapod_workspace.core.base.rotations import ANGLE_CONVENTIONS, convention_to_tt, tt_to_matrix

DOCS = Path(__file__).resolve().parents[1] / "docs" / "configuration.md"


# ---------------------------------------------------------------------------- plain matrices
def rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def plain_tt(phi: float, theta: float, psi: float) -> np.ndarray:
    """Bonev & Ryu: Rz(φ) Ry(θ) Rz(−φ) Rz(ψ)."""
    return rz(phi) @ ry(theta) @ rz(-phi) @ rz(psi)


def plain_quaternion(x: float, y: float, z: float, w: float) -> np.ndarray:
    """The rotation of a unit quaternion, scalar last, by the rotation of a vector about the
    quaternion's axis (Rodrigues), not by the package's closed form."""
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    angle = 2.0 * math.atan2(math.sqrt(x * x + y * y + z * z), w)
    axis = np.array([x, y, z])
    if np.linalg.norm(axis) == 0.0:
        return np.eye(3)
    k = axis / np.linalg.norm(axis)
    cross = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * cross + (1.0 - math.cos(angle)) * cross @ cross


def plain(convention: str, values: list[float]) -> np.ndarray:
    """The vendors' definitions (docs/configuration.md), angles in degrees."""
    if convention == "quaternion":
        return plain_quaternion(*values)
    a, b, c = (math.radians(v) for v in values)
    if convention == "tt":
        return plain_tt(a, b, c)
    if convention == "xyz-moving":  # PI: U about x, then V about the moved y, W the moved z
        return rx(a) @ ry(b) @ rz(c)
    # LinuxCNC A, B, C and Symétrie Rx, Ry, Rz: about the fixed x, then y, then z
    return rz(c) @ ry(b) @ rx(a)


def worked_examples() -> list[tuple[str, str, list[float], list[float]]]:
    """The rows of docs/configuration.md's table of worked examples."""
    text = DOCS.read_text(encoding="utf-8")
    table = text[text.index("Worked examples") :].split("\n\n")[1]
    rows = []
    for line in table.splitlines()[2:]:
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        vendor, flag, given, tt = cells
        numbers = [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", given)]
        rows.append((vendor, flag.strip("`"), numbers, [float(v) for v in tt.split(",")]))
    return rows


EXAMPLES = worked_examples()


def test_the_docs_give_a_worked_example_for_pi_symetrie_and_linuxcnc():
    vendors = {vendor for vendor, *_ in EXAMPLES}
    assert {"PI", "Symétrie", "LinuxCNC"} <= vendors
    assert {flag for _, flag, *_ in EXAMPLES} == set(ANGLE_CONVENTIONS) - {"tt"}


@pytest.mark.parametrize(("vendor", "convention", "given", "tt"), EXAMPLES)
def test_worked_example_is_the_vendors_rotation(vendor, convention, given, tt):
    # The T&T angles the docs print denote the vendor's matrix (to their 3 decimals).
    expected = plain(convention, given)
    assert np.allclose(plain_tt(*np.radians(tt)), expected, atol=2e-5), vendor
    # and the package's conversion gives them
    values = given if convention == "quaternion" else np.radians(given)
    found = convention_to_tt(np.array([values]), convention)[0]
    assert np.degrees(found) == pytest.approx(tt, abs=5e-4)


@pytest.mark.parametrize(("vendor", "convention", "given", "tt"), EXAMPLES)
def test_worked_example_through_the_cli_echoes_the_pose_as_given(vendor, convention, given, tt):
    args = [repr(v) for v in given]
    code, out, err = run_main("--json", "check", "--angles", convention, "--pose", *args)
    assert code in (0, 1), err
    pose = json.loads(out)["poses"][0]
    keys = [f"{c}_deg" for c in ANGLE_CONVENTIONS[convention].components]
    if convention == "quaternion":
        keys = list(ANGLE_CONVENTIONS[convention].components)
    assert list(pose)[: len(keys) + 3] == [*keys, "phi_deg", "theta_deg", "psi_deg"]
    assert [pose[k] for k in keys] == given
    assert [pose["phi_deg"], pose["theta_deg"], pose["psi_deg"]] == pytest.approx(tt, abs=5e-4)


@pytest.mark.parametrize("convention", sorted(set(ANGLE_CONVENTIONS) - {"tt", "quaternion"}))
def test_conversions_match_the_plain_matrices_on_random_angles(convention):
    rng = np.random.default_rng(35)
    degrees = rng.uniform(-400.0, 400.0, size=(200, 3))
    degrees[:5, :] = [[0, 0, 0], [0, 0, 30], [90, 0, 0], [0, 90, 0], [0, 0, -180]]  # θ = 0 etc.
    tt = convention_to_tt(np.radians(degrees), convention)
    assert np.all((tt[:, 0] > -math.pi) & (tt[:, 0] <= math.pi))
    assert np.all((tt[:, 1] >= 0.0) & (tt[:, 1] <= math.pi))
    for row, angles in zip(degrees, tt, strict=True):
        assert np.allclose(plain_tt(*angles), plain(convention, row.tolist()), atol=1e-12)
    # θ = 0: φ = 0 and the rotation is all in ψ
    assert tt[0].tolist() == [0.0, 0.0, 0.0]
    assert tt[1] == pytest.approx([0.0, 0.0, math.radians(30.0)], abs=1e-15)


def test_quaternions_match_the_plain_rotation_and_tt_is_unchanged():
    rng = np.random.default_rng(8)
    quaternions = rng.normal(size=(100, 4))
    tt = convention_to_tt(quaternions, "quaternion")
    for q, angles in zip(quaternions, tt, strict=True):
        assert np.allclose(tt_to_matrix(angles), plain_quaternion(*q), atol=1e-12)
    given = np.radians([[1e3, 20.0, 10.0]])
    assert convention_to_tt(given, "tt") is not None
    assert np.array_equal(convention_to_tt(given, "tt"), given)


# ---------------------------------------------------------------------------- the CLI
def test_check_text_shows_the_given_angles_beside_tt():
    code, out, err = run_main("check", "--angles", "xyz-moving", "--pose", "10", "0", "0")
    assert code == 0, err
    lines = out.splitlines()
    assert lines[2].split()[:6] == ["u", "v", "w", "phi", "theta", "psi"]
    assert lines[4].split()[:6] == ["10.000", "0.000", "0.000", "-90.000", "10.000", "0.000"]


def test_tt_output_is_unchanged_by_the_flag():
    plain_run = run_main("--json", "check", "--pose", "30", "20", "10")
    flagged = run_main("--json", "check", "--angles", "tt", "--pose", "30", "20", "10")
    assert plain_run == flagged
    assert '"phi_deg": 30, "theta_deg": 20' in plain_run[1]


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("header", "row", "convention"),
    [
        ("u_deg,v_deg,w_deg", "10,20,30", "xyz-moving"),
        ("a_deg,b_deg,c_deg", "10,20,30", "xyz-fixed"),
        ("rx_deg,ry_deg,rz_deg", "10,20,30", "symetrie"),
        ("qx,qy,qz,qw", "0,0.1305262,0,0.9914449", "quaternion"),
        ("w_rad,u_deg,v_deg", "0.5235987755982988,10,20", "xyz-moving"),
    ],
)
def test_poses_file_columns_choose_the_convention(tmp_path, header, row, convention):
    source = write(tmp_path / "p.csv", f"{header}\n{row}\n")
    code, out, err = run_main("--json", "check", "--poses-file", str(source))
    assert code in (0, 1), err
    pose = json.loads(out)["poses"][0]
    code, flagged, _ = run_main(
        "--json", "check", "--angles", convention, "--poses-file", str(source)
    )
    assert json.loads(flagged)["poses"][0] == pose
    names = ANGLE_CONVENTIONS[convention].components
    given = [float(v) for v in row.split(",")]
    order = [n.partition("_")[0] for n in header.split(",")]
    values = dict(zip(order, given, strict=True))
    if "w_rad" in header:
        values["w"] = 30.0
    keys = [n if convention == "quaternion" else f"{n}_deg" for n in names]
    assert [pose[k] for k in keys] == pytest.approx([values[n] for n in names], abs=1e-9)
    expected = plain(convention, [values[n] for n in names])
    found = plain_tt(*np.radians([pose["phi_deg"], pose["theta_deg"], pose["psi_deg"]]))
    assert np.allclose(found, expected, atol=1e-9)


def test_headerless_file_is_read_in_the_convention_of_the_flag(tmp_path):
    source = write(tmp_path / "p.csv", "10,0,0\n")
    code, out, err = run_main(
        "--json", "check", "--angles", "xyz-fixed", "--poses-file", str(source)
    )
    assert code == 0, err
    pose = json.loads(out)["poses"][0]
    assert pose["a_deg"] == 10 and pose["phi_deg"] == pytest.approx(-90.0)


@pytest.mark.parametrize(
    ("text", "args", "match"),
    [
        (
            "phi_deg,v_deg,w_deg\n1,2,3\n",
            [],
            "line 1: columns of 2 angle conventions: phi_deg (tt); v_deg,w_deg (xyz-moving)",
        ),
        (
            "u_deg,v_deg,w_deg\n1,2,3\n",
            ["--angles", "xyz-fixed"],
            "columns u_deg,v_deg,w_deg are xyz-moving angles but --angles is xyz-fixed",
        ),
        ("u_deg,v_deg,w_deg\n1,2,3\n", ["--angles", "tt"], "but --angles is tt"),
        ("u_deg,v_deg\n1,2\n", [], "no column for w (expected u_deg,v_deg,w_deg"),
        ("qx,qy,qz,qw\n0,0,0,0\n", [], "expected a quaternion qx qy qz qw of non-zero norm"),
        ("u,v,w\n1,2,3\n", [], "column 'u' names no unit (expected u_deg or u_rad)"),
        ("u_deg,v_deg,w_deg\n1,2,3\n", ["--pose", "0", "0", "0"], "give --angles xyz-moving"),
    ],
)
def test_ambiguous_or_mismatched_files_are_refused_in_one_line(tmp_path, text, args, match):
    source = write(tmp_path / "p.csv", text)
    code, _, err = run_main("check", "--poses-file", str(source), *args)
    assert code == 2
    assert match in one_error_line(err)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["--angles", "quaternion", "--pose", "0", "0", "1"], "expected 4 numbers QX QY QZ QW"),
        (["--angles", "xyz-moving", "--pose", "0", "0", "1", "1"], "expected 3 numbers U V W"),
        (["--pose", "0", "0"], "--pose: expected 3 numbers PHI THETA PSI (tt, degrees), got 2"),
        (["--angles", "euler", "--pose", "0", "0", "0"], "--angles: invalid choice: 'euler'"),
    ],
)
def test_bad_pose_flags_are_refused_in_one_line(args, match):
    code, _, err = run_main("check", *args)
    assert code == 2
    assert match in one_error_line(err)


def test_check_path_reads_and_echoes_another_convention(tmp_path):
    rows = "\n".join(f"0,0,-1.3,{u},0,0" for u in (0.0, 5.0, 10.0))
    source = write(tmp_path / "path.csv", f"x,y,z,u_deg,v_deg,w_deg\n{rows}\n")
    code, out, err = run_main("--json", "check-path", str(source))
    assert code == 0, err
    document = json.loads(out)
    assert document["angles"] == "xyz-moving"
    last = document["waypoints"][-1]
    assert [last["u_deg"], last["v_deg"], last["w_deg"]] == [10.0, 0.0, 0.0]
    assert [last["phi_deg"], last["theta_deg"], last["psi_deg"]] == pytest.approx([-90, 10, 0])
    tt_rows = "\n".join(f"0,0,-1.3,-90,{u},0" for u in (0.0, 5.0, 10.0))
    tt_source = write(tmp_path / "tt.csv", f"x,y,z,phi_deg,theta_deg,psi_deg\n{tt_rows}\n")
    _, tt_out, _ = run_main("--json", "check-path", str(tt_source))
    margins = [w["margins"] for w in json.loads(tt_out)["waypoints"]]
    for waypoint, expected in zip(document["waypoints"], margins, strict=True):
        assert waypoint["margins"] == pytest.approx(expected, abs=1e-9)
    code, _, err = run_main("check-path", str(source), "--angles", "symetrie")
    assert code == 2 and "xyz-moving angles but --angles is symetrie" in one_error_line(err)
    code, _, err = run_main("check-path", str(source), "--angles", "tt", "--frame", "base")
    assert code == 2 and "but --angles is tt" in one_error_line(err)


def test_reach_and_axis_limits_take_and_echo_another_convention():
    code, out, err = run_main(
        "--json", "reach", "--angles", "xyz-moving", "--pose", "10", "0", "0",
        "--direction", "0", "0", "1", "0", "0", "0",
    )  # fmt: skip
    assert code == 0, err
    document = json.loads(out)
    assert document["angles"] == "xyz-moving"
    assert document["pose_given"] == {"u_deg": 10.0, "v_deg": 0.0, "w_deg": 0.0}
    assert document["pose_deg"] == pytest.approx([-90.0, 10.0, 0.0])
    _, tt_out, _ = run_main(
        "--json", "reach", "--pose", "-90", "10", "0", "--direction", "0", "0", "1", "0", "0", "0"
    )
    assert document["plus"] == pytest.approx(json.loads(tt_out)["plus"], abs=1e-6)
    code, out, err = run_main(
        "axis-limits", "--angles", "quaternion", "--pose", "0", "0.1305262", "0", "0.9914449"
    )
    assert code == 0, err
    first = out.splitlines()[0]
    assert first.startswith("pose: qx 0, qy 0.130526, qz 0, qw 0.991445 (quaternion) = phi 0")
    assert "theta 15, psi 0 deg (tt)" in first
