"""NX's ``NURBS`` motion in CL files: the spline it states, as cubic Bézier moves.

The record
----------
Siemens NX writes a spline move of the tool tip as ::

    NURBS/
    KNOT/k_1,...,k_12          (as many KNOT statements as needed)
    CNTRL/x,y,z                (K + 2 of them for K knots)

from the current point, with the tool axis unchanged. The record does not state the degree or the
end knots. Read as the **cubic B-spline clamped at both ends whose first control point is the
current point**, with knot vector ``{0, 0, 0, 0, k_1, ..., k_{K-1}, 1, 1, 1, 1}`` (``k_K = 1``
is the end). For degree p a knot vector clamped at both ends around the K − 1 interior values
has (p + 1) + (K − 1) + (p + 1) = K + 2p + 1 knots, and a B-spline of N control points has
N + p + 1 of them; with N = K + 3 (the current point and the K + 2 ``CNTRL`` points) only p = 3
fits. The only other reading the counts allow, a clamped quadratic through the ``CNTRL``
points alone, would leave the current point: in the public NX sample (test/data/cl/SOURCES.md,
five splines of 2 to 51 knots) it starts 0.30 to 9.5 mm away from the tool. Read as above, every
spline of the sample starts at the tool and is parametrised close to the chord length of its
control polygon: each control point's Greville abscissa ``(t_{i+1} + t_{i+2} + t_{i+3}) / 3``
is within 0.003 of its share of the polygon's length on four splines, 0.042 on the fifth (the
test measures it). No document stating NX's convention was found: a record
whose counts do not fit, whose knots decrease or leave (0, 1], or whose knots repeat more than
three times (a break in the curve) is refused with its line.

The moves
---------
The spline is cut into its cubic Bézier spans (Boehm's knot insertion, each interior knot raised
to multiplicity 3): the control points then fall in groups of four sharing their ends, one group
per span. Each span is a move of its own from one span end to the next (a waypoint at each knot),
checked along the curve like an arc
(:mod:`~hexapod_workspace.core.motions.interpolation`: the rate bounds of a Bézier move come
from the convex hulls of its derivatives). The tool axis stays the one in force.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import InputError

__all__ = ["NXSpline", "bezier_spans", "spline_knots"]

#: Knots are written with 7 decimals: the last one is 1 within this.
_KNOT_ROUNDING = 1e-6


@dataclass
class NXSpline:
    """A ``NURBS`` record being read: its line, its knots and control points (file coordinates,
    m) and the point it starts from (file coordinates, m)."""

    line: int
    shown: str
    start: NDArray[np.float64]
    knots: list[float]
    controls: list[NDArray[np.float64]]


def spline_knots(spline: NXSpline) -> NDArray[np.float64]:
    """The full knot vector of a record, shape (K + 7,), checked (see the module documentation).

    Raises
    ------
    InputError
        No knot or no control point, counts that do not fit a clamped cubic from the current
        point, knots outside (0, 1], decreasing, or repeated more than three times.
    """
    where = f"line {spline.line}: {spline.shown}"
    knots, count = spline.knots, len(spline.controls)
    if not knots or not count:
        msg = f"{where}: expected KNOT/... and CNTRL/x,y,z statements after NURBS/, got "
        msg += f"{len(knots)} knot(s) and {count} control point(s)"
        raise InputError(msg)
    if count != len(knots) + 2:
        msg = (
            f"{where}: expected {len(knots) + 2} CNTRL points for {len(knots)} knots (NX's "
            f"clamped cubic from the current point), got {count}"
        )
        raise InputError(msg)
    values = np.array(knots, dtype=np.float64)
    if abs(values[-1] - 1.0) > _KNOT_ROUNDING:
        msg = f"{where}: expected the last knot to be 1, got {values[-1]:.9g}"
        raise InputError(msg)
    values[-1] = 1.0
    if not values[0] > 0.0 or np.any(np.diff(values) < 0.0):
        msg = f"{where}: expected knots increasing in (0, 1], got {_shown_knots(values)}"
        raise InputError(msg)
    interior = values[:-1]
    if interior.size and (interior[-1] >= 1.0 or _multiplicity(interior) > 3):
        msg = (
            f"{where}: a knot repeated more than three times breaks the curve (not modelled), "
            f"got {_shown_knots(values)}"
        )
        raise InputError(msg)
    result: NDArray[np.float64] = np.concatenate([np.zeros(4), interior, np.ones(4)])
    return result


def _multiplicity(values: NDArray[np.float64]) -> int:
    _, counts = np.unique(values, return_counts=True)
    return int(counts.max())


def _shown_knots(values: NDArray[np.float64]) -> str:
    text = ", ".join(f"{v:.7g}" for v in values[:6])
    return text + (", ..." if values.size > 6 else "")


def bezier_spans(knots: NDArray[np.float64], controls: NDArray[np.float64]) -> NDArray[np.float64]:
    """The cubic Bézier spans of a clamped cubic B-spline.

    Each interior knot is inserted (Boehm) until its multiplicity is 3; the control points then
    fall in groups of four sharing their ends, one group per span of non-zero length.

    Parameters
    ----------
    knots : ndarray, shape (n + 5,)
        Clamped knot vector (four 0s, interior knots, four 1s).
    controls : ndarray, shape (n + 1, 3)
        Control points, m.

    Returns
    -------
    ndarray, shape (S, 4, 3)
        The Bézier control points of each of the S spans, in order.
    """
    t = [float(v) for v in knots]
    points = [np.asarray(p, dtype=np.float64) for p in controls]
    for value in sorted(set(t[4:-4])):
        while t.count(value) < 3:
            # insert `value` once: the span k with t[k] <= value < t[k + 1]
            k = max(i for i in range(len(t) - 1) if t[i] <= value < t[i + 1])
            new = []
            for i in range(k - 2, k + 1):
                alpha = (value - t[i]) / (t[i + 3] - t[i])
                new.append((1.0 - alpha) * points[i - 1] + alpha * points[i])
            points = [*points[: k - 2], *new, *points[k:]]
            t.insert(k + 1, value)
    array = np.array(points, dtype=np.float64)
    spans = (array.shape[0] - 1) // 3
    result: NDArray[np.float64] = np.stack([array[3 * s : 3 * s + 4] for s in range(spans)])
    return result
