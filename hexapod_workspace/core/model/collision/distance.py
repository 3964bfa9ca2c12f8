"""Exact signed distances between convex bodies: closed forms, and GJK on support functions.

Every body is a convex *core* inflated by a radius (the set of points within ``inflation`` of
the core), which covers the four primitive shapes of the collision scene and the moving bodies:

============ ============================== ==================================================
kind         core                           body
============ ============================== ==================================================
``POINT``    the centre                     sphere of radius ``inflation``
``SEGMENT``  centre ± half_length · axis    capsule of radius ``inflation`` (legs, the tool)
``BOX``      the box (half extents)         box (``inflation`` 0)
``CYLINDER`` flat-ended cylinder            cylinder (``inflation`` 0; the platform)
============ ============================== ==================================================

A body is stored as one float64 record of :data:`RECORD_SIZE` values, in the frame the caller
works in (the base frame for the scene): ``[kind, cx, cy, cz, R (9, row-major, local -> frame),
p0, p1, p2, inflation]`` with ``p = (hx, hy, hz)`` half extents for a box, ``(radius,
half_length, 0)`` for a cylinder, ``(half_length, 0, 0)`` for a segment (its axis is column 2 of
``R``, the local z axis; the other columns are not read). Lengths in m.

The signed distance
-------------------
``sd(A, B)`` is the distance between the bodies when they are apart and minus the penetration
depth (the shortest translation that separates them) when they overlap. With ``M = A − B`` the
Minkowski difference,

    sd(A, B) = max over unit d of  min over x in M of d·x,                          (1)

so **every direction d gives a lower bound** ``d·(s_A(−d) − s_B(d))`` (``s`` the support
points), and inflations add: ``sd(A ⊕ r_A, B ⊕ r_B) = sd(A, B) − r_A − r_B``.

* Closed forms (exact to rounding): point and segment cores against each other (Ericson's
  closest points of two segments, degenerate cases included; the Minkowski difference of two
  segments is flat, so their signed distance is their distance), a point against a box and
  against a cylinder (signed: inside, minus the distance to the nearest face), a segment
  against a cylinder whose curved surface holds the closest point (``_segment_cylinder``:
  the distance to the axis minus the radius, exact there), a segment apart from a box
  (``_segment_box``: its ends against the box and the box's 12 edges against it).
* GJK (Gilbert–Johnson–Keerthi) for every other pair (a segment meeting a box, a segment
  against a cylinder's end, box or cylinder against box or cylinder). Each iteration has the
  upper bound ``|v|`` (a point of ``M``) and, by (1) with ``d = v/|v|``, the lower bound
  ``v·w/|v|`` (``w`` the support point of ``M`` in ``−v``).
  The iteration stops when the two are within :data:`GJK_TOLERANCE` (1e-9 m), after
  :data:`GJK_MAX_ITERATIONS`, or when an iteration makes no progress (the closest point of a
  sliver simplex has lost its digits: a few in 10⁵ placements, gaps up to 4e-9 m seen); the
  value returned is the best **lower bound**, so a clearance is never over-stated, and the
  remaining gap (upper − lower) is returned with it. The tests hold every gap to
  :data:`GJK_GAP_BOUND` (1e-8 m).
* Overlapping cores (GJK finds the origin in ``M``): the value is the largest of (1) over the
  candidate axes (box face normals, cylinder axes, cross products of edges and axes, the
  direction between the centres) and over the directions the iterations tried: exact for a
  segment or point against a box (these are all the face normals of ``M``: the
  separating-axis theorem), a lower bound otherwise, raised to the signed distance of two
  capsules that hold the bodies when that is larger, and to a bound the caller passes
  (``floor`` of :func:`_pair`); the upper bound of the cores' distance is then 0 (they
  overlap).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, TypeVar

import numba
import numpy as np
from numpy.typing import NDArray

from ...base.jit import CACHE_DIRECTORY

__all__ = [
    "BOX",
    "CYLINDER",
    "GJK_GAP_BOUND",
    "GJK_MAX_ITERATIONS",
    "GJK_TOLERANCE",
    "KIND_NAMES",
    "POINT",
    "RECORD_SIZE",
    "SEGMENT",
    "pair_distance",
    "pair_distances",
    "record",
]

POINT, SEGMENT, BOX, CYLINDER = 0, 1, 2, 3
KIND_NAMES = ("point", "segment", "box", "cylinder")
RECORD_SIZE = 17
# Offsets in a record.
_KIND, _C, _R, _P, _INFLATION = 0, 1, 4, 13, 16

#: Stopping tolerance of GJK, m: the lower bound returned is within it of the exact distance.
GJK_TOLERANCE = 1e-9
#: Largest gap (upper − lower bound, m) the tests accept from GJK, stagnation included.
GJK_GAP_BOUND = 1e-8
#: Rows of the (WORK_ROWS, 3) working memory of :func:`_pair` (simplex, support points, the
#: tetrahedron's face): callers allocate it once per batch.
WORK_ROWS = 17
#: Iteration cap of GJK (reached only in degenerate numerics; the lower bound stays valid).
GJK_MAX_ITERATIONS = 64

_CACHE = CACHE_DIRECTORY is not None


# numba ships no type information: the decorators are typed as returning the function they
# compile (the Dispatcher is called exactly like it), so mypy checks every call.
_F = TypeVar("_F", bound=Callable[..., Any])


def _jit(function: _F) -> _F:
    """An entry point: nopython mode, releases the GIL, cached on disk when possible."""
    compiled: _F = numba.njit(cache=_CACHE, nogil=True, error_model="numpy")(function)
    return compiled


def _helper(function: _F) -> _F:
    """A function only kernels call (compiled into them)."""
    compiled: _F = numba.njit(nogil=True, error_model="numpy")(function)
    return compiled


def record(
    kind: int,
    centre: NDArray[np.float64],
    rotation: NDArray[np.float64],
    parameters: tuple[float, float, float],
    inflation: float = 0.0,
) -> NDArray[np.float64]:
    """Pack one body into a record.

    Parameters
    ----------
    kind : int
        ``POINT``, ``SEGMENT``, ``BOX`` or ``CYLINDER`` (module constants).
    centre : ndarray, shape (3,)
        Centre of the core in the working frame, m.
    rotation : ndarray, shape (3, 3)
        Local -> working frame (columns are the local axes).
    parameters : tuple of 3 float
        Half extents (box), (radius, half length, 0) (cylinder), (half length, 0, 0) (segment),
        m; unused for a point.
    inflation : float
        Radius added around the core, m (sphere, capsule).

    Returns
    -------
    ndarray, shape (RECORD_SIZE,)
    """
    out = np.zeros(RECORD_SIZE)
    out[_KIND] = kind
    out[_C : _C + 3] = centre
    out[_R : _R + 9] = np.asarray(rotation, dtype=np.float64).ravel()
    out[_P : _P + 3] = parameters
    out[_INFLATION] = inflation
    return out


# ------------------------------------------------------------------------------ helpers
@_helper
def _support(
    body: NDArray[np.float64], dx: float, dy: float, dz: float, out: NDArray[np.float64]
) -> None:
    """Support point of the core of ``body`` in direction d (the point maximising d·x)."""
    kind = int(body[_KIND])
    cx, cy, cz = body[_C], body[_C + 1], body[_C + 2]
    if kind == POINT:
        out[0], out[1], out[2] = cx, cy, cz
        return
    r = body[_R : _R + 9]
    if kind == SEGMENT:
        ax, ay, az = r[2], r[5], r[8]
        h = body[_P] if dx * ax + dy * ay + dz * az >= 0.0 else -body[_P]
        out[0], out[1], out[2] = cx + h * ax, cy + h * ay, cz + h * az
        return
    # Direction in the local frame: Rᵀ d.
    lx = r[0] * dx + r[3] * dy + r[6] * dz
    ly = r[1] * dx + r[4] * dy + r[7] * dz
    lz = r[2] * dx + r[5] * dy + r[8] * dz
    if kind == BOX:
        sx = body[_P] if lx >= 0.0 else -body[_P]
        sy = body[_P + 1] if ly >= 0.0 else -body[_P + 1]
        sz = body[_P + 2] if lz >= 0.0 else -body[_P + 2]
    else:
        radial = math.sqrt(lx * lx + ly * ly)
        if radial > 0.0:
            sx = body[_P] * lx / radial
            sy = body[_P] * ly / radial
        else:
            sx = 0.0
            sy = 0.0
        sz = body[_P + 1] if lz >= 0.0 else -body[_P + 1]
    out[0] = cx + r[0] * sx + r[1] * sy + r[2] * sz
    out[1] = cy + r[3] * sx + r[4] * sy + r[5] * sz
    out[2] = cz + r[6] * sx + r[7] * sy + r[8] * sz


@_helper
def _axis_bound(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    dx: float,
    dy: float,
    dz: float,
    scratch: NDArray[np.float64],
) -> float:
    """min over x in M = A − B of d·x for unit d: a lower bound of sd(cores) by (1)."""
    norm = math.sqrt(dx * dx + dy * dy + dz * dz)
    if not norm > 1e-12:
        return -np.inf
    dx, dy, dz = dx / norm, dy / norm, dz / norm
    _support(a, -dx, -dy, -dz, scratch[0:3])
    _support(b, dx, dy, dz, scratch[3:6])
    return float(
        dx * (scratch[0] - scratch[3])
        + dy * (scratch[1] - scratch[4])
        + dz * (scratch[2] - scratch[5])
    )


@_helper
def _segment_cylinder(segment: NDArray[np.float64], cylinder: NDArray[np.float64]) -> float:
    """Distance from a point or segment core to a cylinder core, in closed form where it is
    exact, else NaN.

    The cylinder lies inside the capsule of its radius r around its axis segment, so
    ``sd ≥ d − r`` with d the distance from the segment to the axis segment. When the closest
    axis point q* is interior (parameter strictly inside (0, 1)), p* − q* is perpendicular to
    the axis (first-order optimality), so ``q* + r (p* − q*)/d`` lies on the curved surface,
    at d − r from p*: then, for d ≥ r, ``sd = d − r`` exactly. Otherwise (an end disc or rim is
    closest, or the cores overlap) NaN, and the caller runs GJK.
    """
    p0x, p0y, p0z, d1x, d1y, d1z = _ends(segment)
    h = cylinder[_P + 1]
    ax, ay, az = cylinder[_R + 2] * h, cylinder[_R + 5] * h, cylinder[_R + 8] * h
    q0x, q0y, q0z = cylinder[_C] - ax, cylinder[_C + 1] - ay, cylinder[_C + 2] - az
    distance, t = _segment_segment_t(
        p0x, p0y, p0z, d1x, d1y, d1z, q0x, q0y, q0z, 2.0 * ax, 2.0 * ay, 2.0 * az
    )
    radius = float(cylinder[_P])
    if 0.0 < t < 1.0 and distance >= radius:
        return float(distance - radius)
    return math.nan


@_helper
def _segment_box(segment: NDArray[np.float64], box: NDArray[np.float64]) -> float:
    """Distance from a segment core to a box core in closed form when they are apart, else NaN.

    In the box's frame: if the segment meets the box (slab test, touching included) NaN, and
    the caller runs GJK. Otherwise the closest pair (x on the segment, y on the box) has x an
    end of the segment (the point–box distance of that end), or y on one of the 12 edges (the
    segment–segment distance to that edge), or y inside a face with x interior; in the last
    case the segment is parallel to the face (x − y is the face normal, orthogonal to the
    segment at an interior minimum), so the distance is constant along the segment while its
    projection stays in the face, and is attained again at an end or where the projection
    crosses an edge. Every candidate is the distance of two points of the bodies (≥ the
    distance), and one of them attains it: the minimum of the 14 is exact.
    """
    p0x, p0y, p0z, d1x, d1y, d1z = _ends(segment)
    r = box[_R : _R + 9]
    x, y, z = p0x - box[_C], p0y - box[_C + 1], p0z - box[_C + 2]
    # Local frame: Rᵀ (p0 − c) and Rᵀ d.
    lx = r[0] * x + r[3] * y + r[6] * z
    ly = r[1] * x + r[4] * y + r[7] * z
    lz = r[2] * x + r[5] * y + r[8] * z
    ux = r[0] * d1x + r[3] * d1y + r[6] * d1z
    uy = r[1] * d1x + r[4] * d1y + r[7] * d1z
    uz = r[2] * d1x + r[5] * d1y + r[8] * d1z
    hx, hy, hz = box[_P], box[_P + 1], box[_P + 2]
    # Slab test on s in [0, 1].
    low, high = 0.0, 1.0
    meets = True
    for p, u, h in ((lx, ux, hx), (ly, uy, hy), (lz, uz, hz)):
        if u == 0.0:
            if abs(p) > h:
                meets = False
        else:
            t1 = (-h - p) / u
            t2 = (h - p) / u
            if t1 > t2:
                t1, t2 = t2, t1
            low = max(low, t1)
            high = min(high, t2)
            if low > high:
                meets = False
    if meets:
        return math.nan
    best = np.inf
    for s in (0.0, 1.0):
        qx = abs(lx + s * ux) - hx
        qy = abs(ly + s * uy) - hy
        qz = abs(lz + s * uz) - hz
        ox, oy, oz = max(qx, 0.0), max(qy, 0.0), max(qz, 0.0)
        best = min(best, math.sqrt(ox * ox + oy * oy + oz * oz))
    for sa in (-1.0, 1.0):
        for sb in (-1.0, 1.0):
            # Edges along x, y and z: the other two coordinates at their ± half extents.
            best = min(
                best,
                _segment_segment(lx, ly, lz, ux, uy, uz, -hx, sa * hy, sb * hz, 2.0 * hx, 0.0, 0.0),
                _segment_segment(lx, ly, lz, ux, uy, uz, sa * hx, -hy, sb * hz, 0.0, 2.0 * hy, 0.0),
                _segment_segment(lx, ly, lz, ux, uy, uz, sa * hx, sb * hy, -hz, 0.0, 0.0, 2.0 * hz),
            )
    return float(best)


@_helper
def _segment_segment(
    p0x: float,
    p0y: float,
    p0z: float,
    d1x: float,
    d1y: float,
    d1z: float,
    q0x: float,
    q0y: float,
    q0z: float,
    d2x: float,
    d2y: float,
    d2z: float,
) -> float:
    """Distance between segments p0 + s·d1 and q0 + t·d2, s, t in [0, 1] (Ericson 5.1.9)."""
    distance, _ = _segment_segment_t(p0x, p0y, p0z, d1x, d1y, d1z, q0x, q0y, q0z, d2x, d2y, d2z)
    return distance


@_helper
def _segment_segment_t(
    p0x: float,
    p0y: float,
    p0z: float,
    d1x: float,
    d1y: float,
    d1z: float,
    q0x: float,
    q0y: float,
    q0z: float,
    d2x: float,
    d2y: float,
    d2z: float,
) -> tuple[float, float]:
    """(distance, t) of segments p0 + s·d1 and q0 + t·d2, s, t in [0, 1] (Ericson 5.1.9), t
    the second segment's parameter of the closest points."""
    rx, ry, rz = p0x - q0x, p0y - q0y, p0z - q0z
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    if a <= 1e-300 and e <= 1e-300:
        s = 0.0
        t = 0.0
    elif a <= 1e-300:
        s = 0.0
        t = min(max(f / e, 0.0), 1.0)
    else:
        c = d1x * rx + d1y * ry + d1z * rz
        if e <= 1e-300:
            t = 0.0
            s = min(max(-c / a, 0.0), 1.0)
        else:
            b = d1x * d2x + d1y * d2y + d1z * d2z
            denom = a * e - b * b
            s = min(max((b * f - c * e) / denom, 0.0), 1.0) if denom > 1e-14 * a * e else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                t = 0.0
                s = min(max(-c / a, 0.0), 1.0)
            elif t > 1.0:
                t = 1.0
                s = min(max((b - c) / a, 0.0), 1.0)
    x = rx + s * d1x - t * d2x
    y = ry + s * d1y - t * d2y
    z = rz + s * d1z - t * d2z
    return math.sqrt(x * x + y * y + z * z), t


