"""Margin kernels (numba): the constraint margins of one pose and of blocks of poses.

Batches are evaluated 128 poses at a time as planes of one flat array, stage by stage
(:func:`_check_block`), so that every loop vectorises; single poses and the rare poses that need
care go through the scalar :func:`_pose`. Both follow the numpy reference of
``test/reference.py`` operation by operation: margins agree to rounding. The model is the packed
vector of :mod:`hexapod_workspace.core.kernels.layout`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

from ..base.jit import Collide
from ..base.jit import entry_points as _entry_points

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import helper as _helper
from ..base.jit import inline as _inline

# isort: split
import numpy as np
from numba.np.unsafe.ndarray import to_fixed_tuple
from numpy.typing import NDArray

from ..constraints.table import (
    ACTUATOR,
    BASE_JOINT,
    COLLISION,
    IK,
    LEG_INTERFERENCE,
    LEG_LENGTH,
    N_CONSTRAINTS,
    PLATFORM_JOINT,
    SINGULARITY,
    TRANSMISSION,
)
from .collision import SCRATCH_FLOATS
from .layout import (
    ALPHA,
    ALPHA_EQUAL,
    AXIS_ALONG,
    AXIS_CROSS,
    BETA,
    BETA_EQUAL,
    BRANCH,
    COLLISION_ON,
    CRANK,
    CROSS,
    DIAMETER,
    INTERFERENCE,
    JA,
    JB,
    LEG,
    LENGTH_FLOOR,
    LMAX,
    LMIN,
    MODEL_SIZE,
    ORDER,
    PAIR_I,
    PAIR_J,
    PAIRED_LENGTH,
    QCENTRE,
    QCOS,
    QMAX,
    QMIN,
    QSIN,
    RAIL,
    RHO,
    ROWS_USED,
    RPAIR,
    RR,
    SCALE,
    SHARED_BASE,
    SHARED_PLATFORM,
    SINGULARITY_MIN,
    SINGULARITY_ON,
    TAU_MIN,
    ZERO,
    A,
    B,
)

__all__ = ["SCRATCH_ROWS", "MarginKernels", "margin_entry_points"]

# ------------------------------------------------------------------------------ one pose
# Slots of the per-pose result vector ``out``.
# Slots 0 .. N_CONSTRAINTS − 1: the margins, in constraint-table order.
OUT_LEG = N_CONSTRAINTS  # limiting leg of each margin (N_CONSTRAINTS slots, as float)
OUT_PAIR = 2 * N_CONSTRAINTS  # closest pair (2 slots)
OUT_SHORTEST = OUT_PAIR + 2  # shortest leg length, m
OUT_GAP = OUT_SHORTEST + 1  # the collision margin's gap to its upper bound, m (kernels.collision)
OUT_SIZE = OUT_GAP + 1
#: First row of the collision margin's working memory in the per-pose scratch.
_COLLISION_SCRATCH = 8
#: Rows of the per-pose scratch (6 legs each): leg vector planes, squared length, 1/ℓ², the
#: base-side ends of pus/rus legs (three planes), then the working memory of the collision margin.
SCRATCH_ROWS = _COLLISION_SCRATCH + (SCRATCH_FLOATS + 5) // 6


@_helper
def _clamp01(value: float) -> float:
    """Clamp to [0, 1]; NaN stays NaN."""
    if value < 0.0:
        return 0.0
    if value > 1.0:
        return 1.0
    return value


@_helper
def _pose(
    model: NDArray[np.float64],
    r: NDArray[np.float64],
    px: float,
    py: float,
    pz: float,
    scratch: NDArray[np.float64],
    out: NDArray[np.float64],
    want_pair: bool,
    moving: int | None,
    cranks: int | None,
    collide: Collide,
    singular: int | None,
) -> None:
    """Margins of one pose into ``out`` (OUT_SIZE,).

    ``r`` (9,) is the rotation matrix row-major, (px, py, pz) the position (m), ``scratch``
    (5, 6) working memory (leg vector planes and squared lengths). Follows the numpy reference
    (test/reference.py, BatchedMargins) operation by operation, so margins agree to rounding:
    the smallest margin of each constraint and its leg (first one on ties; NaN, a zero-length
    leg, wins), the closest pair by Ericson's clamped closest points.
    ``want_pair`` False skips the interference check (margin +inf). Models with moving base
    joints (pus, rus) go to :func:`_pose_moving`. ``moving``, ``cranks``, ``collide`` and
    ``singular`` are the compile-time switches of :mod:`~hexapod_workspace.core.base.jit` (None: the
    code is left out of the compiled function).
    """
    if moving is not None:
        _pose_moving(model, r, px, py, pz, scratch, out, want_pair, cranks, collide, singular)
        return
    out[ACTUATOR] = np.inf
    out[IK] = np.inf
    out[TRANSMISSION] = np.inf
    out[OUT_LEG + ACTUATOR] = 0
    out[OUT_LEG + IK] = 0
    out[OUT_LEG + TRANSMISSION] = 0
    lx = scratch[0]
    ly = scratch[1]
    lz = scratch[2]
    sq = scratch[3]
    inverse_sq = scratch[4]
    r00, r01, r02 = r[0], r[1], r[2]
    r10, r11, r12 = r[3], r[4], r[5]
    r20, r21, r22 = r[6], r[7], r[8]
    m_len = np.inf
    leg_len = 0
    m_a = np.inf
    leg_a = 0
    m_b = np.inf
    leg_b = 0
    shortest = np.inf
    alpha_equal = model[ALPHA_EQUAL] != 0.0
    beta_equal = model[BETA_EQUAL] != 0.0
    for k in range(6):
        bx = model[B + 3 * k]
        by = model[B + 3 * k + 1]
        bz = model[B + 3 * k + 2]
        x = (r00 * bx + r01 * by + r02 * bz) + (px - model[A + 3 * k])
        y = (r10 * bx + r11 * by + r12 * bz) + (py - model[A + 3 * k + 1])
        z = (r20 * bx + r21 * by + r22 * bz) + (pz - model[A + 3 * k + 2])
        lx[k] = x
        ly[k] = y
        lz[k] = z
        squared = x * x + y * y + z * z
        sq[k] = squared
        length = math.sqrt(squared)
        if length < shortest:
            shortest = length
        inverse = 1.0 / length
        inverse_sq[k] = inverse * inverse
        value = min(length - model[LMIN + k], model[LMAX + k] - length)
        if value < m_len or (value != value and m_len == m_len):
            m_len = value
            leg_len = k
        # Base joint: angle between jA_i and n_i.
        cos_a = (
            model[JA + 3 * k] * x + model[JA + 3 * k + 1] * y + model[JA + 3 * k + 2] * z
        ) * inverse
        # Platform joint: angle between R·jB_i and −n_i.
        jx = model[JB + 3 * k]
        jy = model[JB + 3 * k + 1]
        jz = model[JB + 3 * k + 2]
        cos_b = (
            (r00 * jx + r01 * jy + r02 * jz) * x
            + (r10 * jx + r11 * jy + r12 * jz) * y
            + (r20 * jx + r21 * jy + r22 * jz) * z
        ) * -inverse
        # Equal limits: the margin decreases with the angle, the smallest cosine limits (one
        # arccos per pose, below); otherwise the margin itself per leg.
        value = cos_a if alpha_equal else model[ALPHA + k] - math.acos(min(max(cos_a, -1.0), 1.0))
        if value < m_a or (value != value and m_a == m_a):
            m_a = value
            leg_a = k
        value = cos_b if beta_equal else model[BETA + k] - math.acos(min(max(cos_b, -1.0), 1.0))
        if value < m_b or (value != value and m_b == m_b):
            m_b = value
            leg_b = k
    if alpha_equal:
        m_a = model[ALPHA] - math.acos(min(max(m_a, -1.0), 1.0))
    if beta_equal:
        m_b = model[BETA] - math.acos(min(max(m_b, -1.0), 1.0))
    out[LEG_LENGTH] = m_len
    out[BASE_JOINT] = m_a
    out[PLATFORM_JOINT] = m_b
    out[OUT_LEG + LEG_LENGTH] = leg_len
    out[OUT_LEG + BASE_JOINT] = leg_a
    out[OUT_LEG + PLATFORM_JOINT] = leg_b
    out[OUT_SHORTEST] = shortest
    # The collision and singularity kernels are called only when they are on: passing the
    # arrays to a call costs about a fifth of a 6-UPS pose, even when it returns at once.
    if collide is not None and model[COLLISION_ON] != 0.0:
        _pose_collision(model, r, px, py, pz, scratch, out, collide)
    else:
        _no_collision(out)
    out[OUT_LEG + SINGULARITY] = 0
    if singular is not None and model[SINGULARITY_ON] != 0.0:
        out[SINGULARITY] = _pose_singularity(model, r, scratch)
    else:
        out[SINGULARITY] = np.inf
    if not want_pair or model[INTERFERENCE] == 0.0:
        out[LEG_INTERFERENCE] = np.inf
        out[OUT_LEG + LEG_INTERFERENCE] = 0
        out[OUT_PAIR] = 0
        out[OUT_PAIR + 1] = 0
        return
    # Pairs in the model's order (closest at the home pose first). A pair is skipped when an
    # exact lower bound of its distance cannot beat the best so far: projected on the unit
    # vector u = r/|r| (r = A_i − A_j), the segments are at least
    # (|r|² + min(0, c) − max(0, f)) / |r| apart (c = L_i·r, f = L_j·r). The slack covers
    # rounding, so a skipped pair never holds the minimum.
    best = np.inf
    best_squared = np.inf
    best_pair = 0
    for rank in range(15):
        pair = int(model[ORDER + rank])
        i = PAIR_I[pair]
        j = PAIR_J[pair]
        rx = model[RPAIR + 3 * pair]
        ry = model[RPAIR + 3 * pair + 1]
        rz = model[RPAIR + 3 * pair + 2]
        rr = model[RR + pair]
        xi = lx[i]
        yi = ly[i]
        zi = lz[i]
        xj = lx[j]
        yj = ly[j]
        zj = lz[j]
        a = sq[i]
        e = sq[j]
        if model[SHARED_BASE + pair] + model[SHARED_PLATFORM + pair] != 0.0:
            squared = _free_squared(model, pair, rx, ry, rz, xi, yi, zi, xj, yj, zj, a, e)[0]
        else:
            c = xi * rx + yi * ry + zi * rz
            f = xj * rx + yj * ry + zj * rz
            gap = rr + min(c, 0.0) - max(f, 0.0)
            if gap > 0.0 and gap * gap >= rr * (best_squared + 1e-12 * (rr + a + e)):
                continue
            b = xi * xj + yi * yj + zi * zj
            denom = a * e - b * b
            if denom > 1e-14 * a * e:
                s = min(max((b * f - c * e) / denom, 0.0), 1.0)
                t = min(max((b * s + f) * inverse_sq[j], 0.0), 1.0)
                s = min(max((b * t - c) * inverse_sq[i], 0.0), 1.0)
            else:
                # Parallel or point-like segments (or NaN): start from s = 0.
                t = 0.0 if e <= 1e-300 else _clamp01(f / e)
                s = 0.0 if a <= 1e-300 else _clamp01((b * t - c) / a)
            squared = rr + s * (s * a + 2.0 * (c - t * b)) + t * (t * e - 2.0 * f)
        # Compare distances, not their squares, where it matters: pairs whose squares differ
        # in the last bit can have equal distances, and then the lower pair index limits.
        if squared <= best_squared or squared != squared:
            distance = math.sqrt(max(squared, 0.0))
            if (
                distance < best
                or (distance == best and pair < best_pair)
                or (distance != distance and best == best)
            ):
                best = distance
                best_pair = pair
            best_squared = min(squared, best_squared)
    out[LEG_INTERFERENCE] = best - model[DIAMETER]
    out[OUT_LEG + LEG_INTERFERENCE] = PAIR_I[best_pair]
    out[OUT_PAIR] = PAIR_I[best_pair]
    out[OUT_PAIR + 1] = PAIR_J[best_pair]


@_helper
def _pose_singularity(
    model: NDArray[np.float64], r: NDArray[np.float64], scratch: NDArray[np.float64]
) -> float:
    """The singularity margin of one pose from its leg vector planes (scratch rows 0..3) and
    its rotation ``r`` (9,); +inf when the margin is not evaluated."""
    if model[SINGULARITY_ON] == 0.0:
        return np.inf
    rows = np.empty(ROWS_SCRATCH)
    for k in range(6):
        bx, by, bz = model[B + 3 * k], model[B + 3 * k + 1], model[B + 3 * k + 2]
        _plucker_row(
            rows,
            k,
            scratch[0, k],
            scratch[1, k],
            scratch[2, k],
            scratch[3, k],
            r[0] * bx + r[1] * by + r[2] * bz,
            r[3] * bx + r[4] * by + r[5] * bz,
            r[6] * bx + r[7] * by + r[8] * bz,
            model[RHO],
        )
    value: float = _smallest_singular_value(rows) - model[SINGULARITY_MIN]
    return value


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


@_helper
def _pose_moving(
    model: NDArray[np.float64],
    r: NDArray[np.float64],
    px: float,
    py: float,
    pz: float,
    scratch: NDArray[np.float64],
    out: NDArray[np.float64],
    want_pair: bool,
    cranks: int | None,
    collide: Collide,
    singular: int | None,
) -> None:
    """Margins of one pose of a pus or rus model into ``out`` (OUT_SIZE,), as :func:`_pose`.

    Per leg, the inverse kinematics of :mod:`hexapod_workspace.core.model.architectures.pus` or
    :mod:`~hexapod_workspace.core.model.architectures.rus` (the same closed forms), the leg vector
    ``L_k = B_k − A_k(q_k)`` in the scratch planes (lx, ly, lz, sq, 1/ℓ²) and the base-side end
    A_k in planes 5..7. Where some leg has no solution (``ik`` < 0) every margin that needs its
    q is NaN (``leg_length`` +inf: it does not apply; ``singularity`` +inf when not evaluated,
    ``leg_interference`` +inf when disabled).
    """
    lx = scratch[0]
    ly = scratch[1]
    lz = scratch[2]
    sq = scratch[3]
    inverse_sq = scratch[4]
    ax = scratch[5]
    ay = scratch[6]
    az = scratch[7]
    r00, r01, r02 = r[0], r[1], r[2]
    r10, r11, r12 = r[3], r[4], r[5]
    r20, r21, r22 = r[6], r[7], r[8]
    tau_min = model[TAU_MIN]
    m_act = np.inf
    leg_act = 0
    m_ik = np.inf
    leg_ik = 0
    m_tau = np.inf
    leg_tau = 0
    m_a = np.inf
    leg_a = 0
    m_b = np.inf
    leg_b = 0
    solved = True
    for k in range(6):
        bx = model[B + 3 * k]
        by = model[B + 3 * k + 1]
        bz = model[B + 3 * k + 2]
        platform_x = (r00 * bx + r01 * by + r02 * bz) + px
        platform_y = (r10 * bx + r11 * by + r12 * bz) + py
        platform_z = (r20 * bx + r21 * by + r22 * bz) + pz
        dx = platform_x - model[A + 3 * k]
        dy = platform_y - model[A + 3 * k + 1]
        dz = platform_z - model[A + 3 * k + 2]
        if cranks is None:  # pus
            ux, uy, uz = model[RAIL + 3 * k], model[RAIL + 3 * k + 1], model[RAIL + 3 * k + 2]
            ik, q = _slide_leg(dx, dy, dz, ux, uy, uz, model[LEG + k], model[BRANCH + k])
            q = q if ik >= 0.0 else np.nan
            base_x = model[A + 3 * k] + q * ux
            base_y = model[A + 3 * k + 1] + q * uy
            base_z = model[A + 3 * k + 2] + q * uz
            tx, ty, tz = ux, uy, uz
            jx, jy, jz = model[JA + 3 * k], model[JA + 3 * k + 1], model[JA + 3 * k + 2]
        else:
            e, f, w, sizes, centre = _crank(model, k)
            ik, q, cq, sq_ = _crank_leg(dx, dy, dz, e, f, w, sizes, centre)
            if not ik >= 0.0:
                q, cq, sq_ = np.nan, np.nan, np.nan
            base_x, base_y, base_z, tx, ty, tz, jx, jy, jz = _crank_end(
                _vector(model, A, k),
                e,
                f,
                _vector(model, JA, k),
                _vector(model, AXIS_CROSS, k),
                _vector(model, AXIS_ALONG, k),
                sizes[0],
                cq,
                sq_,
            )
        if not ik >= 0.0:
            solved = False
        if ik < m_ik or (ik != ik and m_ik == m_ik):
            m_ik = ik
            leg_ik = k
        x = platform_x - base_x
        y = platform_y - base_y
        z = platform_z - base_z
        ax[k] = base_x
        ay[k] = base_y
        az[k] = base_z
        lx[k] = x
        ly[k] = y
        lz[k] = z
        squared = x * x + y * y + z * z
        sq[k] = squared
        inverse = 1.0 / math.sqrt(squared)
        inverse_sq[k] = inverse * inverse
        value = min(q - model[QMIN + k], model[QMAX + k] - q)
        if value < m_act or (value != value and m_act == m_act):
            m_act = value
            leg_act = k
        value = abs(tx * x + ty * y + tz * z) * inverse - tau_min
        if value < m_tau or (value != value and m_tau == m_tau):
            m_tau = value
            leg_tau = k
        cos_a = (jx * x + jy * y + jz * z) * inverse
        value = model[ALPHA + k] - math.acos(min(max(cos_a, -1.0), 1.0))
        if value < m_a or (value != value and m_a == m_a):
            m_a = value
            leg_a = k
        kx = model[JB + 3 * k]
        ky = model[JB + 3 * k + 1]
        kz = model[JB + 3 * k + 2]
        cos_b = (
            (r00 * kx + r01 * ky + r02 * kz) * x
            + (r10 * kx + r11 * ky + r12 * kz) * y
            + (r20 * kx + r21 * ky + r22 * kz) * z
        ) * -inverse
        value = model[BETA + k] - math.acos(min(max(cos_b, -1.0), 1.0))
        if value < m_b or (value != value and m_b == m_b):
            m_b = value
            leg_b = k
    out[LEG_LENGTH] = np.inf
    out[OUT_LEG + LEG_LENGTH] = 0
    out[ACTUATOR] = m_act
    out[OUT_LEG + ACTUATOR] = leg_act
    out[IK] = m_ik
    out[OUT_LEG + IK] = leg_ik
    out[TRANSMISSION] = m_tau
    out[OUT_LEG + TRANSMISSION] = leg_tau
    out[BASE_JOINT] = m_a
    out[OUT_LEG + BASE_JOINT] = leg_a
    out[PLATFORM_JOINT] = m_b
    out[OUT_LEG + PLATFORM_JOINT] = leg_b
    out[OUT_SHORTEST] = model[LENGTH_FLOOR]
    if collide is not None and model[COLLISION_ON] != 0.0:  # called only when on, as in _pose
        _pose_collision(model, r, px, py, pz, scratch, out, collide)
    else:
        _no_collision(out)
    out[OUT_LEG + SINGULARITY] = 0
    out[OUT_LEG + LEG_INTERFERENCE] = 0
    out[OUT_PAIR] = 0
    out[OUT_PAIR + 1] = 0
    if not solved:
        # Margins that need the unsolved leg's q are undefined (NaN counts as violated).
        out[ACTUATOR] = np.nan
        out[TRANSMISSION] = np.nan
        out[BASE_JOINT] = np.nan
        out[PLATFORM_JOINT] = np.nan
        out[SINGULARITY] = np.nan if model[SINGULARITY_ON] != 0.0 else np.inf
        out[LEG_INTERFERENCE] = np.nan if want_pair and model[INTERFERENCE] != 0.0 else np.inf
        if collide is not None and model[COLLISION_ON] != 0.0:
            out[COLLISION] = np.nan  # a leg body of an unsolved leg is nowhere
            out[OUT_LEG + COLLISION] = -1.0
        return
    if singular is not None and model[SINGULARITY_ON] != 0.0:
        out[SINGULARITY] = _pose_singularity(model, r, scratch)
    else:
        out[SINGULARITY] = np.inf
    if not want_pair or model[INTERFERENCE] == 0.0:
        out[LEG_INTERFERENCE] = np.inf
        return
    # Every pair in index order (the base-side ends move: no pruning by fixed A_i − A_j),
    # Ericson's clamped closest points as in _pose; the first pair wins ties.
    best = np.inf
    best_pair = 0
    for pair in range(15):
        i = PAIR_I[pair]
        j = PAIR_J[pair]
        rx = ax[i] - ax[j]
        ry = ay[i] - ay[j]
        rz = az[i] - az[j]
        rr = rx * rx + ry * ry + rz * rz
        xi, yi, zi = lx[i], ly[i], lz[i]
        xj, yj, zj = lx[j], ly[j], lz[j]
        c = xi * rx + yi * ry + zi * rz
        f = xj * rx + yj * ry + zj * rz
        a = sq[i]
        e = sq[j]
        b = xi * xj + yi * yj + zi * zj
        denom = a * e - b * b
        if denom > 1e-14 * a * e:
            s = min(max((b * f - c * e) / denom, 0.0), 1.0)
            t = min(max((b * s + f) * inverse_sq[j], 0.0), 1.0)
            s = min(max((b * t - c) * inverse_sq[i], 0.0), 1.0)
        else:
            t = 0.0 if e <= 1e-300 else _clamp01(f / e)
            s = 0.0 if a <= 1e-300 else _clamp01((b * t - c) / a)
        squared = rr + s * (s * a + 2.0 * (c - t * b)) + t * (t * e - 2.0 * f)
        distance = math.sqrt(max(squared, 0.0))
        if distance < best or (distance != distance and best == best):
            best = distance
            best_pair = pair
    out[LEG_INTERFERENCE] = best - model[DIAMETER]
    out[OUT_LEG + LEG_INTERFERENCE] = PAIR_I[best_pair]
    out[OUT_PAIR] = PAIR_I[best_pair]
    out[OUT_PAIR + 1] = PAIR_J[best_pair]


@_inline
def _no_collision(out: NDArray[np.float64]) -> None:
    """The collision outputs of a model without a scene: +inf, no pair (−1), no gap."""
    out[COLLISION] = np.inf
    out[OUT_LEG + COLLISION] = -1.0
    out[OUT_GAP] = 0.0


@_helper
def _pose_collision(
    model: NDArray[np.float64],
    r: NDArray[np.float64],
    px: float,
    py: float,
    pz: float,
    scratch: NDArray[np.float64],
    out: NDArray[np.float64],
    collide: Callable[..., tuple[float, float, float]],
) -> None:
    """The collision margin, its pair (as the constraint's "leg") and gap into ``out``, from the
    leg planes of ``scratch`` (the leg bodies run from B_k − L_k to B_k, so a moving base-side
    end is where the leg architecture put it; +inf, −1, 0 without a scene). ``collide`` is
    :func:`~hexapod_workspace.core.kernels.collision.collision_function`."""
    if model[COLLISION_ON] != 0.0:
        memory = scratch[_COLLISION_SCRATCH:].reshape(-1)
        value, pair, gap = collide(
            model, MODEL_SIZE, B, r, px, py, pz, scratch[0], scratch[1], scratch[2], memory
        )
    else:
        value, pair, gap = np.inf, -1.0, 0.0
    out[COLLISION] = value
    out[OUT_LEG + COLLISION] = pair
    out[OUT_GAP] = gap


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


@_helper
def _block_singularity(
    model: NDArray[np.float64],
    work: NDArray[np.float64],
    count: int,
    rows: NDArray[np.float64],
    moving: int | None,
) -> None:
    """The singularity margin of the poses of a block that take the vectorised path (the
    others are computed whole by :func:`_pose`) into the _SIGMA row, from the leg and rotation
    planes (before the outputs overwrite the rotation planes)."""
    for n in range(count):
        if work[(_MIN + _FIX) * BLOCK + n] != 0.0:
            continue
        # pus/rus poses with an unsolved leg: NaN, not computed
        if moving is not None and work[(_MOVE + _UNSOLVED) * BLOCK + n] != 0.0:
            continue
        for k in range(6):
            leg = (_LEGS + 7 * k) * BLOCK + n
            bx, by, bz = model[B + 3 * k], model[B + 3 * k + 1], model[B + 3 * k + 2]
            rbx = (
                work[_R * BLOCK + n] * bx
                + work[(_R + 1) * BLOCK + n] * by
                + work[(_R + 2) * BLOCK + n] * bz
            )
            rby = (
                work[(_R + 3) * BLOCK + n] * bx
                + work[(_R + 4) * BLOCK + n] * by
                + work[(_R + 5) * BLOCK + n] * bz
            )
            rbz = (
                work[(_R + 6) * BLOCK + n] * bx
                + work[(_R + 7) * BLOCK + n] * by
                + work[(_R + 8) * BLOCK + n] * bz
            )
            _plucker_row(
                rows,
                k,
                work[leg + _LX * BLOCK],
                work[leg + _LY * BLOCK],
                work[leg + _LZ * BLOCK],
                work[leg + _SQ * BLOCK],
                rbx,
                rby,
                rbz,
                model[RHO],
            )
        work[_SIGMA * BLOCK + n] = _smallest_singular_value(rows) - model[SINGULARITY_MIN]


@_helper
def _block_collision(
    model: NDArray[np.float64],
    work: NDArray[np.float64],
    count: int,
    px: float,
    py: float,
    pz: float,
    scratch: NDArray[np.float64],
    r: NDArray[np.float64],
    moving: int | None,
    collide: Callable[..., tuple[float, float, float]],
) -> None:
    """The collision margin and its pair of the poses of a block that take the vectorised path
    (the others are computed whole by :func:`_pose`) into the _COLLIDE rows, from the leg and
    rotation planes (before the outputs overwrite the rotation planes). The leg planes hold
    L_k = B_k − A_k with A_k where the leg architecture puts it (NaN for an unsolved leg, whose
    pose is answered by :func:`_unsolved_outputs`)."""
    memory = scratch[_COLLISION_SCRATCH:].reshape(-1)
    for n in range(count):
        if work[(_MIN + _FIX) * BLOCK + n] != 0.0:
            continue
        if moving is not None and work[(_MOVE + _UNSOLVED) * BLOCK + n] != 0.0:
            continue
        for i in range(9):
            r[i] = work[(_R + i) * BLOCK + n]
        for k in range(6):
            leg = (_LEGS + 7 * k) * BLOCK + n
            scratch[0, k] = work[leg + _LX * BLOCK]
            scratch[1, k] = work[leg + _LY * BLOCK]
            scratch[2, k] = work[leg + _LZ * BLOCK]
        value, pair, _ = collide(
            model, MODEL_SIZE, B, r, px, py, pz, scratch[0], scratch[1], scratch[2], memory
        )
        work[_COLLIDE * BLOCK + n] = value
        work[(_COLLIDE + 1) * BLOCK + n] = pair


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


@_inline
def _limiting_constraint(model: NDArray[np.float64], out: NDArray[np.float64]) -> int:
    """Index of the smallest relative margin (first on ties; NaN wins). Only the rows in use
    (``model[ROWS_USED]``) are read: the others are +inf with a finite positive scale, so they
    never limit a pose."""
    best = out[0] / model[SCALE]
    index = 0
    for c in range(1, int(model[ROWS_USED])):
        value = out[c] / model[SCALE + c]
        if value < best or (value != value and best == best):
            best = value
            index = c
    return index


@_inline
def _feasible(out: NDArray[np.float64], rows: int) -> bool:
    """Every margin of the first ``rows`` rows ≥ 0 (NaN counts as violated); a caller whose
    later rows are +inf (``model[ROWS_USED]``: rows that do not apply) may leave them out."""
    for c in range(rows):  # noqa: SIM110 - a loop numba compiles, not a generator
        if not out[c] >= 0.0:
            return False
    return True


# ------------------------------------------------------------------------------ blocks of poses
#: Poses per block of the vectorised check (its working planes stay in the L1/L2 cache).
BLOCK = 128
# Rows of the block scratch (each a plane of BLOCK poses, in one flat array).
_CA, _SA, _CB, _SB, _CG, _SG = 0, 1, 2, 3, 4, 5
_R = 6  # 9 rows: rotation matrix, row-major
_PHI, _THETA, _PSI = 15, 16, 17
_MIN = max(18, OUT_SHORTEST)  # 9 rows: running minima (below the outputs' rows), see below
_LEGS = _MIN + 9  # 7 rows per leg, see the offsets below
_SIGMA = _LEGS + 6 * 7  # σ_min − σ_lim of each pose (when the singularity margin is on)
# Moving base joints (pus, rus): the base-side end of each leg (3 rows per leg: x, y, z) and the
# running minima of the architecture's own margins with their legs.
_BASE = _SIGMA + 1
_MOVE = _BASE + 18
# _UNSOLVED: 1.0 when some leg has no inverse-kinematics solution; _UNSOLVED_LEG: the first.
_M_ACT, _LEG_ACT, _M_IK, _LEG_IK, _M_TAU, _LEG_TAU, _UNSOLVED, _UNSOLVED_LEG = range(8)
_COLLIDE = _MOVE + 8  # 2 rows: collision margin and its pair (when a scene is declared)
_BLOCK_ROWS = _COLLIDE + 2
# Rows of the running minima (offsets from _MIN): margins or cosines and their leg or pair
# (_BEST: the smallest squared distance between two legs).
_M_LEN, _LEG_LEN, _M_A, _LEG_A, _M_B, _LEG_B, _BEST, _PAIR, _FIX = range(9)
# Rows of one leg (offsets from _LEGS + 7·k): vector, squared length, 1/ℓ², joint cosines.
_LX, _LY, _LZ, _SQ, _INV, _COS_A, _COS_B = range(7)


@_helper
def _planes(work: NDArray[np.float64], row: int, rows: int) -> NDArray[np.float64]:
    """The planes [row, row + rows) of a block scratch, as one flat view."""
    return work[row * BLOCK : (row + rows) * BLOCK]


@_inline
def _store_cosines(
    leg: NDArray[np.float64],
    minima: NDArray[np.float64],
    n: int,
    kf: float,
    cos_a: float,
    cos_b: float,
) -> None:
    """Pose n of leg planes: both joint cosines, and their running minima with the leg (first
    leg on ties; one select per statement, so that the loops vectorise)."""
    leg[_COS_A * BLOCK + n] = cos_a
    leg[_COS_B * BLOCK + n] = cos_b
    smallest = minima[_M_A * BLOCK + n]
    minima[_LEG_A * BLOCK + n] = kf if cos_a < smallest else minima[_LEG_A * BLOCK + n]
    minima[_M_A * BLOCK + n] = min(cos_a, smallest)
    smallest = minima[_M_B * BLOCK + n]
    minima[_LEG_B * BLOCK + n] = kf if cos_b < smallest else minima[_LEG_B * BLOCK + n]
    minima[_M_B * BLOCK + n] = min(cos_b, smallest)


# The leg and pair stages take their planes as separate views with constant row offsets inside:
# the compiler then needs only a few run-time overlap checks between views, and vectorises.
@_helper
def _leg_planes(
    model: NDArray[np.float64],
    rotation: NDArray[np.float64],
    leg: NDArray[np.float64],
    minima: NDArray[np.float64],
    count: int,
    k: int,
    px: float,
    py: float,
    pz: float,
) -> None:
    """Leg k over a block: vector, squared length, 1/ℓ², joint cosines; updates the running
    minima of the leg-length margin and of both cosines with their legs (first leg on ties)."""
    bx, by, bz = model[B + 3 * k], model[B + 3 * k + 1], model[B + 3 * k + 2]
    ox, oy, oz = px - model[A + 3 * k], py - model[A + 3 * k + 1], pz - model[A + 3 * k + 2]
    jax, jay, jaz = model[JA + 3 * k], model[JA + 3 * k + 1], model[JA + 3 * k + 2]
    jbx, jby, jbz = model[JB + 3 * k], model[JB + 3 * k + 1], model[JB + 3 * k + 2]
    lmin, lmax, kf = model[LMIN + k], model[LMAX + k], float(k)
    for n in range(count):
        r00, r01, r02 = rotation[n], rotation[BLOCK + n], rotation[2 * BLOCK + n]
        r10, r11, r12 = rotation[3 * BLOCK + n], rotation[4 * BLOCK + n], rotation[5 * BLOCK + n]
        r20, r21, r22 = rotation[6 * BLOCK + n], rotation[7 * BLOCK + n], rotation[8 * BLOCK + n]
        x = (r00 * bx + r01 * by + r02 * bz) + ox
        y = (r10 * bx + r11 * by + r12 * bz) + oy
        z = (r20 * bx + r21 * by + r22 * bz) + oz
        leg[_LX * BLOCK + n] = x
        leg[_LY * BLOCK + n] = y
        leg[_LZ * BLOCK + n] = z
        squared = x * x + y * y + z * z
        leg[_SQ * BLOCK + n] = squared
        length = math.sqrt(squared)
        inverse = 1.0 / length
        leg[_INV * BLOCK + n] = inverse * inverse
        value = min(length - lmin, lmax - length)
        # Running minimum and its leg, one select per statement (so that the loop vectorises).
        smallest = minima[_M_LEN * BLOCK + n]
        minima[_LEG_LEN * BLOCK + n] = kf if value < smallest else minima[_LEG_LEN * BLOCK + n]
        minima[_M_LEN * BLOCK + n] = min(value, smallest)
        cos_a = (jax * x + jay * y + jaz * z) * inverse
        cos_b = (
            (r00 * jbx + r01 * jby + r02 * jbz) * x
            + (r10 * jbx + r11 * jby + r12 * jbz) * y
            + (r20 * jbx + r21 * jby + r22 * jbz) * z
        ) * -inverse
        _store_cosines(leg, minima, n, kf, cos_a, cos_b)
        degenerate = 0.0 if squared > 1e-300 else 1.0
        minima[_FIX * BLOCK + n] = max(minima[_FIX * BLOCK + n], degenerate)


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


@_inline
def _keep_pair(
    minima: NDArray[np.float64], n: int, squared: float, irregular: float, pf: float
) -> None:
    """Pose n: a pair's squared distance into the running minimum and its pair (first pair on
    ties), ``irregular`` (parallel or point-like legs) into the flag of the exact path."""
    distance = max(squared, 0.0)
    smallest = minima[_BEST * BLOCK + n]
    minima[_PAIR * BLOCK + n] = pf if distance < smallest else minima[_PAIR * BLOCK + n]
    minima[_BEST * BLOCK + n] = min(distance, smallest)
    minima[_FIX * BLOCK + n] = max(minima[_FIX * BLOCK + n], irregular)


@_inline
def _pair_at(
    leg_i: NDArray[np.float64],
    leg_j: NDArray[np.float64],
    minima: NDArray[np.float64],
    n: int,
    rx: float,
    ry: float,
    rz: float,
    rr: float,
    pf: float,
) -> None:
    """Pose n of a pair plane: the squared segment distance of legs i and j (r = A_i − A_j,
    clamped at 0) into the running minimum and its pair (first pair on ties), parallel or
    point-like legs flagged.

    The minimum is kept squared and its square root taken once per pose, after the 15 pairs:
    sqrt is correctly rounded and non-decreasing, so the root of the smallest square is the
    smallest root, bit for bit (the distance each pair would give). The pair is the first with
    the smallest square; where two squares differ but round to the same root it is the closer
    pair, where a root per pair named the first of the two."""
    squared, regular = _pair_squared(
        rx,
        ry,
        rz,
        rr,
        leg_i[_LX * BLOCK + n],
        leg_i[_LY * BLOCK + n],
        leg_i[_LZ * BLOCK + n],
        leg_j[_LX * BLOCK + n],
        leg_j[_LY * BLOCK + n],
        leg_j[_LZ * BLOCK + n],
        leg_i[_SQ * BLOCK + n],
        leg_j[_SQ * BLOCK + n],
        leg_i[_INV * BLOCK + n],
        leg_j[_INV * BLOCK + n],
    )
    _keep_pair(minima, n, squared, regular, pf)


@_helper
def _pair_plane(
    model: NDArray[np.float64],
    leg_i: NDArray[np.float64],
    leg_j: NDArray[np.float64],
    minima: NDArray[np.float64],
    count: int,
    pair: int,
) -> None:
    """Segment distance of two legs (pair index ``pair``) over a block (Ericson's clamped
    closest points, as the reference); updates the running minimum and its pair (first pair on
    ties) and flags parallel or point-like legs for the exact path."""
    rx = model[RPAIR + 3 * pair]
    ry = model[RPAIR + 3 * pair + 1]
    rz = model[RPAIR + 3 * pair + 2]
    rr, pf = model[RR + pair], float(pair)
    for n in range(count):
        _pair_at(leg_i, leg_j, minima, n, rx, ry, rz, rr, pf)


@_helper
def _paired_plane(
    model: NDArray[np.float64],
    leg_i: NDArray[np.float64],
    leg_j: NDArray[np.float64],
    minima: NDArray[np.float64],
    count: int,
    pair: int,
) -> None:
    """:func:`_pair_plane` for two legs that share a joint: the distance of their free lengths
    (:func:`_free_squared`)."""
    rx = model[RPAIR + 3 * pair]
    ry = model[RPAIR + 3 * pair + 1]
    rz = model[RPAIR + 3 * pair + 2]
    pf = float(pair)
    for n in range(count):
        squared, irregular = _free_squared(
            model,
            pair,
            rx,
            ry,
            rz,
            leg_i[_LX * BLOCK + n],
            leg_i[_LY * BLOCK + n],
            leg_i[_LZ * BLOCK + n],
            leg_j[_LX * BLOCK + n],
            leg_j[_LY * BLOCK + n],
            leg_j[_LZ * BLOCK + n],
            leg_i[_SQ * BLOCK + n],
            leg_j[_SQ * BLOCK + n],
        )
        _keep_pair(minima, n, squared, irregular, pf)


@_helper
def _pair_plane_moving(
    leg_i: NDArray[np.float64],
    leg_j: NDArray[np.float64],
    base_i: NDArray[np.float64],
    base_j: NDArray[np.float64],
    minima: NDArray[np.float64],
    count: int,
    pair: int,
) -> None:
    """:func:`_pair_plane` for moving base joints: r = A_i − A_j per pose, from the base-end
    planes (x, y, z rows of each leg)."""
    pf = float(pair)
    for n in range(count):
        rx = base_i[n] - base_j[n]
        ry = base_i[BLOCK + n] - base_j[BLOCK + n]
        rz = base_i[2 * BLOCK + n] - base_j[2 * BLOCK + n]
        _pair_at(leg_i, leg_j, minima, n, rx, ry, rz, rx * rx + ry * ry + rz * rz, pf)


@_inline
def _moving_leg_at(
    leg: NDArray[np.float64],
    base: NDArray[np.float64],
    minima: NDArray[np.float64],
    moves: NDArray[np.float64],
    n: int,
    kf: float,
    platform: tuple[float, float, float],
    end: tuple[float, float, float],
    drive: tuple[float, float, float],
    axis: tuple[float, float, float],
    platform_axis: tuple[float, float, float],
    q: float,
    ik: float,
    limits: tuple[float, float, float],
) -> None:
    """Pose n of leg k's planes for moving base joints (pus, rus; ``kf`` = k): the base-side end
    ``end`` into ``base``, the leg vector platform − end, squared length, 1/ℓ² and joint cosines
    into ``leg`` (``axis`` the base joint axis, ``platform_axis`` R·jB_k), the running minima of
    both cosines, of ``actuator`` (q against ``limits`` = (q_min, q_max, τ_min)), ``ik`` and
    ``transmission`` (|n·drive| − τ_min) with their legs (first leg on ties); a leg without a
    solution flags the pose (its margins are NaN: :func:`_unsolved_outputs`), a NaN coordinate
    of a solved leg or a zero-length leg the exact path. One select per statement, no branch,
    so that the loops over poses vectorise."""
    x, y, z = platform[0] - end[0], platform[1] - end[1], platform[2] - end[2]
    base[n] = end[0]
    base[BLOCK + n] = end[1]
    base[2 * BLOCK + n] = end[2]
    leg[_LX * BLOCK + n] = x
    leg[_LY * BLOCK + n] = y
    leg[_LZ * BLOCK + n] = z
    squared = x * x + y * y + z * z
    leg[_SQ * BLOCK + n] = squared
    inverse = 1.0 / math.sqrt(squared)
    leg[_INV * BLOCK + n] = inverse * inverse
    cos_a = (axis[0] * x + axis[1] * y + axis[2] * z) * inverse
    cos_b = (platform_axis[0] * x + platform_axis[1] * y + platform_axis[2] * z) * -inverse
    _store_cosines(leg, minima, n, kf, cos_a, cos_b)
    value = min(q - limits[0], limits[1] - q)
    smallest = moves[_M_ACT * BLOCK + n]
    moves[_LEG_ACT * BLOCK + n] = kf if value < smallest else moves[_LEG_ACT * BLOCK + n]
    moves[_M_ACT * BLOCK + n] = min(value, smallest)
    smallest = moves[_M_IK * BLOCK + n]
    moves[_LEG_IK * BLOCK + n] = kf if ik < smallest else moves[_LEG_IK * BLOCK + n]
    moves[_M_IK * BLOCK + n] = min(ik, smallest)
    value = abs(drive[0] * x + drive[1] * y + drive[2] * z) * inverse - limits[2]
    smallest = moves[_M_TAU * BLOCK + n]
    moves[_LEG_TAU * BLOCK + n] = kf if value < smallest else moves[_LEG_TAU * BLOCK + n]
    moves[_M_TAU * BLOCK + n] = min(value, smallest)
    # Unsolved (ik < 0 or NaN): the first such leg is kept (unsolved > the flag so far only
    # for the first one).
    unsolved = 0.0 if ik >= 0.0 else 1.0
    flagged = moves[_UNSOLVED * BLOCK + n]
    moves[_UNSOLVED_LEG * BLOCK + n] = (
        kf if unsolved > flagged else moves[_UNSOLVED_LEG * BLOCK + n]
    )
    moves[_UNSOLVED * BLOCK + n] = max(flagged, unsolved)
    usable = ((q == q) | (unsolved != 0.0)) & (squared > 1e-300)
    minima[_FIX * BLOCK + n] = max(minima[_FIX * BLOCK + n], 0.0 if usable else 1.0)


def _moving_leg_planes(rus: bool) -> Callable[..., None]:
    """The block stage of one leg for moving base joints, compiled for one architecture
    (``rus`` is a constant of each compiled function, so each loop keeps one branch, and
    vectorises)."""

    def leg_planes(
        model: NDArray[np.float64],
        rotation: NDArray[np.float64],
        leg: NDArray[np.float64],
        base: NDArray[np.float64],
        minima: NDArray[np.float64],
        moves: NDArray[np.float64],
        count: int,
        k: int,
        px: float,
        py: float,
        pz: float,
    ) -> None:
        """Leg k of a pus or rus model over a block: the inverse kinematics of
        :func:`_pose_moving` (:func:`_slide_leg`: the rail is the slide's drive direction, the
        base joint axis translates with the slide; or :func:`_crank_leg` and :func:`_crank_end`:
        the crank end, its unit velocity, the joint axis turned with the crank), then
        :func:`_moving_leg_at`."""
        bx, by, bz = model[B + 3 * k], model[B + 3 * k + 1], model[B + 3 * k + 2]
        ox, oy, oz = model[A + 3 * k], model[A + 3 * k + 1], model[A + 3 * k + 2]
        ux, uy, uz = model[RAIL + 3 * k], model[RAIL + 3 * k + 1], model[RAIL + 3 * k + 2]
        j0x, j0y, j0z = model[JA + 3 * k], model[JA + 3 * k + 1], model[JA + 3 * k + 2]
        jbx, jby, jbz = model[JB + 3 * k], model[JB + 3 * k + 1], model[JB + 3 * k + 2]
        length, branch = model[LEG + k], model[BRANCH + k]
        e, f, w, sizes, centre = _crank(model, k)
        axis_cross, axis_along = _vector(model, AXIS_CROSS, k), _vector(model, AXIS_ALONG, k)
        limits = (model[QMIN + k], model[QMAX + k], model[TAU_MIN])
        kf = float(k)
        for n in range(count):
            r00, r01, r02 = rotation[n], rotation[BLOCK + n], rotation[2 * BLOCK + n]
            r10, r11, r12 = (
                rotation[3 * BLOCK + n],
                rotation[4 * BLOCK + n],
                rotation[5 * BLOCK + n],
            )
            r20, r21, r22 = (
                rotation[6 * BLOCK + n],
                rotation[7 * BLOCK + n],
                rotation[8 * BLOCK + n],
            )
            platform_x = (r00 * bx + r01 * by + r02 * bz) + px
            platform_y = (r10 * bx + r11 * by + r12 * bz) + py
            platform_z = (r20 * bx + r21 * by + r22 * bz) + pz
            dx, dy, dz = platform_x - ox, platform_y - oy, platform_z - oz
            if rus:
                ik, q, cos_q, sin_q = _crank_leg(dx, dy, dz, e, f, w, sizes, centre)
                end_x, end_y, end_z, tx, ty, tz, jx, jy, jz = _crank_end(
                    (ox, oy, oz),
                    e,
                    f,
                    (j0x, j0y, j0z),
                    axis_cross,
                    axis_along,
                    sizes[0],
                    cos_q,
                    sin_q,
                )
            else:
                ik, q = _slide_leg(dx, dy, dz, ux, uy, uz, length, branch)
                end_x, end_y, end_z = ox + q * ux, oy + q * uy, oz + q * uz
                tx, ty, tz, jx, jy, jz = ux, uy, uz, j0x, j0y, j0z
            _moving_leg_at(
                leg,
                base,
                minima,
                moves,
                n,
                kf,
                (platform_x, platform_y, platform_z),
                (end_x, end_y, end_z),
                (tx, ty, tz),
                (jx, jy, jz),
                (
                    r00 * jbx + r01 * jby + r02 * jbz,
                    r10 * jbx + r11 * jby + r12 * jbz,
                    r20 * jbx + r21 * jby + r22 * jbz,
                ),
                q,
                ik,
                limits,
            )

    leg_planes.__name__ = leg_planes.__qualname__ = "_leg_planes_rus" if rus else "_leg_planes_pus"
    return _helper(leg_planes)


_leg_planes_pus = _moving_leg_planes(rus=False)
_leg_planes_rus = _moving_leg_planes(rus=True)


@_helper
def _unsolved_outputs(
    work: NDArray[np.float64],
    moves: NDArray[np.float64],
    n: int,
    singular: bool,
    interference: bool,
) -> None:
    """Outputs of pose n of a pus/rus block where some leg has no inverse-kinematics solution,
    as :func:`_pose_moving` gives them: ``ik`` and its leg; NaN, with the first unsolved leg,
    for every margin that needs the legs' coordinates; ``leg_length`` +inf; ``singularity`` and
    ``leg_interference`` NaN when evaluated (+inf otherwise), leg and pair 0."""
    leg = moves[_UNSOLVED_LEG * BLOCK + n]
    for c in range(N_CONSTRAINTS):
        work[c * BLOCK + n] = np.nan
        work[(OUT_LEG + c) * BLOCK + n] = leg
    work[LEG_LENGTH * BLOCK + n] = np.inf
    work[(OUT_LEG + LEG_LENGTH) * BLOCK + n] = 0.0
    work[IK * BLOCK + n] = moves[_M_IK * BLOCK + n]
    work[(OUT_LEG + IK) * BLOCK + n] = moves[_LEG_IK * BLOCK + n]
    work[SINGULARITY * BLOCK + n] = np.nan if singular else np.inf
    work[(OUT_LEG + SINGULARITY) * BLOCK + n] = 0.0
    work[LEG_INTERFERENCE * BLOCK + n] = np.nan if interference else np.inf
    work[(OUT_LEG + LEG_INTERFERENCE) * BLOCK + n] = 0.0
    work[OUT_PAIR * BLOCK + n] = 0.0
    work[(OUT_PAIR + 1) * BLOCK + n] = 0.0
    work[(OUT_LEG + COLLISION) * BLOCK + n] = -1.0  # no pair: a leg body is nowhere


@_helper
def _check_block(
    model: NDArray[np.float64],
    angles: NDArray[np.float64],
    position: NDArray[np.float64],
    first: int,
    count: int,
    work: NDArray[np.float64],
    scratch: NDArray[np.float64],
    out: NDArray[np.float64],
    r: NDArray[np.float64],
    moving: int | None,
    cranks: int | None,
    collide: Collide,
    singular: int | None,
) -> None:
    """Margins of poses angles[first : first + count] (count ≤ BLOCK) into ``work`` planes.

    Every stage is a loop over the poses of the block without branches, which the compiler
    vectorises; poses that need care (a zero-length leg, parallel or point-like legs, huge
    angles) are flagged in the _FIX row and recomputed one by one by :func:`_pose` (with libm's
    sin and cos for huge angles). Leaves in ``work`` (as floats): the margins in rows
    0..N_CONSTRAINTS − 1, their legs in rows OUT_LEG + c, the closest pair in OUT_PAIR and
    OUT_PAIR + 1; only the rows in use (``model[ROWS_USED]``) are written for poses the
    fast path handles, the others are +inf for every pose and left to the reader.
    """
    px, py, pz = position[0], position[1], position[2]
    for n in range(count):  # strided reads: a loop of its own (it does not vectorise)
        work[_PHI * BLOCK + n] = angles[first + n, 0]
        work[_THETA * BLOCK + n] = angles[first + n, 1]
        work[_PSI * BLOCK + n] = angles[first + n, 2]
    for n in range(count):
        phi = work[_PHI * BLOCK + n]
        theta = work[_THETA * BLOCK + n]
        gamma = work[_PSI * BLOCK + n] - phi
        work[_SA * BLOCK + n], work[_CA * BLOCK + n] = _sincos(phi)
        work[_SB * BLOCK + n], work[_CB * BLOCK + n] = _sincos(theta)
        work[_SG * BLOCK + n], work[_CG * BLOCK + n] = _sincos(gamma)
        largest = max(abs(phi), abs(theta), abs(work[_PSI * BLOCK + n]), abs(gamma))
        work[(_MIN + _FIX) * BLOCK + n] = 1.0 if largest > FAST_TRIG_LIMIT else 0.0
        work[(_MIN + _M_LEN) * BLOCK + n] = np.inf
        work[(_MIN + _M_A) * BLOCK + n] = np.inf
        work[(_MIN + _M_B) * BLOCK + n] = np.inf
        work[(_MIN + _LEG_LEN) * BLOCK + n] = 0.0
        work[(_MIN + _LEG_A) * BLOCK + n] = 0.0
        work[(_MIN + _LEG_B) * BLOCK + n] = 0.0
        work[(_MIN + _BEST) * BLOCK + n] = np.inf
        work[(_MIN + _PAIR) * BLOCK + n] = 0.0
    for n in range(count):
        ca, sa = work[_CA * BLOCK + n], work[_SA * BLOCK + n]
        cb, sb = work[_CB * BLOCK + n], work[_SB * BLOCK + n]
        cg, sg = work[_CG * BLOCK + n], work[_SG * BLOCK + n]
        work[_R * BLOCK + n] = ca * cb * cg - sa * sg
        work[(_R + 1) * BLOCK + n] = -ca * cb * sg - sa * cg
        work[(_R + 2) * BLOCK + n] = ca * sb
        work[(_R + 3) * BLOCK + n] = sa * cb * cg + ca * sg
        work[(_R + 4) * BLOCK + n] = -sa * cb * sg + ca * cg
        work[(_R + 5) * BLOCK + n] = sa * sb
        work[(_R + 6) * BLOCK + n] = -sb * cg
        work[(_R + 7) * BLOCK + n] = sb * sg
        work[(_R + 8) * BLOCK + n] = cb
    rotation = _planes(work, _R, 9)
    minima = _planes(work, _MIN, 9)
    moves = _planes(work, _MOVE, 8)
    if moving is not None:
        for n in range(count):
            for row in (_M_ACT, _M_IK, _M_TAU, _UNSOLVED):
                moves[row * BLOCK + n] = 0.0 if row == _UNSOLVED else np.inf
                moves[(row + 1) * BLOCK + n] = 0.0
    for k in range(6):
        if moving is not None:
            leg = _planes(work, _LEGS + 7 * k, 7)
            base = _planes(work, _BASE + 3 * k, 3)
            if cranks is not None:
                _leg_planes_rus(model, rotation, leg, base, minima, moves, count, k, px, py, pz)
            else:
                _leg_planes_pus(model, rotation, leg, base, minima, moves, count, k, px, py, pz)
        else:
            _leg_planes(
                model, rotation, _planes(work, _LEGS + 7 * k, 7), minima, count, k, px, py, pz
            )
    interference = model[INTERFERENCE] != 0.0
    if interference:
        pair = 0
        for i in range(5):  # pairs in index order: the first pair wins ties, as the reference
            for j in range(i + 1, 6):
                leg_i = _planes(work, _LEGS + 7 * i, 7)
                leg_j = _planes(work, _LEGS + 7 * j, 7)
                if moving is not None:
                    _pair_plane_moving(
                        leg_i,
                        leg_j,
                        _planes(work, _BASE + 3 * i, 3),
                        _planes(work, _BASE + 3 * j, 3),
                        minima,
                        count,
                        pair,
                    )
                elif model[SHARED_BASE + pair] + model[SHARED_PLATFORM + pair] != 0.0:
                    _paired_plane(model, leg_i, leg_j, minima, count, pair)
                else:
                    _pair_plane(model, leg_i, leg_j, minima, count, pair)
                pair += 1
    # The singularity and collision stages exist in the compiled code only where their switch is
    # on; the model says whether they run (search_rays checks a copy with its scene off).
    singular_on = False
    if singular is not None and model[SINGULARITY_ON] != 0.0:
        singular_on = True
        _block_singularity(model, work, count, np.empty(ROWS_SCRATCH), moving)
    collide_on = False
    if collide is not None and model[COLLISION_ON] != 0.0:
        collide_on = True
        _block_collision(model, work, count, px, py, pz, scratch, r, moving, collide)
    # Per pose: the joint-angle margins (arccos), the rare poses that need care, the outputs.
    alpha_equal = model[ALPHA_EQUAL] != 0.0
    beta_equal = model[BETA_EQUAL] != 0.0
    # Rows from ROWS_USED on are +inf for every pose of the model and nobody reads them from
    # `work` (the batch check and the searches read the rows in use): the 6-UPS model without
    # a singularity margin or a scene writes its four rows only.
    rest = int(model[ROWS_USED]) > SINGULARITY
    for n in range(count):
        if work[(_MIN + _FIX) * BLOCK + n] != 0.0:
            _tt_matrix(angles[first + n, 0], angles[first + n, 1], angles[first + n, 2], r)
            _pose(model, r, px, py, pz, scratch, out, True, moving, cranks, collide, singular)
            for slot in range(OUT_SHORTEST):
                work[(slot) * BLOCK + n] = out[slot]
            continue
        if moving is not None and moves[_UNSOLVED * BLOCK + n] != 0.0:
            _unsolved_outputs(work, moves, n, singular_on, interference)
            continue
        if moving is not None:
            work[LEG_LENGTH * BLOCK + n] = np.inf
            work[(OUT_LEG + LEG_LENGTH) * BLOCK + n] = 0.0
        else:
            work[LEG_LENGTH * BLOCK + n] = work[(_MIN + _M_LEN) * BLOCK + n]
            work[(OUT_LEG + LEG_LENGTH) * BLOCK + n] = work[(_MIN + _LEG_LEN) * BLOCK + n]
        if alpha_equal:
            work[BASE_JOINT * BLOCK + n] = model[ALPHA] - math.acos(
                min(max(work[(_MIN + _M_A) * BLOCK + n], -1.0), 1.0)
            )
            work[(OUT_LEG + BASE_JOINT) * BLOCK + n] = work[(_MIN + _LEG_A) * BLOCK + n]
        else:
            work[BASE_JOINT * BLOCK + n], work[(OUT_LEG + BASE_JOINT) * BLOCK + n] = _per_leg_angle(
                model, ALPHA, work, _COS_A, n
            )
        if beta_equal:
            work[PLATFORM_JOINT * BLOCK + n] = model[BETA] - math.acos(
                min(max(work[(_MIN + _M_B) * BLOCK + n], -1.0), 1.0)
            )
            work[(OUT_LEG + PLATFORM_JOINT) * BLOCK + n] = work[(_MIN + _LEG_B) * BLOCK + n]
        else:
            work[PLATFORM_JOINT * BLOCK + n], work[(OUT_LEG + PLATFORM_JOINT) * BLOCK + n] = (
                _per_leg_angle(model, BETA, work, _COS_B, n)
            )
        if interference:
            pair = int(work[(_MIN + _PAIR) * BLOCK + n])
            distance = math.sqrt(work[(_MIN + _BEST) * BLOCK + n])  # kept squared (_pair_at)
            work[LEG_INTERFERENCE * BLOCK + n] = distance - model[DIAMETER]
            work[(OUT_LEG + LEG_INTERFERENCE) * BLOCK + n] = PAIR_I[pair]
            work[OUT_PAIR * BLOCK + n] = PAIR_I[pair]
            work[(OUT_PAIR + 1) * BLOCK + n] = PAIR_J[pair]
        else:
            work[LEG_INTERFERENCE * BLOCK + n] = np.inf
            work[(OUT_LEG + LEG_INTERFERENCE) * BLOCK + n] = 0.0
            work[OUT_PAIR * BLOCK + n] = 0.0
            work[(OUT_PAIR + 1) * BLOCK + n] = 0.0
        if not rest:
            continue
        work[SINGULARITY * BLOCK + n] = work[_SIGMA * BLOCK + n] if singular_on else np.inf
        work[(OUT_LEG + SINGULARITY) * BLOCK + n] = 0.0
        work[COLLISION * BLOCK + n] = work[_COLLIDE * BLOCK + n] if collide_on else np.inf
        work[(OUT_LEG + COLLISION) * BLOCK + n] = (
            work[(_COLLIDE + 1) * BLOCK + n] if collide_on else -1.0
        )
        # Rows of the moving-base architectures (+inf where they do not apply).
        for row, slot in ((ACTUATOR, _M_ACT), (IK, _M_IK), (TRANSMISSION, _M_TAU)):
            if moving is not None:
                work[row * BLOCK + n] = moves[slot * BLOCK + n]
                work[(OUT_LEG + row) * BLOCK + n] = moves[(slot + 1) * BLOCK + n]
            else:
                work[row * BLOCK + n] = np.inf
                work[(OUT_LEG + row) * BLOCK + n] = 0.0


@_helper
def _per_leg_angle(
    model: NDArray[np.float64], limits: int, work: NDArray[np.float64], row: int, n: int
) -> tuple[float, float]:
    """min_i (limit_i − arccos(cos_i)) and its leg, for per-leg joint limits (``row`` is the
    cosine row within each leg's planes)."""
    best = np.inf
    leg = 0.0
    for k in range(6):
        cosine = work[(_LEGS + 7 * k + row) * BLOCK + n]
        value = model[limits + k] - math.acos(min(max(cosine, -1.0), 1.0))
        if value < best:
            best = value
            leg = float(k)
    return best, leg


# ------------------------------------------------------------------------------ batches
class MarginKernels(NamedTuple):
    """The compiled entry points of one kernel variant (:func:`margin_entry_points`)."""

    check_angles: Callable[..., int]
    check_one: Callable[..., tuple[Any, ...]]
    margins_rotations: Callable[..., None]


def margin_entry_points(
    moving: int | None,
    cranks: int | None,
    singular: int | None,
    signatures: dict[str, tuple[object, ...]] | None = None,
) -> MarginKernels:
    """The margin entry points compiled for one set of switches (:mod:`.jit`).

    Each is a closure whose switches are constants of its compiled code (numba keys its cache
    on them), so a 6-UPS model without a scene or a singularity margin compiles none of the
    moving-base, collision or singularity stages. Called once per variant by
    :func:`hexapod_workspace.core.kernels.for_model`. Each takes the ``collide`` switch as its
    last argument: None, or the first-class collision function (then ``signatures`` gives each
    entry point's argument types: numba types a ``FunctionType`` argument only from a
    signature).
    """

    decorate = _entry_points(signatures)

    @decorate("check_angles")
    def check_angles(
        model: NDArray[np.float64],
        angles: NDArray[np.float64],
        position: NDArray[np.float64],
        start: int,
        stop: int,
        margins: NDArray[np.float64],
        ints: NDArray[np.int64],
        pairs: NDArray[np.int64],
        reachable: NDArray[np.bool_],
        collide: Collide,
    ) -> int:
        """Check poses ``angles[start:stop]`` (N, 3) of T&T angles (rad) at ``position`` (3,), m.

        Writes, for each pose n in [start, stop): ``margins[:, n]`` (C, N) with C the rows in use
        (``model[ROWS_USED]``: the rows after the last one that applies to the model are +inf for
        every pose and not written; the arrays may have more rows);
        ``ints[:C, n]`` (C + 2, N), the 1-based leg with the smallest margin of each constraint,
        ``ints[C, n]`` the constraint with the smallest relative margin and ``ints[C + 1, n]`` its
        leg; ``pairs[n]`` (N, 2), the
        1-based closest pair; ``reachable[n]``. Legs and pairs of ``leg_interference`` are 0 when
        the check is disabled. Releases the GIL (threads split large batches).

        Returns
        -------
        int
            −1 when every input is finite (and the outputs are written); otherwise nothing is
            written and it is the first pose in [start, stop) with a non-finite angle, or −2 when
            the angles are finite and the position is not.
        """
        for n in range(start, stop):
            if not (
                math.isfinite(angles[n, 0])
                and math.isfinite(angles[n, 1])
                and math.isfinite(angles[n, 2])
            ):
                return n
        for k in range(3):
            if not math.isfinite(position[k]):
                return -2
        scratch = np.empty((SCRATCH_ROWS, 6))
        out = np.empty(OUT_SIZE)
        r = np.empty(9)
        work = np.empty(_BLOCK_ROWS * BLOCK)
        enabled = 1 if model[INTERFERENCE] != 0.0 else 0
        used = int(model[ROWS_USED])
        for first in range(start, stop, BLOCK):
            count = min(BLOCK, stop - first)
            _check_block(
                model,
                angles,
                position,
                first,
                count,
                work,
                scratch,
                out,
                r,
                moving,
                cranks,
                collide,
                singular,
            )
            for m in range(count):
                n = first + m
                # Only the rows in use: the others are +inf (never limiting, never violated).
                feasible = True
                for c in range(used):
                    out[c] = work[c * BLOCK + m]
                    margins[c, n] = out[c]
                    ints[c, n] = int(work[(OUT_LEG + c) * BLOCK + m]) + 1
                    feasible = feasible and out[c] >= 0.0  # NaN counts as violated
                ints[LEG_INTERFERENCE, n] *= enabled
                ints[SINGULARITY, n] = 0  # a property of all legs together: no limiting leg
                pairs[n, 0] = (int(work[OUT_PAIR * BLOCK + m]) + 1) * enabled
                pairs[n, 1] = (int(work[(OUT_PAIR + 1) * BLOCK + m]) + 1) * enabled
                worst = _limiting_constraint(model, out)
                ints[used, n] = worst
                ints[used + 1, n] = ints[worst, n] if worst < used else 0
                reachable[n] = feasible
        return -1

    @decorate("check_one")
    def check_one(
        model: NDArray[np.float64],
        phi: float,
        theta: float,
        psi: float,
        px: float,
        py: float,
        pz: float,
        collide: Collide,
    ) -> tuple[bool, tuple[float, ...], tuple[int, ...], tuple[int, int], int, int]:
        """One pose (φ, θ, ψ) rad at (px, py, pz) m, finite; the fast path of check_pose.

        Returns the fields of ``constraints.PoseCheck`` as one tuple of plain numbers (numba boxes
        it in C: cheaper than an output array read back and converted in Python): reachable,
        margins (N_CONSTRAINTS), 1-based limiting legs (N_CONSTRAINTS; the interference leg 0 when
        the check is disabled), closest pair (2, 1-based; 0 when disabled), the limiting constraint
        and its leg.
        """
        scratch = np.empty((SCRATCH_ROWS, 6))
        out = np.empty(OUT_SIZE)
        r = np.empty(9)
        _tt_matrix(phi, theta, psi, r)
        _pose(model, r, px, py, pz, scratch, out, True, moving, cranks, collide, singular)
        enabled = 1 if model[INTERFERENCE] != 0.0 else 0
        legs = np.empty(N_CONSTRAINTS, dtype=np.int64)
        for c in range(N_CONSTRAINTS):
            legs[c] = int(out[OUT_LEG + c]) + 1
        legs[LEG_INTERFERENCE] *= enabled
        legs[SINGULARITY] = 0
        worst = _limiting_constraint(model, out)
        return (
            _feasible(out, N_CONSTRAINTS),
            to_fixed_tuple(out[:N_CONSTRAINTS], N_CONSTRAINTS),
            to_fixed_tuple(legs, N_CONSTRAINTS),
            ((int(out[OUT_PAIR]) + 1) * enabled, (int(out[OUT_PAIR + 1]) + 1) * enabled),
            worst,
            legs[worst],
        )

    @decorate("margins_rotations")
    def margins_rotations(
        model: NDArray[np.float64],
        rotations: NDArray[np.float64],
        positions: NDArray[np.float64],
        interference: bool,
        margins: NDArray[np.float64],
        legs: NDArray[np.int64],
        pairs: NDArray[np.int64],
        collide: Collide,
    ) -> None:
        """Margins of N poses given as rotation matrices (N, 3, 3) at positions (M, 3), M ∈ {1, N}.

        Writes ``margins`` (C, N), ``legs`` (C, N) (C = N_CONSTRAINTS) and ``pairs`` (N, 2) as
        :func:`check_angles`.
        """
        scratch = np.empty((SCRATCH_ROWS, 6))
        out = np.empty(OUT_SIZE)
        r = np.empty(9)
        shared = positions.shape[0] == 1
        used = int(model[ROWS_USED])
        for n in range(rotations.shape[0]):
            for i in range(3):
                for j in range(3):
                    r[3 * i + j] = rotations[n, i, j]
            p = 0 if shared else n
            _pose(
                model,
                r,
                positions[p, 0],
                positions[p, 1],
                positions[p, 2],
                scratch,
                out,
                interference,
                moving,
                cranks,
                collide,
                singular,
            )
            for c in range(used):
                margins[c, n] = out[c]
                legs[c, n] = int(out[OUT_LEG + c])
            if n == 0:
                # The rows past the last one that applies are the same for every pose (+inf and a
                # fixed leg): written whole, once, instead of pose by pose.
                for c in range(used, N_CONSTRAINTS):
                    margins[c, :] = out[c]
                    legs[c, :] = int(out[OUT_LEG + c])
            pairs[n, 0] = int(out[OUT_PAIR])
            pairs[n, 1] = int(out[OUT_PAIR + 1])

    return MarginKernels(check_angles, check_one, margins_rotations)
