"""What a schedule (:mod:`hexapod_workspace.core.motions.schedule`) says about each move, and
its quantities at the grid nodes: what limits each move below its ceiling, the time at the
programmed feeds, and the feed, actuator speeds and accelerations at every node (samples for
plots and logs; the certified bounds are
:class:`~hexapod_workspace.core.motions.schedule.PathSchedule`'s peaks).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.manipulator import Manipulator
from .interpolation import _validate_curves
from .schedule import BELOW_CEILING, LIMIT_KINDS, PathSchedule
from .schedule_bounds import rate_derivatives
from .speeds import ACTUATOR_MODELS, SlerpMoves

__all__ = [
    "ScheduleProfiles",
    "feed_ceilings",
    "limited_by",
    "programmed_duration",
    "rapid_boundaries",
    "schedule_profiles",
]


def feed_ceilings(
    feeds: ArrayLike, rapid: ArrayLike, rapid_feed: float, feed_max: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Each move's feed ceiling and programmed feed, as ``schedule`` and ``~/schedule_path``
    take them: a rapid move's is ``rapid_feed``, another's its own feed; the ceiling is that
    (the programmed feed is a ceiling, not a target), at most ``feed_max``.

    Parameters
    ----------
    feeds : array_like, shape (M,)
        Programmed feed of each move, m/s (NaN: none).
    rapid : array_like, shape (M,), bool
        The rapid moves.
    rapid_feed, feed_max : float
        m/s; NaN: none.

    Returns
    -------
    ceilings : ndarray, shape (M,)
        m/s; inf where no feed and no ``feed_max`` bound the move.
    programmed : ndarray, shape (M,)
        m/s; NaN where the move has no feed.
    """
    programmed = np.where(np.asarray(rapid, dtype=bool), rapid_feed, feeds).astype(np.float64)
    cap = math.inf if math.isnan(feed_max) else feed_max
    ceilings = np.minimum(np.where(np.isnan(programmed), math.inf, programmed), cap)
    return ceilings, programmed


def rapid_boundaries(rapid: ArrayLike) -> NDArray[np.bool_]:
    """Per waypoint (M + 1,), whether a rapid run of moves begins or ends there (``rapid``
    (M,), bool): where ``--stop-at-rapids`` and ``stop_at_rapids`` rest."""
    moves = np.asarray(rapid, dtype=bool)
    stops = np.zeros(moves.size + 1, dtype=bool)
    stops[1:-1] = moves[:-1] != moves[1:]
    return stops


def limited_by(schedule: PathSchedule, ceilings: ArrayLike) -> tuple[list[str], NDArray[np.int64]]:
    """What holds each move of ``schedule`` below its ceiling.

    A move whose certified peak feed is within :data:`BELOW_CEILING` of its ceiling, and a
    move that takes no time, is held by its ``feed``; otherwise by what fixed the speed at its
    fastest node: an actuator's ``velocity`` or ``acceleration`` limit (a move too short to
    leave rest between two stops counts as acceleration).

    Parameters
    ----------
    schedule : PathSchedule
    ceilings : array_like, shape (M,)
        Each move's feed ceiling, m/s (rad/s for a rotary move); inf: none.

    Returns
    -------
    kinds : list of str, length M
        ``"feed"``, ``"velocity"`` or ``"acceleration"``.
    actuators : ndarray, shape (M,), int
        The limiting actuator, 1-based; 0 for ``feed``.
    """
    ceiling = np.asarray(ceilings, dtype=np.float64)
    count = schedule.t_start.size
    kinds = ["feed"] * count
    actuators = np.zeros(count, dtype=np.int64)
    for k in range(count):
        top = float(ceiling[k])
        if schedule.t_end[k] == schedule.t_start[k] or (
            math.isfinite(top) and schedule.feed_peak[k] >= (1.0 - BELOW_CEILING) * top
        ):
            continue
        nodes = np.flatnonzero(schedule.node_move == k)
        fastest = nodes[np.argmax(schedule.sdot[nodes])]
        kind = LIMIT_KINDS[int(schedule.limit_kind[fastest])]
        kinds[k] = "acceleration" if kind == "rest" else kind
        if kinds[k] != "feed":
            actuators[k] = int(schedule.limit_actuator[fastest]) + 1
    return kinds, actuators


