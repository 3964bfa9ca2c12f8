"""``check-path`` for a machining cell: CL files (APT CLDATA), work/tool frames, feeds against
actuator speeds.

:func:`cmd_check_path_any` (the ``check-path`` command) runs :func:`cmd_check_cell_path` when
the file is a CL file (by suffix, or by content: a line starting with ``GOTO/``) or when one of
``--frame``, ``--feed-mm-min``, ``--rapid-feed-mm-min``, ``--rotary-feed-deg-min`` is given, and
:func:`hexapod_workspace.cli.check_path.cmd_check_path` otherwise.

Frames. CL coordinates are in the work frame (``work.*``; the default work frame is the base
frame), CSV coordinates in the base frame; ``--frame base|work`` says otherwise. Results report
positions and angles in that same frame (top-level ``frame`` key). The tool frame is ``tool.*``
until a ``LOADTL/n`` selects ``tools.T<n>``; every ``LOADTL`` between moves starts a new *part*
(the controller stops for the tool change).

JSON. A path of one part has the document of a CSV path plus ``frame``, ``tool``,
``work_frame``, ``passed_over`` (CL statements passed over: count per statement), ``cl_units``
(``unit``, ``source``: what stated them), ``cl_frames`` (each ``MSYS``/``ORIGIN`` applied),
``cl_splines`` (each ``NURBS`` spline: ``line`` and ``moves``, its Bézier spans) and
``speed``; every move (``segments[k]``) gains ``duration_s``,
``feed_mm_min`` (or ``feed_deg_min`` for a rotation without translation), ``rapid``,
``actuator_speed_peak`` (certified bound, actuator unit/s, the largest over the actuators),
``speed_ok`` and ``feed_max_mm_min`` (``feed_max_deg_min`` for a rotation; ``null`` when no
limit applies); a CL path's waypoints gain ``line``. A path with tool changes has ``ok``,
``frame``, ``work_frame``, ``passed_over``, ``cl_units``, ``cl_frames``, ``cl_splines``,
``speed`` and ``parts``: one such document per part with ``first_waypoint``.

Speeds. ``limits.actuator_speed_max`` (one or six values, actuator unit/s, 0 = unlimited). A
move's feed is the CL file's ``FEDRAT`` (``--feed-mm-min`` before the first one, and for CSV
files), ``--rapid-feed-mm-min`` for ``RAPID`` moves and ``--rotary-feed-deg-min`` for moves
without translation; a move without one has no duration and no speed verdict (``null``, and the
summary counts it). The check covers the actuator speeds along the programmed moves, each at its
constant feed; corner blending and accelerations are the controller's.
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import replace
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from .._resources import example_config_path
from ..core.base.rotations import (
    degrees_to_radians,
    matrix_to_quaternion,
    matrix_to_tt,
    tt_to_matrix,
)
from ..core.cell.cldata import (
    CL_SUFFIXES,
    CL_UNITS,
    CLProgram,
    looks_like_cldata,
    read_cldata,
)
from ..core.cell.frames import (
    CellFrames,
    Tool,
    WorkFrame,
    cell_from_params_file,
    curves_to_base,
    tool_model,
    vectors_to_base,
    work_to_base,
)
from ..core.model.manipulator import Manipulator
from ..core.motions import (
    DEFAULT_PATH_TOLERANCE,
    PathCheck,
    TorsionPlan,
    check_path,
    plan_torsion,
    reported_parts,
)
from ..core.motions.speeds import ACTUATOR_MODELS, FeedLimits, actuator_rates, feed_limits
from .cam_report import plot_speeds, speed_text
from .check_path import (
    _degrees_flag,
    _text,
    _where,
    check_path_arguments,
    cmd_check_path,
    path_to_json,
    psi_zero_baseline,
    read_path_file,
    record_path_calls,
)
from .commands import PROG
from .inputs import (
    PLOT_FORMATS,
    CliError,
    configured_manipulator,
    finite,
    output_file,
)

__all__ = [
    "DEG_MIN",
    "FRAMES",
    "MM_MIN",
    "SPEED_COVERAGE",
    "cell_arguments",
    "cell_pipeline_applies",
    "check_part_path",
    "check_path_any_arguments",
    "cmd_check_cell_path",
    "cmd_check_path_any",
    "is_cl_file",
    "read_cell_inputs",
    "tool_json",
    "work_json",
]

#: Frames a position on the command line or in a file may be given in.
FRAMES = ("base", "work")
#: What the speed check covers (said in every result).
SPEED_COVERAGE = (
    "actuator speeds along the programmed moves, each at its constant feed (certified bound); "
    "corner blending and accelerations are the controller's"
)
#: m/s per mm/min, and rad/s per deg/min.
MM_MIN, DEG_MIN = 1e-3 / 60.0, math.radians(1.0) / 60.0


def is_cl_file(path: str | Path) -> bool:
    """A CL file by its suffix (.cl, .cls, .apt, .ncl, .aptsource) or its content."""
    path = Path(path)
    if path.suffix.lower() in CL_SUFFIXES:
        return True
    if path.suffix.lower() == ".csv":
        return False
    try:
        with path.open("r", encoding="utf-8") as handle:
            head = handle.read(65536)
    except (OSError, UnicodeDecodeError):
        return False  # the CSV reader reports it
    return looks_like_cldata(head)


def cell_pipeline_applies(options: argparse.Namespace) -> bool:
    """Whether ``check-path`` needs this module (a CL file, a frame or a feed given)."""
    flags = ("frame", "feed_mm_min", "rapid_feed_mm_min", "rotary_feed_deg_min", "cl_units")
    return is_cl_file(options.file) or any(getattr(options, f, None) is not None for f in flags)


def cmd_check_path_any(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``check-path``: this module's pipeline for CL files, frames and feeds, else the CSV one."""
    if cell_pipeline_applies(options):
        return cmd_check_cell_path(options, out, err)
    return cmd_check_path(options, out, err)


