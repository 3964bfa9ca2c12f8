"""APT CLDATA reader: a CL file written the way CAM systems write it reads to the waypoints of
the equivalent CSV; malformed statements are refused with their line number."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hexapod_workspace.cli.check_path import read_path_file
from hexapod_workspace.core.cldata import looks_like_cldata, parse_cldata, read_cldata
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
    assert [name for name, _, _ in program.ignored] == [
        "PARTNO",
        "MACHIN",
        "SPINDL",
        "COOLNT",
        "END",
        "FINI",
    ]
    assert program.ignored[0][1] == 1
    assert looks_like_cldata(CL_TEXT) and not looks_like_cldata(CSV_TEXT)


def test_rapid_applies_to_the_next_motion_only_and_axis_defaults_to_work_z():
    program = parse_cldata("GOTO/0,0,0\nRAPID\nGOTO/1,0,0\nGOTO/2,0,0\n")
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
        ("GOTO/0,0,0\nCIRCLE/0,0,0,0,0,1,5\n", r"^line 2: .*circular moves are not modelled"),
        ("GOTO/0,0,0,$\n", r"^line 1: statement continued with '\$' past the end"),
        ("PARTNO/X\n", r"^CL file: expected at least one GOTO"),
        ("GOTO/0,0,0\n12,3\n", r"^line 2: expected an APT statement"),
    ],
)
def test_malformed_statements_are_refused_with_their_line(text, message):
    with pytest.raises(InputError, match=message) as caught:
        parse_cldata(text, tools={1, 2})
    assert "\n" not in str(caught.value)


def test_file_errors_name_the_file(tmp_path):
    path = tmp_path / "bad.cl"
    path.write_text("GOTO/1,2\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"^CL file .*bad\.cl: line 1: GOTO/1,2"):
        read_cldata(path)
    with pytest.raises(InputError, match="cannot read CL file"):
        read_cldata(tmp_path / "missing.cl")
