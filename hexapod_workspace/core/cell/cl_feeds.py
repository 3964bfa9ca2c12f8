"""Write a CL file again with new feeds: every line kept, the ``FEDRAT`` statements ours.

``schedule FILE --write-cl OUT`` (:mod:`hexapod_workspace.cli.schedule`) gives each cutting
move the feed it can run at; this module puts those feeds into the file's own text:

* every line of the input is kept byte for byte (same line endings), except the ``FEDRAT``
  statements (all their lines), which are removed: the modal feed is always one written here;
* before each cutting (non-``RAPID``) motion statement whose feed differs from the modal feed
  written so far, one ``FEDRAT`` is inserted with the new value, 4 decimals, in the dialect of
  the file's first ``FEDRAT``: its order (``FEDRAT/250.0000,MMPM`` or NX CLSF's
  ``FEDRAT/MMPM,250.0000``) and unit word (``MMPM`` in mm, ``IPM`` in inches, by the units in
  force at that line; a file whose feeds have no unit word gets none, per minute in its
  units); a file without any ``FEDRAT`` gets ``FEDRAT/f,MMPM`` (or ``IPM``);
* a statement that makes several moves (a ``NURBS`` record: many Bézier moves) gets one
  ``FEDRAT``, the smallest of its moves'; an arc's goes before its ``CIRCLE`` (never between
  the ``CIRCLE`` and the ``GOTO`` that ends it); a statement continued with ``$`` is one
  statement;
* statements given no feed (``NaN``: ``RAPID`` moves, rotations without translation, the first
  point of each part) keep the file's programmed feed: ``RAPID`` gets nothing, the others the
  file's modal feed at that point again when ours differs.

New feeds are rounded down to 4 decimals (a feed given as a limit is never written above it);
kept ones to the nearest. Standard library and numpy only.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError
from .cl_statements import (
    _FEED_UNITS,
    CL_UNITS,
    _is_number,
    _number,
    _shown,
    _split,
    _statement_spans,
    _unit_of,
)
from .cldata import CLProgram

__all__ = ["FeedRewrite", "rewrite_feeds"]

#: Words of the statements that make waypoints.
_MOTIONS = ("GOTO", "FROM", "GODLTA", "GOHOME", "NURBS")
_NEWLINE = re.compile(r"\r\n|\r|\n")


@dataclass(frozen=True)
class FeedRewrite:
    """A CL file's text with new feeds.

    Attributes
    ----------
    text : str
        The new file's content.
    statements : int
        ``FEDRAT`` statements written.
    feeds : ndarray, shape (N,)
        Per waypoint of the program, the feed written for the move that ends there, m/s
        (after rounding; the smallest of its statement's moves); NaN where the move keeps the
        programmed feed.
    """

    text: str
    statements: int
    feeds: NDArray[np.float64]


@dataclass
class _Dialect:
    """How the file writes its feeds: the unit word first, and whether it has one."""

    unit_first: bool = False
    unit_word: bool = True

    def statement(self, value: str, unit: str) -> str:
        if not self.unit_word:
            return f"FEDRAT/{value}"
        word = "MMPM" if unit == "mm" else "IPM"
        return f"FEDRAT/{word},{value}" if self.unit_first else f"FEDRAT/{value},{word}"


def _programmed(arguments: list[str], unit: str, line: int, shown: str) -> float:
    """The feed of a ``FEDRAT`` the reader accepted, m/s."""
    value = next(_number(a, line, shown) for a in arguments if _is_number(a))
    words = [a.strip().upper() for a in arguments if not _is_number(a)]
    length = _FEED_UNITS.get(words[0], unit) if words else unit
    return value * CL_UNITS[length] / 60.0


def _in_unit(feed: float, unit: str, *, down: bool) -> str:
    """A feed (m/s) per minute in ``unit``, 4 decimals (rounded down, or to the nearest)."""
    value = feed * 60.0 / CL_UNITS[unit]
    if down:  # 1e-12: a value the file itself wrote is not rounded one step down
        value = math.floor(value * 1e4 * (1.0 + 1e-12)) / 1e4
    return f"{value:.4f}"


def rewrite_feeds(text: str, program: CLProgram, feeds: ArrayLike) -> FeedRewrite:
    """The text of a CL file with ``FEDRAT`` statements giving each move's feed (module
    documentation).

    Parameters
    ----------
    text : str
        The file's content, as :func:`~hexapod_workspace.core.cell.cldata.parse_cldata` read
        it into ``program``.
    program : CLProgram
        That file read.
    feeds : array_like, shape (N,)
        Per waypoint, the feed of the move that ends there, m/s (tool tip, > 0); NaN: keep the
        programmed feed.

    Returns
    -------
    FeedRewrite

    Raises
    ------
    InputError
        ``feeds`` of the wrong shape or not > 0.
    """
    wanted = np.asarray(feeds, dtype=np.float64)
    if wanted.shape != (len(program),) or np.any(wanted[np.isfinite(wanted)] <= 0.0):
        msg = f"feeds: expected {len(program)} values > 0 or NaN (m/s), got shape {wanted.shape}"
        raise InputError(msg)
    if np.any(np.isinf(wanted)):
        msg = "feeds: expected finite values or NaN (m/s)"
        raise InputError(msg)
    at_line: dict[int, list[int]] = {}
    for k, line in enumerate(program.lines.tolist()):
        at_line.setdefault(int(line), []).append(k)
    spans = _statement_spans(text)
    dialect = _Dialect()
    for line, _, statement in spans:
        word, arguments = _split(statement, line, _shown(statement))
        if word == "FEDRAT":
            dialect = _Dialect(not _is_number(arguments[0]), len(arguments) > 1)
            break
    unit = program.units
    removed: set[int] = set()
    inserted: dict[int, str] = {}
    written = np.full(len(program), np.nan)
    modal: float | None = None  # the file's own feed in force, m/s
    ours: tuple[str, str] | None = None  # the feed we last wrote: (value, unit)
    circle = 0  # line of a CIRCLE whose GOTO is next
    for first, last, statement in spans:
        shown = _shown(statement)
        word, arguments = _split(statement, first, shown)
        if word in ("UNITS", "UNIT"):
            unit = _unit_of(word, arguments, first, shown)
        elif word == "FEDRAT":
            modal = _programmed(arguments, unit, first, shown)
            removed.update(range(first, last + 1))
        elif word == "CIRCLE":
            circle = first
        elif word in _MOTIONS and first in at_line:
            moves = at_line[first]
            anchor = circle if word == "GOTO" and circle else first
            circle = 0
            if program.rapid[moves].any():
                continue
            given = wanted[moves]
            new = bool(np.isfinite(given).any())
            if not new and modal is None:
                continue
            feed = float(np.nanmin(given)) if new else float(modal)  # type: ignore[arg-type]
            value = (_in_unit(feed, unit, down=new), unit)
            if new:
                mine = np.array(moves)[np.isfinite(given)]
                written[mine] = float(value[0]) * CL_UNITS[unit] / 60.0
            if value != ours:
                inserted[anchor] = dialect.statement(*value)
                ours = value
    newline = _NEWLINE.search(text)
    end = newline.group(0) if newline else "\n"
    out: list[str] = []
    for number, raw in enumerate(text.splitlines(keepends=True), start=1):
        if number in inserted:
            out.append(inserted[number] + end)
        if number not in removed:
            out.append(raw)
    return FeedRewrite("".join(out), len(inserted), written)
