"""projected, orientation, torsion-range and demo through a real subprocess."""

from __future__ import annotations

import json
import math

import pytest
from cli_support import run_cli

from hexapod_workspace import check


def test_projected_json_fields_and_plot(tmp_path):
    plot = tmp_path / "projected.png"
    done = run_cli("--json", "projected", "--n-phi", "36", "--plot", str(plot))
    assert done.returncode == 0, done.stderr
    document = json.loads(done.stdout)
    for key in (
        "phi_deg",
        "theta_deg",
        "tilt_min_deg",
        "tilt_max_deg",
        "method",
        "position",
        "elapsed_s",
        "solid_angle_sr",
    ):
        assert key in document
    assert document["method"] == "torsion_zero"
    assert document["position"] == [0.0, 0.0, -1.3]
    assert len(document["phi_deg"]) == 36
    assert document["phi_deg"][1] == pytest.approx(10.0)
    assert document["tilt_min_deg"] == pytest.approx(min(document["theta_deg"]))
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_projected_exact_reports_the_gap(example):
    done = run_cli(
        "--json",
        "projected",
        "--method",
        "exact",
        "--n-phi",
        "24",
        "--position",
        "0.2",
        "0.2",
        "-0.95",
    )
    assert done.returncode == 0, done.stderr
    document = json.loads(done.stdout)
    assert document["method"] == "exact"
    assert len(document["torsion_zero_gap_deg"]) == 24
    assert min(document["torsion_zero_gap_deg"]) >= 0.0
    assert document["torsion_zero_gap_max_deg"] > 1.0  # off the axis torsion matters
    # Every reported point is reachable.
    angles = [
        [math.radians(p), math.radians(t), math.radians(s)]
        for p, t, s in zip(
            document["phi_deg"], document["theta_deg"], document["psi_deg"], strict=True
        )
    ]
    assert check(example, angles, [0.2, 0.2, -0.95]).reachable.all()


def test_projected_text_output():
    done = run_cli("projected", "--n-phi", "24")
    assert done.returncode == 0
    assert "tilt range:" in done.stdout
    assert "solid angle" in done.stdout


def test_orientation_json_fields(tmp_path):
    plot = tmp_path / "orientation.png"
    done = run_cli(
        "--json", "orientation", "--n-rays", "24", "--psi-step-deg", "10", "--plot", str(plot)
    )
    assert done.returncode == 0, done.stderr
    document = json.loads(done.stdout)
    for key in ("psi_min_deg", "psi_max_deg", "volume", "slices", "position", "elapsed_s"):
        assert key in document
    assert document["psi_min_deg"] < 0 < document["psi_max_deg"]
    first = document["slices"][0]
    assert set(first) == {"psi_deg", "center_deg", "phi_deg", "theta_deg"}
    assert len(first["center_deg"]) == 2
    assert len(first["phi_deg"]) == 24
    psis = [piece["psi_deg"] for piece in document["slices"]]
    assert psis == sorted(psis)
    assert plot.stat().st_size > 10_000


def test_torsion_range_json_is_exact_shape():
    done = run_cli("--json", "torsion-range", "--direction", "30", "20")
    assert done.returncode == 0, done.stderr
    document = json.loads(done.stdout)
    assert set(document) == {"direction_deg", "intervals_deg"}
    assert document["direction_deg"] == [30.0, 20.0]
    ((low, high),) = document["intervals_deg"]
    assert low < 0 < high


def test_torsion_range_none_feasible_exit_1():
    done = run_cli("--json", "torsion-range", "--direction", "0", "80")
    assert done.returncode == 1
    assert json.loads(done.stdout)["intervals_deg"] == []


def test_unreachable_reference_exit_1_with_reason():
    done = run_cli("--json", "--position", "0", "0", "-0.5", "orientation")
    assert done.returncode == 1
    document = json.loads(done.stdout)
    assert document["reference_reachable"] is False
    assert "unreachable" in document["reason"]
    assert "workspace is empty" in done.stderr


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["projected", "--n-phi", "1000000"], "n_phi: expected 3 to 7200 rays"),
        (["projected", "--n-phi", "2"], "n_phi: expected 3 to 7200 rays"),
        (["projected", "--tol-deg", "0"], "tolerance: expected"),
        (["projected", "--tol-deg", "nan"], "--tol-deg: expected finite"),
        (["orientation", "--psi-step-deg", "0"], "psi_step: expected"),
        (["orientation", "--n-rays", "7200", "--psi-step-deg", "0.01"], "boundary points"),
        (["torsion-range", "--direction", "0", "200"], "theta in [0, pi]"),
        (["projected", "--method", "paper"], "invalid choice"),
    ],
)
def test_absurd_requests_exit_2(args, reason):
    done = run_cli(*args)
    assert done.returncode == 2
    assert reason in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    assert done.stdout == ""


def test_no_progress_bar_when_stderr_is_not_a_terminal():
    done = run_cli("projected", "--n-phi", "12")
    assert "[#" not in done.stderr


def test_demo_writes_table_plots_and_log(tmp_path):
    out = tmp_path / "demo"
    done = run_cli("demo", "--out", str(out), timeout=600)
    assert done.returncode == 0, done.stderr
    names = {path.name for path in out.iterdir()}
    assert {
        "results.md",
        "results.json",
        "demo.mcap",
        "projected_on_axis.png",
        "projected_off_axis.png",
        "orientation_on_axis.png",
        "orientation_off_axis.png",
    } <= names
    rows = json.loads((out / "results.json").read_text())
    assert [row["case"] for row in rows] == ["on_axis", "off_axis"]
    for row in rows:
        assert row["tilt_min_deg"] <= row["exact_tilt_min_deg"]
        assert row["psi_min_deg"] < 0 < row["psi_max_deg"]
    assert "| on_axis |" in done.stdout
    replay = run_cli("--json", "replay", str(out / "demo.mcap"))
    assert replay.returncode == 0, replay.stderr