@_helper
def _ends(body: NDArray[np.float64]) -> tuple[float, float, float, float, float, float]:
    """First end and direction (end − start) of a point or segment core."""
    if int(body[_KIND]) == POINT:
        return body[_C], body[_C + 1], body[_C + 2], 0.0, 0.0, 0.0
    h = body[_P]
    ax, ay, az = body[_R + 2] * h, body[_R + 5] * h, body[_R + 8] * h
    return (
        body[_C] - ax,
        body[_C + 1] - ay,
        body[_C + 2] - az,
        2.0 * ax,
        2.0 * ay,
        2.0 * az,
    )


@_helper
def _enclosing(body: NDArray[np.float64]) -> tuple[float, float, float, float, float, float, float]:
    """A capsule that holds the body: first end, direction (end − start) and radius, m.
    Its axis is the segment or cylinder axis, or the longest axis of a box."""
    kind = int(body[_KIND])
    if kind <= SEGMENT:
        p0x, p0y, p0z, dx, dy, dz = _ends(body)
        return p0x, p0y, p0z, dx, dy, dz, body[_INFLATION]
    if kind == CYLINDER:
        axis, half, radius = 2, body[_P + 1], body[_P]
    else:
        axis = 0
        if body[_P + 1] > body[_P + axis]:
            axis = 1
        if body[_P + 2] > body[_P + axis]:
            axis = 2
        half = body[_P + axis]
        radius = math.sqrt(
            body[_P] ** 2 + body[_P + 1] ** 2 + body[_P + 2] ** 2 - body[_P + axis] ** 2
        )
    ax = body[_R + axis] * half
    ay = body[_R + 3 + axis] * half
    az = body[_R + 6 + axis] * half
    return (
        body[_C] - ax,
        body[_C + 1] - ay,
        body[_C + 2] - az,
        2.0 * ax,
        2.0 * ay,
        2.0 * az,
        radius,
    )


