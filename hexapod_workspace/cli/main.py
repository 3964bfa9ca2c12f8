"""Command-line interface ``hexapod-workspace`` (no ROS needed): the thin argparse front end.

The CLI speaks degrees to humans (JSON keys carry the unit: ``theta_deg``) and SI units for
lengths and margins. Each subcommand is a :class:`Command` in :data:`COMMANDS`: how it adds its
options, which global options it uses, and a small adapter from the parsed options to a plain
function of :mod:`.commands`, :mod:`.replay` or :mod:`.demo`. A new subcommand is one
``register(Command(...))`` call. Exit codes: 0 success, 1 a negative answer (``check``: some pose
unreachable; ``torsion-range``: no feasible torsion; an empty workspace; ``replay``: a damaged
log) with the reason on stderr, 2 bad input with a one-line reason on stderr, 3 an internal
error (a bug, one line; ``HEXAPOD_WORKSPACE_DEBUG=1`` shows the traceback). Never a traceback
otherwise.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np

from .. import __version__
from ..core import kernels
from ..core.base import resolution
from ..errors import HexapodWorkspaceError
from . import atlas, cam, check_path, commands, linuxcnc, loads, reach, scene, schedule
from .inputs import (
    PLOT_FORMATS,
    CliError,
    GivenPoses,
    add_angles_option,
    configured_manipulator,
    configured_model,
    finite,
    output_file,
    pose_flag,
    psi_step_flag,
    rays_flag,
    read_poses_file,
    tolerance_flag,
)

__all__ = ["COMMANDS", "Command", "build_parser", "main", "register"]

PROG = commands.PROG
#: Global options and what they mean; each command says which of them it uses.
GLOBAL_OPTIONS = ("config", "position", "json")

# A negative number in any notation argparse's default misses: -1.3e0, -1e300, -inf, -nan.
_NEGATIVE_NUMBER = re.compile(
    r"^-(?:(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|inf(?:inity)?|nan)$", re.IGNORECASE
)


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line (no usage dump), and which takes every
    negative number (``-1.3e0``, ``-inf``) for a value, not an option."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message: str) -> None:  # type: ignore[override]
        raise CliError(message)


@dataclass(frozen=True)
class Command:
    """One subcommand of the CLI.

    Attributes
    ----------
    name, help, description : str
        As argparse shows them.
    add_arguments : callable
        Adds the command's own options to its subparser.
    run : callable
        ``run(options, out, err) -> exit code``: reads the parsed options, calls the plain
        command function.
    uses : tuple of str
        The global options (of :data:`GLOBAL_OPTIONS`) the command reads; the others are
        refused when given, instead of being silently ignored.
    """

    name: str
    help: str
    description: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace, IO[str], IO[str]], int]
    uses: tuple[str, ...] = GLOBAL_OPTIONS


#: The subcommands, in the order ``--help`` lists them.
COMMANDS: dict[str, Command] = {}


def register(command: Command) -> Command:
    """Add a subcommand (a name may be registered once)."""
    if command.name in COMMANDS:
        msg = f"command {command.name!r} is registered twice"
        raise ValueError(msg)
    COMMANDS[command.name] = command
    return command


# ---------------------------------------------------------------------------- shared options
def _add_tolerance(parser: argparse.ArgumentParser) -> None:
    low, high = (np.degrees(b) for b in (resolution.MIN_TOLERANCE, resolution.MAX_TOLERANCE))
    parser.add_argument(
        "--tol-deg",
        type=float,
        metavar="T",
        help=f"boundary tolerance, degrees, {low:.3g} to {high:.3g} "
        f"(default: {np.degrees(resolution.DEFAULT_TOLERANCE):.3g})",
    )


def _add_outputs(parser: argparse.ArgumentParser, plot_help: str | None) -> None:
    if plot_help is not None:
        parser.add_argument(
            "--plot",
            metavar="FILE",
            help=f"{plot_help}; FILE ends in {', '.join(PLOT_FORMATS)} and its folder exists",
        )
    parser.add_argument(
        "--record",
        metavar="FILE.mcap",
        help="also write the result to an MCAP log (rosbag2 form); the folder must exist",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="replace an existing --plot/--record file even when it is not one of ours",
    )


def _plot_path(options: argparse.Namespace) -> Path | None:
    if getattr(options, "plot", None) is None:
        return None
    return output_file(options.plot, "--plot", force=options.force, suffixes=PLOT_FORMATS)


def _record_path(options: argparse.Namespace) -> Path | None:
    if options.record is None:
        return None
    return output_file(options.record, "--record", force=options.force, suffixes=(".mcap",))


def _manipulator(options: argparse.Namespace, err: IO[str]):
    return configured_manipulator(options.config, options.position, err)


# ---------------------------------------------------------------------------- check
def _check_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--pose",
        nargs="+",
        type=float,
        action="append",
        metavar="V",
        help="a pose: PHI THETA PSI in Tilt-and-Torsion angles, degrees, any finite values, or "
        "the 3 angles (4 quaternion components) of --angles (repeatable)",
    )
    parser.add_argument(
        "--poses-file",
        metavar="F",
        help="CSV of lines phi_deg,theta_deg,psi_deg (header optional, it may name another "
        "convention: u_deg,v_deg,w_deg, qx,qy,qz,qw, ...; ',' ';' tab or space separated); - "
        "reads standard input",
    )
    add_angles_option(parser)
    parser.add_argument(
        "--singularity",
        action="store_true",
        help="report the singularity margin (smallest singular value of the legs' Plucker "
        "matrix) even when limits.singularity_min is 0 (then it never makes a pose unreachable)",
    )
    _add_outputs(parser, None)


def _check_run(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    parts: list[GivenPoses] = []
    if options.pose:
        parts.append(pose_flag(options.pose, options.angles))
    if options.poses_file:
        from_file = read_poses_file(options.poses_file, options.angles)
        if parts and options.angles is None and not from_file.is_tt:
            msg = (
                f"--poses-file {options.poses_file} names {from_file.convention} columns "
                f"({','.join(from_file.keys)}) but --pose is in tt angles (no --angles); give "
                f"--angles {from_file.convention} for both"
            )
            raise CliError(msg)
        parts.append(from_file)
    if not parts:
        msg = "check: give at least one --pose PHI THETA PSI or a --poses-file"
        raise CliError(msg)
    record = _record_path(options)
    poses = GivenPoses(parts[-1].convention, np.concatenate([part.values for part in parts]))
    manipulator, case = configured_model(options.config, options.position, err, loads_read=True)
    return commands.check_command(
        manipulator,
        poses,
        as_json=options.json,
        record=record,
        singularity=options.singularity,
        loads=case if case.limited_rows else None,
        out=out,
        err=err,
    )


# ---------------------------------------------------------------------------- projected
def _projected_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--method",
        choices=[method.value for method in resolution.Method],
        default=resolution.Method.TORSION_ZERO.value,
        help="torsion_zero: the boundary at psi = 0 (the paper's); exact: the largest tilt "
        "over every torsion (the true shadow) (default: %(default)s)",
    )
    parser.add_argument(
        "--n-phi",
        type=int,
        default=resolution.DEFAULT_N_PHI,
        metavar="N",
        help=f"equally spaced azimuths, {resolution.MIN_RAYS} to {resolution.MAX_RAYS} "
        "(default: %(default)s)",
    )
    _add_tolerance(parser)
    _add_outputs(parser, "draw both methods overlaid (polar plot of tilt against azimuth)")


def _projected_run(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    n_phi = rays_flag(options.n_phi, "--n-phi")
    tolerance = tolerance_flag(options.tol_deg)
    plot, record = _plot_path(options), _record_path(options)
    return commands.projected_command(
        _manipulator(options, err),
        method=resolution.Method(options.method),
        n_phi=n_phi,
        tolerance=tolerance,
        as_json=options.json,
        plot=plot,
        record=record,
        out=out,
        err=err,
    )


# ---------------------------------------------------------------------------- orientation
def _orientation_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--n-rays",
        type=int,
        default=resolution.DEFAULT_N_RAYS,
        metavar="N",
        help=f"rays per psi slice, {resolution.MIN_RAYS} to {resolution.MAX_RAYS} "
        "(default: %(default)s)",
    )
    low, high = (np.degrees(b) for b in (resolution.MIN_PSI_STEP, resolution.MAX_PSI_STEP))
    parser.add_argument(
        "--psi-step-deg",
        type=float,
        default=float(np.degrees(resolution.DEFAULT_PSI_STEP)),
        metavar="S",
        help=f"torsion step between slices, degrees, {low:.3g} to {high:.3g} "
        "(default: %(default)g)",
    )
    _add_tolerance(parser)
    _add_outputs(parser, "draw the surface and the top view of the slices (paper's Fig. 4/5)")


def _orientation_run(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    n_rays = rays_flag(options.n_rays, "--n-rays")
    psi_step = psi_step_flag(options.psi_step_deg)
    tolerance = tolerance_flag(options.tol_deg)
    plot, record = _plot_path(options), _record_path(options)
    return commands.orientation_command(
        _manipulator(options, err),
        n_rays=n_rays,
        psi_step=psi_step,
        tolerance=tolerance,
        as_json=options.json,
        plot=plot,
        record=record,
        out=out,
        err=err,
    )


# ---------------------------------------------------------------------------- torsion-range
def _torsion_range_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--direction",
        nargs=2,
        type=float,
        required=True,
        metavar=("PHI", "THETA"),
        help="tool direction: azimuth PHI (any finite value) and tilt THETA (0 to 180), degrees",
    )
    _add_tolerance(parser)


def _torsion_range_run(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    phi, theta = finite(options.direction, "--direction", "degrees").tolist()
    tolerance = tolerance_flag(options.tol_deg)
    return commands.torsion_range_command(
        _manipulator(options, err),
        (phi, theta),
        tolerance=tolerance,
        as_json=options.json,
        out=out,
        err=err,
    )


# ---------------------------------------------------------------------------- check-path
def _check_path_run(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``check-path``: ``--angles`` checked against the file before either pipeline runs (the
    cell pipeline reads a CSV's convention from its columns; a CL file gives tool axes)."""
    if options.angles is not None:
        if cam.is_cl_file(options.file):
            msg = (
                f"--angles: a CL file gives tool axes, not angles; got --angles {options.angles} "
                f"for {options.file}"
            )
            raise CliError(msg)
        if cam.cell_pipeline_applies(options):
            check_path.read_path_file(options.file, options.angles)  # refuses a mismatch
    return cam.cmd_check_path_any(options, out, err)


