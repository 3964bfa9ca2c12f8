"""Actuator speeds along moves: a certified peak per move and the largest feed that keeps every
actuator within its limit.

A move from (p₀, R₀) to (p₁, R₁) (position linear, orientation slerp, s ∈ [0, 1]) runs in a
time T when its feed is known; the actuated coordinate q_i then changes at ``dq_i/dt =
g_i(s)/T`` with ``g_i = dq_i/ds``. Everything below is per unit s; the caller divides by T.

Slerp turns about one fixed axis u (base frame) at a constant rate: ``R(s) = Rot(s·Ω·u)·R₀``, so
the angular velocity per unit s is the constant ``w = Ω·u``. Platform joint i is at ``B_i(s) =
p(s) + R(s)·b_i`` and moves at ``v_i = dB_i/ds = Δp + w × R(s)b_i``, whence

    |v_i| ≤ V_i := |Δp| + Ω·|b_i|,      |dv_i/ds| = |w × (w × R b_i)| ≤ A_i := Ω²·|b_i|.

On an arc (:mod:`~hexapod_workspace.core.motions.interpolation`: ``CIRCLE`` moves) Δp is replaced
by p'(s), so ``V_i := P₁ + Ω·|b_i|`` and ``A_i := P₂ + Ω²·|b_i|`` with P₁ and P₂ the arc's
bounds of |p'| and |p''|; everything below holds with these. The move's length D for a duration
is the arc's lower bound of its length (a shorter D, a shorter T: speeds never under-stated).

**6-UPS legs** (:data:`UPS`, q_i = ℓ_i): ``L_i = B_i − A_i`` with A_i fixed, so
``g_i = dℓ_i/ds = n_i·v_i``. Its own rate is, with ``dn_i/ds = (I − n_i n_iᵀ)·v_i / ℓ_i``,

    dg_i/ds = (dn_i/ds)·v_i + n_i·dv_i/ds = |v_i − (n_i·v_i) n_i|² / ℓ_i + n_i·dv_i/ds,
    |dg_i/ds| ≤ V_i² / ℓ_f + A_i  =: K_i,

where ℓ_f ≤ ℓ_i on the interval considered. On an interval [a, b] of width w,
``|ℓ_i(s) − ℓ_i(a)| ≤ V_i·|s − a|`` gives ``ℓ_f = (ℓ_i(a) + ℓ_i(b) − V_i·w) / 2`` (an interval
where it is not positive gets no bound and is split).

**Certified peak.** On [a, b], ``|g(s)| ≤ min(|g(a)| + K(s − a), |g(b)| + K(b − s))``, whose
largest value is ``(|g(a)| + |g(b)| + K·w) / 2``: an upper bound of |g| on the whole interval,
not a sample. The peak bound of a move is the largest such bound over its intervals. The
intervals whose bound exceeds the largest sampled value of the move by more than ``rel`` (1 %
by default, after weighting every actuator by its speed limit) are bisected, in every move at
once, until none does (or the round limit is hit: the bound stays certified, only looser).

**Largest feed.** The actuator speeds scale with the feed: a move of length D (m, or rad for a
rotation without translation) run at feed f lasts T = D/f, so actuator i runs at most at
``U_i·f/D`` (U_i the certified bound of max|g_i|). The largest feed within every limit is at
least ``feed_max = D·min_i(vmax_i / U_i)`` (a certified lower bound), and at most
``D·min_i(vmax_i / S_i)`` with S_i the sampled maximum: within ``rel`` of the true value.

**6-PUS slides and 6-RUS cranks** (:data:`PUS`, :data:`RUS`; q_i the slide position, m, or
the crank angle, rad). The leg of fixed length L_i joins the base-side end A_i(q_i) to B_i:
``D_i = B_i − A_i(q_i)``, ``|D_i| = L_i``, ``n_i = D_i/L_i``, with ``A' = dA/dq = u_i`` (pus)
or ``r_i·t_i`` (rus, ``t_i = w_i × (C_i − A0_i)/r_i`` the crank end's unit velocity) and
``τ_i = n_i·u_i`` or ``n_i·t_i`` (the ``transmission`` row). Differentiating ``|D|² = L²``:
``n·(v − A'·g) = 0``, so (dropping i, ρ = 1 for pus, r for rus)

    g = dq/ds = (n·v)/(ρ·τ),       |g| ≤ V/(ρ·|τ|),

and ``dD/ds = v − A'·g`` is ⟂ n, whence ``dn/ds = (v − A'g)/L`` and
``|dn/ds| ≤ (V + ρ|g|)/L ≤ V(1 + 1/τ_f)/L =: N`` where ``|τ| ≥ τ_f``. Differentiating
``ρτg = n·v``, with ``d(ρτ)/ds = dn/ds·A' + g·n·A''`` (A'' = 0 for pus, ``−(C − A0)`` of
norm r for rus)::

    ρτ·dg/ds = dn/ds·(v − A'g) + n·dv/ds − g²·n·A''
             = L|dn/ds|² + n·dv/ds − g²·n·A'',
    |dg/ds| ≤ (V²(1 + 1/τ_f)²/L + A [+ V²/(r·τ_f²) for rus]) / (ρ·τ_f)  =: K.

The floor τ_f comes from the rate of |τ| (as ℓ_f above from the rate of ℓ): pus
``dτ/ds = dn/ds·u``, ``|dτ/ds| ≤ N``; rus ``dτ/ds = dn/ds·t + n·dt/ds`` with
``|dt/ds| = |g|``, ``|dτ/ds| ≤ N + V/(r·τ_f)``; both are ``c₀ + c₁/τ_f`` with ``c₀ = V/L``,
``c₁ = V/L`` (pus) or ``V/L + V/r`` (rus). On [a, b] of width w, any ``τ_f ≤ min(|τ(a)|,
|τ(b)|)`` with ``|τ(a)| + |τ(b)| − 2τ_f ≥ (c₀ + c₁/τ_f)·w`` holds on the whole interval: the
stretches ``[a, a + (|τ(a)| − τ_f)/rate]`` and ``[b − (|τ(b)| − τ_f)/rate, b]`` cover it, and
on each the first point where |τ| fell below τ_f would contradict the rate that holds until
then. That is ``2τ_f² − (S − c₀w)τ_f + c₁w ≤ 0`` (S = |τ(a)| + |τ(b)|): the interval takes
the smaller of its larger root and ``min(|τ(a)|, |τ(b)|)`` if that is still above the smaller
root, and is split otherwise. The same argument keeps the leg's inverse kinematics solvable on
the branch it has at a: a solution ceases to exist only where τ reaches 0 (pus: the
discriminant ``L² − h²`` vanishes when D ⟂ u; rus: ``|c| = √(a² + b²)`` when D ⟂ t).

**Unbounded.** Where some leg has no inverse-kinematics solution at a sample, or τ = 0 there,
its rate is +inf: the peak bound of the move is +inf and its ``feed_max`` 0 (no feed is safe;
the move is refused anyway by the ``ik`` or ``transmission`` constraint). A move whose |τ|
approaches 0 without reaching it gets a finite but large bound: the true peak is large too.

**Other architectures.** An :class:`ActuatorModel` gives ``g`` and its floor quantity (ℓ or
|τ|) from the platform joints of :class:`LegMotion`, the floor over an interval, and the bound
K from (V, A, floor); a new leg architecture registers one in :data:`ACTUATOR_MODELS` under its
name.

What the check covers: speeds along the programmed moves, each move at constant feed. Corner
blending, accelerations and the controller's look-ahead are the controller's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError
from ..base.rotations import (
    matrix_to_quaternion,
    quaternion_angle,
    quaternion_conjugate,
    quaternion_multiply,
)
from ..model import architectures
from ..model.manipulator import Manipulator
from .interpolation import _Curves, _validate_curves

__all__ = [
    "ACTUATOR_MODELS",
    "PUS",
    "RUS",
    "UPS",
    "ActuatorModel",
    "FeedLimits",
    "LegMotion",
    "MoveRates",
    "actuator_rates",
    "feed_limits",
]

#: Relative tightness of the certified peak against the sampled one.
DEFAULT_RELATIVE = 0.01
#: Intervals per move before any refinement.
INITIAL_INTERVALS = 16
#: Bisection rounds (each splits every interval still too loose).
MAX_ROUNDS = 40
#: Largest number of intervals alive at once (memory bound; past it the bound is just looser).
MAX_INTERVALS = 2_000_000


@dataclass(frozen=True)
class LegMotion:
    """Platform joints and their velocities at n samples (move, s).

    Attributes
    ----------
    platform : ndarray, shape (n, 6, 3)
        B_i, base frame, m.
    joint_velocities : ndarray, shape (n, 6, 3)
        v_i = dB_i/ds, m per unit s.
    """

    platform: NDArray[np.float64]
    joint_velocities: NDArray[np.float64]


#: ``evaluate(manipulator, motion) -> (g (n, 6), floor quantity (n, 6))``.
Evaluate = Callable[[Manipulator, LegMotion], tuple[NDArray[np.float64], NDArray[np.float64]]]
#: ``interval_floor(manipulator, at_a, at_b, V, width) -> floor (m, 6)`` (≤ 0 or NaN: none).
IntervalFloor = Callable[
    [
        Manipulator,
        NDArray[np.float64],
        NDArray[np.float64],
        NDArray[np.float64],
        NDArray[np.float64],
    ],
    NDArray[np.float64],
]
#: ``rate_bound(manipulator, V, A, floor) -> K (m, 6)``.
RateBound = Callable[
    [Manipulator, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
    NDArray[np.float64],
]


@dataclass(frozen=True)
class ActuatorModel:
    """How an architecture's actuated coordinates move with the platform.

    Attributes
    ----------
    name : str
        Architecture name (``"ups"``, ``"pus"``, ``"rus"``).
    unit : str
        Unit of the actuated coordinate (``"m"`` or ``"rad"``; speeds are per second).
    evaluate : callable
        ``evaluate(manipulator, motion) -> (g, f)``, both (n, 6): g_i = dq_i/ds (+inf where the
        leg has no solution or |τ_i| = 0) and the quantity whose floor the rate bound needs
        (ℓ_i for ups, |τ_i| for pus and rus; 0 where the leg has no solution).
    interval_floor : callable
        ``interval_floor(manipulator, f_a, f_b, V, width)``: a lower bound of f_i over an
        interval from its end values (not positive, or NaN: no bound, the interval is split).
    rate_bound : callable
        ``rate_bound(manipulator, V, A, floor)``: a bound K_i of |dg_i/ds| over an interval
        where |v_i| ≤ V, |dv_i/ds| ≤ A and f_i ≥ floor > 0.
    """

    name: str
    unit: str
    evaluate: Evaluate
    interval_floor: IntervalFloor
    rate_bound: RateBound


def _ups_evaluate(
    manipulator: Manipulator, motion: LegMotion
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """dℓ_i/ds = n_i·v_i and ℓ_i (module documentation)."""
    vectors = motion.platform - manipulator.base_joints
    lengths = np.linalg.norm(vectors, axis=2)
    rates: NDArray[np.float64] = (
        np.einsum("nij,nij->ni", vectors, motion.joint_velocities) / lengths
    )
    return rates, lengths


def _ups_floor(
    manipulator: Manipulator,
    at_a: NDArray[np.float64],
    at_b: NDArray[np.float64],
    speed: NDArray[np.float64],
    width: NDArray[np.float64],
) -> NDArray[np.float64]:
    """ℓ_f = (ℓ(a) + ℓ(b) − V·w)/2 (module documentation)."""
    floor: NDArray[np.float64] = 0.5 * (at_a + at_b - speed * width)
    return floor


def _ups_rate_bound(
    manipulator: Manipulator,
    speed: NDArray[np.float64],
    accel: NDArray[np.float64],
    floor: NDArray[np.float64],
) -> NDArray[np.float64]:
    """|d²ℓ_i/ds²| ≤ V_i²/ℓ_f + A_i (module documentation)."""
    bound: NDArray[np.float64] = speed**2 / floor + accel
    return bound


def _fixed_leg_evaluate(
    manipulator: Manipulator, motion: LegMotion
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """g_i = n_i·v_i / (r_i·τ_i) (r = 1 for pus, the architecture's ``actuator_lever``) and
    |τ_i| (module documentation)."""
    arch = architectures.module(manipulator.architecture)
    q, _ = arch.inverse_kinematics(manipulator, motion.platform)
    solved = np.isfinite(q)
    q = np.where(solved, q, 0.0)
    vectors = motion.platform - arch.base_ends(manipulator, q)
    directions = vectors / np.linalg.norm(vectors, axis=2, keepdims=True)
    tau = arch.transmission(manipulator, directions, q)
    usable = solved & (tau != 0.0)
    along = np.einsum("nij,nij->ni", directions, motion.joint_velocities)
    with np.errstate(divide="ignore", invalid="ignore"):
        rates = along / (arch.actuator_lever(manipulator) * tau)
    return np.where(usable, rates, np.inf), np.where(usable, np.abs(tau), 0.0)


def _tau_rate(
    manipulator: Manipulator, speed: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(c₀, c₁) with |dτ_i/ds| ≤ c₀ + c₁/τ_f (module documentation)."""
    length = manipulator.leg_lengths
    assert length is not None
    arch = architectures.module(manipulator.architecture)
    c0 = speed / length
    c1 = c0 + (speed / arch.actuator_lever(manipulator) if arch.TURNING_BASE else 0.0)
    return c0, c1


def _fixed_leg_floor(
    manipulator: Manipulator,
    at_a: NDArray[np.float64],
    at_b: NDArray[np.float64],
    speed: NDArray[np.float64],
    width: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The largest τ_f ≤ min(|τ(a)|, |τ(b)|) with |τ(a)| + |τ(b)| − 2τ_f ≥ (c₀ + c₁/τ_f)·w."""
    c0, c1 = _tau_rate(manipulator, speed)
    head = at_a + at_b - c0 * width
    with np.errstate(invalid="ignore"):
        root = np.sqrt(head * head - 8.0 * c1 * width)
    upper, lower = 0.25 * (head + root), 0.25 * (head - root)
    floor = np.minimum(upper, np.minimum(at_a, at_b))
    ok = (head > 0.0) & np.isfinite(root) & (floor >= lower) & (floor > 0.0)
    return np.where(ok, floor, np.nan)


def _fixed_leg_rate_bound(
    manipulator: Manipulator,
    speed: NDArray[np.float64],
    accel: NDArray[np.float64],
    floor: NDArray[np.float64],
) -> NDArray[np.float64]:
    """K_i = (V²(1 + 1/τ_f)²/L + A [+ V²/(r τ_f²)]) / (r τ_f) (module documentation; the
    bracket where the base-side end turns, a crank)."""
    length = manipulator.leg_lengths
    assert length is not None
    arch = architectures.module(manipulator.architecture)
    radius = arch.actuator_lever(manipulator)
    numerator = speed**2 * (1.0 + 1.0 / floor) ** 2 / length + accel
    if arch.TURNING_BASE:
        numerator = numerator + speed**2 / (radius * floor**2)
    bound: NDArray[np.float64] = numerator / (radius * floor)
    return bound


#: 6-UPS legs: the actuated coordinate is the leg length (m).
UPS = ActuatorModel(
    "ups", architectures.ups.ACTUATOR_UNIT, _ups_evaluate, _ups_floor, _ups_rate_bound
)
#: 6-PUS slides: the actuated coordinate is the slide position on its rail (m).
PUS = ActuatorModel(
    "pus",
    architectures.pus.ACTUATOR_UNIT,
    _fixed_leg_evaluate,
    _fixed_leg_floor,
    _fixed_leg_rate_bound,
)
#: 6-RUS cranks: the actuated coordinate is the crank angle (rad).
RUS = ActuatorModel(
    "rus",
    architectures.rus.ACTUATOR_UNIT,
    _fixed_leg_evaluate,
    _fixed_leg_floor,
    _fixed_leg_rate_bound,
)
#: Actuator models by architecture name.
ACTUATOR_MODELS: dict[str, ActuatorModel] = {m.name: m for m in (UPS, PUS, RUS)}


@dataclass(frozen=True)
class MoveRates:
    """Actuator rates per unit s along M moves (divide by the duration for speeds).

    Attributes
    ----------
    peak_bound : ndarray, shape (M, 6)
        Certified upper bound of max_s |dq_i/ds| per actuator (actuator unit per unit s).
    peak_sampled : ndarray, shape (M, 6)
        Largest |dq_i/ds| over the evaluated samples (a lower bound of the same maximum).
    translation : ndarray, shape (M,)
        |Δp|, m.
    rotation : ndarray, shape (M,)
        Ω, the slerp angle, rad.
    evaluations : int
        Samples evaluated.
    """

    peak_bound: NDArray[np.float64]
    peak_sampled: NDArray[np.float64]
    translation: NDArray[np.float64]
    rotation: NDArray[np.float64]
    evaluations: int


class SlerpMoves:
    """Poses and joint velocities along slerp moves: R(s) = Rot(s·Ω·u)·R₀ (u in base frame)."""

    def __init__(
        self,
        manipulator: Manipulator,
        positions0: NDArray[np.float64],
        positions1: NDArray[np.float64],
        rotations0: NDArray[np.float64],
        rotations1: NDArray[np.float64],
        arcs: _Curves | None = None,
    ) -> None:
        self.joints = manipulator.platform_joints
        self.p0 = positions0
        self.dp = positions1 - positions0
        self.arcs = arcs
        q0, q1 = matrix_to_quaternion(rotations0), matrix_to_quaternion(rotations1)
        self.omega = quaternion_angle(q0, q1)
        relative = quaternion_multiply(q1, quaternion_conjugate(q0))  # R₁R₀ᵀ, base frame
        relative = np.where(relative[:, 3:] < 0.0, -relative, relative)
        vector = relative[:, :3]
        norm = np.linalg.norm(vector, axis=1, keepdims=True)
        self.axis = np.where(norm > 1e-300, vector / np.where(norm > 0.0, norm, 1.0), 0.0)
        self.r0 = rotations0
        radius = np.linalg.norm(self.joints, axis=1)  # |b_i|
        self.translation = np.linalg.norm(self.dp, axis=1)
        travel = self.translation  # the bound of |dp/ds|
        curvature = np.zeros_like(travel)  # the bound of |d²p/ds²|
        if arcs is not None:
            # Curves (interpolation): |p'| ≤ arcs.speed, |p''| ≤ arcs.accel, so
            # V_i = |p'| + Ω|b_i| and A_i = |p''| + Ω²|b_i| (|dv_i/ds| ≤ |p''| + |w × (w × Rb_i)|);
            # the length for a duration is the curve's lower bound.
            travel = np.where(arcs.mask, arcs.speed, travel)
            curvature = np.where(arcs.mask, arcs.accel, 0.0)
            self.translation = np.where(arcs.mask, arcs.length, self.translation)
        self.speed = travel[:, None] + self.omega[:, None] * radius  # V_i (M, 6)
        self.accel = curvature[:, None] + self.omega[:, None] ** 2 * radius  # A_i (M, 6)
        # J_i ≥ |d²v_i/ds²| = |p''' + w × (w × (w × Rb_i))|, so J_i = |p'''| + Ω³|b_i| (p''' = 0
        # on a straight move; the curve's bound on arcs and Bézier moves, interpolation)
        jolt = np.zeros_like(travel) if arcs is None else np.where(arcs.mask, arcs.jerk, 0.0)
        self.jerk = jolt[:, None] + self.omega[:, None] ** 3 * radius

    def _arms(
        self, moves: NDArray[np.int64], s: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """R(s)·b_i (n, 6, 3) and the angular velocity per unit s, w = Ω·u (n, 3)."""
        angle = s * self.omega[moves]
        u = self.axis[moves]
        cross = np.zeros((u.shape[0], 3, 3))
        cross[:, 0, 1], cross[:, 0, 2], cross[:, 1, 2] = -u[:, 2], u[:, 1], -u[:, 0]
        cross[:, 1, 0], cross[:, 2, 0], cross[:, 2, 1] = u[:, 2], -u[:, 1], u[:, 0]
        turn = (
            np.eye(3)
            + np.sin(angle)[:, None, None] * cross
            + (1.0 - np.cos(angle))[:, None, None] * (cross @ cross)
        )
        rotation = turn @ self.r0[moves]
        arms: NDArray[np.float64] = np.einsum("nij,kj->nki", rotation, self.joints)
        return arms, (self.omega[moves])[:, None] * u

    def _leg_motion(
        self,
        moves: NDArray[np.int64],
        s: NDArray[np.float64],
        arms: NDArray[np.float64],
        w: NDArray[np.float64],
    ) -> LegMotion:
        position = self.p0[moves] + s[:, None] * self.dp[moves]
        linear = self.dp[moves]
        if self.arcs is not None:
            on_arc = self.arcs.mask[moves]
            if on_arc.any():
                position[on_arc] = self.arcs.positions(moves[on_arc], s[on_arc])
                linear = linear.copy()
                linear[on_arc] = self.arcs.velocities(moves[on_arc], s[on_arc])
        velocities = linear[:, None, :] + np.cross(w[:, None, :], arms)
        return LegMotion(position[:, None, :] + arms, velocities)

    def motion(self, moves: NDArray[np.int64], s: NDArray[np.float64]) -> LegMotion:
        """Leg quantities of moves ``moves`` (n,) at parameters ``s`` (n,)."""
        arms, w = self._arms(moves, s)
        return self._leg_motion(moves, s, arms, w)

    def motion_with_accelerations(
        self, moves: NDArray[np.int64], s: NDArray[np.float64]
    ) -> tuple[LegMotion, NDArray[np.float64]]:
        """:meth:`motion` and dv_i/ds = p'' + w × (w × R(s)·b_i) (n, 6, 3) (p'' = 0 on a
        straight move, the curve's on arcs and Bézier moves)."""
        arms, w = self._arms(moves, s)
        spin = np.broadcast_to(w[:, None, :], arms.shape)
        accelerations: NDArray[np.float64] = np.cross(spin, np.cross(spin, arms))
        if self.arcs is not None:
            curved = self.arcs.mask[moves]
            if curved.any():
                bend = self.arcs.accelerations(moves[curved], s[curved])
                accelerations[curved] += bend[:, None, :]
        return self._leg_motion(moves, s, arms, w), accelerations


def _weights(limits: NDArray[np.float64]) -> NDArray[np.float64]:
    """Per-actuator weights for the tightness test: 1/vmax (unlimited: 1/largest limit)."""
    limited = limits > 0.0
    if not np.any(limited):
        return np.ones(6)
    return np.where(limited, 1.0 / np.where(limited, limits, 1.0), 1.0 / float(limits.max()))


@dataclass(frozen=True)
class Intervals:
    """The final intervals of a refinement: on each, certified bounds of |g_i| and |dg_i/ds|.

    Attributes
    ----------
    move : ndarray, shape (m,), int
        Move of each interval.
    a, b : ndarray, shape (m,)
        Its ends, in the move's s ∈ [0, 1].
    g_a, g_b : ndarray, shape (m, 6)
        |g_i| = |dq_i/ds| at the ends (actuator unit per unit s).
    upper : ndarray, shape (m, 6)
        Certified bound of |g_i| on [a, b]: ``(|g(a)| + |g(b)| + K·w)/2`` (module
        documentation); +inf where no floor could be found.
    rate : ndarray, shape (m, 6)
        K_i, the certified bound of |dg_i/ds| on [a, b] (0 for a move that does not move, +inf
        where no floor could be found).
    floor : ndarray, shape (m, 6)
        The floor K_i was computed with (ℓ_f or τ_f; not positive or NaN: none).
    sampled : ndarray, shape (M, 6)
        Largest |g_i| evaluated per move.
    evaluations : int
        Samples evaluated.
    """

    move: NDArray[np.int64]
    a: NDArray[np.float64]
    b: NDArray[np.float64]
    g_a: NDArray[np.float64]
    g_b: NDArray[np.float64]
    upper: NDArray[np.float64]
    rate: NDArray[np.float64]
    floor: NDArray[np.float64]
    sampled: NDArray[np.float64]
    evaluations: int


def interval_nodes(
    move: NDArray[np.int64], a: NDArray[np.float64], b: NDArray[np.float64]
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.int64]]:
    """Every node of intervals (move, a, b) (sorted, tiling each move) once: (move, s) of the
    interval starts, then of each move's end; and the node at each interval's end (the next
    interval's start, or its move's end node)."""
    last = np.r_[move[1:] != move[:-1], True]
    node_move = np.concatenate([move, move[last]])
    node_s = np.concatenate([a, b[last]])
    end_node = np.arange(1, move.size + 1)
    end_node[last] = move.size + np.arange(int(last.sum()))
    return node_move, node_s, end_node


def certified_intervals(
    manipulator: Manipulator,
    model: ActuatorModel,
    moves: SlerpMoves,
    count: int,
    weights: NDArray[np.float64],
    relative: float,
    max_intervals: int,
    *,
    local: bool,
    start: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> Intervals:
    """Bisect the moves' intervals until their bounds of |g_i| are tight (module documentation).

    ``local=False`` (peak speeds): an interval is loose when its bound exceeds the move's largest
    sampled rate by more than ``relative`` (weighted by ``weights``, 1/vmax). ``local=True``
    (schedules, :mod:`~hexapod_workspace.core.motions.schedule`): when it exceeds the larger of
    its own two end values by more than ``relative`` of that value plus ``relative`` of the
    move's weighted peak (an actuator much slower than the move's fastest one does not bind).
    Past :data:`MAX_ROUNDS` rounds, or ``max_intervals`` intervals, the bounds stay certified,
    only looser. ``start``: the first intervals (move, a, b), sorted by move then s and tiling
    each move's [0, 1] (default :data:`INITIAL_INTERVALS` equal ones per move).
    """
    if start is None:
        grid = np.linspace(0.0, 1.0, INITIAL_INTERVALS + 1)
        index = np.repeat(np.arange(count), grid.size)
        s = np.tile(grid, count)
        g, at = model.evaluate(manipulator, moves.motion(index, s))
        g = np.abs(g).reshape(count, grid.size, 6)
        at = at.reshape(count, grid.size, 6)
        evaluations = index.size
        sampled = np.max(g, axis=1)
        move = np.repeat(np.arange(count), INITIAL_INTERVALS)
        a = np.tile(grid[:-1], count)
        b = np.tile(grid[1:], count)
        g_a: NDArray[np.float64] = g[:, :-1].reshape(-1, 6)
        g_b: NDArray[np.float64] = g[:, 1:].reshape(-1, 6)
        f_a: NDArray[np.float64] = at[:, :-1].reshape(-1, 6)
        f_b: NDArray[np.float64] = at[:, 1:].reshape(-1, 6)
    else:
        move, a, b = start
        node_move, node_s, end_node = interval_nodes(move, a, b)
        g_n, f_n = model.evaluate(manipulator, moves.motion(node_move, node_s))
        g_n = np.abs(g_n)
        evaluations = node_s.size
        sampled = np.zeros((count, 6))
        np.maximum.at(sampled, node_move, g_n)
        g_a, f_a = g_n[: move.size], f_n[: move.size]
        g_b, f_b = g_n[end_node], f_n[end_node]
    done: list[tuple[NDArray[Any], ...]] = []
    for round_ in range(MAX_ROUNDS + 1):
        width = (b - a)[:, None]
        speed, accel = moves.speed[move], moves.accel[move]
        floor = model.interval_floor(manipulator, f_a, f_b, speed, width)
        positive = floor > 0.0
        rate = model.rate_bound(manipulator, speed, accel, np.where(positive, floor, 1.0))
        # a move that does not move has zero rates everywhere (V = A = 0)
        rate = np.where(speed == 0.0, 0.0, np.where(positive, rate, np.inf))
        upper = np.where(speed == 0.0, 0.0, 0.5 * (g_a + g_b + rate * width))
        # a floor of 1e-9 of the joint speed keeps a move whose rates are all ~0 from
        # splitting for ever
        scale = np.max(sampled * weights, axis=1) + 1e-9 * np.max(moves.speed * weights, axis=1)
        if local:
            ends = np.maximum(g_a, g_b) * weights
            slack = relative * (ends + scale[move][:, None])
            loose = np.any(upper * weights > ends + slack, axis=1)
        else:
            target = (1.0 + relative) * scale
            loose = np.any(upper * weights > target[move][:, None], axis=1)
        if round_ == MAX_ROUNDS or not np.any(loose) or 2 * a.size > max_intervals:
            done.append((move, a, b, g_a, g_b, upper, rate, floor))
            break
        keep = ~loose
        done.append(tuple(x[keep] for x in (move, a, b, g_a, g_b, upper, rate, floor)))
        mid = 0.5 * (a[loose] + b[loose])
        split = move[loose]
        g_m, f_m = model.evaluate(manipulator, moves.motion(split, mid))
        g_m = np.abs(g_m)
        evaluations += mid.size
        np.maximum.at(sampled, split, g_m)
        move = np.concatenate([split, split])
        a = np.concatenate([a[loose], mid])
        b = np.concatenate([mid, b[loose]])
        g_a, g_b = np.concatenate([g_a[loose], g_m]), np.concatenate([g_m, g_b[loose]])
        f_a = np.concatenate([f_a[loose], f_m])
        f_b = np.concatenate([f_m, f_b[loose]])
    parts = [np.concatenate(column) for column in zip(*done, strict=True)]
    order = np.lexsort((parts[1], parts[0]))  # by move, then by s
    m, a, b, g_a, g_b, upper, rate, floor = (x[order] for x in parts)
    return Intervals(m, a, b, g_a, g_b, upper, rate, floor, sampled, evaluations)


def actuator_rates(
    manipulator: Manipulator,
    positions: ArrayLike,
    rotations: ArrayLike,
    *,
    speed_limits: ArrayLike | None = None,
    architecture: str | None = None,
    relative: float = DEFAULT_RELATIVE,
    arcs: ArrayLike | None = None,
    beziers: ArrayLike | None = None,
) -> MoveRates:
    """Certified peak actuator rates (per unit s) of the N − 1 slerp moves of a path.

    Parameters
    ----------
    manipulator : Manipulator
        In the frame whose poses are given (a :func:`~hexapod_workspace.core.cell.frames.tool_model`
        for tool-frame poses).
    positions : array_like, shape (N, 3)
        Positions, base frame, m.
    rotations : array_like, shape (N, 3, 3)
        Orientations, base frame.
    speed_limits : array_like, shape (6,), optional
        vmax per actuator (0 = unlimited); weights the tightness test only.
    architecture : str, optional
        Key of :data:`ACTUATOR_MODELS`; default the manipulator's (``"ups"``).
    relative : float
        Tightness of the bound against the sampled peak, in (0, 1).
    arcs : array_like, shape (N − 1, 7), optional
        Moves that are arcs, as :func:`~hexapod_workspace.core.motions.checks.check_path` takes
        them; their ``translation`` is then a lower bound of the arc's length.
    beziers : array_like, shape (N − 1, 6), optional
        Moves that are cubic Bézier curves, as
        :func:`~hexapod_workspace.core.motions.checks.check_path` takes them (``translation``:
        a lower bound of the length).

    Returns
    -------
    MoveRates

    Raises
    ------
    InputError
        Wrong shapes, non-finite values, unknown architecture, ``relative`` out of range.
    """
    p = np.asarray(positions, dtype=np.float64)
    r = np.asarray(rotations, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or r.shape != (p.shape[0], 3, 3) or p.shape[0] < 1:
        msg = f"poses: expected positions (N, 3) and rotations (N, 3, 3), got {p.shape}, {r.shape}"
        raise InputError(msg)
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(r))):
        msg = "poses: expected finite positions and rotations"
        raise InputError(msg)
    own = manipulator.architecture
    name = own if architecture is None else architecture
    if name not in ACTUATOR_MODELS:
        msg = f"architecture: expected one of {', '.join(ACTUATOR_MODELS)}, got {name!r}"
        raise InputError(msg)
    if name != own:
        msg = f"architecture: expected the model's {own!r}, got {name!r}"
        raise InputError(msg)
    if not 0.0 < relative < 1.0:
        msg = f"relative: expected a value in (0, 1), got {relative!r}"
        raise InputError(msg)
    model = ACTUATOR_MODELS[name]
    limits = np.zeros(6) if speed_limits is None else np.broadcast_to(speed_limits, (6,))
    weights = _weights(np.asarray(limits, dtype=np.float64))
    moves = SlerpMoves(
        manipulator, p[:-1], p[1:], r[:-1], r[1:], _validate_curves(arcs, beziers, p)
    )
    count = p.shape[0] - 1
    bound = np.zeros((count, 6))
    sampled = np.zeros((count, 6))
    if count == 0:
        return MoveRates(bound, sampled, moves.translation, moves.omega, 0)

    final = certified_intervals(
        manipulator, model, moves, count, weights, relative, MAX_INTERVALS, local=False
    )
    np.maximum.at(bound, final.move, final.upper)
    return MoveRates(bound, final.sampled, moves.translation, moves.omega, final.evaluations)


@dataclass(frozen=True)
class FeedLimits:
    """Actuator speeds of M moves at their feeds, and the largest feeds within the limits.

    Attributes
    ----------
    duration : ndarray, shape (M,)
        s (NaN: no feed for this move).
    speed_peak : ndarray, shape (M,)
        Certified bound of the largest actuator speed over the move (actuator unit/s; NaN
        without a duration).
    speed_ok : ndarray, shape (M,), object
        True when every actuator's bound is within its limit, False when one is not, None
        without a duration.
    feed_max : ndarray, shape (M,)
        Certified lower bound of the largest feed keeping every actuator within its limit,
        in the feed's unit (m/s, or rad/s for ``rotary``), +inf when the move does not move
        a limited actuator, NaN when no limit applies.
    rotary : ndarray, shape (M,), bool
        The move has no translation: its feed is a rotation rate (rad/s).
    """

    duration: NDArray[np.float64]
    speed_peak: NDArray[np.float64]
    speed_ok: NDArray[np.object_]
    feed_max: NDArray[np.float64]
    rotary: NDArray[np.bool_]


def feed_limits(
    rates: MoveRates,
    feeds: ArrayLike,
    rotary_feeds: ArrayLike,
    speed_limits: ArrayLike,
) -> FeedLimits:
    """Durations, certified peak speeds and largest feeds of moves (module documentation).

    Parameters
    ----------
    rates : MoveRates
    feeds : array_like, shape (M,)
        Tool-centre-point feed of each move, m/s (NaN: none).
    rotary_feeds : array_like, shape (M,)
        Rotation rate for moves without translation, rad/s (NaN: none).
    speed_limits : array_like, shape (6,) or (1,)
        vmax per actuator, actuator unit/s (0 = unlimited).

    Returns
    -------
    FeedLimits
    """
    count = rates.translation.shape[0]
    feed = np.broadcast_to(np.asarray(feeds, dtype=np.float64), (count,))
    rotary_feed = np.broadcast_to(np.asarray(rotary_feeds, dtype=np.float64), (count,))
    limits = np.broadcast_to(np.asarray(speed_limits, dtype=np.float64), (6,))
    if np.any(feed <= 0.0) or np.any(rotary_feed <= 0.0) or np.any(limits < 0.0):
        msg = "feeds: expected feeds > 0 and speed limits >= 0"
        raise InputError(msg)
    rotary = rates.translation == 0.0
    length = np.where(rotary, rates.rotation, rates.translation)  # m, or rad
    rate_feed = np.where(rotary, rotary_feed, feed)
    still = length == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        duration = np.where(still, 0.0, length / rate_feed)
        peak_rate = np.max(rates.peak_bound, axis=1)
        speed_peak = np.where(still, 0.0, peak_rate / duration)
        limited = limits > 0.0
        over = np.where(limited, rates.peak_bound / duration[:, None], 0.0) > limits
        headroom = np.where(limited, limits / rates.peak_bound, np.inf)  # 1/s per unit s
        feed_max = length * np.min(headroom, axis=1)
    feed_max = np.where(still, np.inf, feed_max)
    if not np.any(limited):
        feed_max = np.full(count, np.nan)
    known = np.isfinite(duration)
    speed_ok = np.array(
        [None if not known[k] else not bool(np.any(over[k])) for k in range(count)],
        dtype=object,
    )
    return FeedLimits(
        duration=np.where(known, duration, np.nan),
        speed_peak=np.where(known, speed_peak, np.nan),
        speed_ok=speed_ok,
        feed_max=feed_max,
        rotary=rotary,
    )
