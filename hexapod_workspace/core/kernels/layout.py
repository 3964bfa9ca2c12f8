"""Model layout of the compiled kernels: a manipulator packed into one float64 vector.

The kernels take a handful of arrays, which keeps numba's dispatch cheap (a few microseconds per
call): :func:`model_vector` packs the model once per manipulator at the offsets below. A model
with a collision scene has its scene appended after ``MODEL_SIZE``
(:func:`hexapod_workspace.core.kernels.scene_layout.pack_scene`; ``COLLISION_ON`` says so).
"""

from __future__ import annotations

import weakref
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..constraints.table import CONSTRAINTS, N_CONSTRAINTS, applicable, scales
from ..model.architectures import CODES
from .scene_layout import pack_scene

if TYPE_CHECKING:
    from ..model.manipulator import Manipulator

__all__ = ["MODEL_SIZE", "PAIR_I", "PAIR_J", "ROWS_USED", "model_vector"]

# ------------------------------------------------------------------------------ model layout
# Offsets into the model vector. Per-leg 3-vectors are stored leg-major (x, y, z of leg 0, ...).
A = 0  # base joints a_i, base frame, m (18)
B = 18  # platform joints b_i, mobile frame, m (18)
JA = 36  # base joint axes jA_i, base frame (18)
JB = 54  # platform joint axes jB_i, mobile frame (18)
LMIN = 72  # leg length minima, m (6)
LMAX = 78  # leg length maxima, m (6)
ALPHA = 84  # base joint maximum angles, rad (6)
BETA = 90  # platform joint maximum angles, rad (6)
RPAIR = 96  # A_i − A_j for the 15 pairs i < j, m (45)
RR = 141  # |A_i − A_j|² (15)
DIAMETER = 156  # D, m
INTERFERENCE = 157  # 1.0 when the interference check is on (D > 0)
ALPHA_EQUAL = 158  # 1.0 when every base joint has the same maximum angle
BETA_EQUAL = 159  # 1.0 when every platform joint has the same maximum angle
SCALE = 160  # natural scale of each margin (N_CONSTRAINTS): see constraint_table.scales
RHO = SCALE + N_CONSTRAINTS  # max |b_i|, m (Lipschitz constants of the search)
LENGTH_FLOOR = RHO + 1  # min ℓmin_i, m
ESTIMATE_FLOOR = RHO + 2  # max(min ℓmin_i, 1e-3), m (fixed Lipschitz constants of the estimate)
ORDER = RHO + 3  # the 15 pair indices, closest pair at the home pose first (as floats)
# Rates of each margin along the rays of the searches (N_CONSTRAINTS each), from the constraint
# table's |dm/ds| ≤ speed·V + turn·V/ℓ_f + spin·Ω with V = ρ and Ω = 1:
# rate = RAY_CONSTANT + RAY_TURN / ℓ_f (the second term only where RAY_TURN ≠ 0).
RAY_CONSTANT = ORDER + 15  # speed·ρ + spin
RAY_TURN = RAY_CONSTANT + N_CONSTRAINTS  # turn·ρ, m
ESTIMATE_RATE = RAY_TURN + N_CONSTRAINTS  # the rate with ℓ_f = ESTIMATE_FLOOR
SINGULARITY_MIN = ESTIMATE_RATE + N_CONSTRAINTS  # σ_lim of the singularity margin
SINGULARITY_ON = SINGULARITY_MIN + 1  # 1.0 when the singularity margin is evaluated
# Leg architecture (core.architectures): 0 ups, 1 pus, 2 rus, and its parameters.
ARCH = SINGULARITY_ON + 1
RAIL = ARCH + 1  # rail directions u_i (pus) or crank axes w_i (rus), unit (18)
ZERO = RAIL + 18  # crank zero directions e_i (rus), unit (18)
CROSS = ZERO + 18  # f_i = w_i × e_i (rus), unit (18)
AXIS_CROSS = CROSS + 18  # w_i × jA_i (rus: turning the base joint axes with the crank) (18)
AXIS_ALONG = AXIS_CROSS + 18  # (w_i·jA_i)·w_i (rus) (18)
LEG = AXIS_ALONG + 18  # fixed leg lengths L_i, m (6)
BRANCH = LEG + 6  # assembly branch ±1 (6)
CRANK = BRANCH + 6  # crank lengths r_i, m (rus) (6)
QMIN = CRANK + 6  # actuator_min, m or rad (6)
QMAX = QMIN + 6  # actuator_max (6)
QCENTRE = QMAX + 6  # centre of the crank range (rus), rad (6)
QCOS = QCENTRE + 6  # cos of that centre (rus) (6)
QSIN = QCOS + 6  # sin of that centre (rus) (6)
TAU_MIN = QSIN + 6  # limits.transmission_min
# Rates along the rays for pus/rus (constraint_table): with τ_f a lower bound of |τ_i|,
# rate = RAY_CONSTANT + RAY_TURN·(1 + 1/τ_f)/LENGTH_FLOOR + RAY_DRIVE/τ_f.
RAY_DRIVE = TAU_MIN + 1  # (actuate·g + crank/r_min + ends)·ρ, g = 1 (pus) or 1/r_min (rus)
# Rows of the table the batch check writes: 1 + the last row that applies to the model (the
# rows after it are +inf for every pose; check() neither allocates nor fills them).
ROWS_USED = RAY_DRIVE + N_CONSTRAINTS
COLLISION_ON = ROWS_USED + 1  # 1.0 when a collision block follows MODEL_SIZE
# Paired joints (ups): per pair, 1.0 where the two legs share their base (platform) joint; the
# interference of such a pair is measured between the legs' free lengths, PAIRED_LENGTH (c, m)
# left out at each shared end (constraint_table, leg_interference).
SHARED_BASE = COLLISION_ON + 1  # (15)
SHARED_PLATFORM = SHARED_BASE + 15  # (15)
PAIRED_LENGTH = SHARED_PLATFORM + 15  # c, m
MODEL_SIZE = PAIRED_LENGTH + 1

