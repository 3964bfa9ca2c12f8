"""Motions: certified checks of moves and toolpaths, and torsion planning for axisymmetric tools.

A **move** (segment) from pose (p₀, R₀) to (p₁, R₁) is parametrised by s ∈ [0, 1]: the position
is linear, ``p(s) = p₀ + s·Δp``, and the orientation follows one of two interpolations:

* ``"slerp"`` (what a controller does): the shortest rotation at constant rate, so the angular
  velocity has constant norm ``Ω = angle(R₀, R₁)`` (rad per unit s);
* ``"tilt-torsion"``: linear in the T&T angles, ``(φ, θ, ψ)(s) = (φ₀, θ₀, ψ₀) + s·(Δφ, Δθ, Δψ)``
  with Δφ and Δψ the wrapped (shortest) differences. At θ = 0 the azimuth is free (``R = Rz(ψ)``
  whatever φ), so an end with θ = 0 takes the other end's φ and the tilt moves along a straight
  ray; at θ = π, where ``R = Rz(2φ − ψ)·Ry(π)``, the same choice of φ is compensated in ψ.


The work is split by job: interpolation and the motion inputs
(:mod:`~hexapod_workspace.core.motions.interpolation`), the move certificate with its derivation
(:mod:`~hexapod_workspace.core.motions.certificate`), the checks of waypoints and toolpaths
(:mod:`~hexapod_workspace.core.motions.checks`), the torsion planner
(:mod:`~hexapod_workspace.core.motions.planner`) and their results
(:mod:`~hexapod_workspace.core.motions.results`). This module is their public face.
"""

from __future__ import annotations

from ..base.resolution import DEFAULT_PLAN_PSI_STEP
from .certificate import DEFAULT_MAX_SAMPLE_ANGLE, DEFAULT_PATH_TOLERANCE
from .checks import check_path, check_waypoints, report_singularity
from .interpolation import INTERPOLATIONS
from .planner import DEFAULT_MARGIN_RESOLUTION, plan_torsion
from .results import (
    BreakPoint,
    PathCheck,
    SegmentChecks,
    TorsionPlan,
    WaypointChecks,
    reported_parts,
)

__all__ = [
    "DEFAULT_MARGIN_RESOLUTION",
    "DEFAULT_MAX_SAMPLE_ANGLE",
    "DEFAULT_PATH_TOLERANCE",
    "DEFAULT_PLAN_PSI_STEP",
    "INTERPOLATIONS",
    "BreakPoint",
    "PathCheck",
    "SegmentChecks",
    "TorsionPlan",
    "WaypointChecks",
    "check_path",
    "check_waypoints",
    "plan_torsion",
    "report_singularity",
    "reported_parts",
]