def check_path_any_arguments(sub: argparse.ArgumentParser) -> None:
    """``check-path``'s options: the CSV path's and :func:`cell_arguments`."""
    check_path_arguments(sub)
    cell_arguments(sub)


def cell_arguments(sub: argparse.ArgumentParser) -> None:
    """``check-path``'s options for CL files, frames and feeds."""
    sub.add_argument(
        "--frame",
        choices=FRAMES,
        help="frame of the file's positions and orientations and of the results (default: "
        "work for CL files, base for CSV)",
    )
    sub.add_argument(
        "--feed-mm-min",
        type=float,
        metavar="F",
        help="feed of the moves without a programmed FEDRAT (CSV: every move), mm/min",
    )
    sub.add_argument(
        "--rapid-feed-mm-min",
        type=float,
        metavar="F",
        help="feed of RAPID moves, mm/min (default: none, so they get no speed verdict)",
    )
    sub.add_argument(
        "--cl-units",
        choices=tuple(CL_UNITS),
        help="units of a CL file that does not state them (no UNITS statement, no feed in "
        "MMPM or IPM); refused where the file states others",
    )
    sub.add_argument(
        "--rotary-feed-deg-min",
        type=float,
        metavar="F",
        help="rotation rate of moves without translation, deg/min",
    )


def _positive(value: float | None, flag: str, unit: str) -> float:
    """NaN when not given, else a finite value > 0."""
    if value is None:
        return math.nan
    number = float(finite([value], flag, unit)[0])
    if not number > 0.0:
        msg = f"{flag}: expected a value > 0 ({unit}), got {number:g}"
        raise CliError(msg)
    return number


class _Part:
    """One tool's stretch of the path, in the base frame."""

    def __init__(
        self,
        tool: Tool,
        positions: NDArray[np.float64],
        axes: NDArray[np.float64] | None,
        degrees: NDArray[np.float64] | None,
        feeds: NDArray[np.float64],
        rapid: NDArray[np.bool_],
        lines: NDArray[np.int64] | None,
        first: int,
        written: bool = False,
        arcs: NDArray[np.float64] | None = None,
        beziers: NDArray[np.float64] | None = None,
    ) -> None:
        self.tool, self.positions, self.axes, self.degrees = tool, positions, axes, degrees
        self.feeds, self.rapid, self.lines, self.first = feeds, rapid, lines, first
        self.written = written  # degrees are the file's own (base frame): echoed as given
        # the part's moves (N − 1, 7) in the base frame, None when none is an arc (CIRCLE)
        self.arcs = arcs
        # the part's Bézier moves (N − 1, 6) in the base frame, None when none is (NURBS)
        self.beziers = beziers


