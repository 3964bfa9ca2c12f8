"""Compiled kernels (numba): one import for the margin and search kernels, and their warm-up.

The kernels live in modules of their own: numba set-up and the compile-time switches in
:mod:`~hexapod_workspace.core.base.jit`, model layout in
:mod:`~hexapod_workspace.core.kernels.layout`, margins in
:mod:`~hexapod_workspace.core.kernels.margins`, ray searches in
:mod:`~hexapod_workspace.core.kernels.searches`. This module builds the entry points of each
variant of the model (:func:`for_model`: fixed or moving base joints, slides or cranks, a scene,
a singularity margin), tells whether a model's kernels are compiled (:func:`cache_is_warm`) and
compiles or loads them (:func:`warm_up`, returning the seconds it took). Arrays handed to a
kernel are normalised once here (:func:`vector`): one compiled signature per kernel.
"""

from __future__ import annotations

import contextlib
import json
import threading
import time
from collections.abc import Iterable
from typing import Any, NamedTuple

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import CACHE_DIRECTORY, OFF, ON, Switches, compile_notice

# isort: split
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..constraints.table import N_CONSTRAINTS
from .layout import (
    ARCH,
    COLLISION_ON,
    ESTIMATE_FLOOR,
    LENGTH_FLOOR,
    LMAX,
    MODEL_SIZE,
    ORDER,
    RHO,
    ROWS_USED,
    SCALE,
    SINGULARITY_ON,
    A,
    B,
    model_vector,
)
from .margins import margin_entry_points
from .searches import (
    KIND_CYLINDRICAL,
    KIND_TT,
    MAX_STEP,
    SAFETY,
    search_entry_points,
)
from .trig import FAST_TRIG_LIMIT

__all__ = [
    "ALL_SWITCHES",
    "CACHE_DIRECTORY",
    "CHECKS",
    "COLLISION_ON",
    "ENTRY_POINTS",
    "FAST_TRIG_LIMIT",
    "KIND_CYLINDRICAL",
    "KIND_TT",
    "MAX_STEP",
    "ROWS_USED",
    "SAFETY",
    "SCALE",
    "Kernels",
    "cache_is_warm",
    "compile_notice",
    "for_model",
    "model_vector",
    "switches",
    "vector",
    "warm_up",
]


class Kernels(NamedTuple):
    """The compiled entry points of one variant of the model (numba Dispatchers), and the
    ``collide`` switch every one of them takes as its last argument."""

    check_angles: Any
    check_one: Any
    margins_rotations: Any
    search_rays: Any
    torsion_scan: Any
    #: None (no scene) or the first-class collision function.
    collide: Any


#: The compiled entry points of a variant, in :class:`Kernels` order (``collide`` is not one).
ENTRY_POINTS: tuple[str, ...] = Kernels._fields[:-1]


def switches(model: NDArray[np.float64]) -> Switches:
    """The compile-time switches (moving, cranks, collide, singular) of a packed model."""
    arch = model[ARCH]
    return (
        ON if arch != 0.0 else OFF,
        ON if arch == 2.0 else OFF,
        ON if model[COLLISION_ON] != 0.0 else OFF,
        ON if model[SINGULARITY_ON] != 0.0 else OFF,
    )


#: Every variant: 6-UPS, 6-PUS, 6-RUS, each with or without a scene and a singularity margin.
ALL_SWITCHES: tuple[Switches, ...] = tuple(
    (moving, cranks, collide, singular)
    for moving, cranks in ((OFF, OFF), (ON, OFF), (ON, ON))
    for collide in (OFF, ON)
    for singular in (OFF, ON)
)

_VARIANTS: dict[Switches, Kernels] = {}
_LOCK = threading.Lock()


