"""Read APT cutter-location files (CLDATA, what CAM systems export) into waypoints.

What is read
------------
=========================== =================================================================
statement                   meaning here
=========================== =================================================================
``GOTO/x,y,z``              a waypoint; the tool axis stays the last one given (the work
                            frame's z before any)
``GOTO/x,y,z,i,j,k``        a waypoint with its tool axis (any non-zero length, normalised)
``FEDRAT/f``                feed of the following cutting moves, per minute in the current
                            ``UNITS``
``FEDRAT/f,MMPM|IPM``       the same in mm/min or in/min; also ``FEDRAT/MMPM,f``
``RAPID``                   the next motion statement only is a rapid move (APT)
``UNITS/MM|INCHES``         unit of the following coordinates and unit-less feeds (default mm)
``MULTAX[/ON|OFF]``         recorded (5-axis output); GOTO takes 3 or 6 values either way
``LOADTL/n[,...]``          selects tool n of the tool table; between moves it splits the path
                            (the controller stops for the tool change)
=========================== =================================================================

Lines: ``$`` at the end of a line continues the statement on the next line; ``$$`` starts a
comment (a whole line or the end of one); upper or lower case; spaces anywhere between tokens.
Coordinates are in the work frame. Statements that do not change the geometry or the timing
(``PARTNO``, ``SPINDL``, ``COOLNT``, ``CUTTER``, ...) are listed once each in
:attr:`CLProgram.ignored` with their first line, never dropped silently. Statements that would
change the motion and are not modelled (``CIRCLE``, ``MOVARC``, per-revolution feeds) are refused
with their line number, like malformed ones.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

__all__ = ["CLProgram", "looks_like_cldata", "parse_cldata", "read_cldata"]

#: File name suffixes of CL files (``check-path`` also sniffs the content).
CL_SUFFIXES = (".cl", ".cls", ".apt", ".ncl", ".aptsource")
#: Metres per unit.
_LENGTH = {"MM": 1e-3, "INCHES": 0.0254, "INCH": 0.0254}
#: Feed units: metres per second per unit value.
_FEED = {"MMPM": 1e-3 / 60.0, "IPM": 0.0254 / 60.0}
#: Statements that change the motion in ways this reader does not model: refused.
_REFUSED = {
    "CIRCLE": "circular moves are not modelled (export arcs as linear GOTO moves)",
    "MOVARC": "circular moves are not modelled (export arcs as linear GOTO moves)",
    "CYCLE": "canned cycles are not modelled (export them as GOTO moves)",
}
_MOTION = {"GOTO"}


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
        1-based line of the ``GOTO`` of each waypoint.
    parts : tuple of (int, int)
        Waypoint ranges [start, stop) between tool changes (``LOADTL`` between moves).
    ignored : tuple of (str, int, int)
        Statements not used: (name, first line, count), in order of first appearance.
    multax : bool
        ``MULTAX`` (on) appeared.
    """

    positions: NDArray[np.float64]
    axes: NDArray[np.float64]
    feeds: NDArray[np.float64]
    rapid: NDArray[np.bool_]
    tools: NDArray[np.int64]
    lines: NDArray[np.int64]
    parts: tuple[tuple[int, int], ...]
    ignored: tuple[tuple[str, int, int], ...]
    multax: bool

    def __len__(self) -> int:
        return int(self.positions.shape[0])


def _statements(text: str) -> list[tuple[int, str]]:
    """Logical statements with the line they start on: comments removed, continuations joined."""
    statements: list[tuple[int, str]] = []
    pending: list[str] = []
    start = 0
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("$$", 1)[0].rstrip()
        if not pending:
            start = number
        if line.endswith("$"):
            pending.append(line[:-1])
            continue
        pending.append(line)
        statement = " ".join(part.strip() for part in pending).strip()
        pending = []
        if statement:
            statements.append((start, statement))
    if pending and " ".join(pending).strip():
        msg = f"line {start}: statement continued with '$' past the end of the file"
        raise InputError(msg)
    return statements


def _number(token: str, line: int, statement: str) -> float:
    try:
        value = float(token)
    except ValueError:
        msg = f"line {line}: {statement}: expected a number, got {token!r}"
        raise InputError(msg) from None
    if not math.isfinite(value):
        msg = f"line {line}: {statement}: expected a finite number, got {token!r}"
        raise InputError(msg)
    return value


