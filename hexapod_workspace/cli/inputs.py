"""What the user types, checked and converted: flags in degrees, the poses CSV, output files.

Every error here is a :class:`CliError` that speaks the flag and the unit the user typed
(``--tol-deg: expected 5.73e-11 to 5.73 degrees, got 10``), never the core's internal names
and radians. The core still checks everything again; this layer only re-phrases.
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import numpy as np
from numpy.typing import NDArray

from .._resources import example_config_path
from ..core.base import resolution
from ..core.base.params import load_params_file
from ..core.base.rotations import (
    ANGLE_CONVENTIONS,
    convention_to_tt,
    degrees_to_radians,
    tt_to_matrix,
)
from ..core.base.validation import machine_size, millimetre_reason
from ..core.cell.frames import cell_from_params_file, require_plausible_cell, tool_model
from ..core.evaluation.loading import load_manipulator
from ..core.evaluation.loads import LoadCase, load_case_from_mapping, require_plausible_loads
from ..core.model.manipulator import Manipulator
from ..errors import ConfigError, HexapodWorkspaceError, InputError
from .tables import (
    ORIENTATION_QUANTITIES,
    Columns,
    conventions_text,
    orientation_columns,
    orientation_header,
    parse_table,
)

__all__ = [
    "PLOT_FORMATS",
    "POSE_COLUMNS",
    "CliError",
    "GivenPoses",
    "add_angles_option",
    "configured_manipulator",
    "configured_model",
    "finite",
    "given_poses",
    "output_file",
    "plausible_positions",
    "pose_flag",
    "poses_from_degrees",
    "psi_step_flag",
    "rays_flag",
    "read_poses_file",
    "tolerance_flag",
]

#: File formats ``--plot`` writes, by suffix.
PLOT_FORMATS = (".png", ".pdf", ".svg")
_MAGIC = {
    ".png": (b"\x89PNG\r\n\x1a\n",),
    ".pdf": (b"%PDF",),
    ".svg": (b"<?xml", b"<svg"),
    ".mcap": (b"\x89MCAP0\r\n",),
}


class CliError(Exception):
    """Bad command-line input: reported as one line on stderr with exit code 2."""


def finite(values: object, flag: str, unit: str) -> NDArray[np.float64]:
    """The values of ``flag`` as floats, refusing NaN and infinities in the flag's words."""
    array = np.atleast_1d(np.asarray(values, dtype=np.float64))
    if not np.all(np.isfinite(array)):
        shown = " ".join(f"{v:g}" for v in array.ravel().tolist())
        msg = f"{flag}: expected finite numbers ({unit}), got {shown}"
        raise CliError(msg)
    return array


def tolerance_flag(degrees: float | None, flag: str = "--tol-deg") -> float:
    """A boundary tolerance typed in degrees, checked against the core's bounds; rad."""
    if degrees is None:
        return resolution.DEFAULT_TOLERANCE
    value = float(finite(degrees, flag, "degrees")[0])
    low, high = (math.degrees(b) for b in (resolution.MIN_TOLERANCE, resolution.MAX_TOLERANCE))
    if not low <= value <= high:
        msg = f"{flag}: expected {low:.3g} to {high:.3g} degrees, got {value:g}"
        raise CliError(msg)
    return resolution.validate_tolerance(math.radians(value))


def psi_step_flag(degrees: float, flag: str = "--psi-step-deg") -> float:
    """A slice step Δψ typed in degrees, checked against the core's bounds; rad."""
    value = float(finite(degrees, flag, "degrees")[0])
    low, high = (math.degrees(b) for b in (resolution.MIN_PSI_STEP, resolution.MAX_PSI_STEP))
    if not low <= value <= high:
        msg = f"{flag}: expected {low:.3g} to {high:.3g} degrees, got {value:g}"
        raise CliError(msg)
    return resolution.validate_psi_step(math.radians(value))


def rays_flag(count: int, flag: str) -> int:
    """A ray count (``--n-phi``, ``--n-rays``) checked against the core's bounds."""
    if not resolution.MIN_RAYS <= count <= resolution.MAX_RAYS:
        msg = f"{flag}: expected {resolution.MIN_RAYS} to {resolution.MAX_RAYS}, got {count}"
        raise CliError(msg)
    return count


def poses_from_degrees(degrees: NDArray[np.float64]) -> NDArray[np.float64]:
    """(φ, θ, ψ) in degrees, any finite values, to rad: each angle's principal value.

    Reduced modulo 360° before the conversion (exact), so ``--pose 1e20 10 150`` is checked as
    the orientation it denotes (φ = 1e20 mod 360 = 280°), not as a rounding of it.
    """
    return degrees_to_radians(degrees)