def _signatures() -> dict[str, tuple[object, ...]]:
    """The argument types of each entry point of a variant with a scene: the normalised
    layouts (:func:`vector`; the packed model is read-only) and the collision function's type
    last. Without a scene the entry points compile lazily, for the same types."""
    from numba import types

    from .collision import collision_type

    f8 = types.float64
    i8 = types.int64
    model = types.Array(f8, 1, "C", readonly=True)
    v1, v2, v3 = (types.Array(f8, n, "C") for n in (1, 2, 3))
    n1, n2 = types.Array(i8, 1, "C"), types.Array(i8, 2, "C")
    flags = types.Array(types.boolean, 1, "C")
    collide = collision_type()
    return {
        "check_angles": (model, v2, v1, i8, i8, v2, n2, n2, flags, collide),
        "check_one": (model, f8, f8, f8, f8, f8, f8, collide),
        "margins_rotations": (model, v3, v2, types.boolean, v2, n2, n2, collide),
        "search_rays": (
            model,
            v1,
            i8,
            v2,
            v2,
            v1,
            v1,
            f8,
            f8,
            v1,
            v1,
            n1,
            flags,
            types.boolean,
            collide,
        ),
        "torsion_scan": (model, v1, f8, f8, f8, f8, f8, v1, flags, types.boolean, collide),
    }


def _variant(key: Switches) -> Kernels:
    kernels = _VARIANTS.get(key)
    if kernels is None:
        with _LOCK:
            kernels = _VARIANTS.get(key)
            if kernels is None:
                moving, cranks, collide, singular = key
                signatures = None
                function = None
                if collide is not None:
                    from .collision import collision_function

                    function = collision_function()
                    signatures = _signatures()
                kernels = Kernels(
                    *margin_entry_points(moving, cranks, singular, signatures),
                    *search_entry_points(moving, cranks, singular, signatures),
                    function,
                )
                _VARIANTS[key] = kernels
    return kernels


#: id(model) -> (model, its variant): the packed models are cached per manipulator, so the
#: one-pose check looks its variant up by an int instead of reading four switches (0.3 µs of a
#: 2.5 µs call). The model is held, so its id is not reused while it is here; bounded.
_BY_MODEL: dict[int, tuple[NDArray[np.float64], Kernels]] = {}
_BY_MODEL_MAX = 64


def for_model(model: NDArray[np.float64]) -> Kernels:
    """The entry points compiled for ``model``'s variant (built once per variant per process;
    compiled, or loaded from the cache, on first call)."""
    hit = _BY_MODEL.get(id(model))
    if hit is not None and hit[0] is model:
        return hit[1]
    variant = _variant(switches(model))
    if len(_BY_MODEL) >= _BY_MODEL_MAX:
        _BY_MODEL.clear()
    _BY_MODEL[id(model)] = (model, variant)
    return variant


def vector(values: ArrayLike) -> NDArray[np.float64]:
    """``values`` as the kernels take every array input: float64, C-contiguous, writable (a
    copy only where it is not), so that a strided view, a read-only, integer or Fortran-ordered
    array or a list compiles no second signature."""
    array = np.asarray(values, dtype=np.float64)
    if not (array.flags.c_contiguous and array.flags.writeable):
        array = np.array(array, dtype=np.float64, order="C")
    return array


_MARKER = "warm.json"


def _warm_keys() -> set[str]:
    if CACHE_DIRECTORY is None:
        return set()
    try:
        return set(json.loads((CACHE_DIRECTORY / _MARKER).read_text(encoding="utf-8")))
    except (OSError, ValueError, TypeError):
        return set()


def _key_text(key: Switches) -> str:
    return "".join("1" if flag is not None else "0" for flag in key)


def cache_is_warm(model: NDArray[np.float64] | None = None) -> bool:
    """Whether :func:`warm_up` has compiled ``model``'s kernels into the on-disk cache (every
    variant when ``model`` is None), or they are compiled in this process already.

    False means the next use compiles (seconds). Read from a marker that :func:`warm_up` writes
    in the cache directory, next to numba's own files.
    """
    keys = ALL_SWITCHES if model is None else (switches(model),)
    warm = _warm_keys()
    for key in keys:
        compiled = key in _VARIANTS and all(
            getattr(_VARIANTS[key], name).signatures for name in ENTRY_POINTS
        )
        if not compiled and _key_text(key) not in warm:
            return False
    return True