def _read_parts(
    options: argparse.Namespace, cell: CellFrames, frame: str, feed: float
) -> tuple[list[_Part], CLProgram | None]:
    """The file's parts in the base frame, and the CL program (None for CSV)."""
    work = cell.work if frame == "work" else WorkFrame()
    units = getattr(options, "cl_units", None)
    if is_cl_file(options.file):
        program: CLProgram = read_cldata(options.file, tools=set(cell.tools), units=units)
        positions = work.origin + program.positions @ work.rotation.T
        axes = vectors_to_base(program.axes, work)
        feeds = np.where(np.isnan(program.feeds), feed, program.feeds)
        # the curved moves (CIRCLE, NURBS spans) in the base frame
        arcs, beziers = curves_to_base(program.arcs, program.beziers, work)
        assert arcs is not None and beziers is not None
        parts = []
        for start, stop in program.parts:
            number = int(program.tools[start])
            tool = cell.tool if number == 0 else cell.select(number)
            feeds_part = feeds[start:stop].copy()
            feeds_part[0] = math.nan
            parts.append(
                _Part(
                    tool,
                    positions[start:stop],
                    axes[start:stop],
                    None,
                    feeds_part,
                    program.rapid[start:stop],
                    program.lines[start:stop],
                    start,
                    arcs=_part_curves(arcs[start + 1 : stop]),
                    beziers=_part_curves(beziers[start + 1 : stop]),
                )
            )
        for k, (start, stop) in enumerate(program.parts):
            if stop - start < 2:
                msg = (
                    f"CL file {options.file}: line {program.lines[start]}: the only waypoint "
                    f"of part {k} (tool {program.tools[start]}); expected at least 2 (one move) "
                    "per part (tool change, TOOL PATH or END-OF-PATH)"
                )
                raise CliError(msg)
        return parts, program
    if units is not None:
        msg = f"--cl-units: only for CL files ({options.file} is read as CSV, in m)"
        raise CliError(msg)
    waypoints = read_path_file(options.file)
    count = len(waypoints.positions)
    feeds = np.full(count, feed)
    feeds[0] = math.nan
    positions = work.origin + waypoints.positions @ work.rotation.T
    if waypoints.axes is not None:
        axes = vectors_to_base(waypoints.axes, work)
        part = _Part(cell.tool, positions, axes, None, feeds, np.zeros(count, bool), None, 0)
    else:
        assert waypoints.degrees is not None  # read_path_file gives axes or angles
        degrees = waypoints.degrees  # as written: reported as given in the base frame
        if frame == "work":
            local = tt_to_matrix(degrees_to_radians(waypoints.degrees))
            rotation, _ = work_to_base(local, np.zeros((count, 3)), work)
            degrees = np.degrees(matrix_to_tt(rotation))
        part = _Part(
            cell.tool,
            positions,
            None,
            degrees,
            feeds,
            np.zeros(count, bool),
            None,
            0,
            written=frame == "base",
        )
    return [part], None


