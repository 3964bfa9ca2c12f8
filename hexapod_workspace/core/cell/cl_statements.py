"""The words and statements of APT / CLDATA files: the vocabulary
:mod:`hexapod_workspace.core.cell.cldata` reads (units, feeds, the statements it refuses, the
literal ones) and the tokenizer that turns a file into logical statements with their line
numbers (comments removed, ``$`` continuations joined) and statements into a word and its
arguments, with the numbers checked and the unit of a statement found."""

from __future__ import annotations

import math
import re

import numpy as np
from numpy.typing import NDArray

from ...errors import InputError

__all__ = ["CL_SUFFIXES", "CL_UNITS", "PASSED_OVER"]

#: File name suffixes of CL files (``check-path`` also sniffs the content).
CL_SUFFIXES = (".cl", ".cls", ".clsf", ".apt", ".ncl", ".aptsource")
#: Units a caller may state for a file that does not: metres per unit.
CL_UNITS = {"mm": 1e-3, "inch": 0.0254}
#: Spellings of the units in ``UNITS``/``UNIT`` statements.
_UNIT_WORDS = {
    "MM": "mm",
    "MILLIMETER": "mm",
    "MILLIMETERS": "mm",
    "MILLIMETRE": "mm",
    "MILLIMETRES": "mm",
    "IN": "inch",
    "INCH": "inch",
    "INCHES": "inch",
}
#: Feed units per minute and the length unit each states.
_FEED_UNITS = {"MMPM": "mm", "IPM": "inch"}
#: Feed units per spindle revolution (refused).
_PER_REVOLUTION = ("MMPR", "IPR", "PERREV")
#: The only statements passed over: none can change the motion, the frame, the tool or the
#: units. Keys are the statement (or the one form of it) as counted.
PASSED_OVER: dict[str, str] = {
    "PARTNO": "part name",
    "PPRINT": "text for the operator",
    "TPRINT": "tool text for the operator",
    "MACHIN": "post-processor selection",
    "CUTTER": "tool shape (the tool frame is the tool table's)",
    "TLDATA": "tool shape (NX)",
    "SELECT/TOOL": "tool preselection (NX; LOAD/TOOL changes the tool)",
    "SELCTL": "tool preselection",
    "TOLER": "CAM tolerance",
    "INTOL": "CAM tolerance",
    "OUTTOL": "CAM tolerance",
    "THICK": "CAM stock allowance",
    "AUTOPS": "CAM part-surface setting",
    "SPINDL": "spindle speed",
    "COOLNT": "coolant",
    "PAINT": "display colour and speed (NX)",
    "DISPLY": "display",
    "OPSTOP": "optional stop (the path goes on from where it stopped)",
    "STOP": "program stop (the path goes on from where it stopped)",
    "DELAY": "dwell (the tool stays where it is)",
    "SEQNO": "block numbering",
    "CHANNEL": "controller channel (CATIA)",
    "END": "end of a program section",
    "FINI": "end of the file",
    "REWIND": "tape rewind at the end of the program",
    "CYCLE/OFF": "no cycle is active (every other CYCLE is refused)",
    "CUTCOM/OFF": "no compensation is active (every other CUTCOM is refused)",
    "TRACUT/NOMORE": "no transformation is active (every other TRACUT is refused)",
}
#: Statements that change the motion in ways this reader does not model: refused.
_REFUSED = {
    "MOVARC": "circular moves are not modelled (a chord would be checked instead of the arc; "
    "export arcs as linear GOTO moves)",
    "CYCLE": "canned cycles are not modelled (export them as GOTO moves)",
    "CUTCOM": "cutter compensation (the controller offsets the path) is not modelled; "
    "expected CUTCOM/OFF or a tool-centre path",
    "TRACUT": "TRACUT transformations are not modelled (expected TRACUT/NOMORE)",
    "INSERT": "INSERT passes text to the controller, whose effect on the motion is not known",
    "RETRCT": "RETRCT moves to a clearance plane the file does not give as a point",
    "ROTABL": "rotary-table motion is not modelled (a hexapod has no rotary axes)",
    "ROTHED": "rotary-head motion is not modelled (a hexapod has no rotary axes)",
    "AUXFUN": "auxiliary (M) functions have effects that are not known",
    "PREFUN": "preparatory (G) functions change the motion in ways that are not known",
}
_LITERAL = {"PPRINT", "PARTNO", "TPRINT", "INSERT"}
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][+-]?\d+)?")
_WORD = re.compile(r"\s*([A-Za-z][A-Za-z0-9_]*)")
_TOOL_PATH = re.compile(r"\s*TOOL\s+PATH\s*(?:/(.*))?$", re.IGNORECASE)
_END_OF_PATH = re.compile(r"\s*END-OF-PATH\s*(?:/.*)?$", re.IGNORECASE)


def _statements(text: str) -> list[tuple[int, str]]:
    """Logical statements with the line they start on: comments removed, continuations
    joined; ``PPRINT``/``PARTNO``/``TPRINT``/``INSERT`` lines kept literal."""
    return [(start, statement) for start, _, statement in _statement_spans(text)]


