"""``hexapod-workspace schedule FILE``: the fastest feed schedule along a toolpath that is
certified to run (:mod:`hexapod_workspace.core.motions.schedule`, derivations there).

FILE is what ``check-path`` takes (a path CSV or a CL file, with frames, tools and feeds as
:mod:`.cam` reads them); the path is checked as ``check-path`` checks it (its verdict is
``path_ok``) and scheduled along the same moves. Limits: ``limits.actuator_speed_max`` and
``limits.actuator_accel_max`` (one or six values, actuator unit/s and /s², 0 = unlimited), and
the tool centre point's speed at most the move's programmed feed (``FEDRAT``, or
``--feed-mm-min`` where there is none; ``RAPID`` moves ``--rapid-feed-mm-min``, else no
ceiling; moves without translation ``--rotary-feed-deg-min``) and at most
``--feed-max-mm-min``: the programmed feed is a ceiling, not a target. The schedule rests at
both ends of every part (tool changes), at each waypoint where the actuator rates change
direction (a corner: no finite acceleration passes it) and, with ``--stop-at-rapids``, where
``RAPID`` moves begin and end.

JSON: ``duration_s`` (every part; tool changes take no time here), ``programmed_duration_s``
(every move at its programmed feed; ``null`` when a move has none), ``path_ok``,
``actuator_unit``, ``actuator_speed_max``, ``actuator_accel_max``, ``covers``; per part (the top
level for one, else ``parts``) ``grid: [{"s", "sdot"}]`` (s = k + u on move k, ṡ in 1/s, s̈
constant between two nodes of one move so ṡ² is linear in s; at a waypoint the end of one move
and the start of the next are two entries with the same s) and ``moves: [{"t_start_s",
"t_end_s", "feed_peak_mm_min" (``feed_peak_deg_min`` for a rotation), "feed_ceiling_mm_min",
"limited_by": {"kind": "feed"|"velocity"|"acceleration", "actuator": 1-6 or null},
"actuator_speed_peak", "actuator_accel_peak"}]`` (certified bounds, six each). Exit 0 when a
schedule is given, 2 for bad input or a move that cannot be scheduled (named with its line).

``--write-cl OUT`` (CL files only): FILE written again with the ``FEDRAT`` each move can run at,
a CAM user's way to apply the result without a controller that follows s(t). **The feed a move
can run at** is the largest constant feed F, at most the move's programmed feed (``FEDRAT``, or
``--feed-mm-min``) and at most ``--feed-max-mm-min``, such that running the move at constant
parameter rate u' = F/L (L its length as check-path's speeds take it, a lower bound on curves:
how check-path models "a move at feed F") keeps every actuator within
``limits.actuator_speed_max`` and ``limits.actuator_accel_max`` everywhere on it, certified:
with s̈ = 0, ``|q̇_i| ≤ G_i·u'`` and ``|q̈_i| ≤ K_i·u'²`` on every interval of the move
(:func:`~hexapod_workspace.core.motions.schedule.steady_feeds`); it is also at most
check-path's own certified speed bound (looser by up to 1 %), so that check-path on OUT finds
every cutting move within the speed limits. The corners between moves (from one feed to the
next) are not bounded: they stay the controller's look-ahead. ``RAPID`` moves and moves
without translation keep their programmed feed. How the file is written (every other line
kept, the file's own ``FEDRAT`` dialect, one per statement, the smallest of a ``NURBS``
record's moves): :mod:`~hexapod_workspace.core.cell.cl_feeds`. OUT must not be FILE, nor an
existing file without ``--force``. Text: ``wrote OUT: N FEDRAT statements (M moves slower
than programmed)``; JSON: ``"write_cl": {"path", "fedrat_statements", "moves_slowed"}`` and
per move ``"feed_steady_mm_min"`` (the feed written, mm/min; ``null``: the programmed feed
kept).
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from ..core.base.rotations import tt_to_matrix
from ..core.cell.cl_feeds import rewrite_feeds
from ..core.cell.cldata import CL_SUFFIXES, CLProgram
from ..core.cell.frames import CellFrames
from ..core.model.manipulator import Manipulator
from ..core.motions import DEFAULT_PLAN_PSI_STEP, reported_parts
from ..core.motions.schedule import PathSchedule, schedule_path, steady_feeds
from ..core.motions.schedule_report import (
    feed_ceilings,
    limited_by,
    programmed_duration,
    rapid_boundaries,
)
from ..core.motions.speeds import ACTUATOR_MODELS, actuator_rates, feed_limits
from ..errors import InputError
from .cam import (
    DEG_MIN,
    MM_MIN,
    _finite,
    _Part,
    _positive,
    cell_arguments,
    check_part_path,
    is_cl_file,
    read_cell_inputs,
)
from .commands import PROG
from .inputs import PLOT_FORMATS, CliError, output_file
from .schedule_plot import ScheduledPart, plot_schedule

__all__ = ["SCHEDULE_DESCRIPTION", "SCHEDULE_HELP", "cmd_schedule", "schedule_arguments"]

#: What the schedule covers (said in every result).
SCHEDULE_COVERAGE = (
    "actuator speeds and accelerations and the tool centre point's feed along the programmed "
    "moves, certified between grid points; jerk, the controller's look-ahead and its servo "
    "lag are the controller's"
)


def _ceilings(
    part: _Part, feeds: tuple[float, float, float]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Per move: the feed ceiling (m/s, inf: none), the rotary ceiling of moves without
    translation (rad/s) and the programmed feed of moves with translation (m/s, NaN: none)."""
    rapid_feed, rotary_feed, feed_max = feeds
    linear, programmed = feed_ceilings(part.feeds[1:], part.rapid[1:], rapid_feed, feed_max)
    turning = np.full(linear.size, math.inf if math.isnan(rotary_feed) else rotary_feed)
    return linear, turning, programmed