#: Leg pairs (i < j) in the order of numpy.triu_indices(6, 1).
PAIR_I = np.array([i for i in range(6) for j in range(i + 1, 6)], dtype=np.int64)
PAIR_J = np.array([j for i in range(6) for j in range(i + 1, 6)], dtype=np.int64)


#: Packed models by ``id`` of their manipulator (see :func:`model_vector`).
_MODELS: dict[int, NDArray[np.float64]] = {}
#: The same with the singularity margin evaluated as a report (see :func:`model_vector`).
_REPORT_MODELS: dict[int, NDArray[np.float64]] = {}


def model_vector(manipulator: Manipulator, report_singularity: bool = False) -> NDArray[np.float64]:
    """The packed model of a manipulator (cached per manipulator object, for its lifetime).

    Parameters
    ----------
    manipulator : Manipulator
    report_singularity : bool
        Evaluate the singularity margin even when ``manipulator.singularity_min`` is 0 (a
        report: σ_min itself, never negative). With σ_lim > 0 it is always evaluated.

    Returns
    -------
    ndarray, shape (MODEL_SIZE + K,)
        Read-only; layout given by the offsets of this module, then the collision block (K = 0
        without a scene).
    """
    key = id(manipulator)  # one dictionary per kind: the per-call lookup stays an int's
    models = _REPORT_MODELS if report_singularity else _MODELS
    cached = models.get(key)
    if cached is not None:
        return cached
    model: NDArray[np.float64] = np.zeros(MODEL_SIZE)
    model[A : A + 18] = manipulator.base_joints.ravel()
    model[B : B + 18] = manipulator.platform_joints.ravel()
    model[JA : JA + 18] = manipulator.base_joint_axes.ravel()
    model[JB : JB + 18] = manipulator.platform_joint_axes.ravel()
    model[LMIN : LMIN + 6] = manipulator.leg_length_min
    model[LMAX : LMAX + 6] = manipulator.leg_length_max
    model[ALPHA : ALPHA + 6] = manipulator.base_joint_max_angle
    model[BETA : BETA + 6] = manipulator.platform_joint_max_angle
    r = manipulator.base_joints[PAIR_I] - manipulator.base_joints[PAIR_J]
    model[RPAIR : RPAIR + 45] = r.ravel()
    model[RR : RR + 15] = np.einsum("pk,pk->p", r, r)
    model[DIAMETER] = manipulator.leg_diameter
    model[INTERFERENCE] = 1.0 if manipulator.leg_diameter > 0.0 else 0.0
    model[SHARED_BASE : SHARED_BASE + 15] = manipulator.shared_base_pairs
    model[SHARED_PLATFORM : SHARED_PLATFORM + 15] = manipulator.shared_platform_pairs
    model[PAIRED_LENGTH] = manipulator.paired_joint_length
    alpha, beta = manipulator.base_joint_max_angle, manipulator.platform_joint_max_angle
    model[ALPHA_EQUAL] = 1.0 if np.all(alpha == alpha[0]) else 0.0
    model[BETA_EQUAL] = 1.0 if np.all(beta == beta[0]) else 0.0
    model[SCALE : SCALE + N_CONSTRAINTS] = scales(manipulator)
    model[RHO] = float(np.max(np.linalg.norm(manipulator.platform_joints, axis=1)))
    model[LENGTH_FLOOR] = float(np.min(manipulator.leg_length_min))
    model[ESTIMATE_FLOOR] = max(model[LENGTH_FLOOR], 1e-3)
    home = manipulator.home_position + manipulator.platform_joints
    home_distance = [
        _segment_distance_literal(
            manipulator.base_joints[i], home[i], manipulator.base_joints[j], home[j]
        )
        for i, j in zip(PAIR_I, PAIR_J, strict=True)
    ]
    model[ORDER : ORDER + 15] = np.argsort(home_distance, kind="stable")
    code = CODES[manipulator.architecture]
    _pack_architecture(model, manipulator, code)
    for c, row in enumerate(CONSTRAINTS):
        rho = model[RHO]
        speed, turn, spin, actuate, crank, ends = row.coefficients(manipulator)
        model[RAY_CONSTANT + c] = speed * rho + spin
        model[RAY_TURN + c] = turn * rho
        if code == 0:
            # 6-UPS: Q = E = V = ρ along a ray, no crank (constraint_table).
            if actuate + ends != 0.0:
                model[RAY_CONSTANT + c] += (actuate + ends) * rho
            model[ESTIMATE_RATE + c] = model[RAY_CONSTANT + c] + (
                model[RAY_TURN + c] / model[ESTIMATE_FLOOR] if turn != 0.0 else 0.0
            )
        else:
            # pus/rus: Q = g·V/τ_f, K = V/(r_min·τ_f) (rus), E = V/τ_f, N = V(1 + 1/τ_f)/L_min.
            cranks = manipulator.crank_lengths
            inverse_r = 1.0 / float(np.min(cranks)) if cranks is not None else 0.0
            gain = inverse_r if code == 2 else 1.0
            model[RAY_DRIVE + c] = (actuate * gain + crank * inverse_r + ends) * rho
            tau = model[TAU_MIN]
            model[ESTIMATE_RATE + c] = (
                model[RAY_CONSTANT + c]
                + model[RAY_TURN + c] * (1.0 + 1.0 / tau) / model[LENGTH_FLOOR]
                + model[RAY_DRIVE + c] / tau
            )
    model[ROWS_USED] = max(applicable(manipulator)) + 1
    model[SINGULARITY_MIN] = manipulator.singularity_min
    model[SINGULARITY_ON] = 1.0 if manipulator.singularity_min > 0.0 or report_singularity else 0.0
    scene = pack_scene(manipulator)
    if scene.size:
        model[COLLISION_ON] = 1.0
        model = np.concatenate([model, scene])
    model.setflags(write=False)
    # The manipulator is frozen: nothing is written into it. The entry lives as long as the
    # object (its id is not reused before the finalizer has removed the entry).
    if key not in models:
        models[key] = model
        weakref.finalize(manipulator, models.pop, key, None)
    return model


