"""NX ``NURBS`` records in CL files (issue #35 item 2): the clamped cubic from the current point,
read as one Bézier move per span, against a plain Cox–de Boor evaluation written here from the
definition (not the reader's knot insertion); refusals with their line.

The real records are those of the public NX sample ``test/data/cl/nx_nurbs.cls`` (origin in
``test/data/cl/SOURCES.md``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_beziers import casteljau

from hexapod_workspace.core.cell.cldata import parse_cldata, read_cldata
from hexapod_workspace.errors import InputError

SAMPLE = Path(__file__).resolve().parent / "data" / "cl" / "nx_nurbs.cls"


def _records(path: Path) -> list[tuple[int, np.ndarray, list[float], np.ndarray]]:
    """(line, start point, knots, CNTRL points) of each record, mm, read with str.split."""
    records, current, record = [], None, None
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        word, _, rest = line.partition("/")
        if record is not None and word not in ("KNOT", "CNTRL"):
            records.append(record)
            record = None
        values = [float(v) for v in rest.split(",")] if word in ("GOTO", "KNOT", "CNTRL") else []
        if word == "GOTO":
            current = np.array(values[:3])
        elif word == "NURBS":
            record = (number, current, [], [])
        elif word == "KNOT":
            record[2].extend(values)
        elif word == "CNTRL":
            record[3].append(values)
            current = np.array(values)
    return [(line, start, knots, np.array(c)) for line, start, knots, c in records]


def _basis(knots: np.ndarray, degree: int, u: np.ndarray) -> np.ndarray:
    """Cox–de Boor: B-spline basis functions N_{i,degree}(u), shape (len(u), n + 1)."""
    n = knots.size - degree - 1
    u = np.asarray(u, dtype=float)
    basis = np.zeros((u.size, knots.size - 1))
    for i in range(knots.size - 1):
        basis[:, i] = (knots[i] <= u) & (u < knots[i + 1])
    last = np.flatnonzero(knots < knots[-1])[-1]  # u = 1 belongs to the last non-empty span
    basis[u >= knots[-1], :] = 0.0
    basis[u >= knots[-1], last] = 1.0
    for p in range(1, degree + 1):
        following = np.zeros((u.size, knots.size - 1 - p))
        for i in range(knots.size - 1 - p):
            left = knots[i + p] - knots[i]
            right = knots[i + p + 1] - knots[i + 1]
            if left > 0.0:
                following[:, i] += (u - knots[i]) / left * basis[:, i]
            if right > 0.0:
                following[:, i] += (knots[i + p + 1] - u) / right * basis[:, i + 1]
        basis = following
    return basis[:, :n]


def _curve(knots: np.ndarray, controls: np.ndarray, u: np.ndarray) -> np.ndarray:
    return _basis(knots, 3, u) @ controls


def _cubic(knots: list[float]) -> np.ndarray:
    return np.concatenate([np.zeros(4), knots[:-1], np.ones(4)])


def _check_moves(program, line: int, knots: list[float], points: np.ndarray) -> int:
    """Each Bézier move of the spline of ``line`` is the B-spline on its knot interval (the
    parameter mapped affinely); returns the number of moves."""
    rows = np.flatnonzero(program.lines == line)
    assert rows.size and np.all(np.diff(rows) == 1)
    t = _cubic(knots)
    breaks = np.r_[0.0, sorted(set(knots[:-1])), 1.0]
    assert rows.size == breaks.size - 1  # one move per span
    s = np.linspace(0.0, 1.0, 101)
    for k, row in enumerate(rows):
        inner = program.beziers[row].reshape(2, 3)
        control = np.vstack([program.positions[row - 1], inner, program.positions[row]])
        u = breaks[k] + s * (breaks[k + 1] - breaks[k])
        np.testing.assert_allclose(casteljau(control, s), _curve(t, points, u), atol=1e-12)
    return int(rows.size)


def test_every_record_of_the_nx_sample_fits_the_clamped_cubic_from_the_tool():
    """The reading's evidence: K + 2 CNTRL points for K knots in every record; under the cubic
    reading the Greville abscissae follow the control polygon's chord length; the only other
    reading the counts allow (a quadratic through the CNTRL points alone) leaves the tool."""
    records = _records(SAMPLE)
    assert [len(knots) for _, _, knots, _ in records] == [5, 51, 4, 4, 5]
    gaps, jumps = [], []
    for _, start, knots, controls in records:
        assert len(controls) == len(knots) + 2 and knots[-1] == 1.0
        points = np.vstack([start, controls])
        t = _cubic(knots)
        greville = np.array([t[i + 1 : i + 4].mean() for i in range(len(points))])
        length = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
        gaps.append(float(np.abs(greville - length / length[-1]).max()))
        jumps.append(float(np.linalg.norm(controls[0] - start)))
    assert max(sorted(gaps)[:4]) < 0.003 and max(gaps) < 0.045
    assert min(jumps) > 0.3  # mm: the quadratic reading would start this far from the tool


def test_the_sample_reads_as_one_bezier_move_per_span_of_each_spline():
    program = read_cldata(SAMPLE)
    records = _records(SAMPLE)
    assert [line for line, _ in program.splines] == [line for line, *_ in records]
    assert [moves for _, moves in program.splines] == [5, 51, 4, 4, 5]
    assert len(program) == 7 + 69
    for (line, moves), (_, start, knots, controls) in zip(program.splines, records, strict=True):
        points = np.vstack([start, controls]) * 1e-3
        assert _check_moves(program, line, knots, points) == moves
        rows = program.lines == line
        # the spline ends at its last CNTRL point; the tool axis and the feed stay
        np.testing.assert_allclose(program.positions[rows][-1], points[-1], atol=1e-15)
        np.testing.assert_allclose(program.axes[rows], [[0.0, 0.0, 1.0]] * moves, atol=1e-15)
        np.testing.assert_allclose(program.feeds[rows], 0.25 / 60.0)
    curved = np.isin(program.lines, [line for line, _ in program.splines])
    assert np.isnan(program.beziers[~curved]).all() and np.isfinite(program.beziers[curved]).all()


SPLINE = "NURBS/\nKNOT/0.5,1\nCNTRL/1,0,0\nCNTRL/2,1,0\nCNTRL/3,1,1\nCNTRL/4,0,1\n"


def test_a_spline_in_inches_under_a_rotated_msys_is_the_mapped_curve():
    """B-splines are affine invariant: the reader maps the control points; its Bézier moves are
    the curve of the mapped points."""
    text = "UNITS/INCHES\nMSYS/1,2,3,0,1,0,-1,0,0\nGOTO/0,0,0\n" + SPLINE + "GOTO/4,0,2\n"
    program = parse_cldata(text)
    rotation = np.column_stack([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    origin = np.array([1.0, 2.0, 3.0]) * 0.0254
    file_points = np.array([[0, 0, 0], [1, 0, 0], [2, 1, 0], [3, 1, 1], [4, 0, 1]]) * 0.0254
    work = origin + file_points @ rotation.T
    assert program.splines == ((4, 2),)
    np.testing.assert_allclose(program.positions[0], origin, atol=1e-15)
    assert _check_moves(program, 4, [0.5, 1.0], work) == 2
    np.testing.assert_allclose(program.positions[2], work[-1], atol=1e-15)
    np.testing.assert_allclose(program.axes, [rotation[:, 2]] * len(program), atol=1e-15)
    assert np.isnan(program.beziers[[0, 3]]).all()  # the first point, the GOTO after


def test_a_triple_knot_is_a_corner_where_a_move_ends():
    text = "UNITS/MM\nGOTO/0,0,0\nNURBS/\nKNOT/0.5,0.5,0.5,1\n"
    text += "CNTRL/1,0,0\nCNTRL/2,0,0\nCNTRL/2,1,0\nCNTRL/2,2,0\nCNTRL/2,3,0\nCNTRL/2,4,0\n"
    program = parse_cldata(text)
    corner = np.array([2.0, 1.0, 0.0]) * 1e-3  # C(0.5) is the control point at the triple knot
    np.testing.assert_allclose(program.positions[1], corner, atol=1e-15)  # a move ends there
    assert program.splines == ((3, 2),)


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (
            "NURBS/\nKNOT/0.5,1\nCNTRL/1,0,0\nCNTRL/2,0,0\nCNTRL/3,0,0\nGOTO/5,0,0\n",
            r"^line 3: NURBS/: expected 4 CNTRL points for 2 knots .*, got 3$",
        ),
        ("NURBS/3\n", r"^line 3: NURBS/3: expected NURBS/ without values"),
        (
            "NURBS/\nKNOT/0.5\nCNTRL/1,0,0\nKNOT/1\n",
            r"^line 6: KNOT/1: expected the KNOT statements before the first CNTRL$",
        ),
        (
            "NURBS/\nKNOT/1\nCNTRL/1,0,0,1\n",
            r"^line 5: CNTRL/1,0,0,1: expected CNTRL/x,y,z \(3 numbers; weights and tool axes",
        ),
        (
            "NURBS/\nKNOT/0.6,0.5,1\n" + "CNTRL/1,0,0\n" * 5,
            r"^line 3: NURBS/: expected knots increasing in \(0, 1\], got 0.6, 0.5, 1$",
        ),
        (
            "NURBS/\nKNOT/0,0.5,1\n" + "CNTRL/1,0,0\n" * 5,
            r"^line 3: NURBS/: expected knots increasing in \(0, 1\]",
        ),
        (
            "NURBS/\nKNOT/0.5,0.9\n" + "CNTRL/1,0,0\n" * 4,
            r"^line 3: NURBS/: expected the last knot to be 1, got 0.9$",
        ),
        (
            "NURBS/\nKNOT/0.5,0.5,0.5,0.5,1\n" + "CNTRL/1,0,0\n" * 7,
            r"^line 3: NURBS/: a knot repeated more than three times breaks the curve",
        ),
        ("SET/MODE,INCR\nNURBS/\n", r"^line 4: NURBS/: a spline in incremental mode"),
        ("RAPID\nNURBS/\n", r"^line 4: NURBS/: a RAPID spline is not modelled"),
        ("KNOT/1\n", r"^line 3: KNOT/1: expected NURBS/ before it"),
        ("NURBS/\nGOTO/1,0,0\n", r"^line 3: NURBS/: expected KNOT/\.\.\. and CNTRL/x,y,z"),
        ("CIRCLE/0,0,0,0,0,1,1\nNURBS/\n", r"^line 4: NURBS/: expected the GOTO that ends"),
    ],
)
def test_records_that_do_not_fit_are_refused_with_their_line(body, message):
    with pytest.raises(InputError, match=message):
        parse_cldata("UNITS/MM\nGOTO/1,0,0\n" + body)


def test_a_spline_needs_a_point_of_its_part_before_it():
    with pytest.raises(InputError, match=r"^line 2: NURBS/: expected a point of this part"):
        parse_cldata("UNITS/MM\nNURBS/\nKNOT/1\n" + "CNTRL/1,0,0\n" * 3)
