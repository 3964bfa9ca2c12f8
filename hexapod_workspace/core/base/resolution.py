"""One definition of every resolution fact: methods, kinds, bounds, defaults, and their checks.

The core functions, the CLI, the ROS node (parameter ranges, request checks) and the logs (the
``kind`` constant of a recorded request) all read these names, so the same request gets the same
answer and the same refusal wherever it comes in.

Units: rad for angles and tolerances; counts are plain integers.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError, ResolutionError

__all__ = [
    "DEFAULT_N_PHI",
    "DEFAULT_N_RAYS",
    "DEFAULT_PLAN_PSI_STEP",
    "DEFAULT_PSI_STEP",
    "DEFAULT_TOLERANCE",
    "MAX_PLAN_PSI_STEP",
    "MAX_POINTS",
    "MAX_POSITION_NORM",
    "MAX_PSI_STEP",
    "MAX_RAYS",
    "MAX_SLICES",
    "MAX_TOLERANCE",
    "MAX_WAYPOINTS",
    "MIN_PLAN_PSI_STEP",
    "MIN_PSI_STEP",
    "MIN_RAYS",
    "MIN_TOLERANCE",
    "Method",
    "Progress",
    "WorkspaceKind",
    "validate_plan_psi_step",
    "validate_position",
    "validate_positions",
    "validate_psi_step",
    "validate_rays",
    "validate_tolerance",
]


class Method(str, enum.Enum):
    """How the projected orientation workspace is computed."""

    #: The paper's approximation: the boundary along each azimuth at ψ = 0.
    TORSION_ZERO = "torsion_zero"
    #: The true shadow: for each azimuth the largest tilt attainable with some torsion.
    EXACT = "exact"

    def __str__(self) -> str:
        return self.value


class WorkspaceKind(enum.IntEnum):
    """What a workspace request asks for (the ``kind`` constants of ``WorkspaceRequest.msg``)."""

    ORIENTATION = 0
    PROJECTED_TORSION_ZERO = 1
    PROJECTED_EXACT = 2

    @property
    def label(self) -> str:
        """``orientation``, ``torsion_zero`` or ``exact``: the name used in reports and logs."""
        return _KIND_LABELS[self]

    @classmethod
    def of(cls, value: int) -> WorkspaceKind | None:
        """The kind whose constant is ``value``, or None when no kind has it."""
        try:
            return cls(int(value))
        except (ValueError, TypeError):
            return None

    @classmethod
    def projected(cls, method: Method | str) -> WorkspaceKind:
        """The kind of a projected workspace computed with ``method``."""
        return cls.PROJECTED_EXACT if Method(method) is Method.EXACT else cls.PROJECTED_TORSION_ZERO


_KIND_LABELS = {
    WorkspaceKind.ORIENTATION: "orientation",
    WorkspaceKind.PROJECTED_TORSION_ZERO: Method.TORSION_ZERO.value,
    WorkspaceKind.PROJECTED_EXACT: Method.EXACT.value,
}

#: Bounds on ray counts (``n_phi``, ``n_rays``).
MIN_RAYS, MAX_RAYS = 3, 7200
#: Bounds on boundary tolerances, rad.
MIN_TOLERANCE, MAX_TOLERANCE = 1e-12, 0.1
#: Bounds on the slice step Δψ of the orientation workspace, rad.
MIN_PSI_STEP, MAX_PSI_STEP = 1e-4, 0.5
#: Bounds on the torsion grid step of the toolpath planner, rad (0.1° to 90°). Another fact
#: than the slice step: the planner's grid is coarse (its moves are certified between grid
#: torsions), the slices of a workspace are fine.
MIN_PLAN_PSI_STEP, MAX_PLAN_PSI_STEP = math.radians(0.1), math.radians(90.0)
#: Largest number of waypoints of one toolpath check or plan.
MAX_WAYPOINTS = 1_000_000
#: Largest number of slices one orientation workspace may produce (both directions together).
MAX_SLICES = 20_000
#: Largest number of boundary points (slices × rays) one orientation workspace may produce.
MAX_POINTS = 5_000_000

#: Largest accepted distance |OC| of a position from the base origin, m. Far beyond any
#: machine (legs are metres long), and small enough that every squared length, leg direction and
#: margin computed from it stays a finite number.
MAX_POSITION_NORM = 1e6

#: Default azimuths of the projected workspace.
DEFAULT_N_PHI = 360
#: Default rays per slice of the orientation workspace.
DEFAULT_N_RAYS = 180
#: Default slice step of the orientation workspace, rad (1°).
DEFAULT_PSI_STEP = math.radians(1.0)
#: Default torsion grid step of the toolpath planner, rad (5°).
DEFAULT_PLAN_PSI_STEP = math.radians(5.0)
#: Default boundary tolerance of every computation (API, CLI and node alike), rad.
DEFAULT_TOLERANCE = 1e-6

#: A progress callback: receives the fraction done, 0..1, non-decreasing.
Progress = Callable[[float], None]


def validate_rays(count: int, name: str) -> int:
    """Check a ray count (``n_phi``, ``n_rays``) against [:data:`MIN_RAYS`, :data:`MAX_RAYS`]."""
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)):
        msg = f"{name}: expected an integer, got {count!r}"
        raise ResolutionError(msg)
    if not MIN_RAYS <= count <= MAX_RAYS:
        msg = f"{name}: expected {MIN_RAYS} to {MAX_RAYS} rays, got {count}"
        raise ResolutionError(msg)
    return int(count)


def _bounded(value: float, low: float, high: float, name: str) -> float:
    """``value`` as a float when finite and within [low, high] rad, else ResolutionError."""
    number = float(value)
    if not (math.isfinite(number) and low <= number <= high):
        msg = f"{name}: expected {low:g} to {high:g} rad, got {value!r}"
        raise ResolutionError(msg)
    return number


def validate_tolerance(tolerance: float, name: str = "tolerance") -> float:
    """Check a boundary tolerance (rad) against [:data:`MIN_TOLERANCE`, :data:`MAX_TOLERANCE`]."""
    return _bounded(tolerance, MIN_TOLERANCE, MAX_TOLERANCE, name)


def validate_psi_step(psi_step: float, name: str = "psi_step") -> float:
    """Check a slice step Δψ (rad) against [:data:`MIN_PSI_STEP`, :data:`MAX_PSI_STEP`]."""
    return _bounded(psi_step, MIN_PSI_STEP, MAX_PSI_STEP, name)


def validate_plan_psi_step(psi_step: float, name: str = "psi_step") -> float:
    """Check a planner torsion grid step (rad) against [:data:`MIN_PLAN_PSI_STEP`,
    :data:`MAX_PLAN_PSI_STEP`]."""
    number = float(psi_step)
    if not (math.isfinite(number) and MIN_PLAN_PSI_STEP <= number <= MAX_PLAN_PSI_STEP):
        msg = (
            f"{name}: expected {MIN_PLAN_PSI_STEP:.4g} to {MAX_PLAN_PSI_STEP:.4g} rad, "
            f"got {psi_step!r}"
        )
        raise ResolutionError(msg)
    return number


def validate_positions(positions: ArrayLike, minimum: int, maximum: int) -> NDArray[np.float64]:
    """Positions of ``minimum`` to ``maximum`` waypoints, shape (N, 3), m, base frame, checked
    as :func:`validate_position` checks one: finite and within :data:`MAX_POSITION_NORM` of
    the base origin (so a toolpath accepts exactly the points a pose check accepts).

    Raises
    ------
    InputError
        Wrong shape or count, naming the first bad waypoint otherwise.
    """
    array = np.asarray(positions, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 3:
        msg = f"positions: expected shape (N, 3) in m, got {array.shape}"
        raise InputError(msg)
    if not minimum <= array.shape[0] <= maximum:
        msg = f"positions: expected {minimum} to {maximum} waypoints, got {array.shape[0]}"
        raise InputError(msg)
    with np.errstate(over="ignore", invalid="ignore"):
        norms = np.linalg.norm(array, axis=1)
    bad = ~(np.all(np.isfinite(array), axis=1) & (norms <= MAX_POSITION_NORM))
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        msg = (
            f"positions: expected finite values within {MAX_POSITION_NORM:g} m of the base "
            f"origin, waypoint {row} is {array[row].tolist()}"
        )
        raise InputError(msg)
    return array


def validate_position(position: ArrayLike | None, default: ArrayLike) -> NDArray[np.float64]:
    """The position to use, checked: shape (3,), finite, m; ``default`` (a model's
    ``pose.position``) when ``position`` is None.

    Raises
    ------
    InputError
        Not 3 values, NaN or infinite values, or farther than :data:`MAX_POSITION_NORM` from
        the base origin (where margins would stop being finite numbers).
    """
    if position is None:
        return np.array(default, dtype=np.float64)
    try:
        array = np.asarray(position, dtype=np.float64)
    except (TypeError, ValueError) as error:
        msg = f"position: expected 3 numbers (x, y, z) in m, got {position!r}"
        raise InputError(msg) from error
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        msg = f"position: expected 3 finite values (x, y, z) in m, got {np.ravel(array).tolist()}"
        raise InputError(msg)
    if not float(np.linalg.norm(array)) <= MAX_POSITION_NORM:
        msg = (
            f"position: expected a distance from the base origin of at most "
            f"{MAX_POSITION_NORM:g} m, got {array.tolist()}"
        )
        raise InputError(msg)
    return array
