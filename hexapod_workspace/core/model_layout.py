"""Model layout of the compiled kernels: a manipulator packed into one float64 vector.

The kernels take a handful of arrays, which keeps numba's dispatch cheap (a few microseconds per
call): :func:`model_vector` packs the model once per manipulator at the offsets below. A model
with a collision scene has its scene appended after ``MODEL_SIZE``
(:func:`hexapod_workspace.core.collision_kernels.pack_scene`; ``COLLISION_ON`` says so).
"""

from __future__ import annotations

import weakref
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .collision_kernels import pack_scene
from .constraint_table import CONSTRAINTS, N_CONSTRAINTS, scales

if TYPE_CHECKING:
    from .manipulator import Manipulator

__all__ = ["MODEL_SIZE", "PAIR_I", "PAIR_J", "model_vector"]

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
COLLISION_ON = SINGULARITY_ON + 1  # 1.0 when a collision block follows MODEL_SIZE
MODEL_SIZE = COLLISION_ON + 1

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
    for c, row in enumerate(CONSTRAINTS):
        rho = model[RHO]
        speed, turn, spin = row.coefficients(manipulator)
        model[RAY_CONSTANT + c] = speed * rho + spin
        model[RAY_TURN + c] = turn * rho
        model[ESTIMATE_RATE + c] = model[RAY_CONSTANT + c] + (
            model[RAY_TURN + c] / model[ESTIMATE_FLOOR] if turn != 0.0 else 0.0
        )
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