def _part_curves(rows: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """A part's curve rows (arcs or Bézier moves), or None when none of its moves is one."""
    return rows if bool(np.isfinite(rows[:, 0]).any()) else None


def _to_frame(document: dict[str, Any], work: WorkFrame) -> None:
    """Rewrite a path document's base-frame positions and angles in the work frame."""
    r_w = work.rotation

    def position(p: list[float]) -> list[float]:
        local: list[float] = ((np.asarray(p) - work.origin) @ r_w).tolist()
        return local

    def angles(deg: list[float]) -> list[float]:
        local = r_w.T @ tt_to_matrix(np.radians(deg))
        converted: list[float] = np.degrees(matrix_to_tt(local)).tolist()
        return converted

    for waypoint in document["waypoints"]:
        waypoint["position"] = position(waypoint["position"])
        phi, theta, psi = angles([waypoint["phi_deg"], waypoint["theta_deg"], waypoint["psi_deg"]])
        waypoint.update(phi_deg=phi, theta_deg=theta, psi_deg=psi)
    for segment in document["segments"]:
        arc = segment.get("arc")
        if arc is not None:
            arc["centre"] = position(arc["centre"])
            arc["axis"] = (np.asarray(arc["axis"]) @ r_w).tolist()
        bezier = segment.get("bezier")
        if bezier is not None:
            bezier["control_points"] = [position(p) for p in bezier["control_points"]]
        if segment["position_at_violation"] is not None:
            segment["position_at_violation"] = position(segment["position_at_violation"])
            segment["first_violation_pose_deg"] = angles(segment["first_violation_pose_deg"])


def tool_json(tool: Tool) -> dict[str, Any]:
    """A tool in results: number (0: ``tool.*``), offset (m), orientation (deg)."""
    return {
        "number": tool.number,
        "offset": tool.offset.tolist(),
        "orientation_deg": np.degrees(tool.orientation).tolist(),
    }


def work_json(work: WorkFrame) -> dict[str, Any]:
    """The work frame in results: frame_id, origin (m), orientation (deg)."""
    return {
        "frame_id": work.frame_id,
        "origin": work.origin.tolist(),
        "orientation_deg": np.degrees(work.orientation).tolist(),
    }


def check_part_path(
    platform: Manipulator, part: _Part, options: argparse.Namespace
) -> tuple[Manipulator, PathCheck | TorsionPlan, PathCheck, float]:
    """The certified check of one part, as ``check-path`` runs it: the part's tool model, the
    check (or the torsion plan, for tool axes), its psi = 0 baseline and the tolerance (rad)."""
    model = tool_model(platform, part.tool)
    tolerance = (
        DEFAULT_PATH_TOLERANCE
        if options.tol_deg is None
        else _degrees_flag(options.tol_deg, "--tol-deg")
    )
    result: PathCheck | TorsionPlan
    if part.axes is not None:
        max_dpsi = (
            None
            if options.max_dpsi_deg is None
            else _degrees_flag(options.max_dpsi_deg, "--max-dpsi-deg")
        )
        result = plan_torsion(
            model,
            part.positions,
            part.axes,
            psi_step=_degrees_flag(options.psi_step_deg, "--psi-step-deg"),
            max_dpsi=max_dpsi,
            interpolation=options.interpolation,
            tolerance=tolerance,
            arcs=part.arcs,
            beziers=part.beziers,
        )
        baseline = result.baseline
    else:
        assert part.degrees is not None
        result = check_path(
            model,
            part.positions,
            angles=degrees_to_radians(part.degrees),
            interpolation=options.interpolation,
            tolerance=tolerance,
            arcs=part.arcs,
            beziers=part.beziers,
        )
        baseline = psi_zero_baseline(model, result)
    return model, result, baseline, tolerance


def _check_part(
    platform: Manipulator,
    part: _Part,
    cell: CellFrames,
    options: argparse.Namespace,
    feeds: tuple[float, float],
) -> tuple[PathCheck | TorsionPlan, dict[str, Any], tuple[dict[str, Any], dict[str, Any]]]:
    """Check (or plan) one part and add the speed keys to its document; also return the part
    as a ``~/check_path`` call (request and response fields, base frame) for ``--record``."""
    model, result, baseline, tolerance = check_part_path(platform, part, options)
    document = path_to_json(result, baseline, part.degrees if part.written else None)
    checked, _ = reported_parts(result)
    moves = len(checked.segments)
    rapid_feed, rotary_feed = feeds
    feed = np.where(part.rapid[1:], rapid_feed, part.feeds[1:])
    limits = cell.actuator_speed_max
    if options.interpolation != "slerp" and np.any(np.isfinite(feed)):
        msg = "feeds: the speed check needs --interpolation slerp (the controller's moves)"
        raise CliError(msg)
    rotations = tt_to_matrix(checked.waypoints.angles)
    rates = actuator_rates(
        model,
        checked.waypoints.positions,
        rotations,
        speed_limits=limits,
        arcs=part.arcs,
        beziers=part.beziers,
    )
    speeds = feed_limits(rates, feed, np.full(moves, rotary_feed), limits)
    for k, segment in enumerate(document["segments"]):
        known = bool(np.isfinite(speeds.duration[k]))
        rotary = bool(speeds.rotary[k])
        feed_max = float(speeds.feed_max[k])
        per_minute = feed_max / (DEG_MIN if rotary else MM_MIN)
        segment.update(
            rapid=bool(part.rapid[k + 1]),
            duration_s=float(speeds.duration[k]) if known else None,
            actuator_speed_peak=_finite(float(speeds.speed_peak[k])) if known else None,
            speed_ok=speeds.speed_ok[k],
            feed_max_mm_min=None if rotary or math.isnan(feed_max) else _finite(per_minute),
        )
        if rotary:
            segment["feed_deg_min"] = rotary_feed / DEG_MIN if known else None
            segment["feed_max_deg_min"] = None if math.isnan(feed_max) else _finite(per_minute)
        else:
            segment["feed_mm_min"] = float(feed[k]) / MM_MIN if known else None
        if not known:
            segment["speed_note"] = "no feed for this move: no duration, no speed verdict"
        elif not math.isfinite(float(speeds.speed_peak[k])):
            segment["speed_note"] = (
                "actuator speed unbounded: a leg has no inverse-kinematics solution or a "
                "transmission |τ| of 0 on this move (see the ik and transmission constraints)"
            )
    if part.lines is not None:
        for k, waypoint in enumerate(document["waypoints"]):
            waypoint["line"] = int(part.lines[k])
    document["tool"] = tool_json(part.tool)
    document["first_waypoint"] = part.first
    call = _part_call(model, part, cell, result, baseline, tolerance, options, feeds, speeds, feed)
    return result, document, call


def _part_call(
    model: Manipulator,
    part: _Part,
    cell: CellFrames,
    result: PathCheck | TorsionPlan,
    baseline: PathCheck | None,
    tolerance: float,
    options: argparse.Namespace,
    rates: tuple[float, float],
    speeds: FeedLimits,
    feed: NDArray[np.float64],
) -> tuple[dict[str, Any], dict[str, Any]]:
    """One part as the ``~/check_path`` call the node would answer the same way: poses in the
    base frame, the part's feeds (mm/min), rapid flags and curved moves (arcs, Bézier), the
    speeds and frames in the response."""
    from ..logs import paths as path_fields
    from ..logs.cell import cell_frames_fields, segment_speed_fields, slow_moves_clause

    rapid_feed, rotary_feed = rates
    if isinstance(result, TorsionPlan):  # tool axes: psi = 0 poses, the torsion planned
        angles = np.column_stack([result.directions, np.zeros(len(part.positions))])
        max_dpsi = (
            None
            if options.max_dpsi_deg is None
            else _degrees_flag(options.max_dpsi_deg, "--max-dpsi-deg")
        )
        psi_step = _degrees_flag(options.psi_step_deg, "--psi-step-deg")
    else:
        assert part.degrees is not None
        angles, max_dpsi, psi_step = degrees_to_radians(part.degrees), None, 0.0
    request = path_fields.check_path_request_fields(
        part.positions,
        matrix_to_quaternion(tt_to_matrix(angles)),
        free_torsion=isinstance(result, TorsionPlan),
        interpolation=options.interpolation,
        tolerance=tolerance,
        max_dpsi=max_dpsi,
        psi_step=psi_step,
    )
    request.update(
        header={"stamp": {"sec": 0, "nanosec": 0}, "frame_id": model.frame_id},
        feeds_mm_min=(part.feeds[1:] / MM_MIN).tolist(),
        rapid=[bool(r) for r in part.rapid[1:]],
        rapid_feed_mm_min=0.0 if math.isnan(rapid_feed) else rapid_feed / MM_MIN,
        rotary_feed_deg_min=0.0 if math.isnan(rotary_feed) else rotary_feed / DEG_MIN,
        # the curved moves (CIRCLE, NURBS spans), base frame, flattened one row per move
        arcs=[] if part.arcs is None else part.arcs.ravel().tolist(),
        beziers=[] if part.beziers is None else part.beziers.ravel().tolist(),
    )
    response = path_fields.check_path_response_fields(
        result, pairs=model.leg_diameter > 0.0, baseline=baseline
    )
    moves = len(speeds.duration)
    clause = slow_moves_clause(speeds)
    if clause:  # the node's answer to the same request says so too
        response.update(ok=False, message=response["message"] + clause)
    response.update(
        speeds=segment_speed_fields(
            speeds, part.rapid[1:], feed, np.where(speeds.rotary, rotary_feed, math.nan)
        ),
        actuator_speed_max=cell.actuator_speed_max.tolist(),
        frames=cell_frames_fields(replace(cell, tool=part.tool), model.frame_id),
    )
    assert len(response["speeds"]) == moves
    return request, response


def _finite(value: float) -> float | None:
    """JSON has no infinity: a move that moves no limited actuator has no feed limit (null)."""
    return value if math.isfinite(value) else None


def _speed_summary(
    documents: list[dict[str, Any]], limits: NDArray[np.float64], unit: str
) -> dict[str, Any]:
    slow, without = [], 0
    for document in documents:
        for segment in document["segments"]:
            if segment["speed_ok"] is False:
                slow.append(
                    {
                        "part": documents.index(document),
                        "segment": segment["index"],
                        "actuator_speed_peak": segment["actuator_speed_peak"],
                        "feed_max_mm_min": segment["feed_max_mm_min"],
                        "feed_max_deg_min": segment.get("feed_max_deg_min"),
                    }
                )
            without += segment["duration_s"] is None
    return {
        "actuator_unit": unit,
        "actuator_speed_max": limits.tolist(),
        "limited": bool(np.any(limits > 0.0)),
        "moves_to_slow_down": slow,
        "moves_without_feed": without,
        "covers": SPEED_COVERAGE,
    }


def read_cell_inputs(
    options: argparse.Namespace, err: IO[str]
) -> tuple[Manipulator, CellFrames, str, tuple[float, float], list[_Part], CLProgram | None]:
    """What ``check-path`` and ``schedule`` read: the platform frame's model (each part's tool
    model is built from it), the cell, the frame of the file, the rapid and rotary feeds (m/s,
    rad/s; NaN: not given) and the file's parts (with ``--feed-mm-min`` where no feed is
    programmed) and CL program."""
    platform = configured_manipulator(options.config, None, err, with_tool=False)
    cell = cell_from_params_file(options.config or example_config_path())
    frame = options.frame or ("work" if is_cl_file(options.file) else "base")
    feed = _positive(options.feed_mm_min, "--feed-mm-min", "mm/min") * MM_MIN
    rapid = _positive(options.rapid_feed_mm_min, "--rapid-feed-mm-min", "mm/min") * MM_MIN
    rotary = _positive(options.rotary_feed_deg_min, "--rotary-feed-deg-min", "deg/min") * DEG_MIN
    parts, program = _read_parts(options, cell, frame, feed)
    return platform, cell, frame, (rapid, rotary), parts, program


def cmd_check_cell_path(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``check-path`` for CL files, frames and feeds (see the module documentation)."""
    record = (
        None
        if options.record is None
        else output_file(options.record, "--record", force=options.force, suffixes=(".mcap",))
    )
    plot = (
        None
        if options.plot is None
        else output_file(options.plot, "--plot", force=options.force, suffixes=PLOT_FORMATS)
    )
    platform, cell, frame, (rapid, rotary), parts, program = read_cell_inputs(options, err)
    results, documents, calls = [], [], []
    for part in parts:
        result, document, call = _check_part(platform, part, cell, options, (rapid, rotary))
        calls.append(call)
        if frame == "work":
            _to_frame(document, cell.work)
        results.append(result)
        documents.append(document)
    unit = ACTUATOR_MODELS[platform.architecture].unit
    speed = _speed_summary(documents, cell.actuator_speed_max, unit)
    ok = all(d["ok"] for d in documents) and not speed["moves_to_slow_down"]
    common: dict[str, Any] = {
        "frame": frame,
        "work_frame": work_json(cell.work),
        "passed_over": {} if program is None else {n: c for n, _, c in program.passed_over},
        "speed": speed,
    }
    if program is not None:
        common["cl_units"] = {"unit": program.units, "source": program.units_source}
        common["cl_frames"] = [
            {"line": line, "origin": origin.tolist(), "rotation": rotation.tolist()}
            for line, origin, rotation in program.frames
        ]
        common["cl_splines"] = [{"line": line, "moves": moves} for line, moves in program.splines]
    if len(documents) == 1:
        report: dict[str, Any] = {**documents[0], **common, "ok": ok}
    else:
        report = {"ok": ok, **common, "parts": documents}
    if plot is not None:
        plot_speeds(documents, speed, plot)
    if record is not None:  # one ~/check_path call per part (tool), in the base frame
        written = record_path_calls(record, calls)
        err.write(f"{PROG}: recorded the path check ({len(calls)} call(s)) to {written}\n")
    if options.json:
        out.write(json.dumps(report, allow_nan=False) + "\n")
    else:
        if plot is not None:
            out.write(f"  plot: {plot}\n")
        for k, (result, document) in enumerate(zip(results, documents, strict=True)):
            tool = document["tool"]
            name = f"T{tool['number']}" if tool["number"] else "tool.*"
            if len(documents) > 1:
                out.write(f"part {k} (tool {name}, from waypoint {document['first_waypoint']}):\n")
            _text(result, document, out)
        speed_text(report, out)
    if ok:
        return 0
    problems = [
        _where(document, result)
        for result, document in zip(results, documents, strict=True)
        if not document["ok"]
    ]
    if speed["moves_to_slow_down"]:
        problems.append(f"{len(speed['moves_to_slow_down'])} move(s) must slow down")
    err.write(f"{PROG}: {'; '.join(problems)}\n")
    return 1
