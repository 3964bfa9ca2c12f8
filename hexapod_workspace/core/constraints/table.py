"""The constraint table: every constraint of the model defined once, read by every layer.

Each row says what a constraint is called (the exact string of the interface: API dictionaries,
CLI JSON, messages, logs), its unit, the natural scale of its *relative* margin (to compare
constraints of different units: which one limits a pose, the planner's objective), how its
margin can change along a ray or a move (the Lipschitz rates used by the boundary search and by
the move certificate) and its report text (CLI tables).

Rate bounds
-----------
Along a ray or a move, parametrised by s, every platform joint moves at most at ``V`` (m per
unit s) and the platform turns at most at ``Ω`` (rad per unit s): along the rays of
:mod:`~hexapod_workspace.core.workspaces.search` ``V = ρ`` and ``Ω = 1`` (ρ = max_i |b_i|), along a
move of :mod:`~hexapod_workspace.core.motions.certificate` ``V = |Δp| + ρ·Ω``. The margin of each
constraint changes at most at

    |dm/ds| ≤ speed·V + turn·N + spin·Ω + actuate·Q + crank·K + ends·E

with the six coefficients of its row and the rates of the model's leg architecture
(:mod:`~hexapod_workspace.core.model.architectures`) over the interval considered:

* N bounds how fast a unit leg direction n_i turns, Q how fast an actuated coordinate q_i
  changes, K how fast a crank turns (rad), E how fast a leg end moves;
* 6-UPS (fixed base joints A_i, leg length actuated): with ``ℓ_f`` a lower bound of every leg
  length, ``N = V/ℓ_f`` (``|dn| ≤ |dL|/ℓ``), ``Q = V`` (``|dℓ| ≤ |dL|``), ``K = 0``, ``E = V``;
* 6-PUS and 6-RUS (legs of fixed length L_i, base-side end A_i(q) moving): with ``τ_f`` a lower
  bound of every ``|τ_i|`` (row ``transmission``) over the interval, the base-side end moves at
  ``W ≤ V/τ_f``: differentiating the leg closure ``|B − A(q)|² = L²`` gives
  ``n·dB = n·A'(q)·dq``, with ``n·A' = τ`` (pus: A' = u) or ``r·τ`` (rus: A' = w × (C − A0),
  of norm r), so ``|dq| ≤ V/|τ|`` (pus, m) or ``V/(r·|τ|)`` (rus, rad) and ``|dA| = |A'||dq|
  ≤ V/|τ|``. Hence ``E = max(V, W) = V/τ_f`` (as ``|τ| ≤ 1``), ``Q = V/τ_f`` (pus) or
  ``V/(r_min·τ_f)`` (rus), ``K = V/(r_min·τ_f)`` (rus; 0 for pus), and, since
  ``dn = (dB − dA)/L`` projected, ``N = V(1 + 1/τ_f)/L_min``.

A minimum of Lipschitz functions keeps the constant; the angle between two unit vectors changes
at most at the sum of their turning rates:

==================== ===== ===== ===== ======= ===== ==== =========================================
constraint           speed turn  spin  actuate crank ends why
==================== ===== ===== ===== ======= ===== ==== =========================================
``leg_length``       1     0     0     0       0     0    6-UPS: |dℓ_i/ds| ≤ |dL_i/ds| ≤ V
``base_joint``       0     1     0     0       1     0    n_i turns at N; jA_i is fixed (ups), moves
                                                          with the slide (pus) or turns with the
                                                          crank at K (rus)
``platform_joint``   0     1     1     0       0     0    R·jB_i turns at Ω, n_i at ≤ N
``leg_interference`` 0     2c    0     0       0     2    each segment's ends move by ≤ E
                                                          (+ c·N for a free length), two
                                                          segments move; c below
``singularity``      0     √12   √12   0       0     0    Weyl's inequality, below
``actuator``         0     0     0     1       0     0    pus/rus: |dq_i| ≤ Q
``ik``               1     0     0     0       0     0    pus/rus: 1-Lipschitz in B_i (below)
``transmission``     0     1     0     0       1     0    pus: τ = n·u, |dτ| ≤ |dn|; rus: τ = n·t,
                                                          t the crank end's unit velocity turning
                                                          at |dq|, |dτ| ≤ N + K
``collision``        1     0     ρ_c   0       0     0/1  a body point moves at ≤ |ṗ| + Ω·r, below;
                                                          ends 1 where base joints move (pus/rus)
==================== ===== ===== ===== ======= ===== ==== =========================================

*ik.* pus: ``ik_i = L_i − h_i`` with h_i the distance from B_i to the rail line, a
1-Lipschitz function of B_i. rus: ``ik_i = min(L − d_min, d_max − L)`` with d_min, d_max the
smallest and largest distance from B_i to the crank circle, both 1-Lipschitz in B_i. So
``|d ik/ds| ≤ V`` whether or not the legs have a solution; a violated ``ik`` stays violated for
``|ik|/V`` (the searches' recovery step where no other margin is defined).

*Transmission floor.* The rates of the pus/rus rows depend on τ_f, which the searches obtain
like the leg-length floor of 6-UPS: from the rate of ``|τ|`` itself, ``N + K`` with τ_f in it. Along
a ray from a feasible pose (:func:`~hexapod_workspace.core.kernels.steps.certified_step`),
τ_f = max(τ_lim, τ_now/2) and the step is limited to (τ_now − τ_f)/rate_τ(τ_f): the first
point where ``|τ|`` fell to τ_f would contradict the rate that holds until then. Over an interval
[a, b] of a move (:mod:`~hexapod_workspace.core.motions.certificate`), any τ_f ≤ min(τ(a), τ(b))
with ``τ(a) + τ(b) − 2τ_f ≥ rate_τ(τ_f)·w`` holds: the stretches [a, a + (τ(a) − τ_f)/rate] and
[b − (τ(b) − τ_f)/rate, b], on which ``|τ| ≥ τ_f`` by the same first-point argument, then cover the
interval. That is a quadratic inequality in τ_f; the certificate takes the largest admissible
value, and no floor (the rows that need one unbounded) when the interval may contain a pose
without a solution (ik's lower bound < 0) or none is admissible.

*Paired joints.* Two 6-UPS legs that share a joint (``geometry.paired_joint_length`` = c > 0)
are compared along their free lengths, the segments A_i + s·L_i, s ∈ [α_i, β_i], with
α_i = min(c/ℓ_i, 1) where they share the base joint (else 0) and β_i = max(1 − c/ℓ_i, α_i)
where they share the platform joint (else 1). The free segment's ends are X = A_i + c·n_i
(or B_i once ℓ_i ≤ c), moving at c·|dn_i| ≤ c·N (or ≤ E), and Y = B_i − c·n_i (or X), moving
at ≤ E + c·N: both ends move at most at E + c·N, and the Hausdorff argument of the row gives
``2E + 2c·N``, hence turn = 2c (0 when no legs share a joint: the row is unchanged). The ends
are continuous in the pose (min and max of continuous functions), so the bound holds across
the switch at ℓ_i = c.

*Collision.* ``collision = min over the checked pairs of sd − collision.clearance`` (signed
distances of the scene's bodies, :mod:`hexapod_workspace.core.model.collision.scene`), present only
when the model declares a scene with at least one pair (``Constraint.applies``; +inf
otherwise). :func:`hexapod_workspace.core.model.collision.scene.rate_bound` derives
``|dm/ds| ≤ |ṗ| + ρ_c·Ω`` with ρ_c the model's largest moving-body radius about the tool centre
point, for base joints A_i that stand still (6-UPS); since ``V = |Δp| + ρ·Ω ≥ |ṗ|``, speed 1
and spin ρ_c bound it: the ``spin`` coefficient of this row depends on the model
(:meth:`Constraint.coefficients`). Where a leg architecture moves A_i (6-PUS, 6-RUS), a point
``A_i + λ(B_i − A_i)`` of leg i moves at ``(1 − λ)|dA_i| + λ|dB_i|``, so by at most ``E`` more
than the derivation's bound for a fixed A_i (``|dA_i| ≤ E``, the leg end rate above): the row
adds ``ends·E`` with ends = 1 for those architectures (0 for 6-UPS, whose bound is unchanged).
The tool–leg bound of ``rate_bound`` grows the same way (the leg points move by at most E
more; the tool's do not change).

*Singularity.* ``singularity = σ_min(M) − σ_lim`` (σ_lim = ``limits.singularity_min``), M the
6×6 matrix with rows ``r_i = (n_iᵀ, ((R·b_i) × n_i)ᵀ / ρ)``: the unit leg lines in Plücker
coordinates, the moment homogenised by ρ = max_i |b_i| (b_i as written in
``geometry.platform_joints``). By Weyl's inequality for singular values,
``|σ_min(M(s)) − σ_min(M(s'))| ≤ ‖M(s) − M(s')‖₂ ≤ ∫ ‖dM/ds‖_F``, so the rate of σ_min is
at most ‖dM/ds‖_F. Per row, with ``|dn_i/ds| ≤ N`` and ``d(R·b_i)/ds = ω × R·b_i`` of norm
≤ Ω·|b_i| ≤ Ω·ρ:

    |d n_i/ds| ≤ N,
    |d((R·b_i) × n_i)/ds| / ρ ≤ (|ω × R·b_i| + |R·b_i|·|dn_i/ds|) / ρ ≤ Ω + N,

so ``|dr_i/ds|² ≤ N² + (N + Ω)² ≤ 2(N + Ω)²`` and over the six rows
``‖dM/ds‖_F ≤ √6·√2·(N + Ω) = √12·(N + Ω)``: turn = spin = √12 (the same for every
architecture: M depends on the base-side ends only through n_i). With σ_lim = 0 the
margin is not evaluated (+inf: free, never limiting) unless a caller asks for it as a report,
where it is σ_min itself (≥ 0, so it never makes a pose unreachable).

The kernels (:mod:`~hexapod_workspace.core.kernels.layout` copies the coefficients and scales into
the packed model), the searches, the move certificate and the planner read these rows; nothing
else counts constraints.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..model.architectures import module as architecture_module

if TYPE_CHECKING:
    from ..model.manipulator import Manipulator

__all__ = [
    "ACTUATOR",
    "BASE_JOINT",
    "COLLISION",
    "CONSTRAINTS",
    "CONSTRAINT_NAMES",
    "IK",
    "INDEX",
    "LEG_INTERFERENCE",
    "LEG_LENGTH",
    "N_CONSTRAINTS",
    "PLATFORM_JOINT",
    "SINGULARITY",
    "TRANSMISSION",
    "Constraint",
    "applicable",
    "constraint_names",
    "rate_bounds",
    "scales",
]


@dataclass(frozen=True)
class Constraint:
    """One row of the constraint table.

    Attributes
    ----------
    name : str
        The exact string of the interface (dictionary keys, JSON, messages, logs).
    unit : str
        SI unit of the margin (``"m"`` or ``"rad"``).
    margin : str
        The margin's definition (documentation, reports).
    label : str
        Report text (CLI tables, messages to humans).
    column : str
        Column heading of the CLI table (at most 11 characters).
    report_unit : str or callable
        Unit of the CLI table (``"mm"``, ``"deg"``); a callable ``unit(manipulator)`` where it
        depends on the model (read both through :meth:`report`).
    report_factor : float or callable
        SI margin × ``report_factor`` = margin in ``report_unit`` (callable like
        ``report_unit``).
    scale : callable
        ``scale(manipulator)``, float > 0 in the margin's unit: the natural scale of the margin;
        margin / scale is its relative margin (dimensionless).
    scale_text : str
        What the scale is, in words.
    speed, turn, spin : float or callable
        Rate coefficients of V, N (the leg direction's turning rate: V/ℓ_f for ups) and Ω
        (module documentation); a callable ``coefficient(manipulator)`` where it depends on the
        model (read every coefficient through :meth:`coefficients`).
    applies : callable
        ``applies(manipulator)``: whether the constraint exists for this model (a leg-length
        stroke exists only where legs change length, a collision margin only where bodies are
        declared). Where it does not, the kernels hold +inf in its row (never limiting) and the
        interfaces that list margins by name leave it out (:func:`applicable`).
    actuate, crank, ends : float
        Rate coefficients of Q (the actuated coordinate's rate), K (the crank's turning rate,
        rus) and E (the fastest leg end): the full rate is
        ``speed·V + turn·N + spin·Ω + actuate·Q + crank·K + ends·E`` (module documentation).
    """

    name: str
    unit: str
    margin: str
    label: str
    column: str
    report_unit: str | Callable[[Manipulator], str]
    report_factor: float | Callable[[Manipulator], float]
    scale: Callable[[Manipulator], float]
    scale_text: str
    speed: float | Callable[[Manipulator], float]
    turn: float | Callable[[Manipulator], float]
    spin: float | Callable[[Manipulator], float]
    applies: Callable[[Manipulator], bool] = lambda manipulator: True
    actuate: float = 0.0
    crank: float = 0.0
    ends: float | Callable[[Manipulator], float] = 0.0

    def coefficients(
        self, manipulator: Manipulator
    ) -> tuple[float, float, float, float, float, float]:
        """(speed, turn, spin, actuate, crank, ends) of this row for ``manipulator`` (a
        constant coefficient ignores it; a callable one is evaluated)."""
        return (
            _value(self.speed, manipulator),
            _value(self.turn, manipulator),
            _value(self.spin, manipulator),
            _value(self.actuate, manipulator),
            _value(self.crank, manipulator),
            _value(self.ends, manipulator),
        )

    def report(self, manipulator: Manipulator) -> tuple[str, float]:
        """(report_unit, report_factor) of this row for ``manipulator``: the CLI table's unit
        and the factor from the SI margin to it."""
        unit = self.report_unit(manipulator) if callable(self.report_unit) else self.report_unit
        return unit, _value(self.report_factor, manipulator)


def _actuator_report(manipulator: Manipulator) -> tuple[str, float]:
    """The stroke of a slide in mm, the range of a crank in deg."""
    if architecture_module(manipulator.architecture).ACTUATOR_UNIT == "rad":
        return "deg", float(np.degrees(1.0))
    return "mm", 1e3


def _paired_turn(manipulator: Manipulator) -> float:
    """The ``turn`` coefficient of ``leg_interference``: 2c, c = ``paired_joint_length`` (m; 0
    when no legs share a joint): the free lengths' ends turn with the legs (*Paired joints*)."""
    return 2.0 * manipulator.paired_joint_length


def _value(coefficient: float | Callable[[Manipulator], float], manipulator: Manipulator) -> float:
    return float(coefficient(manipulator) if callable(coefficient) else coefficient)


def _has_scene(manipulator: Manipulator) -> bool:
    scene = getattr(manipulator, "collision", None)
    return scene is not None and scene.pair_count > 0


def _collision_spin(manipulator: Manipulator) -> float:
    """ρ_c of :func:`hexapod_workspace.core.model.collision.scene.rate_bound` (0 without a
    scene)."""
    if not _has_scene(manipulator):
        return 0.0
    from ..model.collision.scene import rate_bound

    return rate_bound(manipulator, manipulator.collision).rotation  # type: ignore[arg-type]


def _collision_ends(manipulator: Manipulator) -> float:
    """1 where the leg architecture moves the base joints (module documentation), else 0."""
    return 1.0 if _has_scene(manipulator) and _moving_base(manipulator) else 0.0


def _collision_scale(manipulator: Manipulator) -> float:
    """The clearance, or the leg diameter, or 1 cm: a length at which a collision matters."""
    scene = getattr(manipulator, "collision", None)
    if scene is not None and scene.clearance > 0.0:
        return float(scene.clearance)
    return manipulator.leg_diameter if manipulator.leg_diameter > 0.0 else 0.01


def _moving_base(manipulator: Manipulator) -> bool:
    return architecture_module(manipulator.architecture).MOVING_BASE


def _fixed_base(manipulator: Manipulator) -> bool:
    return not _moving_base(manipulator)


def _half_actuator_range(manipulator: Manipulator) -> float:
    if manipulator.actuator_min is None or manipulator.actuator_max is None:
        return 1.0
    return float(np.mean(manipulator.actuator_max - manipulator.actuator_min)) / 2.0


def _mean_leg_length(manipulator: Manipulator) -> float:
    return float(np.mean(manipulator.leg_length_max))


def _transmission_scale(manipulator: Manipulator) -> float:
    return 1.0 - manipulator.transmission_min


def _half_stroke(manipulator: Manipulator) -> float:
    return float(np.mean(manipulator.leg_length_max - manipulator.leg_length_min)) / 2.0


def _mean_base_angle(manipulator: Manipulator) -> float:
    return float(np.mean(manipulator.base_joint_max_angle))


def _mean_platform_angle(manipulator: Manipulator) -> float:
    return float(np.mean(manipulator.platform_joint_max_angle))


def _singularity_scale(manipulator: Manipulator) -> float:
    return manipulator.singularity_min if manipulator.singularity_min > 0.0 else 1.0


#: √12 = √6·√2: the singularity margin's rate coefficients (module documentation).
SQRT12 = float(np.sqrt(12.0))


def _diameter(manipulator: Manipulator) -> float:
    return manipulator.leg_diameter if manipulator.leg_diameter > 0.0 else 1.0


#: The table, in the order of every margin array (rows of shape (N_CONSTRAINTS, N) arrays).
CONSTRAINTS: tuple[Constraint, ...] = (
    Constraint(
        name="leg_length",
        unit="m",
        margin="min_i min(ℓ_i − ℓmin_i, ℓmax_i − ℓ_i)",
        label="leg length",
        column="leg_length",
        report_unit="mm",
        report_factor=1e3,
        scale=_half_stroke,
        scale_text="half the mean stroke (ℓmax − ℓmin)/2",
        speed=1.0,
        turn=0.0,
        spin=0.0,
        applies=_fixed_base,
    ),
    Constraint(
        name="base_joint",
        unit="rad",
        margin="min_i (α_i − angle(jA_i, n_i))",
        label="base joint",
        column="base_joint",
        report_unit="deg",
        report_factor=float(np.degrees(1.0)),
        scale=_mean_base_angle,
        scale_text="the mean maximum base joint angle",
        speed=0.0,
        turn=1.0,
        spin=0.0,
        crank=1.0,
    ),
    Constraint(
        name="platform_joint",
        unit="rad",
        margin="min_i (β_i − angle(R·jB_i, −n_i))",
        label="platform joint",
        column="platform_j",
        report_unit="deg",
        report_factor=float(np.degrees(1.0)),
        scale=_mean_platform_angle,
        scale_text="the mean maximum platform joint angle",
        speed=0.0,
        turn=1.0,
        spin=1.0,
    ),
    Constraint(
        name="leg_interference",
        unit="m",
        margin=(
            "min_{i<j} (dist(A_iB_i, A_jB_j) − D), legs that share a joint along their free "
            "lengths; +inf when D = 0 (check disabled)"
        ),
        label="leg interference",
        column="interfer.",
        report_unit="mm",
        report_factor=1e3,
        scale=_diameter,
        scale_text="the leg diameter D (1 m when the check is disabled)",
        speed=0.0,
        turn=_paired_turn,
        spin=0.0,
        ends=2.0,
    ),
    Constraint(
        name="singularity",
        unit="1",
        margin="σ_min(M) − σ_lim, M rows (n_iᵀ, ((R·b_i) × n_i)ᵀ/ρ); +inf when σ_lim = 0",
        label="singularity",
        column="singular.",
        report_unit="1",
        report_factor=1.0,
        scale=_singularity_scale,
        scale_text="limits.singularity_min (1 when it is 0)",
        speed=0.0,
        turn=SQRT12,
        spin=SQRT12,
    ),
    Constraint(
        name="actuator",
        unit="m or rad",
        margin="min_i min(q_i − qmin_i, qmax_i − q_i): slide stroke (pus, m), crank (rus, rad)",
        label="actuator",
        column="actuator",
        report_unit=lambda manipulator: _actuator_report(manipulator)[0],
        report_factor=lambda manipulator: _actuator_report(manipulator)[1],
        scale=_half_actuator_range,
        scale_text="half the mean actuator range (qmax − qmin)/2",
        speed=0.0,
        turn=0.0,
        spin=0.0,
        applies=_moving_base,
        actuate=1.0,
    ),
    Constraint(
        name="ik",
        unit="m",
        margin="min_i: how far L_i lies inside the distances from B_i to its actuator's locus",
        label="inverse kinematics",
        column="ik",
        report_unit="mm",
        report_factor=1e3,
        scale=_mean_leg_length,
        scale_text="the mean leg length L",
        speed=1.0,
        turn=0.0,
        spin=0.0,
        applies=_moving_base,
    ),
    Constraint(
        name="transmission",
        unit="1",
        margin="min_i |τ_i| − τ_lim: τ = n·u (pus), n·(w × (C − A0))/r (rus)",
        label="transmission",
        column="transmiss.",
        report_unit="1",
        report_factor=1.0,
        scale=_transmission_scale,
        scale_text="1 − limits.transmission_min",
        speed=0.0,
        turn=1.0,
        spin=0.0,
        applies=_moving_base,
        crank=1.0,
    ),
    Constraint(
        name="collision",
        unit="m",
        margin="min over the scene's pairs of sd − collision.clearance; +inf without a scene",
        label="collision",
        column="collision",
        report_unit="mm",
        report_factor=1e3,
        scale=_collision_scale,
        scale_text="collision.clearance (else the leg diameter D, else 1 cm)",
        speed=1.0,
        turn=0.0,
        spin=_collision_spin,
        applies=_has_scene,
        ends=_collision_ends,
    ),
)

#: The constraint names, in table order.
CONSTRAINT_NAMES: tuple[str, ...] = tuple(row.name for row in CONSTRAINTS)
#: Number of constraints (rows of every margin array).
N_CONSTRAINTS = len(CONSTRAINTS)
#: Row of each constraint by name.
INDEX: dict[str, int] = {row.name: k for k, row in enumerate(CONSTRAINTS)}
#: Rows the kernels and the certificate address by meaning.
LEG_LENGTH = INDEX["leg_length"]
BASE_JOINT = INDEX["base_joint"]
PLATFORM_JOINT = INDEX["platform_joint"]
LEG_INTERFERENCE = INDEX["leg_interference"]
SINGULARITY = INDEX["singularity"]
ACTUATOR = INDEX["actuator"]
IK = INDEX["ik"]
TRANSMISSION = INDEX["transmission"]
COLLISION = INDEX["collision"]


def rate_bounds(
    manipulator: Manipulator,
    speed: NDArray[np.float64],
    turn: NDArray[np.float64],
    spin: NDArray[np.float64],
    actuate: NDArray[np.float64] | None = None,
    crank: NDArray[np.float64] | None = None,
    ends: NDArray[np.float64] | None = None,
    rows: int | None = None,
) -> NDArray[np.float64]:
    """Bounds on how much each margin changes, shape (N_CONSTRAINTS, n), from the rates V, N, Ω,
    Q, K, E of the module documentation (or their integrals over an interval), each shape (n,).
    With ``rows``, only the first ``rows`` rows of the table (shape (rows, n)).

    ``speed·V + turn·N + spin·Ω + actuate·Q + crank·K + ends·E`` per row of the table; a term
    whose coefficient is 0 is left out (so an infinite N, no leg floor, only affects the rows
    that turn with it). Left out, Q and E are V (6-UPS: the leg length changes at most at V, the
    platform joints are the fastest leg ends) and K is 0 (no crank). The kernels compute the
    same sum for one pose (``kernels.steps._rate``).
    """
    quantities = (
        speed,
        turn,
        spin,
        speed if actuate is None else actuate,
        crank,  # None: K = 0, the term adds nothing
        speed if ends is None else ends,
    )
    terms_of_rows = _rate_terms(manipulator)[:rows]
    bounds = np.zeros((len(terms_of_rows), np.shape(speed)[0]))
    # The move certificate asks at every round of its bisection: in place, no temporary where
    # a coefficient is 1. The same sums in the same order (0 + x = x, 1·x = x exactly).
    for k, terms in enumerate(terms_of_rows):
        row = bounds[k]
        for quantity, coefficient in terms:
            value = quantities[quantity]
            if value is None:
                continue
            if coefficient == 1.0:
                row += value
            else:
                row += coefficient * value
    return bounds


#: Non-zero rate coefficients of each row by ``id`` of their manipulator (see _rate_terms).
_RATE_TERMS: dict[int, tuple[tuple[tuple[int, float], ...], ...]] = {}


def _rate_terms(manipulator: Manipulator) -> tuple[tuple[tuple[int, float], ...], ...]:
    """Per row of the table, its (quantity, coefficient) pairs with a non-zero coefficient
    (quantities in the order V, N, Ω, Q, K, E), for ``manipulator``: evaluated once per
    manipulator object and kept for its lifetime (it is frozen), as the packed model is; the
    move certificate asks for them at every round of its bisection."""
    key = id(manipulator)
    terms = _RATE_TERMS.get(key)
    if terms is None:
        terms = tuple(
            tuple(
                (quantity, coefficient)
                for quantity, coefficient in enumerate(row.coefficients(manipulator))
                if coefficient != 0.0
            )
            for row in CONSTRAINTS
        )
        _RATE_TERMS[key] = terms
        # The id is not reused before the finalizer has removed the entry.
        weakref.finalize(manipulator, _RATE_TERMS.pop, key, None)
    return terms


def applicable(manipulator: Manipulator) -> tuple[int, ...]:
    """Rows of the table that exist for this model, in table order (see ``Constraint.applies``)."""
    return tuple(k for k, row in enumerate(CONSTRAINTS) if row.applies(manipulator))


def constraint_names(manipulator: Manipulator) -> tuple[str, ...]:
    """Names of the rows that exist for this model, in table order (the keys of ``check``'s
    margins, of ``check --json`` and of the messages for this model)."""
    return tuple(CONSTRAINTS[k].name for k in applicable(manipulator))


def scales(manipulator: Manipulator) -> NDArray[np.float64]:
    """Natural scale of each margin, shape (N_CONSTRAINTS,), in table order (m or rad)."""
    return np.array([row.scale(manipulator) for row in CONSTRAINTS], dtype=np.float64)
