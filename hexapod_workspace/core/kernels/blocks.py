"""The margins of blocks of 128 poses (numba), stage by stage as planes of one flat array so
that every loop vectorises (:func:`_check_block`); poses that need care go through the scalar
kernel of :mod:`.pose`."""

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
    LMAX,
    LMIN,
    MODEL_SIZE,
    PAIR_I,
    PAIR_J,
    QMAX,
    QMIN,
    RAIL,
    RHO,
    ROWS_USED,
    RPAIR,
    RR,
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
from .pose import (
    _COLLISION_SCRATCH,
    OUT_LEG,
    OUT_PAIR,
    OUT_SHORTEST,
    _pose,
)
from .segments import (
    _free_squared,
    _pair_squared,
)
from .singularity import (
    ROWS_SCRATCH,
    _plucker_row,
    _smallest_singular_value,
)
from .trig import (
    FAST_TRIG_LIMIT,
    _sincos,
    _tt_matrix,
)

__all__ = ["BLOCK"]

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