def _part_document(
    part: _Part,
    schedule: PathSchedule,
    ceilings: NDArray[np.float64],
    rotary_ceiling: NDArray[np.float64],
) -> dict[str, Any]:
    moves = []
    ceiling_of = np.where(schedule.rotary, rotary_ceiling, ceilings)
    kinds, actuators = limited_by(schedule, ceiling_of)
    for k in range(schedule.t_start.size):
        rotary = bool(schedule.rotary[k])
        unit = DEG_MIN if rotary else MM_MIN
        ceiling = float(ceiling_of[k])
        entry: dict[str, Any] = {
            "t_start_s": float(schedule.t_start[k]),
            "t_end_s": float(schedule.t_end[k]),
            ("feed_peak_deg_min" if rotary else "feed_peak_mm_min"): float(
                schedule.feed_peak[k] / unit
            ),
            ("feed_ceiling_deg_min" if rotary else "feed_ceiling_mm_min"): _finite(ceiling / unit),
            "limited_by": {"kind": kinds[k], "actuator": int(actuators[k]) or None},
            "actuator_speed_peak": schedule.speed_peak[k].tolist(),
            "actuator_accel_peak": schedule.accel_peak[k].tolist(),
            "rapid": bool(part.rapid[k + 1]),
        }
        if part.lines is not None:
            entry["line"] = int(part.lines[k + 1])
        moves.append(entry)
    return {
        "duration_s": schedule.duration,
        "grid": [
            {"s": float(s), "sdot": float(v)}
            for s, v in zip(schedule.s, schedule.sdot, strict=True)
        ],
        "moves": moves,
        "stops": [int(k) for k in np.flatnonzero(schedule.stops)],
        "intervals": schedule.intervals,
    }


