"""The move certificate: interval lower bounds of the margins along moves, and the bisection.

-----------------------------------------------------------------------
This extends the argument of :mod:`hexapod_workspace.core.workspaces.search` from rays (pure
rotations at ω ≤ 1) to moves that translate and rotate at once.

*Angular rate.* For slerp ``|ω(s)| = Ω`` exactly. For the tilt-torsion interpolation, write the
orientation in ZYZ Euler angles ``(α, β, γ) = (φ, θ, ψ − φ)``; the space-frame angular velocity is
``ω = α'·e_z + β'·Rz(α)e_y + γ'·Rz(α)Ry(β)e_z`` and, since e_z ⊥ Rz(α)e_y and
Rz(α)e_y ⊥ Rz(α)Ry(β)e_z,

    |ω|² = α'² + β'² + γ'² + 2α'γ' cos β,   α' = Δφ, β' = Δθ, γ' = Δψ − Δφ.

The rates are constant along the move and β = θ(s) is linear in [0, π], where cos is monotone,
so the maximum over the move is at an end: ``Ω = max over θ ∈ {θ₀, θ₁} of |ω|``.

*Joint speed.* Platform joint i is at ``B_i(s) = p(s) + R(s)·b_i``, so
``|dB_i/ds| = |Δp + ω × R b_i| ≤ |Δp| + Ω·ρ =: V`` with ρ = max_i |b_i|. For 6-UPS the base
joints A_i are fixed, so each leg vector ``L_i = B_i − A_i`` moves at most at V; for 6-PUS and
6-RUS the base-side end moves too, at most at V/τ_f with τ_f a lower bound of the transmission
``|τ_i|`` over the interval (:mod:`hexapod_workspace.core.constraints.table`).

*Margins.* With ``ℓ_f`` a lower bound on every leg length over the interval considered, each
margin is Lipschitz in s with the rate of its row of
:mod:`hexapod_workspace.core.constraints.table`, ``speed·V + turn·N + spin·Ω + actuate·Q +
crank·K + ends·E`` (for 6-UPS: V for ``leg_length``, V / ℓ_f for ``base_joint``, Ω + V / ℓ_f for
``platform_joint``, 2V for ``leg_interference``, V + ρ_c·Ω for ``collision``, ρ_c from the
model's scene, bounding the derived |Δp| + ρ_c·Ω since V ≥ |Δp|; the derivations are written
there).

*Moving base joints (pus, rus).* The legs have fixed lengths (ℓ_f = min L_i) and the rates
need a transmission floor τ_f. On an interval [a, b] of width w, ``|τ|`` changes at most at
``rate_τ(τ_f) = V/L + V(1/L + c)/τ_f`` (c = 1/r_min for rus, 0 for pus) while ``|τ| ≥ τ_f``;
any τ_f ≤ min(τ(a), τ(b)) with ``2τ_f ≤ τ(a) + τ(b) − rate_τ(τ_f)·w`` then holds on the whole
interval (from each end, ``|τ|`` cannot reach τ_f before the two stretches meet). Multiplied by
τ_f this is ``2τ_f² − S·τ_f + V·w(1/L + c) ≤ 0`` with ``S = τ(a) + τ(b) − V·w/L``: the
certificate takes the larger root, capped at min(τ(a), τ(b)), when it is admissible and the
``ik`` bound (rate V, no floor needed) shows every leg solvable on the interval; otherwise the
bounds that need τ_f are −inf and the interval is split.

*Interval certificate.* On an interval [a, b] of width w = b − a, with margins m(a), m(b) and
constant L, ``m(s) ≥ max(m(a) − L(s − a), m(b) − L(b − s))`` whose minimum over the interval is

    m_low = min(m(a), m(b), (m(a) + m(b) − L·w) / 2).

The leg-length floor comes the same way: ``ℓ_i ≥ ℓmin + m_leg`` at each end (true for every leg,
feasible or not, since m_leg ≤ ℓ_i − ℓmin_i), so ``ℓ_f = (λ(a) + λ(b) − V·w)/2`` with
``λ = min ℓmin + m_leg``, raised to min ℓmin when the leg-length bound m_low ≥ 0 (then no leg is
shorter than its minimum on the interval). When every m_low ≥ 0 the whole interval is reachable:
it is *certified*. The check bisects the intervals that are not certified, in every segment at
once, until each is certified or narrower than the tolerance ``h`` (in s). The tolerance is
given as an angle ``tol`` (rad): ``h = tol / (Ω + |Δp| / ρ)``, i.e. ``tol`` of platform rotation,
or ``ρ·tol`` of platform-joint travel. Hence:

* an ``ok`` segment has every interval certified, except intervals narrower than ``h`` in which
  every margin is within ``L·h`` of zero: only a violated band narrower than the tolerance can
  hide there;
* the first violation reported is a sampled pose that violates (it is returned with its
  constraints), and every interval before it is certified or narrower than ``h``: no violation
  wider than the tolerance lies before it, and the feasible sample before it is within ``h``.

The smallest relative margin along a segment is reported twice: the smallest over the poses the
check evaluated (``min_relative_margin`` at ``min_at_s``: intervals are also split until no
sample step exceeds ``max_sample_angle`` of motion) and a certified lower bound
(``min_relative_margin_bound``: the smallest ``m_low`` of the final intervals, relative units).
On a violated segment both cover [0, first violation].
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TypedDict

import numpy as np
from numpy.typing import NDArray

from ..constraints.table import (
    IK,
    LEG_LENGTH,
    N_CONSTRAINTS,
    SINGULARITY,
    TRANSMISSION,
    applicable,
    rate_bounds,
)
from ..evaluation.check import PoseMargins, pose_margins, relative_margins
from ..model.architectures import module as architecture_module
from ..model.manipulator import Manipulator
from .interpolation import _Moves

__all__ = ["DEFAULT_MAX_SAMPLE_ANGLE", "DEFAULT_PATH_TOLERANCE", "MAX_ROUNDS"]

#: Default tolerance of the certified segment check, rad of platform rotation (0.01°).
DEFAULT_PATH_TOLERANCE = math.radians(0.01)
#: Largest step between evaluated poses for the sampled minimum margin, rad of motion.
DEFAULT_MAX_SAMPLE_ANGLE = 0.05
#: Bisection rounds of a segment check (each halves the widest interval at least once).
MAX_ROUNDS = 200
_SLACK = 1e-12


class _Certifier:
    """Interval certificates of the module documentation for one manipulator."""

    def __init__(self, manipulator: Manipulator) -> None:
        self.manipulator = manipulator
        self.rho = float(np.max(np.linalg.norm(manipulator.platform_joints, axis=1)))
        self.length_min = float(np.min(manipulator.leg_length_min))
        legs = architecture_module(manipulator.architecture)
        self.moving = legs.MOVING_BASE
        # The certificate works on the leading rows up to the last one that applies and is
        # evaluated by :meth:`margins` (an unenforced singularity margin is not: it is +inf at
        # every pose, as are the rows past the last one that applies). Those later rows have a
        # lower bound of +inf and never hold the smallest relative margin: the bounds, the
        # relative margins and the bisection's arrays leave them out (6-UPS: 4 of 9 rows).
        evaluated = [
            row
            for row in applicable(manipulator)
            if row != SINGULARITY or manipulator.singularity_min > 0.0
        ]
        self.rows = max(evaluated) + 1
        # 1 / min r_i: the actuator's rate per unit speed of the base-side end along the leg
        # line (1 for legs and slides); the turning term only where that end turns (a crank).
        self.actuate_gain = 1.0 / float(np.min(legs.actuator_lever(manipulator)))
        self.crank_inverse = self.actuate_gain if legs.TURNING_BASE else 0.0

    def margins(
        self, rotations: NDArray[np.float64], positions: NDArray[np.float64]
    ) -> PoseMargins:
        """The margins of n poses: rotations (n, 3, 3), positions (n, 3) in m."""
        return pose_margins(self.manipulator, rotations, positions)

    def lower_bounds(
        self,
        start: NDArray[np.float64],
        end: NDArray[np.float64],
        width: NDArray[np.float64],
        speed: NDArray[np.float64],
        omega: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """Certified lower bounds (R, n) of the margins of the first R = ``self.rows`` rows
        (the others are +inf) over intervals of ``width`` (n,) in s, from the margins (C, n),
        C ≥ R, at both ends and the move's V and Ω (n,); the rates are those of the constraint
        table (:func:`~hexapod_workspace.core.constraints.table.rate_bounds`)."""
        start, end = start[: self.rows], end[: self.rows]
        if self.moving:
            return self._lower_bounds_moving(start, end, width, speed, omega)
        travel = speed * width
        length_start, length_end = start[LEG_LENGTH], end[LEG_LENGTH]
        with np.errstate(invalid="ignore", over="ignore"):
            low_length = np.minimum(
                np.minimum(length_start, length_end), 0.5 * (length_start + length_end - travel)
            )
            floor = 0.5 * (2.0 * self.length_min + length_start + length_end - travel)
            floor = np.where(low_length >= 0.0, np.maximum(floor, self.length_min), floor)
            turn = np.where(floor > 0.0, travel / np.where(floor > 0.0, floor, 1.0), np.inf)
            lipschitz_travel = rate_bounds(
                self.manipulator, travel, turn, omega * width, rows=self.rows
            )
            low: NDArray[np.float64] = np.minimum(
                np.minimum(start, end), 0.5 * (start + end - lipschitz_travel)
            )
        low[LEG_LENGTH] = low_length
        return low

    def _lower_bounds_moving(
        self,
        start: NDArray[np.float64],
        end: NDArray[np.float64],
        width: NDArray[np.float64],
        speed: NDArray[np.float64],
        omega: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """:meth:`lower_bounds` for pus/rus (the transmission floor τ_f of the module
        documentation); where no floor can be certified (a leg may lose its solution, or |τ|
        may reach 0) the bounds of the rows that need it are −inf."""
        travel = speed * width
        tau_min = self.manipulator.transmission_min
        length = self.length_min
        crank = self.crank_inverse
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            ik_low = np.minimum(
                np.minimum(start[IK], end[IK]), 0.5 * (start[IK] + end[IK] - travel)
            )
            tau_a, tau_b = start[TRANSMISSION] + tau_min, end[TRANSMISSION] + tau_min
            total = tau_a + tau_b - travel / length
            product = travel * (1.0 / length + crank)
            discriminant = total * total - 8.0 * product
            root = np.sqrt(np.maximum(discriminant, 0.0))
            tau_f = np.minimum(np.minimum((total + root) / 4.0, tau_a), tau_b)
            valid = (
                (discriminant >= 0.0)
                & (tau_f >= (total - root) / 4.0)
                & (tau_f > 0.0)
                & (ik_low >= 0.0)
            )
            inverse = np.where(valid, 1.0 / np.where(valid, tau_f, 1.0), np.inf)
            gain = self.actuate_gain
            lipschitz_travel = rate_bounds(
                self.manipulator,
                travel,
                travel * (1.0 + inverse) / length,
                omega * width,
                actuate=travel * gain * inverse,
                crank=travel * crank * inverse,
                ends=travel * inverse,
                rows=self.rows,
            )
            low: NDArray[np.float64] = np.minimum(
                np.minimum(start, end), 0.5 * (start + end - lipschitz_travel)
            )
        never = np.isposinf(start) & np.isposinf(end)  # rows that do not apply or are off
        low[never] = np.inf
        low[IK] = ik_low
        return low

    def relative(self, margins: NDArray[np.float64]) -> NDArray[np.float64]:
        """Smallest relative margin per column of ``margins`` (C, n); NaN → −inf."""
        if margins.shape[1] == 0:
            return np.zeros(0)
        values = relative_margins(self.manipulator, margins[: self.rows]).min(axis=0)
        smallest: NDArray[np.float64] = np.where(np.isnan(values), -np.inf, values)
        return smallest


class _Samples(TypedDict):
    """Sample table of :func:`_check_moves`: one column per evaluated pose (the K start ends,
    the K far ends, then the interior samples in the order evaluated)."""

    s: NDArray[np.float64]  # (n,) parameter along its move
    move: NDArray[np.int64]  # (n,) index of its move
    margins: NDArray[np.float64]  # (C, n), C constraints
    legs: NDArray[np.int64]  # (C, n) limiting leg per constraint, 0-based
    pairs: NDArray[np.int64]  # (n, 2) closest leg pair, 0-based


@dataclass
class _MoveCheck:
    """Raw per-move outcome of :func:`_check_moves` (arrays over the K moves)."""

    ok: NDArray[np.bool_]
    first_bad: NDArray[np.float64]
    bad_index: NDArray[np.int64]  # row in the sample table of the first violated pose
    min_value: NDArray[np.float64]
    min_s: NDArray[np.float64]
    min_index: NDArray[np.int64]
    bound: NDArray[np.float64]
    samples: _Samples
    evaluations: int


def _check_moves(
    certifier: _Certifier,
    moves: _Moves,
    start: NDArray[np.float64],
    end: NDArray[np.float64],
    tolerance: float,
    max_sample_angle: float,
    start_pose: tuple[NDArray[np.int64], NDArray[np.int64]] | None = None,
    end_pose: tuple[NDArray[np.int64], NDArray[np.int64]] | None = None,
    locate_minimum: bool = True,
) -> _MoveCheck:
    """Certified check of K moves given their end margins (C, K), vectorised over moves.

    ``start_pose``/``end_pose`` are optional (legs (C, K), pairs (K, 2)) of the ends, kept in
    the sample table so that limiting legs at the ends can be reported. Without
    ``locate_minimum`` (the planner) only the smallest sampled margin is computed, not where it
    is (``min_index`` −1, ``min_s`` NaN): the same values, without sorting the sample table.
    The bisection carries the margins of the certifier's rows only (the later rows are +inf at
    every pose: :class:`_Certifier`); the sample table has every row.
    """
    count = start.shape[1]
    used = certifier.rows
    start, end = start[:used], end[:used]
    with np.errstate(divide="ignore"):
        h_tol = np.where(moves.rate > 0.0, tolerance / moves.rate, np.inf)
        h_max = np.where(moves.rate > 0.0, max_sample_angle / moves.rate, np.inf)
    ids = np.arange(count)
    no_legs = np.zeros((N_CONSTRAINTS, count), dtype=np.int64)
    no_pairs = np.zeros((count, 2), dtype=np.int64)
    start_legs, start_pairs = start_pose if start_pose is not None else (no_legs, no_pairs)
    end_legs, end_pairs = end_pose if end_pose is not None else (no_legs, no_pairs)
    # Sample table: ends first (rows 0..K-1 start, K..2K-1 end), then interior samples.
    table_s = [np.zeros(count), np.ones(count)]
    table_move = [ids, ids]
    table_margins = [start, end]
    table_legs = [start_legs, end_legs]
    table_pairs = [start_pairs, end_pairs]
    feasible_start = np.all(start >= 0.0, axis=0)
    feasible_end = np.all(end >= 0.0, axis=0)
    first_bad = np.where(feasible_start, np.where(feasible_end, np.inf, 1.0), 0.0)
    bad_index = np.where(feasible_start, np.where(feasible_end, -1, count + ids), ids)
    # Intervals: move, a, b, row of a and b in the sample table.
    move, lo, hi = ids, np.zeros(count), np.ones(count)
    row_lo, row_hi = ids.copy(), count + ids
    margins_lo, margins_hi = start, end
    final_move, final_lo, final_bound = [], [], []
    next_row = 2 * count
    evaluations = 0
    for _ in range(MAX_ROUNDS):
        keep = lo < first_bad[move]
        move, lo, hi, row_lo, row_hi = move[keep], lo[keep], hi[keep], row_lo[keep], row_hi[keep]
        margins_lo, margins_hi = margins_lo[:, keep], margins_hi[:, keep]
        if move.size == 0:
            break
        width = hi - lo
        bounds = certifier.lower_bounds(
            margins_lo, margins_hi, width, moves.speed[move], moves.omega[move]
        )
        certified = np.all(bounds >= 0.0, axis=0)
        split = np.where(certified, width > h_max[move], width > h_tol[move])
        done = ~split
        final_move.append(move[done])
        final_lo.append(lo[done])
        final_bound.append(certifier.relative(bounds[:, done]))
        if not np.any(split):
            break
        move, lo, hi = move[split], lo[split], hi[split]
        row_lo, row_hi = row_lo[split], row_hi[split]
        margins_lo, margins_hi = margins_lo[:, split], margins_hi[:, split]
        middle = 0.5 * (lo + hi)
        rotations, positions = moves.poses(move, middle)
        found = certifier.margins(rotations, positions)
        evaluations += middle.size
        rows = next_row + np.arange(middle.size)
        next_row += middle.size
        table_s.append(middle)
        table_move.append(move)
        found_margins = found.margins[:used]
        table_margins.append(found_margins)
        table_legs.append(found.limiting_legs)
        table_pairs.append(found.limiting_pairs)
        violated = ~np.all(found_margins >= 0.0, axis=0)
        if np.any(violated):
            # Earliest violated sample per move (np.minimum.at keeps the smallest s).
            candidate = np.full(count, np.inf)
            np.minimum.at(candidate, move[violated], middle[violated])
            better = candidate < first_bad
            first_bad[better] = candidate[better]
            hit = violated & (middle == first_bad[move])
            bad_index[move[hit]] = rows[hit]
        move = np.concatenate([move, move])
        lo, hi = np.concatenate([lo, middle]), np.concatenate([middle, hi])
        row_lo, row_hi = np.concatenate([row_lo, rows]), np.concatenate([rows, row_hi])
        margins_lo = np.concatenate([margins_lo, found_margins], axis=1)
        margins_hi = np.concatenate([found_margins, margins_hi], axis=1)
    else:  # pragma: no cover - MAX_ROUNDS halvings reach any tolerance >= 1e-9 first
        msg = "segment check did not converge"
        raise RuntimeError(msg)
    margins = np.concatenate(table_margins, axis=1)
    samples: _Samples = {
        "s": np.concatenate(table_s),
        "move": np.concatenate(table_move),
        # Every row again: the rows the bisection left out are +inf.
        "margins": np.concatenate(
            [margins, np.full((N_CONSTRAINTS - used, margins.shape[1]), np.inf)]
        ),
        "legs": np.concatenate(table_legs, axis=1),
        "pairs": np.concatenate(table_pairs, axis=0),
    }
    # Minimum over the samples of [0, first violation] and over the final interval bounds.
    relative = certifier.relative(margins)
    inside = samples["s"] <= np.minimum(first_bad, 1.0)[samples["move"]]
    if locate_minimum:
        # Per move: inside first, smallest (every move has its start, s = 0, inside).
        order = np.lexsort((relative, ~inside, samples["move"]))
        first_of_move = np.searchsorted(samples["move"][order], ids)
        min_index = order[first_of_move]
        min_value = relative[min_index]
        min_s = samples["s"][min_index]
    else:
        min_value = np.full(count, np.inf)
        np.minimum.at(min_value, samples["move"][inside], relative[inside])
        min_index = np.full(count, -1, dtype=np.int64)
        min_s = np.full(count, np.nan)
    bound = np.full(count, np.inf)
    if final_move:
        f_move, f_lo = np.concatenate(final_move), np.concatenate(final_lo)
        f_bound = np.concatenate(final_bound)
        before = f_lo < first_bad[f_move]
        np.minimum.at(bound, f_move[before], f_bound[before])
    ok = ~np.isfinite(first_bad)
    bound = np.minimum(bound, min_value)
    return _MoveCheck(
        ok=ok,
        first_bad=np.where(ok, np.nan, first_bad),
        bad_index=bad_index,
        min_value=min_value,
        min_s=min_s,
        min_index=min_index,
        bound=bound,
        samples=samples,
        evaluations=evaluations,
    )
