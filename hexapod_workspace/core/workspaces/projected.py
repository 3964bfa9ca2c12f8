"""Projected orientation workspace: the set of attainable tool directions at a position.

Two methods:

``torsion_zero``
    Bonev & Ryu's approximation. For n_phi azimuths φ_k = k·2π/n_phi, the first tilt θ along
    the ray from θ = 0 at torsion ψ = 0 where a constraint is violated. Located to the
    tolerance with the Lipschitz-certified march + bisection of
    :mod:`hexapod_workspace.core.workspaces.search` (no 0.1° walk; why no thin violated band is
    stepped over is explained there).
``exact``
    The true shadow of the orientation workspace, which the paper leaves open: for each φ the
    largest θ such that some ψ makes (φ, θ, ψ) reachable *and connected to the reference
    orientation*. Connected here means reachable from the reference along a path that first
    turns about the tool axis at θ = 0 (within the torsion interval of the reference) and then
    tilts at constant (φ, ψ). For each φ the boundary tilt θ_b(ψ) of such paths is computed on
    a grid of ψ over that torsion interval (ψ = 0 included, so ``exact`` ≥ ``torsion_zero``
    everywhere by construction), then the best grid cell is refined by golden-section search
    on ψ. Points of the workspace that are only reachable along other paths (a slice that is
    not star-shaped about θ = 0) are not counted, so the result is a certified lower bound of
    the shadow, exact for workspaces whose constant-(φ, ψ) sections are intervals.

Every reported point (φ, θ, ψ) satisfies every constraint; the first violation along its
ray lies within the tolerance beyond it.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError, UnreachableReferenceError
from ..base.resolution import (
    DEFAULT_N_PHI,
    DEFAULT_TOLERANCE,
    Method,
    Progress,
    validate_position,
    validate_rays,
    validate_tolerance,
)
from ..base.rotations import approach_vector
from ..evaluation.check import CONSTRAINT_NAMES
from ..model.manipulator import Manipulator
from .search import RaySearch

__all__ = ["ProjectedWorkspace", "projected_workspace"]

#: ψ samples per azimuth for the ``exact`` method before golden-section refinement.
EXACT_PSI_SAMPLES = 13
#: Golden-section iterations on ψ for the ``exact`` method.
EXACT_GOLDEN_STEPS = 18
#: Boundary tolerance while ranking ψ values in the ``exact`` method, rad.
COARSE_TOLERANCE = 1e-5


@dataclass(frozen=True)
class ProjectedWorkspace:
    """The projected orientation workspace (attainable tool directions) at one position.

    Attributes
    ----------
    method : str
        ``"torsion_zero"`` or ``"exact"``.
    position : ndarray, shape (3,)
        Tool-tip position, base frame, m.
    phi : ndarray, shape (n,)
        Azimuths φ_k = k·2π/n, rad.
    theta : ndarray, shape (n,)
        Boundary tilt per azimuth, rad: reachable, with the first violation within
        ``tolerance`` beyond it (π when the ray never meets a violation).
    psi : ndarray, shape (n,)
        Torsion of the boundary point, rad (0 for ``torsion_zero``).
    limiting : list of str
        Constraint violated just beyond each boundary point ("" when none).
    tilt_min, tilt_max : float
        Min and max of ``theta`` (the paper's θmin, θmax), rad.
    solid_angle : float
        Solid angle of the attainable approach directions, ∫ (1 − cos θ_b(φ)) dφ, sr.
    tolerance : float
        Boundary tolerance, rad.
    elapsed : float
        Computation time, s.
    evaluations : int
        Poses evaluated.
    gap : ndarray, shape (n,) or None
        ``exact`` only: exact θ minus the torsion-zero θ per azimuth (≥ 0), rad.
    """

    method: str
    position: NDArray[np.float64]
    phi: NDArray[np.float64]
    theta: NDArray[np.float64]
    psi: NDArray[np.float64]
    limiting: list[str]
    tilt_min: float
    tilt_max: float
    solid_angle: float
    tolerance: float
    elapsed: float
    evaluations: int = 0
    gap: NDArray[np.float64] | None = field(default=None)

    @property
    def n_phi(self) -> int:
        """Number of azimuths."""
        return int(self.phi.shape[0])

    def approach_vectors(self) -> NDArray[np.float64]:
        """Unit approach vectors of the boundary directions, base frame; shape (n, 3)."""
        return approach_vector(self.phi, self.theta)


def _solid_angle(theta: NDArray[np.float64]) -> float:
    """∫_0^{2π} ∫_0^{θ_b(φ)} sin θ dθ dφ for equally spaced φ (rectangle rule, exact for the
    periodic trapezoid)."""
    return float(2.0 * math.pi * np.mean(1.0 - np.cos(theta)))


def require_reachable_reference(search: RaySearch) -> None:
    """Raise :class:`UnreachableReferenceError` unless (0, 0, 0) is reachable at the position."""
    margins = search.margins(np.zeros((1, 3)))
    if not np.all(margins >= 0.0):  # NaN (a degenerate leg) counts as violated
        names = [CONSTRAINT_NAMES[k] for k in np.flatnonzero(~(margins[:, 0] >= 0.0))]
        x, y, z = search.position
        msg = (
            f"the reference orientation (phi, theta, psi) = (0, 0, 0) is unreachable at position "
            f"({x:g}, {y:g}, {z:g}) m ({', '.join(names)} violated): the workspace is empty"
        )
        raise UnreachableReferenceError(msg)


def reference_torsion_interval(search: RaySearch, tolerance: float) -> tuple[float, float]:
    """The torsion interval [ψ_lo, ψ_hi] at θ = 0 that contains the reference ψ = 0.

    Raises
    ------
    UnreachableReferenceError
        When the reference orientation (0, 0, 0) is itself unreachable.
    """
    require_reachable_reference(search)
    # Torsion rays (0, 0, ±s) from the reference.
    found = search.rays("tt", np.zeros(3), [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]], math.pi, tolerance)
    return -float(found.feasible[1]), float(found.feasible[0])


def tilt_rays(
    search: RaySearch,
    phi: NDArray[np.float64],
    psi: NDArray[np.float64],
    tolerance: float,
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Boundary tilt and limiting constraint along the tilt rays (φ_k, s, ψ_k) from θ = 0.

    Parameters
    ----------
    search : RaySearch
    phi, psi : ndarray, shape (n,)
        Azimuth and torsion of each ray, rad.
    tolerance : float
        rad.

    Returns
    -------
    theta : ndarray, shape (n,)
        Last feasible tilt, rad.
    limiting : ndarray, shape (n,), int
        Constraint violated just beyond (−1: none up to θ = π).
    """
    origins = np.column_stack([phi, np.zeros(phi.size), psi])
    found = search.rays("tt", origins, [0.0, 1.0, 0.0], math.pi, tolerance)
    return found.feasible, found.limiting


def projected_workspace(
    manipulator: Manipulator,
    position: ArrayLike | None = None,
    *,
    method: Method | str = Method.TORSION_ZERO,
    n_phi: int = DEFAULT_N_PHI,
    tolerance: float = DEFAULT_TOLERANCE,
    progress: Progress | None = None,
) -> ProjectedWorkspace:
    """Compute the projected orientation workspace at a position.

    Parameters
    ----------
    manipulator : Manipulator
    position : array_like, shape (3,), optional
        Tool-tip position OC, base frame, m (default ``manipulator.position``).
    method : {"torsion_zero", "exact"}
        See the module documentation.
    n_phi : int
        Number of azimuths φ_k = k·360°/n_phi, 3 to 7200.
    tolerance : float
        Boundary tolerance, rad (1e-12 to 0.1).
    progress : callable, optional
        Called with the completed fraction in [0, 1].

    Returns
    -------
    ProjectedWorkspace

    Raises
    ------
    UnreachableReferenceError
        The reference orientation is unreachable at the position.
    ResolutionError
        ``n_phi`` or ``tolerance`` out of bounds.
    InputError
        Unknown method, bad position.
    """
    started = time.perf_counter()
    try:
        method = Method(method)
    except ValueError:
        names = ", ".join(m.value for m in Method)
        msg = f"method: expected one of {names}, got {method!r}"
        raise InputError(msg) from None
    n_phi = validate_rays(n_phi, "n_phi")
    tolerance = validate_tolerance(tolerance)
    position = validate_position(position, manipulator.position)
    search = RaySearch(manipulator, position)
    require_reachable_reference(search)
    phi = 2.0 * math.pi * np.arange(n_phi) / n_phi
    zero: NDArray[np.float64] = np.zeros(n_phi)
    theta_zero, limiting_zero = tilt_rays(search, phi, zero, tolerance)
    theta, psi, limiting = theta_zero, zero.copy(), limiting_zero
    gap = None
    if method is Method.EXACT:
        if progress:
            progress(0.1)
        torsion = reference_torsion_interval(search, tolerance)
        theta, psi, limiting = _exact(
            search, phi, torsion, tolerance, theta_zero, limiting_zero, progress
        )
        gap = theta - theta_zero
    if progress:
        progress(1.0)
    return ProjectedWorkspace(
        method=method.value,
        position=position,
        phi=phi,
        theta=theta,
        psi=psi,
        limiting=[CONSTRAINT_NAMES[k] if k >= 0 else "" for k in limiting],
        tilt_min=float(theta.min()),
        tilt_max=float(theta.max()),
        solid_angle=_solid_angle(theta),
        tolerance=tolerance,
        elapsed=time.perf_counter() - started,
        evaluations=search.evaluations,
        gap=gap,
    )


#: Three arrays per azimuth: (theta, psi, limiting) of the best points of :func:`_exact` so far,
#: or (psi, theta, limiting) of its trial points.
_Triple = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]