def _schedule_part(
    platform: Manipulator,
    part: _Part,
    cell: CellFrames,
    options: argparse.Namespace,
    feeds: tuple[float, float, float],
) -> tuple[dict[str, Any], ScheduledPart, float]:
    """Check one part as ``check-path`` does, then schedule it; returns its document, the
    part as scheduled and its programmed duration (NaN: some move has no feed)."""
    model, result, _, _ = check_part_path(platform, part, options)
    checked, plan = reported_parts(result)
    rotations = tt_to_matrix(checked.waypoints.angles)
    positions = checked.waypoints.positions
    linear, turning, programmed = _ceilings(part, feeds)
    stops = rapid_boundaries(part.rapid[1:]) if options.stop_at_rapids else None
    try:
        schedule = schedule_path(
            model,
            positions,
            rotations,
            speed_limits=cell.actuator_speed_max,
            accel_limits=cell.actuator_accel_max,
            feeds=linear,
            rotary_feeds=turning,
            stops=stops,
            arcs=part.arcs,
            beziers=part.beziers,
        )
    except InputError as error:
        where = str(error)
        if part.lines is not None and where.startswith("move "):
            number = int(where.split(":", 1)[0].split()[1])
            where = f"CL file {options.file}: line {part.lines[number]}: {where}"
        raise CliError(where) from error
    programmed_time = programmed_duration(schedule, programmed, feeds[1])
    # moves without translation are programmed as a rotation rate (rad/s)
    programmed = np.where(schedule.rotary, feeds[1], programmed)
    document = _part_document(part, schedule, linear, turning)
    document["path_ok"] = bool(checked.ok and (plan is None or plan.ok))
    document["programmed_duration_s"] = _finite(programmed_time)
    scheduled = ScheduledPart(
        model, positions, rotations, part.arcs, part.beziers, programmed, schedule
    )
    if options.write_cl is not None:  # replaced by each move's written feed (_write_cl)
        document["steady"] = _steady_part(scheduled, part.rapid, cell, linear)
    return document, scheduled, programmed_time


def _steady_part(
    scheduled: ScheduledPart, rapid: NDArray[np.bool_], cell: CellFrames, ceilings: NDArray[Any]
) -> NDArray[np.float64]:
    """Per move of the part, the feed it can run at (module documentation, ``--write-cl``),
    m/s; NaN for ``RAPID`` moves, moves without translation and moves no limit bounds."""
    model, positions, rotations = scheduled.model, scheduled.positions, scheduled.rotations
    schedule = scheduled.schedule
    limits = cell.actuator_speed_max
    curves: dict[str, Any] = {"arcs": scheduled.arcs, "beziers": scheduled.beziers}
    try:
        rate = steady_feeds(
            model,
            positions,
            rotations,
            speed_limits=limits,
            accel_limits=cell.actuator_accel_max,
            **curves,
        )
    except InputError as error:  # the schedule refused the same moves first
        raise CliError(str(error)) from error
    # check-path's own certified speed bound (looser, DEFAULT_RELATIVE): so that check-path on
    # OUT finds every move within the speed limits too
    none = np.full(rate.size, math.nan)
    rates = actuator_rates(model, positions, rotations, speed_limits=limits, **curves)
    checked = feed_limits(rates, none, none, limits).feed_max
    with np.errstate(invalid="ignore"):
        feed = np.minimum(np.minimum(ceilings, rate * schedule.length), checked)
    keep = rapid[1:] | schedule.rotary | ~np.isfinite(feed)
    return np.where(keep, math.nan, feed)


def _write_cl_target(options: argparse.Namespace) -> Path | None:
    """``--write-cl OUT``, checked before any work: FILE a CL file, OUT not FILE, OUT not an
    existing file (but with ``--force``)."""
    if options.write_cl is None:
        return None
    if not is_cl_file(options.file):
        msg = f"--write-cl: only for CL files ({options.file} is read as a path CSV)"
        raise CliError(msg)
    if Path(options.write_cl).resolve() == Path(options.file).resolve():
        msg = f"--write-cl: {options.write_cl} is FILE itself; give another file name"
        raise CliError(msg)
    return output_file(options.write_cl, "--write-cl", force=options.force, suffixes=CL_SUFFIXES)


