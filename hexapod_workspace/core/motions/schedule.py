"""The fastest feed schedule along a path that is certified to run: actuator speeds and
accelerations, the tool centre point's feed, rest at both ends.

**The problem.** Along a path of M moves (the moves
:func:`~hexapod_workspace.core.motions.checks.check_path` checks: position linear, or an arc,
or a cubic Bézier curve, orientation by slerp),
s = k + u on move k with u ∈ [0, 1] its own parameter, find the time law s(t) that minimises the
total time subject to, for every actuator i and every s,

    |q̇_i| ≤ v_i,     |q̈_i| ≤ a_i,     |ṗ| ≤ f_k (the move's feed ceiling),

and ṡ = 0 at both ends (and where the path must stop). With g_i = dq_i/du (:mod:`.speeds`),
``q̇_i = g_i·ṡ`` and ``q̈_i = g_i'·ṡ² + g_i·s̈``. In ``x = ṡ²`` (a function of s) the time is
``∫ ds/√x`` and ``s̈ = x'/2``.

**The grid and its certified coefficients.** Each move is cut into intervals by the bisection
of :func:`~hexapod_workspace.core.motions.speeds.certified_intervals` (``local=True``: until the
bound of every |g_i| over an interval is within ``relative`` of the larger of its end values).
On an interval I = [a, b] of width w it gives two certified bounds, valid for every s in I:
G_i ≥ |g_i(s)| and K_i ≥ |g_i'(s)| (derived in :mod:`.speeds`). The tool centre point's speed
per unit s is bounded the same way: ``P = |Δp|`` on a straight move; on a curve
``P = min(P₁, (|p'(a)| + |p'(b)| + P₂·w)/2)`` with P₁, P₂ the curve's bounds of |p'| and |p''|
(``hexapod_workspace.core.motions.interpolation``); a rotation without translation takes
``P = Ω`` against the rotary feed.

**The schedule's form.** On every interval s̈ = u is constant, so x is linear in s:
``x(s) = x_a + 2u·(s − a)``, and ``max_I x = max(x_a, x_b)``. Then, on the whole interval,

    |q̇_i| ≤ G_i·√max(x_a, x_b),       |q̈_i| ≤ K_i·max(x_a, x_b) + G_i·|u|,
    |ṗ| ≤ P·√max(x_a, x_b),

so the schedule holds every limit everywhere (not only at grid points) when, at both ends,

    x ≤ X_I := min_i((v_i/G_i)², a_i/K_i) and (f/P)²,    |u| ≤ U_I(x) := min_i (a_i − K_i x)/G_i.

**Second order.** The bound K of :mod:`.speeds` is a move-wide worst case; each interval
takes the tighter ``K_loc`` of :mod:`.schedule_bounds` (derived there, for straight moves,
arcs and Bézier spans alike) and G from it.

**The passes.** U_I decreases in x, which makes the classic two-pass construction both optimal
on this grid and feasible. Forward from rest, each node takes the largest x the interval allows
from the one before: accelerating (x_b > x_a, so max x = x_b), ``x_b ≤ x_a + 2w·(a_i − K_i x_b)
/G_i``, i.e. ``x_b ≤ (G_i x_a + 2w a_i)/(G_i + 2w K_i)`` for every i, and ``x_b ≤ X``. Backward
from rest the same with a and b swapped. The schedule is ``x = min(forward, backward)``. On
every interval it is feasible: where both ends come from one pass, that pass's step holds (a
capped, decelerating forward step is a backward step, since the backward pass is capped by the
same X); where the forward pass gives x_a and the backward one x_b, ``x_b − x_a`` lies between
the backward step's and the forward step's, each within U at larger x, hence within U at the
schedule's x (U decreasing); the other mixed case is symmetric. Each node's x is the largest any
schedule of this form can have (by induction along each pass), so the time is the least on the
grid; as the grid is refined the bounds G, K close on g, g' and the time approaches the true
optimum from above (``test/test_schedule.py`` compares it with toppra's).

**Waypoints.** Across a waypoint q̇ = g·ṡ stays continuous when the rates of the two moves are
parallel, ``g_left = c·g_right`` with c > 0 (the moves may be of different lengths): the
schedule then runs through with ``x_right = c²·x_left`` (ṡ jumps, q̇ does not; the bounds of q̈
hold on each side). Where the 6-vectors are not parallel (within ``corner``, an angle) q̇ would
jump, which no finite acceleration allows: the schedule stops there (x = 0 on both sides). It
also stops where the caller asks (``stops``: tool changes, ``RAPID`` boundaries). A move that
does not move (repeated waypoint) takes no time and is passed over for the continuity test.

**Time and witnesses.** An interval with x linear lasts ``2w/(√x_a + √x_b)``. Every node records
what fixed its x (rest, the feed, an actuator's speed or acceleration), and every move reports its
certified peak feed and actuator speeds and accelerations (the bounds above at the schedule's
x and u). A move where some actuator has no inverse-kinematics solution, or a transmission of 0,
on the move is refused with the move named, as is a move no limit bounds.
**Steady feeds.** What a CAM user can apply without a controller that follows s(t): the largest
*constant* rate u' = ṡ per move (s̈ = 0) that holds the actuator limits everywhere on it
(:func:`steady_feeds`). With s̈ = 0, ``q̇_i = g_i·u'`` and ``q̈_i = g_i'·u'²``, so on each interval
``|q̇_i| ≤ G_i·u'`` and ``|q̈_i| ≤ K_i·u'²`` and the move holds every limit when
``u'² ≤ min over its intervals and actuators of min((v_i/G_i)², a_i/K_i)`` (the caps X_I
above without the feed). ``schedule --write-cl`` writes F = u'·L as the move's ``FEDRAT``
(L = :attr:`PathSchedule.length`, a lower bound on curves: the tool-tip speed ``|p'|·u'`` may
exceed F on a curve, as check-path's speeds take a move at feed F). The intervals that bind are
bisected again (K shrinks with them on straight moves) while that raises some move's rate by
more than ``relative``/4. The corners between moves (one feed to the next) are not bounded:
they stay the controller's look-ahead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError
from ..model.manipulator import Manipulator
from .interpolation import _validate_curves
from .schedule_bounds import local_rates, tcp_bounds
from .speeds import (
    ACTUATOR_MODELS,
    Intervals,
    SlerpMoves,
    _weights,
    certified_intervals,
)

__all__ = [
    "DEFAULT_CORNER",
    "DEFAULT_SCHEDULE_RELATIVE",
    "LIMIT_KINDS",
    "PathSchedule",
    "schedule_path",
    "steady_feeds",
]

#: Tightness of each interval's bound of |g_i| against its end values (module documentation).
DEFAULT_SCHEDULE_RELATIVE = 0.002
#: Largest angle between the actuator-rate 6-vectors of two moves that still runs through their
#: waypoint, rad (below it the jump of q̇ is at most this share of |q̇|).
DEFAULT_CORNER = 1e-6
#: Largest number of intervals (memory and time bound; past it the bounds are only looser).
MAX_SCHEDULE_INTERVALS = 400_000
#: Rounds of refinement where the schedule ramps.
REFINE_ROUNDS = 16
#: A move whose certified peak feed is this share below its ceiling runs slower than programmed.
BELOW_CEILING = 0.01
#: What fixes a node's speed: ``rest`` (a stop), ``feed``, ``velocity`` or ``acceleration``.
LIMIT_KINDS = ("rest", "feed", "velocity", "acceleration")
_REST, _FEED, _VELOCITY, _ACCELERATION = range(4)


@dataclass(frozen=True)
class PathSchedule:
    """A certified time-optimal schedule of a path of M moves.

    Attributes
    ----------
    s : ndarray, shape (n,)
        Grid nodes, s = k + u on move k; at a waypoint the end of one move and the start of
        the next are two nodes with the same s.
    sdot : ndarray, shape (n,)
        ṡ at the nodes, 1/s (s̈ is constant between two nodes of one move, so ṡ² is linear).
    node_move : ndarray, shape (n,), int
        Move of each node.
    time : ndarray, shape (n,)
        t at the nodes, s.
    limit_kind : ndarray, shape (n,), int
        Index in :data:`LIMIT_KINDS` of what fixed the node's speed.
    limit_actuator : ndarray, shape (n,), int
        The limiting actuator (0-based), −1 for rest and feed.
    t_start, t_end : ndarray, shape (M,)
        Each move's start and end time, s.
    feed_peak : ndarray, shape (M,)
        Certified bound of the tool centre point's speed over the move, m/s (rad/s for a
        rotation without translation).
    speed_peak : ndarray, shape (M, 6)
        Certified bound of |q̇_i| over the move (actuator unit/s).
    accel_peak : ndarray, shape (M, 6)
        Certified bound of |q̈_i| over the move (actuator unit/s²).
    stops : ndarray, shape (M + 1,), bool
        The waypoints where the schedule is at rest.
    rotary : ndarray, shape (M,), bool
        Moves without translation (their feed is a rotation rate).
    length : ndarray, shape (M,)
        Each move's length (m; a lower bound on a curve) or rotation (rad, rotary moves).
    intervals : int
        Grid intervals.
    """

    s: NDArray[np.float64]
    sdot: NDArray[np.float64]
    node_move: NDArray[np.int64]
    time: NDArray[np.float64]
    limit_kind: NDArray[np.int64]
    limit_actuator: NDArray[np.int64]
    t_start: NDArray[np.float64]
    t_end: NDArray[np.float64]
    feed_peak: NDArray[np.float64]
    speed_peak: NDArray[np.float64]
    accel_peak: NDArray[np.float64]
    stops: NDArray[np.bool_]
    rotary: NDArray[np.bool_]
    length: NDArray[np.float64]
    intervals: int

    @property
    def duration(self) -> float:
        """Total time, s."""
        return float(self.time[-1]) if self.time.size else 0.0


def _limits(values: ArrayLike, name: str, unit: str) -> NDArray[np.float64]:
    """One or six limits >= 0 (0 = unlimited) as six, unlimited as +inf."""
    array = np.asarray(values, dtype=np.float64).reshape(-1)
    if array.size not in (1, 6) or not np.all(np.isfinite(array)) or np.any(array < 0.0):
        msg = f"{name}: expected 1 or 6 finite values >= 0 ({unit}, 0 = unlimited), got {array}"
        raise InputError(msg)
    six = np.broadcast_to(array, (6,))
    return np.where(six > 0.0, six, np.inf)


def _ceilings(values: ArrayLike | None, count: int, name: str) -> NDArray[np.float64]:
    """Per-move ceilings > 0 (inf: none)."""
    if values is None:
        return np.full(count, np.inf)
    array = np.broadcast_to(np.asarray(values, dtype=np.float64), (count,))
    if np.any(np.isnan(array)) or np.any(array <= 0.0):
        msg = f"{name}: expected values > 0 per move (inf: no ceiling)"
        raise InputError(msg)
    return np.asarray(array, dtype=np.float64)


def _prepared(
    manipulator: Manipulator,
    positions: ArrayLike,
    rotations: ArrayLike,
    arcs: ArrayLike | None,
    beziers: ArrayLike | None,
    relative: float,
) -> tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    SlerpMoves,
    NDArray[np.bool_],
    NDArray[np.float64],
    NDArray[np.int64],
    SlerpMoves | None,
]:
    """The validated poses (N, 3) and (N, 3, 3), the moves, which are rotations only, each
    move's length (m, or rad for a rotation), the moves that move and their batch (None when
    none does)."""
    p = np.asarray(positions, dtype=np.float64)
    r = np.asarray(rotations, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or r.shape != (p.shape[0], 3, 3) or p.shape[0] < 2:
        msg = (
            "poses: expected positions (N, 3) and rotations (N, 3, 3), N >= 2, "
            f"got {p.shape}, {r.shape}"
        )
        raise InputError(msg)
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(r))):
        msg = "poses: expected finite positions and rotations"
        raise InputError(msg)
    if not 0.0 < relative < 0.5:
        msg = f"relative: expected a value in (0, 0.5), got {relative!r}"
        raise InputError(msg)
    name = manipulator.architecture
    if name not in ACTUATOR_MODELS:
        msg = f"architecture: expected one of {', '.join(ACTUATOR_MODELS)}, got {name!r}"
        raise InputError(msg)
    moves = SlerpMoves(
        manipulator, p[:-1], p[1:], r[:-1], r[1:], _validate_curves(arcs, beziers, p)
    )
    rotary = moves.translation == 0.0
    length = np.where(rotary, moves.omega, moves.translation)
    active = np.flatnonzero(length != 0.0)
    count = p.shape[0] - 1
    if active.size == 0:
        return p, r, moves, rotary, length, active, None
    sub = (
        moves  # the moves that move: all of them, or a new batch without the still ones
        if active.size == count
        else SlerpMoves(
            manipulator,
            p[:-1][active],
            p[1:][active],
            r[:-1][active],
            r[1:][active],
            None if moves.arcs is None else moves.arcs.take(active),
        )
    )
    return p, r, moves, rotary, length, active, sub


def _bisected(
    manipulator: Manipulator,
    sub: SlerpMoves,
    count: int,
    weights: NDArray[np.float64],
    relative: float,
    grid: Intervals,
    split: NDArray[np.bool_],
) -> Intervals:
    """The grid with the intervals ``split`` (m,) cut in two, its bounds certified anew."""
    mid = 0.5 * (grid.a[split] + grid.b[split])
    move = np.concatenate([grid.move, grid.move[split]])
    a = np.concatenate([grid.a, mid])
    b = np.concatenate([np.where(split, 0.5 * (grid.a + grid.b), grid.b), grid.b[split]])
    order = np.lexsort((a, move))
    return certified_intervals(
        manipulator,
        ACTUATOR_MODELS[manipulator.architecture],
        sub,
        count,
        weights,
        relative,
        MAX_SCHEDULE_INTERVALS,
        local=True,
        start=(move[order], a[order], b[order]),
    )


def _checked_rates(
    manipulator: Manipulator, sub: SlerpMoves, grid: Intervals, active: NDArray[np.int64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """K and G per interval (:func:`.schedule_bounds.local_rates`), (m, 6) each; a move where
    one is infinite (no inverse-kinematics solution, a transmission of 0) refused, named
    (1-based)."""
    big_k, big_g = local_rates(manipulator, sub, grid)
    bad = np.flatnonzero(~np.all(np.isfinite(big_g) & np.isfinite(big_k), axis=1))
    if bad.size:
        k = int(active[grid.move[bad[0]]])
        which_leg = int(
            np.flatnonzero(~np.isfinite(big_g[bad[0]]) | ~np.isfinite(big_k[bad[0]]))[0]
        )
        msg = (
            f"move {k + 1}: actuator {which_leg + 1} has no inverse-kinematics solution or a "
            "transmission of 0 on it (no speed can be scheduled; see the ik and transmission "
            "constraints)"
        )
        raise InputError(msg)
    return big_k, big_g


def _actuator_caps(
    big_g: NDArray[np.float64],
    big_k: NDArray[np.float64],
    vmax: NDArray[np.float64],
    amax: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The caps of ṡ² per interval and actuator, (m, 6) each: (v_i/G_i)² and a_i/K_i (+inf
    where the bound is 0 or the limit is none)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        speed_cap = np.where(big_g > 0.0, (vmax / big_g) ** 2, np.inf)
        accel_cap = np.where(big_k > 0.0, amax / big_k, np.inf)
    return speed_cap, accel_cap


def _junctions(
    manipulator: Manipulator,
    moves: SlerpMoves,
    active: NDArray[np.int64],
    stops: NDArray[np.bool_],
    corner: float,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Between consecutive active moves: c² (x_right = c²·x_left) and whether to stop."""
    model = ACTUATOR_MODELS[manipulator.architecture]
    n = active.size
    if n < 2:
        return np.zeros(0), np.zeros(0, dtype=bool)
    left, right = active[:-1], active[1:]  # the moves' numbers in the path
    mine = np.arange(n)  # and in ``moves`` (the active moves only)
    g_left, _ = model.evaluate(manipulator, moves.motion(mine[:-1], np.ones(n - 1)))
    g_right, _ = model.evaluate(manipulator, moves.motion(mine[1:], np.zeros(n - 1)))
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.einsum("ij,ij->i", g_left, g_right) / np.einsum("ij,ij->i", g_right, g_right)
        residual = np.linalg.norm(g_left - scale[:, None] * g_right, axis=1)
        parallel = (scale > 0.0) & (residual <= math.sin(corner) * np.linalg.norm(g_left, axis=1))
    # the waypoint between left and right: any stop requested at it or at a still move between
    asked = np.array(
        [bool(stops[lo + 1 : hi + 1].any()) for lo, hi in zip(left, right, strict=True)]
    )
    stop = ~parallel | asked | ~np.isfinite(scale)
    return np.where(stop, 0.0, scale**2), stop


