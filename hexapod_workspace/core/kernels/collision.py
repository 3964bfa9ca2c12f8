"""The ``collision`` margin inside the compiled kernels: per-pose evaluation of the packed scene.

:func:`~hexapod_workspace.core.kernels.scene_layout.pack_scene` appends the model's collision
scene to the packed model vector of :mod:`hexapod_workspace.core.kernels.layout` (a block after
``MODEL_SIZE``, offsets in :mod:`~hexapod_workspace.core.kernels.scene_layout`);
:func:`collision_margin` evaluates the margin of one pose from the leg vectors the margin
kernels have already computed, and is called from one spot of the scalar pose kernel
(:mod:`hexapod_workspace.core.kernels.pose`) and one of the block kernel
(:mod:`hexapod_workspace.core.kernels.blocks`).

Bodies and pairs are those of :mod:`hexapod_workspace.core.model.collision.scene` (same pair order,
same names, same signed distances of :mod:`hexapod_workspace.core.model.collision.distance`):
``test/test_collision_wiring.py`` compares the two implementations and both with coal.

Leg bodies come from the leg vectors
------------------------------------
Leg k runs from its base-side joint ``A_k = B_k − L_k`` to ``B_k = p + R·b_k``, where
``L_k`` is the leg vector of the kernels' scratch (planes ``lx, ly, lz``). Taking A_k from the
leg vector rather than from the fixed base joint keeps this kernel right for leg architectures
whose base-side joint moves (a prismatic or revolute actuator at the base). *Rate bound*: the
derivation of :mod:`hexapod_workspace.core.model.collision.scene` (legs point 2) uses that A_k
stands still, so that a leg point moves at most at |Ḃ_k|; for a moving base-side joint the leg
body's rate bound must add that joint's speed (the leg point moves at
``(1 − λ)|Ȧ_k| + λ|Ḃ_k|``), and the ``collision`` row's coefficients must include it. For 6-UPS
(A_k fixed) the derivation holds as written.

Cost: a broad phase that keeps the margin exact
-----------------------------------------------
Per pose the moving bodies are first reduced to capsules around their axes (a leg's segment, the
tool's, the platform cylinder's axis with its radius: each holds its body), and the obstacles
(fixed) carry, packed once, a sphere that holds each and the capsule that holds it
(``_obstacle_entry``). Two lower bounds of a pair's signed distance follow by inclusion
(sd only decreases when the bodies grow; the sd of a sphere and a capsule, or of two capsules,
is a distance of segments minus the radii):

1. *first bound*, a few flops and one square root: the obstacle's sphere (for the tool against a
   leg, the tool's sphere) against the moving body's capsule, a point-to-segment distance;
2. *capsule bound* (boxes, cylinders and the platform only, whose exact value costs fourteen
   closed forms or GJK): the two capsules, a segment-to-segment distance.

Every pair's first bound is computed; the pair with the smallest is evaluated exactly first
(usually the closest one), then the others in index order, each only while its bounds can still
beat the best (value, index) found: a lower value, or the same at a lower index. GJK stops once
its own bound is above the best by more than rounding. Each bound is lowered by
:data:`BOUND_SLACK` (1e-9 m) before it is compared, so rounding (~1e-15 m here) never lets a
bound pass the value it bounds, and GJK's value is raised to the pair's first bound (still a
lower bound of sd; the overlap case keeps the best direction GJK tried): so every skipped pair's
value, had it been computed, would lose to the one chosen, and the result (value, pair, gap) is
that of the evaluation of every pair in index order, bit for bit (``collision_margin(...,
pruned=False)``; ``test/test_collision_broadphase.py``). The certified steps of the ray
searches, the torsion scan and the move certificate read that value and its rate bound only,
not how it was found: the pruning leaves their guarantees as they were.
No allocation per call: the working memory is part of the kernels' scratch
(:data:`SCRATCH_FLOATS` floats after the leg planes; the first bounds of up to
:data:`KEPT_BOUNDS` pairs are kept between the two passes, beyond that recomputed).

Exactness
---------
Closed forms are exact to rounding; GJK returns a certified lower bound within 1e-9 m of the
signed distance (:mod:`hexapod_workspace.core.model.collision.distance`). When the cores overlap
(deep contact with a box or cylinder) the value is only a lower bound of the penetration depth;
the gap to the upper bound is returned with it, so that a step that assumes the margin cannot
recover faster than its rate (``kernels.steps.recovery_step``) starts from ``value + gap``,
which is an upper bound of the true margin.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import helper as _helper
from ..base.jit import jit as _jit

# isort: split
import numpy as np
from numpy.typing import NDArray

from ..model.collision.distance import (
    _C,
    _INFLATION,
    _P,
    _R,
    CYLINDER,
    RECORD_SIZE,
    SEGMENT,
    WORK_ROWS,
    _pair,
    _segment_segment,
)
from .scene_layout import (
    _AXES,
    _AXIS_STRIDE,
    _BODIES,
    _BUILT,
    _CAPSULE,
    _ELONGATED,
    _FIRST,
    _FIRST_OBSTACLE,
    _GAPS,
    _KEPT,
    _KEYS,
    _PLATFORM,
    _REFINE,
    _REFINED,
    _SPHERE,
    _STATE,
    _TOOL,
    _VALUE,
    _WORK,
    BOUND_SLACK,
    CLEARANCE,
    GJK_KERNEL_TOLERANCE,
    KEPT_BOUNDS,
    LEG_RADIUS,
    N_OBSTACLES,
    N_PAIRS,
    OBSTACLE_STRIDE,
    OBSTACLES,
    PLATFORM_ON,
    PLATFORM_RECORD,
    SCRATCH_FLOATS,
    TOOL_ENDS,
    TOOL_ON,
    TOOL_RADIUS,
)

if TYPE_CHECKING:
    pass

__all__ = ["collision_margin", "collision_margins"]


# ------------------------------------------------------------------------------ kernel
@_helper
def _segment_body(
    row: NDArray[np.float64],
    ax: float,
    ay: float,
    az: float,
    bx: float,
    by: float,
    bz: float,
    radius: float,
) -> None:
    """Capsule of ``radius`` around segment ab into a record (zero axis for a point)."""
    dx, dy, dz = bx - ax, by - ay, bz - az
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    row[0] = SEGMENT
    row[_C] = 0.5 * (ax + bx)
    row[_C + 1] = 0.5 * (ay + by)
    row[_C + 2] = 0.5 * (az + bz)
    inverse = 1.0 / length if length > 0.0 else 0.0
    row[_R + 2] = dx * inverse
    row[_R + 5] = dy * inverse
    row[_R + 8] = dz * inverse
    row[_P] = 0.5 * length
    row[_INFLATION] = radius


@_helper
def _set_axis(
    memory: NDArray[np.float64],
    body: int,
    ax: float,
    ay: float,
    az: float,
    bx: float,
    by: float,
    bz: float,
    radius: float,
) -> None:
    """The broad phase's view of a moving body: a capsule of ``radius`` around segment ab."""
    at = _AXES + _AXIS_STRIDE * body
    dx, dy, dz = bx - ax, by - ay, bz - az
    squared = dx * dx + dy * dy + dz * dz
    memory[at] = ax
    memory[at + 1] = ay
    memory[at + 2] = az
    memory[at + 3] = dx
    memory[at + 4] = dy
    memory[at + 5] = dz
    memory[at + 6] = 1.0 / squared if squared > 0.0 else 0.0
    memory[at + 7] = radius


