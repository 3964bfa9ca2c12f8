"""``schedule FILE --write-cl OUT``: the CL file written again with the feed each move can run at.

Evidence, without mocks:

* the writer (core.cell.cl_feeds) on the real public CL samples of test/data/cl (SOURCES.md)
  and the packaged pocket: reading OUT with the project's reader gives the same waypoints,
  arcs, Bézier moves, tools, RAPID flags and units, and the feeds written (to 1e-4 in the
  file's unit); every line of FILE but its FEDRAT statements is kept, in order, byte for byte;
* the definition, independently: every cutting move of OUT run at constant u' = F/L, sampled
  at 2·10⁴ points, actuator coordinates from the plain-numpy inverse kinematics of
  test/reference_arch.py, speeds and accelerations by central finite differences at every
  sample (second differences over 20 samples: over one, the round-off of q dominates on short
  moves), in a speed-bound and an acceleration-bound case: no limit exceeded by more than
  0.1 % (the differences' own error is far below); and not needlessly low: every
  move slowed below its programmed feed reaches at least 95 % of a limit, so at 1.05·F it
  exceeds one (speed ×1.05, acceleration ×1.1025);
* check-path on OUT with acceleration limits 0 says speed_ok for every move;
* refusals exit 2 in one line.
"""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import numpy as np
import pytest
import reference_arch
from cli_support import one_error_line, run_main
from test_cli_cam import CELL, POCKET
from test_speeds import log_axis_angle, rodrigues

from hexapod_workspace.cli.cam import check_part_path, read_cell_inputs
from hexapod_workspace.cli.main import build_parser
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.cell.cl_feeds import rewrite_feeds
from hexapod_workspace.core.cell.cl_statements import CL_UNITS
from hexapod_workspace.core.cell.cldata import parse_cldata, read_cldata
from hexapod_workspace.core.motions import reported_parts

DATA = Path(__file__).resolve().parent / "data" / "cl"
SAMPLES = [
    DATA / "nx_inch_ipm.cls",
    DATA / "fusion_inch.apt",
    DATA / "nx_circle_pocket.cls",
    DATA / "nx_nurbs.cls",
    POCKET,
]
VMAX, AMAX = 0.004, 0.05  # m/s, m/s²: slow enough that the pocket's cutting moves slow down
DENSE = 20_000
STRIDE = 20  # samples between the points of a second difference


def _text(path: Path) -> str:
    with path.open(encoding="utf-8", newline="") as handle:
        return handle.read()


def _not_fedrat(text: str) -> list[str]:
    return [
        line
        for line in text.splitlines(keepends=True)
        if not line.strip().upper().replace(" ", "").startswith("FEDRAT/")
    ]


def _same_program(a, b) -> None:
    assert np.allclose(a.positions, b.positions, rtol=0, atol=1e-12)
    assert np.allclose(a.axes, b.axes, rtol=0, atol=1e-12)
    assert np.array_equal(a.rapid, b.rapid) and np.array_equal(a.tools, b.tools)
    assert a.units == b.units and a.parts == b.parts
    for x, y in ((a.arcs, b.arcs), (a.beziers, b.beziers)):
        assert np.array_equal(np.isnan(x), np.isnan(y))
        assert np.allclose(np.nan_to_num(x), np.nan_to_num(y), rtol=0, atol=1e-12)


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.name)
def test_the_writer_round_trips_the_samples(path):
    program = read_cldata(path)
    text = _text(path)
    rng = np.random.default_rng(7)
    cutting = ~program.rapid & np.isfinite(program.feeds)
    wanted = np.where(cutting, program.feeds * rng.uniform(0.2, 1.0, len(program)), np.nan)
    result = rewrite_feeds(text, program, wanted)
    again = parse_cldata(result.text)
    _same_program(program, again)
    unit = CL_UNITS[program.units] / 60.0  # m/s per file unit/min
    written = np.isfinite(result.feeds)
    assert np.array_equal(written, cutting)
    # the reader reads what was written, to 1e-4 in the file's unit
    assert np.max(np.abs(again.feeds[written] - result.feeds[written])) / unit <= 1e-4
    # rounded down, never above what was asked, and within one step of the statement's least
    assert np.all(result.feeds[written] <= wanted[written] * (1 + 1e-12))
    for line in set(program.lines[written].tolist()):
        on = written & (program.lines == line)
        assert np.all(result.feeds[on] == result.feeds[on][0])  # one FEDRAT a statement
        assert (wanted[on].min() - result.feeds[on][0]) / unit <= 1e-4 + 1e-9
    # the moves that keep theirs (RAPID) read as before; every other line kept byte for byte
    assert _not_fedrat(result.text) == _not_fedrat(text)
    lines = result.text.splitlines()
    fedrats = [ln for ln in lines if ln.upper().startswith("FEDRAT/")]
    assert len(fedrats) == result.statements > 0
    word = "IPM" if program.units == "inch" else "MMPM"
    assert all(word in ln for ln in fedrats) and not any(
        ("MMPM" if word == "IPM" else "IPM") in ln for ln in fedrats
    )
    for k, ln in enumerate(lines[:-1]):  # never between a CIRCLE and its GOTO
        if ln.upper().startswith("CIRCLE/"):
            assert lines[k + 1].upper().startswith("GOTO/")


