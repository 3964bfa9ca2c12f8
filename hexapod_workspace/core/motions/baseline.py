"""The ψ = 0 baseline of a path: the paper's recommendation, checked the same way.

Bonev & Ryu recommend keeping the torsion at zero. For a path of fixed orientations the
baseline is the same positions and tool directions with ψ = 0 at every waypoint; the CLI's
``check-path`` and the node's ``~/check_path`` report which of its waypoints and moves fail,
from this one function, so both answer the same. (A torsion plan carries its own baseline,
:attr:`~hexapod_workspace.core.motions.TorsionPlan.baseline`.)
"""

from __future__ import annotations

from ..model.manipulator import Manipulator
from . import PathCheck, TorsionPlan, check_path

__all__ = ["psi_zero_baseline", "reported_baseline"]


def psi_zero_baseline(manipulator: Manipulator, path: PathCheck) -> PathCheck:
    """The path's positions and tool directions with ψ = 0 at every waypoint, checked with the
    path's interpolation and tolerance.

    Parameters
    ----------
    manipulator : Manipulator
    path : PathCheck
        A checked path (waypoint angles in rad, positions in m, base frame).

    Returns
    -------
    PathCheck
        The baseline's check.
    """
    angles = path.waypoints.angles.copy()
    angles[:, 2] = 0.0
    return check_path(
        manipulator,
        path.waypoints.positions,
        angles=angles,
        interpolation=path.interpolation,
        tolerance=path.tolerance,
        arcs=path.arcs,
        beziers=path.beziers,
    )


def reported_baseline(manipulator: Manipulator, result: PathCheck | TorsionPlan) -> PathCheck:
    """The baseline a result is reported with: a plan's own, else :func:`psi_zero_baseline`."""
    if isinstance(result, TorsionPlan):
        return result.baseline
    return psi_zero_baseline(manipulator, result)