@_helper
def _capsule_bound(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """A lower bound of sd(a, b), m: the signed distance of capsules that hold them (signed
    distance only decreases when the bodies grow). Exact for spheres and capsules."""
    p0x, p0y, p0z, d1x, d1y, d1z, ra = _enclosing(a)
    q0x, q0y, q0z, d2x, d2y, d2z, rb = _enclosing(b)
    distance = _segment_segment(p0x, p0y, p0z, d1x, d1y, d1z, q0x, q0y, q0z, d2x, d2y, d2z)
    return float(distance - ra - rb)


@_helper
def _point_solid(point_body: NDArray[np.float64], solid: NDArray[np.float64]) -> float:
    """Signed distance from a point core to a box or cylinder core (exact)."""
    r = solid[_R : _R + 9]
    x = point_body[_C] - solid[_C]
    y = point_body[_C + 1] - solid[_C + 1]
    z = point_body[_C + 2] - solid[_C + 2]
    lx = r[0] * x + r[3] * y + r[6] * z
    ly = r[1] * x + r[4] * y + r[7] * z
    lz = r[2] * x + r[5] * y + r[8] * z
    if int(solid[_KIND]) == BOX:
        qx = abs(lx) - solid[_P]
        qy = abs(ly) - solid[_P + 1]
        qz = abs(lz) - solid[_P + 2]
        ox, oy, oz = max(qx, 0.0), max(qy, 0.0), max(qz, 0.0)
        return float(math.sqrt(ox * ox + oy * oy + oz * oz) + min(max(qx, max(qy, qz)), 0.0))
    qr = math.sqrt(lx * lx + ly * ly) - solid[_P]
    qz = abs(lz) - solid[_P + 1]
    orr, oz = max(qr, 0.0), max(qz, 0.0)
    return float(math.sqrt(orr * orr + oz * oz) + min(max(qr, qz), 0.0))


# ------------------------------------------------------------------------------ GJK
@_helper
def _closest_triangle(simplex: NDArray[np.float64], v: NDArray[np.float64]) -> int:
    """Closest point v of triangle simplex[0:3] to the origin; bit mask of the vertices kept
    (Ericson 5.1.5 with p = 0)."""
    a, b, c = simplex[0], simplex[1], simplex[2]
    ab = b - a
    ac = c - a
    d1 = -(ab[0] * a[0] + ab[1] * a[1] + ab[2] * a[2])
    d2 = -(ac[0] * a[0] + ac[1] * a[1] + ac[2] * a[2])
    if d1 <= 0.0 and d2 <= 0.0:
        v[:] = a
        return 1
    d3 = -(ab[0] * b[0] + ab[1] * b[1] + ab[2] * b[2])
    d4 = -(ac[0] * b[0] + ac[1] * b[1] + ac[2] * b[2])
    if d3 >= 0.0 and d4 <= d3:
        v[:] = b
        return 2
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        w = d1 / (d1 - d3)
        v[:] = a + w * ab
        return 3
    d5 = -(ab[0] * c[0] + ab[1] * c[1] + ab[2] * c[2])
    d6 = -(ac[0] * c[0] + ac[1] * c[1] + ac[2] * c[2])
    if d6 >= 0.0 and d5 <= d6:
        v[:] = c
        return 4
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        v[:] = a + w * ac
        return 5
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        v[:] = b + w * (c - b)
        return 6
    denom = 1.0 / (va + vb + vc)
    v[:] = a + ab * (vb * denom) + ac * (vc * denom)
    return 7


@_helper
def _closest_simplex(
    simplex: NDArray[np.float64],
    count: int,
    v: NDArray[np.float64],
    tmp: NDArray[np.float64],
    face: NDArray[np.float64],
    candidate: NDArray[np.float64],
) -> int:
    """Closest point v of the simplex (count vertices) to the origin; reduces the simplex to
    the vertices that support v and returns their count (0: the origin is inside). ``face``
    (3, 3) and ``candidate`` (3,) are working memory (no allocation per call)."""
    if count == 1:
        v[:] = simplex[0]
        return 1
    if count == 2:
        a, b = simplex[0], simplex[1]
        ab = b - a
        denom = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]
        t = -(a[0] * ab[0] + a[1] * ab[1] + a[2] * ab[2]) / denom if denom > 0.0 else 0.0
        if t <= 0.0:
            v[:] = a
            return 1
        if t >= 1.0:
            v[:] = b
            simplex[0] = b
            return 1
        v[:] = a + t * ab
        return 2
    if count == 3:
        mask = _closest_triangle(simplex, v)
        kept = 0
        for k in range(3):
            if mask >> k & 1:
                tmp[kept] = simplex[k]
                kept += 1
        simplex[:kept] = tmp[:kept]
        return kept
    # Tetrahedron: the closest point lies on a face the origin is outside of (or on any face
    # when the tetrahedron is flat); none -> the origin is inside.
    best = np.inf
    best_mask = 0
    best_face = -1
    for opposite in range(4):
        k = 0
        for m in range(4):
            if m != opposite:
                face[k] = simplex[m]
                k += 1
        e1 = face[1] - face[0]
        e2 = face[2] - face[0]
        nx = e1[1] * e2[2] - e1[2] * e2[1]
        ny = e1[2] * e2[0] - e1[0] * e2[2]
        nz = e1[0] * e2[1] - e1[1] * e2[0]
        side_origin = -(nx * face[0, 0] + ny * face[0, 1] + nz * face[0, 2])
        d = simplex[opposite] - face[0]
        side_opposite = nx * d[0] + ny * d[1] + nz * d[2]
        scale = math.sqrt(nx * nx + ny * ny + nz * nz) * (
            abs(face[0, 0]) + abs(face[0, 1]) + abs(face[0, 2]) + abs(d[0]) + abs(d[1]) + abs(d[2])
        )
        flat = abs(side_opposite) <= 1e-12 * scale
        if not flat and side_origin * side_opposite > 0.0:
            continue
        mask = _closest_triangle(face, candidate)
        squared = candidate[0] ** 2 + candidate[1] ** 2 + candidate[2] ** 2
        if squared < best:
            best = squared
            best_mask = mask
            best_face = opposite
            v[:] = candidate
    if best_face < 0:
        v[:] = 0.0
        return 0
    kept = 0
    k = 0
    for m in range(4):
        if m != best_face:
            if best_mask >> k & 1:
                tmp[kept] = simplex[m]
                kept += 1
            k += 1
    simplex[:kept] = tmp[:kept]
    return kept


