"""Sine, cosine and atan2 for the margin kernels (numba), branch-free so that loops over a block
of poses vectorise, and the T&T rotation matrix built from them."""

from __future__ import annotations

import math

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import helper as _helper
from ..base.jit import inline as _inline

# isort: split
import numpy as np
from numpy.typing import NDArray

__all__ = [
    "FAST_TRIG_LIMIT",
    "MOREBITS",
    "PI",
    "PIO2",
    "PIO2_1",
    "PIO2_2",
    "PIO2_3",
    "PIO4",
    "TWO_OVER_PI",
]

# ------------------------------------------------------------------------------ sin and cos
# Cody–Waite reduction by π/2 in three parts of 33 bits (exact products for |k| < 2**20) and the
# Cephes polynomials on [−π/4, π/4]: within 1 ulp of libm, and branch-free, so that loops over a
# block of poses vectorise. Arguments beyond FAST_TRIG_LIMIT use libm (see _check_block).
PIO2_1 = 1.57079632673412561417e00
PIO2_2 = 6.07710050630396597660e-11
PIO2_3 = 2.02226624879595063154e-21
TWO_OVER_PI = 0.6366197723675814
FAST_TRIG_LIMIT = 1e5
SIN_0, SIN_1, SIN_2 = (
    1.58962301576546568060e-10,
    -2.50507477628578072866e-8,
    2.75573136213857245213e-6,
)
SIN_3, SIN_4, SIN_5 = (
    -1.98412698295895385996e-4,
    8.33333333332211858878e-3,
    -1.66666666666666307295e-1,
)
COS_0, COS_1, COS_2 = (
    -1.13585365213876817300e-11,
    2.08757008419747316778e-9,
    -2.75573141792967388112e-7,
)
COS_3, COS_4, COS_5 = (
    2.48015872888517045348e-5,
    -1.38888888888730564116e-3,
    4.16666666666665929218e-2,
)


@_inline
def _sincos(x: float) -> tuple[float, float]:
    """(sin x, cos x) for |x| ≤ FAST_TRIG_LIMIT, branch-free."""
    k = math.floor(x * TWO_OVER_PI + 0.5)
    r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3
    z = r * r
    sine = r + r * z * (((((SIN_0 * z + SIN_1) * z + SIN_2) * z + SIN_3) * z + SIN_4) * z + SIN_5)
    cosine = (
        1.0
        - 0.5 * z
        + z * z * (((((COS_0 * z + COS_1) * z + COS_2) * z + COS_3) * z + COS_4) * z + COS_5)
    )
    quadrant = k - 4.0 * math.floor(k * 0.25)
    odd = quadrant == 1.0 or quadrant == 3.0
    sin_value = cosine if odd else sine
    cos_value = sine if odd else cosine
    sin_value = -sin_value if quadrant >= 2.0 else sin_value
    cos_value = -cos_value if (quadrant == 1.0 or quadrant == 2.0) else cos_value
    return sin_value, cos_value


# atan2 for the crank angle of 6-RUS legs: Cephes' atan (rational approximation on
# [−0.21, 0.66], the reduction atan t = π/4 + atan((t − 1)/(t + 1)) above; the π/2 and π terms with
# their rounding residue MOREBITS), on t = min(|x|, |y|)/max(|x|, |y|) ∈ [0, 1], and the octant
# by selects: within 2 ulp of libm for finite arguments and branch-free, so that the 6-RUS leg
# loop vectorises (libm's atan2 is a call per pose that keeps a loop scalar).
ATAN_P0, ATAN_P1, ATAN_P2, ATAN_P3, ATAN_P4 = (
    -8.750608600031904122785e-1,
    -1.615753718733365076637e1,
    -7.500855792314704667340e1,
    -1.228866684490136173410e2,
    -6.485021904942025371773e1,
)
ATAN_Q0, ATAN_Q1, ATAN_Q2, ATAN_Q3, ATAN_Q4 = (
    2.485846490142306297962e1,
    1.650270098316988542046e2,
    4.328810604912902668951e2,
    4.853903996359136964868e2,
    1.945506571482613964425e2,
)
PIO4 = 7.85398163397448309616e-1
PIO2 = 1.57079632679489661923e0
PI = 3.14159265358979323846e0
MOREBITS = 6.123233995736765886130e-17  # π/2 − PIO2


@_inline
def _atan2(y: float, x: float) -> float:
    """atan2(y, x) in [−π, π] for finite x, y (NaN in, NaN out), branch-free; the signs of
    zeros as libm's (atan2(±0, −0) = ±π)."""
    ax = abs(x)
    ay = abs(y)
    swap = ay > ax
    big = ay if swap else ax
    small = ax if swap else ay
    # t = small/big; above 0.66 the argument (t − 1)/(t + 1) = (small − big)/(small + big):
    # one division either way.
    reduce = small > 0.66 * big
    u = (small - big if reduce else small) / (small + big if reduce else max(big, 1e-300))
    z = u * u
    p = (
        z
        * ((((ATAN_P0 * z + ATAN_P1) * z + ATAN_P2) * z + ATAN_P3) * z + ATAN_P4)
        / (((((z + ATAN_Q0) * z + ATAN_Q1) * z + ATAN_Q2) * z + ATAN_Q3) * z + ATAN_Q4)
    )
    v = u * p + u
    v = v + 0.5 * MOREBITS if reduce else v
    # atan2 = hi ± atan t: t itself (hi 0), π/2 ∓ atan t (swap), π − atan t (x < 0).
    left = math.copysign(1.0, x) < 0.0
    minus = swap != left
    hi = PIO2 if swap else (PI if left else 0.0)
    lo = MOREBITS if swap else (2.0 * MOREBITS if left else 0.0)
    hi = (hi - PIO4 if minus else hi + PIO4) if reduce else hi
    value = math.copysign(hi + ((-v if minus else v) + lo), y)
    return value if (x == x) & (y == y) else np.nan


@_helper
def _tt_matrix(phi: float, theta: float, psi: float, r: NDArray[np.float64]) -> None:
    """R(φ, θ, ψ) = Rz(φ)·Ry(θ)·Rz(ψ − φ) into r (9,), row-major (as rotations.tt_to_matrix).

    Huge angles are first reduced to their principal values (libm reduces exactly): ψ − φ of
    two huge angles would be rounded to another orientation than the one they denote.
    """
    if max(abs(phi), abs(theta), abs(psi)) > FAST_TRIG_LIMIT:
        phi = math.atan2(math.sin(phi), math.cos(phi))
        theta = math.atan2(math.sin(theta), math.cos(theta))
        psi = math.atan2(math.sin(psi), math.cos(psi))
    gamma = psi - phi
    if max(abs(phi), abs(theta), abs(gamma)) <= FAST_TRIG_LIMIT:
        sa, ca = _sincos(phi)
        sb, cb = _sincos(theta)
        sg, cg = _sincos(gamma)
    else:
        ca, sa = math.cos(phi), math.sin(phi)
        cb, sb = math.cos(theta), math.sin(theta)
        cg, sg = math.cos(gamma), math.sin(gamma)
    r[0] = ca * cb * cg - sa * sg
    r[1] = -ca * cb * sg - sa * cg
    r[2] = ca * sb
    r[3] = sa * cb * cg + ca * sg
    r[4] = -sa * cb * sg + ca * cg
    r[5] = sa * sb
    r[6] = -sb * cg
    r[7] = sb * sg
    r[8] = cb
