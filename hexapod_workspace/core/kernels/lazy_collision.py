"""The lazy collision margin of the ray searches (numba): a certified lower bound of the
collision margin from its last evaluation and the rotation since, so that most probes skip
the exact distances (:mod:`hexapod_workspace.core.kernels.collision`)."""

from __future__ import annotations

import math

from ..base.jit import Collide

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import helper as _helper

# isort: split
import numpy as np
from numpy.typing import NDArray

from ..constraints.table import COLLISION, N_CONSTRAINTS
from .layout import (
    COLLISION_ON,
    MODEL_SIZE,
    RAY_TURN,
    TAU_MIN,
)
from .pose import (
    _limiting_constraint,
    _pose,
)
from .scene_layout import SEARCH_RATE
from .steps import (
    _estimate,
    _rate_moving,
    certified_step,
)

__all__ = [
    "LAZY_SLACK",
    "LAZY_STEP",
]

# ------------------------------------------------------------------------------ lazy collision
#: Subtracted from the collision margin's lower bound, m: the margin the kernels compute is
#: itself a lower bound of the true one, below it by at most GJK's tolerance (1e-7 m; gaps
#: ≤ 1e-8 m where it stagnates), so the bound minus this is also below the value an evaluation
#: would return at the probe (which keeps the guess phase's decisions those of an evaluation).
LAZY_SLACK = 1e-6
#: Along the march, the lazy bound may shorten the certified step to this fraction of the step
#: the other margins allow before the collision margin is evaluated (a few more cheap probes
#: instead of many expensive ones).
LAZY_STEP = 0.5


@_helper
def _lazy_rate(model: NDArray[np.float64], moving: int | None, collide: Collide) -> float:
    """Rate of the collision margin for the lazy bound of :func:`search_rays`, or 0 (no laziness).

    Fixed base joints: ρ_c per rad of rotation at a fixed position (``SEARCH_RATE`` of the
    packed scene, :func:`hexapod_workspace.core.model.collision.scene.rate_bound`: the tool and the
    platform turn about the fixed tool centre point, so their points move at ≤ Ω·r; a leg point
    A + λ(B − A) with A fixed at ≤ λ|Ḃ| ≤ ρ; obstacles stand still; a pair's signed distance
    changes at most at the sum of its two bodies' speeds, ≤ ρ_c = max(ρ, r_tool + ρ, platform
    reach), and so does their minimum). It holds between *any* two orientations at the search
    position (along the rotation that joins them), with no condition on the other margins.
    pus/rus: the table's rate with |τ| ≥ τ_lim (:func:`_rate_moving`), valid only along
    certified march steps (each keeps |τ| ≥ τ_f ≥ τ_lim). ``moving`` and ``collide``: the
    switches of :mod:`~hexapod_workspace.core.base.jit`."""
    if collide is None:
        return 0.0
    if model[COLLISION_ON] == 0.0 or model[RAY_TURN + COLLISION] != 0.0:
        return 0.0
    if moving is None:
        return float(model[MODEL_SIZE + SEARCH_RATE])
    return _rate_moving(model, COLLISION, model[TAU_MIN])


@_helper
def _turn_between(anchors: NDArray[np.float64], row: int, rotation: NDArray[np.float64]) -> float:
    """Angle of the rotation between R_a = anchors[row] and R (both row-major), rad:
    |R_a − R|_F = 2√2·sin(θ/2) for rotations (rounding is far inside LAZY_SLACK)."""
    squared = 0.0
    for i in range(9):
        d = anchors[row, i] - rotation[i]
        squared += d * d
    return 2.0 * math.asin(min(1.0, math.sqrt(squared) / (2.0 * math.sqrt(2.0))))


