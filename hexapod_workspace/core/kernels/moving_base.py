"""The leg stage of moving base joints (numba): 6-PUS slides and 6-RUS cranks, their inverse
kinematics and base-side ends, for the margin kernels of one pose and of blocks
(:mod:`hexapod_workspace.core.model.architectures` holds the same formulas in numpy)."""

from __future__ import annotations

import math

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import inline as _inline

# isort: split
import numpy as np
from numpy.typing import NDArray

from .layout import (
    BRANCH,
    CRANK,
    CROSS,
    LEG,
    QCENTRE,
    QCOS,
    QSIN,
    RAIL,
    ZERO,
)
from .trig import (
    _atan2,
)

__all__ = ["Vector"]


# ------------------------------------------------------------------------------ moving base joints
@_inline
def _crank_ik(along: float, across: float, crank: float, length: float) -> float:
    """The ``ik`` margin of a crank leg, m: min(L − d_min, d_max − L), d_min and d_max the
    distances from B to the crank circle (``along`` and ``across`` the axial and radial
    coordinates of B about the crank axis, ``crank`` = r, ``length`` = L); as
    :mod:`~hexapod_workspace.core.model.architectures.rus` (√(x² + y²) for its hypot: the same value
    to an ulp, and no libm call)."""
    inside = across - crank
    outside = across + crank
    return min(
        length - math.sqrt(along * along + inside * inside),
        math.sqrt(along * along + outside * outside) - length,
    )


#: Three floats: a vector of one leg, or three constants read together.
Vector = tuple[float, float, float]


@_inline
def _crank_angle(
    along_e: float,
    along_f: float,
    across: float,
    scaled: float,
    branch: float,
    centre: Vector,
) -> tuple[float, float, float]:
    """The crank angle q of ``a·cos q + b·sin q = c`` on ``branch`` (±1), rad, in the 2π window
    centred on ``centre`` = (centre, its cosine, its sine), with cos q and sin q: one
    arctangent, no other trigonometric call, one division, no branch (so that the block path's
    loop over poses vectorises).

    The closed form of :mod:`~hexapod_workspace.core.model.architectures.rus` is
    q = φ + branch·γ with φ = atan2(b, a), γ = arccos(c/ρ), ρ = √(a² + b²) (c/ρ clamped to
    [−1, 1]), a = 2r·d·e, b = 2r·d·f. So ρ = 2r·ρ' with ρ' = √((d·e)² + (d·f)²) (``across``:
    the distance of B from the crank axis when e ⟂ w), cos φ = d·e/ρ', sin φ = d·f/ρ'
    (``along_e``, ``along_f``), cos γ = c/(2r·ρ') (``scaled`` = c/(2r), clamped after the
    division) and sin γ = √(1 − cos²γ) ≥ 0 (γ in [0, π]); the angle-sum formulas give exactly

        cos q = (d·e·cos γ − branch·d·f·sin γ)/ρ',   sin q = (d·f·cos γ + branch·d·e·sin γ)/ρ'.

    The offset from the centre of the range, δ = q − centre, has cos δ = cos q·cos c +
    sin q·sin c and sin δ = sin q·cos c − cos q·sin c, so q = centre + atan2(sin δ, cos δ) is the
    solution in (centre − π, centre + π] (:func:`_atan2`, within 2 ulp of libm's). The reference
    takes [centre − π, centre + π); the two differ only at δ = ±π exactly, where the range margin
    min(q − q_min, q_max − q) = (q_max − q_min)/2 − π is the same for both. ρ' = 0 (B on the
    crank axis) gives cos q = 1, sin q = 0, as atan2(+0, +0) + arccos(1) = 0 does. Rounding
    differs from the trigonometric route by a few ulps (products relative to ρ' instead of
    arccos, cos and sin of an angle)."""
    degenerate = across == 0.0
    inverse = 1.0 / (1.0 if degenerate else across)
    ratio = min(max(scaled * inverse, -1.0), 1.0)
    sine = math.sqrt(max(1.0 - ratio * ratio, 0.0))
    cos_q = 1.0 if degenerate else (along_e * ratio - branch * along_f * sine) * inverse
    sin_q = 0.0 if degenerate else (along_f * ratio + branch * along_e * sine) * inverse
    offset = _atan2(sin_q * centre[1] - cos_q * centre[2], cos_q * centre[1] + sin_q * centre[2])
    return centre[0] + offset, cos_q, sin_q


@_inline
def _slide_leg(
    dx: float, dy: float, dz: float, ux: float, uy: float, uz: float, length: float, branch: float
) -> tuple[float, float]:
    """(ik, q) of a slide leg (pus) with d = B − A0 and rail u: ik = L − h, h the distance from
    B to the rail line, q = u·d + branch·√(L² − h²) (√0 where ik < 0: the caller decides)."""
    along = ux * dx + uy * dy + uz * dz
    hx, hy, hz = dx - along * ux, dy - along * uy, dz - along * uz
    h = math.sqrt(hx * hx + hy * hy + hz * hz)
    ik = length - h
    return ik, along + branch * math.sqrt(max(ik * (length + h), 0.0))