def _pack_architecture(model: NDArray[np.float64], manipulator: Manipulator, code: int) -> None:
    """The leg architecture's parameters into the model (zeros for 6-UPS)."""
    model[ARCH] = code
    if code == 0:
        return
    assert manipulator.leg_lengths is not None and manipulator.branch is not None
    assert manipulator.actuator_min is not None and manipulator.actuator_max is not None
    model[LEG : LEG + 6] = manipulator.leg_lengths
    model[BRANCH : BRANCH + 6] = manipulator.branch
    model[QMIN : QMIN + 6] = manipulator.actuator_min
    model[QMAX : QMAX + 6] = manipulator.actuator_max
    model[QCENTRE : QCENTRE + 6] = 0.5 * (manipulator.actuator_min + manipulator.actuator_max)
    model[QCOS : QCOS + 6] = np.cos(model[QCENTRE : QCENTRE + 6])
    model[QSIN : QSIN + 6] = np.sin(model[QCENTRE : QCENTRE + 6])
    model[TAU_MIN] = manipulator.transmission_min
    if code == 1:
        assert manipulator.rail_directions is not None
        model[RAIL : RAIL + 18] = manipulator.rail_directions.ravel()
        return
    w, e = manipulator.crank_axes, manipulator.crank_zero_directions
    assert w is not None and e is not None and manipulator.crank_lengths is not None
    axes = manipulator.base_joint_axes
    model[RAIL : RAIL + 18] = w.ravel()
    model[ZERO : ZERO + 18] = e.ravel()
    model[CROSS : CROSS + 18] = np.cross(w, e).ravel()
    model[AXIS_CROSS : AXIS_CROSS + 18] = np.cross(w, axes).ravel()
    model[AXIS_ALONG : AXIS_ALONG + 18] = (np.einsum("ij,ij->i", w, axes)[:, None] * w).ravel()
    model[CRANK : CRANK + 6] = manipulator.crank_lengths


def _segment_distance_literal(
    p0: NDArray[np.float64],
    p1: NDArray[np.float64],
    q0: NDArray[np.float64],
    q1: NDArray[np.float64],
) -> float:
    """Segment distance by dense sampling of both (only to order the pairs; any estimate
    works there)."""
    s = np.linspace(0.0, 1.0, 65)[:, None]
    first = p0 + s * (p1 - p0)
    second = q0 + s * (q1 - q0)
    return float(np.min(np.linalg.norm(first[:, None, :] - second[None, :, :], axis=2)))
