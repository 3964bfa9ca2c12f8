"""The singularity margin's kernels (numba): one Plücker row of a leg and the smallest singular
value of the 6×6 matrix of the legs' rows (docs/theory.md, "The singularity margin")."""

from __future__ import annotations

import math

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import helper as _helper

# isort: split
import numpy as np
from numpy.typing import NDArray

__all__ = ["ROWS_SCRATCH"]

# ------------------------------------------------------------------------------ singularity
#: Scratch of the singularity margin: M (36), G (36), its tridiagonal form (6 + 6).
ROWS_SCRATCH = 84
#: Machine epsilon of float64 (the stopping tolerance of the smallest eigenvalue).
_EPSILON = float(np.finfo(np.float64).eps)


@_helper
def _plucker_row(
    rows: NDArray[np.float64],
    k: int,
    x: float,
    y: float,
    z: float,
    squared: float,
    rbx: float,
    rby: float,
    rbz: float,
    rho: float,
) -> None:
    """Row k of M into ``rows[6k : 6k + 6]``: (n_k, (R·b_k) × n_k / ρ), n_k = L_k / ℓ_k."""
    inverse = 1.0 / math.sqrt(squared)
    nx, ny, nz = x * inverse, y * inverse, z * inverse
    rows[6 * k] = nx
    rows[6 * k + 1] = ny
    rows[6 * k + 2] = nz
    scale = 1.0 / rho
    rows[6 * k + 3] = (rby * nz - rbz * ny) * scale
    rows[6 * k + 4] = (rbz * nx - rbx * nz) * scale
    rows[6 * k + 5] = (rbx * ny - rby * nx) * scale