# ---------------------------------------------------------------------------- replay
def _replay_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("log", metavar="LOG", help="a .mcap file or a rosbag2 bag folder")
    parser.add_argument(
        "--plot", metavar="DIR", help="redraw the recorded workspaces into DIR (created)"
    )
    parser.add_argument(
        "--publish", action="store_true", help="republish the log on ROS topics (needs rclpy)"
    )
    parser.add_argument(
        "--rate",
        type=float,
        default=1.0,
        metavar="R",
        help="playback speed for --publish: 1 = as recorded, 0 = as fast as possible "
        "(default: %(default)g)",
    )


def _replay_run(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    from .replay import run_replay

    return run_replay(
        options.log,
        as_json=options.json,
        plot_dir=options.plot,
        publish=options.publish,
        rate=options.rate,
        stdout=out,
        stderr=err,
    )


# ---------------------------------------------------------------------------- demo
def _demo_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--out",
        default="demo_out",
        metavar="DIR",
        help="output folder, created with its parents (default: %(default)s)",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="replace files in DIR that the demo writes even when they are not the demo's",
    )


def _demo_run(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    from .demo import run_demo

    return run_demo(
        _manipulator(options, err),
        Path(options.out),
        out=out,
        err=err,
        as_json=options.json,
        force=options.force,
    )


for _command in (
    Command(
        "check",
        "check the reachability of poses (exit 0 all reachable, 1 some not, 2 bad input)",
        "Check poses (phi, theta, psi in degrees) at the position. Each margin is the signed "
        "distance to a limit (>= 0 holds, < 0 violated), in m for leg_length and "
        "leg_interference and rad for the joints (the table shows mm and degrees).",
        _check_arguments,
        _check_run,
    ),
    Command(
        "projected",
        "projected orientation workspace: the attainable tool directions",
        "For N equally spaced azimuths phi, the largest tilt theta the tool can reach from "
        "theta = 0. torsion_zero follows the paper (psi = 0); exact maximises over the torsion.",
        _projected_arguments,
        _projected_run,
    ),
    Command(
        "orientation",
        "3-D orientation workspace (psi slices in the cylindrical picture)",
        "Slices psi = const every --psi-step-deg, rays from the centroid of the previous "
        "slice; psi_min and psi_max located to the tolerance.",
        _orientation_arguments,
        _orientation_run,
    ),
    Command(
        "torsion-range",
        "feasible torsion intervals for one tool direction",
        "Exit 0 when some torsion is feasible, 1 when none is.",
        _torsion_range_arguments,
        _torsion_range_run,
    ),
    Command(
        "replay",
        "what a recorded MCAP log holds (topics, counts, time span, results)",
        "Accepts a bare .mcap file or a rosbag2 bag directory. Exit 1 when the log is damaged "
        "(read as far as intact), 2 when nothing usable can be read.",
        _replay_arguments,
        _replay_run,
        uses=("json",),
    ),
    Command(
        "demo",
        "the example manipulator end to end: results table, plots, MCAP log",
        "On the axis (0, 0, -1.3) m and off the axis (0.2, 0.2, -0.95) m (the demo's own "
        "positions: --position does not apply): projected workspaces (both methods), 3-D "
        "orientation workspaces, plots and a log.",
        _demo_arguments,
        _demo_run,
        uses=("config", "json"),
    ),
    Command(
        "check-path",
        check_path.CHECK_PATH_HELP,
        check_path.CHECK_PATH_DESCRIPTION,
        cam.check_path_any_arguments,
        _check_path_run,
        uses=("config", "json"),
    ),
    Command(
        "schedule",
        schedule.SCHEDULE_HELP,
        schedule.SCHEDULE_DESCRIPTION,
        schedule.schedule_arguments,
        schedule.cmd_schedule,
        uses=("config", "json"),
    ),
    Command(
        "atlas",
        atlas.ATLAS_HELP,
        atlas.ATLAS_DESCRIPTION,
        atlas.atlas_arguments,
        atlas.cmd_atlas,
        uses=("config", "json"),
    ),
    Command(
        "scene",
        scene.SCENE_HELP,
        scene.SCENE_DESCRIPTION,
        scene.scene_arguments,
        scene.cmd_scene,
    ),
    Command(
        "reach",
        reach.REACH_HELP,
        reach.REACH_DESCRIPTION,
        reach.reach_arguments,
        reach.cmd_reach,
    ),
    Command(
        "loads",
        loads.LOADS_HELP,
        loads.LOADS_DESCRIPTION,
        loads.loads_arguments,
        loads.cmd_loads,
    ),
    Command(
        "axis-limits",
        reach.AXIS_LIMITS_HELP,
        reach.AXIS_LIMITS_DESCRIPTION,
        reach.axis_limits_arguments,
        reach.cmd_axis_limits,
    ),
    Command(
        "import-genhexkins",
        linuxcnc.IMPORT_HELP,
        linuxcnc.IMPORT_DESCRIPTION,
        linuxcnc.import_arguments,
        linuxcnc.cmd_import_genhexkins,
        uses=("json",),
    ),
):
    register(_command)


# ---------------------------------------------------------------------------- parser
def _add_global_options(
    parser: argparse.ArgumentParser, names: Sequence[str], *, top: bool
) -> None:
    # Global options are accepted before and after the command; after the command they only
    # override what was given before (default SUPPRESS).
    default: Any = None if top else argparse.SUPPRESS
    if "config" in names:
        parser.add_argument(
            "--config",
            metavar="FILE",
            default=default,
            help="ROS 2 parameters file (root key hexapod_workspace or /**) "
            "(default: the packaged example GPM)",
        )
    if "position" in names:
        parser.add_argument(
            "--position",
            nargs=3,
            type=float,
            metavar=("X", "Y", "Z"),
            default=default,
            help="tool-tip position OC in the base frame, m (default: pose.position of the "
            "parameters file)",
        )
    if "json" in names:
        parser.add_argument(
            "--json",
            action="store_true",
            default=False if top else argparse.SUPPRESS,
            help="machine-readable result on stdout (nothing else on stdout)",
        )


def build_parser() -> argparse.ArgumentParser:
    """The argparse parser of ``hexapod-workspace`` with every registered command."""
    parser = _Parser(
        prog=PROG,
        description="Orientation workspace of hexapods (Gough-Stewart platforms) in "
        "Tilt-and-Torsion angles. Angles on the command line are in degrees, lengths in m.",
    )
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    _add_global_options(parser, GLOBAL_OPTIONS, top=True)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    subparsers.required = True
    for command in COMMANDS.values():
        sub = subparsers.add_parser(
            command.name, help=command.help, description=command.description
        )
        _add_global_options(sub, command.uses, top=False)
        command.add_arguments(sub)
    return parser


def _refuse_unused_globals(options: argparse.Namespace, command: Command) -> None:
    for name in GLOBAL_OPTIONS:
        if name not in command.uses and getattr(options, name, None) not in (None, False):
            msg = f"{command.name}: --{name} does not apply to this command"
            raise CliError(msg)


def main(
    argv: Sequence[str] | None = None,
    *,
    out: IO[str] | None = None,
    err: IO[str] | None = None,
) -> int:
    """Run the CLI; returns the exit code (also the console script's entry point).

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments (default ``sys.argv[1:]``).
    out, err : text streams, optional
        Where results and reasons go (default ``sys.stdout``, ``sys.stderr``).
    """
    out = sys.stdout if out is None else out
    err = sys.stderr if err is None else err
    try:
        options = build_parser().parse_args(argv)
        command = COMMANDS[options.command]
        _refuse_unused_globals(options, command)
        # The first run after an install compiles the kernels: say so in one line.
        with kernels.compile_notice(lambda message: err.write(f"{PROG}: {message}\n")):
            return command.run(options, out, err)
    except (CliError, HexapodWorkspaceError) as error:
        reason = " ".join(str(error).split())
        err.write(f"{PROG}: error: {reason}\n")
        return 2
    except BrokenPipeError:
        return 0
    except OSError as error:  # an output file (plot, log, results) cannot be written
        where = f" {error.filename}" if error.filename else ""
        err.write(f"{PROG}: error: cannot write{where}: {error.strerror or error}\n")
        return 2
    except KeyboardInterrupt:
        err.write(f"{PROG}: interrupted\n")
        return 130
    except SystemExit as done:  # --help, --version
        return done.code if isinstance(done.code, int) else 0
    except Exception as error:  # a bug: still one line, the traceback only on request
        if os.environ.get("HEXAPOD_WORKSPACE_DEBUG"):
            raise
        err.write(
            f"{PROG}: internal error ({type(error).__name__}: {error}); please report it "
            "(HEXAPOD_WORKSPACE_DEBUG=1 shows the traceback)\n"
        )
        return 3


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
