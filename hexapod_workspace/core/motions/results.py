"""Results of the motion checks and of the torsion planner (plain dataclasses of arrays)."""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..evaluation.check import CONSTRAINT_NAMES, violated_by_name, violated_names

__all__ = [
    "BreakPoint",
    "PathCheck",
    "SegmentChecks",
    "TorsionPlan",
    "WaypointChecks",
    "reported_parts",
]


@dataclass(frozen=True)
class WaypointChecks:
    """Reachability of every waypoint (the ``check`` result, one position per pose).

    Attributes
    ----------
    positions : ndarray, shape (N, 3)
        Tool-tip positions OC, base frame, m.
    angles : ndarray, shape (N, 3)
        (φ, θ, ψ) in rad, canonical ranges.
    reachable : ndarray, shape (N,), bool
    margins : dict of str to ndarray, shape (N,)
        Signed margin of each constraint, keyed by the constraint table's names
        (:data:`~hexapod_workspace.core.constraints.table.CONSTRAINT_NAMES`),
        each in its row's unit (m, rad or 1); +inf when not evaluated (interference with
        D = 0, singularity with ``limits.singularity_min`` 0), as in :class:`CheckResult`.
    relative : ndarray, shape (N,)
        Smallest relative margin (dimensionless, see :func:`relative_margins`).
    limiting_constraint : ndarray, shape (N,), int
        Index into :data:`~hexapod_workspace.core.constraints.table.CONSTRAINT_NAMES` of the
        smallest relative margin.
    limiting_leg : ndarray, shape (N,), int
        1-based leg of the limiting constraint (interference: lower leg of the pair).
    limiting_pair : ndarray, shape (N, 2), int
        1-based closest leg pair (0, 0 when the interference check is disabled).
    collision_pair : tuple of str
        Per waypoint, the closest pair of the collision scene (``"tool vs leg 4"``); empty
        (length 0) when the model declares no scene.
    """

    positions: NDArray[np.float64]
    angles: NDArray[np.float64]
    reachable: NDArray[np.bool_]
    margins: dict[str, NDArray[np.float64]]
    relative: NDArray[np.float64]
    limiting_constraint: NDArray[np.int64]
    limiting_leg: NDArray[np.int64]
    limiting_pair: NDArray[np.int64]
    collision_pair: tuple[str, ...] = ()

    def __len__(self) -> int:
        return int(self.reachable.shape[0])

    @property
    def margin_array(self) -> NDArray[np.float64]:
        """The margins as one array, shape (C, N), rows in the order of
        :data:`~hexapod_workspace.core.constraints.table.CONSTRAINT_NAMES`."""
        absent = np.full(len(self), np.inf)  # rows that do not apply to the architecture
        return np.stack([self.margins.get(name, absent) for name in CONSTRAINT_NAMES])

    @functools.cached_property
    def violated(self) -> list[list[str]]:
        """Per waypoint, the names of the violated constraints (computed on first access and
        kept: the result is frozen, so reading it pose by pose costs O(1) per pose)."""
        return violated_by_name(self.margins, len(self))


@dataclass(frozen=True)
class SegmentChecks:
    """Certified checks of the M = N − 1 moves between consecutive waypoints.

    Attributes
    ----------
    ok : ndarray, shape (M,), bool
        No violation wider than the tolerance anywhere on the move (ends included).
    first_violation_s : ndarray, shape (M,)
        Parameter s ∈ [0, 1] of the first violated pose found (NaN when ok); the true first
        violation lies within one tolerance step ``h`` before it.
    violation_angles : ndarray, shape (M, 3)
        (φ, θ, ψ) of that pose, rad (NaN when ok).
    violation_positions : ndarray, shape (M, 3)
        Its position, base frame, m (NaN when ok).
    violation_margins : ndarray, shape (C, M)
        Its margins (NaN when ok).
    limiting_constraint : ndarray, shape (M,), int
        At the first violation (most violated, relative units), else at the smallest margin.
    limiting_leg : ndarray, shape (M,), int
        1-based leg of that constraint.
    limiting_pair : ndarray, shape (M, 2), int
        1-based closest leg pair at the same pose.
    min_relative_margin : ndarray, shape (M,)
        Smallest relative margin over the evaluated poses of [0, min(1, first violation)].
    min_at_s : ndarray, shape (M,)
        Where it is.
    min_relative_margin_bound : ndarray, shape (M,)
        Certified lower bound of the relative margin over the same range.
    angular_rate : ndarray, shape (M,)
        Ω, bound on the angular speed, rad per unit s.
    translation : ndarray, shape (M,)
        |Δp|, m.
    evaluations : int
        Poses evaluated inside the moves (the waypoints excluded).
    collision_pair : tuple of str
        Per move, the closest pair of the collision scene at the first violation (else at the
        smallest margin); empty (length 0) when the model declares no scene.
    """

    ok: NDArray[np.bool_]
    first_violation_s: NDArray[np.float64]
    violation_angles: NDArray[np.float64]
    violation_positions: NDArray[np.float64]
    violation_margins: NDArray[np.float64]
    limiting_constraint: NDArray[np.int64]
    limiting_leg: NDArray[np.int64]
    limiting_pair: NDArray[np.int64]
    min_relative_margin: NDArray[np.float64]
    min_at_s: NDArray[np.float64]
    min_relative_margin_bound: NDArray[np.float64]
    angular_rate: NDArray[np.float64]
    translation: NDArray[np.float64]
    evaluations: int
    collision_pair: tuple[str, ...] = ()

    def __len__(self) -> int:
        return int(self.ok.shape[0])

    @functools.cached_property
    def violated(self) -> list[list[str]]:
        """Per move, the constraints violated at its first violation (empty when ok; computed on
        first access and kept)."""
        return violated_names(
            np.where(np.isnan(self.violation_margins), 0.0, self.violation_margins)
        )


