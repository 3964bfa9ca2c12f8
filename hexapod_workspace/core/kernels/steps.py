"""The steps of the certified ray searches (numba): the rate of each margin along a ray, the
certified step a margin allows, the recovery step after a violation, and the decisions of a
block of probes (:mod:`hexapod_workspace.core.workspaces.search` documents the march)."""

from __future__ import annotations

import math

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import helper as _helper
from ..base.jit import inline as _inline

# isort: split
import numpy as np
from numpy.typing import NDArray

from ..constraints.table import COLLISION, IK, LEG_LENGTH, TRANSMISSION
from .blocks import BLOCK
from .layout import (
    ESTIMATE_RATE,
    LENGTH_FLOOR,
    RAY_CONSTANT,
    RAY_DRIVE,
    RAY_TURN,
    RHO,
    ROWS_USED,
    TAU_MIN,
)
from .pose import (
    OUT_GAP,
    OUT_SHORTEST,
)

__all__ = [
    "KIND_CYLINDRICAL",
    "KIND_TT",
    "MAX_STEP",
    "SAFETY",
    "certified_step",
    "recovery_step",
]


# Search constants, shared with core.search (which documents them).
MAX_STEP = 1.0
SAFETY = 1.0 - 1e-9
#: Ray kinds: angles along a ray are origin + s·direction in T&T coordinates (φ, θ, ψ), or in
#: the cylindrical picture (x, y, ψ) with x = θ cos φ, y = θ sin φ.
KIND_TT, KIND_CYLINDRICAL = 0, 1


# ------------------------------------------------------------------------------ ray searches
@_helper
def _ray_angles(
    kind: int,
    origin: NDArray[np.float64],
    direction: NDArray[np.float64],
    s: float,
    angles: NDArray[np.float64],
    row: int,
) -> None:
    """T&T angles of the ray origin + s·direction (KIND_TT or KIND_CYLINDRICAL) into angles[row]."""
    if kind == KIND_TT:
        angles[row, 0] = origin[0] + s * direction[0]
        angles[row, 1] = origin[1] + s * direction[1]
        angles[row, 2] = origin[2] + s * direction[2]
    else:
        x = origin[0] + s * direction[0]
        y = origin[1] + s * direction[1]
        theta = math.hypot(x, y)
        angles[row, 0] = math.atan2(y, x) if theta > 0.0 else 0.0
        angles[row, 1] = theta
        angles[row, 2] = origin[2] + s * direction[2]


@_helper
def _rate(model: NDArray[np.float64], c: int, floor: float) -> float:
    """Lipschitz rate of margin ``c`` along a ray (ω ≤ 1, joints at ≤ ρ) with legs at least
    ``floor`` long: speed·ρ + turn·ρ/floor + spin, from its row of the constraint table (the
    turn term left out where its coefficient is 0, so a zero floor costs nothing there)."""
    rate: float = model[RAY_CONSTANT + c]
    turn = model[RAY_TURN + c]
    if turn != 0.0:
        rate += turn / floor
    return rate


@_helper
def _rate_moving(model: NDArray[np.float64], c: int, tau: float) -> float:
    """Lipschitz rate of margin ``c`` along a ray for a pus or rus model with |τ_i| ≥ ``tau`` > 0
    on the stretch considered: RAY_CONSTANT + RAY_TURN·(1 + 1/τ)/L_min + RAY_DRIVE/τ (the
    constraint table's speed·V + turn·N + spin·Ω + actuate·Q + crank·K + ends·E with V = ρ,
    Ω = 1, N = V(1 + 1/τ)/L_min, Q = V/τ (pus) or V/(r_min·τ) (rus), K = V/(r_min·τ) (rus),
    E = V/τ); terms with a zero coefficient left out."""
    rate: float = model[RAY_CONSTANT + c]
    turn = model[RAY_TURN + c]
    if turn != 0.0:
        rate += turn * (1.0 + 1.0 / tau) / model[LENGTH_FLOOR]
    drive = model[RAY_DRIVE + c]
    if drive != 0.0:
        rate += drive / tau
    return rate