def schedule_path(
    manipulator: Manipulator,
    positions: ArrayLike,
    rotations: ArrayLike,
    *,
    speed_limits: ArrayLike,
    accel_limits: ArrayLike,
    feeds: ArrayLike | None = None,
    rotary_feeds: ArrayLike | None = None,
    stops: ArrayLike | None = None,
    arcs: ArrayLike | None = None,
    beziers: ArrayLike | None = None,
    relative: float = DEFAULT_SCHEDULE_RELATIVE,
    corner: float = DEFAULT_CORNER,
) -> PathSchedule:
    """The fastest certified schedule of the N − 1 slerp moves of a path (module documentation).

    Parameters
    ----------
    manipulator : Manipulator
        In the frame whose poses are given (a tool model for tool-centre-point poses).
    positions : array_like, shape (N, 3)
        Tool centre point, base frame, m.
    rotations : array_like, shape (N, 3, 3)
        Orientations, base frame.
    speed_limits : array_like, shape (6,) or (1,)
        v_i, actuator unit/s (0 = unlimited).
    accel_limits : array_like, shape (6,) or (1,)
        a_i, actuator unit/s² (0 = unlimited).
    feeds : array_like, shape (N − 1,), optional
        Tool-centre-point speed ceiling per move, m/s (inf: none); default none.
    rotary_feeds : array_like, shape (N − 1,), optional
        Rotation-rate ceiling of moves without translation, rad/s (inf: none).
    stops : array_like, shape (N,), bool, optional
        Waypoints where the schedule must be at rest (the ends always are).
    arcs, beziers : array_like, optional
        Curved moves, as :func:`~hexapod_workspace.core.motions.checks.check_path` takes them.
    relative : float
        Tightness of the grid's bounds, in (0, 0.5).
    corner : float
        Largest angle between two moves' rate vectors that runs through their waypoint, rad,
        in [0, 0.1].

    Returns
    -------
    PathSchedule

    Raises
    ------
    InputError
        Bad shapes or values (naming the parameter); a move where an actuator has no
        inverse-kinematics solution or a transmission of 0, or whose speed no limit bounds
        (naming the move, 1-based).
    """
    if not 0.0 <= corner <= 0.1:
        msg = f"corner: expected an angle in [0, 0.1] rad, got {corner!r}"
        raise InputError(msg)
    p, r, _, rotary, length, active, sub = _prepared(
        manipulator, positions, rotations, arcs, beziers, relative
    )
    name = manipulator.architecture
    count = p.shape[0] - 1
    vmax = _limits(speed_limits, "speed_limits", "actuator unit/s")
    amax = _limits(accel_limits, "accel_limits", "actuator unit/s²")
    feed = _ceilings(feeds, count, "feeds")
    rotary_feed = _ceilings(rotary_feeds, count, "rotary_feeds")
    stop_at = np.zeros(count + 1, dtype=bool)
    if stops is not None:
        asked = np.asarray(stops, dtype=bool)
        if asked.shape != (count + 1,):
            msg = f"stops: expected one flag per waypoint ({count + 1}), got shape {asked.shape}"
            raise InputError(msg)
        stop_at |= asked
    stop_at[0] = stop_at[-1] = True
    model = ACTUATOR_MODELS[name]
    weights = _weights(np.where(np.isfinite(vmax), vmax, 0.0))
    if sub is None:
        return _still_schedule(count, stop_at, rotary, length)
    grid = certified_intervals(
        manipulator, model, sub, active.size, weights, relative, MAX_SCHEDULE_INTERVALS, local=True
    )
    given = (vmax, amax, feed, rotary_feed, rotary, length, stop_at)
    schedule, ramp = _solve(manipulator, sub, grid, active, given, corner)
    # Refine where the schedule ramps (leaves or nears rest, or is acceleration-bound): the grid
    # is what limits the time there; stop when a round gains less than relative/4.
    for _ in range(REFINE_ROUNDS):
        if not ramp.any() or grid.move.size + int(ramp.sum()) > MAX_SCHEDULE_INTERVALS:
            break
        finer = _bisected(manipulator, sub, active.size, weights, relative, grid, ramp)
        candidate, candidate_ramp = _solve(manipulator, sub, finer, active, given, corner)
        gain = schedule.duration - candidate.duration
        if gain < 0.0:
            break
        schedule, ramp, grid = candidate, candidate_ramp, finer
        if gain <= 0.25 * relative * schedule.duration:
            break
    return schedule


