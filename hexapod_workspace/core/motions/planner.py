"""Torsion planning for axisymmetric tools.

Free torsion (axisymmetric tools)
---------------------------------
:func:`plan_torsion` takes positions and tool axes; the torsion ψ at every waypoint is chosen on a
grid of step ``psi_step`` over (−π, π]. Objective, lexicographic:

1. maximise the smallest relative margin along the whole path, measured for every move by the
   certified lower bound ``min_relative_margin_bound`` (so it also bounds the waypoints),
   rounded down to levels of ``margin_resolution`` (0.005 by default): a bottleneck (max-min)
   dynamic programme over waypoints × grid, exact on the grid for these levels, so the plan's
   margin is within one level of the best grid plan;
2. among the plans reaching that optimum, maximise the sum of the moves' certified margins (in
   levels), so the margin stays high where the bottleneck does not bind;
3. then minimise the total torsion travel Σ|Δψ|, so the profile does not zigzag between equal
   choices. (2 and 3 are one min-sum programme over the known moves at the optimum's level.)

A move between two grid torsions counts when its certified check is ok (tolerance ``tol``) and,
with ``max_dpsi``, when ``|wrap(ψ_{k+1} − ψ_k)| ≤ max_dpsi``. Moves certified by their end
margins alone (the interval certificate over the whole move) are not re-checked; the others are
checked in batches, best candidates first, until none of them lies on an optimistic path (one
that counts every unchecked move at its smaller end margin) better than the best plan found. So
the planner is complete to its resolution: "no plan" means that no sequence of grid torsions
gives reachable waypoints joined by ok moves. It then names the first waypoint that no torsion
reaches from the start, and why (the limiting constraints over the grid at that waypoint, or the
constraints that stopped the moves into it).

Where it breaks: the grid. A path whose only feasible torsions lie in intervals narrower than
``psi_step`` may get "no plan" although a finer grid finds one; moves are checked at the
tolerance ``tol`` (bands narrower than it may be missed); the objective is optimal to one level.
Cost grows with (N − 1)·G·B candidate moves (G grid torsions, B torsion changes allowed per
move): ``max_dpsi`` keeps B small. The programmes over these tables are compiled
(:mod:`hexapod_workspace.core.kernels.planner`, a few ms per pass over 1,000 waypoints × 72²
moves, where numpy took ≈ 30 ms); without a torsion limit the full checks of the candidate moves
(≈ 20 µs each) are then most of the time.
"""

from __future__ import annotations

import math
import time
from collections import Counter

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError, ResolutionError
from ..base.resolution import DEFAULT_PLAN_PSI_STEP, validate_plan_psi_step
from ..base.rotations import approach_to_tilt, tt_to_matrix, tt_to_quaternion, wrap_angle
from ..constraints.table import N_CONSTRAINTS
from ..evaluation.check import CONSTRAINT_NAMES, relative_margins
from ..kernels import planner as planner_kernels
from ..model.manipulator import Manipulator
from .certificate import (
    DEFAULT_MAX_SAMPLE_ANGLE,
    DEFAULT_PATH_TOLERANCE,
    _Certifier,
    _check_moves,
)
from .checks import check_path
from .interpolation import (
    _Curves,
    _Moves,
    _unit_rows,
    _validate_curves,
    _validate_interpolation,
    _validate_positions,
    _validate_tolerance,
)
from .results import BreakPoint, TorsionPlan

__all__ = ["DEFAULT_MARGIN_RESOLUTION", "plan_torsion"]

#: Relative-margin levels in which the planner maximises its objective.
DEFAULT_MARGIN_RESOLUTION = 0.005