def programmed_duration(schedule: PathSchedule, feeds: ArrayLike, rotary_feed: float) -> float:
    """The time of the path with every move at its programmed feed (no ramps), s.

    Parameters
    ----------
    schedule : PathSchedule
        Its ``length`` and ``rotary`` give each move's length (m) or rotation (rad).
    feeds : array_like, shape (M,)
        Programmed feed of each translating move, m/s (NaN: none).
    rotary_feed : float
        Rotation rate of the moves without translation, rad/s (NaN: none).

    Returns
    -------
    float
        NaN when a move that moves has no feed; moves that do not move take no time.
    """
    programmed = np.where(schedule.rotary, rotary_feed, np.asarray(feeds, dtype=np.float64))
    with np.errstate(invalid="ignore", divide="ignore"):
        times = np.where(schedule.length == 0.0, 0.0, schedule.length / programmed)
    return float(np.sum(times)) if np.all(np.isfinite(times)) else math.nan


@dataclass(frozen=True)
class ScheduleProfiles:
    """A schedule's quantities at its grid nodes (samples for plots and logs; the certified
    bounds are :class:`PathSchedule`'s peaks).

    Attributes
    ----------
    time : ndarray, shape (n,)
        s.
    feed : ndarray, shape (n,)
        |ṗ| of the tool centre point, m/s.
    speed : ndarray, shape (n, 6)
        q̇_i = g_i·ṡ, actuator unit/s.
    accel : ndarray, shape (n, 6)
        q̈_i = g_i'·ṡ² + g_i·s̈ with the s̈ of the interval that starts at the node (the last
        node of a move: of the interval that ends there), actuator unit/s².
    """

    time: NDArray[np.float64]
    feed: NDArray[np.float64]
    speed: NDArray[np.float64]
    accel: NDArray[np.float64]


def schedule_profiles(
    manipulator: Manipulator,
    positions: ArrayLike,
    rotations: ArrayLike,
    schedule: PathSchedule,
    *,
    arcs: ArrayLike | None = None,
    beziers: ArrayLike | None = None,
) -> ScheduleProfiles:
    """Feed, actuator speeds and accelerations at the nodes of ``schedule`` (the path it was
    computed for; g' exact:
    :func:`~hexapod_workspace.core.motions.schedule_bounds.rate_derivatives`)."""
    p = np.asarray(positions, dtype=np.float64)
    r = np.asarray(rotations, dtype=np.float64)
    moves = SlerpMoves(
        manipulator, p[:-1], p[1:], r[:-1], r[1:], _validate_curves(arcs, beziers, p)
    )
    model = ACTUATOR_MODELS[manipulator.architecture]
    move = schedule.node_move
    u = np.clip(schedule.s - move, 0.0, 1.0)
    g, _ = model.evaluate(manipulator, moves.motion(move, u))
    derivative = rate_derivatives(manipulator, moves, move, u)
    linear = moves.dp[move].copy()
    if moves.arcs is not None:
        on = moves.arcs.mask[move]
        if on.any():
            linear[on] = moves.arcs.velocities(move[on], u[on])
    x = schedule.sdot**2
    # s̈ of the interval starting at each node (a move's last node: the one ending there)
    same = np.r_[move[1:] == move[:-1], False]
    width = np.where(same, np.r_[np.diff(schedule.s), 0.0], 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        forward = np.where(
            width > 0.0, np.r_[np.diff(x), 0.0] / (2.0 * np.where(width > 0, width, 1.0)), 0.0
        )
    backward = np.r_[0.0, forward[:-1]]
    sddot = np.where(same, forward, backward)
    return ScheduleProfiles(
        time=schedule.time,
        feed=np.linalg.norm(linear, axis=1) * schedule.sdot,
        speed=g * schedule.sdot[:, None],
        accel=derivative * x[:, None] + g * sddot[:, None],
    )
