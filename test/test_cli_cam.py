"""The machining cell through the CLI: CL files, frames and feeds in ``check-path``, the tool
frame from ``--config``, ``reach`` and ``axis-limits``; bad input exits 2 in one line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_support import one_error_line, run_main

from hexapod_workspace._resources import example_config_path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CELL = EXAMPLES / "cell_gpm.yaml"
POCKET = EXAMPLES / "pocket_5axis.cl"


def cell_config(tmp_path: Path, extra: str, limits: str = "") -> Path:
    """The packaged example with extra sections under ros__parameters (and limits)."""
    text = example_config_path().read_text(encoding="utf-8")
    text = text.replace("  ros__parameters:\n", "  ros__parameters:\n" + extra, 1)
    if limits:
        text = text.replace("    limits:\n", "    limits:\n" + limits, 1)
    path = tmp_path / "cell.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_cl_file_checks_like_the_equivalent_csv(tmp_path):
    cl = tmp_path / "ring.cl"
    cl.write_text(
        "PARTNO/RING $$ off-axis ring, 17 deg cone\nunits/inches\nMULTAX\n"
        + "".join(
            f"GOTO / {(0.2 + 0.02 * math.cos(t)) / 0.0254:.10f}, "
            f"{(0.2 + 0.02 * math.sin(t)) / 0.0254:.10f}, $\n"
            f"  {-0.95 / 0.0254:.10f}, {math.sin(0.3) * math.cos(t):.10f}, "
            f"{math.sin(0.3) * math.sin(t):.10f}, {math.cos(0.3):.10f}\n"
            for t in np.linspace(0.0, 2.0 * math.pi, 12)
        ),
        encoding="utf-8",
    )
    rows = [
        [
            0.2 + 0.02 * math.cos(t),
            0.2 + 0.02 * math.sin(t),
            -0.95,
            math.sin(0.3) * math.cos(t),
            math.sin(0.3) * math.sin(t),
            math.cos(0.3),
        ]
        for t in np.linspace(0.0, 2.0 * math.pi, 12)
    ]
    csv = tmp_path / "ring.csv"
    np.savetxt(csv, rows, delimiter=",", header="x,y,z,i,j,k", comments="", fmt="%.17g")
    code_cl, out_cl, _ = run_main("check-path", str(cl), "--json")
    code_csv, out_csv, _ = run_main("check-path", str(csv), "--json")
    from_cl, from_csv = json.loads(out_cl), json.loads(out_csv)
    assert code_cl == code_csv
    assert from_cl["frame"] == "work" and from_csv["frame"] == "base"  # identity work frame
    assert from_cl["passed_over"] == {"PARTNO": 1}
    assert from_cl["cl_units"] == {"unit": "inch", "source": "line 2: units/inches"}
    for a, b in zip(from_cl["waypoints"], from_csv["waypoints"], strict=True):
        np.testing.assert_allclose(a["position"], b["position"], atol=1e-9)
        for key in ("phi_deg", "theta_deg", "psi_deg"):
            assert a[key] == pytest.approx(b[key], abs=1e-6)
        assert a["reachable"] == b["reachable"]
    assert [w["line"] for w in from_cl["waypoints"]][:2] == [4, 6]
    # no feed anywhere: no durations, no speed verdicts, and the summary says so
    assert all(s["duration_s"] is None and s["speed_ok"] is None for s in from_cl["segments"])
    assert from_cl["speed"]["moves_without_feed"] == 11


def test_worked_example_with_tool_change_and_feeds(tmp_path):
    plot = tmp_path / "speeds.png"
    code, out, err = run_main(
        "--config",
        str(CELL),
        "check-path",
        str(POCKET),
        "--rapid-feed-mm-min",
        "2400",
        "--rotary-feed-deg-min",
        "360",
        "--plot",
        str(plot),
        "--json",
    )
    assert plot.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    document = json.loads(out)
    assert document["frame"] == "work" and len(document["parts"]) == 2
    assert [p["tool"]["number"] for p in document["parts"]] == [1, 2]
    assert [p["first_waypoint"] for p in document["parts"]] == [0, 17]
    assert all(p["ok"] for p in document["parts"])  # every pose and move is reachable
    first = document["parts"][0]["segments"][1]  # 40 mm at 1200 mm/min
    assert first["feed_mm_min"] == pytest.approx(1200.0)
    assert first["duration_s"] == pytest.approx(0.040 / (1.2 / 60.0))
    assert first["speed_ok"] is True and first["feed_max_mm_min"] > 1200.0
    corner = document["parts"][1]["segments"][3]  # a rotation at a wall corner
    assert corner["feed_deg_min"] == 360.0 and corner["feed_max_mm_min"] is None
    assert corner["feed_max_deg_min"] > 360.0
    slow = document["speed"]["moves_to_slow_down"]
    assert slow and all(m["feed_max_mm_min"] or m["feed_max_deg_min"] for m in slow)
    assert code == 1 and "must slow down" in err
    positions = document["parts"][0]["waypoints"][0]["position"]
    assert positions == pytest.approx([-0.020, -0.010, 0.025])  # in the work frame, m


def test_csv_with_feed_in_the_work_frame(tmp_path):
    config = cell_config(
        tmp_path,
        "    work:\n      origin: [0.2, 0.2, -0.95]\n      orientation: [0.0, 0.0, 0.5]\n",
        "      actuator_speed_max: [0.05]\n",
    )
    csv = tmp_path / "line.csv"
    csv.write_text(
        "x,y,z,phi_deg,theta_deg,psi_deg\n0,0,0,0,10,0\n0.02,0,0,0,10,0\n", encoding="utf-8"
    )
    code, out, _ = run_main(
        "--config", str(config), "check-path", str(csv), "--frame", "work",
        "--feed-mm-min", "600", "--json",
    )  # fmt: skip
    document = json.loads(out)
    assert code == 0 and document["frame"] == "work"
    assert document["waypoints"][1]["position"] == pytest.approx([0.02, 0.0, 0.0])
    assert document["waypoints"][1]["theta_deg"] == pytest.approx(10.0)
    assert document["segments"][0]["duration_s"] == pytest.approx(0.02 / 0.01)
    # the same path given in the base frame (W turned by ψ = 0.5 rad about z: a local
    # (0°, 10°, 0°) is Rz(0.5)·Ry(10°) = T&T (0.5 rad, 10°, 0.5 rad)) has the same margins
    angle = 0.5
    base_csv = tmp_path / "base.csv"
    base_csv.write_text(
        "x,y,z,phi_deg,theta_deg,psi_deg\n"
        f"0.2,0.2,-0.95,{math.degrees(angle)},10,{math.degrees(angle)}\n"
        f"{0.2 + 0.02 * math.cos(angle)},{0.2 + 0.02 * math.sin(angle)},-0.95,"
        f"{math.degrees(angle)},10,{math.degrees(angle)}\n",
        encoding="utf-8",
    )
    _, out_base, _ = run_main("check-path", str(base_csv), "--json")
    base = json.loads(out_base)
    for a, b in zip(document["waypoints"], base["waypoints"], strict=True):
        for name, margin in b["margins"].items():
            assert a["margins"][name] == pytest.approx(margin, abs=1e-9)


def test_tool_offset_in_config_answers_for_the_tool_centre_point(tmp_path):
    config = cell_config(tmp_path, "    tool:\n      offset: [0.0, 0.0, -0.1]\n")
    _, with_tool, _ = run_main(
        "--config", str(config), "--position", "0", "0", "-1.4", "check", "--pose", "0", "5",
        "0", "--json",
    )  # fmt: skip
    _, platform, _ = run_main(
        "--position", "0", "0", "-1.3", "check", "--pose", "0", "5", "0", "--json"
    )
    # a 5° tilt about the tool tip 0.1 m below P moves P sideways: not the same pose
    assert json.loads(with_tool) != json.loads(platform)
    _, untilted, _ = run_main(
        "--config", str(config), "--position", "0", "0", "-1.4", "check", "--pose", "0", "0",
        "0", "--json",
    )  # fmt: skip
    _, reference, _ = run_main(
        "--position", "0", "0", "-1.3", "check", "--pose", "0", "0", "0", "--json"
    )
    a, b = json.loads(untilted), json.loads(reference)
    assert a["poses"][0]["margins"] == b["poses"][0]["margins"]


def test_reach_and_axis_limits_json():
    code, out, _ = run_main(
        "--config", str(CELL), "axis-limits", "--frame", "tool", "--pose", "0", "10", "0",
        "--json",
    )  # fmt: skip
    document = json.loads(out)
    assert code == 0 and document["frame"] == "tool"
    assert list(document["axes"]) == ["x", "y", "z", "rx", "ry", "rz"]
    for axis in document["axes"].values():
        assert set(axis) == {"plus", "minus", "limited_by_plus", "limited_by_minus"}
        assert axis["plus"] >= 0 and axis["minus"] >= 0
    assert document["axes"]["rz"]["plus"] > 10.0  # degrees
    assert document["tool"]["offset"] == [0.0, 0.0, -0.06]  # tool.*
    code, out, _ = run_main(
        "--config", str(CELL), "axis-limits", "--tool", "2", "--json"
    )  # fmt: skip
    assert code == 0 and json.loads(out)["tool"]["offset"] == [0.0, 0.0, -0.095]
    code, _, err = run_main("--config", str(CELL), "axis-limits", "--tool", "3")
    assert code == 2 and "tool 3: not in the tool table" in one_error_line(err)
    code, out, _ = run_main(
        "--config", str(CELL), "--position", "0", "0", "0.01", "reach", "--frame", "work",
        "--direction", "0", "0", "-1", "0", "0", "0", "--t-max", "0.5", "--json",
    )  # fmt: skip
    document = json.loads(out)
    assert code == 0 and 0.0 < document["plus"] < 0.5 and document["limited_by_plus"]
    assert document["t_max"] == 0.5 and document["frame"] == "work"


@pytest.mark.parametrize(
    ("text", "extra", "message"),
    [
        ("GOTO/0,0,0\nGOTO/1,2\n", "", r"line 2: GOTO/1,2: expected 3"),
        ("UNITS/FEET\nGOTO/0,0,0\n", "", r"line 1: UNITS/FEET: expected UNITS/MM"),
        ("FEDRAT/-100\nGOTO/0,0,0\n", "", r"line 1: FEDRAT/-100: expected a feed > 0"),
        ("LOADTL/4\nGOTO/0,0,0\nGOTO/1,0,0\n", "", r"line 1: LOADTL/4: tool 4 is not in"),
        (
            "GOTO/0,0,0\nGOTO/1,0,0\n",
            "    tools:\n      T1:\n        offset: [0.0, .nan, 0.0]\n",
            r"tools\.T1\.offset: expected finite numbers",
        ),
    ],
)
def test_bad_cl_input_exits_2_in_one_line(tmp_path, text, extra, message):
    path = tmp_path / "bad.cl"
    path.write_text(text, encoding="utf-8")
    config = cell_config(tmp_path, extra)
    code, out, err = run_main(
        "--config", str(config), "check-path", str(path), "--cl-units", "mm", "--json"
    )
    assert code == 2 and out == ""
    assert pytest.importorskip("re").search(message, one_error_line(err))


def test_rapid_without_a_rapid_feed_has_no_verdict_and_speeds_need_slerp(tmp_path):
    path = tmp_path / "rapid.cl"
    path.write_text(
        "UNITS/MM\nFEDRAT/600\nGOTO/0,0,-1300\nGOTO/10,0,-1300\nRAPID\nGOTO/10,0,-1250\n"
        "GOTO/0,0,-1250\n",
        encoding="utf-8",
    )
    code, out, _ = run_main("check-path", str(path), "--json")
    document = json.loads(out)
    assert code == 0
    rapid = document["segments"][1]
    assert rapid["rapid"] and rapid["duration_s"] is None and rapid["speed_ok"] is None
    assert "no feed" in rapid["speed_note"]
    assert document["segments"][2]["feed_mm_min"] == pytest.approx(600.0)
    assert document["speed"]["moves_without_feed"] == 1
    assert document["speed"]["limited"] is False  # the packaged example has no speed limit
    assert document["segments"][2]["feed_max_mm_min"] is None
    code, _, err = run_main("check-path", str(path), "--interpolation", "tilt-torsion")
    assert code == 2 and "needs --interpolation slerp" in one_error_line(err)


def test_one_goto_for_a_tool_is_refused(tmp_path):
    path = tmp_path / "short.cl"
    path.write_text("LOADTL/1\nGOTO/0,0,0\nGOTO/1,0,0\nLOADTL/2\nGOTO/0,0,5\n", encoding="utf-8")
    code, _, err = run_main("--config", str(CELL), "check-path", str(path), "--cl-units", "mm")
    assert code == 2
    assert "line 5: the only waypoint of part 1 (tool 2); expected at least 2" in one_error_line(
        err
    )


def test_bad_flags_exit_2(tmp_path):
    csv = tmp_path / "p.csv"
    csv.write_text("x,y,z,i,j,k\n0,0,-1.3,0,0,1\n0.01,0,-1.3,0,0,1\n", encoding="utf-8")
    code, _, err = run_main("check-path", str(csv), "--feed-mm-min", "-5")
    assert code == 2 and "--feed-mm-min: expected a value > 0" in one_error_line(err)
    code, _, err = run_main("reach", "--direction", "0", "0", "0", "0", "0", "0")
    assert code == 2 and "expected a non-zero direction" in one_error_line(err)


def test_record_of_a_cl_file_holds_one_check_path_call_per_tool(tmp_path):
    """--record with a CL file: one ~/check_path call per part, in the base frame, with its feeds
    and the speeds and frames of the JSON document; read back with rosbags and mcap_ros2."""
    from recording_support import read_with_mcap_ros2, read_with_rosbags

    log = tmp_path / "pocket.mcap"
    args = ["--rapid-feed-mm-min", "2400", "--rotary-feed-deg-min", "360", "--json"]
    code, out, err = run_main(
        "--config", str(CELL), "check-path", str(POCKET), *args, "--record", str(log)
    )
    assert code == 1 and "recorded the path check (2 call(s))" in err
    document = json.loads(out)
    for reader in (read_with_rosbags, read_with_mcap_ros2):
        messages = reader(log)
        requests = [m for topic, _, m in messages if topic.endswith("/check_path/request")]
        responses = [m for topic, _, m in messages if topic.endswith("/check_path/response")]
        assert len(requests) == len(responses) == 2
        for part, request, response in zip(document["parts"], requests, responses, strict=True):
            assert request.header.frame_id == "base" and request.free_torsion
            assert len(request.poses) == len(part["waypoints"])
            assert response.frames.tool_number == part["tool"]["number"]
            assert response.frames.request_frame_id == "base"
            assert len(response.speeds) == len(part["segments"])
            for speed, segment in zip(response.speeds, part["segments"], strict=True):
                assert speed.rapid == segment["rapid"]
                if segment["duration_s"] is None:
                    assert not speed.speed_checked and math.isnan(speed.duration_s)
                    continue
                assert speed.speed_ok == segment["speed_ok"]
                assert speed.duration_s == pytest.approx(segment["duration_s"], rel=1e-12)
                assert speed.actuator_speed_peak == pytest.approx(
                    segment["actuator_speed_peak"], rel=1e-12
                )
                if segment["feed_max_mm_min"] is not None:
                    assert speed.feed_max_mm_min == pytest.approx(
                        segment["feed_max_mm_min"], rel=1e-12
                    )
            assert [w.reachable for w in response.waypoints] == [
                w["reachable"] for w in part["waypoints"]
            ]


@pytest.mark.parametrize(("architecture", "z", "unit"), [("pus", -0.80, "m"), ("rus", 0.52, "rad")])
def test_feed_check_for_slides_and_cranks(tmp_path, architecture, z, unit):
    config_dir = Path(__file__).resolve().parents[1] / "config"
    text = (config_dir / f"example_{architecture}.yaml").read_text(encoding="utf-8")
    limit = 0.02 if architecture == "pus" else 0.2  # m/s or rad/s
    text = text.replace("    limits:\n", f"    limits:\n      actuator_speed_max: [{limit}]\n", 1)
    config = tmp_path / "cell.yaml"
    config.write_text(text, encoding="utf-8")
    csv = tmp_path / "line.csv"
    csv.write_text(
        "x,y,z,phi_deg,theta_deg,psi_deg\n"
        f"0,0,{z},0,0,0\n0.03,0,{z},0,0,0\n0.03,0.02,{z + 0.01},30,4,2\n",
        encoding="utf-8",
    )
    code, out, _ = run_main(
        "--config", str(config), "check-path", str(csv), "--feed-mm-min", "1200", "--json"
    )  # fmt: skip
    document = json.loads(out)
    assert document["ok"] is (code == 0)
    assert document["speed"]["actuator_unit"] == unit
    for segment in document["segments"]:
        travel = segment["duration_s"] * 0.02  # 1200 mm/min = 0.02 m/s
        assert travel > 0.0 and segment["actuator_speed_peak"] > 0.0
        # one limit for every actuator: feed_max is the feed that brings the bound to the limit
        feed_max = 1200.0 * limit / segment["actuator_speed_peak"]
        assert segment["feed_max_mm_min"] == pytest.approx(feed_max, rel=1e-9)
        assert segment["speed_ok"] is (segment["actuator_speed_peak"] <= limit)


def test_cl_units_are_stated_refused_or_given_and_passed_over_statements_counted(tmp_path):
    """Issue #35: an NX-style file without UNITS and without a feed unit is refused (exit 2,
    naming --cl-units), runs with --cl-units inch, and reports its units and what it passed
    over; a CSV with --cl-units is refused."""
    path = tmp_path / "nx.cls"
    path.write_text(
        "TOOL PATH/OP1,TOOL,EM10\nMSYS/0,0,0,1,0,0,0,1,0\nPAINT/PATH\nRAPID\n"
        "GOTO/7.87,7.87,-37.4,0,0,1\nPAINT/COLOR,31\nGOTO/8.27,7.87,-37.4\n"
        "PAINT/COLOR,36\nGOTO/8.27,8.27,-37.4\nEND-OF-PATH\n",
        encoding="utf-8",
    )
    code, out, err = run_main("check-path", str(path), "--json")
    assert code == 2 and out == ""
    assert "line 2: MSYS/0,0,0,1,0,0,0,1,0: the file does not state its units" in one_error_line(
        err
    )
    assert "--cl-units" in err
    code, out, err = run_main("check-path", str(path), "--cl-units", "inch", "--json")
    assert code in (0, 1), err
    document = json.loads(out)
    assert document["passed_over"] == {"PAINT": 3}
    assert document["cl_units"] == {"unit": "inch", "source": "units='inch' (--cl-units)"}
    assert document["cl_frames"][0]["line"] == 2
    assert document["waypoints"][0]["position"] == pytest.approx([0.2, 0.2, -0.95], abs=1e-3)
    code, out, _ = run_main("check-path", str(path), "--cl-units", "inch")
    assert "passed over (cannot change motion, frame, tool or units): PAINT x3" in out
    assert "CL units: inch (units='inch' (--cl-units))" in out
    csv = tmp_path / "p.csv"
    csv.write_text("x,y,z,i,j,k\n0,0,-1.3,0,0,1\n0.01,0,-1.3,0,0,1\n", encoding="utf-8")
    code, _, err = run_main("check-path", str(csv), "--cl-units", "mm")
    assert code == 2 and "--cl-units: only for CL files" in one_error_line(err)


def test_nurbs_splines_are_checked_along_the_curve(tmp_path):
    """Issue #35 item 2: the real NX record is checked along its spline, one Bézier move per
    span, not as one chord; the JSON says where each move runs; --record carries the curves."""
    nurbs = Path(__file__).resolve().parent / "data" / "cl" / "nx_nurbs.cls"
    lines = nurbs.read_text(encoding="utf-8").splitlines()
    first = tmp_path / "first_spline.cls"  # the header, the first spline, the closing lines
    first.write_text("\n".join([*lines[:23], *lines[-3:]]) + "\n", encoding="utf-8")
    # the sample's machine coordinates moved into the example's working volume
    text = CELL.read_text(encoding="utf-8")
    assert "origin: [0.0, 0.0, -1.40]" in text
    config = tmp_path / "cell.yaml"
    config.write_text(text.replace("[0.0, 0.0, -1.40]", "[0.255, -0.4595, -1.574]"), "utf-8")
    code, out, err = run_main("--config", str(config), "check-path", str(first), "--json")
    document = json.loads(out)
    assert code == 0 and document["ok"], err
    assert document["cl_splines"] == [{"line": 13, "moves": 5}]
    segments = document["segments"]
    assert len(segments) == 1 + 5 + 1  # GOTO to GOTO, the spline's spans, the last GOTO
    assert [w["line"] for w in document["waypoints"]] == [9, 12, 13, 13, 13, 13, 13, 23]
    curves = [k for k, segment in enumerate(segments) if segment["bezier"] is not None]
    assert curves == [1, 2, 3, 4, 5]
    # the first span's b₁ is the record's first CNTRL point (a clamped end), work frame, m
    inner = segments[1]["bezier"]["control_points"]
    assert inner[0] == pytest.approx([-0.2549774, 0.4662698, 0.2069401], abs=1e-9)
    assert all(segments[k]["feed_mm_min"] == pytest.approx(250.0) for k in curves)
    code, out, _ = run_main("--config", str(config), "check-path", str(first))
    assert code == 0
    assert "NURBS: 1 spline(s) (line 13) as 5 cubic Bézier moves, checked along the curve" in out
    assert "5 of them Bézier curves, checked along the curve" in out
    # --record: the ~/check_path request carries the Bézier moves (base frame), read back
    from recording_support import read_with_rosbags

    record = tmp_path / "run.mcap"
    code, _, err = run_main(
        "--config", str(config), "check-path", str(first), "--record", str(record)
    )
    assert code == 0 and "recorded the path check (1 call(s))" in err
    messages = read_with_rosbags(record)
    (request,) = [m for topic, _, m in messages if topic.endswith("/check_path/request")]
    (response,) = [m for topic, _, m in messages if topic.endswith("/check_path/response")]
    rows = np.asarray(request.beziers).reshape(-1, 6)
    assert np.isfinite(rows[:, 0]).tolist() == [k in curves for k in range(len(segments))]
    assert len(request.arcs) == 0
    origin = np.array([0.255, -0.4595, -1.574])  # the work frame's: no rotation
    np.testing.assert_allclose(rows[1, :3], np.array(inner[0]) + origin, atol=1e-12)
    assert [s.ok for s in response.segments] == [s["ok"] for s in segments]


def _arc_file(tmp_path, circle: bool, radius_mm: float = 350.0) -> Path:
    """Half a circle in the x–z plane of the example's working volume about +y, run clockwise
    seen from +y: from x = −r through z = −1150 − r (below) to x = +r (the CIRCLE left out:
    its chord)."""
    path = tmp_path / ("arc.cl" if circle else "chord.cl")
    path.write_text(
        "UNITS/MM\nFEDRAT/MMPM,600\n"
        f"GOTO/{-radius_mm},0,-1150,0,0,1\n"
        + (f"CIRCLE/0,0,-1150,0,1,0,{radius_mm}\n" if circle else "")
        + f"GOTO/{radius_mm},0,-1150\n",
        encoding="utf-8",
    )
    return path


def test_a_circle_is_checked_and_timed_along_the_arc(tmp_path):
    """Issue #35 item 2: a CIRCLE is a move of its own, checked along the arc (the chord of the
    same file without it passes; the arc leaves the workspace at its bottom)."""
    code, out, err = run_main("check-path", str(_arc_file(tmp_path, circle=False)), "--json")
    assert code == 0, err
    chord = json.loads(out)
    assert "arc" not in chord["segments"][0]
    code, out, err = run_main("check-path", str(_arc_file(tmp_path, circle=True)), "--json")
    arc = json.loads(out)
    assert code == 1 and not arc["ok"]
    segment = arc["segments"][0]
    assert segment["arc"]["angle_deg"] == pytest.approx(-180.0)
    np.testing.assert_allclose(segment["arc"]["centre"], [0.0, 0.0, -1.15], atol=1e-12)
    top = segment["position_at_violation"]
    assert math.hypot(top[0], top[2] + 1.15) == pytest.approx(0.35, abs=1e-9)
    assert top[2] < -1.15  # clockwise about +y (seen from +y) from −x goes under
    # the duration is the arc's length at the feed (not the chord's 0.7 m)
    assert segment["duration_s"] == pytest.approx(math.pi * 0.35 / (0.6 / 60.0), rel=1e-9)
    assert chord["segments"][0]["duration_s"] == pytest.approx(0.7 / (0.6 / 60.0))


def test_a_small_arc_passes_and_is_recorded_as_an_arc(tmp_path):
    small = _arc_file(tmp_path, circle=True, radius_mm=150.0)
    code, out, err = run_main("check-path", str(small), "--json")
    assert code == 0, err
    assert json.loads(out)["segments"][0]["speed_ok"] is True
    code, out, err = run_main("check-path", str(small))
    assert code == 0 and "1 moves (tool axes, torsion planned; 1 of them arcs" in out
    code, out, err = run_main("check-path", str(small), "--record", str(tmp_path / "arc.mcap"))
    assert code == 0 and "recorded the path check (1 call(s))" in err
    from recording_support import read_with_mcap_ros2

    messages = read_with_mcap_ros2(tmp_path / "arc.mcap")
    (request,) = [m for topic, _, m in messages if topic.endswith("/check_path/request")]
    arcs = np.asarray(request.arcs).reshape(-1, 7)
    assert arcs.shape == (1, 7) and np.all(np.isfinite(arcs)) and len(request.beziers) == 0


def test_the_real_nx_pocket_with_circles_is_read_and_checked():
    """The NX pocket (test/data/cl/SOURCES.md): 15 CIRCLE moves read and checked as arcs."""
    pocket = Path(__file__).resolve().parent / "data" / "cl" / "nx_circle_pocket.cls"
    code, out, err = run_main("check-path", str(pocket), "--json")
    assert code in (0, 1), err  # a verdict (the part is larger than the example machine)
    document = json.loads(out)
    arcs = [s["arc"] for s in document["segments"] if s.get("arc") is not None]
    assert len(arcs) == 15
    assert document["passed_over"]["PAINT"] >= 10
