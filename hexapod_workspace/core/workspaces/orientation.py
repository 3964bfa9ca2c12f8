"""3-D orientation workspace (ψ slices in the cylindrical picture) and torsion ranges.

Cylindrical picture (docs/theory.md): x = θ cos φ, y = θ sin φ, z = ψ. The orientation
workspace at a position is the set of reachable (x, y, ψ) connected to the reference
orientation (0, 0, 0). It is computed as in Bonev & Ryu, with every boundary located to a
tolerance by the certified search of :mod:`hexapod_workspace.core.workspaces.search`:

1. The ψ = 0 slice: ``n_rays`` rays from the origin, then again from the area centroid of
   that first polygon.
2. Slices ψ = ±Δψ, ±2Δψ, ... upward and downward: rays from the area centroid of the
   previous slice. When that centroid is unreachable in the new slice, points of the previous
   slice pulled halfway towards its centroid are tried as centres (the most comfortable one,
   largest relative margin, is used); when none is reachable, the torsion-limit search of
   step 3 decides: if some direction of the previous slice still reaches the new torsion, it
   is the centre, otherwise the slice is empty and ends the march.
3. ψmax (ψmin) is located to the tolerance: from the centre and the pulled points of the last
   non-empty slice, the torsion is increased (decreased) until the first violation, and the
   best of those is refined by a shrinking pattern search over (x, y).

Volume: the solid's volume in the cylindrical coordinates (rad³), ∫ area(ψ) dψ by the
trapezoid rule over the slices, with cones to ψmin and ψmax.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError, ResolutionError
from ..base.resolution import (
    DEFAULT_N_RAYS,
    DEFAULT_PSI_STEP,
    DEFAULT_TOLERANCE,
    MAX_POINTS,
    Progress,
    validate_position,
    validate_psi_step,
    validate_rays,
    validate_tolerance,
)
from ..evaluation.check import relative_margins
from ..model.manipulator import Manipulator
from .projected import reference_torsion_interval, require_reachable_reference
from .search import RaySearch

#: numpy >= 2 names it trapezoid; numpy 1.x (Ubuntu 24.04's python3-numpy 1.26) trapz.

__all__ = [
    "OrientationSlice",
    "OrientationWorkspace",
    "TorsionRange",
    "orientation_workspace",
    "torsion_range",
]

#: Pattern-search rounds when refining ψmax / ψmin.
PSI_LIMIT_ROUNDS = 400
#: Directions of the pattern search for the torsion extremes (:meth:`_Slicer.torsion_limit`).
PSI_PATTERN = 16
_PATTERN = np.column_stack(
    [
        np.cos(2.0 * np.pi * np.arange(PSI_PATTERN) / PSI_PATTERN),
        np.sin(2.0 * np.pi * np.arange(PSI_PATTERN) / PSI_PATTERN),
    ]
)
#: Longest scan step of :func:`torsion_range`, rad.
TORSION_MAX_STEP = 0.25


@dataclass(frozen=True)
class OrientationSlice:
    """One ψ slice of the orientation workspace.

    Attributes
    ----------
    psi : float
        Torsion of the slice, rad.
    center : ndarray, shape (2,)
        Ray origin in the cylindrical xy-plane (θ cos φ, θ sin φ), rad.
    phi, theta : ndarray, shape (n_rays,)
        Boundary points as T&T azimuth and tilt, rad (reachable; the first violation along the
        ray lies within the tolerance beyond).
    """

    psi: float
    center: NDArray[np.float64]
    phi: NDArray[np.float64]
    theta: NDArray[np.float64]

    def xy(self) -> NDArray[np.float64]:
        """Boundary points in the cylindrical xy-plane (θ cos φ, θ sin φ); shape (n, 2), rad."""
        return np.column_stack([self.theta * np.cos(self.phi), self.theta * np.sin(self.phi)])

    def area(self) -> float:
        """Area of the boundary polygon in the cylindrical xy-plane, rad²."""
        return float(_polygon_area_centroid(self.xy())[0])


@dataclass(frozen=True)
class OrientationWorkspace:
    """The 3-D orientation workspace at one position.

    Attributes
    ----------
    position : ndarray, shape (3,)
        Tool-tip position, base frame, m.
    slices : list of OrientationSlice
        Ordered by increasing ψ.
    psi_min, psi_max : float
        Lowest and highest reachable torsion connected to the reference, rad (to tolerance).
    volume : float
        Volume of the solid in cylindrical coordinates, rad³.
    n_rays : int
    psi_step : float
        Δψ, rad.
    tolerance : float
        Boundary tolerance, rad.
    elapsed : float
        Computation time, s.
    evaluations : int
        Poses evaluated.
    psi_min_point, psi_max_point : ndarray, shape (2,), optional
        Where in the cylindrical xy-plane (rad) ψmin and ψmax are attained.
    """

    @property
    def psi_min_witness(self) -> NDArray[np.float64] | None:
        """The pose [φ, θ, ψmin] (rad, T&T) that attains ψmin: reachable (``check``)."""
        return _witness(self.psi_min_point, self.psi_min)

    @property
    def psi_max_witness(self) -> NDArray[np.float64] | None:
        """The pose [φ, θ, ψmax] (rad, T&T) that attains ψmax: reachable (``check``)."""
        return _witness(self.psi_max_point, self.psi_max)

    position: NDArray[np.float64]
    slices: list[OrientationSlice]
    psi_min: float
    psi_max: float
    volume: float
    n_rays: int
    psi_step: float
    tolerance: float
    elapsed: float
    evaluations: int = 0
    psi_min_point: NDArray[np.float64] | None = None
    psi_max_point: NDArray[np.float64] | None = None

    def boundary_points(self) -> NDArray[np.float64]:
        """All boundary points; shape (M, 6), columns x, y, z, φ, θ, ψ (rad).

        x, y, z is the cylindrical picture: (θ cos φ, θ sin φ, ψ).
        """
        if not self.slices:
            return np.zeros((0, 6))
        blocks = []
        for piece in self.slices:
            xy = piece.xy()
            psi = np.full(piece.phi.shape, piece.psi)
            blocks.append(np.column_stack([xy, psi, piece.phi, piece.theta, psi]))
        return np.concatenate(blocks)


@dataclass(frozen=True)
class TorsionRange:
    """Feasible torsion angles for one tool direction.

    Attributes
    ----------
    position : ndarray, shape (3,)
        m, base frame.
    phi, theta : float
        The tool direction, rad.
    intervals : ndarray, shape (k, 2)
        Feasible [ψ_lo, ψ_hi] intervals in [−π, π], rad, increasing; ends reachable, the first
        violation beyond each end within the tolerance. An interval touching both −π and π is
        reported as two pieces (and as [−π, π] when every torsion is feasible).
    tolerance : float
        rad.
    """

    position: NDArray[np.float64]
    phi: float
    theta: float
    intervals: NDArray[np.float64]
    tolerance: float


# ---------------------------------------------------------------------------- geometry helpers
def _polygon_area_centroid(xy: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
    """Area and area centroid of a closed polygon given by its vertices (n, 2) in order."""
    x, y = xy[:, 0], xy[:, 1]
    x_next, y_next = np.roll(x, -1), np.roll(y, -1)
    cross = x * y_next - x_next * y
    area = 0.5 * float(cross.sum())
    if abs(area) < 1e-300:
        return 0.0, xy.mean(axis=0)
    cx = float(((x + x_next) * cross).sum()) / (6.0 * area)
    cy = float(((y + y_next) * cross).sum()) / (6.0 * area)
    return abs(area), np.array([cx, cy])


def _xy_to_angles(
    x: NDArray[np.float64], y: NDArray[np.float64], psi: NDArray[np.float64] | float
) -> NDArray[np.float64]:
    """T&T angles (n, 3) of cylindrical points (x, y) at torsion psi."""
    theta = np.hypot(x, y)
    phi = np.where(theta > 0.0, np.arctan2(y, x), 0.0)
    return np.column_stack([phi, theta, np.broadcast_to(psi, theta.shape)])


def _witness(point: NDArray[np.float64] | None, psi: float) -> NDArray[np.float64] | None:
    """The T&T pose (3,) of the cylindrical point ``point`` (2,) at torsion ``psi``."""
    if point is None:
        return None
    witness: NDArray[np.float64] = _xy_to_angles(point[:1], point[1:2], psi)[0]
    return witness


def _ray_ends(center: NDArray[np.float64], directions: NDArray[np.float64]) -> NDArray[np.float64]:
    """Parameter where each ray c + s·u leaves the disk θ ≤ π; shape (n,)."""
    cu = directions @ center
    ends: NDArray[np.float64] = -cu + np.sqrt(
        np.maximum(cu * cu - center @ center + math.pi**2, 0.0)
    )
    return ends


# ---------------------------------------------------------------------------- the computation
class _Slicer:
    """Computes slices for one manipulator, position and resolution."""

    def __init__(self, search: RaySearch, n_rays: int, tolerance: float) -> None:
        self.search = search
        self.n_rays = n_rays
        self.tolerance = tolerance
        gamma = 2.0 * math.pi * np.arange(n_rays) / n_rays
        self.directions = np.column_stack([np.cos(gamma), np.sin(gamma)])

    def slices(
        self, centers: NDArray[np.float64], psis: NDArray[np.float64]
    ) -> list[OrientationSlice]:
        """Slices at torsions ``psis`` (k,) with ray origins ``centers`` (k, 2), in one batch."""
        count = psis.size
        n = self.n_rays
        ends = np.concatenate([_ray_ends(c, self.directions) for c in centers])
        origins = np.column_stack([np.repeat(centers, n, axis=0), np.repeat(psis, n)])
        directions = np.tile(np.column_stack([self.directions, np.zeros(n)]), (count, 1))
        found = self.search.rays("cylindrical", origins, directions, ends, self.tolerance)
        result = []
        for index in range(count):
            s = found.feasible[index * n : (index + 1) * n]
            xy = centers[index] + s[:, None] * self.directions
            theta = np.hypot(xy[:, 0], xy[:, 1])
            phi = np.where(theta > 0.0, np.arctan2(xy[:, 1], xy[:, 0]), 0.0)
            result.append(OrientationSlice(float(psis[index]), centers[index].copy(), phi, theta))
        return result

    def best_center(self, previous: OrientationSlice, psi: float) -> NDArray[np.float64] | None:
        """Ray origin for a new slice at ``psi`` next to ``previous`` (None: slice empty)."""
        _, centroid = _polygon_area_centroid(previous.xy())
        candidates = np.vstack([centroid, 0.5 * (previous.xy() + centroid)])
        margins = self.search.margins(_xy_to_angles(candidates[:, 0], candidates[:, 1], psi))
        feasible = np.all(margins >= 0.0, axis=0)
        if feasible[0]:
            return centroid
        if not np.any(feasible):
            return None
        comfort = relative_margins(self.search.manipulator, margins).min(axis=0)
        comfort[~feasible] = -np.inf
        best: NDArray[np.float64] = candidates[int(np.argmax(comfort))]
        return best

    def torsion_limit(
        self, last: OrientationSlice, sign: float
    ) -> tuple[float, NDArray[np.float64]]:
        """ψmax (sign +1) or ψmin (−1) beyond the last non-empty slice, and where it is.

        Every candidate is a point of the slice and each value is the reachable end of a ray in
        ψ from a point reachable at the slice's torsion (:meth:`_torsion_tops`), so the point
        returned with the value is a witness: the pose (φ, θ, value) is reachable. The slice's
        own boundary points (the certified ray ends, reachable) are among the candidates, so a
        reachable start exists whatever the slice's shape.
        """
        _, centroid = _polygon_area_centroid(last.xy())
        candidates = np.vstack([last.center, centroid, 0.5 * (last.xy() + centroid), last.xy()])
        top = self._torsion_tops(candidates, last.psi, sign)
        best = int(np.argmax(sign * top))
        point, value = candidates[best], top[best]
        # Shrinking pattern search over (x, y) for the extreme torsion, in PSI_PATTERN
        # directions: the torsion top is the lowest of the constraints' tops, so its maximum
        # lies on a ridge where two of them meet, along which a four-direction (compass) search
        # stalls short of the top.
        step = 0.25 * float(np.sqrt(max(last.area(), 1e-12)))
        for _ in range(PSI_LIMIT_ROUNDS):
            trial = point + step * _PATTERN
            tops = self._torsion_tops(trial, last.psi, sign)
            k = int(np.argmax(sign * tops))
            if sign * tops[k] > sign * value:
                point, value = trial[k], tops[k]
            else:
                step *= 0.5
            if step < self.tolerance:
                break
        return float(value), point

    def _torsion_tops(
        self, points: NDArray[np.float64], psi_start: float, sign: float
    ) -> NDArray[np.float64]:
        """For points (n, 2), the last reachable torsion going from psi_start in direction
        ``sign`` (reachable: the ray's certified feasible end); a point unreachable at
        psi_start gets −sign·∞, so that it is never taken for an extreme."""

        origins = np.column_stack([points, np.full(points.shape[0], psi_start)])
        found = self.search.rays(
            "cylindrical", origins, [0.0, 0.0, sign], math.pi - sign * psi_start, self.tolerance
        )
        tops = psi_start + sign * found.feasible
        return np.where(found.start_feasible, tops, -sign * np.inf)


def orientation_workspace(
    manipulator: Manipulator,
    position: ArrayLike | None = None,
    *,
    n_rays: int = DEFAULT_N_RAYS,
    psi_step: float = DEFAULT_PSI_STEP,
    tolerance: float = DEFAULT_TOLERANCE,
    progress: Progress | None = None,
) -> OrientationWorkspace:
    """Compute the 3-D orientation workspace at a position (see the module documentation).

    Parameters
    ----------
    manipulator : Manipulator
    position : array_like, shape (3,), optional
        Tool-tip position OC, base frame, m (default ``manipulator.position``).
    n_rays : int
        Rays per slice, 3 to 7200.
    psi_step : float
        Slice step Δψ, rad, 1e-4 to 0.5.
    tolerance : float
        Boundary tolerance, rad (1e-12 to 0.1).
    progress : callable, optional
        Called with an estimate of the completed fraction in [0, 1].

    Returns
    -------
    OrientationWorkspace

    Raises
    ------
    UnreachableReferenceError
        The reference orientation is unreachable at the position.
    ResolutionError
        A resolution out of bounds, or more than 5·10⁶ boundary points.
    """
    started = time.perf_counter()
    n_rays = validate_rays(n_rays, "n_rays")
    tolerance = validate_tolerance(tolerance)
    step = validate_psi_step(psi_step)
    max_slices = int(2.0 * math.pi / step) + 1
    if max_slices * n_rays > MAX_POINTS:
        msg = (
            f"n_rays × slices: up to {max_slices} slices of {n_rays} rays exceed "
            f"{MAX_POINTS} boundary points; use fewer rays or a larger psi_step"
        )
        raise ResolutionError(msg)
    position = validate_position(position, manipulator.position)
    search = RaySearch(manipulator, position)
    require_reachable_reference(search)
    slicer = _Slicer(search, n_rays, tolerance)
    # Expected span, for the progress estimate only.
    if progress:
        low, high = reference_torsion_interval(search, max(tolerance, 1e-3))
        expected = max((high - low) / step, 1.0)

    first = slicer.slices(np.zeros((1, 2)), np.zeros(1))[0]
    _, centroid = _polygon_area_centroid(first.xy())
    middle = slicer.slices(centroid[None, :], np.zeros(1))[0]
    upper: list[OrientationSlice] = [middle]
    lower: list[OrientationSlice] = [middle]
    growing = {1.0: True, -1.0: True}
    limits: dict[float, tuple[float, NDArray[np.float64]]] = {}
    while any(growing.values()):
        centers, next_psis, signs = [], [], []
        for sign, stack in ((1.0, upper), (-1.0, lower)):
            if not growing[sign]:
                continue
            psi = stack[-1].psi + sign * step
            if abs(psi) > math.pi:
                growing[sign] = False
                continue
            center = slicer.best_center(stack[-1], psi)
            if center is None:
                # No pulled point reaches the next slice: the torsion limit search tells whether
                # some direction still does (then it is the centre) or the slice is empty.
                limit, point = slicer.torsion_limit(stack[-1], sign)
                limits[sign] = (limit, point)
                if sign * (limit - psi) < 0.0:
                    growing[sign] = False
                    continue
                center = point
            centers.append(center)
            next_psis.append(psi)
            signs.append(sign)
        if not centers:
            break
        for sign, piece in zip(
            signs, slicer.slices(np.array(centers), np.array(next_psis)), strict=True
        ):
            (upper if sign > 0 else lower).append(piece)
        if progress:
            progress(min(0.95, (len(upper) + len(lower)) / expected))
    for sign, stack in ((1.0, upper), (-1.0, lower)):
        if sign not in limits or sign * (limits[sign][0] - stack[-1].psi) >= step:
            limits[sign] = slicer.torsion_limit(stack[-1], sign)
    psi_max, psi_max_point = limits[1.0]
    psi_min, psi_min_point = limits[-1.0]
    slices = lower[:0:-1] + upper
    areas = np.array([piece.area() for piece in slices])
    psis = np.array([piece.psi for piece in slices])
    # Trapezoid rule written out: numpy.trapezoid needs numpy >= 2 (Ubuntu 24.04 has 1.26).
    volume = float(np.sum(0.5 * (areas[1:] + areas[:-1]) * np.diff(psis)))
    # Cones from the end slices to the extreme torsions (area shrinking to zero).
    volume += 0.5 * areas[-1] * (psi_max - psis[-1]) + 0.5 * areas[0] * (psis[0] - psi_min)
    if progress:
        progress(1.0)
    return OrientationWorkspace(
        position=position,
        slices=slices,
        psi_min=psi_min,
        psi_max=psi_max,
        volume=volume,
        n_rays=n_rays,
        psi_step=step,
        tolerance=tolerance,
        elapsed=time.perf_counter() - started,
        evaluations=search.evaluations,
        psi_min_point=psi_min_point,
        psi_max_point=psi_max_point,
    )


def torsion_range(
    manipulator: Manipulator,
    phi: float,
    theta: float,
    position: ArrayLike | None = None,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
) -> TorsionRange:
    """Feasible torsion intervals for one tool direction (what a 5-axis controller needs).

    The whole circle ψ ∈ [−π, π] is scanned with certified steps in both directions: from a
    feasible point no violation can occur within the certified step, and from a violated point
    the most violated constraint cannot recover within |m_c| / L_c either, so no interval
    wider than ``h_min`` (1e-3 rad) is missed. Each transition is bisected to the tolerance.

    Parameters
    ----------
    manipulator : Manipulator
    phi, theta : float
        Tool direction (azimuth, tilt), rad.
    position : array_like, shape (3,), optional
        m, base frame (default ``manipulator.position``).
    tolerance : float
        rad.

    Returns
    -------
    TorsionRange
    """
    tolerance = validate_tolerance(tolerance)
    position = validate_position(position, manipulator.position)
    values = np.array([phi, theta], dtype=np.float64)
    if not np.all(np.isfinite(values)):
        msg = f"direction: expected finite (phi, theta), got {values.tolist()}"
        raise InputError(msg)
    if not 0.0 <= theta <= math.pi:
        msg = f"direction: expected theta in [0, pi] rad, got {theta!r}"
        raise InputError(msg)
    search = RaySearch(manipulator, position)
    capacity = math.ceil(2.0 * math.pi / search.min_step) + 2
    edges: NDArray[np.float64] = np.empty(capacity)
    rising: NDArray[np.bool_] = np.empty(capacity, dtype=np.bool_)
    count, start_feasible = search.kernels.torsion_scan(
        search.model,
        search.position,
        float(phi),
        float(theta),
        search.min_step,
        TORSION_MAX_STEP,
        tolerance,
        edges,
        rising,
        search.lazy_collision,
        search.kernels.collide,
    )
    edges, rising = edges[:count], rising[:count]
    intervals = []
    start = -math.pi if start_feasible else None
    for edge, up in zip(edges, rising, strict=True):
        if up:
            start = float(edge)
        elif start is not None:
            intervals.append((start, float(edge)))
            start = None
    if start is not None:
        intervals.append((start, math.pi))
    return TorsionRange(
        position=position,
        phi=float(phi),
        theta=float(theta),
        intervals=np.array(intervals, dtype=np.float64).reshape(-1, 2),
        tolerance=tolerance,
    )