def steady_feeds(
    manipulator: Manipulator,
    positions: ArrayLike,
    rotations: ArrayLike,
    *,
    speed_limits: ArrayLike,
    accel_limits: ArrayLike,
    arcs: ArrayLike | None = None,
    beziers: ArrayLike | None = None,
    relative: float = DEFAULT_SCHEDULE_RELATIVE,
) -> NDArray[np.float64]:
    """The largest certified constant parameter rate of each of the N − 1 slerp moves of a
    path (module documentation, "Steady feeds").

    Running move k at ``u' = rate[k]`` (u ∈ [0, 1] its parameter, s̈ = 0) keeps every
    actuator within ``speed_limits`` and ``accel_limits`` everywhere on it: with G_i ≥ |g_i|
    and K_i ≥ |g_i'| on each interval
    (:func:`~hexapod_workspace.core.motions.speeds.certified_intervals`,
    :func:`.schedule_bounds.local_rates`), ``|q̇_i| ≤ G_i·u'`` and ``|q̈_i| ≤ K_i·u'²``, so
    ``u'² = min over the move's intervals and actuators of min((v_i/G_i)², a_i/K_i)``.
    The feed F = u'·L (L = :attr:`PathSchedule.length`) is that of check-path's speed verdicts.
    Junctions between moves are not bounded (the controller's look-ahead).

    Parameters
    ----------
    manipulator : Manipulator
        The model of the poses' frame (a tool model for tool-centre-point poses).
    positions, rotations : array_like, shapes (N, 3) and (N, 3, 3)
        The waypoints: tool centre point (m) and orientation, both in the base frame.
    speed_limits, accel_limits : array_like, shape (6,) or (1,)
        v_i (actuator unit/s) and a_i (actuator unit/s²), 0 = unlimited.
    arcs, beziers : array_like, optional
        The curved moves, as for :func:`schedule_path`.
    relative : float
        Tightness of the grid's bounds, in (0, 0.5).

    Returns
    -------
    ndarray, shape (N − 1,)
        u' per move, 1/s; +inf where no limit bounds it (no limits, or a move that does not
        move).

    Raises
    ------
    InputError
        Bad shapes or values (naming the parameter); a move where an actuator has no
        inverse-kinematics solution or a transmission of 0 (naming the move, 1-based).
    """
    p, _, _, _, _, active, sub = _prepared(
        manipulator, positions, rotations, arcs, beziers, relative
    )
    vmax = _limits(speed_limits, "speed_limits", "actuator unit/s")
    amax = _limits(accel_limits, "accel_limits", "actuator unit/s²")
    rate = np.full(p.shape[0] - 1, np.inf)
    if sub is None:
        return rate
    model = ACTUATOR_MODELS[manipulator.architecture]
    weights = _weights(np.where(np.isfinite(vmax), vmax, 0.0))
    grid = certified_intervals(
        manipulator, model, sub, active.size, weights, relative, MAX_SCHEDULE_INTERVALS, local=True
    )
    best = np.zeros(active.size)
    for round_ in range(REFINE_ROUNDS + 1):
        big_k, big_g = _checked_rates(manipulator, sub, grid, active)
        speed_cap, accel_cap = _actuator_caps(big_g, big_k, vmax, amax)
        cap = np.minimum(speed_cap, accel_cap).min(axis=1)  # of ṡ², per interval
        lowest = np.full(active.size, np.inf)
        np.minimum.at(lowest, grid.move, cap)
        value = np.sqrt(lowest)
        gained = round_ == 0 or bool(np.any(value > best * (1.0 + 0.25 * relative)))
        best = np.maximum(best, value)  # every grid's value is certified
        # bisect the intervals that may bind (within 10 % of their move's rate) while it pays
        binding = np.isfinite(cap) & (cap <= 1.21 * lowest[grid.move])
        if (
            not gained
            or round_ == REFINE_ROUNDS
            or not binding.any()
            or grid.move.size + int(binding.sum()) > MAX_SCHEDULE_INTERVALS
        ):
            break
        grid = _bisected(manipulator, sub, active.size, weights, relative, grid, binding)
    rate[active] = best
    return rate