@_helper
def _gjk(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    work: NDArray[np.float64],
    tolerance: float = GJK_TOLERANCE,
    cutoff: float = np.inf,
) -> tuple[float, float]:
    """(lower, upper) bounds of sd(core A, core B), m; upper − lower ≤ ``tolerance`` unless the
    iteration cap or the numerics stopped it (lower stays a certified bound), or as soon as
    lower > ``cutoff`` (a caller that looks for a minimum below it needs no more). ``work`` is
    (WORK_ROWS, 3) working memory."""
    simplex = work[0:4]
    tmp = work[4:8]
    v = work[8]
    sa = work[9]
    sb = work[10]
    scratch = work[11:13].ravel()
    dx = a[_C] - b[_C]
    dy = a[_C + 1] - b[_C + 1]
    dz = a[_C + 2] - b[_C + 2]
    if dx == 0.0 and dy == 0.0 and dz == 0.0:
        dx = 1.0
    _support(a, -dx, -dy, -dz, sa)
    _support(b, dx, dy, dz, sb)
    simplex[0] = sa - sb
    count = 1
    v[:] = simplex[0]
    lower = -np.inf
    upper = np.inf
    overlap = False
    for _ in range(GJK_MAX_ITERATIONS):
        vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
        vn = math.sqrt(vv)
        upper = min(upper, vn)
        if vn <= 1e-12:
            overlap = True
            break
        _support(a, -v[0], -v[1], -v[2], sa)
        _support(b, v[0], v[1], v[2], sb)
        w = sa - sb
        bound = (v[0] * w[0] + v[1] * w[1] + v[2] * w[2]) / vn
        lower = max(lower, bound)
        if upper - lower <= tolerance or lower > cutoff:
            break
        duplicate = False
        for k in range(count):
            if simplex[k, 0] == w[0] and simplex[k, 1] == w[1] and simplex[k, 2] == w[2]:
                duplicate = True
        if duplicate:
            break
        simplex[count] = w
        count = _closest_simplex(simplex, count + 1, v, tmp, work[13:16], work[16])
        if count == 0:
            overlap = True
            break
        if v[0] * v[0] + v[1] * v[1] + v[2] * v[2] >= vv:
            # No progress: the closest point of a sliver simplex has lost its digits. The lower
            # bound stands; the gap is returned (≤ GJK_GAP_BOUND in the tests).
            break
    if not overlap:
        return lower, upper
    # The cores overlap: the best of the candidate axes in (1) and of the directions the
    # iterations tried (``lower``: each is (1) for its direction, so the value never drops below
    # a bound an earlier stop at ``cutoff`` would have returned); upper bound 0.
    best = lower
    for body in (a, b):
        kind = int(body[_KIND])
        if kind == BOX:
            for col in range(3):
                ex, ey, ez = body[_R + col], body[_R + 3 + col], body[_R + 6 + col]
                best = max(best, _axis_bound(a, b, ex, ey, ez, scratch))
                best = max(best, _axis_bound(a, b, -ex, -ey, -ez, scratch))
        elif kind in (CYLINDER, SEGMENT):
            ex, ey, ez = body[_R + 2], body[_R + 5], body[_R + 8]
            best = max(best, _axis_bound(a, b, ex, ey, ez, scratch))
            best = max(best, _axis_bound(a, b, -ex, -ey, -ez, scratch))
    # Cross products of the axes of the two bodies (edge-edge axes of a box and a segment).
    ka, kb = int(a[_KIND]), int(b[_KIND])
    if ka != POINT and kb != POINT:
        for ca in range(3):
            if ka != BOX and ca != 2:
                continue
            ux, uy, uz = a[_R + ca], a[_R + 3 + ca], a[_R + 6 + ca]
            for cb in range(3):
                if kb != BOX and cb != 2:
                    continue
                wx, wy, wz = b[_R + cb], b[_R + 3 + cb], b[_R + 6 + cb]
                nx = uy * wz - uz * wy
                ny = uz * wx - ux * wz
                nz = ux * wy - uy * wx
                best = max(best, _axis_bound(a, b, nx, ny, nz, scratch))
                best = max(best, _axis_bound(a, b, -nx, -ny, -nz, scratch))
    best = max(best, _axis_bound(a, b, dx, dy, dz, scratch))
    return min(best, 0.0), 0.0


