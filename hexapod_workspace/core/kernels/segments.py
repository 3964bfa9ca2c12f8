"""Squared distances between two leg segments (numba), for the interference margin of the
block kernel and of one pose: the pair's closest points (Ericson, *Real-Time Collision
Detection*, 5.1.9) and the free lengths of two legs that share a joint."""

from __future__ import annotations

import math

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import helper as _helper
from ..base.jit import inline as _inline

# isort: split
import numpy as np
from numpy.typing import NDArray

from .layout import (
    PAIRED_LENGTH,
    SHARED_BASE,
    SHARED_PLATFORM,
)

__all__ = []


@_helper
def _clamp01(value: float) -> float:
    """Clamp to [0, 1]; NaN stays NaN."""
    if value < 0.0:
        return 0.0
    if value > 1.0:
        return 1.0
    return value


@_inline
def _pair_squared(
    rx: float,
    ry: float,
    rz: float,
    rr: float,
    xi: float,
    yi: float,
    zi: float,
    xj: float,
    yj: float,
    zj: float,
    a: float,
    e: float,
    inverse_i: float,
    inverse_j: float,
) -> tuple[float, float]:
    """Squared distance of two leg segments A_i + s·L_i, A_j + t·L_j (r = A_i − A_j, rr = |r|²,
    a = |L_i|², e = |L_j|², inverse_* = 1/|L|²) by Ericson's clamped closest points, and 1.0
    when the segments are parallel or point-like (for the exact path), else 0.0."""
    b = xi * xj + yi * yj + zi * zj
    c = xi * rx + yi * ry + zi * rz
    f = xj * rx + yj * ry + zj * rz
    denom = a * e - b * b
    s = min(max((b * f - c * e) / denom, 0.0), 1.0)
    t = min(max((b * s + f) * inverse_j, 0.0), 1.0)
    s = min(max((b * t - c) * inverse_i, 0.0), 1.0)
    squared = rr + s * (s * a + 2.0 * (c - t * b)) + t * (t * e - 2.0 * f)
    return squared, (0.0 if denom > 1e-14 * a * e else 1.0)


@_helper
def _free_squared(
    model: NDArray[np.float64],
    pair: int,
    rx: float,
    ry: float,
    rz: float,
    xi: float,
    yi: float,
    zi: float,
    xj: float,
    yj: float,
    zj: float,
    a: float,
    e: float,
) -> tuple[float, float]:
    """Squared distance of the free lengths of two legs that share a joint (pair ``pair``),
    and 1.0 when they are parallel or point-like (else 0.0).

    The free length of leg i is A_i + s·L_i for s in [α_i, β_i]: α_i = min(c/ℓ_i, 1) where the
    pair shares its base joint (else 0), β_i = max(1 − c/ℓ_i, α_i) where it shares its platform
    joint (else 1), c = ``model[PAIRED_LENGTH]``, ℓ_i = |L_i| (r = A_i − A_j, a = ℓ_i²,
    e = ℓ_j²). Ericson's clamped closest points of the two free segments, with the fallback of
    :func:`_pose` for parallel or point-like ones. The ends move at most c·N faster than the
    leg's ends (the rate bound of ``leg_interference`` in the constraint table)."""
    c = model[PAIRED_LENGTH]
    li = math.sqrt(a)
    lj = math.sqrt(e)
    base = model[SHARED_BASE + pair] != 0.0
    ai = min(c / li, 1.0) if base else 0.0
    aj = min(c / lj, 1.0) if base else 0.0
    platform = model[SHARED_PLATFORM + pair] != 0.0
    bi = max(1.0 - c / li, ai) if platform else 1.0
    bj = max(1.0 - c / lj, aj) if platform else 1.0
    # The free segments: starts S_i = A_i + α_i·L_i (u = S_i − S_j) and vectors (β − α)·L.
    ux = rx + ai * xi - aj * xj
    uy = ry + ai * yi - aj * yj
    uz = rz + ai * zi - aj * zj
    dix, diy, diz = (bi - ai) * xi, (bi - ai) * yi, (bi - ai) * zi
    djx, djy, djz = (bj - aj) * xj, (bj - aj) * yj, (bj - aj) * zj
    a2 = dix * dix + diy * diy + diz * diz
    e2 = djx * djx + djy * djy + djz * djz
    b = dix * djx + diy * djy + diz * djz
    c2 = dix * ux + diy * uy + diz * uz
    f = djx * ux + djy * uy + djz * uz
    denom = a2 * e2 - b * b
    if denom > 1e-14 * a2 * e2:
        s = _clamp01((b * f - c2 * e2) / denom)
        t = _clamp01((b * s + f) / e2)
        s = _clamp01((b * t - c2) / a2)
        regular = 0.0
    else:
        t = 0.0 if e2 <= 1e-300 else _clamp01(f / e2)
        s = 0.0 if a2 <= 1e-300 else _clamp01((b * t - c2) / a2)
        regular = 1.0
    rr = ux * ux + uy * uy + uz * uz
    squared = rr + s * (s * a2 + 2.0 * (c2 - t * b)) + t * (t * e2 - 2.0 * f)
    return squared, regular
