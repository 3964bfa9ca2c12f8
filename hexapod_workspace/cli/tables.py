"""The CSV files the CLI reads (``check --poses-file``, ``check-path``): one reader, one set of
header rules, errors that name the file's line.

Rules (docs/cli.md, "CSV files"):

* cells are separated by semicolons, commas, tabs or spaces (the first of ``;``, ``,``, tab
  found on a line; else spaces); blank lines and lines starting with ``#`` are skipped;
* a first line whose cells are all names is a **header**, and columns are then read **by
  name**, in any order: an angle column names its unit (``phi_deg`` or ``phi_rad``), a length
  column may (``x``, ``x_m``, ``x_mm``); a name the file kind does not know, a unit it does not
  take, an angle without a unit or a quantity given twice is refused with the header's line;
* every data line must have one number per column: a short or long line, a cell that is not a
  number, NaN or an infinity is refused with the line number of the file (comments, blank lines
  and the header count) and the line as written.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..core.base.rotations import ANGLE_CONVENTIONS
from ..errors import InputError

__all__ = [
    "ANGLE_UNITS",
    "LENGTH_UNITS",
    "ORIENTATION_QUANTITIES",
    "PLAIN",
    "Columns",
    "Table",
    "conventions_text",
    "orientation_columns",
    "orientation_header",
    "parse_table",
    "split",
]

#: Units an angle column may name, with the factor to degrees.
ANGLE_UNITS: Mapping[str, float] = {"deg": 1.0, "rad": 180.0 / math.pi}
#: Units a length column may name ("" = no suffix = metres), with the factor to metres.
LENGTH_UNITS: Mapping[str, float] = {"": 1.0, "m": 1.0, "mm": 1e-3}
#: A unitless column (components of a direction).
PLAIN: Mapping[str, float] = {"": 1.0}
#: The orientation columns of every convention (:data:`ANGLE_CONVENTIONS`): angles in degrees or
#: radians (``u_deg``, ``u_rad``), quaternion components unitless (``qx``).
ORIENTATION_QUANTITIES: Mapping[str, Mapping[str, float]] = {
    name: ANGLE_UNITS if convention.angular else PLAIN
    for convention in ANGLE_CONVENTIONS.values()
    for name in convention.components
}


def orientation_header(convention: str) -> list[str]:
    """The orientation columns of ``convention`` as a header spells them (``u_deg, ...``)."""
    found = ANGLE_CONVENTIONS[convention]
    return [f"{n}_deg" if found.angular else n for n in found.components]


def conventions_text() -> str:
    """The orientation columns a file may name, for messages (T&T first, spelled in full)."""
    tt = ", ".join(f"{n}_deg or {n}_rad" for n in ANGLE_CONVENTIONS["tt"].components)
    others = [
        f"{','.join(orientation_header(name))} ({name})"
        for name, c in ANGLE_CONVENTIONS.items()
        if name != "tt" and c.angular
    ]
    quaternions = [
        f"{','.join(orientation_header(name))} ({name})"
        for name, c in ANGLE_CONVENTIONS.items()
        if not c.angular
    ]
    return f"{tt}; or {', '.join(others)}, each also _rad; or {', '.join(quaternions)}"


def split(line: str) -> list[str]:
    """Cells of a CSV line: semicolon-, comma-, tab- or space-separated (in that preference, so
    that ``1,5;2;3`` is read as a decimal comma, and refused with a hint)."""
    for separator in (";", ",", "\t"):
        if separator in line:
            return [cell.strip() for cell in line.split(separator)]
    return line.split()


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


@dataclass(frozen=True)
class Table:
    """The numbers of a CSV file and where each row came from.

    Attributes
    ----------
    where : str
        ``"poses file F"``: how errors name the file.
    header : list of str or None
        The header's cells as written, or None when the file has none.
    header_line : int
        File line (1-based) of the header; 0 without one.
    values : ndarray, shape (N, C)
        One row per data line, finite.
    lines : list of int
        File line (1-based) of each row.
    """

    where: str
    header: list[str] | None
    header_line: int
    values: NDArray[np.float64]
    lines: list[int]


def parse_table(
    text: str, where: str, default_columns: list[str] | None, *, rows_name: str = "rows"
) -> Table:
    """Read the rows of a CSV text (see the module documentation).

    Parameters
    ----------
    text : str
        The file's content.
    where : str
        ``"poses file F"``: the start of every error message.
    default_columns : list of str or None
        The columns of a file without a header (read by position), or None when a header is
        required.
    rows_name : str
        What a row is (``"poses"``, ``"waypoints"``), for the message of a file without any.

    Raises
    ------
    InputError
        No header where one is required, no data, a line with the wrong number of cells, a
        cell that is not a number, NaN or infinite values.
    """
    header: list[str] | None = None
    header_line = 0
    lines: list[int] = []
    rows: list[list[str]] = []
    source = text.splitlines()
    for number, line in enumerate(source, start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = split(stripped)
        if header is None and not lines and not any(_is_number(c) for c in cells if c):
            header, header_line = cells, number
            continue
        if header is None and default_columns is None:
            msg = f"{where}, line {number}: expected a header (column names) as the first row"
            raise InputError(msg)
        lines.append(number)
        rows.append(cells)
    columns = header if header is not None else default_columns or []
    if not rows:
        msg = f"{where}: no {rows_name} (expected lines {','.join(columns)})"
        raise InputError(msg)
    for number, cells in zip(lines, rows, strict=True):
        if len(cells) != len(columns):
            msg = (
                f"{where}, line {number}: expected {len(columns)} values {','.join(columns)}, "
                f"got {len(cells)}: {source[number - 1].strip()!r}"
            )
            raise InputError(msg)
        bad = next((c for c in cells if not _is_number(c)), None)
        if bad is not None:
            hint = " (use a decimal point)" if re.fullmatch(r"-?\d+,\d+", bad) else ""
            msg = f"{where}, line {number}: {bad!r} is not a number{hint}"
            raise InputError(msg)
    values = np.array(rows, dtype=np.float64).reshape(len(rows), len(columns))
    bad_rows = np.flatnonzero(~np.all(np.isfinite(values), axis=1))
    if bad_rows.size:
        number = lines[int(bad_rows[0])]
        msg = f"{where}, line {number}: expected finite numbers, got {source[number - 1].strip()!r}"
        raise InputError(msg)
    return Table(where, header, header_line, values, lines)


class Columns:
    """The quantities a kind of file takes and the units each may name.

    Parameters
    ----------
    quantities : mapping
        ``{"phi": ANGLE_UNITS, "x": LENGTH_UNITS, "i": PLAIN}``: quantity name to its units
        (unit suffix to the factor to the quantity's reading unit: degrees, metres).
    """

    def __init__(
        self, quantities: Mapping[str, Mapping[str, float]], expected: str | None = None
    ) -> None:
        self.quantities = dict(quantities)
        self._expected = expected

    def _spelled(self, quantity: str) -> str:
        units = self.quantities[quantity]
        return " or ".join(f"{quantity}_{u}" if u else quantity for u in units)

    def expected(self) -> str:
        if self._expected is not None:
            return self._expected
        return ", ".join(self._spelled(q) for q in self.quantities)

    def read(self, table: Table) -> dict[str, NDArray[np.float64]]:
        """The header's columns by quantity, converted to degrees or metres.

        Returns
        -------
        dict
            Quantity name to its column, shape (N,); only the quantities the header names.

        Raises
        ------
        InputError
            An unknown name, a unit not taken, an angle without its unit, a quantity twice;
            the message names the header's line.
        """
        if table.header is None:
            msg = f"{table.where}: read by position (no header), not by name"
            raise ValueError(msg)
        where = f"{table.where}, line {table.header_line}"
        found: dict[str, tuple[int, float, str]] = {}
        for index, cell in enumerate(table.header):
            name = cell.strip().lower()
            quantity, _, unit = name.rpartition("_") if "_" in name else (name, "", "")
            if name in self.quantities:
                quantity, unit = name, ""
            if quantity not in self.quantities:
                msg = f"{where}: unknown column {cell!r} (expected {self.expected()})"
                raise InputError(msg)
            units = self.quantities[quantity]
            if unit not in units:
                given = "names no unit" if not unit else f"has unit {unit!r}, not taken here"
                msg = f"{where}: column {cell!r} {given} (expected {self._spelled(quantity)})"
                raise InputError(msg)
            if quantity in found:
                msg = (
                    f"{where}: {quantity} given twice (columns {found[quantity][2]!r} and {cell!r})"
                )
                raise InputError(msg)
            found[quantity] = (index, units[unit], cell)
        return {q: table.values[:, i] * factor for q, (i, factor, _) in found.items()}


def orientation_columns(
    table: Table,
    columns: Mapping[str, NDArray[np.float64]],
    angles: str | None,
    flag: str = "--angles",
    *,
    incomplete: str | None = None,
) -> tuple[str, NDArray[np.float64]] | None:
    """The orientation a header names: its convention and its columns, in the convention's order.

    A file's convention must be unambiguous: the columns of two conventions (``phi_deg`` beside
    ``u_deg``), an incomplete set, or a convention other than the one ``--angles`` names are
    refused in one line naming the columns.

    Parameters
    ----------
    table : Table
        The file (for its name and header line).
    columns : mapping
        :meth:`Columns.read` of the file: quantity name to its column, degrees or unitless.
    angles : str or None
        The convention ``--angles`` gave, or None when the flag was not given.
    flag : str
        How the flag is named in messages.
    incomplete : str, optional
        The message of an incomplete convention (default: the first missing column named).

    Returns
    -------
    tuple (str, ndarray of shape (N, k)) or None
        The convention and its columns (degrees, or the quaternion's components); None when the
        header names no orientation column.

    Raises
    ------
    InputError
        Two conventions' columns, an incomplete convention, or one that ``--angles`` does not
        name.
    """
    where = f"{table.where}, line {table.header_line}"
    named = {
        name: [c for c in convention.components if c in columns]
        for name, convention in ANGLE_CONVENTIONS.items()
    }
    present = [name for name, found in named.items() if found]
    if not present:
        return None
    header = {q: cell for q, cell in zip(_quantities(table), table.header or [], strict=True)}
    if len(present) > 1:
        shown = "; ".join(
            f"{','.join(header[c] for c in named[name])} ({name})" for name in present
        )
        msg = f"{where}: columns of {len(present)} angle conventions: {shown}; expected one"
        raise InputError(msg)
    convention = present[0]
    if angles is not None and convention != angles:
        msg = (
            f"{where}: columns {','.join(header[c] for c in named[convention])} are "
            f"{convention} angles but {flag} is {angles} (expected "
            f"{','.join(orientation_header(angles))}, or {flag} {convention})"
        )
        raise InputError(msg)
    components = ANGLE_CONVENTIONS[convention].components
    missing = [c for c in components if c not in columns]
    if missing:
        msg = incomplete or (
            f"{where}: no column for {missing[0]} (expected "
            f"{','.join(orientation_header(convention))} for {convention} angles)"
        )
        raise InputError(msg)
    return convention, np.column_stack([columns[c] for c in components])


def _quantities(table: Table) -> list[str]:
    """The quantity each header cell names (as :meth:`Columns.read` reads it)."""
    found = []
    for cell in table.header or []:
        name = cell.strip().lower()
        if name in ORIENTATION_QUANTITIES:
            found.append(name)
        else:
            found.append(name.rpartition("_")[0] if "_" in name else name)
    return found