# ---------------------------------------------------------------------------- conventions
@dataclass(frozen=True)
class GivenPoses:
    """Orientations as the user gave them, in one convention (:data:`ANGLE_CONVENTIONS`).

    Attributes
    ----------
    convention : str
        ``tt``, ``xyz-moving``, ``xyz-fixed``, ``symetrie`` or ``quaternion``.
    values : ndarray, shape (N, 3) or (N, 4)
        As typed: angles in degrees (any finite values), or quaternions (x, y, z, w).
    """

    convention: str
    values: NDArray[np.float64]

    @property
    def keys(self) -> list[str]:
        """The JSON keys of the given numbers: ``u_deg, v_deg, w_deg`` or ``qx, qy, qz, qw``."""
        return orientation_header(self.convention)

    @property
    def names(self) -> tuple[str, ...]:
        """The names of the given numbers (``u``, ``v``, ``w``)."""
        return ANGLE_CONVENTIONS[self.convention].components

    @property
    def is_tt(self) -> bool:
        return self.convention == "tt"

    def radians(self) -> NDArray[np.float64]:
        """(φ, θ, ψ) in rad, shape (N, 3): ``tt`` each angle's principal value (exact for any
        finite degrees), the others through their rotation matrix (canonical ranges)."""
        if not ANGLE_CONVENTIONS[self.convention].angular:
            return convention_to_tt(self.values, self.convention)
        radians = degrees_to_radians(self.values)
        return radians if self.is_tt else convention_to_tt(radians, self.convention)

    def matrices(self) -> NDArray[np.float64]:
        """Rotation matrices, shape (N, 3, 3): from each convention's own formula."""
        if self.is_tt:
            return tt_to_matrix(self.radians())
        found = ANGLE_CONVENTIONS[self.convention]
        return found.to_matrix(degrees_to_radians(self.values) if found.angular else self.values)

    def echo(self, row: int = 0) -> str:
        """One pose as typed, for text answers: ``u 10, v 5, w 0 deg (xyz-moving)``."""
        unit = " deg" if ANGLE_CONVENTIONS[self.convention].angular else ""
        numbers = ", ".join(
            f"{n} {v:g}" for n, v in zip(self.names, self.values[row].tolist(), strict=True)
        )
        return f"{numbers}{unit} ({self.convention})"

    def tt_degrees(self) -> NDArray[np.float64]:
        """(φ, θ, ψ) in degrees, shape (N, 3): the values as typed for ``tt``."""
        return self.values if self.is_tt else np.degrees(self.radians())


def given_poses(values: NDArray[np.float64], convention: str, where: str) -> GivenPoses:
    """Check orientations written in ``convention`` (finite; quaternions of non-zero norm).

    Parameters
    ----------
    values : ndarray, shape (N, k)
        k = 3 angles in degrees or k = 4 quaternion components.
    convention : str
        A key of :data:`ANGLE_CONVENTIONS`.
    where : str
        How messages name the source (``--pose``, ``poses file p.csv``).
    """
    values = np.asarray(values, dtype=np.float64)
    if not ANGLE_CONVENTIONS[convention].angular:
        norm = np.linalg.norm(values, axis=-1)
        bad = np.flatnonzero(~(norm > 1e-12))
        if bad.size:
            shown = " ".join(f"{v:g}" for v in values[bad[0]].tolist())
            msg = f"{where}: expected a quaternion qx qy qz qw of non-zero norm, got {shown}"
            raise CliError(msg)
    return GivenPoses(convention, values)


def add_angles_option(parser: argparse.ArgumentParser) -> None:
    """``--angles CONVENTION``: the convention of ``--pose`` and of the files' orientations."""
    parser.add_argument(
        "--angles",
        choices=tuple(ANGLE_CONVENTIONS),
        metavar="CONVENTION",
        help="convention of the orientations given: tt (Tilt-and-Torsion phi theta psi, the "
        "default), xyz-moving (PI's U V W: Rx(U) Ry(V) Rz(W)), xyz-fixed (LinuxCNC's A B C: "
        "Rz(C) Ry(B) Rx(A)), symetrie (Symetrie's Rx Ry Rz: Rz(Rz) Ry(Ry) Rx(Rx)), quaternion "
        "(qx qy qz qw); a file's columns name their own (docs/configuration.md)",
    )