@_helper
def _lazy_collision(
    model: NDArray[np.float64],
    out: NDArray[np.float64],
    bound: float,
    reference: float,
    march: bool,
    moving: int | None,
) -> bool:
    """Whether ``bound`` > 0, a lower bound of the collision margin at the probe, may stand in
    for the margin; if so it is stored in ``out[COLLISION]`` (else that slot stays +inf).

    ``out`` holds the probe's other margins (its collision slot +inf). What the search reads
    from a probe is monotone in each margin: the verdict (all ≥ 0), the certified step (a
    minimum of m_c/L_c), the estimate (a minimum of m_c/E_c) and the limiting constraint (the
    smallest m_c/S_c, first on ties; collision is the last row). The evaluated margin m lies in
    [bound, +inf], so where a quantity is the same at both ends it is the same at m.

    * The verdict: bound > 0 makes the probe collision-free, as m would.
    * A feasible march probe: the certified step from ``bound`` is certified (bound ≤ m), and
      is accepted when it is at least :data:`LAZY_STEP` of the step from ``reference`` (the
      evaluated margin the bound comes from, a stand-in for the unknown m): a bound from a
      nearby anchor is taken, one worn down by a long way from its anchor is not.
    * Any other probe (a violated one, the secant/bisection phase): the estimate and the
      limiting constraint must be the same at both ends, so the probe is decided exactly as
      an evaluation would decide it.

    A NaN margin (a leg without a solution) is always evaluated."""
    if not bound > 0.0:
        return False
    feasible = True
    for c in range(N_CONSTRAINTS):
        if out[c] != out[c]:
            return False
        if out[c] < 0.0:
            feasible = False
    if march and feasible:
        # The certified step is min(S, m/r)·SAFETY (S from the other margins, r the collision
        # rate), so bound ≥ LAZY_STEP·reference already gives the step LAZY_STEP asks for.
        if bound >= LAZY_STEP * reference:
            out[COLLISION] = bound
            return True
        out[COLLISION] = reference
        step = certified_step(model, out, moving)
        out[COLLISION] = bound
        same = certified_step(model, out, moving) >= LAZY_STEP * step
    else:
        estimate = _estimate(model, out)
        limiting = -1 if feasible else _limiting_constraint(model, out)
        out[COLLISION] = bound
        same = _estimate(model, out) == estimate
        if same and not feasible:
            same = _limiting_constraint(model, out) == limiting
    if not same:
        out[COLLISION] = np.inf
    return same


@_helper
def _scan_pose(
    model: NDArray[np.float64],
    plain: NDArray[np.float64],
    r: NDArray[np.float64],
    position: NDArray[np.float64],
    scratch: NDArray[np.float64],
    out: NDArray[np.float64],
    bound: float,
    reference: float,
    march: bool,
    moving: int | None,
    cranks: int | None,
    collide: Collide,
    singular: int | None,
) -> float:
    """One sample of the torsion scan (``torsion_scan`` of :mod:`.searches`) into ``out``;
    returns what the scan knows of the collision margin there, a lower bound of it: ``bound``
    where that stands in for the margin (``plain`` is the model with its scene off: every other
    margin evaluated), the evaluated margin otherwise (``bound`` −inf: always evaluated).
    Acceptance (derivation in ``torsion_scan``'s docstring): the scan reads from a sample its
    verdict, its certified step where feasible (marching, ``march``) and its recovery step where
    violated; bisecting, only the verdict."""
    x, y, z = position[0], position[1], position[2]
    if collide is not None and bound > 0.0:
        _pose(plain, r, x, y, z, scratch, out, True, moving, cranks, collide, singular)
        usable = True
        feasible = True
        for c in range(N_CONSTRAINTS):
            if out[c] != out[c]:
                usable = False
            elif out[c] < 0.0:
                feasible = False
        if usable:
            if not (march and feasible):
                out[COLLISION] = bound
                return bound
            if _lazy_collision(model, out, bound, reference, True, moving):
                return bound
    _pose(model, r, x, y, z, scratch, out, True, moving, cranks, collide, singular)
    return float(out[COLLISION])
