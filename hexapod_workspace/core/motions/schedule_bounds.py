"""Certified bounds along slerp moves for the schedule
(:mod:`hexapod_workspace.core.motions.schedule`): the tool centre point's speed per unit s, and
the tighter second-order bound of |g_i'| on straight moves.

With g_i = dq_i/du (:mod:`.speeds`) and an interval I = [a, b] of width w:

**Second order.** The bound K of :mod:`.speeds` is a move-wide worst case: it does not shrink
with the interval, and ``K·x`` would slow every fast stretch down. With the platform joint's
velocity ``v_i = p' + w × R b_i`` (w = Ω·axis constant along a slerp), ``v_i' = p'' + w × (w ×
R b_i)`` and ``v_i'' = p''' + w × (w × (w × R b_i))``, so ``|v_i''| ≤ J_i := |p'''| + Ω³·|b_i|``
with p''' = 0 on a straight move, ``−3Δρφ²·T − ρφ³·A`` on an arc (|p'''| ≤ 3|Δρ|φ² + ρ_max|φ|³)
and the constant ``6(e₁ − e₀)`` on a Bézier span (``hexapod_workspace.core.motions.interpolation``).
Each interval therefore takes
``K_loc = min(K, (|g'(a)| + |g'(b)| + K2·w)/2)`` (the argument of the certified peak, one
order up), with g' evaluated exactly at the nodes and K2 ≥ |g''| on the interval. Then G is
re-derived from K_loc (``G = (|g(a)| + |g(b)| + K_loc·w)/2``, valid for any bound of |g'|).

* 6-UPS: ``g' = (|v|² − g²)/ℓ + n·v'``; differentiating, with ``ℓ' = g``, ``|n'| ≤ V/ℓ``,
  ``|g| ≤ V`` and ``|g'| ≤ K``: ``|g''| ≤ (3VA + 2VK)/ℓ_f + V³/ℓ_f² + J =: K2``.
* 6-PUS and 6-RUS (ρ, τ_f, L, N as in :mod:`.speeds`; A' = dA/dq, A'' and A''' of norm r for
  a crank, 0 for a slide; ``h = ρτ = n·A'``): ``h·g' = E := L|n'|² + n·v' − g²·n·A''`` with
  ``n' = (v − A'g)/L``. Differentiating, ``n'' = (v' − A''g² − A'g')/L``,
  ``h' = n'·A' + g·n·A''`` and ``E' = 2L·n'·n'' + n'·v' + n·v'' − 2gg'·n·A'' −
  g²(n'·A'' + g·n·A''')``, so ``g'' = (E' − h'g')/h`` and, with ``|g| ≤ Ĝ := V/(ρτ_f)``,
  ``|n'| ≤ N``, ``|n''| ≤ (A + rĜ² + ρK)/L``, ``|h'| ≤ ρN + rĜ``:
  ``|g''| ≤ (2LN|n''| + NA + J + 2ĜKr + Ĝ²(Nr + rĜ) + |h'|K)/(ρτ_f) =: K2``.

The tool centre point's speed per unit s: ``P = |Δp|`` on a straight move; on a curve
``P = min(P₁, (|p'(a)| + |p'(b)| + P₂·w)/2)`` with P₁, P₂ the curve's bounds of |p'| and |p''|
(``hexapod_workspace.core.motions.interpolation``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..model import architectures
from ..model.manipulator import Manipulator
from .speeds import Intervals, SlerpMoves, interval_nodes

__all__ = ["local_rates", "rate_derivatives", "tcp_bounds", "third_bound"]


def tcp_bounds(
    moves: SlerpMoves, move: NDArray[np.int64], a: NDArray[np.float64], b: NDArray[np.float64]
) -> NDArray[np.float64]:
    """P per interval: a certified bound of |p'(s)| on [a, b] (module documentation)."""
    bound: NDArray[np.float64] = np.linalg.norm(moves.dp[move], axis=1)
    curves = moves.arcs
    if curves is not None:
        on = curves.mask[move]
        if on.any():
            m = move[on]
            ends = np.linalg.norm(curves.velocities(m, a[on]), axis=1) + np.linalg.norm(
                curves.velocities(m, b[on]), axis=1
            )
            local = 0.5 * (ends + curves.accel[m] * (b[on] - a[on]))
            bound[on] = np.minimum(curves.speed[m], local)
    return bound