def _exact(
    search: RaySearch,
    phi: NDArray[np.float64],
    torsion: tuple[float, float],
    tolerance: float,
    theta_zero: NDArray[np.float64],
    limiting_zero: NDArray[np.int64],
    progress: Progress | None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Max over ψ of the boundary tilt, per azimuth (see the module documentation)."""
    n_phi = phi.size
    psi_low, psi_high = torsion
    # Grid over the reference torsion interval, ψ = 0 included exactly.
    grid = np.linspace(psi_low, psi_high, EXACT_PSI_SAMPLES)
    spacing = (psi_high - psi_low) / (EXACT_PSI_SAMPLES - 1)
    # ψ = 0 exactly (the torsion-zero rays), without a near-duplicate from the linspace.
    grid = np.sort(np.append(grid[np.abs(grid) > 0.25 * spacing], 0.0))

    # The grid and the golden-section phase only rank ψ values: a coarser tolerance suffices
    # there; the winner is searched again at full tolerance at the end.
    coarse = max(tolerance, COARSE_TOLERANCE)

    def boundary(
        psi: NDArray[np.float64], tol: float = coarse
    ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
        """Boundary tilt and limiting constraint of rays (phi[k % n_phi], psi[k])."""
        return tilt_rays(search, np.resize(phi, psi.size), psi, tol)

    others = grid[grid != 0.0]
    found, found_limits = boundary(np.repeat(others, n_phi))
    samples = np.empty((grid.size, n_phi))
    limits = np.empty((grid.size, n_phi), dtype=np.int64)
    samples[grid != 0.0] = found.reshape(others.size, n_phi)
    limits[grid != 0.0] = found_limits.reshape(others.size, n_phi)
    samples[grid == 0.0], limits[grid == 0.0] = theta_zero, limiting_zero
    if progress:
        progress(0.5)
    best = samples.argmax(axis=0)
    columns = np.arange(n_phi)
    theta = samples[best, columns].copy()
    psi = grid[best].copy()
    limiting = limits[best, columns].copy()
    # Golden-section search for the max of θ_b(ψ) on the neighbouring grid cells.
    low = grid[np.maximum(best - 1, 0)]
    high = grid[np.minimum(best + 1, grid.size - 1)]
    ratio = (math.sqrt(5.0) - 1.0) / 2.0

    def keep_best(best: _Triple, *trials: _Triple) -> _Triple:
        """(theta, psi, limiting) improved by trial points (psi, theta, limiting) where higher."""
        theta_best, psi_best, limit_best = best
        for candidate, value, limit in trials:
            better = value > theta_best
            theta_best = np.where(better, value, theta_best)
            psi_best = np.where(better, candidate, psi_best)
            limit_best = np.where(better, limit, limit_best)
        return theta_best, psi_best, limit_best

    left = high - ratio * (high - low)
    right = low + ratio * (high - low)
    theta_left, limit_left = boundary(left)
    theta_right, limit_right = boundary(right)
    for step in range(EXACT_GOLDEN_STEPS):
        theta, psi, limiting = keep_best(
            (theta, psi, limiting),
            (left, theta_left, limit_left),
            (right, theta_right, limit_right),
        )
        go_right = theta_left < theta_right
        low = np.where(go_right, left, low)
        high = np.where(go_right, high, right)
        new_left = np.where(go_right, right, high - ratio * (high - low))
        new_right = np.where(go_right, low + ratio * (high - low), left)
        keep_left = np.where(go_right, theta_right, theta_left)
        keep_limit = np.where(go_right, limit_right, limit_left)
        # Only one new point per iteration: the other is reused.
        fresh = np.where(go_right, new_right, new_left)
        theta_fresh, limit_fresh = boundary(fresh)
        theta_left = np.where(go_right, keep_left, theta_fresh)
        limit_left = np.where(go_right, keep_limit, limit_fresh)
        theta_right = np.where(go_right, theta_fresh, keep_left)
        limit_right = np.where(go_right, limit_fresh, keep_limit)
        left, right = new_left, new_right
        if progress:
            progress(0.5 + 0.5 * (step + 1) / EXACT_GOLDEN_STEPS)
    theta, psi, limiting = keep_best(
        (theta, psi, limiting), (left, theta_left, limit_left), (right, theta_right, limit_right)
    )
    # Full tolerance at the winning torsion (ψ = 0 keeps its torsion-zero result).
    refine = psi != 0.0
    if tolerance < coarse and np.any(refine):
        theta_fine, limit_fine = boundary(psi, tolerance)
        theta = np.where(refine, theta_fine, theta)
        limiting = np.where(refine, limit_fine, limiting)
    return theta, psi, limiting