def _solve(
    manipulator: Manipulator,
    sub: SlerpMoves,
    grid: Intervals,
    active: NDArray[np.int64],
    given: tuple[NDArray[Any], ...],
    corner: float,
) -> tuple[PathSchedule, NDArray[np.bool_]]:
    """The schedule on one grid (module documentation), and its ramp intervals (an end at rest
    or below its cap)."""
    vmax, amax, feed, rotary_feed, rotary, length, stop_at = given
    count = feed.size

    move, a, b = grid.move, grid.a, grid.b
    width = b - a
    big_k, big_g = _checked_rates(manipulator, sub, grid, active)

    # the caps X_I per interval, and what sets them
    speed_cap, accel_cap = _actuator_caps(big_g, big_k, vmax, amax)
    tcp = np.where(rotary[active][move], sub.omega[move], tcp_bounds(sub, move, a, b))
    ceiling = np.where(rotary[active][move], rotary_feed[active][move], feed[active][move])
    with np.errstate(divide="ignore"):
        feed_cap = np.where(tcp > 0.0, (ceiling / tcp) ** 2, np.inf)
    candidates = np.column_stack([feed_cap, speed_cap, accel_cap])  # (m, 13)
    which = np.argmin(candidates, axis=1)
    cap = candidates[np.arange(which.size), which]
    unbounded = np.flatnonzero(~np.isfinite(cap))
    if unbounded.size:
        k = int(active[move[unbounded[0]]])
        msg = (
            f"move {k + 1}: no limit bounds its speed (give it a feed, or set "
            "limits.actuator_speed_max or limits.actuator_accel_max)"
        )
        raise InputError(msg)
    cap_kind = np.where(which == 0, _FEED, np.where(which <= 6, _VELOCITY, _ACCELERATION))
    cap_actuator = np.where(which == 0, -1, (which - 1) % 6)

    # per-interval step coefficients: x_next <= lam_i·x + mu_i (module documentation)
    with np.errstate(divide="ignore", invalid="ignore"):
        den = big_g + 2.0 * width[:, None] * big_k
        lam = np.where(den > 0.0, big_g / den, 1.0)
        mu = np.where(den > 0.0, 2.0 * width[:, None] * amax / den, np.inf)
    lam = np.where(np.isfinite(amax), lam, 1.0)
    mu = np.where(np.isfinite(amax), mu, np.inf)

    first = np.flatnonzero(np.r_[True, move[1:] != move[:-1]])  # first interval of each move
    factor, junction_stop = _junctions(manipulator, sub, active, stop_at, corner)
    nodes_per_move = np.diff(np.r_[first, move.size]) + 1
    total = int(nodes_per_move.sum())
    node_start = np.r_[0, np.cumsum(nodes_per_move)[:-1]]
    # node caps: a node inside a move takes both neighbouring intervals' caps
    node_cap = np.empty(total)
    node_kind = np.empty(total, dtype=np.int64)
    node_act = np.empty(total, dtype=np.int64)
    interval_node = np.empty(move.size, dtype=np.int64)  # node at each interval's start
    for j, (start, n) in enumerate(zip(first, nodes_per_move - 1, strict=True)):
        lo = node_start[j]
        interval_node[start : start + n] = np.arange(lo, lo + n)
        left = np.r_[cap[start : start + n], np.inf]
        right = np.r_[np.inf, cap[start : start + n]]
        use_left = left <= right
        node_cap[lo : lo + n + 1] = np.minimum(left, right)
        idx = np.r_[np.arange(start, start + n), start + n - 1]
        idx_right = np.r_[start, np.arange(start, start + n)]
        chosen = np.where(use_left, idx, idx_right)
        node_kind[lo : lo + n + 1] = cap_kind[chosen]
        node_act[lo : lo + n + 1] = cap_actuator[chosen]
    rest = np.zeros(total, dtype=bool)
    rest[0] = rest[-1] = True
    ends = node_start + nodes_per_move - 1
    rest[ends[:-1][junction_stop]] = True
    rest[node_start[1:][junction_stop]] = True
    node_cap[rest] = 0.0

    forward, f_act = _pass(node_cap, lam, mu, interval_node, ends, node_start, factor, 1)
    backward, b_act = _pass(node_cap, lam, mu, interval_node, ends, node_start, factor, -1)
    x = np.minimum(forward, backward)
    kind = np.where(
        rest,
        _REST,
        np.where(x >= node_cap, node_kind, _ACCELERATION),
    )
    actuator = np.where(
        rest, -1, np.where(x >= node_cap, node_act, np.where(forward <= backward, f_act, b_act))
    )

    # time and the certified peaks per move
    x_a, x_b = x[interval_node], x[interval_node + 1]
    root_a, root_b = np.sqrt(x_a), np.sqrt(x_b)
    with np.errstate(divide="ignore"):
        dt = np.where(width > 0.0, 2.0 * width / (root_a + root_b), 0.0)
    if not np.all(np.isfinite(dt)):
        worst = int(active[move[np.flatnonzero(~np.isfinite(dt))[0]]])
        msg = f"move {worst + 1}: the schedule cannot leave rest on it (a limit of 0 speed)"
        raise InputError(msg)
    high = np.maximum(x_a, x_b)
    u = np.where(width > 0.0, (x_b - x_a) / (2.0 * width), 0.0)
    interval_speed = big_g * np.sqrt(high)[:, None]
    interval_accel = big_k * high[:, None] + big_g * np.abs(u)[:, None]
    interval_feed = tcp * np.sqrt(high)
    time = np.empty(total)
    s = np.empty(total)
    node_move = np.empty(total, dtype=np.int64)
    clock = 0.0
    t_start = np.zeros(count)
    t_end = np.zeros(count)
    feed_peak = np.zeros(count)
    speed_peak = np.zeros((count, 6))
    accel_peak = np.zeros((count, 6))
    previous = -1
    for j, k in enumerate(active):
        start, n, lo = first[j], nodes_per_move[j] - 1, node_start[j]
        t_start[previous + 1 : k + 1] = clock  # still moves before k take no time
        t_end[previous + 1 : k] = clock
        times = clock + np.r_[0.0, np.cumsum(dt[start : start + n])]
        time[lo : lo + n + 1] = times
        s[lo : lo + n + 1] = k + np.r_[a[start : start + n], 1.0]
        node_move[lo : lo + n + 1] = k
        clock = float(times[-1])
        t_end[k] = clock
        feed_peak[k] = float(np.max(interval_feed[start : start + n]))
        speed_peak[k] = np.max(interval_speed[start : start + n], axis=0)
        accel_peak[k] = np.max(interval_accel[start : start + n], axis=0)
        previous = k
    t_start[previous + 1 :] = clock
    t_end[previous + 1 :] = clock
    sdot = np.sqrt(x)
    stops_out = stop_at.copy()
    for j in range(active.size - 1):
        if junction_stop[j]:
            stops_out[active[j] + 1 : active[j + 1] + 1] = True
    at_cap = x >= node_cap
    ramp = ~(at_cap[interval_node] & at_cap[interval_node + 1]) | rest[interval_node]
    ramp |= rest[interval_node + 1]
    return PathSchedule(
        s=s,
        sdot=sdot,
        node_move=node_move,
        time=time,
        limit_kind=kind,
        limit_actuator=actuator,
        t_start=t_start,
        t_end=t_end,
        feed_peak=feed_peak,
        speed_peak=speed_peak,
        accel_peak=accel_peak,
        stops=stops_out,
        rotary=rotary,
        length=length,
        intervals=int(move.size),
    ), ramp