def _write_cl(
    options: argparse.Namespace,
    target: Path,
    program: CLProgram | None,
    parts: list[_Part],
    documents: list[dict[str, Any]],
) -> dict[str, Any]:
    """Write FILE again with each move's feed (:mod:`~hexapod_workspace.core.cell.cl_feeds`);
    each move's document gets ``feed_steady_mm_min`` (null: the programmed feed kept)."""
    assert program is not None
    wanted = np.full(len(program), math.nan)
    for part, document in zip(parts, documents, strict=True):
        steady = document.pop("steady")
        wanted[part.first + 1 : part.first + 1 + steady.size] = steady
    try:
        with Path(options.file).open(encoding="utf-8", newline="") as handle:
            text = handle.read()
        result = rewrite_feeds(text, program, wanted)
        with target.open("w", encoding="utf-8", newline="") as handle:
            handle.write(result.text)
    except OSError as error:
        msg = f"--write-cl: cannot write {target}: {error.strerror or error}"
        raise CliError(msg) from error
    slowed = 0
    for part, document in zip(parts, documents, strict=True):
        for k, move in enumerate(document["moves"]):
            feed = float(result.feeds[part.first + 1 + k])
            move["feed_steady_mm_min"] = _finite(feed / MM_MIN)
            ceiling = move.get("feed_ceiling_mm_min")
            # slower than programmed: below the ceiling by more than the 4 decimals' rounding
            if math.isfinite(feed) and ceiling is not None:
                slowed += int(feed / MM_MIN < ceiling * (1.0 - 1e-6) - 2e-4)
    return {"path": str(target), "fedrat_statements": result.statements, "moves_slowed": slowed}