@_helper
def _sphere_bound(
    memory: NDArray[np.float64], body: int, sphere: NDArray[np.float64], s: int
) -> float:
    """Signed distance of the capsule around moving body ``body``'s axis and the sphere
    (centre, radius) = sphere[s : s + 4], m: a lower bound of the pair's sd (both hold the
    bodies). Offsets, not views, are passed: a view costs reference counting per call."""
    at = _AXES + _AXIS_STRIDE * body
    ax, ay, az = memory[at], memory[at + 1], memory[at + 2]
    dx, dy, dz = memory[at + 3], memory[at + 4], memory[at + 5]
    wx, wy, wz = sphere[s] - ax, sphere[s + 1] - ay, sphere[s + 2] - az
    t = (wx * dx + wy * dy + wz * dz) * memory[at + 6]
    t = min(max(t, 0.0), 1.0)
    ex, ey, ez = wx - t * dx, wy - t * dy, wz - t * dz
    return float(math.sqrt(ex * ex + ey * ey + ez * ez) - sphere[s + 3] - memory[at + 7])


@_helper
def _capsule_pair_bound(
    memory: NDArray[np.float64], body: int, capsule: NDArray[np.float64], c: int, radius: float
) -> float:
    """Signed distance of the capsule around moving body ``body``'s axis and the capsule of
    ``radius`` around segment (first end, direction) = capsule[c : c + 6], m: a lower bound of
    the pair's sd."""
    at = _AXES + _AXIS_STRIDE * body
    distance = _segment_segment(
        memory[at],
        memory[at + 1],
        memory[at + 2],
        memory[at + 3],
        memory[at + 4],
        memory[at + 5],
        capsule[c],
        capsule[c + 1],
        capsule[c + 2],
        capsule[c + 3],
        capsule[c + 4],
        capsule[c + 5],
    )
    return float(distance - memory[at + 7] - radius)


