"""The torsion planner's dynamic programmes in numpy: the oracle of the compiled ones.

These are the programmes :class:`hexapod_workspace.core.motions.planner._Planner` ran before they
were compiled (:mod:`hexapod_workspace.core.kernels.planner`), kept verbatim: the tests compare the
kernels with them on seeded random tables, and ``benchmarks/paths.py`` times the planner with
them in the same run. :func:`numpy_planner` swaps them into ``plan_torsion`` for a block.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from hexapod_workspace.core.kernels.planner import KNOWN, NO, NONE, UNKNOWN
from hexapod_workspace.core.motions import planner as paths


def forward(levels0, status, value, source, offsets: int, optimistic: bool) -> NDArray[np.int32]:
    """Bottleneck value (N, G) of the best path from waypoint 0 to each state."""
    steps = status.shape[0]
    reach = np.empty((steps + 1, levels0.shape[0]), dtype=np.int32)
    reach[0] = levels0
    usable = (status != NO) if optimistic else (status == KNOWN)
    values = np.where(usable, value, NONE)
    gather = (source * offsets + np.arange(offsets)).ravel()
    through = np.empty(values.shape[1:], dtype=np.int32)
    for k in range(steps):
        np.minimum(reach[k][:, None], values[k], out=through)  # (G, B) by source g
        reach[k + 1] = np.take(through, gather).reshape(through.shape).max(axis=1)
    return reach


def backward(levels_last, status, value, dest) -> NDArray[np.int32]:
    """Optimistic bottleneck value (N, G) of the best path from each state to the end."""
    steps = status.shape[0]
    back = np.empty((steps + 1, levels_last.shape[0]), dtype=np.int32)
    back[-1] = levels_last
    values = np.where(status != NO, value, NONE)
    flat = dest.ravel()
    for k in range(steps - 1, -1, -1):
        ahead = np.take(back[k + 1], flat).reshape(dest.shape)
        back[k] = np.minimum(values[k], ahead).max(axis=1)
    return back


def candidates(reach, back, status, value, dest, best: int, batch: int):
    """The batch of unknown moves to check next: k, g, b (best optimistic bottleneck first)."""
    through = np.minimum(reach[:-1, :, None], value)
    np.minimum(through, back[1:][:, dest], out=through)
    relevant = (status == UNKNOWN) & (through > best)
    k, g, b = np.nonzero(relevant)
    if k.size > batch:
        top = np.argsort(-through[k, g, b], kind="stable")[:batch]
        k, g, b = k[top], g[top], b[top]
    return k, g, b, through


def smoothest(levels0, status, value, source, travel, best: int) -> NDArray[np.int64]:
    """Grid index per waypoint of the min-sum programme at level ``best``."""
    size, width = source.shape
    columns = np.arange(width)
    scale = float(status.shape[0] + 1) * 4.0
    cost = np.where(levels0 >= best, 0.0, np.inf)
    back = []
    usable = (status == KNOWN) & (value >= best)
    step_cost = np.where(usable, -value.astype(np.float64) * scale, np.inf)
    for k in range(status.shape[0]):
        total = (cost[:, None] + step_cost[k] + travel)[source, columns]
        choice = np.argmin(total, axis=1)  # offset index per target h
        cost = total[np.arange(size), choice]
        back.append(source[np.arange(size), choice])
    index = int(np.argmin(cost))
    path = [index]
    for came_from in reversed(back):
        index = int(came_from[index])
        path.append(index)
    return np.array(path[::-1])


class NumpyPlanner(paths._Planner):
    """The planner with the numpy programmes (as before they were compiled)."""

    @property
    def source(self) -> NDArray[np.int64]:
        """source[h, b]: the torsion g that reaches h by offset b."""
        size = self.grid_size
        return (np.arange(size)[:, None] - self.offsets[None, :]) % size

    def _forward(self, optimistic: bool) -> NDArray[np.int32]:
        return forward(
            self.levels[0], self.status, self.value, self.source, self.offsets.size, optimistic
        )

    def _backward(self) -> NDArray[np.int32]:
        return backward(self.levels[-1], self.status, self.value, self.dest)

    def solve(self):
        while True:
            best = int(self._forward(optimistic=False)[-1].max())
            k, g, b, _ = candidates(
                self._forward(optimistic=True),
                self._backward(),
                self.status,
                self.value,
                self.dest,
                best,
                paths.CHECK_BATCH,
            )
            if k.size == 0:
                break
            self._check(k, g, b)
        if best == NONE:
            return None, -math.inf, self._breakpoint()
        path = smoothest(self.levels[0], self.status, self.value, self.source, self.travel, best)
        return self.grid[path], best * self.resolution, None


@contextlib.contextmanager
def numpy_planner() -> Iterator[None]:
    """Within the block, ``plan_torsion`` plans with the numpy programmes."""
    compiled = paths._Planner
    paths._Planner = NumpyPlanner
    try:
        yield
    finally:
        paths._Planner = compiled
