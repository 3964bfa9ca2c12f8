"""Margin kernels (numba): the constraint margins of one pose and of blocks of poses.

Batches are evaluated 128 poses at a time as planes of one flat array, stage by stage
(:func:`_check_block`), so that every loop vectorises; single poses and the rare poses that need
care go through the scalar :func:`_pose`. Both follow the numpy reference of
``test/reference.py`` operation by operation: margins agree to rounding. The model is the packed
vector of :mod:`hexapod_workspace.core.kernels.layout`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

from ..base.jit import Collide
from ..base.jit import entry_points as _entry_points

# Imported first: it points numba's cache directory somewhere writable before numba loads.

# isort: split
import numpy as np
from numba.np.unsafe.ndarray import to_fixed_tuple
from numpy.typing import NDArray

from ..constraints.table import (
    LEG_INTERFERENCE,
    N_CONSTRAINTS,
    SINGULARITY,
)
from .blocks import (
    _BLOCK_ROWS,
    BLOCK,
    _check_block,
)
from .layout import (
    INTERFERENCE,
    ROWS_USED,
)
from .pose import (
    OUT_LEG,
    OUT_PAIR,
    OUT_SIZE,
    SCRATCH_ROWS,
    _feasible,
    _limiting_constraint,
    _pose,
)
from .trig import (
    _tt_matrix,
)

__all__ = ["MarginKernels", "margin_entry_points"]


# ------------------------------------------------------------------------------ batches
class MarginKernels(NamedTuple):
    """The compiled entry points of one kernel variant (:func:`margin_entry_points`)."""

    check_angles: Callable[..., int]
    check_one: Callable[..., tuple[Any, ...]]
    margins_rotations: Callable[..., None]


def margin_entry_points(
    moving: int | None,
    cranks: int | None,
    singular: int | None,
    signatures: dict[str, tuple[object, ...]] | None = None,
) -> MarginKernels:
    """The margin entry points compiled for one set of switches (:mod:`.jit`).

    Each is a closure whose switches are constants of its compiled code (numba keys its cache
    on them), so a 6-UPS model without a scene or a singularity margin compiles none of the
    moving-base, collision or singularity stages. Called once per variant by
    :func:`hexapod_workspace.core.kernels.for_model`. Each takes the ``collide`` switch as its
    last argument: None, or the first-class collision function (then ``signatures`` gives each
    entry point's argument types: numba types a ``FunctionType`` argument only from a
    signature).
    """

    decorate = _entry_points(signatures)

    @decorate("check_angles")
    def check_angles(
        model: NDArray[np.float64],
        angles: NDArray[np.float64],
        position: NDArray[np.float64],
        start: int,
        stop: int,
        margins: NDArray[np.float64],
        ints: NDArray[np.int64],
        pairs: NDArray[np.int64],
        reachable: NDArray[np.bool_],
        collide: Collide,
    ) -> int:
        """Check poses ``angles[start:stop]`` (N, 3) of T&T angles (rad) at ``position`` (3,), m.

        Writes, for each pose n in [start, stop): ``margins[:, n]`` (C, N) with C the rows in use
        (``model[ROWS_USED]``: the rows after the last one that applies to the model are +inf for
        every pose and not written; the arrays may have more rows);
        ``ints[:C, n]`` (C + 2, N), the 1-based leg with the smallest margin of each constraint,
        ``ints[C, n]`` the constraint with the smallest relative margin and ``ints[C + 1, n]`` its
        leg; ``pairs[n]`` (N, 2), the
        1-based closest pair; ``reachable[n]``. Legs and pairs of ``leg_interference`` are 0 when
        the check is disabled. Releases the GIL (threads split large batches).

        Returns
        -------
        int
            −1 when every input is finite (and the outputs are written); otherwise nothing is
            written and it is the first pose in [start, stop) with a non-finite angle, or −2 when
            the angles are finite and the position is not.
        """
        for n in range(start, stop):
            if not (
                math.isfinite(angles[n, 0])
                and math.isfinite(angles[n, 1])
                and math.isfinite(angles[n, 2])
            ):
                return n
        for k in range(3):
            if not math.isfinite(position[k]):
                return -2
        scratch = np.empty((SCRATCH_ROWS, 6))
        out = np.empty(OUT_SIZE)
        r = np.empty(9)
        work = np.empty(_BLOCK_ROWS * BLOCK)
        enabled = 1 if model[INTERFERENCE] != 0.0 else 0
        used = int(model[ROWS_USED])
        for first in range(start, stop, BLOCK):
            count = min(BLOCK, stop - first)
            _check_block(
                model,
                angles,
                position,
                first,
                count,
                work,
                scratch,
                out,
                r,
                moving,
                cranks,
                collide,
                singular,
            )
            for m in range(count):
                n = first + m
                # Only the rows in use: the others are +inf (never limiting, never violated).
                feasible = True
                for c in range(used):
                    out[c] = work[c * BLOCK + m]
                    margins[c, n] = out[c]
                    ints[c, n] = int(work[(OUT_LEG + c) * BLOCK + m]) + 1
                    feasible = feasible and out[c] >= 0.0  # NaN counts as violated
                ints[LEG_INTERFERENCE, n] *= enabled
                ints[SINGULARITY, n] = 0  # a property of all legs together: no limiting leg
                pairs[n, 0] = (int(work[OUT_PAIR * BLOCK + m]) + 1) * enabled
                pairs[n, 1] = (int(work[(OUT_PAIR + 1) * BLOCK + m]) + 1) * enabled
                worst = _limiting_constraint(model, out)
                ints[used, n] = worst
                ints[used + 1, n] = ints[worst, n] if worst < used else 0
                reachable[n] = feasible
        return -1

    @decorate("check_one")
    def check_one(
        model: NDArray[np.float64],
        phi: float,
        theta: float,
        psi: float,
        px: float,
        py: float,
        pz: float,
        collide: Collide,
    ) -> tuple[bool, tuple[float, ...], tuple[int, ...], tuple[int, int], int, int]:
        """One pose (φ, θ, ψ) rad at (px, py, pz) m, finite; the fast path of check_pose.

        Returns the fields of ``constraints.PoseCheck`` as one tuple of plain numbers (numba boxes
        it in C: cheaper than an output array read back and converted in Python): reachable,
        margins (N_CONSTRAINTS), 1-based limiting legs (N_CONSTRAINTS; the interference leg 0 when
        the check is disabled), closest pair (2, 1-based; 0 when disabled), the limiting constraint
        and its leg.
        """
        scratch = np.empty((SCRATCH_ROWS, 6))
        out = np.empty(OUT_SIZE)
        r = np.empty(9)
        _tt_matrix(phi, theta, psi, r)
        _pose(model, r, px, py, pz, scratch, out, True, moving, cranks, collide, singular)
        enabled = 1 if model[INTERFERENCE] != 0.0 else 0
        legs = np.empty(N_CONSTRAINTS, dtype=np.int64)
        for c in range(N_CONSTRAINTS):
            legs[c] = int(out[OUT_LEG + c]) + 1
        legs[LEG_INTERFERENCE] *= enabled
        legs[SINGULARITY] = 0
        worst = _limiting_constraint(model, out)
        return (
            _feasible(out, N_CONSTRAINTS),
            to_fixed_tuple(out[:N_CONSTRAINTS], N_CONSTRAINTS),
            to_fixed_tuple(legs, N_CONSTRAINTS),
            ((int(out[OUT_PAIR]) + 1) * enabled, (int(out[OUT_PAIR + 1]) + 1) * enabled),
            worst,
            legs[worst],
        )

    @decorate("margins_rotations")
    def margins_rotations(
        model: NDArray[np.float64],
        rotations: NDArray[np.float64],
        positions: NDArray[np.float64],
        interference: bool,
        margins: NDArray[np.float64],
        legs: NDArray[np.int64],
        pairs: NDArray[np.int64],
        collide: Collide,
    ) -> None:
        """Margins of N poses given as rotation matrices (N, 3, 3) at positions (M, 3), M ∈ {1, N}.

        Writes ``margins`` (C, N), ``legs`` (C, N) (C = N_CONSTRAINTS) and ``pairs`` (N, 2) as
        :func:`check_angles`.
        """
        scratch = np.empty((SCRATCH_ROWS, 6))
        out = np.empty(OUT_SIZE)
        r = np.empty(9)
        shared = positions.shape[0] == 1
        used = int(model[ROWS_USED])
        for n in range(rotations.shape[0]):
            for i in range(3):
                for j in range(3):
                    r[3 * i + j] = rotations[n, i, j]
            p = 0 if shared else n
            _pose(
                model,
                r,
                positions[p, 0],
                positions[p, 1],
                positions[p, 2],
                scratch,
                out,
                interference,
                moving,
                cranks,
                collide,
                singular,
            )
            for c in range(used):
                margins[c, n] = out[c]
                legs[c, n] = int(out[OUT_LEG + c])
            if n == 0:
                # The rows past the last one that applies are the same for every pose (+inf and a
                # fixed leg): written whole, once, instead of pose by pose.
                for c in range(used, N_CONSTRAINTS):
                    margins[c, :] = out[c]
                    legs[c, :] = int(out[OUT_LEG + c])
            pairs[n, 0] = int(out[OUT_PAIR])
            pairs[n, 1] = int(out[OUT_PAIR + 1])

    return MarginKernels(check_angles, check_one, margins_rotations)
