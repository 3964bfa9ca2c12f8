"""Command-line interface ``hexapod-workspace`` (no ROS needed).

The CLI speaks degrees to humans (JSON keys carry the unit: ``theta_deg``) and SI units for
lengths and margins. Each command is a plain function taking parsed options and returning an
exit code; :func:`main` is the thin argparse front end. Exit codes: 0 success (``check``: all
poses reachable), 1 ``check`` found unreachable poses, 2 bad input with a one-line reason on
stderr.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from numpy.typing import NDArray

from .. import __version__
from .._resources import example_config_path
from ..core.constraints import CONSTRAINT_NAMES, CheckResult, check
from ..core.manipulator import Manipulator
from ..core.orientation import OrientationWorkspace, orientation_workspace, torsion_range
from ..core.projected import ProjectedWorkspace, projected_workspace
from ..errors import HexapodWorkspaceError, InputError, UnreachableReferenceError
from .check_path import add_check_path_command

__all__ = ["main", "read_poses_file"]

PROG = "hexapod-workspace"


class CliError(Exception):
    """Bad command-line input: reported as one line on stderr with exit code 2."""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line (no usage dump) and exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise CliError(message)


# ---------------------------------------------------------------------------- helpers
def _finite(values: Sequence[float], what: str) -> NDArray[np.float64]:
    array = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        msg = f"{what}: expected finite numbers, got {array.tolist()}"
        raise CliError(msg)
    return array


class ProgressBar:
    """A one-line progress bar on stderr, drawn only when stderr is a terminal."""

    def __init__(self, label: str, *, stream: TextIO | None = None) -> None:
        self.stream = sys.stderr if stream is None else stream
        self.enabled = bool(getattr(self.stream, "isatty", lambda: False)())
        self.label = label
        self.shown = -1

    def __call__(self, fraction: float) -> None:
        if not self.enabled:
            return
        percent = int(100 * min(max(fraction, 0.0), 1.0))
        if percent == self.shown:
            return
        self.shown = percent
        filled = percent * 30 // 100
        self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (30 - filled)}] {percent:3d}%")
        if percent >= 100:
            self.stream.write("\n")
        self.stream.flush()


def _degrees(values: Any) -> Any:
    """Radians to degrees as plain Python floats (lists for arrays)."""
    converted = np.degrees(values)
    return converted.tolist() if isinstance(converted, np.ndarray) else float(converted)


def _tolerance(options: argparse.Namespace, default_rad: float) -> float:
    if options.tol_deg is None:
        return default_rad
    return math.radians(_finite([options.tol_deg], "--tol-deg")[0])


def _record(options: argparse.Namespace, manipulator: Manipulator, results: list) -> None:
    """Write ``--record FILE`` (rosbag2-form MCAP) when asked."""
    if getattr(options, "record", None):
        from .replay import record_results

        path = record_results(options.record, results, frame_id=manipulator.frame_id)
        print(f"{PROG}: recorded {len(results)} result(s) to {path}", file=sys.stderr)


def _unreachable(error: UnreachableReferenceError, position: Any, options, out: TextIO) -> int:
    """Report an empty workspace: exit 1, the reason on stderr (and in the JSON result)."""
    reason = " ".join(str(error).split())
    if options.json:
        document = {
            "position": np.asarray(position, dtype=float).tolist(),
            "reference_reachable": False,
            "reason": reason,
        }
        out.write(json.dumps(document) + "\n")
    print(f"{PROG}: {reason}", file=sys.stderr)
    return 1


def load_manipulator(options: argparse.Namespace) -> Manipulator:
    """The manipulator of ``--config`` (default: the packaged example), at ``--position``."""
    path = Path(options.config) if options.config else example_config_path()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        manipulator = Manipulator.from_params_file(path)
    for warning in caught:
        print(f"{PROG}: warning: {warning.message}", file=sys.stderr)
    if options.position is not None:
        manipulator = manipulator.with_position(_finite(options.position, "--position"))
    return manipulator


def read_poses_file(path: str | Path) -> NDArray[np.float64]:
    """Read a CSV of poses ``phi_deg,theta_deg,psi_deg`` (degrees), one pose per row.

    A first row that is not numeric is taken as a header; blank lines and lines starting with
    ``#`` are skipped.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    ndarray, shape (N, 3)
        (φ, θ, ψ) in degrees.

    Raises
    ------
    InputError
        Unreadable file, wrong column count, non-numbers, NaN or infinite values, no rows.
    """
    path = Path(path)
    try:
        with path.open("r", encoding="utf-8") as handle:
            first = handle.readline()
    except OSError as error:
        msg = f"cannot read poses file {path}: {error.strerror or error}"
        raise InputError(msg) from error
    except UnicodeDecodeError as error:
        msg = f"poses file {path} is not text"
        raise InputError(msg) from error
    skip = 0
    cells = [cell.strip() for cell in first.split(",")]
    if first.strip() and not first.lstrip().startswith("#"):
        # A header row has no numeric cell; a row with some numbers is data (errors reported).
        numeric = 0
        for cell in cells:
            try:
                float(cell)
                numeric += 1
            except ValueError:
                pass
        skip = 1 if numeric == 0 else 0
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "empty input file": reported below
            poses = np.loadtxt(path, delimiter=",", skiprows=skip, ndmin=2, comments="#")
    except ValueError as error:
        reason = str(error).splitlines()[0]
        msg = f"poses file {path}: expected rows phi_deg,theta_deg,psi_deg ({reason})"
        raise InputError(msg) from error
    except UnicodeDecodeError as error:
        msg = f"poses file {path} is not text"
        raise InputError(msg) from error
    if poses.shape[0] == 0:
        msg = f"poses file {path}: no poses"
        raise InputError(msg)
    if poses.shape[1] != 3:
        msg = (
            f"poses file {path}: expected 3 columns phi_deg,theta_deg,psi_deg, got {poses.shape[1]}"
        )
        raise InputError(msg)
    if not np.all(np.isfinite(poses)):
        row = int(np.flatnonzero(~np.all(np.isfinite(poses), axis=1))[0])
        msg = (
            f"poses file {path}: expected finite numbers, "
            f"row {row + 1 + skip} is {poses[row].tolist()}"
        )
        raise InputError(msg)
    return poses


def _json_number(value: float) -> str:  # value: a Python float
    """JSON text of a float; infinities (a disabled check) become null."""
    return repr(value) if math.isfinite(value) else "null"


# ---------------------------------------------------------------------------- check
def _write_rows(out: TextIO, template: str, columns: Sequence[Sequence[Any]], sep: str) -> None:
    """Write ``template % row`` for the rows of ``columns`` joined by ``sep``, in blocks."""
    block = 65536
    count = len(columns[0])
    for start in range(0, count, block):
        rows = zip(*(column[start : start + block] for column in columns), strict=True)
        text = sep.join([template % row for row in rows])
        out.write(text if start + block >= count else text + sep)


def _violated_masks(result: CheckResult) -> NDArray[np.int64]:
    """Bit k of the mask is set when constraint k of CONSTRAINT_NAMES is violated; shape (N,)."""
    negative = np.stack([result.margins[name] < 0.0 for name in CONSTRAINT_NAMES], axis=1)
    return negative.astype(np.int64) @ (1 << np.arange(len(CONSTRAINT_NAMES)))


def _violated_names(mask: int, sep: str) -> str:
    return sep.join(name for k, name in enumerate(CONSTRAINT_NAMES) if mask >> k & 1)


def check_poses_to_json(
    result: CheckResult, out: TextIO, degrees: NDArray[np.float64] | None = None
) -> None:
    """Write ``{"position": [...], "poses": [...]}`` for a check result, streaming.

    One object per pose in input order with ``phi_deg, theta_deg, psi_deg, reachable,
    violated, margins{...} (SI: m, rad; null when a check is disabled), limiting_leg``.
    Numbers carry 12 significant digits.

    Parameters
    ----------
    result : CheckResult
    out : file-like
    degrees : ndarray, shape (N, 3), optional
        The poses as the user gave them, degrees (default: converted from ``result.angles``).
    """
    degrees = np.degrees(result.angles) if degrees is None else degrees
    violated = np.array(
        [json.dumps(_violated_names(mask, ",").split(",") if mask else []) for mask in range(16)],
        dtype=object,
    )[_violated_masks(result)]
    margins = [
        result.margins[name].tolist()
        if np.all(np.isfinite(result.margins[name]))
        else [_json_number(v) for v in result.margins[name].tolist()]
        for name in CONSTRAINT_NAMES
    ]
    # 12 significant digits: exact to 1e-12 relative, and twice as fast to format as repr().
    margin_fields = ", ".join(
        f'"{name}": {"%.12g" if np.all(np.isfinite(result.margins[name])) else "%s"}'
        for name in CONSTRAINT_NAMES
    )
    template = (
        '{"phi_deg": %.12g, "theta_deg": %.12g, "psi_deg": %.12g, "reachable": %s, "violated": %s, '
        f'"margins": {{{margin_fields}}}, "limiting_leg": %d}}'
    )
    columns = [
        *degrees.T.tolist(),
        np.where(result.reachable, "true", "false").tolist(),
        violated.tolist(),
        *margins,
        result.limiting_leg.tolist(),
    ]
    out.write(f'{{"position": {json.dumps(result.position.tolist())}, "poses": [\n')
    _write_rows(out, template, columns, ",\n")
    out.write("]}\n")


def check_poses_to_table(
    result: CheckResult, out: TextIO, degrees: NDArray[np.float64] | None = None
) -> None:
    """Write a readable table: angles in degrees, margins in mm and degrees.

    Parameters are those of :func:`check_poses_to_json`.
    """
    degrees = np.degrees(result.angles) if degrees is None else degrees
    x, y, z = result.position
    out.write(f"position: ({x:.4f}, {y:.4f}, {z:.4f}) m\n")
    out.write(
        f"{'phi':>9} {'theta':>9} {'psi':>9}  {'reachable':<9}  {'leg_length':>11} "
        f"{'base_joint':>10} {'platform_j':>10} {'interfer.':>10}  {'leg':>3}  violated\n"
        f"{'[deg]':>9} {'[deg]':>9} {'[deg]':>9}  {'':<9}  {'[mm]':>11} {'[deg]':>10} "
        f"{'[deg]':>10} {'[mm]':>10}\n"
    )
    violated = np.array([_violated_names(mask, ",") or "-" for mask in range(16)], dtype=object)
    columns = [
        *degrees.T.tolist(),
        np.where(result.reachable, "yes", "NO").tolist(),
        (result.margins["leg_length"] * 1e3).tolist(),
        np.degrees(result.margins["base_joint"]).tolist(),
        np.degrees(result.margins["platform_joint"]).tolist(),
        (result.margins["leg_interference"] * 1e3).tolist(),
        result.limiting_leg.tolist(),
        violated[_violated_masks(result)].tolist(),
    ]
    template = "%9.3f %9.3f %9.3f  %-9s  %11.3f %10.3f %10.3f %10.3f  %3d  %s"
    _write_rows(out, template, columns, "\n")
    reachable = int(np.count_nonzero(result.reachable))
    out.write(f"\n{reachable}/{len(result)} poses reachable\n")


def cmd_check(options: argparse.Namespace, out: TextIO) -> int:
    """``check``: reachability of poses given with ``--pose`` and/or ``--poses-file``."""
    manipulator = load_manipulator(options)
    parts = []
    if options.pose:
        parts.append(_finite(options.pose, "--pose").reshape(-1, 3))
    if options.poses_file:
        parts.append(read_poses_file(options.poses_file))
    if not parts:
        msg = "check: give at least one --pose PHI THETA PSI or a --poses-file"
        raise CliError(msg)
    degrees = np.concatenate(parts)
    result = check(manipulator, np.radians(degrees))
    _record(options, manipulator, [result])
    if options.json:
        check_poses_to_json(result, out, degrees)
    else:
        check_poses_to_table(result, out, degrees)
    return 0 if bool(np.all(result.reachable)) else 1


# ---------------------------------------------------------------------------- workspaces
def _finish_workspace(
    options: argparse.Namespace,
    out: TextIO,
    manipulator: Manipulator,
    workspace: Any,
    to_json: Callable[[Any], dict[str, Any]],
    to_text: Callable[[Any, TextIO], None],
) -> int:
    """Record (``--record``) and print a computed workspace (JSON or text); exit code 0."""
    _record(options, manipulator, [workspace])
    if options.json:
        out.write(json.dumps(to_json(workspace)) + "\n")
    else:
        to_text(workspace, out)
        if options.plot:
            out.write(f"  plot: {options.plot}\n")
    return 0


def projected_to_json(workspace: ProjectedWorkspace) -> dict[str, Any]:
    """The JSON document of a projected workspace (angles in degrees)."""
    document: dict[str, Any] = {
        "method": workspace.method,
        "position": workspace.position.tolist(),
        "reference_reachable": True,
        "phi_deg": _degrees(workspace.phi),
        "theta_deg": _degrees(workspace.theta),
        "psi_deg": _degrees(workspace.psi),
        "limiting": workspace.limiting,
        "tilt_min_deg": _degrees(workspace.tilt_min),
        "tilt_max_deg": _degrees(workspace.tilt_max),
        "solid_angle_sr": workspace.solid_angle,
        "tolerance_deg": _degrees(workspace.tolerance),
        "elapsed_s": workspace.elapsed,
    }
    if workspace.gap is not None:
        document["torsion_zero_gap_deg"] = _degrees(workspace.gap)
        document["torsion_zero_gap_max_deg"] = _degrees(float(workspace.gap.max()))
        document["torsion_zero_gap_mean_deg"] = _degrees(float(workspace.gap.mean()))
    return document


def _projected_text(workspace: ProjectedWorkspace, out: TextIO) -> None:
    x, y, z = workspace.position
    out.write(
        f"projected orientation workspace ({workspace.method}) at ({x:.4f}, {y:.4f}, {z:.4f}) m\n"
        f"  azimuths: {workspace.n_phi}, tolerance {math.degrees(workspace.tolerance):.2e} deg, "
        f"{workspace.elapsed * 1e3:.1f} ms\n"
        f"  tilt range: {math.degrees(workspace.tilt_min):.4f} .. "
        f"{math.degrees(workspace.tilt_max):.4f} deg\n"
        f"  solid angle of attainable directions: {workspace.solid_angle:.5f} sr\n"
    )
    if workspace.gap is not None:
        worst = int(np.argmax(workspace.gap))
        out.write(
            f"  torsion_zero lies inside by up to {math.degrees(workspace.gap[worst]):.4f} deg "
            f"(phi {math.degrees(workspace.phi[worst]):.1f} deg, "
            f"mean {math.degrees(float(workspace.gap.mean())):.4f} deg)\n"
        )
    step = max(1, workspace.n_phi // 12)
    out.write(f"  {'phi [deg]':>10} {'theta [deg]':>12} {'psi [deg]':>10}  limiting\n")
    for k in range(0, workspace.n_phi, step):
        out.write(
            f"  {math.degrees(workspace.phi[k]):10.2f} {math.degrees(workspace.theta[k]):12.4f} "
            f"{math.degrees(workspace.psi[k]):10.3f}  {workspace.limiting[k] or '-'}\n"
        )


def cmd_projected(options: argparse.Namespace, out: TextIO) -> int:
    """``projected``: the projected orientation workspace (attainable tool directions)."""
    manipulator = load_manipulator(options)
    tolerance = _tolerance(options, 1e-6)
    try:
        workspace = projected_workspace(
            manipulator,
            method=options.method,
            n_phi=options.n_phi,
            tolerance=tolerance,
            progress=ProgressBar(f"projected ({options.method})"),
        )
    except UnreachableReferenceError as error:
        return _unreachable(error, manipulator.position, options, out)
    if options.plot:
        other = "exact" if options.method == "torsion_zero" else "torsion_zero"
        overlay = projected_workspace(
            manipulator,
            method=other,
            n_phi=options.n_phi,
            tolerance=tolerance,
            progress=ProgressBar(f"projected ({other}, for the plot)"),
        )
        from .plotting import plot_projected

        ordered = (
            [workspace, overlay] if workspace.method == "torsion_zero" else [overlay, workspace]
        )
        plot_projected(ordered, options.plot)
    return _finish_workspace(
        options, out, manipulator, workspace, projected_to_json, _projected_text
    )


def orientation_to_json(workspace: OrientationWorkspace) -> dict[str, Any]:
    """The JSON document of a 3-D orientation workspace (angles in degrees)."""
    return {
        "position": workspace.position.tolist(),
        "reference_reachable": True,
        "psi_min_deg": _degrees(workspace.psi_min),
        "psi_max_deg": _degrees(workspace.psi_max),
        "volume": workspace.volume,
        "volume_unit": "rad^3",
        "n_rays": workspace.n_rays,
        "psi_step_deg": _degrees(workspace.psi_step),
        "tolerance_deg": _degrees(workspace.tolerance),
        "slices": [
            {
                "psi_deg": _degrees(piece.psi),
                "center_deg": _degrees(piece.center),
                "phi_deg": _degrees(piece.phi),
                "theta_deg": _degrees(piece.theta),
            }
            for piece in workspace.slices
        ],
        "elapsed_s": workspace.elapsed,
    }


def _orientation_text(workspace: OrientationWorkspace, out: TextIO) -> None:
    x, y, z = workspace.position
    areas = [piece.area() for piece in workspace.slices]
    middle = min(range(len(workspace.slices)), key=lambda k: abs(workspace.slices[k].psi))
    zero = workspace.slices[middle]
    out.write(
        f"orientation workspace at ({x:.4f}, {y:.4f}, {z:.4f}) m\n"
        f"  {len(workspace.slices)} slices of {workspace.n_rays} rays, "
        f"step {math.degrees(workspace.psi_step):g} deg, "
        f"tolerance {math.degrees(workspace.tolerance):.2e} deg, {workspace.elapsed:.2f} s\n"
        f"  torsion range: {math.degrees(workspace.psi_min):.4f} .. "
        f"{math.degrees(workspace.psi_max):.4f} deg\n"
        f"  volume (cylindrical coordinates): {workspace.volume:.5f} rad^3\n"
        f"  psi = 0 slice: tilt {math.degrees(zero.theta.min()):.3f} .. "
        f"{math.degrees(zero.theta.max()):.3f} deg, area {areas[middle]:.5f} rad^2\n"
    )


def cmd_orientation(options: argparse.Namespace, out: TextIO) -> int:
    """``orientation``: the 3-D orientation workspace (ψ slices)."""
    manipulator = load_manipulator(options)
    step = math.radians(_finite([options.psi_step_deg], "--psi-step-deg")[0])
    try:
        workspace = orientation_workspace(
            manipulator,
            n_rays=options.n_rays,
            psi_step=step,
            tolerance=_tolerance(options, 1e-5),
            progress=ProgressBar("orientation"),
        )
    except UnreachableReferenceError as error:
        return _unreachable(error, manipulator.position, options, out)
    if options.plot:
        from .plotting import plot_orientation

        plot_orientation(workspace, options.plot)
    return _finish_workspace(
        options, out, manipulator, workspace, orientation_to_json, _orientation_text
    )


def cmd_torsion_range(options: argparse.Namespace, out: TextIO) -> int:
    """``torsion-range``: feasible torsion intervals for one tool direction."""
    manipulator = load_manipulator(options)
    phi, theta = _finite(options.direction, "--direction")
    found = torsion_range(
        manipulator, math.radians(phi), math.radians(theta), tolerance=_tolerance(options, 1e-6)
    )
    intervals = np.degrees(found.intervals).tolist()
    if options.json:
        document = {"direction_deg": [float(phi), float(theta)], "intervals_deg": intervals}
        out.write(json.dumps(document) + "\n")
    else:
        x, y, z = found.position
        out.write(
            f"torsion range for direction phi {phi:g} deg, theta {theta:g} deg "
            f"at ({x:.4f}, {y:.4f}, {z:.4f}) m\n"
        )
        if not intervals:
            out.write("  no feasible torsion\n")
        for low, high in intervals:
            out.write(f"  psi in [{low:.4f}, {high:.4f}] deg\n")
    return 0 if intervals else 1


def cmd_replay(options: argparse.Namespace, out: TextIO) -> int:
    """``replay``: what a recorded log holds (see :func:`.replay.run_replay`)."""
    from .replay import run_replay

    return run_replay(
        options.log,
        as_json=options.json,
        plot_dir=options.plot,
        publish=options.publish,
        rate=options.rate,
        stdout=out,
    )


def cmd_demo(options: argparse.Namespace, out: TextIO) -> int:
    """``demo``: the example manipulator end to end (see :mod:`hexapod_workspace.cli.demo`)."""
    from .demo import run_demo

    manipulator = load_manipulator(options)
    return run_demo(manipulator, Path(options.out), out=out, as_json=options.json)


# ---------------------------------------------------------------------------- parser
def _add_global_options(parser: argparse.ArgumentParser, *, top: bool) -> None:
    # Global options are accepted before and after the command; after the command they only
    # override what was given before (default SUPPRESS).
    default: Any = None if top else argparse.SUPPRESS
    parser.add_argument(
        "--config",
        metavar="FILE",
        default=default,
        help="ROS 2 parameters file (root key hexapod_workspace or /**); "
        "default: the packaged example GPM",
    )
    parser.add_argument(
        "--position",
        nargs=3,
        type=float,
        metavar=("X", "Y", "Z"),
        default=default,
        help="tool-tip position OC in the base frame, m (default: pose.position)",
    )
    parser.add_argument(
        "--json",
        action="store_true",
        default=False if top else argparse.SUPPRESS,
        help="machine-readable result on stdout (nothing else on stdout)",
    )


def _add_workspace_options(parser: argparse.ArgumentParser, plot_help: str) -> None:
    """Options shared by the workspace commands: tolerance, plot and log."""
    parser.add_argument("--tol-deg", type=float, metavar="T", help="boundary tolerance, degrees")
    parser.add_argument("--plot", metavar="FILE.png", help=plot_help)
    parser.add_argument("--record", metavar="FILE", help="also write the result to an MCAP log")


def build_parser() -> argparse.ArgumentParser:
    """The argparse parser of ``hexapod-workspace``."""
    parser = _Parser(
        prog=PROG,
        description="Orientation workspace of hexapods (Gough-Stewart platforms) in "
        "Tilt-and-Torsion angles. Angles on the command line are in degrees, lengths in m.",
    )
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    _add_global_options(parser, top=True)
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    commands.required = True

    sub = commands.add_parser(
        "check",
        help="check the reachability of poses (exit 0 all reachable, 1 some not, 2 bad input)",
        description="Check poses (phi, theta, psi in degrees) at the position. Margins are "
        "signed (>= 0 holds), in m for leg_length and leg_interference and rad for the joints "
        "(the table shows mm and degrees).",
    )
    _add_global_options(sub, top=False)
    sub.add_argument(
        "--pose",
        nargs=3,
        type=float,
        action="append",
        metavar=("PHI", "THETA", "PSI"),
        help="a pose in Tilt-and-Torsion angles, degrees (repeatable)",
    )
    sub.add_argument(
        "--poses-file",
        metavar="F",
        help="CSV file of rows phi_deg,theta_deg,psi_deg (optional header)",
    )
    sub.add_argument("--record", metavar="FILE", help="also write the result to an MCAP log")
    sub.set_defaults(handler=cmd_check)

    sub = commands.add_parser(
        "projected",
        help="projected orientation workspace: the attainable tool directions",
        description="For n equally spaced azimuths phi, the largest tilt theta the tool can "
        "reach. torsion_zero follows the paper (psi = 0); exact maximises over the torsion.",
    )
    _add_global_options(sub, top=False)
    sub.add_argument("--method", choices=("torsion_zero", "exact"), default="torsion_zero")
    sub.add_argument("--n-phi", type=int, default=360, metavar="N", help="azimuths (3-7200)")
    _add_workspace_options(sub, "polar plot, both methods overlaid")
    sub.set_defaults(handler=cmd_projected)

    sub = commands.add_parser(
        "orientation",
        help="3-D orientation workspace (psi slices in the cylindrical picture)",
        description="Slices psi = const every --psi-step-deg, rays from the centroid of the "
        "previous slice; psi_min and psi_max located to the tolerance.",
    )
    _add_global_options(sub, top=False)
    sub.add_argument("--n-rays", type=int, default=180, metavar="N", help="rays per slice")
    sub.add_argument("--psi-step-deg", type=float, default=1.0, metavar="S")
    _add_workspace_options(sub, "surface + top view (paper's Fig. 4/5)")
    sub.set_defaults(handler=cmd_orientation)

    sub = commands.add_parser(
        "torsion-range",
        help="feasible torsion intervals for one tool direction",
        description="Exit 0 when some torsion is feasible, 1 when none is.",
    )
    _add_global_options(sub, top=False)
    sub.add_argument(
        "--direction",
        nargs=2,
        type=float,
        required=True,
        metavar=("PHI", "THETA"),
        help="tool direction (azimuth, tilt), degrees",
    )
    sub.add_argument("--tol-deg", type=float, metavar="T", help="boundary tolerance, degrees")
    sub.set_defaults(handler=cmd_torsion_range)

    add_check_path_command(commands, _add_global_options)

    sub = commands.add_parser(
        "replay",
        help="what a recorded MCAP log holds (topics, counts, time span, results)",
        description="Accepts a bare .mcap file or a rosbag2 bag directory. Exit 2 when "
        "nothing usable can be read.",
    )
    _add_global_options(sub, top=False)
    sub.add_argument("log", metavar="LOG")
    sub.add_argument("--plot", metavar="DIR", help="redraw the recorded workspaces into DIR")
    sub.add_argument(
        "--publish", action="store_true", help="republish the log on ROS topics (needs rclpy)"
    )
    sub.add_argument(
        "--rate",
        type=float,
        default=1.0,
        metavar="R",
        help="playback speed for --publish (1 = recorded, 0 = as fast as possible)",
    )
    sub.set_defaults(handler=cmd_replay)

    sub = commands.add_parser(
        "demo",
        help="the example manipulator end to end: results table, plots, MCAP log",
        description="On the axis (0, 0, -1.3) m and off the axis (0.2, 0.2, -0.95) m: "
        "projected workspaces (both methods), 3-D orientation workspaces, plots and a log.",
    )
    _add_global_options(sub, top=False)
    sub.add_argument("--out", default="demo_out", metavar="DIR", help="output folder")
    sub.set_defaults(handler=cmd_demo)
    return parser


def main(argv: Sequence[str] | None = None, *, out: TextIO | None = None) -> int:
    """Run the CLI; returns the exit code (also the console script's entry point).

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments (default ``sys.argv[1:]``).
    out : file-like, optional
        Where results go (default ``sys.stdout``).
    """
    out = sys.stdout if out is None else out
    parser = build_parser()
    try:
        options = parser.parse_args(argv)
        handler: Callable[[argparse.Namespace, TextIO], int] = options.handler
        return handler(options, out)
    except (CliError, HexapodWorkspaceError) as error:
        reason = " ".join(str(error).split())
        print(f"{PROG}: error: {reason}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        return 0
    except OSError as error:  # an output file (plot, log, results) cannot be written
        where = f" {error.filename}" if error.filename else ""
        print(f"{PROG}: error: cannot write{where}: {error.strerror or error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
