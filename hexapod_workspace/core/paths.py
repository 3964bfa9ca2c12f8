"""Motions: certified checks of moves and toolpaths, and torsion planning for axisymmetric tools.

A **move** (segment) from pose (p₀, R₀) to (p₁, R₁) is parametrised by s ∈ [0, 1]: the position
is linear, ``p(s) = p₀ + s·Δp``, and the orientation follows one of two interpolations:

* ``"slerp"`` (what a controller does): the shortest rotation at constant rate, so the angular
  velocity has constant norm ``Ω = angle(R₀, R₁)`` (rad per unit s);
* ``"tilt-torsion"``: linear in the T&T angles, ``(φ, θ, ψ)(s) = (φ₀, θ₀, ψ₀) + s·(Δφ, Δθ, Δψ)``
  with Δφ and Δψ the wrapped (shortest) differences. At θ = 0 the azimuth is free (``R = Rz(ψ)``
  whatever φ), so an end with θ = 0 takes the other end's φ and the tilt moves along a straight
  ray; at θ = π, where ``R = Rz(2φ − ψ)·Ry(π)``, the same choice of φ is compensated in ψ.

Why no violation wider than the tolerance is missed (certified segments)
-----------------------------------------------------------------------
This extends the argument of :mod:`hexapod_workspace.core.search` from rays (pure rotations at
ω ≤ 1) to moves that translate and rotate at once.

*Angular rate.* For slerp ``|ω(s)| = Ω`` exactly. For the tilt-torsion interpolation, write the
orientation in ZYZ Euler angles ``(α, β, γ) = (φ, θ, ψ − φ)``; the space-frame angular velocity is
``ω = α'·e_z + β'·Rz(α)e_y + γ'·Rz(α)Ry(β)e_z`` and, since e_z ⊥ Rz(α)e_y and
Rz(α)e_y ⊥ Rz(α)Ry(β)e_z,

    |ω|² = α'² + β'² + γ'² + 2α'γ' cos β,   α' = Δφ, β' = Δθ, γ' = Δψ − Δφ.

The rates are constant along the move and β = θ(s) is linear in [0, π], where cos is monotone,
so the maximum over the move is at an end: ``Ω = max over θ ∈ {θ₀, θ₁} of |ω|``.

*Joint speed.* Platform joint i is at ``B_i(s) = p(s) + R(s)·b_i``, so
``|dB_i/ds| = |Δp + ω × R b_i| ≤ |Δp| + Ω·ρ =: V`` with ρ = max_i |b_i|. The base joints
A_i are fixed, so each leg vector ``L_i = B_i − A_i`` moves at most at V.

*Margins.* With ``ℓ_f`` a lower bound on every leg length over the interval considered, the
margins are Lipschitz in s with constants (a minimum of Lipschitz functions keeps the constant;
the angle between two unit vectors changes at most at the sum of their turning rates):

==================== ====================== ==================================================
constraint           bound on |dm/ds|       why
==================== ====================== ==================================================
``leg_length``       V                      |dℓ_i/ds| ≤ |dL_i/ds| ≤ V
``base_joint``       V / ℓ_f                |dn_i/ds| ≤ |dL_i/ds| / ℓ_i; jA_i is fixed
``platform_joint``   Ω + V / ℓ_f            R·jB_i turns at Ω, n_i at ≤ V / ℓ_f
``leg_interference`` 2V                     each leg segment A_iB_i moves by ≤ V (Hausdorff)
==================== ====================== ==================================================

*Interval certificate.* On an interval [a, b] of width w = b − a, with margins m(a), m(b) and
constant L, ``m(s) ≥ max(m(a) − L(s − a), m(b) − L(b − s))`` whose minimum over the interval is

    m_low = min(m(a), m(b), (m(a) + m(b) − L·w) / 2).

The leg-length floor comes the same way: ``ℓ_i ≥ ℓmin + m_leg`` at each end (true for every leg,
feasible or not, since m_leg ≤ ℓ_i − ℓmin_i), so ``ℓ_f = (λ(a) + λ(b) − V·w)/2`` with
``λ = min ℓmin + m_leg``, raised to min ℓmin when the leg-length bound m_low ≥ 0 (then no leg is
shorter than its minimum on the interval). When every m_low ≥ 0 the whole interval is reachable:
it is *certified*. The check bisects the intervals that are not certified, in every segment at
once, until each is certified or narrower than the tolerance ``h`` (in s). The tolerance is
given as an angle ``tol`` (rad): ``h = tol / (Ω + |Δp| / ρ)``, i.e. ``tol`` of platform rotation,
or ``ρ·tol`` of platform-joint travel. Hence:

* an ``ok`` segment has every interval certified, except intervals narrower than ``h`` in which
  every margin is within ``L·h`` of zero: only a violated band narrower than the tolerance can
  hide there;
* the first violation reported is a sampled pose that violates (it is returned with its
  constraints), and every interval before it is certified or narrower than ``h``: no violation
  wider than the tolerance lies before it, and the feasible sample before it is within ``h``.

The smallest relative margin along a segment is reported twice: the smallest over the poses the
check evaluated (``min_relative_margin`` at ``min_at_s``: intervals are also split until no
sample step exceeds ``max_sample_angle`` of motion) and a certified lower bound
(``min_relative_margin_bound``: the smallest ``m_low`` of the final intervals, relative units).
On a violated segment both cover [0, first violation].

Free torsion (axisymmetric tools)
---------------------------------
:func:`plan_torsion` takes positions and tool axes; the torsion ψ at every waypoint is chosen on a
grid of step ``psi_step`` over (−π, π]. Objective, lexicographic:

1. maximise the smallest relative margin along the whole path, measured for every move by the
   certified lower bound ``min_relative_margin_bound`` (so it also bounds the waypoints),
   rounded down to levels of ``margin_resolution`` (0.005 by default): a bottleneck (max-min)
   dynamic programme over waypoints × grid, exact on the grid for these levels, so the plan's
   margin is within one level of the best grid plan;
2. among the plans reaching that optimum, maximise the sum of the moves' certified margins (in
   levels), so the margin stays high where the bottleneck does not bind;
3. then minimise the total torsion travel Σ|Δψ|, so the profile does not zigzag between equal
   choices. (2 and 3 are one min-sum programme over the known moves at the optimum's level.)

A move between two grid torsions counts when its certified check is ok (tolerance ``tol``) and,
with ``max_dpsi``, when ``|wrap(ψ_{k+1} − ψ_k)| ≤ max_dpsi``. Moves certified by their end
margins alone (the interval certificate over the whole move) are not re-checked; the others are
checked in batches, best candidates first, until none of them lies on an optimistic path (one
that counts every unchecked move at its smaller end margin) better than the best plan found. So
the planner is complete to its resolution: "no plan" means that no sequence of grid torsions
gives reachable waypoints joined by ok moves. It then names the first waypoint that no torsion
reaches from the start, and why (the limiting constraints over the grid at that waypoint, or the
constraints that stopped the moves into it).

Where it breaks: the grid. A path whose only feasible torsions lie in intervals narrower than
``psi_step`` may get "no plan" although a finer grid finds one; moves are checked at the
tolerance ``tol`` (bands narrower than it may be missed); the objective is optimal to one level.
Cost grows with (N − 1)·G·B candidate moves (G grid torsions, B torsion changes allowed per
move): ``max_dpsi`` keeps B small. The programmes over these tables are compiled
(:mod:`hexapod_workspace.core.planner_kernels`, a few ms per pass over 1,000 waypoints × 72²
moves, where numpy took ≈ 30 ms); without a torsion limit the full checks of the candidate moves
(≈ 20 µs each) are then most of the time.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from dataclasses import dataclass, field
from typing import TypedDict

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, ResolutionError
from . import planner_kernels
from .constraints import (
    CONSTRAINT_NAMES,
    PoseMargins,
    pose_margins,
    relative_margins,
    violated_names,
)
from .manipulator import Manipulator
from .rotations import (
    approach_to_tilt,
    matrix_to_quaternion,
    matrix_to_tt,
    quaternion_angle,
    quaternion_slerp,
    quaternion_to_matrix,
    tt_to_matrix,
    tt_to_quaternion,
    wrap_angle,
)

__all__ = [
    "DEFAULT_PATH_TOLERANCE",
    "DEFAULT_PSI_STEP",
    "INTERPOLATIONS",
    "BreakPoint",
    "PathCheck",
    "SegmentChecks",
    "TorsionPlan",
    "WaypointChecks",
    "check_path",
    "check_waypoints",
    "plan_torsion",
    "reported_parts",
]

#: Interpolations between waypoints (see the module documentation).
INTERPOLATIONS = ("slerp", "tilt-torsion")
#: Default tolerance of the certified segment check, rad of platform rotation (0.01°).
DEFAULT_PATH_TOLERANCE = math.radians(0.01)
#: Largest step between evaluated poses for the sampled minimum margin, rad of motion.
DEFAULT_MAX_SAMPLE_ANGLE = 0.05
#: Default torsion grid step of the planner, rad (5°).
DEFAULT_PSI_STEP = math.radians(5.0)
#: Relative-margin levels in which the planner maximises its objective.
DEFAULT_MARGIN_RESOLUTION = 0.005
#: Largest coordinate of a position accepted, m (beyond it the kinematics overflow or mean
#: nothing for a hexapod).
MAX_POSITION = 1e6
#: Bounds on the number of waypoints per call and on the torsion grid.
MAX_WAYPOINTS = 1_000_000
MIN_PSI_STEP, MAX_PSI_STEP = math.radians(0.1), math.radians(90.0)
#: Deviation from a rotation matrix accepted in inputs (|RᵀR − I| and |det R − 1|).
ROTATION_TOLERANCE = 1e-6
#: Bisection rounds of a segment check (each halves the widest interval at least once).
MAX_ROUNDS = 200
_SLACK = 1e-12


# ============================================================================ results
@dataclass(frozen=True)
class WaypointChecks:
    """Reachability of every waypoint (the ``check`` result, one position per pose).

    Attributes
    ----------
    positions : ndarray, shape (N, 3)
        Tool-tip positions OC, base frame, m.
    angles : ndarray, shape (N, 3)
        (φ, θ, ψ) in rad, canonical ranges.
    reachable : ndarray, shape (N,), bool
    margins : dict of str to ndarray, shape (N,)
        Signed margin of each constraint (keys :data:`CONSTRAINT_NAMES`; m, rad, rad, m; +inf
        when the interference check is disabled), as in :class:`CheckResult`.
    relative : ndarray, shape (N,)
        Smallest relative margin (dimensionless, see :func:`relative_margins`).
    limiting_constraint : ndarray, shape (N,), int
        Index into :data:`CONSTRAINT_NAMES` of the smallest relative margin.
    limiting_leg : ndarray, shape (N,), int
        1-based leg of the limiting constraint (interference: lower leg of the pair).
    limiting_pair : ndarray, shape (N, 2), int
        1-based closest leg pair (0, 0 when the interference check is disabled).
    """

    positions: NDArray[np.float64]
    angles: NDArray[np.float64]
    reachable: NDArray[np.bool_]
    margins: dict[str, NDArray[np.float64]]
    relative: NDArray[np.float64]
    limiting_constraint: NDArray[np.int64]
    limiting_leg: NDArray[np.int64]
    limiting_pair: NDArray[np.int64]

    def __len__(self) -> int:
        return int(self.reachable.shape[0])

    @property
    def margin_array(self) -> NDArray[np.float64]:
        """The margins as one array, shape (4, N), rows in :data:`CONSTRAINT_NAMES` order."""
        return np.stack([self.margins[name] for name in CONSTRAINT_NAMES])

    @property
    def violated(self) -> list[list[str]]:
        """Per waypoint, the names of the violated constraints."""
        return violated_names(self.margin_array)


@dataclass(frozen=True)
class SegmentChecks:
    """Certified checks of the M = N − 1 moves between consecutive waypoints.

    Attributes
    ----------
    ok : ndarray, shape (M,), bool
        No violation wider than the tolerance anywhere on the move (ends included).
    first_violation_s : ndarray, shape (M,)
        Parameter s ∈ [0, 1] of the first violated pose found (NaN when ok); the true first
        violation lies within one tolerance step ``h`` before it.
    violation_angles : ndarray, shape (M, 3)
        (φ, θ, ψ) of that pose, rad (NaN when ok).
    violation_positions : ndarray, shape (M, 3)
        Its position, base frame, m (NaN when ok).
    violation_margins : ndarray, shape (4, M)
        Its margins (NaN when ok).
    limiting_constraint : ndarray, shape (M,), int
        At the first violation (most violated, relative units), else at the smallest margin.
    limiting_leg : ndarray, shape (M,), int
        1-based leg of that constraint.
    limiting_pair : ndarray, shape (M, 2), int
        1-based closest leg pair at the same pose.
    min_relative_margin : ndarray, shape (M,)
        Smallest relative margin over the evaluated poses of [0, min(1, first violation)].
    min_at_s : ndarray, shape (M,)
        Where it is.
    min_relative_margin_bound : ndarray, shape (M,)
        Certified lower bound of the relative margin over the same range.
    angular_rate : ndarray, shape (M,)
        Ω, bound on the angular speed, rad per unit s.
    translation : ndarray, shape (M,)
        |Δp|, m.
    evaluations : int
        Poses evaluated inside the moves (the waypoints excluded).
    """

    ok: NDArray[np.bool_]
    first_violation_s: NDArray[np.float64]
    violation_angles: NDArray[np.float64]
    violation_positions: NDArray[np.float64]
    violation_margins: NDArray[np.float64]
    limiting_constraint: NDArray[np.int64]
    limiting_leg: NDArray[np.int64]
    limiting_pair: NDArray[np.int64]
    min_relative_margin: NDArray[np.float64]
    min_at_s: NDArray[np.float64]
    min_relative_margin_bound: NDArray[np.float64]
    angular_rate: NDArray[np.float64]
    translation: NDArray[np.float64]
    evaluations: int

    def __len__(self) -> int:
        return int(self.ok.shape[0])

    @property
    def violated(self) -> list[list[str]]:
        """Per move, the constraints violated at its first violation (empty when ok)."""
        return violated_names(
            np.where(np.isnan(self.violation_margins), 0.0, self.violation_margins)
        )


@dataclass(frozen=True)
class PathCheck:
    """Result of :func:`check_path`.

    Attributes
    ----------
    waypoints : WaypointChecks
    segments : SegmentChecks
    interpolation : str
        ``"slerp"`` or ``"tilt-torsion"``.
    tolerance : float
        rad of platform rotation (see the module documentation).
    elapsed : float
        s.
    """

    waypoints: WaypointChecks
    segments: SegmentChecks
    interpolation: str
    tolerance: float
    elapsed: float

    @property
    def ok(self) -> bool:
        """Every waypoint and every move can run."""
        return bool(np.all(self.waypoints.reachable) and np.all(self.segments.ok))

    @property
    def failed_waypoints(self) -> list[int]:
        """0-based indices of the unreachable waypoints."""
        failed: list[int] = np.flatnonzero(~self.waypoints.reachable).tolist()
        return failed

    @property
    def failed_segments(self) -> list[int]:
        """0-based indices of the moves that cannot run (move k joins waypoints k and k + 1)."""
        failed: list[int] = np.flatnonzero(~self.segments.ok).tolist()
        return failed


@dataclass(frozen=True)
class BreakPoint:
    """Where a toolpath cannot be continued by any torsion of the grid.

    Attributes
    ----------
    kind : str
        ``"waypoint"`` (no torsion reaches waypoint ``index``) or ``"segment"`` (no ok move
        from the torsions reachable at waypoint ``index`` to those at ``index + 1``).
    index : int
        0-based waypoint or move index.
    constraints : dict of str to int
        How often each constraint limited the grid torsions (waypoint) or the checked moves
        (segment): why the path breaks.
    reason : str
        One sentence for humans.
    """

    kind: str
    index: int
    constraints: dict[str, int]
    reason: str


@dataclass(frozen=True)
class TorsionPlan:
    """Result of :func:`plan_torsion`.

    Attributes
    ----------
    ok : bool
        A plan exists on the grid.
    psi : ndarray, shape (N,) or None
        Planned torsion at every waypoint, rad in (−π, π] (None without a plan).
    path : PathCheck or None
        The planned path re-checked by :func:`check_path` (None without a plan).
    objective : float
        Smallest certified relative margin along the plan (−inf without a plan).
    baseline : PathCheck
        The same waypoints with ψ ≡ 0 (the paper's recommendation).
    breakpoint : BreakPoint or None
        Where and why the path breaks (None with a plan).
    psi_step : float
        Grid step, rad.
    max_dpsi : float or None
        Largest torsion change per move, rad (None: no limit).
    interpolation : str
    tolerance : float
        rad.
    moves_checked : int
        Candidate moves given the full certified check (the others were certified by their end
        margins or could not improve the plan).
    elapsed : float
        s.
    positions : ndarray, shape (N, 3)
        The waypoints' tool-tip positions, base frame, m.
    directions : ndarray, shape (N, 2)
        The tool directions (φ, θ) of the given axes, rad.
    """

    ok: bool
    psi: NDArray[np.float64] | None
    path: PathCheck | None
    objective: float
    baseline: PathCheck
    breakpoint: BreakPoint | None
    psi_step: float
    max_dpsi: float | None
    interpolation: str
    tolerance: float
    moves_checked: int
    elapsed: float
    positions: NDArray[np.float64] = field(repr=False)
    directions: NDArray[np.float64] = field(repr=False)

    @property
    def reported(self) -> PathCheck:
        """The path this plan reports: the planned one when ok, otherwise the ψ = 0 baseline."""
        return self.path if self.ok and self.path is not None else self.baseline


def reported_parts(result: PathCheck | TorsionPlan) -> tuple[PathCheck, TorsionPlan | None]:
    """The path a result reports (:attr:`TorsionPlan.reported` for a plan) and the plan, if any."""
    if isinstance(result, TorsionPlan):
        return result.reported, result
    return result, None


# ============================================================================ inputs
def _validate_positions(positions: ArrayLike, minimum: int = 2) -> NDArray[np.float64]:
    array = np.asarray(positions, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 3:
        msg = f"positions: expected shape (N, 3) in m, got {array.shape}"
        raise InputError(msg)
    if not minimum <= array.shape[0] <= MAX_WAYPOINTS:
        msg = f"positions: expected {minimum} to {MAX_WAYPOINTS} waypoints, got {array.shape[0]}"
        raise InputError(msg)
    bad = ~np.all(np.isfinite(array) & (np.abs(array) <= MAX_POSITION), axis=1)
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        msg = (
            f"positions: expected finite values within ±{MAX_POSITION:g} m, "
            f"waypoint {row} is {array[row].tolist()}"
        )
        raise InputError(msg)
    return array


def _first_bad_row(ok: NDArray[np.bool_]) -> int | None:
    bad = np.flatnonzero(~ok)
    return int(bad[0]) if bad.size else None


def _orientations(
    count: int,
    angles: ArrayLike | None,
    quaternions: ArrayLike | None,
    rotations: ArrayLike | None,
) -> NDArray[np.float64]:
    """Rotation matrices (N, 3, 3) from exactly one of the three forms, validated."""
    given = [
        name
        for name, v in (("angles", angles), ("quaternions", quaternions), ("rotations", rotations))
        if v is not None
    ]
    if len(given) != 1:
        msg = f"orientations: give exactly one of angles, quaternions, rotations (got {given})"
        raise InputError(msg)
    if angles is not None:
        array = np.asarray(angles, dtype=np.float64)
        if array.shape != (count, 3):
            msg = f"angles: expected shape ({count}, 3) of (phi, theta, psi), got {array.shape}"
            raise InputError(msg)
        row = _first_bad_row(np.all(np.isfinite(array), axis=1))
        if row is not None:
            msg = f"angles: expected finite values, waypoint {row} is {array[row].tolist()}"
            raise InputError(msg)
        # Reduce each angle to its principal value first (exact): combining huge angles
        # (ψ − φ) before reducing would lose every significant digit.
        return tt_to_matrix(wrap_angle(array))
    if quaternions is not None:
        unit = _unit_rows(quaternions, count, 4, "quaternions", "(x, y, z, w)")
        return quaternion_to_matrix(unit)
    array = np.asarray(rotations, dtype=np.float64)
    if array.shape != (count, 3, 3):
        msg = f"rotations: expected shape ({count}, 3, 3), got {array.shape}"
        raise InputError(msg)
    finite = np.all(np.isfinite(array), axis=(1, 2))
    safe = np.where(finite[:, None, None], array, np.eye(3))
    gram = np.abs(np.einsum("nki,nkj->nij", safe, safe) - np.eye(3)).max(axis=(1, 2))
    row = _first_bad_row(
        finite & (gram <= ROTATION_TOLERANCE) & (np.abs(np.linalg.det(safe) - 1.0) <= 1e-5)
    )
    if row is not None:
        msg = f"rotations: waypoint {row} is not a finite rotation matrix (orthonormal, det 1)"
        raise InputError(msg)
    return array


def _unit_rows(
    values: ArrayLike, count: int, width: int, name: str, what: str
) -> NDArray[np.float64]:
    """Rows (count, width) normalised to unit length; zero or non-finite rows refused."""
    array = np.asarray(values, dtype=np.float64)
    if array.shape != (count, width):
        msg = f"{name}: expected shape ({count}, {width}) of {what}, got {array.shape}"
        raise InputError(msg)
    # Scale each row by its largest component first: huge or tiny finite rows keep their
    # direction instead of overflowing or underflowing in the norm.
    with np.errstate(invalid="ignore"):
        scale = np.max(np.abs(array), axis=1)
    row = _first_bad_row(np.all(np.isfinite(array), axis=1) & (scale > 0.0))
    if row is not None:
        msg = f"{name}: expected finite non-zero values, waypoint {row} is {array[row].tolist()}"
        raise InputError(msg)
    scaled = array / scale[:, None]
    unit: NDArray[np.float64] = scaled / np.linalg.norm(scaled, axis=1, keepdims=True)
    return unit


def _validate_interpolation(interpolation: str) -> str:
    if interpolation not in INTERPOLATIONS:
        msg = f"interpolation: expected one of {', '.join(INTERPOLATIONS)}, got {interpolation!r}"
        raise InputError(msg)
    return interpolation


def _validate_tolerance(tolerance: float) -> float:
    value = float(tolerance)
    if not (math.isfinite(value) and 1e-9 <= value <= 0.1):
        msg = f"tolerance: expected 1e-09 to 0.1 rad, got {tolerance!r}"
        raise ResolutionError(msg)
    return value


# ============================================================================ moves
class _Moves:
    """A batch of K moves: interpolated poses and the rate bounds of the module documentation.

    Parameters
    ----------
    positions0, positions1 : ndarray, shape (K, 3)
        m.
    rotations0, rotations1 : ndarray, shape (K, 3, 3)
    interpolation : str
    rho : float
        max_i |b_i|, m.
    """

    def __init__(
        self,
        positions0: NDArray[np.float64],
        positions1: NDArray[np.float64],
        rotations0: NDArray[np.float64],
        rotations1: NDArray[np.float64],
        interpolation: str,
        rho: float,
        quaternions: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    ) -> None:
        self.p0 = positions0
        self.dp = positions1 - positions0
        self.translation = np.linalg.norm(self.dp, axis=1)
        self.interpolation = interpolation
        if interpolation == "slerp":
            q0, q1 = (
                quaternions
                if quaternions is not None
                else (matrix_to_quaternion(rotations0), matrix_to_quaternion(rotations1))
            )
            self.q0, self.q1 = q0, q1
            self.omega = quaternion_angle(q0, q1)
        else:
            a0, a1 = matrix_to_tt(rotations0), matrix_to_tt(rotations1)
            a0, a1 = _align_singular(a0, a1), _align_singular(a1, a0)
            self.a0 = a0
            self.da = np.column_stack(
                [
                    wrap_angle(a1[:, 0] - a0[:, 0]),
                    a1[:, 1] - a0[:, 1],
                    wrap_angle(a1[:, 2] - a0[:, 2]),
                ]
            )
            d_alpha, d_beta = self.da[:, 0], self.da[:, 1]
            d_gamma = self.da[:, 2] - self.da[:, 0]
            base = d_alpha**2 + d_beta**2 + d_gamma**2
            cross = 2.0 * d_alpha * d_gamma
            squared = np.maximum(base + cross * np.cos(a0[:, 1]), base + cross * np.cos(a1[:, 1]))
            self.omega = np.sqrt(np.maximum(squared, 0.0))
        self.speed = self.translation + rho * self.omega  # V, m per unit s
        self.rate = self.omega + self.translation / rho  # motion in rad-equivalent per unit s

    def poses(
        self, moves: NDArray[np.int64], s: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Rotations (n, 3, 3) and positions (n, 3) of moves ``moves`` (n,) at parameters s."""
        positions = self.p0[moves] + s[:, None] * self.dp[moves]
        if self.interpolation == "slerp":
            rotations = quaternion_to_matrix(quaternion_slerp(self.q0[moves], self.q1[moves], s))
        else:
            rotations = tt_to_matrix(self.a0[moves] + s[:, None] * self.da[moves])
        return rotations, positions


def _align_singular(angles: NDArray[np.float64], other: NDArray[np.float64]) -> NDArray[np.float64]:
    """T&T angles with φ taken from ``other`` where θ is 0 or π (same rotation), (K, 3)."""
    theta = angles[:, 1]
    top = np.sin(theta) < 1e-12
    if not np.any(top):
        return angles
    out = angles.copy()
    phi_new = other[:, 0]
    bottom = top & (np.cos(theta) < 0.0)
    # θ = 0: R = Rz(ψ) for every φ. θ = π: R = Rz(2φ − ψ)·Ry(π), so ψ moves by 2Δφ.
    out[top, 0] = phi_new[top]
    out[bottom, 2] = wrap_angle(angles[bottom, 2] + 2.0 * (phi_new[bottom] - angles[bottom, 0]))
    return out


class _Certifier:
    """Interval certificates of the module documentation for one manipulator."""

    def __init__(self, manipulator: Manipulator) -> None:
        self.manipulator = manipulator
        self.rho = float(np.max(np.linalg.norm(manipulator.platform_joints, axis=1)))
        self.length_min = float(np.min(manipulator.leg_length_min))

    def margins(
        self, rotations: NDArray[np.float64], positions: NDArray[np.float64]
    ) -> PoseMargins:
        """The margins of n poses: rotations (n, 3, 3), positions (n, 3) in m."""
        return pose_margins(self.manipulator, rotations, positions)

    def lower_bounds(
        self,
        start: NDArray[np.float64],
        end: NDArray[np.float64],
        width: NDArray[np.float64],
        speed: NDArray[np.float64],
        omega: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """Certified lower bounds (4, n) of the margins over intervals of ``width`` (n,) in s,
        from the margins (4, n) at both ends and the move's V and Ω (n,)."""
        travel = speed * width
        lipschitz_travel = np.empty_like(start)
        with np.errstate(invalid="ignore", over="ignore"):
            lipschitz_travel[0] = travel
            lipschitz_travel[3] = 2.0 * travel
            low_length = np.minimum(
                np.minimum(start[0], end[0]), 0.5 * (start[0] + end[0] - travel)
            )
            floor = 0.5 * (2.0 * self.length_min + start[0] + end[0] - travel)
            floor = np.where(low_length >= 0.0, np.maximum(floor, self.length_min), floor)
            turn = np.where(floor > 0.0, travel / np.where(floor > 0.0, floor, 1.0), np.inf)
            lipschitz_travel[1] = turn
            lipschitz_travel[2] = omega * width + turn
            low: NDArray[np.float64] = np.minimum(
                np.minimum(start, end), 0.5 * (start + end - lipschitz_travel)
            )
        low[0] = low_length
        return low

    def relative(self, margins: NDArray[np.float64]) -> NDArray[np.float64]:
        """Smallest relative margin per column of ``margins`` (4, n); NaN → −inf."""
        if margins.shape[1] == 0:
            return np.zeros(0)
        values = relative_margins(self.manipulator, margins).min(axis=0)
        smallest: NDArray[np.float64] = np.where(np.isnan(values), -np.inf, values)
        return smallest


class _Samples(TypedDict):
    """Sample table of :func:`_check_moves`: one column per evaluated pose (the K start ends,
    the K far ends, then the interior samples in the order evaluated)."""

    s: NDArray[np.float64]  # (n,) parameter along its move
    move: NDArray[np.int64]  # (n,) index of its move
    margins: NDArray[np.float64]  # (4, n)
    legs: NDArray[np.int64]  # (4, n) limiting leg per constraint, 0-based
    pairs: NDArray[np.int64]  # (n, 2) closest leg pair, 0-based


@dataclass
class _MoveCheck:
    """Raw per-move outcome of :func:`_check_moves` (arrays over the K moves)."""

    ok: NDArray[np.bool_]
    first_bad: NDArray[np.float64]
    bad_index: NDArray[np.int64]  # row in the sample table of the first violated pose
    min_value: NDArray[np.float64]
    min_s: NDArray[np.float64]
    min_index: NDArray[np.int64]
    bound: NDArray[np.float64]
    samples: _Samples
    evaluations: int


def _check_moves(
    certifier: _Certifier,
    moves: _Moves,
    start: NDArray[np.float64],
    end: NDArray[np.float64],
    tolerance: float,
    max_sample_angle: float,
    start_pose: tuple[NDArray[np.int64], NDArray[np.int64]] | None = None,
    end_pose: tuple[NDArray[np.int64], NDArray[np.int64]] | None = None,
    locate_minimum: bool = True,
) -> _MoveCheck:
    """Certified check of K moves given their end margins (4, K), vectorised over moves.

    ``start_pose``/``end_pose`` are optional (legs (4, K), pairs (K, 2)) of the ends, kept in
    the sample table so that limiting legs at the ends can be reported. Without
    ``locate_minimum`` (the planner) only the smallest sampled margin is computed, not where it
    is (``min_index`` −1, ``min_s`` NaN): the same values, without sorting the sample table.
    """
    count = start.shape[1]
    with np.errstate(divide="ignore"):
        h_tol = np.where(moves.rate > 0.0, tolerance / moves.rate, np.inf)
        h_max = np.where(moves.rate > 0.0, max_sample_angle / moves.rate, np.inf)
    ids = np.arange(count)
    zeros4 = np.zeros((4, count), dtype=np.int64)
    zeros2 = np.zeros((count, 2), dtype=np.int64)
    start_legs, start_pairs = start_pose if start_pose is not None else (zeros4, zeros2)
    end_legs, end_pairs = end_pose if end_pose is not None else (zeros4, zeros2)
    # Sample table: ends first (rows 0..K-1 start, K..2K-1 end), then interior samples.
    table_s = [np.zeros(count), np.ones(count)]
    table_move = [ids, ids]
    table_margins = [start, end]
    table_legs = [start_legs, end_legs]
    table_pairs = [start_pairs, end_pairs]
    feasible_start = np.all(start >= 0.0, axis=0)
    feasible_end = np.all(end >= 0.0, axis=0)
    first_bad = np.where(feasible_start, np.where(feasible_end, np.inf, 1.0), 0.0)
    bad_index = np.where(feasible_start, np.where(feasible_end, -1, count + ids), ids)
    # Intervals: move, a, b, row of a and b in the sample table.
    move, lo, hi = ids, np.zeros(count), np.ones(count)
    row_lo, row_hi = ids.copy(), count + ids
    margins_lo, margins_hi = start, end
    final_move, final_lo, final_bound = [], [], []
    next_row = 2 * count
    evaluations = 0
    for _ in range(MAX_ROUNDS):
        keep = lo < first_bad[move]
        move, lo, hi, row_lo, row_hi = move[keep], lo[keep], hi[keep], row_lo[keep], row_hi[keep]
        margins_lo, margins_hi = margins_lo[:, keep], margins_hi[:, keep]
        if move.size == 0:
            break
        width = hi - lo
        bounds = certifier.lower_bounds(
            margins_lo, margins_hi, width, moves.speed[move], moves.omega[move]
        )
        certified = np.all(bounds >= 0.0, axis=0)
        split = np.where(certified, width > h_max[move], width > h_tol[move])
        done = ~split
        final_move.append(move[done])
        final_lo.append(lo[done])
        final_bound.append(certifier.relative(bounds[:, done]))
        if not np.any(split):
            break
        move, lo, hi = move[split], lo[split], hi[split]
        row_lo, row_hi = row_lo[split], row_hi[split]
        margins_lo, margins_hi = margins_lo[:, split], margins_hi[:, split]
        middle = 0.5 * (lo + hi)
        rotations, positions = moves.poses(move, middle)
        found = certifier.margins(rotations, positions)
        evaluations += middle.size
        rows = next_row + np.arange(middle.size)
        next_row += middle.size
        table_s.append(middle)
        table_move.append(move)
        table_margins.append(found.margins)
        table_legs.append(found.limiting_legs)
        table_pairs.append(found.limiting_pairs)
        violated = ~np.all(found.margins >= 0.0, axis=0)
        if np.any(violated):
            # Earliest violated sample per move (np.minimum.at keeps the smallest s).
            candidate = np.full(count, np.inf)
            np.minimum.at(candidate, move[violated], middle[violated])
            better = candidate < first_bad
            first_bad[better] = candidate[better]
            hit = violated & (middle == first_bad[move])
            bad_index[move[hit]] = rows[hit]
        move = np.concatenate([move, move])
        lo, hi = np.concatenate([lo, middle]), np.concatenate([middle, hi])
        row_lo, row_hi = np.concatenate([row_lo, rows]), np.concatenate([rows, row_hi])
        margins_lo = np.concatenate([margins_lo, found.margins], axis=1)
        margins_hi = np.concatenate([found.margins, margins_hi], axis=1)
    else:  # pragma: no cover - MAX_ROUNDS halvings reach any tolerance >= 1e-9 first
        msg = "segment check did not converge"
        raise RuntimeError(msg)
    samples: _Samples = {
        "s": np.concatenate(table_s),
        "move": np.concatenate(table_move),
        "margins": np.concatenate(table_margins, axis=1),
        "legs": np.concatenate(table_legs, axis=1),
        "pairs": np.concatenate(table_pairs, axis=0),
    }
    # Minimum over the samples of [0, first violation] and over the final interval bounds.
    relative = certifier.relative(samples["margins"])
    inside = samples["s"] <= np.minimum(first_bad, 1.0)[samples["move"]]
    if locate_minimum:
        # Per move: inside first, smallest (every move has its start, s = 0, inside).
        order = np.lexsort((relative, ~inside, samples["move"]))
        first_of_move = np.searchsorted(samples["move"][order], ids)
        min_index = order[first_of_move]
        min_value = relative[min_index]
        min_s = samples["s"][min_index]
    else:
        min_value = np.full(count, np.inf)
        np.minimum.at(min_value, samples["move"][inside], relative[inside])
        min_index = np.full(count, -1, dtype=np.int64)
        min_s = np.full(count, np.nan)
    bound = np.full(count, np.inf)
    if final_move:
        f_move, f_lo = np.concatenate(final_move), np.concatenate(final_lo)
        f_bound = np.concatenate(final_bound)
        before = f_lo < first_bad[f_move]
        np.minimum.at(bound, f_move[before], f_bound[before])
    ok = ~np.isfinite(first_bad)
    bound = np.minimum(bound, min_value)
    return _MoveCheck(
        ok=ok,
        first_bad=np.where(ok, np.nan, first_bad),
        bad_index=bad_index,
        min_value=min_value,
        min_s=min_s,
        min_index=min_index,
        bound=bound,
        samples=samples,
        evaluations=evaluations,
    )


# ============================================================================ check_path
def _waypoint_checks(
    certifier: _Certifier, positions: NDArray[np.float64], rotations: NDArray[np.float64]
) -> tuple[WaypointChecks, PoseMargins]:
    found = certifier.margins(rotations, positions)
    relative = relative_margins(certifier.manipulator, found.margins)
    limiting = np.argmin(np.where(np.isnan(relative), -np.inf, relative), axis=0)
    columns = np.arange(positions.shape[0])
    enabled = certifier.manipulator.leg_diameter > 0.0
    result = WaypointChecks(
        positions=positions,
        angles=matrix_to_tt(rotations),
        reachable=found.reachable,
        margins={name: found.margins[k] for k, name in enumerate(CONSTRAINT_NAMES)},
        relative=certifier.relative(found.margins),
        limiting_constraint=limiting,
        limiting_leg=found.limiting_legs[limiting, columns] + 1,
        limiting_pair=found.limiting_pairs + 1 if enabled else found.limiting_pairs,
    )
    return result, found


def check_waypoints(
    manipulator: Manipulator,
    positions: ArrayLike,
    *,
    angles: ArrayLike | None = None,
    quaternions: ArrayLike | None = None,
    rotations: ArrayLike | None = None,
) -> WaypointChecks:
    """Check N poses, each at its own position (what ROS poses are), without the moves.

    Parameters are those of :func:`check_path` (N ≥ 1).

    Returns
    -------
    WaypointChecks

    Raises
    ------
    InputError
        As :func:`check_path`.
    """
    positions = _validate_positions(positions, minimum=1)
    matrices = _orientations(positions.shape[0], angles, quaternions, rotations)
    return _waypoint_checks(_Certifier(manipulator), positions, matrices)[0]


def check_path(
    manipulator: Manipulator,
    positions: ArrayLike,
    *,
    angles: ArrayLike | None = None,
    quaternions: ArrayLike | None = None,
    rotations: ArrayLike | None = None,
    interpolation: str = "slerp",
    tolerance: float = DEFAULT_PATH_TOLERANCE,
    max_sample_angle: float = DEFAULT_MAX_SAMPLE_ANGLE,
) -> PathCheck:
    """Check a path of N waypoints and the N − 1 moves between them, certified.

    Parameters
    ----------
    manipulator : Manipulator
    positions : array_like, shape (N, 3)
        Tool-tip positions OC, base frame, m (N ≥ 2).
    angles : array_like, shape (N, 3), optional
        Orientations as T&T angles (φ, θ, ψ), rad (any finite values; reduced first).
    quaternions : array_like, shape (N, 4), optional
        Orientations as quaternions (x, y, z, w), any non-zero norm.
    rotations : array_like, shape (N, 3, 3), optional
        Orientations as rotation matrices (mobile frame in base frame).
        Exactly one of ``angles``, ``quaternions``, ``rotations`` is given.
    interpolation : {"slerp", "tilt-torsion"}
        Orientation between waypoints (see the module documentation).
    tolerance : float
        Width (rad of platform rotation, or ρ·tolerance of joint travel) below which a violated
        band may be missed; also the accuracy of the first violation. 1e-9 to 0.1.
    max_sample_angle : float
        Largest motion (rad-equivalent) between poses evaluated for the sampled minimum margin.

    Returns
    -------
    PathCheck
        Unreachable poses and moves are results, not exceptions.

    Raises
    ------
    InputError
        Wrong shapes, fewer than 2 waypoints, NaN/infinite or absurd values, zero quaternions,
        non-rotation matrices, unknown interpolation.
    """
    started = time.perf_counter()
    positions = _validate_positions(positions)
    matrices = _orientations(positions.shape[0], angles, quaternions, rotations)
    interpolation = _validate_interpolation(interpolation)
    tolerance = _validate_tolerance(tolerance)
    if not (math.isfinite(max_sample_angle) and max_sample_angle >= tolerance):
        msg = f"max_sample_angle: expected a finite value >= tolerance, got {max_sample_angle!r}"
        raise ResolutionError(msg)
    certifier = _Certifier(manipulator)
    waypoints, found = _waypoint_checks(certifier, positions, matrices)
    moves = _Moves(
        positions[:-1], positions[1:], matrices[:-1], matrices[1:], interpolation, certifier.rho
    )
    raw = _check_moves(
        certifier,
        moves,
        found.margins[:, :-1],
        found.margins[:, 1:],
        tolerance,
        max_sample_angle,
        (found.limiting_legs[:, :-1], found.limiting_pairs[:-1]),
        (found.limiting_legs[:, 1:], found.limiting_pairs[1:]),
    )
    segments = _segment_checks(certifier, moves, raw)
    return PathCheck(
        waypoints=waypoints,
        segments=segments,
        interpolation=interpolation,
        tolerance=tolerance,
        elapsed=time.perf_counter() - started,
    )


def _segment_checks(certifier: _Certifier, moves: _Moves, raw: _MoveCheck) -> SegmentChecks:
    """Per-move results from the raw check: violation pose, limiting constraint and leg."""
    count = raw.ok.shape[0]
    samples = raw.samples
    # The pose that names the limiting constraint: first violation, else the smallest margin.
    rows = np.where(raw.ok, raw.min_index, raw.bad_index)
    margins = samples["margins"][:, rows]
    relative = relative_margins(certifier.manipulator, margins)
    limiting = np.argmin(np.where(np.isnan(relative), -np.inf, relative), axis=0)
    legs = samples["legs"][limiting, rows] + 1
    enabled = certifier.manipulator.leg_diameter > 0.0
    pairs = samples["pairs"][rows] + 1 if enabled else np.zeros((count, 2), dtype=np.int64)
    s_bad = np.where(raw.ok, 0.0, raw.first_bad)
    rotations, positions = moves.poses(np.arange(count), s_bad)
    angles = matrix_to_tt(rotations)
    nan_rows = raw.ok
    angles[nan_rows] = np.nan
    positions[nan_rows] = np.nan
    violation_margins = np.where(nan_rows[None, :], np.nan, margins)
    return SegmentChecks(
        ok=raw.ok,
        first_violation_s=raw.first_bad,
        violation_angles=angles,
        violation_positions=positions,
        violation_margins=violation_margins,
        limiting_constraint=limiting,
        limiting_leg=legs,
        limiting_pair=pairs,
        min_relative_margin=raw.min_value,
        min_at_s=raw.min_s,
        min_relative_margin_bound=raw.bound,
        angular_rate=moves.omega,
        translation=moves.translation,
        evaluations=raw.evaluations,
    )


# ============================================================================ planner
def plan_torsion(
    manipulator: Manipulator,
    positions: ArrayLike,
    tool_axes: ArrayLike,
    *,
    psi_step: float = DEFAULT_PSI_STEP,
    max_dpsi: float | None = None,
    interpolation: str = "slerp",
    tolerance: float = DEFAULT_PATH_TOLERANCE,
    margin_resolution: float = DEFAULT_MARGIN_RESOLUTION,
) -> TorsionPlan:
    """Choose the torsion at every waypoint of a toolpath for an axisymmetric tool.

    See the module documentation for the objective, the completeness statement and the
    certified move checks.

    Parameters
    ----------
    manipulator : Manipulator
    positions : array_like, shape (N, 3)
        Tool-tip positions, base frame, m (N ≥ 2).
    tool_axes : array_like, shape (N, 3)
        Approach vectors (tool axis z' in the base frame), any non-zero length.
    psi_step : float
        Torsion grid step, rad (0.1° to 90°); the grid is ``−π + k·step`` (it contains ψ = 0
        when the step divides π).
    max_dpsi : float, optional
        Largest torsion change per move, rad (None: no limit).
    interpolation : {"slerp", "tilt-torsion"}
    tolerance : float
        Tolerance of the certified move checks, rad.
    margin_resolution : float
        The objective is maximised in levels of this many relative-margin units (1e-6 to
        0.1): the plan's smallest margin is within this of the best on the grid.

    Returns
    -------
    TorsionPlan
        "No plan" is a result (``ok`` False with a :class:`BreakPoint`), not an exception.

    Raises
    ------
    InputError
        Bad shapes, fewer than 2 waypoints, non-finite or zero axes, bad options.
    """
    started = time.perf_counter()
    positions = _validate_positions(positions)
    count = positions.shape[0]
    axes = _unit_rows(tool_axes, count, 3, "tool_axes", "(x, y, z) tool axes")
    interpolation = _validate_interpolation(interpolation)
    tolerance = _validate_tolerance(tolerance)
    psi_step = float(psi_step)
    if not (math.isfinite(psi_step) and MIN_PSI_STEP <= psi_step <= MAX_PSI_STEP):
        msg = f"psi_step: expected {MIN_PSI_STEP:.4g} to {MAX_PSI_STEP:.4g} rad, got {psi_step!r}"
        raise ResolutionError(msg)
    if max_dpsi is not None:
        max_dpsi = float(max_dpsi)
        if not (math.isfinite(max_dpsi) and max_dpsi >= 0.0):
            msg = f"max_dpsi: expected a finite value >= 0 rad or None, got {max_dpsi!r}"
            raise InputError(msg)
    directions = approach_to_tilt(axes)  # (N, 2)
    baseline = check_path(
        manipulator,
        positions,
        angles=np.column_stack([directions, np.zeros(count)]),
        interpolation=interpolation,
        tolerance=tolerance,
    )
    margin_resolution = float(margin_resolution)
    if not (math.isfinite(margin_resolution) and 1e-6 <= margin_resolution <= 0.1):
        msg = f"margin_resolution: expected 1e-06 to 0.1, got {margin_resolution!r}"
        raise ResolutionError(msg)
    planner = _Planner(
        manipulator,
        positions,
        directions,
        psi_step,
        max_dpsi,
        interpolation,
        tolerance,
        margin_resolution,
    )
    psi, objective, breakpoint = planner.solve()
    path = None
    if psi is not None:
        path = check_path(
            manipulator,
            positions,
            angles=np.column_stack([directions, psi]),
            interpolation=interpolation,
            tolerance=tolerance,
        )
    return TorsionPlan(
        ok=psi is not None,
        psi=psi,
        path=path,
        objective=objective,
        baseline=baseline,
        breakpoint=breakpoint,
        psi_step=psi_step,
        max_dpsi=max_dpsi,
        interpolation=interpolation,
        tolerance=tolerance,
        moves_checked=planner.moves_checked,
        elapsed=time.perf_counter() - started,
        positions=positions,
        directions=directions,
    )


#: Level code of "no move" (infeasible or not allowed) in the planner's integer tables.
_NONE = planner_kernels.NONE
#: Largest level magnitude stored (relative margins beyond ±2^30 levels are clipped).
_LEVEL_CLIP = 2**30
#: Pair status in the planner: no move, value known, not yet checked (optimistic value).
_NO, _KNOWN, _UNKNOWN = planner_kernels.NO, planner_kernels.KNOWN, planner_kernels.UNKNOWN
#: Moves given the full certified check per batch of the planner.
CHECK_BATCH = 2000
#: Largest number of candidate moves (waypoint pairs × torsions × torsion changes) per plan.
MAX_PLAN_MOVES = 30_000_000


def _best_first(through: NDArray[np.int32], count: int) -> NDArray[np.int64]:
    """Indices of the ``count`` largest values, largest first, ties in index order: exactly
    ``np.argsort(-through, kind="stable")[:count]``, in O(n) plus a sort of ``count`` values."""
    size = through.shape[0]
    if size <= count:
        return np.argsort(-through.astype(np.int64), kind="stable")
    threshold = np.partition(through, size - count)[size - count]  # the count-th largest
    above = np.flatnonzero(through > threshold)
    ties = np.flatnonzero(through == threshold)[: count - above.size]
    chosen = np.union1d(above, ties)  # sorted: index order
    order = np.argsort(-through[chosen].astype(np.int64), kind="stable")
    return chosen[order].astype(np.int64)


class _Planner:
    """Bottleneck + min-travel dynamic programmes over waypoints × torsion grid.

    Values are integer levels ``floor(relative margin / resolution)``. A move from torsion g at
    waypoint k goes to ``h = (g + offset) mod G`` for the allowed offsets (all of them, or those
    within ``max_dpsi``), so the tables are banded, shape (N − 1, G, B). Every move is in one of
    three states: no move (an end unreachable or checked and not ok), known (certified by its
    end margins alone, or checked in full; value = level of its certified lower bound) or
    unknown (not certified by its ends; its value is at most the level of its smaller end
    margin: the *optimistic* value). The search checks, in batches, the unknown moves that lie
    on an optimistic path better than the best known plan, until none is left: the best known
    plan is then optimal on the grid (to one level).
    """

    def __init__(
        self,
        manipulator: Manipulator,
        positions: NDArray[np.float64],
        directions: NDArray[np.float64],
        psi_step: float,
        max_dpsi: float | None,
        interpolation: str,
        tolerance: float,
        resolution: float,
    ) -> None:
        self.certifier = _Certifier(manipulator)
        self.positions = positions
        self.interpolation = interpolation
        self.tolerance = tolerance
        self.resolution = resolution
        self.max_dpsi = max_dpsi
        self.moves_checked = 0
        size = max(1, round(2.0 * math.pi / psi_step))
        self.grid = wrap_angle(-math.pi + psi_step * np.arange(size))
        self.grid_size = size
        reach = size // 2 if max_dpsi is None else math.floor(max_dpsi / psi_step + 1e-9)
        if 2 * reach + 1 >= size:
            offsets = np.arange(size) - size // 2
        else:
            offsets = np.arange(-reach, reach + 1)
        self.offsets = offsets
        count = positions.shape[0]
        if (count - 1) * size * offsets.size > MAX_PLAN_MOVES:
            msg = (
                f"plan_torsion: {count - 1} moves x {size} torsions x {offsets.size} torsion "
                f"changes exceed {MAX_PLAN_MOVES:g} candidate moves; use a coarser psi_step, "
                f"a max_dpsi or fewer waypoints"
            )
            raise ResolutionError(msg)
        # dest[g, b]: target torsion of offset b from torsion g.
        self.dest = (np.arange(size)[:, None] + offsets[None, :]) % size
        self.travel = np.abs(wrap_angle(offsets * (2.0 * math.pi / size)))  # (B,)
        angles = np.empty((count, size, 3))
        angles[:, :, 0] = directions[:, 0:1]
        angles[:, :, 1] = directions[:, 1:2]
        angles[:, :, 2] = self.grid
        self.rotations = tt_to_matrix(angles)  # (N, G, 3, 3)
        self.quaternions = tt_to_quaternion(angles)  # (N, G, 4)
        flat = self.certifier.margins(
            self.rotations.reshape(-1, 3, 3), np.repeat(positions, size, axis=0)
        )
        self.margins = flat.margins.reshape(4, count, size)
        self.relative_flat = relative_margins(manipulator, flat.margins)
        self.feasible = np.all(self.margins >= 0.0, axis=0)  # (N, G)
        self.levels = np.where(
            self.feasible,
            self._level(self.certifier.relative(flat.margins)).reshape(count, size),
            _NONE,
        ).astype(np.int32)
        shape = (count - 1, size, offsets.size)
        self.status = np.zeros(shape, dtype=np.uint8)
        self.value = np.full(shape, _NONE, dtype=np.int32)
        self.stopped = np.full(shape, -1, dtype=np.int8)
        self._certify_by_ends()

    def _level(self, values: NDArray[np.float64]) -> NDArray[np.int32]:
        """Relative margins as integer levels of the margin resolution (NaN → no move)."""
        with np.errstate(invalid="ignore", over="ignore"):
            scaled = np.floor(values / self.resolution)
        scaled = np.clip(np.nan_to_num(scaled, nan=-np.inf), -_LEVEL_CLIP, _LEVEL_CLIP)
        return scaled.astype(np.int32)

    def _moves(self, k: NDArray[np.int64], g: NDArray[np.int64], h: NDArray[np.int64]) -> _Moves:
        return _Moves(
            self.positions[k],
            self.positions[k + 1],
            self.rotations[k, g],
            self.rotations[k + 1, h],
            self.interpolation,
            self.certifier.rho,
            quaternions=(self.quaternions[k, g], self.quaternions[k + 1, h]),
        )

    def _certify_by_ends(self) -> None:
        """Status and values of every allowed move between reachable ends, from the end margins
        alone (interval certificate over the whole move)."""
        per_step = self.grid_size * self.offsets.size
        chunk = max(1, 200_000 // per_step)
        for first in range(0, self.status.shape[0], chunk):
            last = min(first + chunk, self.status.shape[0])
            steps = np.arange(first, last)[:, None, None]
            pairs = self.feasible[first:last, :, None] & self.feasible[steps + 1, self.dest]
            k, g, b = np.nonzero(pairs)
            k = k + first
            h = self.dest[g, b]
            moves = self._moves(k, g, h)
            bounds = self.certifier.lower_bounds(
                self.margins[:, k, g],
                self.margins[:, k + 1, h],
                np.ones(k.size),
                moves.speed,
                moves.omega,
            )
            certified = np.all(bounds >= 0.0, axis=0)
            self.status[k, g, b] = np.where(certified, _KNOWN, _UNKNOWN)
            # Unknown moves: at most the level of their smaller end margin.
            optimistic = np.minimum(self.levels[k, g], self.levels[k + 1, h])
            self.value[k, g, b] = np.where(
                certified, self._level(self.certifier.relative(bounds)), optimistic
            )

    # ---------------------------------------------------------------- programmes
    def _forward(self, optimistic: bool) -> NDArray[np.int32]:
        """Bottleneck value (N, G) of the best path from waypoint 0 to each state (compiled:
        :func:`planner_kernels.forward`)."""
        reach = np.empty(self.levels.shape, dtype=np.int32)
        planner_kernels.forward(
            self.levels[0], self.status, self.value, self.dest, optimistic, reach
        )
        return reach

    def _backward(self) -> NDArray[np.int32]:
        """Optimistic bottleneck value (N, G) of the best path from each state to the end."""
        back = np.empty(self.levels.shape, dtype=np.int32)
        planner_kernels.backward(self.levels, self.status, self.value, self.dest, back)
        return back

    def _check(self, k: NDArray[np.int64], g: NDArray[np.int64], b: NDArray[np.int64]) -> None:
        """Full certified check of moves (k, g, b), sampled as :func:`check_path` samples them
        (so a plan's re-check reproduces these bounds); updates status, value and stopped."""
        h = self.dest[g, b]
        moves = self._moves(k, g, h)
        raw = _check_moves(
            self.certifier,
            moves,
            self.margins[:, k, g],
            self.margins[:, k + 1, h],
            self.tolerance,
            DEFAULT_MAX_SAMPLE_ANGLE,
            locate_minimum=False,
        )
        self.moves_checked += k.size
        self.status[k, g, b] = np.where(raw.ok, _KNOWN, _NO)
        self.value[k, g, b] = np.where(raw.ok, self._level(raw.bound), _NONE)
        bad = ~raw.ok
        if np.any(bad):
            rows = raw.bad_index[bad]
            relative = relative_margins(self.certifier.manipulator, raw.samples["margins"][:, rows])
            worst = np.argmin(np.where(np.isnan(relative), -np.inf, relative), axis=0)
            self.stopped[k[bad], g[bad], b[bad]] = worst

    def solve(self) -> tuple[NDArray[np.float64] | None, float, BreakPoint | None]:
        """The plan (ψ per waypoint, rad), its objective and the break point (without a plan)."""
        while True:
            best = int(self._forward(optimistic=False)[-1].max())
            # Optimistic bottleneck of the best path through each move (recomputed after every
            # batch: the checks lower it, and that is what prunes the remaining moves).
            k, g, b, through = planner_kernels.candidates(
                self._forward(optimistic=True),
                self._backward(),
                self.status,
                self.value,
                self.dest,
                best,
            )
            if k.size == 0:
                break
            if k.size > CHECK_BATCH:
                top = _best_first(through, CHECK_BATCH)
                k, g, b = k[top], g[top], b[top]
            self._check(k, g, b)
        if best == _NONE:
            return None, -math.inf, self._breakpoint()
        return self._smoothest(best), best * self.resolution, None

    def _smoothest(self, best: int) -> NDArray[np.float64]:
        """Among the known moves whose level reaches the objective: the largest sum of move
        levels, then the least torsion travel Σ|Δψ|; ψ (N,), rad."""
        # cost = −Σ levels · scale + Σ|Δψ|: scale exceeds any total travel (N·π), so the sum of
        # levels decides and the travel only breaks ties (exact in float64 for these sizes).
        scale = float(self.status.shape[0] + 1) * 4.0
        path = planner_kernels.smoothest(
            self.levels[0], self.status, self.value, self.dest, self.travel, best, scale
        )
        return self.grid[path]

    def _breakpoint(self) -> BreakPoint:
        """The first waypoint that no torsion reaches from the start, with the reasons."""
        while True:
            reach = self._forward(optimistic=False) > _NONE
            first = int(np.argmin(np.any(reach, axis=1)))
            if not np.any(self.feasible[first]):
                return self._waypoint_break(first)
            k = first - 1
            g, b = np.nonzero(reach[k][:, None] & (self.status[k] == _UNKNOWN))
            if g.size == 0:
                return self._segment_break(k, reach[k])
            self._check(np.full(g.size, k), g, b)

    def _waypoint_break(self, index: int) -> BreakPoint:
        size = self.grid_size
        relative = self.relative_flat[:, index * size : (index + 1) * size]
        worst = np.argmin(np.where(np.isnan(relative), -np.inf, relative), axis=0)
        counts = Counter(CONSTRAINT_NAMES[c] for c in worst.tolist())
        names = ", ".join(f"{name} ({n})" for name, n in counts.most_common())
        reason = (
            f"waypoint {index}: no torsion on the {math.degrees(2 * math.pi / size):g} deg grid "
            f"is reachable there (limiting constraint over the {size} torsions: {names})"
        )
        return BreakPoint("waypoint", index, dict(counts), reason)

    def _segment_break(self, index: int, reach: NDArray[np.bool_]) -> BreakPoint:
        sources = int(np.count_nonzero(reach))
        targets = int(np.count_nonzero(self.feasible[index + 1]))
        pairs = reach[:, None] & self.feasible[index + 1][self.dest]
        stopped = self.stopped[index][pairs]
        counts = Counter(CONSTRAINT_NAMES[c] for c in stopped[stopped >= 0].tolist())
        limit = ""
        if self.max_dpsi is not None:
            every = int(np.count_nonzero(reach)) * targets
            limit = (
                f"; {int(np.count_nonzero(pairs))} of {every} torsion pairs are within "
                f"max_dpsi {math.degrees(self.max_dpsi):g} deg"
            )
        names = ", ".join(f"{name} ({n})" for name, n in counts.most_common()) or "none"
        reason = (
            f"segment {index} (waypoints {index} -> {index + 1}): no certified move from the "
            f"{sources} torsions that continue the path at waypoint {index} to the {targets} "
            f"reachable at waypoint {index + 1}{limit}; moves stopped by: {names}"
        )
        return BreakPoint("segment", index, dict(counts), reason)
