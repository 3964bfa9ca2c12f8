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

# isort: split
import numpy as np
from numpy.typing import NDArray

from ..constraints.table import COLLISION, N_CONSTRAINTS
from .blocks import _BLOCK_ROWS, BLOCK, _check_block
from .layout import (
    ARCH,
    COLLISION_ON,
    ROWS_USED,
)
from .lazy_collision import (
    LAZY_SLACK,
    _lazy_collision,
    _lazy_rate,
    _scan_pose,
    _turn_between,
)
from .pose import (
    OUT_SIZE,
    SCRATCH_ROWS,
    _feasible,
    _limiting_constraint,
)
from .steps import (
    _DONE,
    _GUESS,
    _MARCH,
    _PLUS,
    KIND_CYLINDRICAL,
    KIND_TT,
    MAX_STEP,
    SAFETY,
    _block_decisions,
    _estimate,
    _ray_angles,
    certified_step,
    recovery_step,
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
