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
:mod:`~hexapod_workspace.core.search` ``V = ρ`` and ``Ω = 1`` (ρ = max_i |b_i|), along a move
of :mod:`~hexapod_workspace.core.path_certificate` ``V = |Δp| + ρ·Ω``. With ``ℓ_f`` a lower
bound of every leg length over the interval considered, the margin of each constraint changes
at most at

    |dm/ds| ≤ speed·V + turn·V/ℓ_f + spin·Ω

with the three coefficients of its row (a minimum of Lipschitz functions keeps the constant;
the angle between two unit vectors changes at most at the sum of their turning rates):

==================== ===== ===== ===== =======================================================
constraint           speed turn  spin  why
==================== ===== ===== ===== =======================================================
``leg_length``       1     0     0     |dℓ_i/ds| ≤ |dL_i/ds| ≤ V (the base joints A_i are fixed)
``base_joint``       0     1     0     |dn_i/ds| ≤ |dL_i/ds| / ℓ_i; jA_i is fixed
``platform_joint``   0     1     1     R·jB_i turns at Ω, n_i at ≤ V / ℓ_f
``leg_interference`` 2     0     0     each segment A_iB_i moves by ≤ V (Hausdorff), two move
``singularity``      0     √12   √12   Weyl's inequality, below
``collision``        1     0     ρ_c   a body point moves at ≤ |ṗ| + Ω·r, below
==================== ===== ===== ===== =======================================================