def rate_derivatives(
    manipulator: Manipulator, sub: SlerpMoves, moves: NDArray[np.int64], s: NDArray[np.float64]
) -> NDArray[np.float64]:
    """g_i' = d²q_i/ds² (n, 6) at (moves, s), exact (module documentation)."""
    motion, dv = sub.motion_with_accelerations(moves, s)
    v = motion.joint_velocities
    arch = architectures.module(manipulator.architecture)
    if not arch.MOVING_BASE:  # g' = (|v|² − g²)/ℓ + n·v'
        d = motion.platform - manipulator.base_joints
        length = np.linalg.norm(d, axis=2)
        n = d / length[..., None]
        g = np.sum(n * v, axis=2)
        result: NDArray[np.float64] = (np.sum(v * v, axis=2) - g * g) / length + np.sum(
            n * dv, axis=2
        )
        return result
    q, _ = arch.inverse_kinematics(manipulator, motion.platform)
    q = np.where(np.isfinite(q), q, 0.0)  # unsolved legs are refused by G = inf
    d = motion.platform - arch.base_ends(manipulator, q)
    length = np.linalg.norm(d, axis=2)
    n = d / length[..., None]
    first, second = arch.base_end_derivatives(manipulator, q)
    h = np.sum(n * first, axis=2)  # ρ·τ
    with np.errstate(divide="ignore", invalid="ignore"):
        g = np.sum(n * v, axis=2) / h
        dn = (v - first * g[..., None]) / length[..., None]
        # ρτ·g' = L|n'|² + n·v' − g²·n·A″
        derivative: NDArray[np.float64] = (
            length * np.sum(dn * dn, axis=2)
            + np.sum(n * dv, axis=2)
            - g * g * np.sum(n * second, axis=2)
        ) / h
    return derivative


def third_bound(
    manipulator: Manipulator,
    speed: NDArray[np.float64],
    accel: NDArray[np.float64],
    jerk: NDArray[np.float64],
    floor: NDArray[np.float64],
    rate: NDArray[np.float64],
) -> NDArray[np.float64]:
    """K2_i ≥ |g_i″| on an interval where |v| ≤ V, |v′| ≤ A, |v″| ≤ J, the floor holds and
    |g′| ≤ K (module documentation, "Second order")."""
    arch = architectures.module(manipulator.architecture)
    v, a, j, k = speed, accel, jerk, rate
    if not arch.MOVING_BASE:
        bound: NDArray[np.float64] = (3.0 * v * a + 2.0 * v * k) / floor + v**3 / floor**2 + j
        return bound
    length = manipulator.leg_lengths
    assert length is not None
    rho = arch.actuator_lever(manipulator)
    turning = rho if arch.TURNING_BASE else np.zeros(6)  # |A″| = |A‴| = r for a crank
    g = v / (rho * floor)  # |g|
    n1 = v * (1.0 + 1.0 / floor) / length  # |n′|
    n2 = (a + turning * g * g + rho * k) / length  # |n″|
    h1 = rho * n1 + g * turning  # |(ρτ)′|
    e1 = 2.0 * length * n1 * n2 + n1 * a + j + 2.0 * g * k * turning
    e1 = e1 + g * g * (n1 * turning + turning * g)
    bound = (e1 + h1 * k) / (rho * floor)
    return bound


def local_rates(
    manipulator: Manipulator, sub: SlerpMoves, grid: Intervals
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Tighter certified bounds of |g_i′| and |g_i| per interval: the second-order bound
    ``(|g′(a)| + |g′(b)| + K2·w)/2`` where it is smaller than K (straight moves), and G from
    it (module documentation, "Second order")."""
    move, a, b = grid.move, grid.a, grid.b
    node_move, node_s, end_node = interval_nodes(move, a, b)
    derivative = np.abs(rate_derivatives(manipulator, sub, node_move, node_s))
    width = (b - a)[:, None]
    positive = grid.floor > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        k2 = third_bound(
            manipulator,
            sub.speed[move],
            sub.accel[move],
            sub.jerk[move],
            np.where(positive, grid.floor, 1.0),
            np.where(np.isfinite(grid.rate), grid.rate, 0.0),
        )
        local = 0.5 * (derivative[: move.size] + derivative[end_node] + k2 * width)
    usable = positive & np.isfinite(local) & np.isfinite(grid.rate)
    rate = np.where(usable, np.minimum(grid.rate, local), grid.rate)
    upper = np.minimum(grid.upper, 0.5 * (grid.g_a + grid.g_b + rate * width))
    return rate, upper