def _statement_spans(text: str) -> list[tuple[int, int, str]]:
    """:func:`_statements` with the last line of each statement: (first, last, statement),
    1-based lines of ``text.splitlines()``."""
    statements: list[tuple[int, int, str]] = []
    pending: list[str] = []
    start = 0
    for number, raw in enumerate(text.splitlines(), start=1):
        if not pending:
            start = number
            word = _WORD.match(raw)
            if word and word.group(1).upper() in _LITERAL:
                statements.append((number, number, raw.strip()))
                continue
        line = raw.split("$$", 1)[0].rstrip()
        if line.endswith("$"):
            pending.append(line[:-1])
            continue
        pending.append(line)
        statement = " ".join(part.strip() for part in pending).strip()
        pending = []
        if statement:
            statements.append((start, number, statement))
    if pending and " ".join(pending).strip():
        msg = f"line {start}: statement continued with '$' past the end of the file"
        raise InputError(msg)
    return statements


def _split(statement: str, line: int, shown: str) -> tuple[str, list[str]]:
    """A statement's major word (upper case) and its arguments."""
    if _TOOL_PATH.match(statement):
        return "TOOL PATH", []
    if _END_OF_PATH.match(statement):
        return "END-OF-PATH", []
    match = _WORD.match(statement)
    if match is None:
        msg = f"line {line}: expected an APT statement (WORD or WORD/...), got {shown!r}"
        raise InputError(msg)
    word = match.group(1).upper()
    rest = statement[match.end() :].strip()
    if word in _LITERAL:
        return word, [rest.removeprefix("/")] if rest else []
    if rest.startswith(("/", ",")):
        body = rest[1:]
        return word, [a.strip() for a in body.split(",")] if body.strip() else []
    if rest:
        msg = f"line {line}: expected an APT statement (WORD or WORD/...), got {shown!r}"
        raise InputError(msg)
    return word, []


def _is_number(token: str) -> bool:
    return _NUMBER.fullmatch(token.strip()) is not None


def _number(token: str, line: int, statement: str) -> float:
    text = token.strip()
    if _NUMBER.fullmatch(text) is None:
        msg = f"line {line}: {statement}: expected a number, got {token!r}"
        raise InputError(msg)
    value = float(text.replace("D", "E").replace("d", "e"))
    if not math.isfinite(value):
        msg = f"line {line}: {statement}: expected a finite number, got {token!r}"
        raise InputError(msg)
    return value


def _numbers(
    arguments: list[str], counts: tuple[int, ...], line: int, shown: str, what: str
) -> NDArray[np.float64]:
    if len(arguments) not in counts:
        got = len(arguments)
        msg = f"line {line}: {shown}: expected {what}, got {got} value{'s' * (got != 1)}"
        raise InputError(msg)
    return np.array([_number(a, line, shown) for a in arguments], dtype=np.float64)


def _unit_of(word: str, arguments: list[str], line: int, shown: str) -> str:
    unit = arguments[0].upper() if len(arguments) == 1 else ""
    if unit not in _UNIT_WORDS:
        msg = f"line {line}: {shown}: expected {word}/MM or {word}/INCHES (or INCH)"
        raise InputError(msg)
    return _UNIT_WORDS[unit]


def _feed_unit(arguments: list[str]) -> str | None:
    """The length unit a FEDRAT's explicit per-minute unit states, else None."""
    for argument in arguments:
        if argument.strip().upper() in _FEED_UNITS:
            return _FEED_UNITS[argument.strip().upper()]
    return None


def _initial_units(statements: list[tuple[int, str]], units: str | None) -> tuple[str | None, str]:
    """The units the file starts in, and what says so: the first feed with a unit before the
    first UNITS statement, else the caller's; disagreements refused."""
    evidence: tuple[str, int, str] | None = None
    for line, statement in statements:
        shown = _shown(statement)
        try:
            word, arguments = _split(statement, line, shown)
        except InputError:
            break  # the main pass reports it
        if word in ("UNITS", "UNIT"):
            break
        if word == "FEDRAT":
            unit = _feed_unit(arguments)
            if unit is not None:
                if evidence is not None and evidence[0] != unit:
                    msg = (
                        f"line {line}: {shown}: a feed in {_NAMES[unit]}, but line "
                        f"{evidence[1]} ({evidence[2]}) says {_NAMES[evidence[0]]}; the "
                        "file's units disagree"
                    )
                    raise InputError(msg)
                evidence = evidence or (unit, line, shown)
    if evidence is not None:
        if units is not None and units != evidence[0]:
            msg = (
                f"line {evidence[1]}: {evidence[2]}: a feed in {_NAMES[evidence[0]]}, but the "
                f"units given for the file (--cl-units) are {units}"
            )
            raise InputError(msg)
        return evidence[0], f"line {evidence[1]}: {evidence[2]}"
    if units is not None:
        return units, f"units={units!r} (--cl-units)"
    return None, ""


_NAMES = {"mm": "mm", "inch": "inches"}


def _shown(statement: str) -> str:
    return statement if len(statement) <= 60 else statement[:57] + "..."