def parse_cldata(text: str, tools: Collection[int] | None = None) -> CLProgram:
    """Read the text of a CL file (see the module documentation).

    Parameters
    ----------
    text : str
        The file's content.
    tools : collection of int, optional
        Tool numbers of the tool table; a ``LOADTL`` of another number is refused. None: any
        number is accepted (the caller resolves them).

    Returns
    -------
    CLProgram

    Raises
    ------
    InputError
        One line naming the file line, the statement, what was expected and what was given:
        a GOTO without 3 or 6 numbers, a zero tool axis, an unknown unit, a negative or zero
        feed, a ``LOADTL`` of a tool not in the table, ``CIRCLE``, no GOTO at all.
    """
    scale = _LENGTH["MM"]
    axis = np.array([0.0, 0.0, 1.0])
    feed = math.nan
    rapid_next = False
    tool = 0
    multax = False
    positions: list[NDArray[np.float64]] = []
    axes: list[NDArray[np.float64]] = []
    feeds: list[float] = []
    rapid: list[bool] = []
    tool_of: list[int] = []
    lines: list[int] = []
    part_starts = [0]
    ignored: dict[str, list[int]] = {}
    for line, statement in _statements(text):
        major, _, rest = statement.partition("/")
        word = major.strip().upper()
        arguments = [a.strip() for a in rest.split(",")] if rest.strip() else []
        shown = statement if len(statement) <= 60 else statement[:57] + "..."
        if word == "GOTO":
            if len(arguments) not in (3, 6):
                msg = (
                    f"line {line}: {shown}: expected 3 (x,y,z) or 6 (x,y,z,i,j,k) numbers, "
                    f"got {len(arguments)}"
                )
                raise InputError(msg)
            values = np.array([_number(a, line, shown) for a in arguments])
            if values.size == 6:
                norm = float(np.linalg.norm(values[3:]))
                if not norm > 1e-12:
                    msg = f"line {line}: {shown}: expected a non-zero tool axis (i,j,k)"
                    raise InputError(msg)
                axis = values[3:] / norm
            if np.max(np.abs(values[:3])) * scale > 1e6:
                msg = f"line {line}: {shown}: expected coordinates within 1e6 m"
                raise InputError(msg)
            positions.append(values[:3] * scale)
            axes.append(axis)
            first = len(positions) - 1 == part_starts[-1]
            feeds.append(math.nan if first else feed)
            rapid.append(rapid_next and not first)
            tool_of.append(tool)
            lines.append(line)
            rapid_next = False
        elif word == "RAPID":
            if arguments:
                msg = f"line {line}: {shown}: expected RAPID without arguments"
                raise InputError(msg)
            rapid_next = True
        elif word == "FEDRAT":
            feed = _feed(arguments, scale, line, shown)
        elif word == "UNITS":
            unit = arguments[0].upper() if len(arguments) == 1 else ""
            if unit not in _LENGTH:
                msg = f"line {line}: {shown}: expected UNITS/MM or UNITS/INCHES"
                raise InputError(msg)
            scale = _LENGTH[unit]
        elif word == "MULTAX":
            state = arguments[0].upper() if arguments else "ON"
            if len(arguments) > 1 or state not in ("ON", "OFF"):
                msg = f"line {line}: {shown}: expected MULTAX, MULTAX/ON or MULTAX/OFF"
                raise InputError(msg)
            multax = multax or state == "ON"
        elif word == "LOADTL":
            if not arguments:
                msg = f"line {line}: {shown}: expected LOADTL/n (a tool number)"
                raise InputError(msg)
            number = _number(arguments[0], line, shown)
            if number != int(number) or number < 1:
                msg = f"line {line}: {shown}: expected a tool number 1, 2, ..., got {arguments[0]}"
                raise InputError(msg)
            if tools is not None and int(number) not in tools:
                have = ", ".join(f"T{n}" for n in sorted(tools)) or "none"
                msg = (
                    f"line {line}: {shown}: tool {int(number)} is not in the tool table "
                    f"(tools.T<n>; defined: {have})"
                )
                raise InputError(msg)
            tool = int(number)
            if len(positions) > part_starts[-1]:
                part_starts.append(len(positions))
        elif word in _REFUSED:
            msg = f"line {line}: {shown}: {_REFUSED[word]}"
            raise InputError(msg)
        else:
            if not word or not word.replace("_", "").isalnum():
                msg = f"line {line}: expected an APT statement (WORD or WORD/...), got {shown!r}"
                raise InputError(msg)
            ignored.setdefault(word, []).append(line)
    if not positions:
        msg = "CL file: expected at least one GOTO statement, found none"
        raise InputError(msg)
    stops = [*part_starts[1:], len(positions)]
    return CLProgram(
        positions=np.array(positions, dtype=np.float64).reshape(-1, 3),
        axes=np.array(axes, dtype=np.float64).reshape(-1, 3),
        feeds=np.array(feeds, dtype=np.float64),
        rapid=np.array(rapid, dtype=np.bool_),
        tools=np.array(tool_of, dtype=np.int64),
        lines=np.array(lines, dtype=np.int64),
        parts=tuple(zip(part_starts, stops, strict=True)),
        ignored=tuple((name, where[0], len(where)) for name, where in ignored.items()),
        multax=multax,
    )


def _feed(arguments: list[str], scale: float, line: int, shown: str) -> float:
    """FEDRAT's feed in m/s: ``f``, ``f,UNIT`` or ``UNIT,f``; per minute in UNITS by default."""
    words = [a.upper() for a in arguments]
    units = [w for w in words if not _is_number(w)]
    numbers = [a for a in arguments if _is_number(a)]
    if len(numbers) != 1 or len(units) > 1 or len(arguments) > 2:
        msg = f"line {line}: {shown}: expected FEDRAT/f, FEDRAT/f,MMPM|IPM or FEDRAT/MMPM|IPM,f"
        raise InputError(msg)
    value = _number(numbers[0], line, shown)
    if units and units[0] in ("MMPR", "IPR"):
        msg = f"line {line}: {shown}: per-revolution feeds are not modelled (expected MMPM or IPM)"
        raise InputError(msg)
    if units and units[0] not in _FEED:
        msg = f"line {line}: {shown}: unknown feed unit {units[0]!r} (expected MMPM or IPM)"
        raise InputError(msg)
    if not value > 0.0:
        msg = f"line {line}: {shown}: expected a feed > 0, got {numbers[0]}"
        raise InputError(msg)
    per_unit = _FEED[units[0]] if units else scale / 60.0
    return value * per_unit


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def looks_like_cldata(text: str) -> bool:
    """Whether a file's text is APT CLDATA rather than CSV: some line starts with ``GOTO/``."""
    return any(
        line.split("$$", 1)[0].strip().upper().replace(" ", "").startswith("GOTO/")
        for line in text.splitlines()
    )


def read_cldata(path: str | Path, tools: Collection[int] | None = None) -> CLProgram:
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
        return parse_cldata(text, tools)
    except InputError as error:
        msg = f"CL file {path}: {error}"
        raise InputError(msg) from error
