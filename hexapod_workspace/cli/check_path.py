"""``hexapod-workspace check-path FILE``: certified check of a path, or torsion planning.

The CSV file has a header row. Columns ``x,y,z,phi_deg,theta_deg,psi_deg`` (m, degrees) give a
fixed orientation per waypoint (or the columns of another convention, ``u_deg,v_deg,w_deg``,
``a_deg,b_deg,c_deg``, ``rx_deg,ry_deg,rz_deg``, ``qx,qy,qz,qw``: ``--angles``, echoed as given
beside the T&T angles); columns ``x,y,z,i,j,k`` give a tool axis (approach vector, any
non-zero length) and the torsion is then planned (:func:`hexapod_workspace.plan_torsion`).
Columns are read by name, in any order; angles may be in radians (``phi_rad``), positions in
millimetres (``x_mm``). Blank lines and lines starting with ``#`` are skipped; rules and errors
as for every CSV file the CLI reads (:mod:`.tables`).

Exit codes: 0 the whole path runs, 1 it does not (where, on stderr), 2 bad input (one line on
stderr).
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from ..core.base.rotations import matrix_to_quaternion, tt_to_matrix
from ..core.model.manipulator import Manipulator
from ..core.motions import (
    DEFAULT_PATH_TOLERANCE,
    DEFAULT_PLAN_PSI_STEP,
    INTERPOLATIONS,
    PathCheck,
    TorsionPlan,
    check_path,
    plan_torsion,
    reported_parts,
)
from ..core.motions.baseline import psi_zero_baseline, reported_baseline
from ..errors import InputError
from .commands import PROG
from .inputs import (
    PLOT_FORMATS,
    GivenPoses,
    add_angles_option,
    configured_manipulator,
    finite,
    given_poses,
    output_file,
    plausible_positions,
)
from .reports import write_json
from .tables import (
    LENGTH_UNITS,
    ORIENTATION_QUANTITIES,
    PLAIN,
    Columns,
    conventions_text,
    orientation_columns,
    parse_table,
)

if TYPE_CHECKING:
    from matplotlib.projections.polar import PolarAxes

__all__ = [
    "CHECK_PATH_DESCRIPTION",
    "CHECK_PATH_HELP",
    "PathFile",
    "check_path_arguments",
    "cmd_check_path",
    "path_to_json",
    "plot_path",
    "psi_zero_baseline",
    "read_path_file",
    "record_path",
    "record_path_calls",
]

_POSITION = ("x", "y", "z")
_AXIS = ("i", "j", "k")
#: The columns of a path file: positions in m (or mm), the orientation of one convention
#: (angles in degrees or radians, quaternions unitless), or tool axes.
PATH_COLUMNS = Columns(
    {
        **dict.fromkeys(_POSITION, LENGTH_UNITS),
        **ORIENTATION_QUANTITIES,
        **dict.fromkeys(_AXIS, PLAIN),
    },
    expected=f"x, y, z (or x_m, x_mm, ...); {conventions_text()}; or i, j, k",
)


@dataclass(frozen=True)
class PathFile:
    """The waypoints of a path file.

    Attributes
    ----------
    positions : ndarray, shape (N, 3)
        m, base frame.
    degrees : ndarray, shape (N, 3) or None
        (φ, θ, ψ) in degrees (fixed orientations): as written for T&T columns, else converted
        from the convention the columns name.
    axes : ndarray, shape (N, 3) or None
        Tool axes (free torsion).
    given : GivenPoses or None
        The fixed orientations as written, in their convention.
    """

    positions: NDArray[np.float64]
    degrees: NDArray[np.float64] | None
    axes: NDArray[np.float64] | None
    given: GivenPoses | None = None

    @property
    def free_torsion(self) -> bool:
        return self.axes is not None


def read_path_file(path: str | Path, angles: str | None = None) -> PathFile:
    """Read a path CSV (see the module documentation; rules: :mod:`.tables`).

    Parameters
    ----------
    path : str or pathlib.Path
    angles : str, optional
        The convention ``--angles`` names; columns of another convention are refused.

    Raises
    ------
    InputError
        Unreadable file, missing or unknown columns, the columns of two conventions or of
        another convention than ``angles``, non-numbers, NaN or infinite values, fewer than 2
        waypoints; every line error names the line of the file.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        msg = f"cannot read path file {path}: {error.strerror or error}"
        raise InputError(msg) from error
    except UnicodeDecodeError as error:
        msg = f"path file {path} is not text"
        raise InputError(msg) from error
    table = parse_table(text, f"path file {path}", None, rows_name="waypoints")
    columns = PATH_COLUMNS.read(table)
    given = set(columns)
    bad_header = (
        f"path file {path}, line {table.header_line}: expected a header "
        f"x,y,z,phi_deg,theta_deg,psi_deg (or phi_rad, ..., or another convention's columns: "
        f"u_deg,v_deg,w_deg, qx,qy,qz,qw, ...) or x,y,z,i,j,k, got "
        f"{','.join(table.header or [])}"
    )
    orientation = orientation_columns(table, columns, angles, incomplete=bad_header)
    has_axis = set(_AXIS) <= given
    if (
        not set(_POSITION) <= given
        or (orientation is None) != has_axis
        or (orientation is not None and set(_AXIS) & given)
    ):
        raise InputError(bad_header)
    if table.values.shape[0] < 2:
        msg = f"path file {path}: expected at least 2 waypoints, got {table.values.shape[0]}"
        raise InputError(msg)
    positions = np.column_stack([columns[n] for n in _POSITION])
    if orientation is not None:
        poses = given_poses(orientation[1], orientation[0], f"path file {path}")
        return PathFile(positions, poses.tt_degrees(), None, poses)
    return PathFile(positions, None, np.column_stack([columns[n] for n in _AXIS]))


