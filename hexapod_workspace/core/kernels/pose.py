"""The margins of one pose (numba): the scalar kernel :func:`_pose` (fixed base joints) and
:func:`_pose_moving` (slides and cranks), the collision and singularity stages, and the verdict
of a result vector. They follow ``test/reference.py`` operation by operation."""

from __future__ import annotations

import math
from collections.abc import Callable

from ..base.jit import Collide

# Imported first: it points numba's cache directory somewhere writable before numba loads.
from ..base.jit import helper as _helper
from ..base.jit import inline as _inline

# isort: split
import numpy as np
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
from .layout import (
    ALPHA,
    ALPHA_EQUAL,
    AXIS_ALONG,
    AXIS_CROSS,
    BETA,
    BETA_EQUAL,
    BRANCH,
    COLLISION_ON,
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
    QMAX,
    QMIN,
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
    A,
    B,
)
from .moving_base import (
    _crank,
    _crank_end,
    _crank_leg,
    _slide_leg,
    _vector,
)
from .scene_layout import SCRATCH_FLOATS
from .segments import (
    _clamp01,
    _free_squared,
)
from .singularity import (
    ROWS_SCRATCH,
    _plucker_row,
    _smallest_singular_value,
)

__all__ = ["OUT_GAP", "OUT_LEG", "OUT_PAIR", "OUT_SHORTEST", "OUT_SIZE", "SCRATCH_ROWS"]

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