def plan_torsion(
    manipulator: Manipulator,
    positions: ArrayLike,
    tool_axes: ArrayLike,
    *,
    psi_step: float = DEFAULT_PLAN_PSI_STEP,
    max_dpsi: float | None = None,
    interpolation: str = "slerp",
    tolerance: float = DEFAULT_PATH_TOLERANCE,
    margin_resolution: float = DEFAULT_MARGIN_RESOLUTION,
    arcs: ArrayLike | None = None,
    beziers: ArrayLike | None = None,
) -> TorsionPlan:
    """Choose the torsion at every waypoint of a toolpath for an axisymmetric tool.

    See the module documentation for the objective, the completeness statement and the
    certified move checks.

    Parameters
    ----------
    manipulator : Manipulator
    positions : array_like, shape (N, 3)
        Tool-tip positions, base frame, m (N ≥ 2).
    tool_axes : array_like, shape (N, 3)
        Approach vectors (tool axis z' in the base frame), any non-zero length.
    psi_step : float
        Torsion grid step, rad (0.1° to 90°); the grid is ``−π + k·step`` (it contains ψ = 0
        when the step divides π).
    max_dpsi : float, optional
        Largest torsion change per move, rad (None: no limit).
    interpolation : {"slerp", "tilt-torsion"}
    tolerance : float
        Tolerance of the certified move checks, rad.
    margin_resolution : float
        The objective is maximised in levels of this many relative-margin units (1e-6 to
        0.1): the plan's smallest margin is within this of the best on the grid.
    arcs : array_like, shape (N − 1, 7), optional
        Moves that are arcs, as :func:`~hexapod_workspace.core.motions.checks.check_path` takes
        them.
    beziers : array_like, shape (N − 1, 6), optional
        Moves that are cubic Bézier curves, as
        :func:`~hexapod_workspace.core.motions.checks.check_path` takes them.

    Returns
    -------
    TorsionPlan
        "No plan" is a result (``ok`` False with a :class:`BreakPoint`), not an exception.

    Raises
    ------
    InputError
        Bad shapes, fewer than 2 waypoints, non-finite or zero axes, bad options.
    """
    started = time.perf_counter()
    positions = _validate_positions(positions)
    count = positions.shape[0]
    axes = _unit_rows(tool_axes, count, 3, "tool_axes", "(x, y, z) tool axes")
    interpolation = _validate_interpolation(interpolation)
    tolerance = _validate_tolerance(tolerance)
    psi_step = validate_plan_psi_step(psi_step)
    if max_dpsi is not None:
        max_dpsi = float(max_dpsi)
        if not (math.isfinite(max_dpsi) and max_dpsi >= 0.0):
            msg = f"max_dpsi: expected a finite value >= 0 rad or None, got {max_dpsi!r}"
            raise InputError(msg)
    directions = approach_to_tilt(axes)  # (N, 2)
    circles = _validate_curves(arcs, beziers, positions)
    baseline = check_path(
        manipulator,
        positions,
        angles=np.column_stack([directions, np.zeros(count)]),
        interpolation=interpolation,
        tolerance=tolerance,
        arcs=arcs,
        beziers=beziers,
    )
    margin_resolution = float(margin_resolution)
    if not (math.isfinite(margin_resolution) and 1e-6 <= margin_resolution <= 0.1):
        msg = f"margin_resolution: expected 1e-06 to 0.1, got {margin_resolution!r}"
        raise ResolutionError(msg)
    planner = _Planner(
        manipulator,
        positions,
        directions,
        psi_step,
        max_dpsi,
        interpolation,
        tolerance,
        margin_resolution,
        circles,
    )
    psi, objective, breakpoint = planner.solve()
    path = None
    if psi is not None:
        path = check_path(
            manipulator,
            positions,
            angles=np.column_stack([directions, psi]),
            interpolation=interpolation,
            tolerance=tolerance,
            arcs=arcs,
            beziers=beziers,
        )
    return TorsionPlan(
        ok=psi is not None,
        psi=psi,
        path=path,
        objective=objective,
        baseline=baseline,
        breakpoint=breakpoint,
        psi_step=psi_step,
        max_dpsi=max_dpsi,
        interpolation=interpolation,
        tolerance=tolerance,
        moves_checked=planner.moves_checked,
        elapsed=time.perf_counter() - started,
        positions=positions,
        directions=directions,
    )


#: Level code of "no move" (infeasible or not allowed) in the planner's integer tables.
_NONE = planner_kernels.NONE
#: Largest level magnitude stored (relative margins beyond ±2^30 levels are clipped).
_LEVEL_CLIP = 2**30
#: Pair status in the planner: no move, value known, not yet checked (optimistic value).
_NO, _KNOWN, _UNKNOWN = planner_kernels.NO, planner_kernels.KNOWN, planner_kernels.UNKNOWN
#: Moves given the full certified check per batch of the planner.
CHECK_BATCH = 2000
#: Largest number of candidate moves (waypoint pairs × torsions × torsion changes) per plan.
MAX_PLAN_MOVES = 30_000_000