# ---------------------------------------------------------------------------- JSON
def _number(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def _no_plan_reason(plan: TorsionPlan) -> str:
    """Why a plan that is not ok found no torsion (its break point says)."""
    return plan.breakpoint.reason if plan.breakpoint is not None else "no break point recorded"


def path_to_json(
    result: PathCheck | TorsionPlan,
    baseline: PathCheck,
    degrees: NDArray[np.float64] | None = None,
    given: GivenPoses | None = None,
) -> dict[str, Any]:
    """The JSON document of a path check or a torsion plan (documented keys, degrees).

    Parameters
    ----------
    result : PathCheck or TorsionPlan
        A plan without a solution reports the ψ = 0 poses with ``"plan": {"found": false}``.
    baseline : PathCheck
        The ψ ≡ 0 path (:func:`psi_zero_baseline`, or ``plan.baseline``).
    degrees : ndarray, shape (N, 3), optional
        The fixed orientations in T&T degrees as the user wrote them (reported as given).
    given : GivenPoses, optional
        Fixed orientations written in another convention than T&T: each waypoint starts with
        them (``u_deg, v_deg, w_deg``, ``qx, ..., qw``), and the document says ``angles``.
    """
    path, plan = reported_parts(result)
    waypoints, segments = path.waypoints, path.segments
    angles_deg = np.degrees(waypoints.angles) if degrees is None else degrees
    violated = waypoints.violated
    names = list(waypoints.margins)  # the constraints of the model's architecture
    scene = "collision" in waypoints.margins  # a collision scene is declared
    margins = {name: waypoints.margins[name].tolist() for name in names}
    echo = given is not None and not given.is_tt
    own = (
        [dict(zip(given.keys, row, strict=True)) for row in given.values.tolist()]
        if given is not None and echo
        else [{}] * len(waypoints)
    )
    document: dict[str, Any] = {
        **({"angles": given.convention} if given is not None and echo else {}),
        "ok": bool(path.ok and (plan is None or plan.ok)),
        "planned_torsion": plan is not None,
        "interpolation": path.interpolation,
        "tolerance_deg": math.degrees(path.tolerance),
        "waypoints": [
            {
                "index": k,
                "position": waypoints.positions[k].tolist(),
                **own[k],
                "phi_deg": float(angles_deg[k, 0]),
                "theta_deg": float(angles_deg[k, 1]),
                "psi_deg": float(angles_deg[k, 2]),
                "reachable": bool(waypoints.reachable[k]),
                "violated": violated[k],
                "margins": {name: _number(margins[name][k]) for name in names},
                "limiting_leg": int(waypoints.limiting_leg[k]),
                "relative_margin": _number(waypoints.relative[k]),
                **({"collision_pair": waypoints.collision_pair[k]} if scene else {}),
            }
            for k in range(len(waypoints))
        ],
        "segments": [_segment_json(segments, k) for k in range(len(segments))],
    }
    if path.arcs is not None:  # CIRCLE moves: where each one runs (base frame, m)
        for k, segment in enumerate(document["segments"]):
            row = path.arcs[k]
            segment["arc"] = (
                {
                    "centre": row[:3].tolist(),
                    "axis": row[3:6].tolist(),
                    "angle_deg": math.degrees(float(row[6])),
                }
                if math.isfinite(float(row[0]))
                else None
            )
    if path.beziers is not None:  # NURBS spans: the inner control points (base frame, m)
        for k, segment in enumerate(document["segments"]):
            inner = path.beziers[k]
            segment["bezier"] = (
                {"control_points": [inner[:3].tolist(), inner[3:].tolist()]}
                if math.isfinite(float(inner[0]))
                else None
            )
    document["psi_zero_baseline"] = {
        "waypoints_failed": baseline.failed_waypoints,
        "segments_failed": baseline.failed_segments,
    }
    if plan is not None:
        broken = plan.breakpoint
        document["plan"] = {
            "found": plan.ok,
            "objective": plan.objective if plan.ok else None,
            "psi_step_deg": math.degrees(plan.psi_step),
            "max_dpsi_deg": None if plan.max_dpsi is None else math.degrees(plan.max_dpsi),
            "moves_checked": plan.moves_checked,
            "breakpoint": None
            if broken is None
            else {
                "kind": broken.kind,
                "index": broken.index,
                "constraints": broken.constraints,
                "reason": broken.reason,
            },
            "elapsed_s": plan.elapsed,
        }
    return document


def _segment_json(segments: Any, k: int) -> dict[str, Any]:
    ok = bool(segments.ok[k])
    return {
        "index": k,
        "ok": ok,
        "first_violation_s": None if ok else float(segments.first_violation_s[k]),
        "first_violation_pose_deg": None
        if ok
        else np.degrees(segments.violation_angles[k]).tolist(),
        "position_at_violation": None if ok else segments.violation_positions[k].tolist(),
        "violated": segments.violated[k],
        "limiting_leg": int(segments.limiting_leg[k]),
        "min_relative_margin": _number(segments.min_relative_margin[k]),
        "min_at_s": float(segments.min_at_s[k]),
        "min_relative_margin_bound": _number(segments.min_relative_margin_bound[k]),
        **(
            {"collision_pair": None if ok else segments.collision_pair[k]}
            if len(segments.collision_pair)
            else {}
        ),
    }


# ---------------------------------------------------------------------------- text
def _limited_by(entry: dict[str, Any]) -> str:
    """What limits a waypoint or move: "leg 3", the collision pair ("tool vs leg 4") when
    collision limits (no leg then), or both when collision is violated besides the leg."""
    pair = entry.get("collision_pair")
    leg = f"leg {entry['limiting_leg']}" if entry["limiting_leg"] else ""
    named = pair if pair and "collision" in entry["violated"] else ""
    return ", ".join(part for part in (leg, named) if part) or f"leg {entry['limiting_leg']}"


def _text(result: PathCheck | TorsionPlan, document: dict[str, Any], out: IO[str]) -> None:
    plan = result if isinstance(result, TorsionPlan) else None
    waypoints, segments = document["waypoints"], document["segments"]
    mode = "tool axes, torsion planned" if plan is not None else "fixed orientations"
    arcs = sum(1 for segment in segments if segment.get("arc") is not None)
    mode += f"; {arcs} of them arcs, checked along the arc" if arcs else ""
    curves = sum(1 for segment in segments if segment.get("bezier") is not None)
    mode += f"; {curves} of them Bézier curves, checked along the curve" if curves else ""
    out.write(
        f"path: {len(waypoints)} waypoints, {len(segments)} moves ({mode}), "
        f"{document['interpolation']}, tolerance {document['tolerance_deg']:.3g} deg\n"
    )
    if plan is not None:
        if plan.ok and plan.psi is not None:
            psi = np.degrees(plan.psi)
            out.write(
                f"  planned torsion: {psi.min():.1f} .. {psi.max():.1f} deg "
                f"(grid {math.degrees(plan.psi_step):g} deg), smallest certified relative "
                f"margin {plan.objective:.3f}, {plan.elapsed:.2f} s\n"
            )
        else:
            out.write(f"  no plan: {_no_plan_reason(plan)}\n")
    failing_w = [w for w in waypoints if not w["reachable"]]
    failing_s = [s for s in segments if not s["ok"]]
    sampled = [s["min_relative_margin"] for s in segments if s["ok"]]
    bounds = [s["min_relative_margin_bound"] for s in segments if s["ok"]]
    out.write(
        f"  waypoints reachable: {len(waypoints) - len(failing_w)}/{len(waypoints)}; "
        f"moves ok: {len(segments) - len(failing_s)}/{len(segments)}"
        + (
            f"; smallest relative margin on ok moves {min(sampled):.3f} sampled, "
            f">= {min(bounds):.3f} certified\n"
            if sampled
            else "\n"
        )
    )
    for w in failing_w[:10]:
        out.write(
            f"  waypoint {w['index']}: unreachable ({', '.join(w['violated'])}, {_limited_by(w)})\n"
        )
    for s in failing_s[:10]:
        phi, theta, psi = s["first_violation_pose_deg"]
        out.write(
            f"  move {s['index']}: leaves the workspace at s = {s['first_violation_s']:.5f} "
            f"(phi {phi:.2f}, theta {theta:.2f}, psi {psi:.2f} deg): "
            f"{', '.join(s['violated'])}, {_limited_by(s)}\n"
        )
    baseline = document["psi_zero_baseline"]
    out.write(
        f"  psi = 0 baseline: {len(baseline['waypoints_failed'])} waypoints and "
        f"{len(baseline['segments_failed'])} moves fail\n"
    )


def _where(document: dict[str, Any], result: PathCheck | TorsionPlan) -> str:
    """Where the path fails, one line for stderr."""
    if isinstance(result, TorsionPlan) and not result.ok:
        return f"no torsion plan: {_no_plan_reason(result)}"
    waypoints = [w["index"] for w in document["waypoints"] if not w["reachable"]]
    moves = [s for s in document["segments"] if not s["ok"]]
    parts = []
    if waypoints:
        shown = ", ".join(map(str, waypoints[:10])) + (", ..." if len(waypoints) > 10 else "")
        parts.append(f"{len(waypoints)} unreachable waypoint(s): {shown}")
    if moves:
        first = moves[0]
        parts.append(
            f"{len(moves)} move(s) leave the workspace, first move {first['index']} at "
            f"s = {first['first_violation_s']:.5f} ({', '.join(first['violated'])})"
        )
    return "path does not run: " + "; ".join(parts)


# ---------------------------------------------------------------------------- plot
def plot_path(
    result: PathCheck | TorsionPlan,
    baseline: PathCheck,
    manipulator: Manipulator,
    path: str | Path,
) -> Path:
    """Margins along the path, the torsion profile, and the tool directions over the projected
    workspace at the path's mean position.

    Parameters
    ----------
    result : PathCheck or TorsionPlan
    baseline : PathCheck
        The ψ ≡ 0 path.
    manipulator : Manipulator
    path : str or Path
        PNG file.
    """
    figure = path_figure(result, baseline, manipulator)
    path = Path(path)
    figure.savefig(path, dpi=120, bbox_inches="tight")
    return path


def path_figure(
    result: PathCheck | TorsionPlan, baseline: PathCheck, manipulator: Manipulator
) -> Any:
    """The figure of :func:`plot_path` (a :class:`matplotlib.figure.Figure`), not saved."""
    from matplotlib.figure import Figure

    from ..core.workspaces.projected import projected_workspace
    from .plotting import label_rings

    checked, plan = reported_parts(result)
    waypoints = checked.waypoints
    count = len(waypoints)
    index = np.arange(count)
    figure = Figure(figsize=(12.0, 6.0))
    grid = figure.add_gridspec(2, 2, width_ratios=[1.35, 1.0], height_ratios=[1.6, 1.0])
    margins_axes = figure.add_subplot(grid[0, 0])
    torsion_axes = figure.add_subplot(grid[1, 0], sharex=margins_axes)
    label = "planned torsion" if plan is not None and plan.ok else "as given"
    margins_axes.plot(index, waypoints.relative, color="tab:blue", lw=1.4, label=f"{label}")
    segment_x = index[:-1] + checked.segments.min_at_s
    margins_axes.plot(
        segment_x,
        checked.segments.min_relative_margin_bound,
        color="tab:blue",
        lw=0.0,
        marker=".",
        ms=3,
        alpha=0.6,
        label=f"{label}: certified minimum of each move",
    )
    margins_axes.plot(
        index, baseline.waypoints.relative, color="tab:red", lw=1.2, ls="--", label="ψ ≡ 0"
    )
    failed = np.asarray(baseline.failed_waypoints, dtype=int)
    if failed.size:
        margins_axes.plot(
            failed,
            baseline.waypoints.relative[failed],
            "x",
            color="tab:red",
            ms=4,
            label=f"ψ ≡ 0: {failed.size} unreachable waypoints",
        )
    own_failed = np.asarray(checked.failed_waypoints, dtype=int)
    if own_failed.size:
        margins_axes.plot(
            own_failed,
            waypoints.relative[own_failed],
            "o",
            color="black",
            ms=4,
            label=f"{label}: {own_failed.size} unreachable waypoints",
        )
    margins_axes.axhline(0.0, color="black", lw=0.8)
    margins_axes.set_ylabel("smallest relative margin")
    margins_axes.set_title("Margins along the path (< 0: a constraint is violated)", fontsize=10)
    margins_axes.legend(fontsize=7, loc="best")
    margins_axes.grid(alpha=0.3)
    margins_axes.tick_params(labelbottom=False)
    torsion_axes.plot(
        index, np.degrees(waypoints.angles[:, 2]), color="tab:blue", lw=1.4, label=label
    )
    torsion_axes.axhline(0.0, color="tab:red", lw=1.2, ls="--", label="ψ ≡ 0")
    torsion_axes.set_xlabel("waypoint (a move k spans k .. k + 1)")
    torsion_axes.set_ylabel("torsion ψ [deg]")
    torsion_axes.legend(fontsize=7, loc="best")
    torsion_axes.grid(alpha=0.3)

    polar = cast("PolarAxes", figure.add_subplot(grid[:, 1], projection="polar"))
    center = waypoints.positions.mean(axis=0)
    at_center = manipulator.with_position(center)
    drawn = []  # (phi deg, theta deg) of everything on the polar plot, for the ring labels
    for method, color, style in (("torsion_zero", "tab:red", "--"), ("exact", "tab:green", "-")):
        try:
            workspace = projected_workspace(at_center, method=method, n_phi=180, tolerance=1e-4)
        except Exception:  # an empty workspace at the mean position: nothing to draw
            continue
        drawn.append((np.degrees(workspace.phi), np.degrees(workspace.theta)))
        polar.plot(
            np.append(workspace.phi, workspace.phi[0]),
            np.degrees(np.append(workspace.theta, workspace.theta[0])),
            color=color,
            ls=style,
            lw=1.3,
            label="projected workspace, ψ = 0"
            if method == "torsion_zero"
            else "projected workspace, best ψ",
        )
    phi, theta = waypoints.angles[:, 0], np.degrees(waypoints.angles[:, 1])
    good = waypoints.reachable
    polar.plot(phi[good], theta[good], ".", color="tab:blue", ms=3, label="tool directions")
    if failed.size:
        polar.plot(
            phi[failed], theta[failed], "x", color="tab:red", ms=4, label="unreachable with ψ ≡ 0"
        )
    drawn.append((np.degrees(phi), theta))
    label_rings(polar, drawn)  # every ring labelled, no label over a curve or a direction
    spread = np.ptp(waypoints.positions, axis=0).max()
    polar.set_title(
        "Tool directions: tilt θ [deg] vs azimuth φ\nworkspace at the mean position "
        f"({center[0]:.3f}, {center[1]:.3f}, {center[2]:.3f}) m; path spans {spread * 1e3:.0f} mm",
        fontsize=9,
    )
    polar.legend(loc="lower center", bbox_to_anchor=(0.5, -0.24), fontsize=7)
    figure.tight_layout()
    return figure


# ---------------------------------------------------------------------------- record
def record_path(
    path: str | Path,
    result: PathCheck | TorsionPlan,
    request: dict[str, Any],
    *,
    pairs: bool = True,
    stamp_ns: int | None = None,
    baseline: PathCheck | None = None,
) -> Path:
    """Record a path check as a ``~/check_path`` call (request, then response) in MCAP.

    Parameters
    ----------
    path : str or Path
        The ``.mcap`` file (replaced).
    result : PathCheck or TorsionPlan
    request : dict
        CheckPath_Request fields (:func:`hexapod_workspace.logs.paths.check_path_request_fields`).
    pairs : bool
        The interference check is enabled.
    stamp_ns : int, optional
        Log time of the request, ns since the epoch (default now).
    baseline : PathCheck, optional
        The ψ = 0 baseline of a path of fixed orientations
        (:func:`~hexapod_workspace.core.motions.baseline.psi_zero_baseline`).
    """
    from ..logs import paths as path_fields

    response = path_fields.check_path_response_fields(result, pairs=pairs, baseline=baseline)
    return record_path_calls(path, [(request, response)], stamp_ns=stamp_ns)


def record_path_calls(
    path: str | Path,
    calls: list[tuple[dict[str, Any], dict[str, Any]]],
    *,
    stamp_ns: int | None = None,
) -> Path:
    """Record ``~/check_path`` calls (CheckPath_Request and _Response fields, in order) in MCAP,
    1 µs apart, starting at ``stamp_ns`` (default now)."""
    from ..logs import SERVICE_QOS, LogWriter, recorded_type, service_topics
    from ..logs import paths as path_fields

    stamp = time.time_ns() if stamp_ns is None else int(stamp_ns)
    request_topic, response_topic = service_topics(path_fields.CHECK_PATH_TOPIC)
    with LogWriter(path, flush_interval=0, flush_messages=1) as writer:
        for request, response in calls:
            writer.write_fields(
                request_topic,
                recorded_type(f"{path_fields.CHECK_PATH_TYPE}_Request"),
                request,
                stamp,
                qos=SERVICE_QOS,
            )
            writer.write_fields(
                response_topic,
                recorded_type(f"{path_fields.CHECK_PATH_TYPE}_Response"),
                response,
                stamp + 1_000,
                qos=SERVICE_QOS,
            )
            stamp += 2_000
    return Path(path)


# ---------------------------------------------------------------------------- command
def cmd_check_path(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``check-path``: certified check of the path in FILE, or torsion planning."""
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
    manipulator = configured_manipulator(options.config, None, err)
    waypoints = read_path_file(options.file, options.angles)
    plausible_positions(manipulator, waypoints.positions, f"path file {options.file}: x,y,z")
    tolerance = (
        DEFAULT_PATH_TOLERANCE
        if options.tol_deg is None
        else _degrees_flag(options.tol_deg, "--tol-deg")
    )
    max_dpsi = (
        None
        if options.max_dpsi_deg is None
        else _degrees_flag(options.max_dpsi_deg, "--max-dpsi-deg")
    )
    psi_step = _degrees_flag(options.psi_step_deg, "--psi-step-deg")
    result: PathCheck | TorsionPlan
    if waypoints.axes is not None:  # free torsion
        result = plan_torsion(
            manipulator,
            waypoints.positions,
            waypoints.axes,
            psi_step=psi_step,
            max_dpsi=max_dpsi,
            interpolation=options.interpolation,
            tolerance=tolerance,
        )
        degrees = None
        orientation = np.column_stack([result.directions, np.zeros(len(waypoints.positions))])
    else:
        assert waypoints.given is not None  # read_path_file gives axes or angles
        # T&T: exact for any finite degrees; another convention: through its matrix.
        orientation = waypoints.given.radians()
        result = check_path(
            manipulator,
            waypoints.positions,
            angles=orientation,
            interpolation=options.interpolation,
            tolerance=tolerance,
        )
        degrees = waypoints.degrees
    baseline = reported_baseline(manipulator, result)
    document = path_to_json(result, baseline, degrees, waypoints.given)
    document["frame"] = "base"
    if record is not None:
        from ..logs.paths import check_path_request_fields

        request = check_path_request_fields(
            waypoints.positions,
            matrix_to_quaternion(tt_to_matrix(orientation)),
            free_torsion=waypoints.free_torsion,
            interpolation=options.interpolation,
            tolerance=tolerance,
            max_dpsi=max_dpsi,
            psi_step=psi_step if waypoints.free_torsion else 0.0,
        )
        written = record_path(
            record, result, request, pairs=manipulator.leg_diameter > 0.0, baseline=baseline
        )
        err.write(f"{PROG}: recorded the path check to {written}\n")
    scene_plot = None
    if plot is not None:
        plot_path(result, baseline, manipulator, plot)
        from .scene import plot_first_violation  # the machine at the first violation

        scene_plot = plot_first_violation(
            result, manipulator, options.config, plot, force=options.force
        )
    if options.json:
        write_json(document, out)
    else:
        _text(result, document, out)
        if plot is not None:
            out.write(f"  plot: {plot}\n")
        if scene_plot is not None:
            out.write(f"  scene at the first violation: {scene_plot}\n")
    if document["ok"]:
        return 0
    err.write(f"{PROG}: {_where(document, result)}\n")
    return 1


def _degrees_flag(value: float, flag: str) -> float:
    """A finite number of degrees from ``flag``, in rad (the core checks its range)."""
    return math.radians(float(finite([value], flag, "degrees")[0]))


CHECK_PATH_HELP = (
    "check a path (every waypoint and every move, certified), or plan the torsion "
    "for tool axes (exit 0 runs, 1 does not, 2 bad input)"
)
CHECK_PATH_DESCRIPTION = (
    "FILE is a CSV with a header: x,y,z,phi_deg,theta_deg,psi_deg (m, deg) "
    "for fixed orientations, or x,y,z,i,j,k for tool axes (the torsion is then planned: "
    "largest smallest margin on a psi grid). Between waypoints the position is linear and "
    "the orientation follows the interpolation; every move is checked with Lipschitz "
    "bounds, so no violation wider than the tolerance is missed. Positions come from FILE. "
    "FILE may also be an APT cutter-location file (CLDATA: .cl, .cls, .apt, .ncl, or a file "
    "with GOTO/ lines): GOTO, FEDRAT, RAPID, UNITS, MULTAX, LOADTL (tool table tools.T<n>), "
    "MSYS, CIRCLE arcs and NX's NURBS splines (checked along the curve) and the other "
    "statements of docs/cell.md, each modelled or refused with its line, in the work frame "
    "(work.*); with feeds, every move gets its certified peak actuator "
    "speed against limits.actuator_speed_max and the largest feed within it."
)


def check_path_arguments(sub: argparse.ArgumentParser) -> None:
    """The ``check-path`` command's own options."""
    sub.add_argument("file", metavar="FILE", help="path CSV or APT CL file (see above)")
    sub.add_argument(
        "--interpolation",
        choices=INTERPOLATIONS,
        default="slerp",
        help="orientation between waypoints: shortest rotation at constant rate (slerp, "
        "default) or linear in Tilt-and-Torsion angles",
    )
    sub.add_argument(
        "--max-dpsi-deg",
        type=float,
        metavar="D",
        help="planned torsion: largest change per move, degrees (default: no limit)",
    )
    sub.add_argument(
        "--psi-step-deg",
        type=float,
        default=math.degrees(DEFAULT_PLAN_PSI_STEP),
        metavar="S",
        help="planned torsion: grid step, degrees (default %(default)g); the planner is "
        "complete on this grid",
    )
    add_angles_option(sub)
    sub.add_argument(
        "--tol-deg",
        type=float,
        metavar="T",
        help=f"certified check tolerance, degrees of platform rotation (default "
        f"{math.degrees(DEFAULT_PATH_TOLERANCE):g})",
    )
    sub.add_argument(
        "--plot",
        metavar="FILE.png",
        help="margins along the path and tool directions; a path that does not run also gets "
        "FILE-scene.png, the machine at its first violation with the closest pair",
    )
    sub.add_argument("--record", metavar="FILE", help="also write the check to an MCAP log")
    sub.add_argument(
        "--force",
        action="store_true",
        help="replace an existing --plot/--record file even when it is not one of ours",
    )