@_inline
def _crank(
    model: NDArray[np.float64], k: int
) -> tuple[Vector, Vector, Vector, tuple[float, float, float, float], Vector]:
    """The constants of crank leg k: (e_k, f_k, w_k), (r_k, L_k, branch_k, 1/(2r_k)), and the
    centre of its range with the centre's cosine and sine (read once per leg, outside the loops
    over poses)."""
    return (
        (model[ZERO + 3 * k], model[ZERO + 3 * k + 1], model[ZERO + 3 * k + 2]),
        (model[CROSS + 3 * k], model[CROSS + 3 * k + 1], model[CROSS + 3 * k + 2]),
        (model[RAIL + 3 * k], model[RAIL + 3 * k + 1], model[RAIL + 3 * k + 2]),
        (model[CRANK + k], model[LEG + k], model[BRANCH + k], 0.5 / model[CRANK + k]),
        (model[QCENTRE + k], model[QCOS + k], model[QSIN + k]),
    )


@_inline
def _crank_leg(
    dx: float,
    dy: float,
    dz: float,
    e: Vector,
    f: Vector,
    w: Vector,
    sizes: tuple[float, float, float, float],
    centre: Vector,
) -> tuple[float, float, float, float]:
    """(ik, q, cos q, sin q) of a crank leg with d = B − A0 and the constants of :func:`_crank`
    (``sizes`` = (r, L, branch, 1/(2r))): the ``ik`` margin from the axial and radial
    coordinates of B about the crank axis (:func:`_crank_ik`), the angle by
    :func:`_crank_angle` (its value where ik < 0 has no meaning: the caller decides)."""
    crank, length = sizes[0], sizes[1]
    along_e = dx * e[0] + dy * e[1] + dz * e[2]
    along_f = dx * f[0] + dy * f[1] + dz * f[2]
    along = dx * w[0] + dy * w[1] + dz * w[2]
    # The radial coordinate as the reference takes it (|d − (d·w)w|: the loader accepts an e
    # up to 1e-6 off ⟂ w, where √((d·e)² + (d·f)²) would differ from it by as much).
    hx, hy, hz = dx - along * w[0], dy - along * w[1], dz - along * w[2]
    ik = _crank_ik(along, math.sqrt(hx * hx + hy * hy + hz * hz), crank, length)
    # c/(2r), c = |d|² + r² − L² (a/(2r) and b/(2r) are d·e and d·f).
    scaled = ((dx * dx + dy * dy + dz * dz) + crank * crank - length * length) * sizes[3]
    norm = math.sqrt(along_e * along_e + along_f * along_f)
    q, cos_q, sin_q = _crank_angle(along_e, along_f, norm, scaled, sizes[2], centre)
    return ik, q, cos_q, sin_q


@_inline
def _crank_end(
    origin: Vector,
    e: Vector,
    f: Vector,
    axis: Vector,
    axis_cross: Vector,
    axis_along: Vector,
    crank: float,
    cos_q: float,
    sin_q: float,
) -> tuple[float, float, float, float, float, float, float, float, float]:
    """Crank end C(q) = A0 + r(cos q·e + sin q·f) (m, base frame), its unit velocity
    w × (C − A0)/r = cos q·f − sin q·e and the crank-end joint axis ``axis`` (at q = 0) turned
    by q about w (Rodrigues: cos q·j + sin q·(w × j) + (1 − cos q)(w·j)w), from cos q and
    sin q."""
    one_minus = 1.0 - cos_q
    return (
        origin[0] + crank * (cos_q * e[0] + sin_q * f[0]),
        origin[1] + crank * (cos_q * e[1] + sin_q * f[1]),
        origin[2] + crank * (cos_q * e[2] + sin_q * f[2]),
        cos_q * f[0] - sin_q * e[0],
        cos_q * f[1] - sin_q * e[1],
        cos_q * f[2] - sin_q * e[2],
        cos_q * axis[0] + sin_q * axis_cross[0] + one_minus * axis_along[0],
        cos_q * axis[1] + sin_q * axis_cross[1] + one_minus * axis_along[1],
        cos_q * axis[2] + sin_q * axis_cross[2] + one_minus * axis_along[2],
    )


@_inline
def _vector(model: NDArray[np.float64], offset: int, k: int) -> Vector:
    """The 3-vector of leg k at ``offset`` of the model (leg-major layout)."""
    return (model[offset + 3 * k], model[offset + 3 * k + 1], model[offset + 3 * k + 2])