def pose_flag(
    values: list[list[float]] | list[float], convention: str | None, flag: str = "--pose"
) -> GivenPoses:
    """The orientations of a repeatable ``--pose`` (3 angles in degrees, or 4 quaternion
    components), in the convention of ``--angles`` (default ``tt``)."""
    name = convention or "tt"
    found = ANGLE_CONVENTIONS[name]
    rows: list[list[float]] = (
        [list(values)]  # type: ignore[arg-type]  # one pose (nargs="+" without append)
        if values and not isinstance(values[0], list)
        else list(values)  # type: ignore[arg-type]
    )
    size = len(found.components)
    for row in rows:
        if len(row) != size:
            words = " ".join(c.upper() for c in found.components)
            unit = "degrees" if found.angular else "unitless"
            msg = (
                f"{flag}: expected {size} numbers {words} ({name}, {unit}), got {len(row)}: "
                + " ".join(f"{v:g}" for v in row)
            )
            raise CliError(msg)
    array = finite(rows, flag, "degrees" if found.angular else "quaternion components")
    return given_poses(array.reshape(-1, size), name, flag)


def configured_manipulator(
    config: str | Path | None,
    position: NDArray[np.float64] | None,
    err: IO[str],
    *,
    with_tool: bool = True,
    loads_read: bool = False,
) -> Manipulator:
    """The manipulator of :func:`configured_model` (the same arguments)."""
    manipulator, _ = configured_model(
        config, position, err, with_tool=with_tool, loads_read=loads_read
    )
    return manipulator


def configured_model(
    config: str | Path | None,
    position: NDArray[np.float64] | None,
    err: IO[str],
    *,
    with_tool: bool = True,
    loads_read: bool = False,
) -> tuple[Manipulator, LoadCase]:
    """The manipulator of ``--config`` (default: the packaged example), at ``--position``, and
    the file's loads with the centre of mass in that model's mobile frame (every command
    refuses a bad loads parameter, naming the file).

    ``loads_read``: the caller reads the loads' limits (``loads``), which the other commands
    refuse (:func:`~hexapod_workspace.core.evaluation.loading.manipulator_from_mapping`).

    Warnings of the model (an unreachable home pose) go to ``err`` as one line each. With
    ``tool.offset`` / ``tool.orientation`` in the file, the model answers for the tool frame's
    poses (:func:`hexapod_workspace.core.cell.frames.tool_model`), unless ``with_tool`` is False
    (the platform frame's model).
    """
    path = Path(config) if config else example_config_path()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        manipulator = load_manipulator(path, loads_read=loads_read)
    try:
        case = require_plausible_loads(manipulator, load_case_from_mapping(load_params_file(path)))
    except ConfigError as error:
        msg = f"parameters file {path}: {error}"
        raise CliError(msg) from error
    cell = require_plausible_cell(manipulator, cell_from_params_file(path))
    if with_tool:
        manipulator = tool_model(manipulator, cell.tool)
        case = case.in_tool_frame(cell.tool.offset, cell.tool.rotation)
    for warning in caught:
        err.write(f"hexapod-workspace: warning: {warning.message}\n")
    if position is None:
        return manipulator, case
    position = finite(position, "--position", "m")
    plausible_positions(manipulator, position, "--position")
    try:
        resolution.validate_position(position, manipulator.position)
    except InputError as error:
        msg = "--position" + str(error).removeprefix("position")
        raise CliError(msg) from error
    return manipulator.with_position(position), case


def tool_position(
    given: NDArray[np.float64] | None, manipulator: Manipulator, platform: Manipulator
) -> NDArray[np.float64]:
    """``--position`` (m, base frame), refused when it fits only in millimetres, or the tool
    model's ``pose.position`` when not given (``platform``: the model the hint sizes)."""
    if given is None:
        return manipulator.position
    position = finite(given, "--position", "m")
    plausible_positions(platform, position, "--position")
    return position


def plausible_positions(
    manipulator: Manipulator, positions: NDArray[np.float64], where: str
) -> None:
    """Refuse positions (m) that fit the machine only once divided by 1000, with the unit
    hint (:func:`~hexapod_workspace.core.base.validation.millimetre_reason`), naming ``where``."""
    size = machine_size(
        manipulator.base_joints, manipulator.platform_joints, manipulator.home_position
    )
    with np.errstate(over="ignore"):  # a position of 1e300 m: inf, refused by its own check
        distances = np.linalg.norm(np.atleast_2d(positions), axis=-1)
    reason = millimetre_reason(where, distances, size)
    if reason is not None:
        raise CliError(reason.replace("got ", "got a distance from the base origin of ", 1))