def _pass(
    cap: NDArray[np.float64],
    lam: NDArray[np.float64],
    mu: NDArray[np.float64],
    interval_node: NDArray[np.int64],
    ends: NDArray[np.int64],
    starts: NDArray[np.int64],
    factor: NDArray[np.float64],
    direction: int,
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """One pass (1: forward, −1: backward): each node's largest x from its predecessor, capped;
    also the actuator whose acceleration bounds the step (−1: the cap or a junction)."""
    total = cap.size
    # predecessor of each node in this direction: an interval (its index) or a junction
    step_interval = np.full(total, -1, dtype=np.int64)
    junction_of = np.full(total, -1, dtype=np.int64)
    if direction > 0:
        step_interval[interval_node + 1] = np.arange(interval_node.size)
        junction_of[starts[1:]] = np.arange(starts.size - 1)
        order = range(total)
    else:
        step_interval[interval_node] = np.arange(interval_node.size)
        junction_of[ends[:-1]] = np.arange(ends.size - 1)
        order = range(total - 1, -1, -1)
    lam_rows, mu_rows = lam.tolist(), mu.tolist()
    caps, steps, junctions, factors = (
        cap.tolist(),
        step_interval.tolist(),
        junction_of.tolist(),
        factor.tolist(),
    )
    values = [0.0] * total
    acts = [-1] * total
    previous, previous_act = 0.0, -1
    for node in order:
        interval = steps[node]
        if interval >= 0:
            best, who = caps[node], -1
            for i, (l_i, m_i) in enumerate(zip(lam_rows[interval], mu_rows[interval], strict=True)):
                reach = l_i * previous + m_i
                if reach < best:
                    best, who = reach, i
        else:
            junction = junctions[node]
            if junction < 0:  # the first node of the pass
                best, who = caps[node], -1
            else:
                scale = factors[junction]
                reach = (
                    previous * scale
                    if direction > 0
                    else (previous / scale if scale > 0.0 else 0.0)
                )
                best, who = (reach, previous_act) if reach < caps[node] else (caps[node], -1)
        values[node], acts[node] = best, who
        previous, previous_act = best, who
    return np.array(values), np.array(acts, dtype=np.int64)


def _still_schedule(
    count: int, stops: NDArray[np.bool_], rotary: NDArray[np.bool_], length: NDArray[np.float64]
) -> PathSchedule:
    """A path none of whose moves moves: no time, no grid."""
    zeros = np.zeros(count)
    return PathSchedule(
        s=np.zeros(0),
        sdot=np.zeros(0),
        node_move=np.zeros(0, dtype=np.int64),
        time=np.zeros(0),
        limit_kind=np.zeros(0, dtype=np.int64),
        limit_actuator=np.zeros(0, dtype=np.int64),
        t_start=zeros,
        t_end=zeros.copy(),
        feed_peak=zeros.copy(),
        speed_peak=np.zeros((count, 6)),
        accel_peak=np.zeros((count, 6)),
        stops=stops,
        rotary=rotary,
        length=length,
        intervals=0,
    )