def test_the_writer_keeps_the_dialect_and_line_endings():
    nx = read_cldata(DATA / "nx_circle_pocket.cls")
    text = _text(DATA / "nx_circle_pocket.cls").replace("\n", "\r\n")
    wanted = np.where(~nx.rapid & np.isfinite(nx.feeds), 0.004, np.nan)  # 240 mm/min
    result = rewrite_feeds(text, nx, wanted)
    assert "\r\n" in result.text and "\n" not in result.text.replace("\r\n", "")
    assert "FEDRAT/MMPM,240.0000\r\n" in result.text  # NX: the unit first
    assert result.statements == 1  # one feed throughout: written once
    fusion = read_cldata(DATA / "fusion_inch.apt")
    wanted = np.where(~fusion.rapid & np.isfinite(fusion.feeds), 0.00254, np.nan)
    result = rewrite_feeds(_text(DATA / "fusion_inch.apt"), fusion, wanted)
    assert "FEDRAT/6.0000,IPM" in result.text  # the value first; 6 inch/min
    # a NURBS record gets one FEDRAT, before the record, with the least of its moves
    nurbs = read_cldata(DATA / "nx_nurbs.cls")
    line, count = nurbs.splines[0]
    on = np.flatnonzero(nurbs.lines == line)
    assert on.size == count > 1
    wanted = np.where(~nurbs.rapid & np.isfinite(nurbs.feeds), 0.004, np.nan)
    wanted[on] = np.linspace(0.003, 0.002, on.size)  # 180 down to 120 mm/min
    result = rewrite_feeds(_text(DATA / "nx_nurbs.cls"), nurbs, wanted)
    out = result.text.splitlines()
    record = next(k for k, ln in enumerate(out) if ln.upper().startswith("NURBS"))
    assert out[record - 1] == "FEDRAT/MMPM,120.0000"


def _config(tmp_path: Path, vmax: float = VMAX, amax: float = AMAX) -> Path:
    text = CELL.read_text(encoding="utf-8")
    changed = text.replace("actuator_speed_max: [0.05]", f"actuator_speed_max: [{vmax}]")
    changed = changed.replace("actuator_accel_max: [0.5]", f"actuator_accel_max: [{amax}]")
    assert f"actuator_speed_max: [{vmax}]" in changed and f"[{amax}]" in changed
    path = tmp_path / "cell.yaml"
    path.write_text(changed, encoding="utf-8")
    return path


FEEDS = ("--rapid-feed-mm-min", "3000", "--rotary-feed-deg-min", "3600")


def _dense_ratios(
    config: Path, cl: Path, vmax: float = VMAX, amax: float = AMAX
) -> list[tuple[float, float, float]]:
    """Per cutting move with translation of ``cl`` run at its feed F (u' = F/L, straight
    moves): (max |q̇|/v, max |q̈|/a, F in mm/min), from the reference inverse kinematics."""
    options = build_parser().parse_args(["schedule", str(cl), "--config", str(config), *FEEDS])
    options.interpolation = "slerp"
    platform, _, _, _, parts, _ = read_cell_inputs(options, io.StringIO())
    reference = reference_arch.load(config)
    ratios = []
    for part in parts:
        assert part.arcs is None and part.beziers is None  # the pocket's moves are straight
        _, result, _, _ = check_part_path(platform, part, options)
        checked, _ = reported_parts(result)
        positions = checked.waypoints.positions
        rotations = tt_to_matrix(checked.waypoints.angles)
        tool_rotation = reference_arch.rotation_matrices(part.tool.orientation)[0]
        joints = (reference.platform_joints - part.tool.offset) @ tool_rotation  # R_toolᵀ(b − t)
        for k in range(len(positions) - 1):
            length = float(np.linalg.norm(positions[k + 1] - positions[k]))
            feed = float(part.feeds[k + 1])
            if part.rapid[k + 1] or length == 0.0:
                continue
            u = np.linspace(0.0, 1.0, DENSE)
            axis, angle = log_axis_angle(rotations[k + 1] @ rotations[k].T)
            turning = rodrigues(axis, u * angle) @ rotations[k]
            p = positions[k] + u[:, None] * (positions[k + 1] - positions[k])
            points = p[:, None, :] + np.einsum("nij,kj->nki", turning, joints)
            q, _ = reference_arch.inverse_kinematics(reference, points)
            dt = length / feed / (DENSE - 1)  # u' = F/L
            speed = np.gradient(q, dt, axis=0)
            # central second differences of stride STRIDE at every sample (a stride of 1 on a
            # 5 mm move is all round-off: q''·h² ~ 5e-14 m against q's 1e-16 m)
            accel = (q[2 * STRIDE :] - 2.0 * q[STRIDE:-STRIDE] + q[: -2 * STRIDE]) / (
                STRIDE * dt
            ) ** 2
            ratios.append(
                (float(np.max(np.abs(speed))) / vmax, float(np.max(np.abs(accel))) / amax, feed)
            )
    return ratios