*Collision.* ``collision = min over the checked pairs of sd − collision.clearance`` (signed
distances of the scene's bodies, :mod:`hexapod_workspace.core.collision.scene`), present only
when the model declares a scene with at least one pair (``Constraint.applies``; +inf
otherwise). :func:`hexapod_workspace.core.collision.scene.rate_bound` derives
``|dm/ds| ≤ |ṗ| + ρ_c·Ω`` with ρ_c the model's largest moving-body radius about the tool centre
point; since ``V = |Δp| + ρ·Ω ≥ |ṗ|``, speed 1 and spin ρ_c bound it: the ``spin`` coefficient
of this row depends on the model (:meth:`Constraint.coefficients`). The derivation holds for
base joints A_i that stand still (6-UPS); where a leg architecture moves A_i, each leg body's
rate must add that joint's speed.

*Singularity.* ``singularity = σ_min(M) − σ_lim`` (σ_lim = ``limits.singularity_min``), M the
6×6 matrix with rows ``r_i = (n_iᵀ, ((R·b_i) × n_i)ᵀ / ρ)``: the unit leg lines in Plücker
coordinates, the moment homogenised by ρ = max_i |b_i| (b_i as written in
``geometry.platform_joints``). By Weyl's inequality for singular values,
``|σ_min(M(s)) − σ_min(M(s'))| ≤ ‖M(s) − M(s')‖₂ ≤ ∫ ‖dM/ds‖_F``, so the rate of σ_min is
at most ‖dM/ds‖_F. Per row, with ``|dn_i/ds| ≤ V/ℓ_f`` (as for ``base_joint``) and
``d(R·b_i)/ds = ω × R·b_i`` of norm ≤ Ω·|b_i| ≤ Ω·ρ:

    |d n_i/ds| ≤ V/ℓ_f,
    |d((R·b_i) × n_i)/ds| / ρ ≤ (|ω × R·b_i| + |R·b_i|·|dn_i/ds|) / ρ ≤ Ω + V/ℓ_f,

so ``|dr_i/ds|² ≤ a² + (a + Ω)² ≤ 2(a + Ω)²`` with a = V/ℓ_f, and over the six rows
``‖dM/ds‖_F ≤ √6·√2·(V/ℓ_f + Ω) = √12·(V/ℓ_f + Ω)``: turn = spin = √12. With σ_lim = 0 the
margin is not evaluated (+inf: free, never limiting) unless a caller asks for it as a report,
where it is σ_min itself (≥ 0, so it never makes a pose unreachable).

The kernels (:mod:`~hexapod_workspace.core.model_layout` copies the coefficients and scales into
the packed model), the searches, the move certificate and the planner read these rows; nothing
else counts constraints.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from .manipulator import Manipulator

__all__ = [
    "BASE_JOINT",
    "COLLISION",
    "CONSTRAINTS",
    "CONSTRAINT_NAMES",
    "INDEX",
    "LEG_INTERFERENCE",
    "LEG_LENGTH",
    "N_CONSTRAINTS",
    "PLATFORM_JOINT",
    "SINGULARITY",
    "Constraint",
    "applicable",
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
    report_unit : str
        Unit of the CLI table (``"mm"``, ``"deg"``).
    report_factor : float
        SI margin × ``report_factor`` = margin in ``report_unit``.
    scale : callable
        ``scale(manipulator)``, float > 0 in the margin's unit: the natural scale of the margin;
        margin / scale is its relative margin (dimensionless).
    scale_text : str
        What the scale is, in words.
    speed, turn, spin : float or callable
        Rate coefficients: ``|dm/ds| ≤ speed·V + turn·V/ℓ_f + spin·Ω`` (module documentation);
        a callable ``coefficient(manipulator)`` where it depends on the model (read them through
        :meth:`coefficients`).
    applies : callable
        ``applies(manipulator)``: whether the constraint exists for this model (a leg-length
        stroke exists only where legs change length, a collision margin only where bodies are
        declared). Where it does not, the kernels hold +inf in its row (never limiting) and the
        interfaces that list margins by name leave it out (:func:`applicable`).
    """

    name: str
    unit: str
    margin: str
    label: str
    column: str
    report_unit: str
    report_factor: float
    scale: Callable[[Manipulator], float]
    scale_text: str
    speed: float | Callable[[Manipulator], float]
    turn: float | Callable[[Manipulator], float]
    spin: float | Callable[[Manipulator], float]
    applies: Callable[[Manipulator], bool] = lambda manipulator: True

    def coefficients(self, manipulator: Manipulator) -> tuple[float, float, float]:
        """(speed, turn, spin) of this row for ``manipulator`` (a constant row ignores it)."""
        return (
            _value(self.speed, manipulator),
            _value(self.turn, manipulator),
            _value(self.spin, manipulator),
        )


def _value(coefficient: float | Callable[[Manipulator], float], manipulator: Manipulator) -> float:
    return float(coefficient(manipulator) if callable(coefficient) else coefficient)


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


def _has_scene(manipulator: Manipulator) -> bool:
    scene = getattr(manipulator, "collision", None)
    return scene is not None and scene.pair_count > 0


def _collision_spin(manipulator: Manipulator) -> float:
    """ρ_c of :func:`hexapod_workspace.core.collision.scene.rate_bound` (0 without a scene)."""
    if not _has_scene(manipulator):
        return 0.0
    from .collision.scene import rate_bound

    return rate_bound(manipulator, manipulator.collision).rotation  # type: ignore[arg-type]


def _collision_scale(manipulator: Manipulator) -> float:
    """The clearance, or the leg diameter, or 1 cm: a length at which a collision matters."""
    scene = getattr(manipulator, "collision", None)
    if scene is not None and scene.clearance > 0.0:
        return float(scene.clearance)
    return manipulator.leg_diameter if manipulator.leg_diameter > 0.0 else 0.01


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
        margin="min_{i<j} (dist(A_iB_i, A_jB_j) − D); +inf when D = 0 (check disabled)",
        label="leg interference",
        column="interfer.",
        report_unit="mm",
        report_factor=1e3,
        scale=_diameter,
        scale_text="the leg diameter D (1 m when the check is disabled)",
        speed=2.0,
        turn=0.0,
        spin=0.0,
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
COLLISION = INDEX["collision"]


def rate_bounds(
    manipulator: Manipulator,
    speed: NDArray[np.float64],
    turn: NDArray[np.float64],
    spin: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Bounds on how much each margin changes, shape (N_CONSTRAINTS, n), from V, V/ℓ_f and Ω
    (or their integrals over an interval: travel, travel/ℓ_f, turned angle), each shape (n,),
    with the coefficients of ``manipulator``'s rows (:meth:`Constraint.coefficients`).

    ``speed·V + turn·V/ℓ_f + spin·Ω`` per row of the table; a term whose coefficient is 0 is
    left out (so an infinite V/ℓ_f, no leg floor, only affects the rows that turn with it). The
    kernels compute the same sum for one pose (``search_kernels._rate``).
    """
    bounds = np.zeros((N_CONSTRAINTS, np.shape(speed)[0]))
    for k, row in enumerate(CONSTRAINTS):
        coefficients = row.coefficients(manipulator)
        for coefficient, value in zip(coefficients, (speed, turn, spin), strict=True):
            if coefficient != 0.0:
                bounds[k] = bounds[k] + coefficient * value
    return bounds


def applicable(manipulator: Manipulator) -> tuple[int, ...]:
    """Rows of the table that exist for this model, in table order (see ``Constraint.applies``)."""
    return tuple(k for k, row in enumerate(CONSTRAINTS) if row.applies(manipulator))


def scales(manipulator: Manipulator) -> NDArray[np.float64]:
    """Natural scale of each margin, shape (N_CONSTRAINTS,), in table order (m or rad)."""
    return np.array([row.scale(manipulator) for row in CONSTRAINTS], dtype=np.float64)