@dataclass(frozen=True)
class PathCheck:
    """Result of :func:`check_path`.

    Attributes
    ----------
    waypoints : WaypointChecks
    segments : SegmentChecks
    interpolation : str
        ``"slerp"`` or ``"tilt-torsion"``.
    tolerance : float
        rad of platform rotation (see the module documentation).
    elapsed : float
        s.
    arcs : ndarray, shape (N − 1, 7), or None
        The moves that are arcs, as :func:`check_path` took them (NaN rows: straight moves);
        None when every move is straight.
    beziers : ndarray, shape (N − 1, 6), or None
        The moves that are cubic Bézier curves, as :func:`check_path` took them (their inner
        control points; NaN rows: other moves); None when none is.
    """

    waypoints: WaypointChecks
    segments: SegmentChecks
    interpolation: str
    tolerance: float
    elapsed: float
    arcs: NDArray[np.float64] | None = field(default=None, repr=False)
    beziers: NDArray[np.float64] | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        """Every waypoint and every move can run."""
        return bool(np.all(self.waypoints.reachable) and np.all(self.segments.ok))

    @property
    def failed_waypoints(self) -> list[int]:
        """0-based indices of the unreachable waypoints."""
        failed: list[int] = np.flatnonzero(~self.waypoints.reachable).tolist()
        return failed

    @property
    def failed_segments(self) -> list[int]:
        """0-based indices of the moves that cannot run (move k joins waypoints k and k + 1)."""
        failed: list[int] = np.flatnonzero(~self.segments.ok).tolist()
        return failed


@dataclass(frozen=True)
class BreakPoint:
    """Where a toolpath cannot be continued by any torsion of the grid.

    Attributes
    ----------
    kind : str
        ``"waypoint"`` (no torsion reaches waypoint ``index``) or ``"segment"`` (no ok move
        from the torsions reachable at waypoint ``index`` to those at ``index + 1``).
    index : int
        0-based waypoint or move index.
    constraints : dict of str to int
        How often each constraint limited the grid torsions (waypoint) or the checked moves
        (segment): why the path breaks.
    reason : str
        One sentence for humans.
    """

    kind: str
    index: int
    constraints: dict[str, int]
    reason: str


@dataclass(frozen=True)
class TorsionPlan:
    """Result of :func:`plan_torsion`.

    Attributes
    ----------
    ok : bool
        A plan exists on the grid.
    psi : ndarray, shape (N,) or None
        Planned torsion at every waypoint, rad in (−π, π] (None without a plan).
    path : PathCheck or None
        The planned path re-checked by :func:`check_path` (None without a plan).
    objective : float
        Smallest certified relative margin along the plan (−inf without a plan).
    baseline : PathCheck
        The same waypoints with ψ ≡ 0 (the paper's recommendation).
    breakpoint : BreakPoint or None
        Where and why the path breaks (None with a plan).
    psi_step : float
        Grid step, rad.
    max_dpsi : float or None
        Largest torsion change per move, rad (None: no limit).
    interpolation : str
    tolerance : float
        rad.
    moves_checked : int
        Candidate moves given the full certified check (the others were certified by their end
        margins or could not improve the plan).
    elapsed : float
        s.
    positions : ndarray, shape (N, 3)
        The waypoints' tool-tip positions, base frame, m.
    directions : ndarray, shape (N, 2)
        The tool directions (φ, θ) of the given axes, rad.
    """

    ok: bool
    psi: NDArray[np.float64] | None
    path: PathCheck | None
    objective: float
    baseline: PathCheck
    breakpoint: BreakPoint | None
    psi_step: float
    max_dpsi: float | None
    interpolation: str
    tolerance: float
    moves_checked: int
    elapsed: float
    positions: NDArray[np.float64] = field(repr=False)
    directions: NDArray[np.float64] = field(repr=False)

    @property
    def reported(self) -> PathCheck:
        """The path this plan reports: the planned one when ok, otherwise the ψ = 0 baseline."""
        return self.path if self.ok and self.path is not None else self.baseline


def reported_parts(result: PathCheck | TorsionPlan) -> tuple[PathCheck, TorsionPlan | None]:
    """The path a result reports (:attr:`TorsionPlan.reported` for a plan) and the plan, if any."""
    if isinstance(result, TorsionPlan):
        return result.reported, result
    return result, None
