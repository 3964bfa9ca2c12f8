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

from . import __version__
from ._resources import example_config_path
from .constraints import CONSTRAINT_NAMES, CheckResult, check
from .errors import HexapodWorkspaceError, InputError
from .manipulator import Manipulator

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
    if options.json:
        check_poses_to_json(result, out, degrees)
    else:
        check_poses_to_table(result, out, degrees)
    return 0 if bool(np.all(result.reachable)) else 1


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
    sub.set_defaults(handler=cmd_check)
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
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
