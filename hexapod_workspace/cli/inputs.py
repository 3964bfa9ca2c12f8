"""What the user types, checked and converted: flags in degrees, the poses CSV, output files.

Every error here is a :class:`CliError` that speaks the flag and the unit the user typed
(``--tol-deg: expected 5.73e-11 to 5.73 degrees, got 10``), never the core's internal names
and radians. The core still checks everything again; this layer only re-phrases.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path
from typing import IO

import numpy as np
from numpy.typing import NDArray

from .._resources import example_config_path
from ..core import resolution
from ..core.frames import cell_from_params_file, tool_model
from ..core.manipulator import Manipulator
from ..core.rotations import degrees_to_radians
from ..errors import HexapodWorkspaceError, InputError
from .tables import ANGLE_UNITS, Columns, parse_table

__all__ = [
    "PLOT_FORMATS",
    "POSE_COLUMNS",
    "CliError",
    "finite",
    "load_manipulator",
    "output_file",
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


def load_manipulator(
    config: str | Path | None,
    position: NDArray[np.float64] | None,
    err: IO[str],
    *,
    with_tool: bool = True,
) -> Manipulator:
    """The manipulator of ``--config`` (default: the packaged example), at ``--position``.

    Warnings of the model (an unreachable home pose) go to ``err`` as one line each. With
    ``tool.offset`` / ``tool.orientation`` in the file, the model answers for the tool frame's
    poses (:func:`hexapod_workspace.core.frames.tool_model`), unless ``with_tool`` is False
    (the platform frame's model).
    """
    path = Path(config) if config else example_config_path()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        manipulator = Manipulator.from_params_file(path)
    if with_tool:
        manipulator = tool_model(manipulator, cell_from_params_file(path).tool)
    for warning in caught:
        err.write(f"hexapod-workspace: warning: {warning.message}\n")
    if position is None:
        return manipulator
    position = finite(position, "--position", "m")
    try:
        resolution.validate_position(manipulator, position)
    except InputError as error:
        msg = "--position" + str(error).removeprefix("position")
        raise CliError(msg) from error
    return manipulator.with_position(position)


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
#: The columns of a poses file: each angle in degrees or radians, named by the header.
POSE_COLUMNS = Columns({"phi": ANGLE_UNITS, "theta": ANGLE_UNITS, "psi": ANGLE_UNITS})
_POSE_DEFAULT = ["phi_deg", "theta_deg", "psi_deg"]


def read_poses_file(path: str | Path) -> NDArray[np.float64]:
    """Read a CSV of poses (φ, θ, ψ), one pose per line (rules: :mod:`.tables`).

    With a header, the columns are read by name in any order, each angle in the unit it names
    (``theta_deg``, ``phi_rad``); all three angles are required and any other name is refused.
    Without a header, the columns are ``phi_deg,theta_deg,psi_deg``. ``-`` reads standard input
    (as does ``/dev/stdin``, piped or not). Errors name the line of the file.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    ndarray, shape (N, 3)
        (φ, θ, ψ) in degrees (as typed, or converted from the radians the header names).

    Raises
    ------
    InputError
        Unreadable file, an unknown or incomplete header, a line without exactly 3 numbers,
        NaN or infinite values, no poses.
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
    table = parse_table(text, f"poses file {name}", _POSE_DEFAULT, rows_name="poses")
    if table.header is None:
        return table.values
    columns = POSE_COLUMNS.read(table)
    missing = [q for q in POSE_COLUMNS.quantities if q not in columns]
    if missing:
        msg = (
            f"poses file {name}, line {table.header_line}: no column for {missing[0]} "
            f"(expected {POSE_COLUMNS.expected()})"
        )
        raise InputError(msg)
    return np.column_stack([columns[q] for q in POSE_COLUMNS.quantities])


def core_error(error: HexapodWorkspaceError) -> str:
    """The one-line text of a core error."""
    return " ".join(str(error).split())
