"""Compiled kernels (numba): one import for the margin and search kernels, and their warm-up.

The kernels live in modules of their own: numba set-up in :mod:`~hexapod_workspace.core.jit`,
model layout in :mod:`~hexapod_workspace.core.model_layout`, margins in
:mod:`~hexapod_workspace.core.margin_kernels`, ray searches in
:mod:`~hexapod_workspace.core.search_kernels`. This module gathers their entry points,
tells whether a run will compile (:func:`cache_is_warm`) and compiles or loads every kernel
(:func:`warm_up`, returning the seconds it took).
"""

from __future__ import annotations

import time
from typing import Any

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from .jit import CACHE_DIRECTORY, compile_notice

# isort: split
import numpy as np

from .constraint_table import N_CONSTRAINTS
from .margin_kernels import FAST_TRIG_LIMIT, check_angles, check_one, margins_rotations
from .model_layout import (
    COLLISION_ON,
    ESTIMATE_FLOOR,
    LENGTH_FLOOR,
    LMAX,
    MODEL_SIZE,
    ORDER,
    RHO,
    ROWS_USED,
    SCALE,
    A,
    B,
    model_vector,
)
from .search_kernels import KIND_CYLINDRICAL, KIND_TT, MAX_STEP, SAFETY, search_rays, torsion_scan

__all__ = [
    "CACHE_DIRECTORY",
    "COLLISION_ON",
    "FAST_TRIG_LIMIT",
    "KIND_CYLINDRICAL",
    "KIND_TT",
    "MAX_STEP",
    "ROWS_USED",
    "SAFETY",
    "SCALE",
    "cache_is_warm",
    "check_angles",
    "check_one",
    "compile_notice",
    "margins_rotations",
    "model_vector",
    "search_rays",
    "torsion_scan",
    "warm_up",
]


def _kernels() -> list[Any]:
    """The cached entry points, as numba Dispatchers (untyped: numba ships no stubs)."""
    return [check_angles, check_one, margins_rotations, search_rays, torsion_scan]


def cache_is_warm() -> bool:
    """Whether every kernel is already compiled in this process or in the on-disk cache.

    False means the next use compiles (seconds). Uses numba's cache index (an internal
    interface); when it cannot be read, answers False.
    """
    try:
        for kernel in _kernels():
            if kernel.signatures:
                continue
            if kernel._cache is None or not kernel._cache._cache_file._load_index():
                return False
    except (AttributeError, OSError, TypeError, ValueError):
        return False
    return True


def warm_up() -> float:
    """Compile (first run after install) or load from the cache every kernel; seconds taken.

    Runs each kernel once on a tiny problem of the argument types production uses. For the
    ROS node to call before it reports ready, and for the CLI.
    """
    started = time.perf_counter()
    model = np.zeros(MODEL_SIZE)
    model[A : A + 18] = np.tile([1.0, 0.0, 0.0], 6)
    model[B : B + 18] = np.tile([0.5, 0.0, 0.0], 6)
    model[SCALE : SCALE + N_CONSTRAINTS] = 1.0
    model[ROWS_USED] = N_CONSTRAINTS
    model[RHO] = 0.5
    model[LENGTH_FLOOR] = model[ESTIMATE_FLOOR] = 1e-3
    model[LMAX : LMAX + 6] = 2.0
    model[ORDER : ORDER + 15] = np.arange(15)
    model.setflags(write=False)
    position = np.array([0.0, 0.0, 1.0])
    angles = np.zeros((1, 3))
    margins = np.empty((N_CONSTRAINTS, 1))
    legs = np.empty((N_CONSTRAINTS, 1), dtype=np.int64)
    pairs = np.empty((1, 2), dtype=np.int64)
    check_angles(
        model,
        angles,
        position,
        0,
        1,
        margins,
        np.empty((N_CONSTRAINTS + 2, 1), dtype=np.int64),
        pairs,
        np.empty(1, dtype=np.bool_),
    )
    check_one(model, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
    margins_rotations(model, np.eye(3)[None], position[None], True, margins, legs, pairs)
    ones = np.ones(1)
    search_rays(
        model,
        position,
        KIND_TT,
        angles,
        np.array([[0.0, 1.0, 0.0]]),
        np.zeros(1),
        ones,
        1e-3,
        1e-3,
        np.empty(1),
        np.empty(1),
        np.empty(1, dtype=np.int64),
        np.empty(1, dtype=np.bool_),
        True,
    )
    torsion_scan(
        model,
        position,
        0.0,
        0.0,
        1e-3,
        0.25,
        1e-3,
        np.empty(8),
        np.empty(8, dtype=np.bool_),
        True,
    )
    return time.perf_counter() - started