@_helper
def _smallest_singular_value(rows: NDArray[np.float64]) -> float:
    """σ_min of the 6×6 matrix M in ``rows[:36]`` (row-major); ``rows`` (84,) is scratch and is
    overwritten, M included.

    σ_min = √λ_min(G), G = MᵀM, in three steps (about 400 flops):

    1. G, and its Householder reduction to a symmetric tridiagonal T (diagonal d, off-diagonal
       e) with the same eigenvalues (Golub & Van Loan, *Matrix Computations*, 4th ed.,
       algorithm 8.3.1; eigenvalues only). Backward stable: the eigenvalues of T are those of
       G + δG, ‖δG‖ ≲ ε·‖G‖.
    2. det(T − xI) by the three-term recurrence p_k = (d_k − x) p_{k−1} − e_k² p_{k−2}
       (p_{−1} = 1, p_0 = d_0 − x), and its first two derivatives in x by differentiating it.
       The ratios p_k/p_{k−1} are the LDLᵀ pivots of T − xI: all are positive exactly when
       x < λ_min (Sylvester's law of inertia; the Sturm sequence of T). With
       u_i = 1/(λ_i − x): S1 = Σ u_i = −p′/p and S2 = Σ u_i² = S1² − p″/p. No overflow or
       underflow: each row of M has norm ≤ √2 (|n| = 1, |R·b × n|/ρ ≤ 1), so
       6 ≤ tr G ≤ 12 and |p| ≤ 12⁶ on [0, λ_min].
    3. Laguerre's iteration from x = 0 (G is positive semi-definite, 0 ≤ λ_min):
       x ← x + 6 / (S1 + √(5 (6 S2 − S1²))). For a polynomial with real roots, the step from
       a point below all of them never passes the smallest root and converges to it,
       monotonically, cubically for a simple root (Parlett, "Laguerre's method applied to the
       matrix eigenvalue problem", *Math. Comp.* 18, 1964). The cancellation in 6 S2 − S1²
       (≥ 0 by Cauchy–Schwarz) is covered by adding 10⁻¹³ S2 under the root, which only
       shortens the step; a step made too long by the rounding of S1 and S2 passes λ_min by
       no more than that rounding, and the pivots' signs catch it (below). It stops when the
       step, or the width of the bracket λ_min − x ∈ [step, S1/S2] (u_max ≥ S2/S1 since
       S2 ≤ u_max·S1), is below 4ε·‖G‖, or when a pivot is not positive: x is then λ_min
       to rounding (it was reached by a step that cannot pass λ_min). 2–3 evaluations of the
       recurrence for most poses. Should it stop for any other reason (a step that is not
       positive, 60 steps: neither seen), x is still below λ_min: the margin errs on the safe
       side.

    Accuracy as a full eigensolver (this replaced the implicit QL algorithm, with the same
    margins to 10⁻¹² on the packaged example, in a third of the time): λ_min to a few tens of
    ε·‖G‖ (forming G moves its eigenvalues by at most 36 ε·‖G‖, the rest adds a few ε·‖G‖),
    so σ_min to ≈ 50 ε·‖M‖² / σ_min (1e-12 for σ_min ≥ 0.01), enough for a margin compared
    with a limit σ_lim > 0; ``test/test_singularity.py`` compares it with numpy's SVD,
    clustered and rank-deficient matrices included. NaN rows (a zero-length leg) give NaN.
    """
    a = rows[36:72]
    for i in range(6):
        for j in range(i + 1):
            total = 0.0
            for k in range(6):
                total += rows[6 * k + i] * rows[6 * k + j]
            a[6 * i + j] = total
            a[6 * j + i] = total
    norm = 0.0
    for i in range(6):
        row = 0.0
        for j in range(6):
            row += abs(a[6 * i + j])
        if row > norm or row != row:  # NaN sticks (max() would drop it)
            norm = row
    if norm != norm:
        return norm
    d = rows[72:78]
    e = rows[78:84]  # e[k] couples d[k − 1] and d[k]
    v = rows[0:6]  # M is no longer needed: its rows hold the Householder vectors
    w = rows[6:12]
    for k in range(4):
        squared = 0.0
        for i in range(k + 1, 6):
            v[i] = a[6 * i + k]
            squared += v[i] * v[i]
        d[k] = a[7 * k]
        first = v[k + 1]
        alpha = -math.sqrt(squared) if first >= 0.0 else math.sqrt(squared)
        e[k + 1] = alpha
        v[k + 1] = first - alpha
        length = squared - first * first + v[k + 1] * v[k + 1]
        if length == 0.0:  # the column is already reduced
            continue
        beta = 2.0 / length
        along = 0.0
        for i in range(k + 1, 6):
            total = 0.0
            for j in range(k + 1, 6):
                total += a[6 * i + j] * v[j]
            w[i] = beta * total
            along += w[i] * v[i]
        half = 0.5 * beta * along
        for i in range(k + 1, 6):
            w[i] -= half * v[i]
        for i in range(k + 1, 6):
            for j in range(k + 1, 6):
                a[6 * i + j] -= v[i] * w[j] + w[i] * v[j]
    d[4] = a[28]
    d[5] = a[35]
    e[5] = a[34]
    tolerance = 4.0 * _EPSILON * norm
    x = 0.0
    for _iteration in range(60):
        # det(T − xI) (p) and its first two derivatives (dp, ddp) by the three-term recurrence
        p0 = 1.0
        p1 = d[0] - x
        dp0 = 0.0
        dp1 = -1.0
        ddp0 = 0.0
        ddp1 = 0.0
        positive = p1 > 0.0
        for k in range(1, 6):
            coupling = e[k] * e[k]
            shifted = d[k] - x
            p2 = shifted * p1 - coupling * p0
            dp2 = shifted * dp1 - p1 - coupling * dp0
            ddp2 = shifted * ddp1 - 2.0 * dp1 - coupling * ddp0
            positive = positive and p2 > 0.0
            p0, p1 = p1, p2
            dp0, dp1 = dp1, dp2
            ddp0, ddp1 = ddp1, ddp2
        if not positive:
            break
        inverse = 1.0 / p1
        s1 = -dp1 * inverse
        s2 = s1 * s1 - ddp1 * inverse
        step = 6.0 / (s1 + math.sqrt(5.0 * (max(6.0 * s2 - s1 * s1, 0.0) + 1e-13 * s2)))
        if not step > 0.0:  # rounding at a pole, or overflow: x stays a lower bound
            break
        x += step
        if step <= tolerance or s1 / s2 - step <= tolerance:
            break
    return math.sqrt(x)