@_helper
def _first_bound(
    model: NDArray[np.float64],
    block: int,
    memory: NDArray[np.float64],
    moving: int,
    other: int,
) -> float:
    """The pair's first broad-phase bound, lowered by BOUND_SLACK: the obstacle's sphere against
    the moving body's capsule, or for an elongated obstacle the two capsules; the tool against
    a leg, the two capsules (their distance, the exact value up to rounding)."""
    if other < _FIRST_OBSTACLE:
        at = _AXES + _AXIS_STRIDE * other
        bound = _capsule_pair_bound(memory, moving, memory, at, memory[at + 7])
    else:
        at = block + OBSTACLES + OBSTACLE_STRIDE * (other - _FIRST_OBSTACLE)
        if model[at + _ELONGATED] != 0.0:
            bound = _capsule_pair_bound(
                memory, moving, model, at + _CAPSULE, model[at + _CAPSULE + 6]
            )
        else:
            bound = _sphere_bound(memory, moving, model, at + _SPHERE)
    return bound - BOUND_SLACK


@_helper
def _refined_bound(
    model: NDArray[np.float64],
    block: int,
    memory: NDArray[np.float64],
    moving: int,
    other: int,
) -> float:
    """The pair's capsule bound (two capsules), lowered by BOUND_SLACK, where the exact value
    is costly (a box, a cylinder, the platform); −inf elsewhere (the exact value is as cheap)."""
    if other < _FIRST_OBSTACLE:
        return -np.inf
    at = block + OBSTACLES + OBSTACLE_STRIDE * (other - _FIRST_OBSTACLE)
    if model[at + _ELONGATED] != 0.0 or (model[at + _REFINE] == 0.0 and moving != _PLATFORM):
        return -np.inf
    radius = model[at + _CAPSULE + 6]
    return _capsule_pair_bound(memory, moving, model, at + _CAPSULE, radius) - BOUND_SLACK