def _best_first(through: NDArray[np.int32], count: int) -> NDArray[np.int64]:
    """Indices of the ``count`` largest values, largest first, ties in index order: exactly
    ``np.argsort(-through, kind="stable")[:count]``, in O(n) plus a sort of ``count`` values."""
    size = through.shape[0]
    if size <= count:
        return np.argsort(-through.astype(np.int64), kind="stable")
    threshold = np.partition(through, size - count)[size - count]  # the count-th largest
    above = np.flatnonzero(through > threshold)
    ties = np.flatnonzero(through == threshold)[: count - above.size]
    chosen = np.union1d(above, ties)  # sorted: index order
    order = np.argsort(-through[chosen].astype(np.int64), kind="stable")
    return chosen[order].astype(np.int64)


class _Planner:
    """Bottleneck + min-travel dynamic programmes over waypoints × torsion grid.

    Values are integer levels ``floor(relative margin / resolution)``. A move from torsion g at
    waypoint k goes to ``h = (g + offset) mod G`` for the allowed offsets (all of them, or those
    within ``max_dpsi``), so the tables are banded, shape (N − 1, G, B). Every move is in one of
    three states: no move (an end unreachable or checked and not ok), known (certified by its
    end margins alone, or checked in full; value = level of its certified lower bound) or
    unknown (not certified by its ends; its value is at most the level of its smaller end
    margin: the *optimistic* value). The search checks, in batches, the unknown moves that lie
    on an optimistic path better than the best known plan, until none is left: the best known
    plan is then optimal on the grid (to one level).
    """

    def __init__(
        self,
        manipulator: Manipulator,
        positions: NDArray[np.float64],
        directions: NDArray[np.float64],
        psi_step: float,
        max_dpsi: float | None,
        interpolation: str,
        tolerance: float,
        resolution: float,
        arcs: _Curves | None = None,
    ) -> None:
        self.certifier = _Certifier(manipulator)
        self.arcs = arcs
        self.positions = positions
        self.interpolation = interpolation
        self.tolerance = tolerance
        self.resolution = resolution
        self.max_dpsi = max_dpsi
        self.moves_checked = 0
        size = max(1, round(2.0 * math.pi / psi_step))
        self.grid = wrap_angle(-math.pi + psi_step * np.arange(size))
        self.grid_size = size
        reach = size // 2 if max_dpsi is None else math.floor(max_dpsi / psi_step + 1e-9)
        if 2 * reach + 1 >= size:
            offsets = np.arange(size) - size // 2
        else:
            offsets = np.arange(-reach, reach + 1)
        self.offsets = offsets
        count = positions.shape[0]
        if (count - 1) * size * offsets.size > MAX_PLAN_MOVES:
            msg = (
                f"plan_torsion: {count - 1} moves x {size} torsions x {offsets.size} torsion "
                f"changes exceed {MAX_PLAN_MOVES:g} candidate moves; use a coarser psi_step, "
                f"a max_dpsi or fewer waypoints"
            )
            raise ResolutionError(msg)
        # dest[g, b]: target torsion of offset b from torsion g.
        self.dest = (np.arange(size)[:, None] + offsets[None, :]) % size
        self.travel = np.abs(wrap_angle(offsets * (2.0 * math.pi / size)))  # (B,)
        angles = np.empty((count, size, 3))
        angles[:, :, 0] = directions[:, 0:1]
        angles[:, :, 1] = directions[:, 1:2]
        angles[:, :, 2] = self.grid
        self.rotations = tt_to_matrix(angles)  # (N, G, 3, 3)
        self.quaternions = tt_to_quaternion(angles)  # (N, G, 4)
        flat = self.certifier.margins(
            self.rotations.reshape(-1, 3, 3), np.repeat(positions, size, axis=0)
        )
        self.margins = flat.margins.reshape(N_CONSTRAINTS, count, size)
        self.relative_flat = relative_margins(manipulator, flat.margins)
        self.feasible = np.all(self.margins >= 0.0, axis=0)  # (N, G)
        self.levels = np.where(
            self.feasible,
            self._level(self.certifier.relative(flat.margins)).reshape(count, size),
            _NONE,
        ).astype(np.int32)
        shape = (count - 1, size, offsets.size)
        self.status = np.zeros(shape, dtype=np.uint8)
        self.value = np.full(shape, _NONE, dtype=np.int32)
        self.stopped = np.full(shape, -1, dtype=np.int8)
        self._certify_by_ends()

    def _level(self, values: NDArray[np.float64]) -> NDArray[np.int32]:
        """Relative margins as integer levels of the margin resolution (NaN → no move)."""
        with np.errstate(invalid="ignore", over="ignore"):
            scaled = np.floor(values / self.resolution)
        scaled = np.clip(np.nan_to_num(scaled, nan=-np.inf), -_LEVEL_CLIP, _LEVEL_CLIP)
        return scaled.astype(np.int32)

    def _moves(self, k: NDArray[np.int64], g: NDArray[np.int64], h: NDArray[np.int64]) -> _Moves:
        return _Moves(
            self.positions[k],
            self.positions[k + 1],
            self.rotations[k, g],
            self.rotations[k + 1, h],
            self.interpolation,
            self.certifier.rho,
            quaternions=(self.quaternions[k, g], self.quaternions[k + 1, h]),
            arcs=None if self.arcs is None else self.arcs.take(k),
        )

    def _certify_by_ends(self) -> None:
        """Status and values of every allowed move between reachable ends, from the end margins
        alone (interval certificate over the whole move)."""
        per_step = self.grid_size * self.offsets.size
        chunk = max(1, 200_000 // per_step)
        for first in range(0, self.status.shape[0], chunk):
            last = min(first + chunk, self.status.shape[0])
            steps = np.arange(first, last)[:, None, None]
            pairs = self.feasible[first:last, :, None] & self.feasible[steps + 1, self.dest]
            k, g, b = np.nonzero(pairs)
            k = k + first
            h = self.dest[g, b]
            moves = self._moves(k, g, h)
            bounds = self.certifier.lower_bounds(
                self.margins[:, k, g],
                self.margins[:, k + 1, h],
                np.ones(k.size),
                moves.speed,
                moves.omega,
            )
            certified = np.all(bounds >= 0.0, axis=0)
            self.status[k, g, b] = np.where(certified, _KNOWN, _UNKNOWN)
            # Unknown moves: at most the level of their smaller end margin.
            optimistic = np.minimum(self.levels[k, g], self.levels[k + 1, h])
            self.value[k, g, b] = np.where(
                certified, self._level(self.certifier.relative(bounds)), optimistic
            )

    # ---------------------------------------------------------------- programmes
    def _forward(self, optimistic: bool) -> NDArray[np.int32]:
        """Bottleneck value (N, G) of the best path from waypoint 0 to each state (compiled:
        :func:`planner_kernels.forward`)."""
        reach = np.empty(self.levels.shape, dtype=np.int32)
        planner_kernels.forward(
            self.levels[0], self.status, self.value, self.dest, optimistic, reach
        )
        return reach

    def _backward(self) -> NDArray[np.int32]:
        """Optimistic bottleneck value (N, G) of the best path from each state to the end."""
        back = np.empty(self.levels.shape, dtype=np.int32)
        planner_kernels.backward(self.levels, self.status, self.value, self.dest, back)
        return back

    def _check(self, k: NDArray[np.int64], g: NDArray[np.int64], b: NDArray[np.int64]) -> None:
        """Full certified check of moves (k, g, b), sampled as :func:`check_path` samples them
        (so a plan's re-check reproduces these bounds); updates status, value and stopped."""
        h = self.dest[g, b]
        moves = self._moves(k, g, h)
        raw = _check_moves(
            self.certifier,
            moves,
            self.margins[:, k, g],
            self.margins[:, k + 1, h],
            self.tolerance,
            DEFAULT_MAX_SAMPLE_ANGLE,
            locate_minimum=False,
        )
        self.moves_checked += k.size
        self.status[k, g, b] = np.where(raw.ok, _KNOWN, _NO)
        self.value[k, g, b] = np.where(raw.ok, self._level(raw.bound), _NONE)
        bad = ~raw.ok
        if np.any(bad):
            rows = raw.bad_index[bad]
            relative = relative_margins(self.certifier.manipulator, raw.samples["margins"][:, rows])
            worst = np.argmin(np.where(np.isnan(relative), -np.inf, relative), axis=0)
            self.stopped[k[bad], g[bad], b[bad]] = worst

    def solve(self) -> tuple[NDArray[np.float64] | None, float, BreakPoint | None]:
        """The plan (ψ per waypoint, rad), its objective and the break point (without a plan)."""
        while True:
            best = int(self._forward(optimistic=False)[-1].max())
            # Optimistic bottleneck of the best path through each move (recomputed after every
            # batch: the checks lower it, and that is what prunes the remaining moves).
            k, g, b, through = planner_kernels.candidates(
                self._forward(optimistic=True),
                self._backward(),
                self.status,
                self.value,
                self.dest,
                best,
            )
            if k.size == 0:
                break
            if k.size > CHECK_BATCH:
                top = _best_first(through, CHECK_BATCH)
                k, g, b = k[top], g[top], b[top]
            self._check(k, g, b)
        if best == _NONE:
            return None, -math.inf, self._breakpoint()
        return self._smoothest(best), best * self.resolution, None

    def _smoothest(self, best: int) -> NDArray[np.float64]:
        """Among the known moves whose level reaches the objective: the largest sum of move
        levels, then the least torsion travel Σ|Δψ|; ψ (N,), rad."""
        # cost = −Σ levels · scale + Σ|Δψ|: scale exceeds any total travel (N·π), so the sum of
        # levels decides and the travel only breaks ties (exact in float64 for these sizes).
        scale = float(self.status.shape[0] + 1) * 4.0
        path = planner_kernels.smoothest(
            self.levels[0], self.status, self.value, self.dest, self.travel, best, scale
        )
        return self.grid[path]

    def _breakpoint(self) -> BreakPoint:
        """The first waypoint that no torsion reaches from the start, with the reasons."""
        while True:
            reach = self._forward(optimistic=False) > _NONE
            first = int(np.argmin(np.any(reach, axis=1)))
            if not np.any(self.feasible[first]):
                return self._waypoint_break(first)
            k = first - 1
            g, b = np.nonzero(reach[k][:, None] & (self.status[k] == _UNKNOWN))
            if g.size == 0:
                return self._segment_break(k, reach[k])
            self._check(np.full(g.size, k), g, b)

    def _waypoint_break(self, index: int) -> BreakPoint:
        size = self.grid_size
        relative = self.relative_flat[:, index * size : (index + 1) * size]
        worst = np.argmin(np.where(np.isnan(relative), -np.inf, relative), axis=0)
        counts = Counter(CONSTRAINT_NAMES[c] for c in worst.tolist())
        names = ", ".join(f"{name} ({n})" for name, n in counts.most_common())
        reason = (
            f"waypoint {index}: no torsion on the {math.degrees(2 * math.pi / size):g} deg grid "
            f"is reachable there (limiting constraint over the {size} torsions: {names})"
        )
        return BreakPoint("waypoint", index, dict(counts), reason)

    def _segment_break(self, index: int, reach: NDArray[np.bool_]) -> BreakPoint:
        sources = int(np.count_nonzero(reach))
        targets = int(np.count_nonzero(self.feasible[index + 1]))
        pairs = reach[:, None] & self.feasible[index + 1][self.dest]
        stopped = self.stopped[index][pairs]
        counts = Counter(CONSTRAINT_NAMES[c] for c in stopped[stopped >= 0].tolist())
        limit = ""
        if self.max_dpsi is not None:
            every = int(np.count_nonzero(reach)) * targets
            limit = (
                f"; {int(np.count_nonzero(pairs))} of {every} torsion pairs are within "
                f"max_dpsi {math.degrees(self.max_dpsi):g} deg"
            )
        names = ", ".join(f"{name} ({n})" for name, n in counts.most_common()) or "none"
        reason = (
            f"segment {index} (waypoints {index} -> {index + 1}): no certified move from the "
            f"{sources} torsions that continue the path at waypoint {index} to the {targets} "
            f"reachable at waypoint {index + 1}{limit}; moves stopped by: {names}"
        )
        return BreakPoint("segment", index, dict(counts), reason)