@_helper
def _pair(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    work: NDArray[np.float64],
    tolerance: float = GJK_TOLERANCE,
    cutoff: float = np.inf,
    floor: float = -np.inf,
) -> tuple[float, float]:
    """(signed distance lower bound, gap to the upper bound) of two bodies, m; GJK's
    ``tolerance`` and ``cutoff`` (on the cores' distance: stop once it cannot be below it) as
    in :func:`_gjk`. ``floor`` is a lower bound of sd the caller already holds (a bound from
    bodies that hold these two): where GJK answers, the value is raised to it (it stays a
    certified lower bound, and a caller that skipped pairs by that bound skips exactly the
    pairs whose value could not be the smallest); closed forms ignore it (exact)."""
    ka = int(a[_KIND])
    kb = int(b[_KIND])
    inflation = a[_INFLATION] + b[_INFLATION]
    if ka <= SEGMENT and kb <= SEGMENT:
        p0x, p0y, p0z, d1x, d1y, d1z = _ends(a)
        q0x, q0y, q0z, d2x, d2y, d2z = _ends(b)
        value = _segment_segment(p0x, p0y, p0z, d1x, d1y, d1z, q0x, q0y, q0z, d2x, d2y, d2z)
        return value - inflation, 0.0
    if ka == POINT:
        return _point_solid(a, b) - inflation, 0.0
    if kb == POINT:
        return _point_solid(b, a) - inflation, 0.0
    if ka == SEGMENT or kb == SEGMENT:
        # A segment against a box or a cylinder: the closed form where it holds, else NaN.
        segment, solid = (a, b) if ka == SEGMENT else (b, a)
        if int(solid[_KIND]) == BOX:
            value = _segment_box(segment, solid)
        else:
            value = _segment_cylinder(segment, solid)
        if value == value:
            return value - inflation, 0.0
    lower, upper = _gjk(a, b, work, tolerance, cutoff + inflation)
    # Both are lower bounds of sd; in contact the enclosing capsules' can be the better one
    # (and the scene's pair skipping relies on the value never being below it).
    value = max(lower - inflation, _capsule_bound(a, b), floor)
    return value, max(upper - inflation - value, 0.0)