@_helper
def _best_first(
    model: NDArray[np.float64],
    block: int,
    r: NDArray[np.float64],
    px: float,
    py: float,
    pz: float,
    memory: NDArray[np.float64],
    bodies: NDArray[np.float64],
    work: NDArray[np.float64],
    pairs_at: int,
    n_pairs: int,
    clearance: float,
) -> tuple[float, float, float]:
    """:func:`collision_margin` for at most KEPT_BOUNDS pairs: pairs visited in the order of
    their bounds (module docstring, "Cost").

    Each pair holds a key, a lower bound of its value: the first bound, raised to the capsule
    bound once refined, then its value. The pair of the smallest (key, index) is taken: a
    first bound is refined where a capsule bound exists, a bound is replaced by the value,
    and a value ends the search (every other pair's value is at least its key: higher, or the
    same at a higher index, so it loses). GJK may stop once it passes the next smallest key
    by 2·BOUND_SLACK; its value then stands as the pair's key (a lower bound of its full value,
    which is never below what an earlier stop returned), marked to be evaluated again if taken.
    """
    first = memory[_KEPT : _KEPT + KEPT_BOUNDS]
    key = memory[_KEYS : _KEYS + KEPT_BOUNDS]
    state = memory[_STATE : _STATE + KEPT_BOUNDS]
    gaps = memory[_GAPS : _GAPS + KEPT_BOUNDS]
    for k in range(n_pairs):
        bound = _first_bound(
            model, block, memory, int(model[pairs_at + 2 * k]), int(model[pairs_at + 2 * k + 1])
        )
        first[k] = bound
        key[k] = bound
        state[k] = _FIRST
    while True:
        k = 0
        second = np.inf
        for j in range(1, n_pairs):
            if key[j] < key[k]:
                second = key[k]
                k = j
            elif key[j] < second:
                second = key[j]
        if state[k] == _VALUE:
            return key[k] - clearance, float(k), gaps[k]
        moving = int(model[pairs_at + 2 * k])
        other = int(model[pairs_at + 2 * k + 1])
        if state[k] == _FIRST:
            state[k] = _REFINED
            refined = _refined_bound(model, block, memory, moving, other)
            if refined > key[k]:
                key[k] = refined
                continue
        value, gap = _exact(
            model,
            block,
            r,
            px,
            py,
            pz,
            memory,
            bodies,
            work,
            moving,
            other,
            first[k],
            second + 2.0 * BOUND_SLACK,
        )
        if value != value:  # a NaN value wins (the leg planes were finite: not expected)
            return value, float(k), gap
        key[k] = value
        gaps[k] = gap
        # At most second + BOUND_SLACK, GJK ran to its tolerance (an early stop returns more).
        state[k] = _VALUE if value <= second + BOUND_SLACK else _REFINED


@_helper
def _exact(
    model: NDArray[np.float64],
    block: int,
    r: NDArray[np.float64],
    px: float,
    py: float,
    pz: float,
    memory: NDArray[np.float64],
    bodies: NDArray[np.float64],
    work: NDArray[np.float64],
    moving: int,
    other: int,
    floor: float,
    cutoff: float,
) -> tuple[float, float]:
    """(value, gap) of one pair by :func:`.collision.distance._pair`: the moving body's record
    is filled on first use at this pose; ``floor`` is the pair's first bound (GJK's answer is
    raised to it), ``cutoff`` GJK's early stop; ``bodies`` (9, RECORD_SIZE) and ``work``
    (WORK_ROWS, 3) are views of ``memory``, made once per pose (a reshape costs)."""
    for body in (moving, other):
        if body < _FIRST_OBSTACLE and memory[_BUILT + body] == 0.0:
            memory[_BUILT + body] = 1.0
            if body == _PLATFORM:
                _platform_body(model, block, r, px, py, pz, bodies[_PLATFORM])
            else:
                at = _AXES + _AXIS_STRIDE * body
                ax, ay, az = memory[at], memory[at + 1], memory[at + 2]
                _segment_body(
                    bodies[body],
                    ax,
                    ay,
                    az,
                    ax + memory[at + 3],
                    ay + memory[at + 4],
                    az + memory[at + 5],
                    memory[at + 7],
                )
    second = bodies[other if other < _FIRST_OBSTACLE else 8]
    if other >= _FIRST_OBSTACLE:
        at = block + OBSTACLES + OBSTACLE_STRIDE * (other - _FIRST_OBSTACLE)
        for i in range(RECORD_SIZE):
            second[i] = model[at + i]
    return _pair(bodies[moving], second, work, GJK_KERNEL_TOLERANCE, cutoff, floor)


