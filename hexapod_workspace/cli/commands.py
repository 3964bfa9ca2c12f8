"""The CLI's commands as plain functions with typed arguments.

Each function takes checked values (SI units, rad, or degrees as typed where it echoes them),
writes results to ``out`` and reasons to ``err``, and returns the exit code: 0 success, 1 a
negative answer (an unreachable pose, no feasible torsion, an empty workspace), with its reason
on ``err``. Bad input raises :class:`~hexapod_workspace.cli.inputs.CliError` or an error of
:mod:`hexapod_workspace.errors` before any result is printed; :func:`.main.main` turns those into
exit code 2. Tests call these functions, or ``main(argv, out=..., err=...)``, directly.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from ..core.base import resolution
from ..core.base.rotations import tt_to_matrix
from ..core.evaluation.check import check
from ..core.evaluation.loads import LoadCase, load_rows
from ..core.model.manipulator import Manipulator
from ..core.workspaces.orientation import orientation_workspace, torsion_range
from ..core.workspaces.projected import projected_workspace
from ..errors import ResolutionError, UnreachableReferenceError
from . import reports
from .inputs import CliError, GivenPoses, poses_from_degrees
from .progress import ProgressBar

__all__ = [
    "PROG",
    "check_command",
    "orientation_command",
    "projected_command",
    "torsion_range_command",
]

PROG = "hexapod-workspace"


def _record(
    path: Path | None, manipulator: Manipulator, results: list[Any], started_ns: int, err: IO[str]
) -> None:
    """Write ``--record FILE`` (rosbag2-form MCAP) when asked; the file was checked before."""
    if path is None:
        return
    from ..logs.record import record_results

    written = record_results(
        path, results, frame_id=manipulator.frame_id, stamps_ns=[started_ns] * len(results)
    )
    err.write(f"{PROG}: recorded {len(results)} result(s) to {written}\n")


def _unreachable(
    error: UnreachableReferenceError, position: Any, as_json: bool, out: IO[str], err: IO[str]
) -> int:
    """Report an empty workspace: exit 1, the reason on stderr (and in the JSON result)."""
    reason = " ".join(str(error).split())
    if as_json:
        reports.write_json(reports.unreachable_json(position, reason), out)
    err.write(f"{PROG}: {reason}\n")
    return 1


def check_command(
    manipulator: Manipulator,
    poses_deg: NDArray[np.float64] | GivenPoses,
    *,
    as_json: bool = False,
    record: Path | None = None,
    singularity: bool = False,
    loads: LoadCase | None = None,
    out: IO[str],
    err: IO[str],
) -> int:
    """``check``: reachability of poses (φ, θ, ψ in degrees, any finite values, or poses in
    another convention, :class:`~hexapod_workspace.cli.inputs.GivenPoses`, echoed as given
    beside their T&T angles).

    ``singularity`` reports the singularity margin even when ``limits.singularity_min`` is 0.
    ``loads`` (centre of mass in the model's tool frame) adds the loads' rows it sets
    (:func:`~hexapod_workspace.core.evaluation.loads.load_rows`) to each pose's verdict; the log
    does not carry them, so ``record`` must be None then.
    Returns 0 when every pose is reachable (within the loads' limits), 1 when some is not (the
    count on ``err``).
    """
    started = time.time_ns()
    poses = poses_deg if isinstance(poses_deg, GivenPoses) else GivenPoses("tt", poses_deg)
    degrees = poses.tt_degrees()
    given = None if poses.is_tt else (poses.keys, poses.values)
    radians = poses_from_degrees(degrees) if poses.is_tt else poses.radians()
    if loads is not None and record is not None:
        msg = (
            "--record: the log's check messages carry no loads rows; drop --record or the "
            "loads' limits"
        )
        raise CliError(msg)
    result = check(manipulator, radians, singularity=singularity)
    rows = None
    if loads is not None:
        rows = load_rows(manipulator, loads, tt_to_matrix(radians), manipulator.position)
    _record(record, manipulator, [result], started, err)
    if as_json:
        reports.check_json(result, out, degrees, given, rows)
    else:
        reports.check_table(result, out, degrees, manipulator, given, rows)
    held = result.reachable if rows is None else result.reachable & rows.holds
    unreachable = len(result) - int(np.count_nonzero(held))
    if unreachable:
        what = "unreachable" if rows is None else "unreachable or beyond the loads' limits"
        err.write(f"{PROG}: {unreachable} of {len(result)} poses {what}\n")
        return 1
    return 0


def projected_command(
    manipulator: Manipulator,
    *,
    method: resolution.Method,
    n_phi: int,
    tolerance: float,
    as_json: bool = False,
    plot: Path | None = None,
    record: Path | None = None,
    out: IO[str],
    err: IO[str],
) -> int:
    """``projected``: the projected orientation workspace (attainable tool directions)."""
    started = time.time_ns()
    try:
        workspace = projected_workspace(
            manipulator,
            method=method.value,
            n_phi=n_phi,
            tolerance=tolerance,
            progress=ProgressBar(f"projected ({method.value})", stream=err),
        )
    except UnreachableReferenceError as error:
        return _unreachable(error, manipulator.position, as_json, out, err)
    if plot is not None:
        other = next(m for m in resolution.Method if m is not method)
        overlay = projected_workspace(
            manipulator,
            method=other.value,
            n_phi=n_phi,
            tolerance=tolerance,
            progress=ProgressBar(f"projected ({other.value}, for the plot)", stream=err),
        )
        from .plotting import plot_projected

        ordered = (
            [workspace, overlay]
            if method is resolution.Method.TORSION_ZERO
            else [
                overlay,
                workspace,
            ]
        )
        plot_projected(ordered, plot)
    _record(record, manipulator, [workspace], started, err)
    if as_json:
        reports.write_json(reports.projected_json(workspace), out)
    else:
        reports.projected_text(workspace, out)
    if plot is not None:
        (err if as_json else out).write(f"plot: {plot}\n")
    return 0


def orientation_command(
    manipulator: Manipulator,
    *,
    n_rays: int,
    psi_step: float,
    tolerance: float,
    as_json: bool = False,
    plot: Path | None = None,
    record: Path | None = None,
    out: IO[str],
    err: IO[str],
) -> int:
    """``orientation``: the 3-D orientation workspace (ψ slices)."""
    started = time.time_ns()
    try:
        workspace = orientation_workspace(
            manipulator,
            n_rays=n_rays,
            psi_step=psi_step,
            tolerance=tolerance,
            progress=ProgressBar("orientation", stream=err),
        )
    except UnreachableReferenceError as error:
        return _unreachable(error, manipulator.position, as_json, out, err)
    except ResolutionError as error:  # the only one left: too many boundary points
        slices = int(2.0 * math.pi / psi_step) + 1
        msg = (
            f"--n-rays {n_rays} with --psi-step-deg {math.degrees(psi_step):g}: up to "
            f"{slices} slices of {n_rays} rays exceed {resolution.MAX_POINTS} boundary points; "
            "use fewer rays or a larger step"
        )
        raise CliError(msg) from error
    if plot is not None:
        from .plotting import plot_orientation

        plot_orientation(workspace, plot)
    _record(record, manipulator, [workspace], started, err)
    if as_json:
        reports.write_json(reports.orientation_json(workspace), out)
    else:
        reports.orientation_text(workspace, out)
    if plot is not None:
        (err if as_json else out).write(f"plot: {plot}\n")
    return 0


def torsion_range_command(
    manipulator: Manipulator,
    direction_deg: tuple[float, float],
    *,
    tolerance: float,
    as_json: bool = False,
    out: IO[str],
    err: IO[str],
) -> int:
    """``torsion-range``: feasible torsion intervals for one tool direction (degrees as typed).

    Returns 0 when some torsion is feasible, 1 when none is (the reason on ``err``).
    """
    phi_deg, theta_deg = direction_deg
    if not 0.0 <= theta_deg <= 180.0:
        msg = f"--direction: expected THETA in [0, 180] degrees, got {theta_deg:g}"
        raise CliError(msg)
    phi = float(poses_from_degrees(np.array(phi_deg)))
    found = torsion_range(manipulator, phi, math.radians(theta_deg), tolerance=tolerance)
    if as_json:
        reports.write_json(reports.torsion_range_json(found, direction_deg), out)
    else:
        reports.torsion_range_text(found, direction_deg, out)
    if not len(found.intervals):
        err.write(
            f"{PROG}: no torsion is feasible for direction phi {phi_deg:g} deg, "
            f"theta {theta_deg:g} deg\n"
        )
        return 1
    return 0
