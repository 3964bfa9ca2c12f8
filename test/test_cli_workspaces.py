"""projected, orientation, torsion-range, demo and the help, in-process (``main(argv, out=)``)."""

from __future__ import annotations

import argparse
import json
import math
import re
import shlex
from pathlib import Path

import pytest
from cli_support import one_error_line, run_main

from hexapod_workspace import check, torsion_range


def test_projected_json_fields_and_plot(tmp_path):
    plot = tmp_path / "projected.png"
    code, out, err = run_main("--json", "projected", "--n-phi", "36", "--plot", str(plot))
    assert code == 0, err
    document = json.loads(out)
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
    assert err == f"plot: {plot}\n"  # JSON mode: nothing else on stdout


def test_projected_exact_reports_the_gap(example):
    code, out, err = run_main(
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
    assert code == 0, err
    document = json.loads(out)
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


def test_projected_text_says_the_table_is_thinned():
    code, out, _ = run_main("projected", "--n-phi", "360")
    assert code == 0
    assert "tilt range:" in out and "solid angle" in out
    assert "boundary, every 30th of the 360 azimuths (12 rows; --json gives all):" in out
    lines = out.splitlines()
    table = lines[lines.index(next(r for r in lines if r.endswith("limiting"))) + 1 :]
    assert len(table) == 12
    assert len({r.index(".") for r in table}) == 1  # phi column aligned
    code, out, _ = run_main("projected", "--n-phi", "8")
    assert "boundary (8 azimuths):" in out


@pytest.mark.parametrize("name", ["plot.txt", "plot"])
def test_plot_name_must_say_the_format_before_any_work(tmp_path, name):
    """No result, then a traceback; a refused name costs nothing."""
    code, out, err = run_main("projected", "--plot", str(tmp_path / name))
    assert (code, out) == (2, "")
    assert "--plot: expected a file name ending in .png or .pdf or .svg" in one_error_line(err)


def test_plot_into_a_folder_or_a_missing_folder_is_refused(tmp_path):
    code, _, err = run_main("orientation", "--plot", str(tmp_path))
    assert code == 2 and "is a folder; give a file name such as" in one_error_line(err)
    code, _, err = run_main("orientation", "--plot", str(tmp_path / "new" / "o.png"))
    assert code == 2 and "does not exist" in one_error_line(err)
    other = tmp_path / "notes.png"
    other.write_text("my notes")
    code, _, err = run_main("projected", "--n-phi", "12", "--plot", str(other))
    assert code == 2 and "not replaced (use --force)" in one_error_line(err)


def test_plot_formats_and_the_printed_path_is_the_file_written(tmp_path):
    for name in ("p.svg", "p.pdf"):
        plot = tmp_path / name
        code, out, err = run_main("projected", "--n-phi", "12", "--plot", str(plot))
        assert code == 0, err
        assert f"plot: {plot}\n" in out
        assert plot.stat().st_size > 1000


def test_orientation_json_fields(tmp_path):
    plot = tmp_path / "orientation.png"
    code, out, err = run_main(
        "--json", "orientation", "--n-rays", "24", "--psi-step-deg", "10", "--plot", str(plot)
    )
    assert code == 0, err
    document = json.loads(out)
    for key in ("psi_min_deg", "psi_max_deg", "volume", "slices", "position", "elapsed_s"):
        assert key in document
    assert document["psi_min_deg"] < 0 < document["psi_max_deg"]
    for end in ("min", "max"):  # the witnesses of the extremes, reachable by `check`
        witness = document[f"psi_{end}_witness_deg"]
        assert len(witness) == 3 and witness[2] == document[f"psi_{end}_deg"]
        code, verdict, err = run_main("check", "--pose", *map(repr, witness))
        assert code == 0, (witness, verdict, err)
    first = document["slices"][0]
    assert set(first) == {"psi_deg", "center_deg", "phi_deg", "theta_deg"}
    assert len(first["center_deg"]) == 2
    assert len(first["phi_deg"]) == 24
    psis = [piece["psi_deg"] for piece in document["slices"]]
    assert psis == sorted(psis)
    assert plot.stat().st_size > 10_000


def test_orientation_text_says_what_the_zero_slice_numbers_are():
    """The psi = 0 slice's tilts come from rays from the slice centre, not from
    theta = 0 as in `projected`; the text says so and gives the centre."""
    code, out, _ = run_main("--position", "0.2", "0.2", "-0.95", "orientation", "--n-rays", "36")
    assert code == 0
    assert "boundary points\n    (rays from the slice centre (" in out
    assert "`projected` samples the same boundary along\n    azimuths from theta = 0" in out


def test_torsion_range_json_is_exact_shape():
    code, out, err = run_main("--json", "torsion-range", "--direction", "30", "20")
    assert code == 0, err
    document = json.loads(out)
    assert set(document) == {"direction_deg", "intervals_deg"}
    assert document["direction_deg"] == [30.0, 20.0]
    ((low, high),) = document["intervals_deg"]
    assert low < 0 < high


def test_torsion_range_of_a_huge_azimuth_is_that_of_its_principal_value(example):
    """Phi = 1e20 deg denotes 280 deg; 1e20 rad in the API denotes its own value."""
    _, out, _ = run_main("--json", "torsion-range", "--direction", "1e20", "10")
    _, reference, _ = run_main("--json", "torsion-range", "--direction", "280", "10")
    assert json.loads(out)["direction_deg"] == [1e20, 10.0]
    ((low, high),) = json.loads(out)["intervals_deg"]
    assert [low, high] == pytest.approx(json.loads(reference)["intervals_deg"][0], abs=1e-6)
    huge = torsion_range(example, 1e20, 0.3).intervals
    principal = torsion_range(example, math.atan2(math.sin(1e20), math.cos(1e20)), 0.3).intervals
    assert huge.shape == principal.shape and huge.ravel() == pytest.approx(
        principal.ravel(), abs=1e-5
    )


def test_torsion_range_none_feasible_exit_1_reason_on_stderr():
    code, out, err = run_main("--json", "torsion-range", "--direction", "0", "80")
    assert code == 1
    assert json.loads(out)["intervals_deg"] == []
    assert (
        err == "hexapod-workspace: no torsion is feasible for direction phi 0 deg, theta 80 deg\n"
    )


def test_unreachable_reference_exit_1_with_reason():
    code, out, err = run_main("--json", "--position", "0", "0", "-0.5", "orientation")
    assert code == 1
    document = json.loads(out)
    assert document["reference_reachable"] is False
    assert "unreachable" in document["reason"]
    assert "workspace is empty" in err


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        # The flag's own words and units.
        (["projected", "--n-phi", "1000000"], "--n-phi: expected 3 to 7200, got 1000000"),
        (["projected", "--n-phi", "2"], "--n-phi: expected 3 to 7200, got 2"),
        (["projected", "--tol-deg", "0"], "--tol-deg: expected 5.73e-11 to 5.73 degrees, got 0"),
        (["projected", "--tol-deg", "10"], "--tol-deg: expected 5.73e-11 to 5.73 degrees, got 10"),
        (["projected", "--tol-deg", "nan"], "--tol-deg: expected finite numbers (degrees)"),
        (["orientation", "--psi-step-deg", "0"], "--psi-step-deg: expected 0.00573 to 28.6 deg"),
        (["orientation", "--n-rays", "7200", "--psi-step-deg", "0.01"], "boundary points"),
        (["torsion-range", "--direction", "0", "200"], "--direction: expected THETA in [0, 180]"),
        (["torsion-range", "--direction", "0", "10", "--tol-deg", "-1e-3"], "--tol-deg"),
        (["projected", "--method", "paper"], "invalid choice"),
        # Options that would be ignored are refused.
        (["--position", "0", "0", "-1.3", "demo"], "demo: --position does not apply"),
        (["replay", "x.mcap", "--config", "c.yaml"], "unrecognized arguments: --config"),
        (["--config", "c.yaml", "replay", "x.mcap"], "replay: --config does not apply"),
    ],
)
def test_absurd_requests_exit_2(args, reason):
    code, out, err = run_main(*args)
    assert (code, out) == (2, "")
    assert reason in one_error_line(err)
    if any(arg.endswith("-deg") for arg in args):
        assert " rad" not in err and "tolerance:" not in err and "psi_step:" not in err