@_jit
def _pair_batch(
    first: NDArray[np.float64],
    second: NDArray[np.float64],
    distance: NDArray[np.float64],
    gap: NDArray[np.float64],
) -> None:
    work = np.empty((WORK_ROWS, 3))
    for k in range(first.shape[0]):
        distance[k], gap[k] = _pair(first[k], second[k], work)


def pair_distances(
    first: NDArray[np.float64], second: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Signed distances of N pairs of bodies.

    Parameters
    ----------
    first, second : ndarray, shape (N, RECORD_SIZE)
        Body records (:func:`record`) in one frame.

    Returns
    -------
    distance : ndarray, shape (N,)
        Signed distance (negative: penetration depth), m; a certified lower bound within
        ``gap`` of the exact value.
    gap : ndarray, shape (N,)
        Upper bound minus the value, m: 0 for the closed forms, ≤ GJK_TOLERANCE when GJK
        converged (≤ GJK_GAP_BOUND when it stagnated); for overlapping cores, at most
        0 − value (the depth is bounded from below only).
    """
    first = np.ascontiguousarray(first, dtype=np.float64)
    second = np.ascontiguousarray(second, dtype=np.float64)
    if first.ndim != 2 or first.shape[1] != RECORD_SIZE or first.shape != second.shape:
        msg = f"expected two arrays of shape (N, {RECORD_SIZE}), got {first.shape}, {second.shape}"
        raise ValueError(msg)
    distance = np.empty(first.shape[0])
    gap = np.empty(first.shape[0])
    _pair_batch(first, second, distance, gap)
    return distance, gap


def pair_distance(first: NDArray[np.float64], second: NDArray[np.float64]) -> float:
    """Signed distance of two bodies (records), m: see :func:`pair_distances`."""
    distance, _ = pair_distances(first[None, :], second[None, :])
    return float(distance[0])