@pytest.mark.parametrize(
    ("vmax", "amax", "binds"), [(VMAX, AMAX, "speed"), (0.05, 2e-4, "acceleration")]
)
def test_pocket_write_cl_holds_the_limits_at_the_written_feeds(tmp_path, vmax, amax, binds):
    config = _config(tmp_path, vmax, amax)
    out = tmp_path / "pocket_steady.cl"
    code, text, err = run_main(
        "schedule", str(POCKET), "--config", str(config), *FEEDS, "--write-cl", str(out), "--json"
    )
    assert code == 0, err
    report = json.loads(text)
    written = report["write_cl"]
    assert written["path"] == str(out) and written["fedrat_statements"] == _text(out).count(
        "FEDRAT/"
    )
    moves = [m for p in report["parts"] for m in p["moves"]]
    slowed = [
        m
        for m in moves
        if m["feed_steady_mm_min"] is not None
        and m["feed_steady_mm_min"] < m["feed_ceiling_mm_min"] - 1e-3
    ]
    assert written["moves_slowed"] == len(slowed) >= 10
    assert all(m["feed_steady_mm_min"] is None for m in moves if m["rapid"])
    _same_program(read_cldata(POCKET), read_cldata(out))
    # independent: run at the written feeds, no limit is exceeded ...
    ratios = _dense_ratios(config, out, vmax, amax)
    assert len(ratios) >= len(slowed)
    assert max(max(s, a) for s, a, _ in ratios) <= 1.001
    # the case exercises the limit it is meant to (the other one far from binding)
    column = 0 if binds == "speed" else 1
    assert sum(r[column] >= 0.9 for r in ratios) >= 10
    # ... and the slowed moves are not needlessly slow: each reaches 95 % of some limit in
    # feed terms (speed ∝ F, acceleration ∝ F²), so 1.05·F would exceed it
    slowed_feeds = {round(m["feed_steady_mm_min"], 4) for m in slowed}
    tight = [
        max(s, math.sqrt(a)) for s, a, f in ratios if round(f / 1.0e-3 * 60.0, 4) in slowed_feeds
    ]
    assert len(tight) >= len(slowed) and min(tight) >= 0.95
    # text output
    code, text, err = run_main(
        "schedule", str(POCKET), "--config", str(config), *FEEDS, "--write-cl", str(out), "--force"
    )
    assert code == 0, err
    assert (
        f"wrote {out}: {written['fedrat_statements']} FEDRAT statements "
        f"({written['moves_slowed']} moves slower than programmed)"
    ) in text


def _cutting_verdicts(report: dict) -> list[bool]:
    """check-path's speed_ok of every cutting move with translation (RAPID moves and
    rotations keep their programmed feed in OUT)."""
    return [
        s["speed_ok"]
        for p in report["parts"]
        for s in p["segments"]
        if not s["rapid"] and s.get("feed_mm_min") is not None
    ]


def test_check_path_on_the_written_file_says_speed_ok(tmp_path):
    config = _config(tmp_path)
    no_accel = tmp_path / "no_accel.yaml"
    no_accel.write_text(
        config.read_text(encoding="utf-8").replace(f"[{AMAX}]", "[0.0]"), encoding="utf-8"
    )
    out = tmp_path / "steady.cl"
    code, _, err = run_main(
        "schedule", str(POCKET), "--config", str(no_accel), *FEEDS, "--write-cl", str(out)
    )
    assert code == 0, err
    code, text, _ = run_main("check-path", str(out), "--config", str(no_accel), *FEEDS, "--json")
    verdicts = _cutting_verdicts(json.loads(text))
    assert len(verdicts) >= 20 and all(verdicts)
    # the input at its programmed feeds does not: the check can fail
    code, text, _ = run_main("check-path", str(POCKET), "--config", str(no_accel), *FEEDS, "--json")
    before = _cutting_verdicts(json.loads(text))
    assert len(before) == len(verdicts) and not all(before)