def output_file(path: str | Path, flag: str, *, force: bool, suffixes: tuple[str, ...]) -> Path:
    """Check a file the user asked us to write, before any work is done.

    Rules (docs/cli.md, "Files the CLI writes"): the name must end with one of ``suffixes``;
    its folder must exist (files are never written into folders we would have to invent); an
    existing file is replaced only when it already is a file of that kind (a log for
    ``--record``, an image for ``--plot``) or with ``--force``.

    Returns
    -------
    pathlib.Path
        The path that will be written, exactly.
    """
    path = Path(path)
    if path.is_dir():
        msg = f"{flag}: {path} is a folder; give a file name such as {path / ('x' + suffixes[0])}"
        raise CliError(msg)
    if path.suffix.lower() not in suffixes:
        msg = f"{flag}: expected a file name ending in {' or '.join(suffixes)}, got {path}"
        raise CliError(msg)
    folder = path.parent
    if not folder.is_dir():
        msg = f"{flag}: folder {folder} does not exist"
        raise CliError(msg)
    if path.exists() and not force:
        try:
            with path.open("rb") as handle:
                head = handle.read(16)
        except OSError as error:
            msg = f"{flag}: cannot read the existing {path}: {error.strerror or error}"
            raise CliError(msg) from error
        magic = _MAGIC.get(path.suffix.lower(), ())
        if head and not any(head.lstrip().startswith(m) for m in magic):
            kind = "an MCAP log" if path.suffix.lower() == ".mcap" else f"a {path.suffix} file"
            msg = f"{flag}: {path} exists and is not {kind}; not replaced (use --force)"
            raise CliError(msg)
    return path


# ---------------------------------------------------------------------------- poses CSV
#: The columns of a poses file: the orientation of one convention, each angle in degrees or
#: radians (``u_deg``, ``u_rad``), the quaternion's components unitless.
POSE_COLUMNS = Columns(ORIENTATION_QUANTITIES, expected=conventions_text())


def read_poses_file(path: str | Path, angles: str | None = None) -> GivenPoses:
    """Read a CSV of poses, one pose per line (rules: :mod:`.tables`).

    With a header, the columns are read by name in any order, each angle in the unit it names
    (``theta_deg``, ``phi_rad``); the header names one convention's columns, all of them
    (``phi_deg,theta_deg,psi_deg``, ``u_deg,v_deg,w_deg``, ``a_deg,b_deg,c_deg``,
    ``rx_deg,ry_deg,rz_deg`` or ``qx,qy,qz,qw``), and any other name is refused. Without a
    header, the columns are those of ``angles`` (``phi_deg,theta_deg,psi_deg`` by default).
    ``-`` reads standard input (as does ``/dev/stdin``, piped or not). Errors name the line of
    the file.

    Parameters
    ----------
    path : str or pathlib.Path
    angles : str, optional
        The convention ``--angles`` names; a header of another convention is refused.

    Returns
    -------
    GivenPoses
        The convention and the values, shape (N, 3) in degrees (as typed, or converted from
        the radians the header names) or (N, 4) quaternions.

    Raises
    ------
    InputError
        Unreadable file, an unknown, incomplete or ambiguous header, a header of another
        convention than ``angles``, a line with the wrong count of numbers, NaN or infinite
        values, no poses.
    """
    name = "standard input" if str(path) == "-" else str(path)
    try:
        if str(path) == "-":
            text = sys.stdin.read()
        else:
            with open(path, encoding="utf-8") as handle:  # one read: pipes and FIFOs work
                text = handle.read()
    except OSError as error:
        msg = f"cannot read poses file {name}: {error.strerror or error}"
        raise InputError(msg) from error
    except UnicodeDecodeError as error:
        msg = f"poses file {name} is not text"
        raise InputError(msg) from error
    default = orientation_header(angles or "tt")
    where = f"poses file {name}"
    table = parse_table(text, where, default, rows_name="poses")
    if table.header is None:
        return given_poses(table.values, angles or "tt", where)
    found = orientation_columns(table, POSE_COLUMNS.read(table), angles)
    if found is None:
        msg = (
            f"{where}, line {table.header_line}: no orientation columns "
            f"(expected {conventions_text()})"
        )
        raise InputError(msg)
    return given_poses(found[1], found[0], where)


def core_error(error: HexapodWorkspaceError) -> str:
    """The one-line text of a core error."""
    return " ".join(str(error).split())
