"""Search kernels (numba): the certified march + secant/bisection of
:mod:`hexapod_workspace.core.workspaces.search` along whole families of rays, and the torsion scan.

Every ray's probes are evaluated together with the block kernel of
:mod:`hexapod_workspace.core.kernels.margins`, so that a search pays no per-call overhead per step.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

from ..base.jit import Collide
from ..base.jit import entry_points as _entry_points

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import helper as _helper
from ..base.jit import inline as _inline

# isort: split
import numpy as np
from numpy.typing import NDArray

from ..constraints.table import COLLISION, IK, LEG_LENGTH, N_CONSTRAINTS, TRANSMISSION
from .blocks import _BLOCK_ROWS, BLOCK, _check_block
from .collision import SEARCH_RATE
from .layout import (
    ARCH,
    COLLISION_ON,
    ESTIMATE_RATE,
    LENGTH_FLOOR,
    MODEL_SIZE,
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
    OUT_SIZE,
    SCRATCH_ROWS,
    _feasible,
    _limiting_constraint,
    _pose,
)
from .trig import _tt_matrix

__all__ = [
    "KIND_CYLINDRICAL",
    "KIND_TT",
    "MAX_STEP",
    "SAFETY",
    "SearchKernels",
    "search_entry_points",
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
    """One sample of :func:`torsion_scan` into ``out``; returns what the scan knows of the
    collision margin there, a lower bound of it: ``bound`` where that stands in for the margin
    (``plain`` is the model with its scene off: every other margin evaluated), the evaluated
    margin otherwise (``bound`` −inf: always evaluated). Acceptance (derivation in
    :func:`torsion_scan`): the scan reads from a sample its verdict, its certified step where
    feasible (marching, ``march``) and its recovery step where violated; bisecting, only the
    verdict."""
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


class SearchKernels(NamedTuple):
    """The compiled search entry points of one kernel variant (:func:`search_entry_points`)."""

    search_rays: Callable[..., tuple[int, int]]
    torsion_scan: Callable[..., tuple[int, bool]]


def search_entry_points(
    moving: int | None,
    cranks: int | None,
    singular: int | None,
    signatures: dict[str, tuple[object, ...]] | None = None,
) -> SearchKernels:
    """The search entry points compiled for one set of switches, each with the ``collide``
    switch as its last argument (as
    :func:`~hexapod_workspace.core.kernels.margins.margin_entry_points`)."""

    decorate = _entry_points(signatures)

    @decorate("search_rays")
    def search_rays(
        model: NDArray[np.float64],
        position: NDArray[np.float64],
        kind: int,
        origins: NDArray[np.float64],
        directions: NDArray[np.float64],
        s_start: NDArray[np.float64],
        s_end: NDArray[np.float64],
        tolerance: float,
        min_step: float,
        feasible: NDArray[np.float64],
        violated: NDArray[np.float64],
        limiting: NDArray[np.int64],
        start_feasible: NDArray[np.bool_],
        lazy: bool,
        collide: Collide,
    ) -> tuple[int, int]:
        """First violation along rays (the algorithm of core.search, all rays in lockstep).

        Each round takes the next probe of every unfinished ray and evaluates them together with
        the vectorised block kernel; per ray, the sequence of probes is that of a search along it
        alone: a march with certified steps, then secant guesses on the distance estimate
        (bisection when a secant step fails to halve the bracket), two probes around each guess,
        the second only when the first is feasible.

        Parameters
        ----------
        model : ndarray, shape (MODEL_SIZE,)
        position : ndarray, shape (3,)
            m, base frame.
        kind : int
            KIND_TT or KIND_CYLINDRICAL.
        origins, directions : ndarray, shape (n, 3)
            Ray i is origins[i] + s·directions[i].
        s_start, s_end : ndarray, shape (n,)
            Parameter range of each ray, rad.
        tolerance, min_step : float
            Bracket width at which the search stops; shortest march step (rad).
        feasible, violated, limiting, start_feasible : ndarray, shape (n,)
            Outputs, see core.search.RaySearchResult.
        lazy : bool
            Evaluate the collision margin only where it can change the search (above).

        Returns
        -------
        evaluations : int
            Poses evaluated.
        collision_evaluations : int
            Poses at which the collision margin was evaluated (``evaluations`` with a scene and
            ``lazy=False``, 0 without a scene).

        Notes
        -----
        *Lazy collision margin.* The collision margin costs tens of times the others (a signed
        distance per pair of bodies) and along most of a ray decides nothing, so it is evaluated
        only where it could. With fixed base joints it is Lipschitz in the orientation at the
        search position with rate L_c = ρ_c per rad (``_lazy_rate``): from its value m₀ at an
        *anchor* orientation R₀ (an evaluated probe: itself a lower bound of the true margin),

            m_c(R) ≥ m₀ − L_c·∠(R₀ᵀR)                                                  (1)

        for every orientation R, ∠ the rotation angle (``_turn_between``); along a ray
        ∠ ≤ |s − s₀| (ω ≤ 1). The bound tried first is the ray's own anchor, m₀ − L_c·|s − s₀| (no
        trigonometry); a lower bound accepted at s is itself an anchor of (1) for the later probes.
        Then the last evaluated poses of the rays on either side (two each way; a workspace's rays
        come in order, a fraction of a degree apart) and of the most recently evaluated ray, by
        their rotation angle. Each bound is lowered by ``LAZY_SLACK``. With moving base joints
        (pus/rus) the rate depends on the transmission, which is only known along certified steps:
        only the ray's own anchor is used, with L_c(τ_lim), in the march, dropped after a step
        floored at ``min_step``; the secant/bisection phase evaluates every probe.

        Each round evaluates its probes block by block without the collision margin (the block
        kernel on the model with its scene off), then walks the block's probes in order: where
        ``_lazy_collision`` accepts a bound it stands in for the margin, else the probe is evaluated
        with the scene on (the block kernel on that pose, in planes of its own: the margin of a
        search without laziness) and becomes an anchor; then the probe is decided.
        **Why nothing is missed**: a probe whose bound is > 0 is collision-free (the bound is below
        the true margin), and a march step taken from the bound is certified for the collision
        margin exactly as one taken from the margin itself (a smaller lower bound only shortens
        it), so the march's guarantee (no violated band wider than ``min_step`` stepped over) is
        unchanged. Violated probes and the secant/bisection phase are decided exactly as with the
        margin evaluated (same verdict, estimate and limiting constraint). The march may take a few
        more, shorter steps (each at least ``LAZY_STEP`` of the step from the evaluated margin the
        bound comes from), so a ray's probes can differ from a search with ``lazy=False``; both
        answers are certified, and agree to the tolerance where the boundary crosses once
        (``test/test_collision_lazy.py`` compares them and checks both against dense sampling).
        """
        count = origins.shape[0]
        phase = np.zeros(count, dtype=np.int64)
        s = s_start.copy()
        low_value = np.zeros(count)
        high_value = np.zeros(count)
        minus_value = np.zeros(count)
        minus = np.zeros(count)
        plus = np.zeros(count)
        width = np.zeros(count)
        bisect = np.zeros(count, dtype=np.bool_)
        first = np.ones(count, dtype=np.bool_)
        for ray in range(count):
            feasible[ray] = np.nan
            violated[ray] = np.inf
            limiting[ray] = -1
            start_feasible[ray] = True
        rays = np.empty(count, dtype=np.int64)
        angles = np.empty((count, 3))
        work = np.empty(_BLOCK_ROWS * BLOCK)
        scratch = np.empty((SCRATCH_ROWS, 6))
        out = np.empty(OUT_SIZE)
        r = np.empty(9)
        half = 0.25 * tolerance
        evaluations = 0
        collisions = 0
        # Estimates, verdicts and (fixed base) certified steps of a block's probes, computed for the
        # whole block (_block_decisions) where nothing changes a margin after the block kernel.
        estimates = np.empty(BLOCK)
        verdicts = np.empty(BLOCK)
        steps = np.empty(BLOCK)
        lengths = np.empty(2 * BLOCK)
        fixed = model[ARCH] == 0.0
        # Lazy collision margin: the model with its scene off, the margins of every probe of a
        # round, and per ray the last evaluated collision margin (anchor_s NaN: none usable).
        scene_on = model[COLLISION_ON] != 0.0
        rate_c = _lazy_rate(model, moving, collide) if lazy else 0.0
        lazy = rate_c > 0.0
        everywhere = model[ARCH] == 0.0  # (1) holds for every s, not only along certified steps
        copy = model.copy()  # (a copy of a few hundred floats per call)
        if lazy:
            copy[COLLISION_ON] = 0.0
        # Typed as the model (read-only): numba unifies the two array types, so the block
        # kernel is compiled once for both (the copy alone would be a second, writable type).
        plain = model
        if lazy:
            plain = copy
        single = np.empty(_BLOCK_ROWS * BLOCK if lazy else 0)  # the lazy pass's one-pose planes
        single_out = np.empty(
            OUT_SIZE
        )  # and its one-pose scratch (`out` holds the probe's margins)
        at = np.empty(count)
        anchor_s = np.full(count, np.nan)  # per ray: s, a lower bound of the margin there and
        anchor_value = np.zeros(count)  # the evaluated margin that bound comes from
        anchor_reference = np.zeros(count)
        posed = np.zeros(count, dtype=np.bool_)  # per ray: its last evaluated pose and margin
        posed_value = np.zeros(count)
        anchor_r = np.zeros((count, 9))
        rotation = np.empty(9)
        recent = 0
        # Rows in use: the block kernel writes +inf in the others for every pose, and so do
        # their slots of `out` here, so reading only these rows decides every probe as before.
        used = int(model[ROWS_USED])
        for slot in range(N_CONSTRAINTS):
            out[slot] = np.inf
        while True:
            # The next probe of every unfinished ray.
            probes = 0
            for ray in range(count):
                state = phase[ray]
                if state == _DONE:
                    continue
                if state == _MARCH:
                    probe = s[ray]
                elif state == _GUESS:
                    low, high = feasible[ray], violated[ray]
                    if not high - low > tolerance:
                        phase[ray] = _DONE
                        continue
                    width[ray] = high - low
                    secant = low + low_value[ray] / (low_value[ray] - high_value[ray]) * width[ray]
                    if bisect[ray] or not math.isfinite(secant):
                        guess = low + 0.5 * width[ray]
                    else:
                        guess = secant
                    guess = min(max(guess, low + half), high - half)
                    minus[ray] = guess - half
                    plus[ray] = guess + half
                    probe = minus[ray]
                else:
                    probe = plus[ray]
                _ray_angles(kind, origins[ray], directions[ray], probe, angles, probes)
                rays[probes] = ray
                at[probes] = probe
                probes += 1
            if probes == 0:
                break
            evaluations += probes
            if scene_on and not lazy:
                collisions += probes
            # Margins of every probe (the collision margin left out where lazy: the lazy pass below
            # puts a bound in its place or evaluates it), each probe decided while its block's
            # planes are in the cache. A ray has one probe per round; a decision changes only its
            # own ray's state, and a probe's lazy bound reads its own ray's anchor and phase and
            # the evaluated poses of rays, which decisions leave alone: probes decided block by
            # block go exactly as if the whole round were evaluated before any was decided.
            for block in range(0, probes, BLOCK):
                size = min(BLOCK, probes - block)
                _check_block(
                    plain,
                    angles,
                    position,
                    block,
                    size,
                    work,
                    scratch,
                    out,
                    r,
                    moving,
                    cranks,
                    collide,
                    singular,
                )
                if not lazy:
                    _block_decisions(
                        model, work, size, used, fixed, estimates, verdicts, steps, lengths
                    )
                for m in range(size):
                    n = block + m
                    ray = rays[n]
                    for slot in range(used):
                        out[slot] = work[slot * BLOCK + m]
                    if collide is not None and lazy:  # (left out without a scene)
                        collision = np.nan
                        placed = False
                        march = phase[ray] == _MARCH
                        # The ray's own anchor first (no trigonometry: the turn is at most |Δs|).
                        since = anchor_s[ray]
                        if since == since and (everywhere or march):
                            bound = anchor_value[ray] - rate_c * abs(at[n] - since) - LAZY_SLACK
                            if _lazy_collision(
                                model, out, bound, anchor_reference[ray], march, moving
                            ):
                                collision = bound
                                placed = True
                        if not placed and everywhere:  # the evaluated poses of nearby rays
                            _tt_matrix(angles[n, 0], angles[n, 1], angles[n, 2], rotation)
                            bound = -np.inf
                            reference = np.inf
                            for candidate in (ray, recent, ray - 1, ray + 1, ray - 2, ray + 2):
                                if 0 <= candidate < count and posed[candidate]:
                                    turn = _turn_between(anchor_r, candidate, rotation)
                                    value = posed_value[candidate] - rate_c * turn
                                    if value > bound:
                                        bound = value
                                        reference = posed_value[candidate]
                            bound -= LAZY_SLACK
                            if _lazy_collision(model, out, bound, reference, march, moving):
                                collision = bound
                                placed = True
                                anchor_s[ray] = at[n]  # a lower bound at s is an anchor of (1) too
                                anchor_value[ray] = bound
                                anchor_reference[ray] = reference
                        if not placed:
                            # Evaluated: the block kernel on this one pose (the margin of a
                            # search without laziness) in planes of its own, which becomes the
                            # ray's anchor.
                            _check_block(
                                model,
                                angles,
                                position,
                                n,
                                1,
                                single,
                                scratch,
                                single_out,
                                r,
                                moving,
                                cranks,
                                collide,
                                singular,
                            )
                            collision = single[COLLISION * BLOCK]
                            usable = collision == collision
                            anchor_s[ray] = at[n] if usable else np.nan
                            anchor_value[ray] = collision
                            anchor_reference[ray] = collision
                            if everywhere:
                                for i in range(9):
                                    anchor_r[ray, i] = rotation[i]
                                posed[ray] = usable
                                posed_value[ray] = collision
                                if usable:
                                    recent = ray
                            collisions += 1
                        out[COLLISION] = collision
                        ok = _feasible(out, used)  # decided from `out`, its collision slot placed
                        estimate = _estimate(model, out)
                    else:
                        ok = verdicts[m] != 0.0
                        estimate = estimates[m]
                    state = phase[ray]
                    if state == _MARCH:
                        if not ok:
                            violated[ray] = s[ray]
                            high_value[ray] = estimate
                            limiting[ray] = _limiting_constraint(model, out)
                            if first[ray]:
                                start_feasible[ray] = False
                                phase[ray] = _DONE
                            else:
                                phase[ray] = _GUESS
                            continue
                        first[ray] = False
                        feasible[ray] = s[ray]
                        low_value[ray] = estimate
                        certified = (
                            steps[m] if fixed and not lazy else certified_step(model, out, moving)
                        )
                        step = max(certified, min_step)
                        if step > certified and not everywhere:
                            anchor_s[ray] = np.nan  # (1) does not reach over an uncertified step
                        if s[ray] >= s_end[ray]:
                            phase[ray] = _DONE
                        else:
                            s[ray] = min(s[ray] + step, s_end[ray])
                    elif state == _GUESS:  # the probe below the guess
                        if not ok:
                            violated[ray] = minus[ray]
                            high_value[ray] = estimate
                            limiting[ray] = _limiting_constraint(model, out)
                            bisect[ray] = (violated[ray] - feasible[ray]) > 0.5 * width[ray]
                        else:
                            minus_value[ray] = estimate
                            phase[ray] = _PLUS
                    else:  # the probe above the guess
                        if not ok:
                            feasible[ray] = minus[ray]
                            low_value[ray] = minus_value[ray]
                            violated[ray] = plus[ray]
                            high_value[ray] = estimate
                            limiting[ray] = _limiting_constraint(model, out)
                        else:
                            feasible[ray] = plus[ray]
                            low_value[ray] = estimate
                        bisect[ray] = (violated[ray] - feasible[ray]) > 0.5 * width[ray]
                        phase[ray] = _GUESS
        return evaluations, collisions

    @decorate("torsion_scan")
    def torsion_scan(
        model: NDArray[np.float64],
        position: NDArray[np.float64],
        phi: float,
        theta: float,
        min_step: float,
        max_step: float,
        tolerance: float,
        edges: NDArray[np.float64],
        rising: NDArray[np.bool_],
        lazy: bool,
        collide: Collide,
    ) -> tuple[int, bool]:
        """Feasible-torsion transitions over ψ ∈ [−π, π] for one tool direction (φ, θ).

        Scans with certified steps (recovery steps from violated samples), clipped to
        [min_step, max_step], then bisects every transition, all of them together, until the widest
        bracket is within the tolerance (as core.orientation.torsion_range did).

        Parameters
        ----------
        edges, rising : ndarray, shape (K,)
            Outputs: the feasible end of each transition, and whether it goes infeasible → feasible.
            K must be at least the number of transitions (ceil(2π / min_step) + 1 is enough).
        lazy : bool
            Bound the collision margin from the samples before instead of evaluating it where the
            bound decides the sample as the margin would (below); False evaluates it everywhere.

        Returns
        -------
        count : int
            Number of transitions written (−1 − count when the outputs were too short).
        start_ok : bool
            Whether ψ = −π is feasible.

        Notes
        -----
        *Lazy collision margin* (fixed base joints only, as the ray searches' ``_lazy_rate``).
        At fixed (φ, θ) and position, R(ψ) = R(ψ₀)·Rz(ψ − ψ₀) (the tilt-and-torsion angles turn
        the platform about the tool axis by Δψ; checked numerically in the tests), so between two
        samples the platform turns by |ψ − ψ₀| rad about the fixed tool centre point, and by the
        collision margin's rate bound at a fixed position (ρ_c per rad, ``_lazy_rate``)

            m(ψ) ≥ m(ψ₀) − ρ_c·|ψ − ψ₀|.                                                    (1)

        With m₀ the kernel's value at ψ₀ (itself ≤ the true margin, within GJK's tolerance) or a
        bound already derived from (1), ``bound = m₀ − ρ_c·|Δψ| − LAZY_SLACK`` is below the value an
        evaluation would return at ψ. The scan reads from a sample its verdict, its certified step
        (feasible) or its recovery step (violated). Where ``bound`` > 0: the verdict is that of the
        margin (the collision row is satisfied either way); on a violated sample the recovery step
        reads only the negative margins (collision's is positive either way), so it is the same; on
        a feasible sample the certified step from ``bound`` is certified (bound ≤ m) and is taken
        when it keeps ``LAZY_STEP`` of the step from m₀ (``_lazy_collision``), otherwise the
        margin is evaluated. Bisecting, only the verdict is read: the bound at the middle is the
        larger of (1) from the two ends of the bracket. A NaN margin is always evaluated. The
        transitions found are certified as before (every step is certified from lower bounds of
        the margins); the samples can differ from an eager scan's (shorter steps where the bound
        is taken), so the edges agree to the tolerance, as the tests check against dense sampling.
        """
        scratch = np.empty((SCRATCH_ROWS, 6))
        out = np.empty(OUT_SIZE)
        r = np.empty(9)
        capacity = edges.shape[0]
        low = np.empty(capacity)
        high = np.empty(capacity)
        # Lower bounds of the collision margin at low and high (the lazy scan's anchors).
        low_bound = np.empty(capacity)
        high_bound = np.empty(capacity)
        rate_c = 0.0
        if moving is None and lazy:
            rate_c = _lazy_rate(model, moving, collide)
        copy = model.copy()
        copy[COLLISION_ON] = 0.0
        # ``plain`` is the copy, typed as the model (read-only): the branch, always taken but
        # not decided at compile time, makes numba unify the two array types, so _pose is
        # compiled once for both (the copy alone would be a second, writable type).
        plain = model
        if rate_c == rate_c:  # the rate is finite (never NaN)
            plain = copy
        count = 0
        psi = -math.pi
        previous_ok = False
        start_ok = False
        first = True
        previous = psi
        known = -np.inf  # a lower bound of the collision margin at `previous`
        reference = np.inf  # the evaluated margin that bound comes from
        while True:
            _tt_matrix(phi, theta, psi, r)
            bound = known - rate_c * (psi - previous) - LAZY_SLACK if rate_c > 0.0 else -np.inf
            here = _scan_pose(
                model,
                plain,
                r,
                position,
                scratch,
                out,
                bound,
                reference,
                True,
                moving,
                cranks,
                collide,
                singular,
            )
            if here != bound:
                reference = here
            ok = _feasible(out, N_CONSTRAINTS)
            if first:
                start_ok = ok
            elif ok != previous_ok:
                if count >= capacity:
                    return -1 - count, start_ok
                low[count] = previous
                high[count] = psi
                low_bound[count] = known
                high_bound[count] = here
                rising[count] = ok
                count += 1
            first = False
            previous_ok = ok
            previous = psi
            known = here
            if psi >= math.pi:
                break
            step = certified_step(model, out, moving) if ok else recovery_step(model, out, moving)
            psi = min(psi + min(max(step, min_step), max_step), math.pi)
        while count > 0:
            widest = 0.0
            for k in range(count):
                widest = max(widest, high[k] - low[k])
            if not widest > tolerance:
                break
            for k in range(count):
                middle = 0.5 * (low[k] + high[k])
                _tt_matrix(phi, theta, middle, r)
                bound = -np.inf
                if rate_c > 0.0:
                    bound = max(
                        low_bound[k] - rate_c * (middle - low[k]),
                        high_bound[k] - rate_c * (high[k] - middle),
                    )
                    bound -= LAZY_SLACK
                here = _scan_pose(
                    model,
                    plain,
                    r,
                    position,
                    scratch,
                    out,
                    bound,
                    np.inf,
                    False,
                    moving,
                    cranks,
                    collide,
                    singular,
                )
                # Keep the transition inside [low, high]: the side matching the start state moves.
                if _feasible(out, N_CONSTRAINTS) != rising[k]:
                    low[k] = middle
                    low_bound[k] = here
                else:
                    high[k] = middle
                    high_bound[k] = here
        for k in range(count):
            edges[k] = high[k] if rising[k] else low[k]
        return count, start_ok

    return SearchKernels(search_rays, torsion_scan)
