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
most ρ per unit ``s`` and each margin changes at most at a known rate (a Lipschitz bound): the
rate of its row of :mod:`hexapod_workspace.core.constraints.table` with V = ρ and Ω = 1 (ρ for
``leg_length``, ρ / ℓ_floor for ``base_joint``, 1 + ρ / ℓ_floor for ``platform_joint``, 2ρ for
``leg_interference``; the derivations are written there).

``ℓ_floor`` is a lower bound on the leg lengths over the step: the smallest ℓmin (valid because
the step never lets the leg-length margin reach zero), and at least half of the current shortest
leg (the step is also limited to keep that true). From a feasible point with margins m_c, no
margin can reach zero within ``min_c m_c / L_c``: a step of that length is *certified*. The
search takes certified steps, so it cannot skip a violated band, except where every margin is
already within ``L_c · h_min`` of zero: there it steps by ``h_min`` (default 1e-3 rad) and
bands narrower than ``h_min`` could be missed. Once a violated sample is met, bisection
between the last feasible sample and it locates the crossing to the tolerance; the reported
point is the feasible end, so every reported boundary point satisfies every constraint.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import kernels
from ..constraints.table import N_CONSTRAINTS
from ..model.manipulator import Manipulator

__all__ = ["DEFAULT_MIN_STEP", "RAY_KINDS", "RaySearch", "RaySearchResult"]

#: Shortest step of the march (rad): below it, steps are no longer Lipschitz-certified.
DEFAULT_MIN_STEP = 1e-3
#: Longest step of the march (rad); steps are certified, this only bounds a single jump.
MAX_STEP = kernels.MAX_STEP
#: Shrink certified steps by this factor so that rounding cannot land on a violated point.
SAFETY = kernels.SAFETY
#: Coordinates in which a ray is a straight line: T&T angles (φ, θ, ψ), or the cylindrical
#: picture (x, y, ψ) = (θ cos φ, θ sin φ, ψ).
RAY_KINDS = {"tt": kernels.KIND_TT, "cylindrical": kernels.KIND_CYLINDRICAL}


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
        Index into CONSTRAINT_NAMES of the most violated constraint (relative margins) at
        ``violated`` (−1 when none was met).
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


def _vectors(values: ArrayLike, count: int) -> NDArray[np.float64]:
    """(count, 3) contiguous, writable float64 from (3,) or (count, 3).

    Always a writable copy: numba compiles one specialisation per read-only flag, and the
    kernels are warmed up (compiled ahead) for writable arrays only.
    """
    return np.array(np.broadcast_to(np.asarray(values, dtype=np.float64), (count, 3)), order="C")


def _scalars(values: ArrayLike, count: int) -> NDArray[np.float64]:
    """(count,) contiguous, writable float64 from a scalar or (count,) (see :func:`_vectors`)."""
    return np.array(np.broadcast_to(np.asarray(values, dtype=np.float64), (count,)), order="C")


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

    #: Evaluate the collision margin along rays and in the torsion scan only where its Lipschitz
    #: bound cannot decide a probe (False: at every probe, as a reference; see
    #: ``kernels.searches.search_rays`` and ``kernels.searches.torsion_scan``).
    lazy_collision: bool = True

    def __init__(
        self, manipulator: Manipulator, position: NDArray[np.float64], min_step: float = 1e-3
    ) -> None:
        self.manipulator = manipulator
        self.position = np.array(position, dtype=np.float64, order="C")  # writable: _vectors
        self.min_step = float(min_step)
        self.model = kernels.model_vector(manipulator)
        #: The entry points compiled for this model's variant.
        self.kernels = kernels.for_model(self.model)
        self.evaluations = 0
        #: Poses at which the collision margin was evaluated (the ray searches evaluate it only
        #: where it can change the answer: ``kernels.searches.search_rays``).
        self.collision_evaluations = 0

    def margins(self, angles: NDArray[np.float64]) -> NDArray[np.float64]:
        """The margins of poses (n, 3) at the search position; shape (C, n), C constraints."""
        angles = np.ascontiguousarray(angles, dtype=np.float64)
        if not angles.flags.writeable:  # one compiled specialisation: writable arrays
            angles = angles.copy()
        count = angles.shape[0]
        margins = np.empty((N_CONSTRAINTS, count))
        margins[int(self.model[kernels.ROWS_USED]) :] = np.inf  # rows the kernel leaves out
        self.kernels.check_angles(
            self.model,
            angles,
            self.position,
            0,
            count,
            margins,
            np.empty((N_CONSTRAINTS + 2, count), dtype=np.int64),
            np.empty((count, 2), dtype=np.int64),
            np.empty(count, dtype=np.bool_),
            self.kernels.collide,
        )
        self.evaluations += count
        if self.model[kernels.COLLISION_ON] != 0.0:
            self.collision_evaluations += count
        return margins

    def rays(
        self,
        kind: str,
        origins: ArrayLike,
        directions: ArrayLike,
        s_end: ArrayLike,
        tolerance: float,
        s_start: ArrayLike = 0.0,
    ) -> RaySearchResult:
        """Find, along rays ``origins + s·directions``, the first violated s in [s_start, s_end].

        Parameters
        ----------
        kind : {"tt", "cylindrical"}
            Coordinates of ``origins`` and ``directions``: T&T angles (φ, θ, ψ), rad, or the
            cylindrical picture (x, y, ψ), rad.
        origins, directions : array_like, shape (n, 3) or (3,)
            Ray i is ``origins[i] + s·directions[i]`` (the platform turns at most 1 rad per
            unit s along the rays used here: see the module documentation).
        s_end : float or array_like, shape (n,)
            End of each ray, rad.
        tolerance : float
            Bracket width at which the search stops, rad.
        s_start : float or array_like, shape (n,)
            Start of each ray (normally a feasible point), rad.

        Returns
        -------
        RaySearchResult
        """
        shapes = [np.shape(v) for v in (origins, directions)]
        count = max([shape[0] for shape in shapes if len(shape) == 2] + [np.size(s_end), 1])
        feasible = np.empty(count)
        violated = np.empty(count)
        limiting = np.empty(count, dtype=np.int64)
        start_feasible = np.empty(count, dtype=np.bool_)
        evaluations, collisions = self.kernels.search_rays(
            self.model,
            self.position,
            RAY_KINDS[kind],
            _vectors(origins, count),
            _vectors(directions, count),
            _scalars(s_start, count),
            _scalars(s_end, count),
            float(tolerance),
            self.min_step,
            feasible,
            violated,
            limiting,
            start_feasible,
            self.lazy_collision,
            self.kernels.collide,
        )
        self.evaluations += evaluations
        self.collision_evaluations += collisions
        return RaySearchResult(feasible, violated, limiting, start_feasible, evaluations)
