"""APT CLDATA reader: a CL file written the way CAM systems write it reads to the waypoints of
the equivalent CSV; malformed statements are refused with their line number."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from hexapod_workspace.cli.check_path import read_path_file
from hexapod_workspace.core.cell.cldata import looks_like_cldata, parse_cldata, read_cldata
from hexapod_workspace.errors import InputError

# Post-processor style: header records, mixed case, spaces, continuation lines, end-of-line
# comments, a switch to inches and back, feeds in both orders, one RAPID, a 3-value GOTO.
CL_TEXT = """\
PARTNO / POCKET TEST $$ exported by a CAM system
MACHIN / HEXAPOD, 1
UNITS / MM
MULTAX
LOADTL / 1 , ADJUST, 1
SPINDL / 12000, CLW
COOLNT / ON
rapid
GOTO / 10.000, 20.000, 5.000, 0.000000, 0.000000, 1.000000
FEDRAT / 600.0 , MMPM
goto/ 12.5,20.0,$
  2.0 , 0.0, 0.2588190, 0.9659258  $$ tilted 15 deg about x... towards +y
$$ a whole-line comment
  GOTO/15.0, 20.0, 2.0
UNITS/INCHES
FEDRAT/IPM, 20
GOTO/0.70866142, 0.78740157, 0.07874016, 0.3, 0.0, 1.0
units/mm
FEDRAT/ 300
GOTO / 18, 22, 2, 0, 0, 2
END
FINI
"""

CSV_TEXT = """\
x,y,z,i,j,k
0.010,0.020,0.005,0,0,1
0.0125,0.020,0.002,0.0,0.2588190,0.9659258
0.015,0.020,0.002,0.0,0.2588190,0.9659258
0.018,0.020,0.002,0.3,0.0,1.0
0.018,0.022,0.002,0,0,1
"""


def test_cl_file_reads_to_the_waypoints_of_the_equivalent_csv(tmp_path):
    cl_path, csv_path = tmp_path / "pocket.cl", tmp_path / "pocket.csv"
    cl_path.write_text(CL_TEXT, encoding="utf-8")
    csv_path.write_text(CSV_TEXT, encoding="utf-8")
    program = read_cldata(cl_path, tools={1})
    csv = read_path_file(csv_path)
    assert csv.axes is not None
    # 0.70866142 in = 18.0 mm, 0.78740157 in = 20.0 mm, 0.07874016 in = 2.0 mm
    np.testing.assert_allclose(program.positions, csv.positions, atol=1e-9)
    unit_axes = csv.axes / np.linalg.norm(csv.axes, axis=1, keepdims=True)
    np.testing.assert_allclose(program.axes, unit_axes, atol=1e-12)
    # feeds in m/s: none into the first, 600 mm/min, 600 again, 20 in/min, 300 mm/min
    expected = [math.nan, 0.6 / 60, 0.6 / 60, 20 * 0.0254 / 60, 0.3 / 60]
    np.testing.assert_allclose(program.feeds, expected, rtol=1e-12)
    assert program.rapid.tolist() == [False] * 5  # RAPID before the first GOTO: no move
    assert program.tools.tolist() == [1] * 5
    assert program.lines.tolist() == [9, 11, 14, 17, 20]
    assert program.parts == ((0, 5),)
    assert program.multax
    assert [name for name, _, _ in program.passed_over] == [
        "PARTNO",
        "MACHIN",
        "SPINDL",
        "COOLNT",
        "END",
        "FINI",
    ]
    assert program.passed_over[0][1] == 1
    assert program.units == "mm" and program.units_source == "line 3: UNITS / MM"
    assert looks_like_cldata(CL_TEXT) and not looks_like_cldata(CSV_TEXT)


def test_rapid_applies_to_the_next_motion_only_and_axis_defaults_to_work_z():
    program = parse_cldata("UNITS/MM\nGOTO/0,0,0\nRAPID\nGOTO/1,0,0\nGOTO/2,0,0\n")
    assert program.rapid.tolist() == [False, True, False]
    np.testing.assert_array_equal(program.axes, [[0, 0, 1]] * 3)
    assert np.isnan(program.feeds).all()  # no FEDRAT: no feed


def test_unitless_feed_is_per_minute_in_the_current_units():
    program = parse_cldata("UNITS/INCHES\nFEDRAT/10\nGOTO/0,0,0\nUNITS/MM\nGOTO/25.4,0,0\n")
    assert program.feeds[1] == pytest.approx(10 * 0.0254 / 60)  # set in in/min, kept
    np.testing.assert_allclose(program.positions[1], [0.0254, 0, 0])


def test_tool_change_splits_the_path():
    program = parse_cldata(
        "LOADTL/1\nGOTO/0,0,0\nGOTO/1,0,0\nLOADTL/2\nGOTO/1,0,5\nFEDRAT/100\nGOTO/2,0,5\n",
        tools={1, 2},
        units="mm",
    )
    assert program.parts == ((0, 2), (2, 4))
    assert program.tools.tolist() == [1, 1, 2, 2]
    assert np.isnan(program.feeds[2])  # the first waypoint of a part has no incoming move


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("GOTO/0,0,0\nGOTO/1,2\n", r"^line 2: GOTO/1,2: expected 3 \(x,y,z\) or 6"),
        ("UNITS/FEET\nGOTO/0,0,0\n", r"^line 1: UNITS/FEET: expected UNITS/MM or UNITS/INCHES"),
        ("FEDRAT/-5\n", r"^line 1: FEDRAT/-5: expected a feed > 0, got -5"),
        ("FEDRAT/5,FPM\n", r"^line 1: FEDRAT/5,FPM: unknown feed unit 'FPM'"),
        ("FEDRAT/0.2,MMPR\n", r"^line 1: .*per-revolution feeds are not modelled"),
        ("GOTO/0,0,0\nLOADTL/3\n", r"^line 2: LOADTL/3: tool 3 is not in the tool table"),
        ("GOTO/0,0,0,0,0,0\n", r"^line 1: .*expected a non-zero tool axis"),
        ("GOTO/0,0,x\n", r"^line 1: GOTO/0,0,x: expected a number, got 'x'"),
        ("GOTO/5,0,0\nCIRCLE/0,0,0,0,0,1,5\n", r"^line 2: CIRCLE.*expected a GOTO after it"),
        ("GOTO/5,0,0\nCIRCLE/0,0,0,0,0,1\n", r"^line 2: .*at least 7 numbers"),
        ("GOTO/5,0,0\nCIRCLE/0,0,0,0,0,1,0\n", r"^line 2: .*expected a radius > 0"),
        ("GOTO/5,0,0\nCIRCLE/0,0,0,0,0,1,5\nGOTO/0,4,0\n", r"^line 3: .*end is 4 mm from"),
        ("GOTO/5.1,0,0\nCIRCLE/0,0,0,0,0,1,5\nGOTO/0,5,0\n", r"^line 3: .*start is 5.1 mm"),
        (
            "GOTO/5,0,0\nCIRCLE/0,0,0,0,0,1,5\nGOTO/0,5,0,0,1,0\n",
            r"^line 3: .*the tool axis changes along the arc of line 2",
        ),
        (
            "GOTO/5,0,0\nCIRCLE/0,0,0,0,0,1,5\nFEDRAT/100\nGOTO/0,5,0\n",
            r"^line 3: FEDRAT/100: expected the GOTO that ends the arc of line 2",
        ),
        ("CIRCLE/0,0,0,0,0,1,5\nGOTO/0,5,0\n", r"^line 1: .*expected a point of this part"),
        (
            "GOTO/5,0,0\nSET/MODE,INCR\nCIRCLE/0,0,0,0,0,1,5\n",
            r"^line 3: .*CIRCLE in incremental mode",
        ),
        ("GOTO/0,0,0,$\n", r"^line 1: statement continued with '\$' past the end"),
        ("PARTNO/X\n", r"^CL file: expected at least one GOTO"),
        ("GOTO/0,0,0\n12,3\n", r"^line 2: expected an APT statement"),
    ],
)
def test_malformed_statements_are_refused_with_their_line(text, message):
    with pytest.raises(InputError, match=message) as caught:
        parse_cldata(text, tools={1, 2}, units="mm")
    assert "\n" not in str(caught.value)


def test_file_errors_name_the_file(tmp_path):
    path = tmp_path / "bad.cl"
    path.write_text("UNITS/MM\nGOTO/1,2\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"^CL file .*bad\.cl: line 2: GOTO/1,2"):
        read_cldata(path)
    with pytest.raises(InputError, match="cannot read CL file"):
        read_cldata(tmp_path / "missing.cl")


# --- issue #35: real CAM files (test/data/cl/, sources in test/data/cl/SOURCES.md) ----------

DATA = Path(__file__).resolve().parent / "data" / "cl"
INCH = 0.0254


def _read(name: str, **kwargs):
    return read_cldata(DATA / name, **kwargs)


# 1. units: stated, told from the feeds, or refused; never guessed


def test_nx_inch_file_without_units_is_read_in_inches_from_its_ipm_feeds():
    program = _read("nx_inch_ipm.cls")
    assert program.units == "inch" and program.units_source.startswith("line 14: FEDRAT/IPM")
    np.testing.assert_allclose(program.positions[0], [-0.7874 * INCH, -0.3937 * INCH, INCH])
    assert program.feeds[2] == pytest.approx(40 * INCH / 60)


def test_fusion_unit_inch_is_read():
    program = _read("fusion_inch.apt")
    assert program.units == "inch" and program.units_source == "line 6: UNIT/INCH"
    np.testing.assert_allclose(program.positions[1], [-0.7874 * INCH, -0.3937 * INCH, INCH])


@pytest.mark.parametrize(
    ("statement", "metres"),
    [
        ("UNITS/MM", 1e-3),
        ("UNITS/INCHES", INCH),
        ("UNITS/INCH", INCH),
        ("UNIT/INCH", INCH),
        ("unit/mm", 1e-3),
        ("UNITS/IN", INCH),
        ("UNITS/MILLIMETERS", 1e-3),
    ],
)
def test_every_spelling_of_units_is_read(statement, metres):
    program = parse_cldata(f"{statement}\nGOTO/1,0,0\n")
    assert program.positions[0, 0] == pytest.approx(metres)


def test_a_file_that_does_not_state_its_units_is_refused_unless_the_caller_does():
    text = "GOTO/0,0,0\nFEDRAT/100\nGOTO/10,0,0\n"
    with pytest.raises(
        InputError, match=r"^line 1: GOTO/0,0,0: the file does not state its units.*--cl-units"
    ):
        parse_cldata(text)
    assert parse_cldata(text, units="inch").positions[1, 0] == pytest.approx(10 * INCH)
    assert parse_cldata(text, units="mm").units_source == "units='mm' (--cl-units)"


def test_mm_feeds_state_mm_without_units():
    program = parse_cldata("RAPID\nGOTO/0,0,50\nFEDRAT/MMPM,250\nGOTO/0,0,0\n")
    assert program.units == "mm" and program.positions[0, 2] == pytest.approx(0.05)


@pytest.mark.parametrize(
    ("text", "units", "message"),
    [
        (
            "UNITS/MM\nGOTO/0,0,0\nFEDRAT/IPM,20\nGOTO/1,0,0\n",
            None,
            r"^line 3: FEDRAT/IPM,20: a feed in inches, but line 1 \(UNITS/MM\) says mm",
        ),
        (
            "FEDRAT/MMPM,100\nGOTO/0,0,0\nFEDRAT/IPM,20\n",
            None,
            r"^line 3: FEDRAT/IPM,20: a feed in inches, but line 1 \(FEDRAT/MMPM,100\) says mm",
        ),
        (
            "GOTO/0,0,0\nFEDRAT/IPM,20\nGOTO/1,0,0\n",
            "mm",
            r"^line 2: FEDRAT/IPM,20: a feed in inches, but the units given .*--cl-units.* mm",
        ),
        (
            "UNITS/MM\nGOTO/0,0,0\n",
            "inch",
            r"^line 1: UNITS/MM: the file says mm, but the units given .*--cl-units.* inch",
        ),
    ],
)
def test_statements_that_disagree_on_the_units_are_refused_naming_both(text, units, message):
    with pytest.raises(InputError, match=message):
        parse_cldata(text, units=units)


# 2. NURBS: modelled as the spline (test_cl_splines.py)


# 3. MSYS: the machining coordinate system is composed with the work frame


def test_nx_msys_with_z_down_maps_to_the_work_frame_like_a_homogeneous_transform():
    program = _read("nx_msys_zdown.cls")
    x_axis, y_axis = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])
    transform = np.eye(4)
    transform[:3, :3] = np.column_stack([x_axis, y_axis, np.cross(x_axis, y_axis)])
    transform[:3, 3] = np.array([-120.2591, -1196.5, 142.5]) * 1e-3
    assert transform[2, 2] == -1.0  # the MCS's z points down
    file_point = np.array([0.0, 222.6719, -177.5, 1000.0]) * 1e-3
    np.testing.assert_allclose(program.positions[0], (transform @ file_point)[:3], atol=1e-12)
    np.testing.assert_allclose(program.axes, [[0.0, 0.0, 1.0]] * len(program), atol=1e-12)
    assert program.positions[:, 2].min() == pytest.approx(0.240)  # 97.5 mm below 142.5 mm
    ((line, origin, rotation),) = program.frames
    assert line == 3 and np.allclose(rotation, transform[:3, :3])
    assert program.tools.tolist() == [2] * len(program)  # 4. LOAD/TOOL,2
    assert program.units == "mm"


def test_msys_must_be_orthonormal_and_origin_with_a_rotated_msys_is_refused():
    with pytest.raises(InputError, match=r"line 1: .*expected unit, orthogonal X and Y axes"):
        parse_cldata("MSYS/0,0,0,1,0,0,1,1,0\nGOTO/0,0,0\n", units="mm")
    with pytest.raises(InputError, match=r"line 2: ORIGIN/1,0,0: ORIGIN with the rotated MSYS"):
        parse_cldata("MSYS/0,0,0,0,1,0,1,0,0\nORIGIN/1,0,0\nGOTO/0,0,0\n", units="mm")


# 4. LOAD/TOOL,n is a tool change


def test_load_tool_acts_like_loadtl():
    text = "UNITS/MM\nLOAD/TOOL,1\nGOTO/0,0,0\nGOTO/1,0,0\nLOAD/TOOL,2,ADJUST,2\nGOTO/1,0,5\n"
    program = parse_cldata(text + "GOTO/2,0,5\n", tools={1, 2})
    assert program.parts == ((0, 2), (2, 4)) and program.tools.tolist() == [1, 1, 2, 2]
    with pytest.raises(InputError, match=r"line 5: LOAD/TOOL,2,ADJUST,2: tool 2 is not in"):
        parse_cldata(text, tools={1})
    catia = parse_cldata(
        "UNITS/MM\nTOOLNO/1,MILL,10\nLOADTL/1\nGOTO/0,0,0\nGOTO/1,0,0\nTOOLNO/2,MILL,6\n"
        "LOADTL/2\nGOTO/1,0,5\nGOTO/2,0,5\n",
        tools={1, 2},
    )
    assert catia.parts == ((0, 2), (2, 4)) and catia.tools.tolist() == [1, 1, 2, 2]
    with pytest.raises(InputError, match=r"line 1: LOAD/WIRE: expected LOAD/TOOL,n"):
        parse_cldata("LOAD/WIRE\n", units="mm")


# 5. FROM, GODLTA, GOHOME, TLAXIS, SET/MODE, ORIGIN modelled; TRACUT, CUTCOM refused


def test_from_godlta_gohome_tlaxis_and_incremental_mode_are_modelled():
    program = parse_cldata(
        "UNITS/MM\nFROM/0,0,100,0,0,1\nRAPID\nGOTO/10,0,5\nTLAXIS/0,1,1\nGOTO/10,0,0\n"
        "GODLTA/0,5,0\nGODLTA/2\nSET/MODE,INCR\nGOTO/1,1,1\nSET/MODE,ABSOL\nGOTO/0,0,0\n"
        "RAPID\nGOHOME\n"
    )
    s = math.sqrt(0.5)
    expected = [
        [0, 0, 100],
        [10, 0, 5],
        [10, 0, 0],
        [10, 5, 0],
        [10, 5 + 2 * s, 2 * s],
        [11, 6 + 2 * s, 1 + 2 * s],
        [0, 0, 0],
        [0, 0, 100],
    ]
    np.testing.assert_allclose(program.positions, np.array(expected) * 1e-3, atol=1e-12)
    np.testing.assert_allclose(program.axes[2], [0, s, s])
    np.testing.assert_allclose(program.axes[-1], [0, 0, 1])  # GOHOME: FROM's axis
    assert program.rapid.tolist() == [False, True, False, False, False, False, False, True]
    assert program.lines.tolist() == [2, 4, 6, 7, 8, 10, 12, 14]


def test_origin_shifts_the_following_coordinates():
    program = parse_cldata(
        "UNITS/MM\nGOTO/0,0,0\nORIGIN/10,20,30\nGOTO/1,0,0\nORIGIN/0,0,0\nGOTO/1,0,0\n"
    )
    np.testing.assert_allclose(program.positions * 1e3, [[0, 0, 0], [11, 20, 30], [1, 0, 0]])


@pytest.mark.parametrize(
    ("statement", "message"),
    [
        ("TRACUT/1,0,0,0,0,1,0,0,0,0,1,0", r"TRACUT transformations are not modelled"),
        ("CUTCOM/LEFT", r"cutter compensation .* is not modelled"),
        ("CUTCOM/LEFT,0", r"cutter compensation .* is not modelled"),
        ("CYCLE/DRILL,5,MMPM,100", r"canned cycles are not modelled"),
        ("INSERT G0 X0", r"INSERT passes text to the controller"),
        ("SET/UPPER,25", r"expected SET/MODE,INCR or SET/MODE,ABSOL"),
        ("GOHOME", r"GOHOME without a FROM point"),
        ("WHATEVER/1", r"unknown statement WHATEVER: not modelled, so refused"),
        ("SET/MODE,INCR\nGOTO/1,0,0,0,0,1", r"a tool axis in incremental mode"),
    ],
)
def test_statements_that_change_the_motion_and_are_not_modelled_are_refused(statement, message):
    with pytest.raises(InputError, match=r"^line \d+: " + ".*" + message):
        parse_cldata(f"UNITS/MM\nGOTO/0,0,0\n{statement}\nGOTO/1,0,0\n")


def test_from_after_a_move_of_the_same_part_and_godlta_first_are_refused():
    with pytest.raises(InputError, match=r"^line 3: FROM/0,0,0: FROM after a move"):
        parse_cldata("UNITS/MM\nGOTO/0,0,0\nFROM/0,0,0\n")
    with pytest.raises(InputError, match=r"^line 2: GODLTA/1: expected a previous point"):
        parse_cldata("UNITS/MM\nGODLTA/1\n")


def test_trivial_off_forms_are_passed_over_and_counted():
    program = parse_cldata(
        "UNITS/MM\nCUTCOM/OFF\nTRACUT/NOMORE\nGOTO/0,0,0\nCYCLE/OFF\nGOTO/1,0,0\nCYCLE/OFF\n"
    )
    assert program.passed_over == (
        ("CUTCOM/OFF", 2, 1),
        ("TRACUT/NOMORE", 3, 1),
        ("CYCLE/OFF", 5, 2),
    )


def test_pprint_ending_in_a_dollar_does_not_swallow_the_next_goto():
    program = parse_cldata("UNITS/MM\nPPRINT/ROUGHING $\nGOTO/0,0,0\nPARTNO/A$\nGOTO/1,0,0\n")
    assert program.lines.tolist() == [3, 5]
    assert dict((n, c) for n, _, c in program.passed_over) == {"PPRINT": 1, "PARTNO": 1}


# 6. valid statements of NX and CATIA that were refused


def test_nx_tool_path_and_end_of_path_split_the_path():
    text = (
        "TOOL PATH/OP1,TOOL,EM10\nFEDRAT/MMPM,100\nGOTO/0,0,0\nGOTO/1,0,0\nEND-OF-PATH\n"
        "TOOL PATH/OP2,TOOL,EM10\nGOTO/5,0,0\nGOTO/6,0,0\nEND-OF-PATH\n"
    )
    program = parse_cldata(text)
    assert program.parts == ((0, 2), (2, 4))
    assert np.isnan(program.feeds[2])  # a new part has no incoming move


def test_catia_file_reads():
    program = _read("catia_channel.aptsource")
    np.testing.assert_allclose(program.positions[0], [-0.020, -0.010, 0.010])  # 1.0D+01 mm
    assert len(program) == 5 and program.tools.tolist() == [1] * 5
    counts = {name: count for name, _, count in program.passed_over}
    assert counts["PARTNO"] == 1 and counts["PPRINT"] == 2 and counts["CHANNEL"] == 1
    assert counts["TPRINT"] == 1 and "TOOLNO" not in counts  # TOOLNO/1: a tool change


@pytest.mark.parametrize("feed", ["FEDRAT/0.1,PERREV", "FEDRAT/PERREV,0.1", "FEDRAT/0.1,IPR"])
def test_per_revolution_feeds_get_the_per_revolution_message(feed):
    with pytest.raises(InputError, match=r"^line 2: .*per-revolution feeds are not modelled"):
        parse_cldata(f"UNITS/MM\n{feed}\nGOTO/0,0,0\n")


def test_fortran_exponents_are_numbers():
    program = parse_cldata("UNITS/MM\nGOTO/1.0D+01,2.5d-1,-1.0E+00\n")
    np.testing.assert_allclose(program.positions[0], [0.010, 0.00025, -0.001])


def test_the_fusion_sample_models_from_and_gohome():
    program = _read("fusion_inch.apt", tools={3})
    assert program.lines[0] == 13 and program.lines[-1] == 24  # FROM ... GOHOME
    np.testing.assert_allclose(program.positions[-1], program.positions[0])
    assert program.tools.tolist() == [3] * len(program)
    counts = {name: count for name, _, count in program.passed_over}
    assert counts == {
        "PARTNO": 1,
        "MACHIN": 1,
        "PPRINT": 1,
        "SPINDL": 2,
        "COOLNT": 2,
        "OPSTOP": 1,
        "CYCLE/OFF": 1,
        "END": 1,
        "FINI": 1,
    }


NX_CIRCLE = Path(__file__).resolve().parent / "data" / "cl" / "nx_circle_pocket.cls"


def test_arcs_run_clockwise_about_their_axis_and_a_full_circle_closes():
    # Clockwise about +z from (5, 0) to (0, 5) is three quarters of a turn; about −z, one.
    for z, quarter_turns in ((1, 3), (-1, 1)):
        axis = f"0,0,{z}"
        program = parse_cldata(f"GOTO/5,0,0\nCIRCLE/0,0,0,{axis},5\nGOTO/0,5,0\n", units="mm")
        phi = program.arcs[1, 6]
        assert phi == pytest.approx(-quarter_turns * math.pi / 2)
        np.testing.assert_allclose(program.arcs[1, :6], [0, 0, 0, 0, 0, z])
        assert np.isnan(program.arcs[0]).all()
    full = parse_cldata("GOTO/5,0,0\nCIRCLE/0,0,0,0,0,1,5\nGOTO/5,0,0\n", units="mm")
    assert full.arcs[1, 6] == pytest.approx(-2 * math.pi)


def test_the_nx_pocket_s_arcs_are_tangent_to_their_neighbours():
    """The real NX CLSF (test/data/cl/SOURCES.md): under the clockwise-about-the-axis reading
    every arc starts and ends tangent to the moves beside it (G1 continuity, as the CAM system
    computes a pocket's contour); the other reading would reverse the tool at each arc."""
    program = read_cldata(NX_CIRCLE)
    arcs = np.flatnonzero(np.isfinite(program.arcs[:, 0]))
    assert arcs.size == 15
    assert program.units == "mm"
    assert {name for name, _, _ in program.passed_over} >= {"PAINT", "TLDATA"}

    def tangents(k, flip=1.0):
        """Directions of move k (ending at waypoint k) at its start and its end (``flip`` −1:
        the arcs read the other way round)."""
        p0, p1 = program.positions[k - 1], program.positions[k]
        if not np.isfinite(program.arcs[k, 0]):
            direction = (p1 - p0) / np.linalg.norm(p1 - p0)
            return direction, direction
        centre, axis, phi = program.arcs[k, :3], program.arcs[k, 3:6], program.arcs[k, 6]
        sense = flip * math.copysign(1.0, phi)  # right-handed about the axis: < 0 clockwise
        ends = []
        for point in (p0, p1):
            radial = point - centre
            radial -= (radial @ axis) * axis
            tangent = sense * np.cross(axis, radial)
            ends.append(tangent / np.linalg.norm(tangent))
        return ends[0], ends[1]

    def joints(flip):
        """Cosines between each arc's end tangents and its neighbours' (links of 5 µm, which
        have no direction to speak of, left out)."""
        cosines = []
        for k in arcs:
            start, end = tangents(k, flip)
            for neighbour, here, side in ((k - 1, start, 1), (k + 1, end, 0)):
                step = program.positions[neighbour] - program.positions[neighbour - 1]
                if np.linalg.norm(step) > 1e-4:
                    cosines.append(float(tangents(neighbour, flip)[side] @ here))
        return np.array(cosines)

    ours, other = joints(1.0), joints(-1.0)
    # Clockwise: no joint reverses the tool; most are tangent, the rest are the pocket's corners
    # (the tool leaves an arc along its radius). Counter-clockwise: the tool would reverse.
    assert np.all(ours > -0.1)
    assert np.sum(ours > 0.999) >= 20
    assert np.sum(other < -0.999) >= 10