def test_help_describes_every_option_and_shows_defaults():
    import contextlib
    import io

    from hexapod_workspace.cli.main import COMMANDS, build_parser

    parser = build_parser()
    for name in COMMANDS:
        text = io.StringIO()
        with contextlib.redirect_stdout(text), pytest.raises(SystemExit):
            parser.parse_args([name, "--help"])
        assert "--json" in text.getvalue()
    # Every option whose absence means a value shows that value in --help: those with an
    # argparse default show exactly it; those whose None stands for a value computed later
    # (listed here) say what it is.
    computed = {
        "atlas": {"--tol-deg", "--scheduler", "--workers", "--chunk"},
        "check-path": {"--max-dpsi-deg"},
        "projected": {"--tol-deg", "--n-phi"},
        "orientation": {"--tol-deg", "--n-rays", "--psi-step-deg"},
    }
    commands = next(a for a in parser._actions if a.dest == "command").choices
    for name, sub in commands.items():
        for action in sub._actions:
            if not action.option_strings or action.required or action.nargs == 0:
                continue  # positionals, required options, flags
            shown = sub._get_formatter()._expand_help(action) if action.help else ""
            option = f"{name} {action.option_strings[0]}"
            if action.default == argparse.SUPPRESS:  # global options repeated after the command
                assert "default" in shown or action.dest == "json", option
            elif action.default not in (None, []):
                default = action.default
                if isinstance(default, list):  # nargs options show their values as typed
                    text = " ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in default)
                else:
                    text = f"{default:g}" if isinstance(default, float) else str(default)
                said = (f"default {text}", f"default: {text}", f"{text}, default")
                assert any(words in shown for words in said), (option, shown)
            elif action.option_strings[0] in computed.get(name, set()):
                assert "default" in shown, option