@_helper
def _certified_step_moving(model: NDArray[np.float64], out: NDArray[np.float64]) -> float:
    """certified_step for pus/rus (feasible margins, so every leg has its q and
    |τ_i| ≥ τ_lim > 0). With τ_now = min |τ_i| and τ_f = max(τ_lim, τ_now/2), the rates with
    floor τ_f hold as long as |τ| ≥ τ_f; the step is also limited to (τ_now − τ_f)/rate_τ(τ_f),
    within which |τ| cannot fall to τ_f (the first such point would contradict the rate), and
    ``ik`` (rate V, independent of τ) keeps every leg solvable over any step it allows."""
    tau_now = out[TRANSMISSION] + model[TAU_MIN]
    tau_f = max(model[TAU_MIN], 0.5 * tau_now)
    step = (tau_now - tau_f) / _rate_moving(model, TRANSMISSION, tau_f)
    for c in range(int(model[ROWS_USED])):
        step = _fmin(step, out[c] / _rate_moving(model, c, tau_f))
    step = _fmin(step, MAX_STEP)
    if not step > 0.0:
        step = 0.0
    return step * SAFETY


@_helper
def _recovery_step_moving(model: NDArray[np.float64], out: NDArray[np.float64]) -> float:
    """recovery_step for pus/rus, the largest of three valid bounds:

    * a violated ``ik`` stays violated for |ik|/ρ (1-Lipschitz in each B_i, which moves at ≤ ρ);
    * a violated ``transmission`` (every leg solved, τ_now = min |τ_i| < τ_lim): to climb back
      to τ_lim, |τ| must cross [τ_now, τ_lim] on a stretch where it stays ≥ τ_now, so the legs
      stay solved (a leg loses its solution only through τ = 0: at ik = 0 the leg is tangent
      to its actuator's locus) and its rate is at most rate_τ(τ_now): it stays violated for
      (τ_lim − τ_now)/rate_τ(τ_now);
    * another violated margin (every leg solved, τ_now > 0): with τ_f = τ_now/2 and the step
      kept within (τ_now − τ_f)/rate_τ(τ_f), |τ| stays above τ_f (the legs stay solved, q is
      continuous) and the margin cannot climb back to zero within |m_c|/rate_c(τ_f).

    NaN margins (a leg without a solution) give no bound but ik's."""
    rho: float = model[RHO]
    recover = 0.0
    if out[IK] < 0.0:
        recover = -out[IK] / rho
    tau_now = out[TRANSMISSION] + model[TAU_MIN]
    if out[IK] >= 0.0 and tau_now > 0.0:
        if out[TRANSMISSION] < 0.0:
            climb = -out[TRANSMISSION] / _rate_moving(model, TRANSMISSION, tau_now)
            if climb > recover:
                recover = climb
        tau_f = 0.5 * tau_now
        other = 0.0
        for c in range(int(model[ROWS_USED])):
            if c == IK or c == TRANSMISSION:  # noqa: SIM109 - plain comparisons for numba
                continue
            margin = out[c] + out[OUT_GAP] if c == COLLISION else out[c]
            value = -margin / _rate_moving(model, c, tau_f) if margin < 0.0 else 0.0
            if value > other:
                other = value
        other = min(other, (tau_now - tau_f) / _rate_moving(model, TRANSMISSION, tau_f))
        if other > recover:
            recover = other
    return recover * SAFETY


@_helper
def _estimate(model: NDArray[np.float64], out: NDArray[np.float64]) -> float:
    """Signed distance estimate min_c m_c / L_c with fixed Lipschitz constants, rad (NaN wins).

    The constants are the ray rates of the constraint table with the fixed leg floor
    ESTIMATE_FLOOR (precomputed in the model): a continuous estimate for the secant steps, not
    a certificate."""
    best: float = out[0] / model[ESTIMATE_RATE]
    for c in range(1, int(model[ROWS_USED])):
        value = out[c] / model[ESTIMATE_RATE + c]
        if value < best or value != value:
            best = value
    return best


@_helper
def _fmin(a: float, b: float) -> float:
    """numpy.fmin: the smaller, ignoring a NaN."""
    if a != a:
        return b
    if b != b:
        return a
    return a if a < b else b


@_helper
def certified_step(
    model: NDArray[np.float64], out: NDArray[np.float64], moving: int | None
) -> float:
    """Length over which no margin can reach zero, from feasible margins (core.search).

    Like every step and estimate here, reads only the rows in use (``model[ROWS_USED]``): the
    kernels write +inf in the others, which can bound no step. :func:`_block_decisions` does
    this function's fixed-base arithmetic (and :func:`_estimate`'s) for a whole block: a change
    here goes there too (``test_block_decisions_equal_the_per_probe_functions`` holds them
    equal, bit for bit). ``moving``: the switch of :mod:`~hexapod_workspace.core.base.jit` (None for
    fixed base joints)."""
    if moving is not None:
        return _certified_step_moving(model, out)
    rho = model[RHO]
    length_min = model[LENGTH_FLOOR]
    length_now = length_min + max(out[LEG_LENGTH], 0.0)
    floor = max(length_min, 0.5 * length_now)
    step = out[0] / _rate(model, 0, floor)
    for c in range(1, int(model[ROWS_USED])):
        step = _fmin(step, out[c] / _rate(model, c, floor))
    step = _fmin(step, 0.5 * length_now / rho)
    step = _fmin(step, MAX_STEP)
    if not step > 0.0:  # numpy.fmax(step, 0) (a NaN step becomes 0)
        step = 0.0
    return step * SAFETY


