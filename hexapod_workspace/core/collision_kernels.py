"""The ``collision`` margin inside the compiled kernels: packed scene and per-pose evaluation.

:func:`pack_scene` appends the model's collision scene to the packed model vector of
:mod:`hexapod_workspace.core.model_layout` (a block after ``MODEL_SIZE``, offsets below);
:func:`collision_margin` evaluates the margin of one pose from the leg vectors the margin
kernels have already computed, and is called from one spot of the scalar pose kernel and one
of the block kernel (:mod:`hexapod_workspace.core.margin_kernels`).

Bodies and pairs are those of :mod:`hexapod_workspace.core.collision.scene` (same pair order,
same names, same signed distances of :mod:`hexapod_workspace.core.collision.distance`):
``test/test_collision_wiring.py`` compares the two implementations and both with coal.

Leg bodies come from the leg vectors
------------------------------------
Leg k runs from its base-side joint ``A_k = B_k − L_k`` to ``B_k = p + R·b_k``, where
``L_k`` is the leg vector of the kernels' scratch (planes ``lx, ly, lz``). Taking A_k from the
leg vector rather than from the fixed base joint keeps this kernel right for leg architectures
whose base-side joint moves (a prismatic or revolute actuator at the base). *Rate bound*: the
derivation of :mod:`hexapod_workspace.core.collision.scene` (legs point 2) uses that A_k stands
still, so that a leg point moves at most at |Ḃ_k|; for a moving base-side joint the leg
body's rate bound must add that joint's speed (the leg point moves at
``(1 − λ)|Ȧ_k| + λ|Ḃ_k|``), and the ``collision`` row's coefficients must include it. For 6-UPS
(A_k fixed) the derivation holds as written.

Cost
----
Per pose: the tool–leg pairs by the closed form of two segments (exact); every body–obstacle
pair first by a lower bound (the signed distance of two capsules that hold the bodies, a
closed form: ≤ sd by inclusion), and exactly (closed form or GJK) only when that bound can
still beat the smallest distance found; GJK itself stops as soon as its lower bound shows the
pair cannot be the smallest.
The pair that was closest at the previous pose of the same call is evaluated first (rays and
moves are continuous), so that usually one or two obstacle pairs are evaluated exactly. The
result does not depend on that order: the smallest value wins, the lower pair index on ties.
No allocation per call: the working memory is part of the kernels' scratch
(:data:`SCRATCH_FLOATS` floats after the leg planes).

Exactness
---------
Closed forms are exact to rounding; GJK returns a certified lower bound within 1e-9 m of the
signed distance (:mod:`hexapod_workspace.core.collision.distance`). When the cores overlap
(deep contact with a box or cylinder) the value is only a lower bound of the penetration depth;
the gap to the upper bound is returned with it, so that a step that assumes the margin cannot
recover faster than its rate (``search_kernels.recovery_step``) starts from ``value + gap``,
which is an upper bound of the true margin.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from .jit import helper as _helper

# isort: split
import numpy as np
from numpy.typing import NDArray

from .collision.distance import (
    _C,
    _INFLATION,
    _P,
    _R,
    CYLINDER,
    RECORD_SIZE,
    SEGMENT,
    WORK_ROWS,
    _capsule_bound,
    _pair,
)

if TYPE_CHECKING:
    from .manipulator import Manipulator

__all__ = ["GJK_KERNEL_TOLERANCE", "SCRATCH_FLOATS", "collision_margin", "pack_scene"]

# ------------------------------------------------------------------------------ packed block
# Offsets from the start of the block (model_layout.MODEL_SIZE).
N_OBSTACLES = 0
N_PAIRS = 1
CLEARANCE = 2
LEG_RADIUS = 3
TOOL_ON = 4
TOOL_RADIUS = 5
TOOL_ENDS = 6  # q0, q1 in the mobile frame (6)
PLATFORM_ON = 12
SEARCH_RATE = 13  # ρ_c: the margin's rate per rad of rotation at a fixed position
PLATFORM_RECORD = 14  # the platform cylinder in the mobile frame (RECORD_SIZE)
OBSTACLES = PLATFORM_RECORD + RECORD_SIZE
OBSTACLE_STRIDE = RECORD_SIZE  # the obstacle's record, base frame
# Then the pairs: (moving body, other body) per pair, bodies numbered as in collision.scene
# (0-5 legs, 6 platform, 7 tool, 8 + k obstacle k).
_PLATFORM, _TOOL, _FIRST_OBSTACLE = 6, 7, 8

#: GJK's stopping tolerance inside the kernels, m: the value stays a certified lower bound of
#: the signed distance, within this of it (against a curved cylinder GJK converges linearly:
#: 1e-9 m costs several times the iterations, for digits no verdict needs).
GJK_KERNEL_TOLERANCE = 1e-7

# Working memory (a flat view of the kernels' scratch after the leg planes).
_BODIES = 0  # 8 moving-body records, then the obstacle being evaluated (a writable copy)
_WORK = 9 * RECORD_SIZE  # GJK working memory (WORK_ROWS, 3)
_HINT = _WORK + 3 * WORK_ROWS  # the closest pair at the previous pose (−1 or garbage: checked)
#: Floats of working memory :func:`collision_margin` needs.
SCRATCH_FLOATS = _HINT + 1


def pack_scene(manipulator: Manipulator) -> NDArray[np.float64]:
    """The collision block of the packed model (empty when the model has no scene).

    Returns
    -------
    ndarray, shape (K,)
        Layout given by the offsets of this module.
    """
    from .collision.scene import _tool_ends, pair_table, platform_record, rate_bound

    scene = manipulator.collision
    if scene is None or scene.pair_count == 0:
        return np.zeros(0)
    pairs, _ = pair_table(scene)
    count = len(scene.obstacles)
    block = np.zeros(OBSTACLES + OBSTACLE_STRIDE * count + 2 * pairs.shape[0])
    block[N_OBSTACLES] = count
    block[N_PAIRS] = pairs.shape[0]
    block[CLEARANCE] = scene.clearance
    block[LEG_RADIUS] = 0.5 * manipulator.leg_diameter
    block[SEARCH_RATE] = rate_bound(manipulator, scene).rotation
    if scene.tool is not None:
        block[TOOL_ON] = 1.0
        block[TOOL_RADIUS] = scene.tool.radius
        block[TOOL_ENDS : TOOL_ENDS + 6] = _tool_ends(scene).ravel()
    if scene.platform is not None:
        record = platform_record(scene)
        block[PLATFORM_ON] = 1.0
        block[PLATFORM_RECORD : PLATFORM_RECORD + RECORD_SIZE] = record
    for k, obstacle in enumerate(scene.obstacles):
        start = OBSTACLES + OBSTACLE_STRIDE * k
        block[start : start + RECORD_SIZE] = obstacle.record
    block[OBSTACLES + OBSTACLE_STRIDE * count :] = pairs.ravel()
    return block


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
) -> tuple[float, float, float]:
    """The ``collision`` margin of one pose.

    Parameters
    ----------
    model : ndarray
        The packed model; its collision block starts at ``block``, the platform joints b_k
        (mobile frame, leg-major) at ``joints`` (``model_layout.B``).
    r : ndarray, shape (9,)
        Rotation (mobile -> base frame), row-major.
    px, py, pz : float
        Position of the mobile frame's origin (the tool centre point), base frame, m.
    lx, ly, lz : ndarray, shape (6,)
        Leg vectors L_k = B_k − A_k, base frame, m.
    memory : ndarray, shape (≥ SCRATCH_FLOATS,)
        Working memory (kept between poses of one call: the previous closest pair).

    Returns
    -------
    margin : float
        Smallest signed distance over the pairs minus the clearance, m (+inf without pairs).
    pair : float
        Index of that pair in the scene's pair table (−1.0 without pairs).
    gap : float
        Upper bound of that pair's signed distance minus the value (0 for closed forms).
    """
    bodies = memory[_BODIES : _BODIES + 9 * RECORD_SIZE].reshape(9, RECORD_SIZE)
    work = memory[_WORK : _WORK + 3 * WORK_ROWS].reshape(WORK_ROWS, 3)
    r00, r01, r02 = r[0], r[1], r[2]
    r10, r11, r12 = r[3], r[4], r[5]
    r20, r21, r22 = r[6], r[7], r[8]
    leg_radius = model[block + LEG_RADIUS]
    for k in range(6):
        bx, by, bz = model[joints + 3 * k], model[joints + 3 * k + 1], model[joints + 3 * k + 2]
        qx = r00 * bx + r01 * by + r02 * bz + px
        qy = r10 * bx + r11 * by + r12 * bz + py
        qz = r20 * bx + r21 * by + r22 * bz + pz
        _segment_body(bodies[k], qx - lx[k], qy - ly[k], qz - lz[k], qx, qy, qz, leg_radius)
    tool = model[block + TOOL_ON] != 0.0
    if tool:
        t = block + TOOL_ENDS
        x0 = r00 * model[t] + r01 * model[t + 1] + r02 * model[t + 2] + px
        y0 = r10 * model[t] + r11 * model[t + 1] + r12 * model[t + 2] + py
        z0 = r20 * model[t] + r21 * model[t + 1] + r22 * model[t + 2] + pz
        x1 = r00 * model[t + 3] + r01 * model[t + 4] + r02 * model[t + 5] + px
        y1 = r10 * model[t + 3] + r11 * model[t + 4] + r12 * model[t + 5] + py
        z1 = r20 * model[t + 3] + r21 * model[t + 4] + r22 * model[t + 5] + pz
        _segment_body(bodies[_TOOL], x0, y0, z0, x1, y1, z1, model[block + TOOL_RADIUS])
    if model[block + PLATFORM_ON] != 0.0:
        _platform_body(model, block, r, px, py, pz, bodies[_PLATFORM])
    n_obstacles = int(model[block + N_OBSTACLES])
    n_pairs = int(model[block + N_PAIRS])
    pairs_at = block + OBSTACLES + OBSTACLE_STRIDE * n_obstacles
    best = np.inf
    chosen = -1
    best_gap = 0.0
    hint = memory[_HINT]
    start = int(hint) if hint >= 0.0 and hint < n_pairs else -1
    for visit in range(-1, n_pairs):
        k = start if visit < 0 else visit
        if k < 0 or (visit >= 0 and k == start):
            continue
        moving = int(model[pairs_at + 2 * k])
        other = int(model[pairs_at + 2 * k + 1])
        first = bodies[moving]
        second = bodies[other if other < _FIRST_OBSTACLE else 8]
        if other >= _FIRST_OBSTACLE:
            at = block + OBSTACLES + OBSTACLE_STRIDE * (other - _FIRST_OBSTACLE)
            for i in range(RECORD_SIZE):
                second[i] = model[at + i]
            if visit >= 0:
                # Lower bound: the signed distance of capsules that hold the two bodies (≤ sd
                # by inclusion; exact for capsules and spheres, tight for long cylinders).
                bound = _capsule_bound(first, second)
                if bound > best or (bound == best and k > chosen):
                    continue
        value, gap = _pair(first, second, work, GJK_KERNEL_TOLERANCE, best)
        if value < best or (value == best and k < chosen) or value != value:
            best = value
            chosen = k
            best_gap = gap
            if value != value:
                break
    memory[_HINT] = chosen
    return best - model[block + CLEARANCE], float(chosen), best_gap


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