@_helper
def collision_margin(
    model: NDArray[np.float64],
    block: int,
    joints: int,
    r: NDArray[np.float64],
    px: float,
    py: float,
    pz: float,
    lx: NDArray[np.float64],
    ly: NDArray[np.float64],
    lz: NDArray[np.float64],
    memory: NDArray[np.float64],
    pruned: bool = True,
) -> tuple[float, float, float]:
    """The ``collision`` margin of one pose.

    Parameters
    ----------
    model : ndarray
        The packed model; its collision block starts at ``block``, the platform joints b_k
        (mobile frame, leg-major) at ``joints`` (``kernels.layout.B``).
    r : ndarray, shape (9,)
        Rotation (mobile -> base frame), row-major.
    px, py, pz : float
        Position of the mobile frame's origin (the tool centre point), base frame, m.
    lx, ly, lz : ndarray, shape (6,)
        Leg vectors L_k = B_k − A_k, base frame, m.
    memory : ndarray, shape (≥ SCRATCH_FLOATS,)
        Working memory.
    pruned : bool
        Skip the pairs the broad phase proves cannot give the margin (the kernels always do);
        False evaluates every pair (the reference the tests compare with: same result).

    Returns
    -------
    margin : float
        Smallest signed distance over the pairs minus the clearance, m (+inf without pairs).
    pair : float
        Index of that pair in the scene's pair table (−1.0 without pairs), the lowest index
        among pairs of the same value.
    gap : float
        Upper bound of that pair's signed distance minus the value (0 for closed forms).

    Notes
    -----
    Broad phase (module docstring, "Cost"): a pair is evaluated only when its bounds can still
    beat the best value found. Every bound is a lower bound of the value the pair would get (a
    signed distance of bodies that hold the two, lowered by BOUND_SLACK for rounding; GJK's
    answer is raised to the first bound), so the result is the one of the evaluation of every
    pair, value and pair, bit for bit. The certified steps of the ray searches, the torsion scan
    and the move certificate depend only on that value (and its rate bound), not on how it is
    found: pruning changes none of their guarantees.
    """
    r00, r01, r02 = r[0], r[1], r[2]
    r10, r11, r12 = r[3], r[4], r[5]
    r20, r21, r22 = r[6], r[7], r[8]
    leg_radius = model[block + LEG_RADIUS]
    finite = True
    for k in range(6):
        bx, by, bz = model[joints + 3 * k], model[joints + 3 * k + 1], model[joints + 3 * k + 2]
        qx = r00 * bx + r01 * by + r02 * bz + px
        qy = r10 * bx + r11 * by + r12 * bz + py
        qz = r20 * bx + r21 * by + r22 * bz + pz
        _set_axis(memory, k, qx - lx[k], qy - ly[k], qz - lz[k], qx, qy, qz, leg_radius)
        if not (abs(lx[k]) + abs(ly[k]) + abs(lz[k]) < np.inf):
            finite = False
    if model[block + TOOL_ON] != 0.0:
        t = block + TOOL_ENDS
        x0 = r00 * model[t] + r01 * model[t + 1] + r02 * model[t + 2] + px
        y0 = r10 * model[t] + r11 * model[t + 1] + r12 * model[t + 2] + py
        z0 = r20 * model[t] + r21 * model[t + 1] + r22 * model[t + 2] + pz
        x1 = r00 * model[t + 3] + r01 * model[t + 4] + r02 * model[t + 5] + px
        y1 = r10 * model[t + 3] + r11 * model[t + 4] + r12 * model[t + 5] + py
        z1 = r20 * model[t + 3] + r21 * model[t + 4] + r22 * model[t + 5] + pz
        radius = model[block + TOOL_RADIUS]
        _set_axis(memory, _TOOL, x0, y0, z0, x1, y1, z1, radius)
    if model[block + PLATFORM_ON] != 0.0:
        # The axis segment of the platform cylinder, and its radius (the capsule holds it).
        at = block + PLATFORM_RECORD
        h = model[at + _P + 1]
        ex, ey, ez = model[at + _R + 2] * h, model[at + _R + 5] * h, model[at + _R + 8] * h
        cx, cy, cz = model[at + _C], model[at + _C + 1], model[at + _C + 2]
        ax, ay, az = cx - ex, cy - ey, cz - ez
        bx, by, bz = cx + ex, cy + ey, cz + ez
        _set_axis(
            memory,
            _PLATFORM,
            r00 * ax + r01 * ay + r02 * az + px,
            r10 * ax + r11 * ay + r12 * az + py,
            r20 * ax + r21 * ay + r22 * az + pz,
            r00 * bx + r01 * by + r02 * bz + px,
            r10 * bx + r11 * by + r12 * bz + py,
            r20 * bx + r21 * by + r22 * bz + pz,
            model[at + _P],
        )
    for body in range(8):
        memory[_BUILT + body] = 0.0
    bodies = memory[_BODIES : _BODIES + 9 * RECORD_SIZE].reshape(9, RECORD_SIZE)
    work = memory[_WORK : _WORK + 3 * WORK_ROWS].reshape(WORK_ROWS, 3)
    n_obstacles = int(model[block + N_OBSTACLES])
    n_pairs = int(model[block + N_PAIRS])
    pairs_at = block + OBSTACLES + OBSTACLE_STRIDE * n_obstacles
    clearance = model[block + CLEARANCE]
    best = np.inf
    chosen = -1
    best_gap = 0.0
    if not pruned or not finite:
        # Every pair, in index order (a NaN value wins and stops: the first pair it reaches).
        for k in range(n_pairs):
            moving = int(model[pairs_at + 2 * k])
            other = int(model[pairs_at + 2 * k + 1])
            floor = _first_bound(model, block, memory, moving, other)
            value, gap = _exact(
                model, block, r, px, py, pz, memory, bodies, work, moving, other, floor, np.inf
            )
            if value < best or value != value:
                best, chosen, best_gap = value, k, gap
                if value != value:
                    break
        return best - clearance, float(chosen), best_gap
    if n_pairs <= KEPT_BOUNDS:
        return _best_first(
            model, block, r, px, py, pz, memory, bodies, work, pairs_at, n_pairs, clearance
        )
    # More pairs than kept bounds: two passes, bounds recomputed. First pass: every pair's first
    # bound; the pair of the smallest is evaluated first.
    first = 0
    first_bound = np.inf
    for k in range(n_pairs):
        bound = _first_bound(
            model, block, memory, int(model[pairs_at + 2 * k]), int(model[pairs_at + 2 * k + 1])
        )
        if bound < first_bound:
            first, first_bound = k, bound
    # Second pass, the first pair then the others in index order: a pair goes on only while
    # its bound can beat (best, chosen) (a lower value, or the same at a lower index).
    for visit in range(-1, n_pairs):
        k = first if visit < 0 else visit
        if visit == first:
            continue
        moving = int(model[pairs_at + 2 * k])
        other = int(model[pairs_at + 2 * k + 1])
        floor = _first_bound(model, block, memory, moving, other)
        if floor > best or (floor == best and k > chosen):
            continue
        bound = _refined_bound(model, block, memory, moving, other)
        if bound > best or (bound == best and k > chosen):
            continue
        # GJK may stop once its bound passes best + BOUND_SLACK: the value it then returns is
        # above best (by more than rounding), so the pair loses, as its full value would.
        value, gap = _exact(
            model,
            block,
            r,
            px,
            py,
            pz,
            memory,
            bodies,
            work,
            moving,
            other,
            floor,
            best + BOUND_SLACK,
        )
        if value < best or (value == best and k < chosen):
            best, chosen, best_gap = value, k, gap
    return best - clearance, float(chosen), best_gap