def test_no_progress_bar_when_stderr_is_not_a_terminal():
    _, _, err = run_main("projected", "--n-phi", "12")
    assert "[#" not in err


def test_demo_writes_table_plots_and_a_log_with_real_times(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out_dir = Path("deep") / "demo"  # --out is created with its parents
    code, out, err = run_main("demo", "--out", str(out_dir))
    assert code == 0, err
    # The replay hint names the log as seen from where the demo ran, and works from there.
    hint = re.search(r"`(hexapod-workspace replay [^`]+)`", out)
    assert hint and hint.group(1) == "hexapod-workspace replay deep/demo/demo.mcap"
    assert run_main(*shlex.split(hint.group(1))[1:])[0] == 0
    names = {path.name for path in out_dir.iterdir()}
    assert {
        "results.md",
        "results.json",
        "demo.mcap",
        "projected_on_axis.png",
        "projected_off_axis.png",
        "orientation_on_axis.png",
        "orientation_off_axis.png",
    } <= names
    rows = json.loads((out_dir / "results.json").read_text())
    assert [row["case"] for row in rows] == ["on_axis", "off_axis"]
    for row in rows:
        assert row["tilt_min_deg"] <= row["exact_tilt_min_deg"]
        assert row["psi_min_deg"] < 0 < row["psi_max_deg"]
    assert "| on_axis |" in out
    code, out, err = run_main("--json", "replay", str(out_dir / "demo.mcap"))
    assert code == 0, err
    report = json.loads(out)
    # Each result at the time it was computed, not one timestamp for all.
    times = [w["time_s"] for w in report["workspaces"]]
    assert len(times) == 6 and times == sorted(times)
    total = sum(sum(row["elapsed_s"].values()) for row in rows)
    assert report["duration_s"] >= 0.9 * total > 0.0
    # A second run replaces the demo's own files; a foreign file is kept without --force.
    (out_dir / "results.md").write_text("my notes")
    code, _, err = run_main("demo", "--out", str(out_dir))
    assert code == 2 and "results.md exists and is not the demo's" in one_error_line(err)
    assert (out_dir / "results.md").read_text() == "my notes"
