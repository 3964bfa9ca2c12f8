"""Compiled dynamic programmes of the torsion planner (numba).

:class:`hexapod_workspace.core.motions.planner._Planner` searches waypoints × torsion grid; its
tables are banded, shape (M, G, B) for M = N − 1 moves, G grid torsions and B torsion changes
per move: ``status`` (:data:`NO`, :data:`KNOWN`, :data:`UNKNOWN`), ``value`` (integer margin levels;
for unknown moves the optimistic level of their smaller end margin) and ``dest[g, b]`` (the
torsion that offset b leads to from g). Without a torsion limit B = G, and these programmes
run over G² pairs per move after every batch of certified checks; in numpy each pass over
1,000 waypoints took ≈ 30 ms, compiled it takes a few.

Each kernel computes exactly what the numpy programme it replaces computed (integer max-min
over the same moves; the min-sum programme adds in the same order and breaks ties on the
first offset, as ``np.argmin``): the plans are identical. ``test/test_paths_planner.py`` keeps
the numpy programmes as the oracle and compares them on seeded random tables.

The kernels are cached on disk next to those of :mod:`hexapod_workspace.core.kernels` (same
cache directory, set up when that module is imported).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar, cast

import numpy as np
from numpy.typing import NDArray

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import CACHE_DIRECTORY

# isort: split
import numba

__all__ = [
    "KNOWN",
    "NO",
    "NONE",
    "UNKNOWN",
    "backward",
    "candidates",
    "forward",
    "smoothest",
    "warm_up",
]

#: Level code of "no move" (infeasible or not allowed) in the integer tables.
NONE = int(np.iinfo(np.int32).min)
#: Move status: no move, value known, not yet checked (optimistic value).
NO, KNOWN, UNKNOWN = 0, 1, 2

_Function = TypeVar("_Function", bound=Callable[..., Any])


def _jit(function: _Function) -> _Function:
    """Nopython mode, releases the GIL, cached on disk when a cache directory is writable."""
    compiled = numba.njit(cache=CACHE_DIRECTORY is not None, nogil=True)(function)
    return cast(_Function, compiled)


@_jit
def forward(
    start: NDArray[np.int32],
    status: NDArray[np.uint8],
    value: NDArray[np.int32],
    dest: NDArray[np.int64],
    optimistic: bool,
    reach: NDArray[np.int32],
) -> None:
    """Bottleneck value of the best path from waypoint 0 to every state, in place.

    Parameters
    ----------
    start : ndarray, shape (G,), int32
        Levels of the torsions at waypoint 0 (:data:`NONE`: unreachable).
    status, value : ndarray, shape (M, G, B)
        Move tables (uint8, int32).
    dest : ndarray, shape (G, B), int64
        Target torsion of offset b from torsion g.
    optimistic : bool
        Count unknown moves at their optimistic value (else only known moves).
    reach : ndarray, shape (M + 1, G), int32
        Output: ``reach[k + 1, h] = max over (g, b) → h of min(reach[k, g], value[k, g, b])``
        over the usable moves, :data:`NONE` where no path arrives.
    """
    steps, size, width = status.shape
    for g in range(size):
        reach[0, g] = start[g]
    for k in range(steps):
        for h in range(size):
            reach[k + 1, h] = NONE
        for g in range(size):
            here = reach[k, g]
            if here == NONE:
                continue  # min(NONE, ·) = NONE never raises a maximum
            for b in range(width):
                state = status[k, g, b]
                if state == NO or (state == UNKNOWN and not optimistic):
                    continue
                through = min(here, value[k, g, b])
                h = dest[g, b]
                if through > reach[k + 1, h]:
                    reach[k + 1, h] = through


@_jit
def backward(
    levels: NDArray[np.int32],
    status: NDArray[np.uint8],
    value: NDArray[np.int32],
    dest: NDArray[np.int64],
    back: NDArray[np.int32],
) -> None:
    """Optimistic bottleneck value of the best path from every state to the end, in place.

    ``back[-1] = levels[-1]`` and
    ``back[k, g] = max over b of min(value[k, g, b], back[k + 1, dest[g, b]])`` over the moves
    whose status is not :data:`NO`; ``levels`` (M + 1, G) are the waypoint levels
    (:data:`NONE`: torsion unreachable, and then every move from it is :data:`NO`, so its row
    is skipped); other shapes as :func:`forward`.
    """
    steps, size, width = status.shape
    for g in range(size):
        back[steps, g] = levels[steps, g]
    for k in range(steps - 1, -1, -1):
        for g in range(size):
            best = NONE
            if levels[k, g] != NONE:
                for b in range(width):
                    if status[k, g, b] == NO:
                        continue
                    through = min(value[k, g, b], back[k + 1, dest[g, b]])
                    if through > best:
                        best = through
            back[k, g] = best


@_jit
def candidates(
    reach: NDArray[np.int32],
    back: NDArray[np.int32],
    status: NDArray[np.uint8],
    value: NDArray[np.int32],
    dest: NDArray[np.int64],
    best: int,
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int32]]:
    """The unknown moves on an optimistic path better than ``best``, in C order of (k, g, b).

    The optimistic bottleneck through move (k, g, b) is
    ``min(reach[k, g], value[k, g, b], back[k + 1, dest[g, b]])`` (``reach`` from
    :func:`forward` with ``optimistic``, ``back`` from :func:`backward`). Returns k, g, b
    (int64) and that bottleneck (int32) of every unknown move where it exceeds ``best``.
    """
    steps, size, width = status.shape
    count = 0
    for k in range(steps):
        for g in range(size):
            here = reach[k, g]
            if here <= best:
                continue
            for b in range(width):
                if status[k, g, b] != UNKNOWN or value[k, g, b] <= best:
                    continue
                if back[k + 1, dest[g, b]] > best:
                    count += 1
    moves_k = np.empty(count, dtype=np.int64)
    moves_g = np.empty(count, dtype=np.int64)
    moves_b = np.empty(count, dtype=np.int64)
    through = np.empty(count, dtype=np.int32)
    n = 0
    for k in range(steps):
        for g in range(size):
            here = reach[k, g]
            if here <= best:
                continue
            for b in range(width):
                if status[k, g, b] != UNKNOWN or value[k, g, b] <= best:
                    continue
                ahead = back[k + 1, dest[g, b]]
                if ahead > best:
                    moves_k[n], moves_g[n], moves_b[n] = k, g, b
                    through[n] = min(here, value[k, g, b], ahead)
                    n += 1
    return moves_k, moves_g, moves_b, through


@_jit
def smoothest(
    start: NDArray[np.int32],
    status: NDArray[np.uint8],
    value: NDArray[np.int32],
    dest: NDArray[np.int64],
    travel: NDArray[np.float64],
    best: int,
    scale: float,
) -> NDArray[np.int64]:
    """Min-sum programme over the known moves at level ``best`` or above: grid index per
    waypoint (M + 1,) of the path of least ``Σ (−level · scale + travel)``.

    Parameters
    ----------
    start : ndarray, shape (G,), int32
        Levels at waypoint 0; the path starts where they reach ``best``.
    status, value : ndarray, shape (M, G, B)
    dest : ndarray, shape (G, B), int64
    travel : ndarray, shape (B,)
        |Δψ| of each offset, rad.
    best : int
        The bottleneck optimum (level).
    scale : float
        Weight of one level against travel (larger than any total travel).

    Notes
    -----
    The cost of arriving at h by offset b is ``(cost[g] + step) + travel[b]`` with
    ``step = −float(level)·scale`` (+inf for a move that is not usable), added in this order;
    per h the first offset b of least cost wins, then the first torsion of least total cost:
    exactly the numpy programme's ``np.argmin`` choices, so equal plans come out. Only usable
    moves from finite costs are visited (the others cost +inf: they win only where every
    offset does, and then offset 0 wins, which is the initial choice).
    """
    steps, size, width = status.shape
    cost = np.empty(size)
    for g in range(size):
        cost[g] = 0.0 if start[g] >= best else np.inf
    arrived = np.empty(size)
    offset = np.empty(size, dtype=np.int64)
    came_from = np.empty((steps, size), dtype=np.int64)
    for k in range(steps):
        for h in range(size):
            arrived[h] = np.inf
            offset[h] = 0
            came_from[k, h] = (h - dest[0, 0]) % size  # the torsion offset 0 comes from
        for g in range(size):
            if cost[g] == np.inf:
                continue
            for b in range(width):
                level = value[k, g, b]
                if status[k, g, b] != KNOWN or level < best:
                    continue
                total = (cost[g] + (-np.float64(level) * scale)) + travel[b]
                h = dest[g, b]
                if total < arrived[h] or (total == arrived[h] and b < offset[h]):
                    arrived[h] = total
                    offset[h] = b
                    came_from[k, h] = g
        for h in range(size):
            cost[h] = arrived[h]
    index = 0
    for g in range(1, size):
        if cost[g] < cost[index]:
            index = g
    path = np.empty(steps + 1, dtype=np.int64)
    path[steps] = index
    for k in range(steps - 1, -1, -1):
        index = came_from[k, index]
        path[k] = index
    return path


def warm_up() -> None:
    """Compile (or load from the cache) every kernel of this module on a tiny problem of the
    argument types the planner uses."""
    status = np.full((1, 2, 2), KNOWN, dtype=np.uint8)
    value = np.zeros((1, 2, 2), dtype=np.int32)
    dest = np.array([[0, 1], [1, 0]], dtype=np.int64)
    levels = np.zeros(2, dtype=np.int32)
    table = np.empty((2, 2), dtype=np.int32)
    forward(levels, status, value, dest, True, table)
    back = np.empty((2, 2), dtype=np.int32)
    backward(table, status, value, dest, back)
    candidates(table, back, status, value, dest, -1)
    smoothest(levels, status, value, dest, np.zeros(2), 0, 4.0)