@_jit
def collision_margins(
    model: NDArray[np.float64],
    block: int,
    joints: int,
    rotations: NDArray[np.float64],
    positions: NDArray[np.float64],
    legs: NDArray[np.float64],
    pruned: bool,
    out: NDArray[np.float64],
) -> None:
    """:func:`collision_margin` of N poses (the tests compare ``pruned`` with every pair, the
    benchmark times both).

    Parameters
    ----------
    rotations : ndarray, shape (N, 9)
        R (mobile -> base frame), row-major.
    positions : ndarray, shape (N, 3)
        Tool centre points, base frame, m.
    legs : ndarray, shape (N, 3, 6)
        Leg vectors L_k = B_k − A_k (x, y, z planes), base frame, m.
    out : ndarray, shape (N, 3)
        Margin (m), pair index, gap (m) of each pose.
    """
    memory = np.empty(SCRATCH_FLOATS)
    for n in range(rotations.shape[0]):
        margin, pair, gap = collision_margin(
            model,
            block,
            joints,
            rotations[n],
            positions[n, 0],
            positions[n, 1],
            positions[n, 2],
            legs[n, 0],
            legs[n, 1],
            legs[n, 2],
            memory,
            pruned,
        )
        out[n, 0] = margin
        out[n, 1] = pair
        out[n, 2] = gap