@_helper
def recovery_step(
    model: NDArray[np.float64], out: NDArray[np.float64], moving: int | None
) -> float:
    """Length over which a violated pose stays violated: the most violated constraint, in
    Lipschitz units, cannot climb back to zero within |m_c| / L_c; joint-angle bounds use half
    the current shortest leg, and the step keeps every leg at least that long. The collision
    margin is a lower bound within its gap of the true one (exact except in deep contact with a
    box or cylinder): its recovery starts from value + gap, an upper bound. ``moving`` as in
    :func:`certified_step`."""
    if moving is not None:
        return _recovery_step_moving(model, out)
    rho: float = model[RHO]
    floor: float = 0.5 * out[OUT_SHORTEST]
    recover = 0.0
    for c in range(int(model[ROWS_USED])):
        margin = out[c] + out[OUT_GAP] if c == COLLISION else out[c]
        value = -margin / _rate(model, c, floor) if margin < 0.0 else 0.0
        if value > recover or value != value:
            recover = value
    return min(recover, floor / rho) * SAFETY


@_inline
def _fmin_select(a: float, b: float) -> float:
    """:func:`_fmin` as one expression (no early return), so that loops over probes vectorise."""
    return b if a != a else (a if b != b else (a if a < b else b))


@_helper
def _block_decisions(
    model: NDArray[np.float64],
    work: NDArray[np.float64],
    size: int,
    used: int,
    fixed: bool,
    estimates: NDArray[np.float64],
    verdicts: NDArray[np.float64],
    steps: NDArray[np.float64],
    lengths: NDArray[np.float64],
) -> None:
    """What :func:`search_rays` reads from each probe of a block, row by row over the block.

    ``work`` holds the margins of ``size`` probes as :func:`_check_block` leaves them (rows
    0..used − 1). Writes, each (BLOCK,), for probe m < size: ``estimates[m]`` = :func:`_estimate`,
    ``verdicts[m]`` 1.0 where every margin is ≥ 0 (:func:`_feasible`) else 0.0, and with fixed
    base joints ``steps[m]`` = :func:`certified_step` (``lengths`` (2·BLOCK,): scratch). Each
    is the per-probe function's arithmetic, the same operations in the same order (a NaN start
    is what :func:`_fmin` turns into its other argument), so the values are the same bit for
    bit; the loops run over the probes of one row at a time, without calls, and vectorise.
    Steps are computed for every probe and read for the feasible probes of the march only.
    """
    for m in range(size):
        value = work[m]
        estimates[m] = value / model[ESTIMATE_RATE]
        verdicts[m] = 1.0 if value >= 0.0 else 0.0
    for c in range(1, used):
        rate = model[ESTIMATE_RATE + c]
        for m in range(size):
            value = work[c * BLOCK + m]
            ratio = value / rate
            best = estimates[m]
            estimates[m] = ratio if (ratio < best) | (ratio != ratio) else best
            verdicts[m] = verdicts[m] if value >= 0.0 else 0.0
    if not fixed:
        return
    rho = model[RHO]
    length_min = model[LENGTH_FLOOR]
    for m in range(size):
        length_now = length_min + max(work[LEG_LENGTH * BLOCK + m], 0.0)
        lengths[m] = length_now
        lengths[BLOCK + m] = max(length_min, 0.5 * length_now)  # the leg floor of the rates
        steps[m] = np.nan
    for c in range(used):
        constant = model[RAY_CONSTANT + c]
        turn = model[RAY_TURN + c]
        if turn != 0.0:  # _rate: the turn term only where its coefficient is not 0
            for m in range(size):
                rate = constant + turn / lengths[BLOCK + m]
                steps[m] = _fmin_select(steps[m], work[c * BLOCK + m] / rate)
        else:
            for m in range(size):
                steps[m] = _fmin_select(steps[m], work[c * BLOCK + m] / constant)
    for m in range(size):
        step = _fmin_select(steps[m], 0.5 * lengths[m] / rho)
        step = _fmin_select(step, MAX_STEP)
        steps[m] = (step if step > 0.0 else 0.0) * SAFETY  # a NaN step becomes 0


# Phases of a ray in search_rays.
_MARCH, _GUESS, _PLUS, _DONE = 0, 1, 2, 3
