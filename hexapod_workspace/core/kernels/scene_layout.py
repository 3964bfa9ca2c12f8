"""The collision scene packed for the kernels: the block :func:`pack_scene` appends to the packed
model vector of :mod:`hexapod_workspace.core.kernels.layout` (after ``MODEL_SIZE``), its offsets,
and the layout of the per-pose scratch the collision margin
(:mod:`hexapod_workspace.core.kernels.collision`) works in."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

# Imported first: it points numba's cache directory somewhere writable before numba loads.

# isort: split
import numpy as np
from numpy.typing import NDArray

from ..model.collision.distance import (
    _C,
    _INFLATION,
    _P,
    BOX,
    CYLINDER,
    POINT,
    RECORD_SIZE,
    SEGMENT,
    WORK_ROWS,
    _enclosing,
)

if TYPE_CHECKING:
    from ..model.manipulator import Manipulator

__all__ = [
    "BOUND_SLACK",
    "CLEARANCE",
    "ELONGATED",
    "GJK_KERNEL_TOLERANCE",
    "KEPT_BOUNDS",
    "LEG_RADIUS",
    "N_OBSTACLES",
    "N_PAIRS",
    "OBSTACLES",
    "OBSTACLE_STRIDE",
    "PLATFORM_ON",
    "PLATFORM_RECORD",
    "SCRATCH_FLOATS",
    "SEARCH_RATE",
    "TOOL_ENDS",
    "TOOL_ON",
    "TOOL_RADIUS",
    "pack_scene",
]

# ------------------------------------------------------------------------------ packed block
# Offsets from the start of the block (kernels.layout.MODEL_SIZE).
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
# Per obstacle: its record (base frame), then what the broad phase reads (base frame, fixed):
# the centre and radius of a sphere that holds it, a capsule that holds it (first end,
# direction, radius) and whether a capsule bound is worth computing before the exact value.
_SPHERE = RECORD_SIZE  # centre (3), radius
_CAPSULE = _SPHERE + 4  # first end (3), direction end − start (3), radius
_REFINE = _CAPSULE + 7  # 1.0: a box or cylinder (its exact value: 14 closed forms, or GJK)
_ELONGATED = _REFINE + 1  # 1.0: the sphere is much wider than the capsule: the capsule first
OBSTACLE_STRIDE = _ELONGATED + 1
#: An obstacle whose sphere's radius exceeds its capsule's by this factor (a column, a long
#: box) is bounded by its capsule from the start: its sphere would prune nothing.
ELONGATED = 1.5
# Then the pairs: (moving body, other body) per pair, bodies numbered as in collision.scene
# (0-5 legs, 6 platform, 7 tool, 8 + k obstacle k).
_PLATFORM, _TOOL, _FIRST_OBSTACLE = 6, 7, 8

#: GJK's stopping tolerance inside the kernels, m: the value stays a certified lower bound of
#: the signed distance, within this of it (against a curved cylinder GJK converges linearly:
#: 1e-9 m costs several times the iterations, for digits no verdict needs).
GJK_KERNEL_TOLERANCE = 1e-7

#: What every broad-phase bound is lowered by before it is compared, m: the bounds and the exact
#: values are computed by different formulas, whose rounding (~1e-15 m at the scale of a machine)
#: must never let a bound exceed the value it bounds.
BOUND_SLACK = 1e-9

#: Pairs whose bounds the working memory keeps (visited best first); beyond, two passes in index
#: order with the bounds recomputed.
KEPT_BOUNDS = 64

# Working memory (a flat view of the kernels' scratch after the leg planes).
_BODIES = 0  # 8 moving-body records, then the obstacle being evaluated (a writable copy)
_WORK = 9 * RECORD_SIZE  # GJK working memory (WORK_ROWS, 3)
_AXES = _WORK + 3 * WORK_ROWS  # per moving body: end (3), direction (3), 1/|direction|², radius
_AXIS_STRIDE = 8
_BUILT = _AXES + 8 * _AXIS_STRIDE  # per moving body: 1.0 once its record is filled at this pose
_KEPT = _BUILT + 8  # per pair (up to KEPT_BOUNDS): its first bound,
_KEYS = _KEPT + KEPT_BOUNDS  # the best lower bound of its value known (or the value),
_STATE = _KEYS + KEPT_BOUNDS  # what that key is (_FIRST, _REFINED, _VALUE),
_GAPS = _STATE + KEPT_BOUNDS  # and the gap of the value
_FIRST, _REFINED, _VALUE = 0.0, 1.0, 2.0
#: Floats of working memory :func:`collision_margin` needs.
SCRATCH_FLOATS = _GAPS + KEPT_BOUNDS


def pack_scene(manipulator: Manipulator) -> NDArray[np.float64]:
    """The collision block of the packed model (empty when the model has no scene).

    Returns
    -------
    ndarray, shape (K,)
        Layout given by the offsets of this module.
    """
    from ..model.collision.scene import _tool_ends, pair_table, platform_record, rate_bound

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
        block[start : start + OBSTACLE_STRIDE] = _obstacle_entry(obstacle.record)
    block[OBSTACLES + OBSTACLE_STRIDE * count :] = pairs.ravel()
    return block


def _obstacle_entry(body: NDArray[np.float64]) -> NDArray[np.float64]:
    """An obstacle's record followed by its bounding sphere, its enclosing capsule (the one the
    exact evaluation's own capsule bound uses) and whether a capsule bound is worth computing
    before the exact value, shape (OBSTACLE_STRIDE,)."""
    entry = np.zeros(OBSTACLE_STRIDE)
    entry[:RECORD_SIZE] = body
    kind = int(body[0])
    half = body[_P : _P + 3]
    if kind == CYLINDER:
        reach = math.hypot(half[0], half[1])
    elif kind == SEGMENT:
        reach = half[0]
    elif kind == POINT:
        reach = 0.0
    else:  # a box: its corners
        reach = float(np.linalg.norm(half))
    entry[_SPHERE : _SPHERE + 3] = body[_C : _C + 3]
    entry[_SPHERE + 3] = reach + body[_INFLATION]
    entry[_CAPSULE : _CAPSULE + 7] = _enclosing(np.ascontiguousarray(body))
    entry[_REFINE] = 1.0 if kind in (BOX, CYLINDER) else 0.0
    entry[_ELONGATED] = 1.0 if entry[_SPHERE + 3] > ELONGATED * entry[_CAPSULE + 6] else 0.0
    return entry