def _tiny_model(key: Switches) -> NDArray[np.float64]:
    """A small model of variant ``key`` (6-UPS layout; the kernels only need its flags)."""
    model = np.zeros(MODEL_SIZE)
    model[A : A + 18] = np.tile([1.0, 0.0, 0.0], 6)
    model[B : B + 18] = np.tile([0.5, 0.0, 0.0], 6)
    model[SCALE : SCALE + N_CONSTRAINTS] = 1.0
    model[ROWS_USED] = N_CONSTRAINTS
    model[RHO] = 0.5
    model[LENGTH_FLOOR] = model[ESTIMATE_FLOOR] = 1e-3
    model[LMAX : LMAX + 6] = 2.0
    model[ORDER : ORDER + 15] = np.arange(15)
    return model


#: The entry points a pose check needs (``check``, ``check_pose``): what the ROS node compiles
#: before it answers, the others after.
CHECKS = ("check_angles", "check_one")


def _run_variant(kernels: Kernels, names: Iterable[str] | None = None) -> None:
    """Run each entry point of one variant (or those ``names``) once on a tiny problem of the
    argument types production uses (the model's own flags off: the compiled code is the
    variant's)."""
    wanted = set(ENTRY_POINTS if names is None else names)
    model = _tiny_model((OFF, OFF, OFF, OFF))
    model.setflags(write=False)  # as model_vector's
    position = np.array([0.0, 0.0, 1.0])
    angles = np.zeros((1, 3))
    margins = np.empty((N_CONSTRAINTS, 1))
    legs = np.empty((N_CONSTRAINTS, 1), dtype=np.int64)
    pairs = np.empty((1, 2), dtype=np.int64)
    if "check_angles" in wanted:
        kernels.check_angles(
            model,
            angles,
            position,
            0,
            1,
            margins,
            np.empty((N_CONSTRAINTS + 2, 1), dtype=np.int64),
            pairs,
            np.empty(1, dtype=np.bool_),
            kernels.collide,
        )
    if "check_one" in wanted:
        kernels.check_one(model, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, kernels.collide)
    if "margins_rotations" in wanted:
        kernels.margins_rotations(
            model, np.eye(3)[None], position[None], True, margins, legs, pairs, kernels.collide
        )
    if "search_rays" in wanted:
        ones = np.ones(1)
        kernels.search_rays(
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
            kernels.collide,
        )
    if "torsion_scan" in wanted:
        kernels.torsion_scan(
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
            kernels.collide,
        )


def warm_up(*models: NDArray[np.float64], names: Iterable[str] | None = None) -> float:
    """Compile (first run after install) or load from the cache the kernels of the variants of
    ``models`` (packed, :func:`model_vector`; none given: every variant); seconds taken.

    For the ROS node (with its model), the CLI and the tests. ``names``: only these entry
    points (:data:`CHECKS`: what a pose check needs). Records the variants whose every entry
    point it compiled in the cache directory's marker (:func:`cache_is_warm`).
    """
    started = time.perf_counter()
    keys: Iterable[Switches] = (
        dict.fromkeys(switches(model) for model in models) if models else ALL_SWITCHES
    )
    done = []
    for key in keys:
        _run_variant(_variant(key), names)
        if names is None:
            done.append(_key_text(key))
    if CACHE_DIRECTORY is not None:
        warm = _warm_keys() | set(done)
        # A read-only cache: the marker only saves a later warm-up's question.
        with contextlib.suppress(OSError):
            (CACHE_DIRECTORY / _MARKER).write_text(json.dumps(sorted(warm)), encoding="utf-8")
    return time.perf_counter() - started