@_helper
def _platform_body(
    model: NDArray[np.float64],
    block: int,
    r: NDArray[np.float64],
    px: float,
    py: float,
    pz: float,
    row: NDArray[np.float64],
) -> None:
    """The platform cylinder at the pose (R, p) into a record, base frame."""
    at = block + PLATFORM_RECORD
    row[0] = CYLINDER
    for i in range(3):
        row[_C + i] = (
            r[3 * i] * model[at + _C]
            + r[3 * i + 1] * model[at + _C + 1]
            + r[3 * i + 2] * model[at + _C + 2]
        )
        for j in range(3):
            row[_R + 3 * i + j] = (
                r[3 * i] * model[at + _R + j]
                + r[3 * i + 1] * model[at + _R + 3 + j]
                + r[3 * i + 2] * model[at + _R + 6 + j]
            )
    row[_C] += px
    row[_C + 1] += py
    row[_C + 2] += pz
    row[_P] = model[at + _P]
    row[_P + 1] = model[at + _P + 1]
    row[_P + 2] = 0.0
    row[_INFLATION] = 0.0


# ------------------------------------------------------------------------------ first-class entry
def _collision_pose(
    model: NDArray[np.float64],
    block: int,
    joints: int,
    r: NDArray[np.float64],
    px: float,
    py: float,
    pz: float,
    lx: NDArray[np.float64],
    ly: NDArray[np.float64],
    lz: NDArray[np.float64],
    memory: NDArray[np.float64],
) -> tuple[float, float, float]:
    """:func:`collision_margin` with the broad phase on: the function the margin kernels call."""
    return collision_margin(model, block, joints, r, px, py, pz, lx, ly, lz, memory, True)


_COLLISION_FUNCTION: list[object] = []


def collision_function() -> object:
    """The collision margin of one pose, compiled once (and cached) as a first-class function.

    The margin and search kernels of a model with a scene take it as their ``collide`` switch
    (:mod:`~hexapod_workspace.core.base.jit`) and call it through its address: its code, the largest
    of the core (GJK and the broad phase), is compiled and optimised once instead of again
    inside every kernel and every variant that calls it (numba links a callee's code into each
    caller and optimises the whole again). Its type is :func:`collision_type`.
    """
    if not _COLLISION_FUNCTION:
        from ..base.jit import first_class

        _COLLISION_FUNCTION.append(first_class(_collision_pose, collision_signature()))
    return _COLLISION_FUNCTION[0]


def collision_signature() -> object:
    """The numba signature of :func:`collision_function` (the model read-only or not: a
    writable C array converts to the read-only type)."""
    from numba import types

    vector = types.Array(types.float64, 1, "C")
    model = types.Array(types.float64, 1, "C", readonly=True)
    return types.UniTuple(types.float64, 3)(
        model,
        types.int64,
        types.int64,
        vector,
        types.float64,
        types.float64,
        types.float64,
        vector,
        vector,
        vector,
        vector,
    )


def collision_type() -> object:
    """The numba type of :func:`collision_function` as an argument of a kernel."""
    from numba import types

    return types.FunctionType(collision_signature())
