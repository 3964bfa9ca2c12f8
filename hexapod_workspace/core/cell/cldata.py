"""Read APT cutter-location files (CLDATA, what CAM systems export) into waypoints.

The policy
----------
Every statement of a CL file is **modelled**, or **refused** with its line and why. Only the
fixed list :data:`PASSED_OVER` (statements that cannot change the motion, the frame, the tool
or the units: part names, comments, spindle, coolant, tool descriptions, display colours, ...)
is passed over, and :attr:`CLProgram.passed_over` counts them per statement (``check-path``
reports the counts). A statement not in these tables is refused as unknown, never passed
over: a reader that skips what it does not know checks a path other than the one the
controller will run.

What is modelled
----------------
=============================== ===============================================================
statement                       meaning here
=============================== ===============================================================
``GOTO/x,y,z``                  a waypoint; the tool axis stays the last one given (``TLAXIS``,
                                a 6-value ``GOTO``; the frame's z before any)
``GOTO/x,y,z,i,j,k``            a waypoint with its tool axis (any non-zero length, normalised)
``FROM/x,y,z[,i,j,k]``          the start point: the first waypoint of a part (refused after a
                                move of the same part) and the point ``GOHOME`` returns to
``GOHOME``                      a move to the ``FROM`` point (its axis if it gave one)
``GODLTA/dx,dy,dz``, ``/d``     a move by (dx, dy, dz), or by d along the tool axis
``CIRCLE/x,y,z,i,j,k,r[,...]``  the next ``GOTO`` (nothing but passed-over statements between)
                                ends an arc about centre (x, y, z) and axis (i, j, k) of
                                radius r, run clockwise about the axis (NX's extra values, a
                                tolerance and the tool's size, cannot change it): a move of its
                                own, checked along the arc (``CLProgram.arcs``); a helix when
                                the end's height along the axis differs; refused when an end
                                is off the circle, the tool axis changes, in incremental mode
``NURBS/``, ``KNOT/k,...``,      a spline move from the current point (NX): the clamped cubic
``CNTRL/x,y,z``                 B-spline of :mod:`~hexapod_workspace.core.cell.cl_splines`, one
                                Bézier move per span, checked along the curve
                                (``CLProgram.beziers``, ``CLProgram.splines``); the tool axis
                                stays; refused when the counts do not fit, in incremental mode,
                                after ``RAPID``, or with weights or tool axes in ``CNTRL``
``SET/MODE,INCR|ABSOL``         following ``GOTO`` positions are increments / absolute
``TLAXIS/i,j,k``                the tool axis of following 3-value ``GOTO`` statements
``FEDRAT/f[,MMPM|IPM|PERMIN]``  feed of the following cutting moves (also ``FEDRAT/MMPM,f``);
                                without a unit, per minute in the current units
``RAPID``                       the next motion statement only is a rapid move (APT)
``UNITS/MM|INCHES``             unit of the following coordinates and unit-less feeds; also
                                ``UNIT/``, ``INCH``, ``IN``, ``MILLIMETERS``, ``MILLIMETRES``
``MULTAX[/ON|OFF]``             recorded (5-axis output); GOTO takes 3 or 6 values either way
``LOADTL/n``, ``LOAD/TOOL,n``,  selects tool n of the tool table; between moves it splits the
``TOOLNO/n,...``                path (the controller stops for the tool change); CATIA's
                                ``TOOLNO`` is read as a tool change too (a ``LOADTL`` of the
                                same tool before any move changes nothing)
``TOOL PATH/...``,              part boundaries (NX CLSF operations): the path is split there
``END-OF-PATH``
``MSYS/x,y,z,a,b,c,d,e,f``      NX's machining coordinate system: origin (x, y, z) and X and Y
                                axes, given in the work frame; following coordinates and tool
                                axes are in it (``p_work = origin + [X Y X×Y]·p``)
``ORIGIN/x,y,z``                following coordinates are relative to the point (x, y, z)
``CYCLE/OFF``, ``CUTCOM/OFF``,  no cycle, compensation or transformation is ever active (the
``TRACUT/NOMORE``               other forms are refused), so these change nothing; counted
                                with the passed-over statements
=============================== ===============================================================

Units are never guessed. ``UNITS``/``UNIT`` statements say them; before the first one, a feed
with a unit (``FEDRAT/MMPM`` says mm, ``IPM`` says inches: NX CLSF writes no ``UNITS``
statement in either unit) or the caller's ``units`` (``check-path --cl-units``) does. A file
whose statements disagree (``UNITS/MM`` and ``FEDRAT/IPM``; a ``UNITS`` statement or a feed
against ``--cl-units``) is refused naming both. A file that states no units at all (no
``UNITS``, no feed with a unit) is refused at its first length unless ``units`` is given: APT
itself has no default unit, and an inch file read as mm is a path 25.4 times smaller that may
well pass.

Refused, with the line and why: ``MOVARC`` (a curve's chord is not the curve), canned cycles,
cutter compensation, ``TRACUT`` with a matrix, ``INSERT`` (text for the controller, whose effect is
unknown), per-revolution feeds (``MMPR``, ``IPR``, ``PERREV``), ``ORIGIN`` together with a rotated
``MSYS`` (the order they compose in is not stated), ``LOAD`` of anything but a tool, ``SET`` but
``MODE,INCR|ABSOL``, a ``GODLTA``/``GOHOME``/incremental ``GOTO`` without a known previous point, a
6-value ``GOTO`` in incremental mode, and every statement not listed here or in
:data:`PASSED_OVER`.

Lines: ``$`` at the end of a line continues the statement on the next line; ``$$`` starts a
comment (a whole line or the end of one); upper or lower case; spaces anywhere between tokens;
``WORD/args``, ``WORD,args`` (CATIA's ``CHANNEL,2``) or ``WORD`` alone. ``PPRINT``, ``PARTNO``,
``TPRINT`` and ``INSERT`` are literal text to the end of their line (with or without ``/``): a
``$`` there does not continue. Numbers may use Fortran exponents (``1.0D+01``).
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ...errors import InputError
from .cl_splines import NXSpline, bezier_spans, spline_knots
from .cl_statements import (
    _FEED_UNITS,
    _NAMES,
    _PER_REVOLUTION,
    _REFUSED,
    CL_SUFFIXES,
    CL_UNITS,
    PASSED_OVER,
    _initial_units,
    _is_number,
    _number,
    _numbers,
    _shown,
    _split,
    _statements,
    _unit_of,
)

__all__ = [
    "CL_SUFFIXES",
    "CL_UNITS",
    "PASSED_OVER",
    "CLProgram",
    "looks_like_cldata",
    "parse_cldata",
    "read_cldata",
]


@dataclass(frozen=True)
class CLProgram:
    """The waypoints of a CL file, in the work frame, SI units.

    Attributes
    ----------
    positions : ndarray, shape (N, 3)
        Tool-tip positions, work frame, m.
    axes : ndarray, shape (N, 3)
        Unit tool axes (approach vectors), work frame.
    feeds : ndarray, shape (N,)
        Programmed feed of the move that ends at waypoint k, m/s (NaN: none programmed yet,
        and for the first waypoint of each part).
    rapid : ndarray, shape (N,), bool
        The move that ends at waypoint k is a ``RAPID`` move.
    tools : ndarray, shape (N,), int
        Tool number active at waypoint k (0 before any ``LOADTL``).
    lines : ndarray, shape (N,), int
        1-based line of the statement of each waypoint (``GOTO``, ``FROM``, ``GODLTA``,
        ``GOHOME``).
    parts : tuple of (int, int)
        Waypoint ranges [start, stop) between tool changes and part boundaries (``LOADTL``
        between moves, ``TOOL PATH``, ``END-OF-PATH``).
    passed_over : tuple of (str, int, int)
        Statements of :data:`PASSED_OVER` met: (name, first line, count), in order of first
        appearance.
    multax : bool
        ``MULTAX`` (on) appeared.
    units : str
        ``mm`` or ``inch``: the units the file's coordinates start in.
    units_source : str
        What stated them (``line 3: UNITS/MM``, ``line 12: FEDRAT/IPM,20``, ``units='inch'``).
    frames : tuple of (int, ndarray, ndarray)
        Each ``MSYS`` and ``ORIGIN`` applied: (line, origin in the work frame (m), rotation
        from the file's coordinates to the work frame (3, 3)).
    beziers : ndarray, shape (N, 6)
        The move that ends at waypoint k as a cubic Bézier curve (a span of a ``NURBS``
        spline): its inner control points b₁, b₂ (work frame, m), as
        :func:`~hexapod_workspace.core.motions.checks.check_path` takes them; NaN for other
        moves and for the first waypoint of each part.
    splines : tuple of (int, int)
        Each ``NURBS`` spline: (line, number of Bézier moves). Its moves end at waypoints whose
        ``lines`` is the ``NURBS`` line.
    arcs : ndarray, shape (N, 7)
        The move that ends at waypoint k as an arc (``CIRCLE``): centre (work frame, m), unit
        axis (work frame) and angle φ (rad, right-handed about the axis: negative, the file's
        arcs run clockwise about their axis), as
        :func:`~hexapod_workspace.core.motions.checks.check_path` takes them; NaN for a straight
        move and for the first waypoint of each part.
    """

    positions: NDArray[np.float64]
    axes: NDArray[np.float64]
    feeds: NDArray[np.float64]
    rapid: NDArray[np.bool_]
    tools: NDArray[np.int64]
    lines: NDArray[np.int64]
    parts: tuple[tuple[int, int], ...]
    passed_over: tuple[tuple[str, int, int], ...]
    multax: bool
    units: str = "mm"
    units_source: str = ""
    frames: tuple[tuple[int, NDArray[np.float64], NDArray[np.float64]], ...] = field(default=())
    arcs: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 7)))
    beziers: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 6)))
    splines: tuple[tuple[int, int], ...] = ()

    def __len__(self) -> int:
        return int(self.positions.shape[0])

    @property
    def ignored(self) -> tuple[tuple[str, int, int], ...]:
        """The former name of :attr:`passed_over`."""
        return self.passed_over


class _Reader:
    """The state of the main pass."""

    def __init__(self, tools: Collection[int] | None, unit: str | None, source: str) -> None:
        self.tools = tools
        self.unit, self.unit_source = unit, source
        self.first_unit = unit
        self.option: str | None = None  # the caller's units (--cl-units)
        self.unit_said: tuple[int, str] | None = None  # the UNITS statement in force
        self.axis_given = False
        self.rotation: NDArray[np.float64] = np.eye(3)  # file coordinates -> work frame
        self.origin: NDArray[np.float64] = np.zeros(3)  # of the file frame in the work frame, m
        self.rotated_line = 0  # line of the MSYS that rotated the frame (0: none)
        self.shifted_line = 0  # line of a non-zero ORIGIN (0: none)
        self.msys_origin: NDArray[np.float64] = np.zeros(3)
        self.shift: NDArray[np.float64] = np.zeros(3)
        self.axis_file: NDArray[np.float64] = np.array(
            [0.0, 0.0, 1.0]
        )  # tool axis in file coordinates
        self.feed = math.nan
        self.rapid_next = False
        self.incremental = False
        self.tool = 0
        self.multax = False
        self.home: tuple[NDArray[np.float64], NDArray[np.float64] | None] | None = None
        self.positions: list[NDArray[np.float64]] = []
        self.axes: list[NDArray[np.float64]] = []
        self.feeds: list[float] = []
        self.rapid: list[bool] = []
        self.tool_of: list[int] = []
        self.lines: list[int] = []
        self.part_starts = [0]
        self.passed: dict[str, list[int]] = {}
        self.frames: list[tuple[int, NDArray[np.float64], NDArray[np.float64]]] = []
        # A CIRCLE waiting for the GOTO that ends it: (line, shown, centre and unit axis in file
        # coordinates (m), radius (m)); the arcs of the moves, one row per waypoint.
        self.circle: tuple[int, str, NDArray[np.float64], NDArray[np.float64], float] | None = None
        self.arcs: list[NDArray[np.float64]] = []
        # A NURBS record being read, each spline read, the Bézier moves, one row per waypoint.
        self.spline: NXSpline | None = None
        self.splines: list[tuple[int, int]] = []
        self.beziers: list[NDArray[np.float64]] = []

    # -- units -----------------------------------------------------------------------------
    def scale(self, line: int, shown: str) -> float:
        if self.unit is None:
            msg = (
                f"line {line}: {shown}: the file does not state its units (no UNITS statement "
                "before this line, no feed in MMPM or IPM); give them with --cl-units mm|inch "
                "(units= in the API)"
            )
            raise InputError(msg)
        return CL_UNITS[self.unit]

    # -- frames ----------------------------------------------------------------------------
    def _update_frame(self) -> None:
        self.origin = self.msys_origin + self.shift

    def to_work(self, point_file: NDArray[np.float64]) -> NDArray[np.float64]:
        result: NDArray[np.float64] = self.origin + self.rotation @ point_file
        return result

    def to_file(self, point_work: NDArray[np.float64]) -> NDArray[np.float64]:
        result: NDArray[np.float64] = self.rotation.T @ (point_work - self.origin)
        return result

    # -- waypoints -------------------------------------------------------------------------
    def in_part(self) -> bool:
        return len(self.positions) > self.part_starts[-1]

    def new_part(self) -> None:
        if self.in_part():
            self.part_starts.append(len(self.positions))

    def last(self, line: int, shown: str) -> NDArray[np.float64]:
        if not self.positions:
            msg = f"line {line}: {shown}: expected a previous point (a GOTO or FROM) before it"
            raise InputError(msg)
        return self.positions[-1]

    def add(
        self, position: NDArray[np.float64], axis: NDArray[np.float64], line: int, shown: str
    ) -> None:
        """A waypoint (work frame, m), with the feed, RAPID flag and tool in force."""
        if np.max(np.abs(position)) > 1e6:
            msg = f"line {line}: {shown}: expected coordinates within 1e6 m"
            raise InputError(msg)
        self.positions.append(position)
        self.axes.append(axis)
        self.arcs.append(np.full(7, np.nan))
        self.beziers.append(np.full(6, np.nan))
        first = len(self.positions) - 1 == self.part_starts[-1]
        self.feeds.append(math.nan if first else self.feed)
        self.rapid.append(self.rapid_next and not first)
        self.tool_of.append(self.tool)
        self.lines.append(line)
        self.rapid_next = False

    def axis_work(self) -> NDArray[np.float64]:
        result: NDArray[np.float64] = self.rotation @ self.axis_file
        return result


def _unit_axis(values: NDArray[np.float64], line: int, shown: str) -> NDArray[np.float64]:
    norm = float(np.linalg.norm(values))
    if not norm > 1e-12:
        msg = f"line {line}: {shown}: expected a non-zero tool axis (i,j,k)"
        raise InputError(msg)
    result: NDArray[np.float64] = values / norm
    return result


def parse_cldata(
    text: str, tools: Collection[int] | None = None, units: str | None = None
) -> CLProgram:
    """Read the text of a CL file (see the module documentation).

    Parameters
    ----------
    text : str
        The file's content.
    tools : collection of int, optional
        Tool numbers of the tool table; a ``LOADTL`` of another number is refused. None: any
        number is accepted (the caller resolves them).
    units : {'mm', 'inch'}, optional
        The units of a file that does not state them (``check-path --cl-units``); refused
        where the file states others before its first ``UNITS`` statement.

    Returns
    -------
    CLProgram

    Raises
    ------
    InputError
        One line naming the file line, the statement, what was expected and what was given:
        a malformed or refused statement (see the module documentation), units not stated or
        disagreeing, a ``LOADTL`` of a tool not in the table, no waypoint at all.
    """
    if units is not None and units not in CL_UNITS:
        msg = f"units: expected one of {', '.join(CL_UNITS)}, got {units!r}"
        raise InputError(msg)
    statements = _statements(text)
    unit, source = _initial_units(statements, units)
    state = _Reader(tools, unit, source)
    state.option = units
    for line, statement in statements:
        shown = _shown(statement)
        word, arguments = _split(statement, line, shown)
        _statement(state, word, arguments, line, shown)
    if state.spline is not None:
        _end_spline(state)
    if not state.positions:
        msg = "CL file: expected at least one GOTO (or FROM) statement, found none"
        raise InputError(msg)
    if state.part_starts[-1] == len(state.positions):  # a boundary after the last move
        state.part_starts.pop()
    if state.circle is not None:
        line, shown = state.circle[:2]
        msg = f"line {line}: {shown}: expected a GOTO after it (the arc's end), found none"
        raise InputError(msg)
    stops = [*state.part_starts[1:], len(state.positions)]
    return CLProgram(
        positions=np.array(state.positions, dtype=np.float64).reshape(-1, 3),
        axes=np.array(state.axes, dtype=np.float64).reshape(-1, 3),
        feeds=np.array(state.feeds, dtype=np.float64),
        rapid=np.array(state.rapid, dtype=np.bool_),
        tools=np.array(state.tool_of, dtype=np.int64),
        lines=np.array(state.lines, dtype=np.int64),
        parts=tuple(zip(state.part_starts, stops, strict=True)),
        passed_over=tuple((name, where[0], len(where)) for name, where in state.passed.items()),
        multax=state.multax,
        units=state.first_unit or "mm",
        units_source=state.unit_source,
        frames=tuple(state.frames),
        arcs=np.array(state.arcs, dtype=np.float64).reshape(-1, 7),
        beziers=np.array(state.beziers, dtype=np.float64).reshape(-1, 6),
        splines=tuple(state.splines),
    )


def _statement(state: _Reader, word: str, arguments: list[str], line: int, shown: str) -> None:
    """Apply one statement to the reader's state (or refuse it)."""
    if state.spline is not None:
        if word in ("KNOT", "CNTRL"):
            _spline_data(state, word, arguments, line, shown)
            return
        _end_spline(state)  # any other statement ends the record
    if state.circle is not None and word != "GOTO" and word not in PASSED_OVER:
        msg = (
            f"line {line}: {shown}: expected the GOTO that ends the arc of line "
            f"{state.circle[0]} ({state.circle[1]}) first"
        )
        raise InputError(msg)
    if word == "CIRCLE":
        _circle(state, arguments, line, shown)
    elif word == "NURBS":
        _start_spline(state, arguments, line, shown)
    elif word in ("KNOT", "CNTRL"):
        msg = f"line {line}: {shown}: expected NURBS/ before it (spline data outside a spline)"
        raise InputError(msg)
    elif word == "GOTO" and state.circle is not None:
        _end_arc(state, arguments, line, shown)
    elif word == "GOTO":
        values = _numbers(arguments, (3, 6), line, shown, "3 (x,y,z) or 6 (x,y,z,i,j,k) numbers")
        if values.size == 6:
            if state.incremental:
                msg = (
                    f"line {line}: {shown}: a tool axis in incremental mode (SET/MODE,INCR) "
                    "is not modelled (whether i,j,k are increments is not standard)"
                )
                raise InputError(msg)
            state.axis_file = _unit_axis(values[3:], line, shown)
            state.axis_given = True
        point = values[:3] * state.scale(line, shown)
        if state.incremental:
            point = state.to_file(state.last(line, shown)) + point
        state.add(state.to_work(point), state.axis_work(), line, shown)
    elif word == "FROM":
        values = _numbers(arguments, (3, 6), line, shown, "3 (x,y,z) or 6 (x,y,z,i,j,k) numbers")
        if state.in_part():
            msg = (
                f"line {line}: {shown}: FROM after a move of the same part (expected it first: "
                "how the tool gets there is not stated)"
            )
            raise InputError(msg)
        given = None
        if values.size == 6:
            state.axis_file = _unit_axis(values[3:], line, shown)
            state.axis_given = True
            given = state.axis_work()
        position = state.to_work(values[:3] * state.scale(line, shown))
        state.home = (position, given)
        rapid = state.rapid_next
        state.add(position, state.axis_work(), line, shown)
        state.rapid_next = rapid  # FROM is not a motion: a RAPID before it is for the next one
    elif word == "GOHOME":
        if arguments:
            msg = f"line {line}: {shown}: expected GOHOME without arguments"
            raise InputError(msg)
        if state.home is None:
            msg = f"line {line}: {shown}: GOHOME without a FROM point before it"
            raise InputError(msg)
        position, given = state.home
        if given is not None:
            state.axis_file = state.rotation.T @ given
        state.add(position.copy(), state.axis_work(), line, shown)
    elif word == "GODLTA":
        values = _numbers(arguments, (1, 3), line, shown, "1 (d along the tool axis) or 3 numbers")
        last = state.last(line, shown)
        scale = state.scale(line, shown)
        if values.size == 1:
            position = last + values[0] * scale * state.axis_work()
        else:
            position = last + state.rotation @ (values * scale)
        state.add(position, state.axis_work(), line, shown)
    elif word == "TLAXIS":
        values = _numbers(arguments, (3,), line, shown, "TLAXIS/i,j,k (3 numbers)")
        state.axis_file = _unit_axis(values, line, shown)
        state.axis_given = True
    elif word == "SET":
        mode = [a.upper() for a in arguments]
        if mode not in (["MODE", "INCR"], ["MODE", "ABSOL"]):
            msg = f"line {line}: {shown}: expected SET/MODE,INCR or SET/MODE,ABSOL (other SET "
            msg += "statements are not modelled)"
            raise InputError(msg)
        state.incremental = mode[1] == "INCR"
    elif word == "RAPID":
        if arguments:
            msg = f"line {line}: {shown}: expected RAPID without arguments"
            raise InputError(msg)
        state.rapid_next = True
    elif word == "FEDRAT":
        state.feed = _feed(state, arguments, line, shown)
    elif word in ("UNITS", "UNIT"):
        state.unit = _unit_of(word, arguments, line, shown)
        if state.option is not None and state.unit != state.option:
            msg = (
                f"line {line}: {shown}: the file says {_NAMES[state.unit]}, but the units "
                f"given for the file (--cl-units) are {state.option}"
            )
            raise InputError(msg)
        if state.first_unit is None:
            state.first_unit, state.unit_source = state.unit, f"line {line}: {shown}"
        state.unit_said = (line, shown)
    elif word == "MULTAX":
        flag = arguments[0].upper() if arguments else "ON"
        if len(arguments) > 1 or flag not in ("ON", "OFF"):
            msg = f"line {line}: {shown}: expected MULTAX, MULTAX/ON or MULTAX/OFF"
            raise InputError(msg)
        state.multax = state.multax or flag == "ON"
    elif word in ("LOADTL", "TOOLNO") or (
        word == "LOAD" and arguments[:1] and arguments[0].upper() == "TOOL"
    ):
        numbers = arguments if word != "LOAD" else arguments[1:]
        _load_tool(state, numbers, line, shown)
    elif word == "LOAD":
        msg = f"line {line}: {shown}: expected LOAD/TOOL,n (other LOAD statements are not modelled)"
        raise InputError(msg)
    elif word in ("TOOL PATH", "END-OF-PATH"):
        state.new_part()
        state.home = None
    elif word == "MSYS":
        _msys(state, arguments, line, shown)
    elif word == "ORIGIN":
        values = _numbers(arguments, (3,), line, shown, "ORIGIN/x,y,z (3 numbers)")
        if state.rotated_line and np.any(values != 0.0):
            msg = (
                f"line {line}: {shown}: ORIGIN with the rotated MSYS of line "
                f"{state.rotated_line} in force: the order they compose in is not stated"
            )
            raise InputError(msg)
        state.shift = values * state.scale(line, shown)
        state.shifted_line = line if np.any(values != 0.0) else 0
        state._update_frame()
        state.frames.append((line, state.origin.copy(), state.rotation.copy()))
    elif word in ("CYCLE", "CUTCOM", "TRACUT", "SELECT"):
        form = f"{word}/{arguments[0].upper()}" if len(arguments) >= 1 else word
        allowed = form in PASSED_OVER and (len(arguments) == 1 or form == "SELECT/TOOL")
        if not allowed:
            reason = _REFUSED.get(word, "expected SELECT/TOOL,n (other SELECT forms are unknown)")
            msg = f"line {line}: {shown}: {reason}"
            raise InputError(msg)
        state.passed.setdefault(form, []).append(line)
    elif word in _REFUSED:
        msg = f"line {line}: {shown}: {_REFUSED[word]}"
        raise InputError(msg)
    elif word in PASSED_OVER:
        state.passed.setdefault(word, []).append(line)
    else:
        msg = (
            f"line {line}: {shown}: unknown statement {word}: not modelled, so refused (only "
            "statements that cannot change the motion, frame, tool or units are passed over)"
        )
        raise InputError(msg)


#: An arc's ends may be off its circle by the file's rounding: this much of the radius, plus
#: 2 µm (four decimals of an inch file round a coordinate by 1.3 µm).
_ARC_RELATIVE, _ARC_ABSOLUTE = 1e-5, 2e-6


def _curve_start(state: _Reader, line: int, shown: str, statement: str, curve: str) -> None:
    """A curve (arc, spline) starts at the current point of its part, in absolute mode."""
    if state.incremental:
        msg = f"line {line}: {shown}: a {statement} in incremental mode (SET/MODE,INCR) is not "
        msg += "modelled"
        raise InputError(msg)
    if not state.in_part():
        msg = f"line {line}: {shown}: expected a point of this part before the {curve}"
        raise InputError(msg)


def _circle(state: _Reader, arguments: list[str], line: int, shown: str) -> None:
    """``CIRCLE/xc,yc,zc,i,j,k,r[,...]``: the arc that the next GOTO ends (NX adds a
    tolerance, the tool diameter and two more values, which cannot change the arc)."""
    values = [_number(a, line, shown) for a in arguments]
    if len(values) < 7:
        msg = f"line {line}: {shown}: expected CIRCLE/x,y,z,i,j,k,r (at least 7 numbers)"
        raise InputError(msg)
    _curve_start(state, line, shown, "CIRCLE", "arc")
    scale = state.scale(line, shown)
    radius = values[6] * scale
    if not radius > 0.0:
        msg = f"line {line}: {shown}: expected a radius > 0, got {values[6]:g}"
        raise InputError(msg)
    axis = _unit_axis(np.array(values[3:6]), line, shown)
    state.circle = (line, shown, np.array(values[:3]) * scale, axis, radius)


def _end_arc(state: _Reader, arguments: list[str], line: int, shown: str) -> None:
    """The GOTO that ends a CIRCLE: the waypoint, and the move to it as an arc.

    The tool runs **clockwise about the circle's axis** (seen from the axis's tip): the reading
    of the NX CLSF sample (test/data/cl/SOURCES.md) under which no arc reverses the tool where it
    meets the moves beside it and most meet them tangentially (read the other way, ten joints
    reverse it); its arcs are all under 180°, so it does not tell this reading from "the short
    way round", and no document stating the convention was found. φ is the clockwise angle from the
    start to the end (a full circle when they coincide), negative (right-handed about the axis).
    The ends must lie on the circle (within the rounding of :data:`_ARC_RELATIVE` and
    :data:`_ARC_ABSOLUTE`); a change of height along the axis makes a helix.
    """
    assert state.circle is not None
    circle_line, _, centre, axis, radius = state.circle
    values = _numbers(arguments, (3, 6), line, shown, "3 (x,y,z) or 6 (x,y,z,i,j,k) numbers")
    if values.size == 6:
        given = _unit_axis(values[3:], line, shown)
        if float(np.linalg.norm(given - state.axis_file)) > 1e-9:
            msg = (
                f"line {line}: {shown}: the tool axis changes along the arc of line "
                f"{circle_line}: not modelled (expected the tool axis of the arc's start)"
            )
            raise InputError(msg)
    start = state.to_file(state.last(line, shown))
    end = values[:3] * state.scale(line, shown)
    planar = []
    for name, point in (("start", start), ("end", end)):
        offset = point - centre
        inplane = offset - float(offset @ axis) * axis
        distance = float(np.linalg.norm(inplane))
        if abs(distance - radius) > _ARC_RELATIVE * radius + _ARC_ABSOLUTE:
            msg = (
                f"line {line}: {shown}: the arc's {name} is {distance * 1e3:.6g} mm from the "
                f"axis of the CIRCLE of line {circle_line}, whose radius is "
                f"{radius * 1e3:.6g} mm"
            )
            raise InputError(msg)
        planar.append(inplane)
    right_handed = math.atan2(
        float(np.cross(planar[0], planar[1]) @ axis), float(planar[0] @ planar[1])
    )
    if abs(right_handed) < 1e-9:
        phi = -2.0 * math.pi  # the end is the start: a full circle
    elif right_handed > 0.0:
        phi = right_handed - 2.0 * math.pi
    else:
        phi = right_handed
    state.add(state.to_work(end), state.axis_work(), line, shown)
    state.arcs[-1] = np.array([*state.to_work(centre), *(state.rotation @ axis), phi])
    state.circle = None


def _start_spline(state: _Reader, arguments: list[str], line: int, shown: str) -> None:
    """``NURBS/``: a spline from the current point; its KNOT and CNTRL statements follow."""
    if arguments:
        msg = f"line {line}: {shown}: expected NURBS/ without values (NX's form), got "
        msg += f"{len(arguments)}"
        raise InputError(msg)
    if state.rapid_next:
        msg = f"line {line}: {shown}: a RAPID spline is not modelled (expected a GOTO after RAPID)"
        raise InputError(msg)
    _curve_start(state, line, shown, "spline", "spline")
    start = state.to_file(state.last(line, shown))
    state.spline = NXSpline(line, shown, start, [], [])


def _spline_data(state: _Reader, word: str, arguments: list[str], line: int, shown: str) -> None:
    """A ``KNOT`` (all before the first ``CNTRL``) or ``CNTRL`` statement of the record."""
    spline = state.spline
    assert spline is not None
    if word == "KNOT":
        if spline.controls:
            msg = f"line {line}: {shown}: expected the KNOT statements before the first CNTRL"
            raise InputError(msg)
        if not arguments:
            msg = f"line {line}: {shown}: expected KNOT/k,... (at least one number)"
            raise InputError(msg)
        spline.knots.extend(_number(a, line, shown) for a in arguments)
        return
    what = "CNTRL/x,y,z (3 numbers; weights and tool axes along a spline are not modelled)"
    values = _numbers(arguments, (3,), line, shown, what)
    spline.controls.append(values * state.scale(line, shown))


def _end_spline(state: _Reader) -> None:
    """The Bézier moves of the record just read (work frame), each ending at a waypoint of the
    NURBS line."""
    spline = state.spline
    assert spline is not None
    state.spline = None
    knots = spline_knots(spline)
    # a B-spline of affinely mapped control points is the mapped curve
    work = np.array([state.to_work(point) for point in [spline.start, *spline.controls]])
    spans = bezier_spans(knots, work)
    for span in spans:
        state.add(span[3], state.axis_work(), spline.line, spline.shown)
        state.beziers[-1] = span[1:3].reshape(6)
    state.splines.append((spline.line, int(spans.shape[0])))


def _load_tool(state: _Reader, arguments: list[str], line: int, shown: str) -> None:
    if not arguments:
        msg = f"line {line}: {shown}: expected LOADTL/n or LOAD/TOOL,n (a tool number)"
        raise InputError(msg)
    number = _number(arguments[0], line, shown)
    if number != int(number) or number < 1:
        msg = f"line {line}: {shown}: expected a tool number 1, 2, ..., got {arguments[0]}"
        raise InputError(msg)
    if state.tools is not None and int(number) not in state.tools:
        have = ", ".join(f"T{n}" for n in sorted(state.tools)) or "none"
        msg = (
            f"line {line}: {shown}: tool {int(number)} is not in the tool table "
            f"(tools.T<n>; defined: {have})"
        )
        raise InputError(msg)
    state.tool = int(number)
    state.new_part()


def _msys(state: _Reader, arguments: list[str], line: int, shown: str) -> None:
    """MSYS/x,y,z,xi,xj,xk,yi,yj,yk: the machining coordinate system in the work frame."""
    values = _numbers(arguments, (9,), line, shown, "MSYS/x,y,z,xi,xj,xk,yi,yj,yk (9 numbers)")
    x_axis, y_axis = values[3:6], values[6:9]
    if (
        abs(np.linalg.norm(x_axis) - 1.0) > 1e-5
        or abs(np.linalg.norm(y_axis) - 1.0) > 1e-5
        or abs(float(x_axis @ y_axis)) > 1e-5
    ):
        msg = f"line {line}: {shown}: expected unit, orthogonal X and Y axes (within 1e-5)"
        raise InputError(msg)
    x_axis = x_axis / np.linalg.norm(x_axis)
    y_axis = y_axis - (y_axis @ x_axis) * x_axis
    y_axis = y_axis / np.linalg.norm(y_axis)
    rotation = np.column_stack([x_axis, y_axis, np.cross(x_axis, y_axis)])
    rotated = not np.allclose(rotation, np.eye(3), atol=1e-12)
    if rotated and state.shifted_line:
        msg = (
            f"line {line}: {shown}: a rotated MSYS with the ORIGIN of line "
            f"{state.shifted_line} in force: the order they compose in is not stated"
        )
        raise InputError(msg)
    # a tool axis given before stays the same direction in the work frame until a new one is
    # given; before any, the axis is the new frame's z
    axis = state.axis_work()
    state.rotation = rotation
    if state.axis_given:
        state.axis_file = rotation.T @ axis
    state.msys_origin = values[:3] * state.scale(line, shown)
    state.rotated_line = line if rotated else 0
    state._update_frame()
    state.frames.append((line, state.origin.copy(), rotation))


def _feed(state: _Reader, arguments: list[str], line: int, shown: str) -> float:
    """FEDRAT's feed in m/s: ``f``, ``f,UNIT`` or ``UNIT,f``; per minute in the units by
    default; a unit that contradicts the units in force refused."""
    words = [a.upper() for a in arguments]
    units = [w for w in words if not _is_number(w)]
    numbers = [a for a in arguments if _is_number(a)]
    if any(u in _PER_REVOLUTION for u in units):
        msg = f"line {line}: {shown}: per-revolution feeds are not modelled (expected MMPM or IPM)"
        raise InputError(msg)
    if len(numbers) != 1 or len(units) > 1 or len(arguments) > 2:
        msg = f"line {line}: {shown}: expected FEDRAT/f, FEDRAT/f,MMPM|IPM or FEDRAT/MMPM|IPM,f"
        raise InputError(msg)
    value = _number(numbers[0], line, shown)
    unit = units[0] if units else "PERMIN"
    if unit not in _FEED_UNITS and unit != "PERMIN":
        msg = f"line {line}: {shown}: unknown feed unit {unit!r} (expected MMPM or IPM)"
        raise InputError(msg)
    if not value > 0.0:
        msg = f"line {line}: {shown}: expected a feed > 0, got {numbers[0]}"
        raise InputError(msg)
    if unit == "PERMIN":
        return value * state.scale(line, shown) / 60.0
    length = _FEED_UNITS[unit]
    if state.unit is not None and state.unit != length:
        said = state.unit_said
        where = f"line {said[0]} ({said[1]})" if said else state.unit_source
        msg = (
            f"line {line}: {shown}: a feed in {_NAMES[length]}, but {where} says "
            f"{_NAMES[state.unit]}; the file's units disagree"
        )
        raise InputError(msg)
    if state.unit is None:  # cannot happen: the first such feed set the initial units
        state.unit, state.unit_source = length, f"line {line}: {shown}"
    return value * CL_UNITS[length] / 60.0


def looks_like_cldata(text: str) -> bool:
    """Whether a file's text is APT CLDATA rather than CSV: some line starts with ``GOTO``
    followed by ``/`` (spaces allowed between)."""
    return any(
        line.split("$$", 1)[0].strip().upper().replace(" ", "").startswith("GOTO/")
        for line in text.splitlines()
    )


def read_cldata(
    path: str | Path, tools: Collection[int] | None = None, units: str | None = None
) -> CLProgram:
    """Read a CL file from disk (see :func:`parse_cldata`).

    Raises
    ------
    InputError
        Unreadable or non-text file (``CL file PATH: ...``), or what :func:`parse_cldata`
        refuses, prefixed with the file name.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        msg = f"cannot read CL file {path}: {error.strerror or error}"
        raise InputError(msg) from error
    except UnicodeDecodeError as error:
        msg = f"CL file {path} is not text"
        raise InputError(msg) from error
    try:
        return parse_cldata(text, tools, units)
    except InputError as error:
        msg = f"CL file {path}: {error}"
        raise InputError(msg) from error