def cmd_schedule(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``schedule``: the certified fastest schedule of FILE (module documentation)."""
    target = _write_cl_target(options)
    plot = (
        None
        if options.plot is None
        else output_file(options.plot, "--plot", force=options.force, suffixes=PLOT_FORMATS)
    )
    options.interpolation = "slerp"  # the controller's moves, as the speeds take them
    feed_max = _positive(options.feed_max_mm_min, "--feed-max-mm-min", "mm/min") * MM_MIN
    platform, cell, frame, (rapid, rotary), parts, program = read_cell_inputs(options, err)
    documents: list[dict[str, Any]] = []
    schedules: list[ScheduledPart] = []
    programmed: list[float] = []
    for part in parts:
        document, scheduled, planned = _schedule_part(
            platform, part, cell, options, (rapid, rotary, feed_max)
        )
        document["first_waypoint"] = part.first
        documents.append(document)
        schedules.append(scheduled)
        programmed.append(planned)
    total = float(sum(s.schedule.duration for s in schedules))
    planned_total = float(sum(programmed))
    unit = ACTUATOR_MODELS[platform.architecture].unit
    report: dict[str, Any] = {
        "duration_s": total,
        "programmed_duration_s": _finite(planned_total),
        "path_ok": all(d["path_ok"] for d in documents),
        "frame": frame,
        "actuator_unit": unit,
        "actuator_speed_max": cell.actuator_speed_max.tolist(),
        "actuator_accel_max": cell.actuator_accel_max.tolist(),
        "covers": SCHEDULE_COVERAGE,
    }
    if target is not None:
        report["write_cl"] = _write_cl(options, target, program, parts, documents)
    if len(documents) == 1:
        report.update(documents[0])
        report["duration_s"], report["programmed_duration_s"] = total, _finite(planned_total)
    else:
        report["parts"] = documents
    if plot is not None:
        plot_schedule(schedules, cell, unit, Path(plot))
    if options.json:
        out.write(json.dumps(report, allow_nan=False) + "\n")
    else:
        _text(report, documents, unit, out)
        if plot is not None:
            out.write(f"  plot: {plot}\n")
        if target is not None:
            written = report["write_cl"]
            out.write(
                f"wrote {written['path']}: {written['fedrat_statements']} FEDRAT statements "
                f"({written['moves_slowed']} moves slower than programmed)\n"
            )
    if not report["path_ok"]:
        err.write(f"{PROG}: the path does not run (check-path FILE says where); scheduled anyway\n")
    return 0


def _text(report: dict[str, Any], documents: list[dict[str, Any]], unit: str, out: IO[str]) -> None:
    planned = report["programmed_duration_s"]
    against = (
        "no programmed time (a move has no feed)"
        if planned is None
        else (f"{planned:.3f} s at the programmed feeds")
    )
    moves = sum(len(d["moves"]) for d in documents)
    stops = sum(len(d["stops"]) for d in documents)
    out.write(
        f"schedule: {report['duration_s']:.3f} s ({against}), {moves} moves, "
        f"{stops} stops (ends, corners{', tool changes' if len(documents) > 1 else ''})\n"
    )
    speed = ", ".join(f"{v:g}" for v in sorted(set(report["actuator_speed_max"])))
    accel = ", ".join(f"{v:g}" for v in sorted(set(report["actuator_accel_max"])))
    out.write(
        f"  limits: actuator speed {speed} {unit}/s, acceleration {accel} {unit}/s² (0: none)\n"
    )
    slow = []
    for p, document in enumerate(documents):
        for k, move in enumerate(document["moves"]):
            limit = move["limited_by"]
            if limit["kind"] == "feed":
                continue
            where = f"line {move['line']}" if "line" in move else f"move {k + 1}"
            if len(documents) > 1:
                where = f"part {p}, {where}"
            peak = move.get("feed_peak_mm_min", move.get("feed_peak_deg_min"))
            per = "mm/min" if "feed_peak_mm_min" in move else "deg/min"
            ceiling = move.get("feed_ceiling_mm_min", move.get("feed_ceiling_deg_min"))
            of = f" of {ceiling:.0f}" if ceiling is not None else ""
            slow.append(
                f"    {where}: peak {peak:.0f}{of} {per}, limited by actuator "
                f"{limit['actuator']} {limit['kind']}\n"
            )
    out.write(f"  below the programmed feed: {len(slow)} move(s)\n")
    for line in slow[:20]:
        out.write(line)
    if len(slow) > 20:
        out.write(f"    ... and {len(slow) - 20} more (--json lists every move)\n")
    out.write(f"  covers: {report['covers']}\n")


SCHEDULE_HELP = (
    "fastest certified feed schedule along a path: actuator speed and acceleration limits, "
    "the programmed feed as a ceiling (exit 0 scheduled, 2 bad input)"
)
SCHEDULE_DESCRIPTION = (
    "FILE is what check-path takes (a path CSV or an APT CL file, in the work frame). Along "
    "the same moves, the time law that minimises the total time with every actuator within "
    "limits.actuator_speed_max and limits.actuator_accel_max, the tool centre point within "
    "each move's programmed feed (and --feed-max-mm-min), at rest at both ends and at every "
    "corner; the limits hold between grid points too (certified bounds, derived in "
    "hexapod_workspace/core/motions/schedule.py)."
)


def schedule_arguments(sub: argparse.ArgumentParser) -> None:
    """The ``schedule`` command's options."""
    sub.add_argument("file", metavar="FILE", help="path CSV or APT CL file (as check-path)")
    cell_arguments(sub)
    sub.add_argument(
        "--feed-max-mm-min",
        type=float,
        metavar="F",
        help="ceiling of every move's feed, mm/min (default: the programmed feeds only)",
    )
    sub.add_argument(
        "--stop-at-rapids",
        action="store_true",
        help="also rest where RAPID moves begin and end",
    )
    sub.add_argument(
        "--tol-deg",
        type=float,
        metavar="T",
        help="tolerance of the path check (path_ok), degrees of platform rotation",
    )
    sub.add_argument(
        "--psi-step-deg",
        type=float,
        default=math.degrees(DEFAULT_PLAN_PSI_STEP),
        metavar="S",
        help="tool axes (CL files): torsion planner's grid step, degrees (default %(default)g)",
    )
    sub.add_argument(
        "--max-dpsi-deg",
        type=float,
        metavar="D",
        help="tool axes: largest torsion change per move, degrees (default: no limit)",
    )
    sub.add_argument(
        "--plot",
        metavar="FILE.png",
        help="feed along the path against the programmed feed, and each actuator's speed and "
        "acceleration against its limits, over time",
    )
    sub.add_argument(
        "--write-cl",
        metavar="OUT",
        help="CL files: write FILE again as OUT (every line kept) with a FEDRAT before each "
        "cutting move whose feed changes: the largest constant feed, at most the programmed one "
        "and --feed-max-mm-min, at which the move keeps every actuator within "
        "limits.actuator_speed_max and limits.actuator_accel_max everywhere on it (certified; "
        "RAPID moves and rotations keep theirs; the corners between moves stay the "
        "controller's look-ahead). See docs/cell.md",
    )
    sub.add_argument(
        "--force",
        action="store_true",
        help="replace an existing --plot file not of ours, or an existing --write-cl file",
    )