def test_refusals_exit_2_in_one_line(tmp_path):
    csv = tmp_path / "p.csv"
    csv.write_text("x,y,z,i,j,k\n0,0,-1.3,0,0,1\n0.01,0,-1.3,0,0,1\n", encoding="utf-8")
    code, _, err = run_main(
        "schedule", str(csv), "--feed-mm-min", "600", "--write-cl", str(tmp_path / "o.cl")
    )
    assert code == 2 and "--write-cl: only for CL files" in one_error_line(err)
    existing = tmp_path / "old.cl"
    existing.write_text("GOTO/0,0,0\n", encoding="utf-8")
    code, _, err = run_main("schedule", str(POCKET), *FEEDS, "--write-cl", str(existing))
    assert code == 2 and "exists" in one_error_line(err) and "--force" in one_error_line(err)
    assert existing.read_text(encoding="utf-8") == "GOTO/0,0,0\n"
    code, _, err = run_main("schedule", str(POCKET), *FEEDS, "--write-cl", str(POCKET), "--force")
    assert (
        code == 2 and "--write-cl" in one_error_line(err) and "FILE itself" in one_error_line(err)
    )


def test_a_nurbs_record_through_the_cli_gets_one_fedrat_the_least_of_its_spans(tmp_path):
    """The real NX spline (its first record, moved into the example's volume as in
    test_cli_cam): one FEDRAT before the NURBS line, the smallest of its Bézier moves' feeds."""
    lines = (DATA / "nx_nurbs.cls").read_text(encoding="utf-8").splitlines()
    first = tmp_path / "first_spline.cls"
    first.write_text("\n".join([*lines[:23], *lines[-3:]]) + "\n", encoding="utf-8")
    text = CELL.read_text(encoding="utf-8").replace("[0.0, 0.0, -1.40]", "[0.255, -0.4595, -1.574]")
    text = text.replace("actuator_speed_max: [0.05]", "actuator_speed_max: [0.0005]")
    config = tmp_path / "cell.yaml"
    config.write_text(text, encoding="utf-8")
    out = tmp_path / "out.cls"
    code, report_text, err = run_main(
        "--config", str(config), "schedule", str(first), "--write-cl", str(out), "--json"
    )
    assert code == 0, err
    moves = json.loads(report_text)["moves"]
    spans = [m for m in moves if m["line"] == 13]
    assert len(spans) == 5
    least = min(m["feed_steady_mm_min"] for m in spans)
    assert least < 250.0 and all(m["feed_steady_mm_min"] == least for m in spans)
    written = out.read_text(encoding="utf-8").splitlines()
    record = written.index(lines[12])  # the NURBS line
    assert written[record - 1] == f"FEDRAT/MMPM,{least:.4f}"
    _same_program(read_cldata(first), read_cldata(out))


def test_steady_feeds_unbounded_and_refused_moves():
    from hexapod_workspace.core.evaluation.loading import example_manipulator
    from hexapod_workspace.core.motions.schedule import steady_feeds
    from hexapod_workspace.errors import InputError

    model = example_manipulator()
    positions = np.array([[0.0, 0.0, -1.3], [0.05, 0.0, -1.3], [0.05, 0.0, -1.3]])
    rotations = np.repeat(np.eye(3)[None], 3, axis=0)
    none = steady_feeds(model, positions, rotations, speed_limits=[0.0], accel_limits=[0.0])
    assert np.all(np.isinf(none))  # no limit; the second move does not move
    rate = steady_feeds(model, positions, rotations, speed_limits=[0.02], accel_limits=[0.0])
    assert 0.0 < rate[0] < math.inf and math.isinf(rate[1])
    # speed-bound: at u' the certified peak is the limit, so the feed u'·L is at most
    # 0.02 m/s over the largest |dq/ds| per metre (a leg can never outrun the tool: ≤ 1)
    assert rate[0] * 0.05 >= 0.02 * (1 - 1e-9)
    # a 6-PUS whose legs cannot reach the end of move 2: refused, the move named
    from test_schedule import machine
    from test_speeds import CASES

    pus = machine("pus")
    path = np.array(CASES["pus"][1]) + np.array([[0, 0, 0], [0.005, 0, 0], [0.005, 0, -2.0]])
    with pytest.raises(InputError, match="move 2: actuator [1-6] has no inverse-kinematics"):
        steady_feeds(pus, path, rotations, speed_limits=[0.02], accel_limits=[0.2])
