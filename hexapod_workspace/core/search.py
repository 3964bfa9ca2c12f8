"""Boundary search along families of rays in orientation space, certified by Lipschitz bounds.

Every workspace algorithm reduces to: along many rays at once (a ray is a one-parameter
family of orientations, parameter ``s`` in rad), find the *first* ``s`` where a constraint is
violated, to a tolerance. Bisection alone cannot do that: it finds *a* crossing, and steps over
a violated band that lies between two feasible samples.

Why this search does not step over a violated band
--------------------------------------------------
Along every ray used here the platform turns at an angular rate ω ≤ 1 rad per unit ``s``:

* a tilt ray from the origin, ``(φ, s, ψ)`` with φ, ψ fixed, is a rotation about a fixed
  horizontal axis (ω = 1);
* a straight ray in the cylindrical picture at fixed ψ, ``(x, y) = c + s·u``, moves the tilt
  ``exp([w])`` with ``w = (−y, x, 0)``; the differential of the SO(3) exponential has norm ≤ 1,
  so ω ≤ |dw/ds| = 1;
* a torsion ray ``(φ, θ, s)`` is a rotation about the tool axis (ω = 1).

With ρ = max_i |b_i| (platform joint radius about the tool tip), each platform joint moves at
most ρ per unit ``s`` and each margin changes at most at a known rate (a Lipschitz bound):

==================== =========================== ==============================================
constraint           bound on |d margin / ds|    why
==================== =========================== ==============================================
``leg_length``       ρ                           |dL_i/ds| = |ω × R b_i| ≤ ρ
``base_joint``       ρ / ℓ_floor                 |dn_i/ds| ≤ |dL_i/ds| / ℓ_i
``platform_joint``   1 + ρ / ℓ_floor             R·jB_i turns at ω ≤ 1, plus |dn_i/ds|
``leg_interference`` 2ρ                          each segment moves by ≤ ρ (Hausdorff), two move
==================== =========================== ==============================================

``ℓ_floor`` is a lower bound on the leg lengths over the step: the smallest ℓmin (valid because
the step never lets the leg-length margin reach zero), and at least half of the current shortest
leg (the step is also limited to keep that true). From a feasible point with margins m_c, no
margin can reach zero within ``min_c m_c / L_c``: a step of that length is *certified*. The
search takes certified steps, so it cannot skip a violated band, except where every margin is
already within ``L_c · h_min`` of zero: there it steps by ``h_min`` (default 1e-3 rad) and
bands narrower than ``h_min`` could be missed. Once a violated sample is met, bisection
between the last feasible sample and it locates the crossing to the tolerance; the reported
point is the feasible end, so every reported boundary point satisfies all four constraints.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .constraints import inverse_kinematics, pose_margins, relative_margins
from .manipulator import Manipulator
from .rotations import tt_to_matrix

__all__ = ["DEFAULT_MIN_STEP", "RaySearch", "RaySearchResult"]

#: Shortest step of the march (rad): below it, steps are no longer Lipschitz-certified.
DEFAULT_MIN_STEP = 1e-3
#: Longest step of the march (rad); steps are certified, this only bounds a single jump.
MAX_STEP = 1.0
#: Shrink certified steps by this factor so that rounding cannot land on a violated point.
SAFETY = 1.0 - 1e-9

#: angles_at(ray_indices (n,), s (n,)) -> Tilt-and-Torsion angles (n, 3), rad.
AnglesAt = Callable[[NDArray[np.int64], NDArray[np.float64]], NDArray[np.float64]]


@dataclass(frozen=True)
class RaySearchResult:
    """Outcome of a search along n rays.

    Attributes
    ----------
    feasible : ndarray, shape (n,)
        Last feasible parameter found (the reported boundary), rad.
    violated : ndarray, shape (n,)
        First violated parameter found, ``feasible < violated ≤ feasible + tolerance``;
        ``inf`` when the ray reached its end without a violation.
    limiting : ndarray, shape (n,), int
        Index into CONSTRAINT_NAMES of the most violated constraint at ``violated``
        (−1 when none was met).
    start_feasible : ndarray, shape (n,), bool
        Whether the ray's start point was feasible (when not, ``feasible`` is NaN).
    evaluations : int
        Poses evaluated.
    """

    feasible: NDArray[np.float64]
    violated: NDArray[np.float64]
    limiting: NDArray[np.int64]
    start_feasible: NDArray[np.bool_]
    evaluations: int


class RaySearch:
    """First-violation search along rays for one manipulator at one position.

    Parameters
    ----------
    manipulator : Manipulator
    position : ndarray, shape (3,)
        Tool-tip position, base frame, m.
    min_step : float
        ``h_min`` of the module documentation, rad.
    """

    def __init__(
        self, manipulator: Manipulator, position: NDArray[np.float64], min_step: float = 1e-3
    ) -> None:
        self.manipulator = manipulator
        self.position = np.asarray(position, dtype=np.float64)
        self.min_step = float(min_step)
        self.rho = float(np.max(np.linalg.norm(manipulator.platform_joints, axis=1)))
        self.length_min = float(np.min(manipulator.leg_length_min))
        self.evaluations = 0

    # ------------------------------------------------------------------ evaluation
    def margins(self, angles: NDArray[np.float64]) -> NDArray[np.float64]:
        """The four margins of poses (n, 3) at the search position; shape (4, n)."""
        self.evaluations += angles.shape[0]
        return pose_margins(self.manipulator, tt_to_matrix(angles), self.position).margins

    def certified_step(self, margins: NDArray[np.float64]) -> NDArray[np.float64]:
        """Length over which no margin can reach zero, from feasible margins (4, n); (n,)."""
        # Shortest leg now: both leg-length margins are >= m_len, so l >= l_min + m_len.
        length_now = self.length_min + np.maximum(margins[0], 0.0)
        floor = np.maximum(self.length_min, 0.5 * length_now)
        rho = self.rho
        # fmin ignores NaN; +inf (interference disabled) never limits.
        step = np.fmin(margins[0] / rho, margins[1] * floor / rho)
        np.fmin(step, margins[2] / (1.0 + rho / floor), out=step)
        np.fmin(step, margins[3] / (2.0 * rho), out=step)
        np.fmin(step, 0.5 * length_now / rho, out=step)
        np.fmin(step, MAX_STEP, out=step)
        return np.fmax(step, 0.0, out=step) * SAFETY

    def recovery_step(
        self, angles: NDArray[np.float64], margins: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Length over which violated poses (n, 3) stay violated; margins (4, n); shape (n,).

        The most violated constraint, in Lipschitz units, cannot climb back to zero within
        ``|m_c| / L_c``; the joint-angle bounds use the current shortest leg (from the inverse
        kinematics) and a step that keeps every leg at least half that long.
        """
        lengths = inverse_kinematics(self.manipulator, tt_to_matrix(angles), self.position).lengths
        floor = 0.5 * lengths.min(axis=1)
        rho = self.rho
        bounds = np.stack(
            [
                np.full_like(floor, rho),
                rho / floor,
                1.0 + rho / floor,
                np.full_like(floor, 2.0 * rho),
            ]
        )
        with np.errstate(invalid="ignore"):
            recover = np.where(margins < 0.0, -margins / bounds, 0.0).max(axis=0)
        return np.minimum(recover, floor / rho) * SAFETY

    def distance_estimate(self, margins: NDArray[np.float64]) -> NDArray[np.float64]:
        """A continuous signed estimate of the distance to the boundary along a ray (rad):
        min_c m_c / L_c with fixed Lipschitz constants; ≥ 0 exactly when feasible."""
        floor = max(self.length_min, 1e-3)
        rho = self.rho
        scale = np.array([rho, rho / floor, 1.0 + rho / floor, 2.0 * rho])[:, None]
        return np.min(margins / scale, axis=0)

    def most_violated(self, margins: NDArray[np.float64]) -> NDArray[np.int64]:
        """Index of the most violated constraint (relative units) per pose; margins (4, n)."""
        return relative_margins(self.manipulator, margins).argmin(axis=0)

    # ------------------------------------------------------------------ search
    def first_violation(
        self,
        angles_at: AnglesAt,
        count: int,
        s_end: NDArray[np.float64] | float,
        tolerance: float,
        s_start: NDArray[np.float64] | float = 0.0,
    ) -> RaySearchResult:
        """Find, along ``count`` rays, the first violated parameter in [s_start, s_end].

        Parameters
        ----------
        angles_at : callable
            ``angles_at(ray_indices, s)`` gives the T&T angles (n, 3) of rays at parameters s.
        count : int
            Number of rays.
        s_end : float or ndarray, shape (count,)
            End of each ray, rad.
        tolerance : float
            Bracket width at which bisection stops, rad.
        s_start : float or ndarray, shape (count,)
            Start of each ray (normally a feasible point), rad.

        Returns
        -------
        RaySearchResult
        """
        start_count = self.evaluations
        s_end = np.broadcast_to(np.asarray(s_end, dtype=np.float64), (count,)).copy()
        s = np.broadcast_to(np.asarray(s_start, dtype=np.float64), (count,)).copy()
        feasible = np.full(count, np.nan)
        violated = np.full(count, np.inf)
        # Signed distance estimates at the feasible and violated ends, for the secant phase.
        feasible_value = np.zeros(count)
        violated_value = np.zeros(count)
        limiting = np.full(count, -1, dtype=np.int64)
        start_feasible = np.ones(count, dtype=bool)
        first = np.ones(count, dtype=bool)
        active = np.arange(count)
        bracket: list[NDArray[np.int64]] = []
        while active.size:
            margins = self.margins(angles_at(active, s[active]))
            bad = ~np.all(margins >= 0.0, axis=0)
            estimate = self.distance_estimate(margins)
            if np.any(bad):
                rays = active[bad]
                violated[rays] = s[rays]
                violated_value[rays] = estimate[bad]
                limiting[rays] = self.most_violated(margins[:, bad])
                start_feasible[rays[first[rays]]] = False
                bracket.append(rays[~first[rays]])
            good = active[~bad]
            first[active] = False
            feasible[good] = s[good]
            feasible_value[good] = estimate[~bad]
            step = np.maximum(self.certified_step(margins[:, ~bad]), self.min_step)
            done = s[good] >= s_end[good]
            s[good] = np.minimum(s[good] + step, s_end[good])
            active = good[~done]
        rays = np.concatenate(bracket) if bracket else np.zeros(0, dtype=np.int64)
        low, high = feasible[rays], violated[rays]
        low_value, high_value = feasible_value[rays], violated_value[rays]
        bisect = np.zeros(rays.size, dtype=bool)
        open_ = np.flatnonzero(high - low > tolerance)
        while open_.size:
            width = high[open_] - low[open_]
            # Secant estimate of the crossing of the signed distance estimate; midpoint where
            # the last secant step failed to halve the bracket (safeguard).
            with np.errstate(divide="ignore", invalid="ignore"):
                secant = (
                    low[open_] + low_value[open_] / (low_value[open_] - high_value[open_]) * width
                )
            guess = np.where(bisect[open_] | ~np.isfinite(secant), low[open_] + 0.5 * width, secant)
            half = 0.25 * tolerance
            guess = np.clip(guess, low[open_] + half, high[open_] - half)
            # Probe on both sides of the guess: when it is right, the bracket is done.
            probes = np.concatenate([guess - half, guess + half])
            rays_twice = np.concatenate([rays[open_], rays[open_]])
            margins = self.margins(angles_at(rays_twice, probes))
            values = self.distance_estimate(margins)
            bad = ~np.all(margins >= 0.0, axis=0)
            count = open_.size
            minus_bad, plus_bad = bad[:count], bad[count:]
            minus, plus = guess - half, guess + half
            new_low = np.where(minus_bad, low[open_], np.where(plus_bad, minus, plus))
            new_high = np.where(minus_bad, minus, np.where(plus_bad, plus, high[open_]))
            new_low_value = np.where(
                minus_bad, low_value[open_], np.where(plus_bad, values[:count], values[count:])
            )
            new_high_value = np.where(
                minus_bad, values[:count], np.where(plus_bad, values[count:], high_value[open_])
            )
            which = np.where(minus_bad, 0, np.where(plus_bad, 1, -1))
            hit = which >= 0
            if np.any(hit):
                columns = np.where(which == 1, count, 0) + np.arange(count)
                limiting[rays[open_][hit]] = self.most_violated(margins[:, columns[hit]])
            bisect[open_] = (new_high - new_low) > 0.5 * width
            low[open_], high[open_] = new_low, new_high
            low_value[open_], high_value[open_] = new_low_value, new_high_value
            open_ = open_[(new_high - new_low) > tolerance]
        feasible[rays], violated[rays] = low, high
        return RaySearchResult(
            feasible, violated, limiting, start_feasible, self.evaluations - start_count
        )
