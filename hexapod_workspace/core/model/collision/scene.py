"""The collision scene of a hexapod cell: moving bodies, obstacles, the ``collision`` margin.

Bodies (SI, frames named; see :mod:`.distance` for the shapes and the signed distance)

* **Legs 1–6**: capsules of radius ``limits.leg_diameter / 2`` around the segments A_iB_i
  (base frame), the body the ``leg_interference`` constraint already assumes (two legs
  interfere when their segments come closer than D: capsule against capsule). A capsule holds
  the flat-ended cylinder of the same diameter, so a clearance is never over-stated.
* **Platform**: a cylinder about the z axis of the platform (mobile) frame, between
  ``collision.platform.z_min`` and ``z_max``, of ``collision.platform.radius``.
* **Tool/spindle**: a capsule of ``collision.tool.radius`` around the segment from the tool
  centre point C along +z of the tool frame for ``collision.tool.length`` (towards the
  platform in the packaged example). The tool frame is the mobile frame unless a tool transform
  (platform <- tool, the machining cell's tool frame) is given.
* **Obstacles**: fixed boxes, cylinders, spheres and capsules
  (:mod:`hexapod_workspace.core.model.collision.params`).

Pairs checked: the tool against each leg, and every moving body (tool, platform, legs) against
every obstacle. Bodies attached to each other are not checked (legs–platform, tool–platform);
leg against leg is the ``leg_interference`` constraint.

Rate bounds (Lipschitz) of the margin
-------------------------------------
Along a move the platform pose (p, R) changes with translation speed |ṗ| and angular rate Ω
(the move certificate's s-parametrisation; along a search ray |ṗ| = 0 and Ω ≤ 1).

1. *A body attached to the platform*: a point x = p + R q moves at
   |ẋ| = |ṗ + ω × R q| ≤ |ṗ| + Ω |q|, so at most |ṗ| + Ω r with r = max |q| over the body's
   core (the inflation radius moves with it and only shifts the distance), i.e. the largest
   distance of the core from the tool centre point C: ``max(|q0|, |q1|)`` for the tool segment,
   ``hypot(radius, max(|z_min|, |z_max|))`` for the platform cylinder.
2. *A leg*: its core point x = A_i + λ (B_i − A_i), λ ∈ [0, 1], moves at λ |Ḃ_i| ≤ |Ḃ_i|
   ≤ |ṗ| + Ω |b_i| (the base joint A_i stands still): the largest of its end speeds.
3. *Signed distance*: if within a time δ every point of A moves by at most u_A δ and every point
   of B by at most u_B δ, the support functions change by at most that much, so by equation (1)
   of :mod:`.distance` the signed distance changes by at most (u_A + u_B) δ.
   Against an obstacle (u = 0) the rate is that of the moving body.
4. *Tool against leg i*: the signed distance does not change under a rigid motion applied to
   both bodies; in the frame that translates with C (not turning), tool points move at
   ≤ Ω r_tool, and leg points at (1 − λ)|ṗ| + λ Ω |b_i| ≤ |ṗ| + Ω |b_i|: the rate is at most
   |ṗ| + Ω (r_tool + |b_i|).

Hence, for every pair, ``|d margin / dt| ≤ |ṗ| + ρ_c Ω`` with
``ρ_c = max(r_tool + max_i |b_i|, r_platform, max_i |b_i|, r_tool)`` (terms of absent bodies
dropped): :func:`rate_bound` returns (1, ρ_c). The clearance is a constant and does not change
the rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ....errors import ConfigError, InputError
from ..legs import leg_endpoints
from .distance import (
    _C,
    _INFLATION,
    _P,
    _R,
    CYLINDER,
    RECORD_SIZE,
    SEGMENT,
    WORK_ROWS,
    _capsule_bound,
    _helper,
    _jit,
    _pair,
)

if TYPE_CHECKING:
    from ..manipulator import Manipulator
    from .params import CollisionScene

__all__ = [
    "MOVING_BODIES",
    "RateBound",
    "SceneDistances",
    "pair_table",
    "platform_record",
    "rate_bound",
    "require_free_home",
    "scene_distances",
]

#: Names of the moving bodies, in the order of the body array of the kernel.
MOVING_BODIES = ("leg 1", "leg 2", "leg 3", "leg 4", "leg 5", "leg 6", "platform", "tool")
_PLATFORM, _TOOL, _FIRST_OBSTACLE = 6, 7, 8


@dataclass(frozen=True)
class SceneDistances:
    """The ``collision`` margin of N poses.

    Attributes
    ----------
    margin : ndarray, shape (N,)
        Smallest signed distance over the checked pairs minus ``collision.clearance``, m
        (≥ 0: clear; +inf when no pair is checked). A certified lower bound: see
        :mod:`.distance`.
    pair : ndarray of int, shape (N,)
        Index into ``pair_names`` of the pair that gives the margin (-1 when no pair).
    pair_names : tuple of str
        ``"tool vs leg 4"``, ``"leg 2 vs vise"``, ``"platform vs column"``: moving body first.
    distances : ndarray, shape (N, P) or None
        Signed distance of every pair (m, before the clearance) when asked for (``all_pairs``).
    """

    margin: NDArray[np.float64]
    pair: NDArray[np.int64]
    pair_names: tuple[str, ...]
    distances: NDArray[np.float64] | None

    def pair_name(self, index: int) -> str:
        """Name of the limiting pair of pose ``index`` ("" when no pair is checked)."""
        pair = int(self.pair[index])
        return self.pair_names[pair] if pair >= 0 else ""


@dataclass(frozen=True)
class RateBound:
    """Rate bound of the ``collision`` margin: |d margin/dt| ≤ translation·|ṗ| + rotation·Ω.

    Attributes
    ----------
    translation : float
        Per unit of translation speed of the tool centre point (m/m): 1.
    rotation : float
        ρ_c, per unit of angular rate of the platform (m/rad).
    """

    translation: float
    rotation: float


def pair_table(scene: CollisionScene) -> tuple[NDArray[np.int64], tuple[str, ...]]:
    """The pairs the scene checks: indices into the kernel's body array, and their names.

    Returns
    -------
    pairs : ndarray of int, shape (P, 2)
        (moving body, other body); bodies 0–5 legs, 6 platform, 7 tool, 8 + k obstacle k.
    names : tuple of str, length P
    """
    pairs: list[tuple[int, int]] = []
    names: list[str] = []
    if scene.tool is not None:
        for leg in range(6):
            pairs.append((_TOOL, leg))
            names.append(f"tool vs {MOVING_BODIES[leg]}")
    moving = [_TOOL] if scene.tool is not None else []
    moving += [_PLATFORM] if scene.platform is not None else []
    moving += list(range(6))
    for k, obstacle in enumerate(scene.obstacles):
        for body in moving:
            pairs.append((body, _FIRST_OBSTACLE + k))
            names.append(f"{MOVING_BODIES[body]} vs {obstacle.name}")
    return np.array(pairs, dtype=np.int64).reshape(-1, 2), tuple(names)


def _tool_ends(scene: CollisionScene) -> NDArray[np.float64]:
    """Tool segment ends q0 (the tool centre point) and q1, mobile frame, m, shape (2, 3)."""
    assert scene.tool is not None
    rotation, translation = scene.tool_transform[:3, :3], scene.tool_transform[:3, 3]
    return np.array([translation, translation + rotation @ np.array([0.0, 0.0, scene.tool.length])])


def platform_record(scene: CollisionScene) -> NDArray[np.float64]:
    """The platform cylinder as a record in the mobile frame (kind POINT with zero radius, never
    read, when the scene has no platform body), shape (RECORD_SIZE,)."""
    out = np.zeros(RECORD_SIZE)
    if scene.platform is None:
        return out
    platform = scene.platform
    rotation, translation = scene.platform_transform[:3, :3], scene.platform_transform[:3, 3]
    out[0] = CYLINDER
    out[_C : _C + 3] = translation + rotation @ np.array(
        [0.0, 0.0, 0.5 * (platform.z_min + platform.z_max)]
    )
    out[_R : _R + 9] = rotation.ravel()
    out[_P] = platform.radius
    out[_P + 1] = 0.5 * (platform.z_max - platform.z_min)
    return out


def _cylinder_reach(record: NDArray[np.float64]) -> float:
    """Largest distance of a cylinder core (record, mobile frame) from the mobile origin C:
    attained on the rim of an end disc, sqrt((|e⊥| + r)² + (e·a)²) for end centre e."""
    centre, axis = record[_C : _C + 3], record[_R : _R + 9].reshape(3, 3)[:, 2]
    reach = 0.0
    for sign in (-1.0, 1.0):
        end = centre + sign * record[_P + 1] * axis
        along = float(end @ axis)
        across = float(np.linalg.norm(end - along * axis))
        reach = max(reach, math.hypot(across + record[_P], along))
    return reach


def rate_bound(manipulator: Manipulator, scene: CollisionScene) -> RateBound:
    """The Lipschitz bound of the ``collision`` margin along a move (derivation: module doc).

    Parameters
    ----------
    manipulator : Manipulator
    scene : CollisionScene

    Returns
    -------
    RateBound
        (1, ρ_c) with ρ_c in m/rad; along a search ray (ω ≤ 1 rad per unit s, fixed position)
        the margin changes at most ρ_c per unit s. The platform's term is the largest distance
        of its cylinder from C (exact, also when the model's mobile frame is the tool's).
    """
    legs = float(np.max(np.linalg.norm(manipulator.platform_joints, axis=1)))
    rotation = legs
    if scene.tool is not None:
        tool = float(np.max(np.linalg.norm(_tool_ends(scene), axis=1)))
        rotation = max(rotation, tool + legs)
    if scene.platform is not None:
        rotation = max(rotation, _cylinder_reach(platform_record(scene)))
    return RateBound(1.0, rotation)


@_helper
def _transform(
    r: NDArray[np.float64], q: NDArray[np.float64], p: NDArray[np.float64]
) -> NDArray[np.float64]:
    """p + R q (no BLAS: numba's matrix product needs SciPy)."""
    out = np.empty(3)
    for i in range(3):
        out[i] = r[i, 0] * q[0] + r[i, 1] * q[1] + r[i, 2] * q[2] + p[i]
    return out


@_helper
def _segment_record(
    row: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64], radius: float
) -> None:
    """Fill ``row`` with the capsule of ``radius`` around segment ab (a leg, the tool): centre,
    unit axis as the record's local z, half length; a zero-length segment gets a zero axis."""
    axis = b - a
    length = math.sqrt(axis[0] ** 2 + axis[1] ** 2 + axis[2] ** 2)
    row[0] = SEGMENT
    row[_C : _C + 3] = 0.5 * (a + b)
    if length > 0.0:
        axis = axis / length
    else:
        axis[:] = 0.0
    row[_R + 2] = axis[0]
    row[_R + 5] = axis[1]
    row[_R + 8] = axis[2]
    row[_P] = 0.5 * length
    row[_INFLATION] = radius


@_jit
def _scene_kernel(
    rotations: NDArray[np.float64],
    positions: NDArray[np.float64],
    base_ends: NDArray[np.float64],
    platform_joints: NDArray[np.float64],
    leg_radius: float,
    tool_ends: NDArray[np.float64],
    tool_radius: float,
    platform_record: NDArray[np.float64],
    bodies: NDArray[np.float64],
    pairs: NDArray[np.int64],
    all_pairs: bool,
    distances: NDArray[np.float64],
    best_distance: NDArray[np.float64],
    best_pair: NDArray[np.int64],
) -> None:
    """Per pose: fill the moving bodies (rows 0–7 of ``bodies``; leg k from
    ``base_ends[pose, k]``), then the closest pair.

    Unless ``all_pairs``, pairs are visited by increasing lower bound (the signed distance of
    capsules that hold the two bodies: ≤ sd, by inclusion; exact for capsule pairs) and the
    visit stops once that bound cannot beat the best distance found: the minimum is the same
    as over all pairs.
    """
    n_pairs = pairs.shape[0]
    work = np.empty((WORK_ROWS, 3))
    bound = np.empty(n_pairs)
    order = np.empty(n_pairs, dtype=np.int64)
    for pose in range(rotations.shape[0]):
        r = rotations[pose]
        p = positions[pose]
        for leg in range(6):
            b = _transform(r, platform_joints[leg], p)
            _segment_record(bodies[leg], base_ends[pose, leg], b, leg_radius)
        if tool_ends.shape[0] == 2:
            q0 = _transform(r, tool_ends[0], p)
            q1 = _transform(r, tool_ends[1], p)
            _segment_record(bodies[_TOOL], q0, q1, tool_radius)
        if platform_record[0] == CYLINDER:
            row = bodies[_PLATFORM]
            row[0] = CYLINDER
            row[_C : _C + 3] = _transform(r, platform_record[_C : _C + 3], p)
            for i in range(3):
                for j in range(3):
                    row[_R + 3 * i + j] = (
                        r[i, 0] * platform_record[_R + j]
                        + r[i, 1] * platform_record[_R + 3 + j]
                        + r[i, 2] * platform_record[_R + 6 + j]
                    )
            row[_P : _P + 3] = platform_record[_P : _P + 3]
            row[_INFLATION] = 0.0
        best = np.inf
        chosen = -1
        if all_pairs:
            for k in range(n_pairs):
                value, _ = _pair(bodies[pairs[k, 0]], bodies[pairs[k, 1]], work)
                distances[pose, k] = value
                if value < best or (value != value and best == best):
                    best = value
                    chosen = k
        else:
            for k in range(n_pairs):
                bound[k] = _capsule_bound(bodies[pairs[k, 0]], bodies[pairs[k, 1]])
            order[:] = np.argsort(bound, kind="mergesort")
            for rank in range(n_pairs):
                k = order[rank]
                if bound[k] > best:
                    break
                value, _ = _pair(bodies[pairs[k, 0]], bodies[pairs[k, 1]], work)
                if value < best or (value == best and k < chosen) or value != value:
                    best = value
                    chosen = k
                    if value != value:
                        break
        best_distance[pose] = best
        best_pair[pose] = chosen


def scene_distances(
    manipulator: Manipulator,
    scene: CollisionScene,
    rotations: ArrayLike,
    positions: ArrayLike,
    *,
    all_pairs: bool = False,
) -> SceneDistances:
    """The ``collision`` margin (smallest signed distance minus the clearance) of N poses.

    Parameters
    ----------
    manipulator : Manipulator
        Leg architecture (the legs' base-side ends come from
        :func:`hexapod_workspace.core.model.legs.leg_endpoints`), platform joints b_i (mobile
        frame), leg diameter.
    scene : CollisionScene
        Clearance, platform and tool bodies, obstacles in the base frame
        (:func:`hexapod_workspace.core.model.collision.params.collision_scene`).
    rotations : array_like, shape (N, 3, 3) or (3, 3)
        Platform orientations R (mobile -> base frame).
    positions : array_like, shape (N, 3) or (3,)
        Tool-tip positions OC, base frame, m (one is broadcast to every rotation).
    all_pairs : bool
        Also return the distance of every pair (otherwise pairs that cannot be the closest, by
        the capsules that hold them, are skipped).

    Returns
    -------
    SceneDistances

    Raises
    ------
    InputError
        Wrong shapes, NaN or infinite values.
    """
    rotations = np.asarray(rotations, dtype=np.float64)
    if rotations.ndim == 2:
        rotations = rotations[None]
    if rotations.ndim != 3 or rotations.shape[1:] != (3, 3):
        msg = f"rotations: expected shape (N, 3, 3), got {rotations.shape}"
        raise InputError(msg)
    count = rotations.shape[0]
    positions = np.asarray(positions, dtype=np.float64)
    if positions.shape == (3,):
        positions = np.broadcast_to(positions, (count, 3))
    if positions.shape != (count, 3):
        msg = f"positions: expected shape ({count}, 3) or (3,), got {positions.shape}"
        raise InputError(msg)
    for name, values in (("rotations", rotations), ("positions", positions)):
        if not np.all(np.isfinite(values)):
            first = int(np.flatnonzero(~np.isfinite(values.reshape(count, -1)).all(axis=1))[0])
            msg = f"{name}: expected finite values, pose {first} is {values[first].tolist()}"
            raise InputError(msg)
    # The legs' base-side ends where the architecture puts them (a slide's joint, a crank's end;
    # NaN for a leg without an inverse-kinematics solution, whose margin is then NaN).
    base_ends, _ = leg_endpoints(manipulator, rotations, positions)
    pairs, names = pair_table(scene)
    bodies = np.zeros((_FIRST_OBSTACLE + len(scene.obstacles), RECORD_SIZE))
    for k, obstacle in enumerate(scene.obstacles):
        bodies[_FIRST_OBSTACLE + k] = obstacle.record
    tool_ends = _tool_ends(scene) if scene.tool is not None else np.zeros((0, 3))
    tool_radius = scene.tool.radius if scene.tool is not None else 0.0
    platform = platform_record(scene)
    distances = np.empty((count, pairs.shape[0]) if all_pairs else (0, 0))
    margin = np.empty(count)
    chosen = np.empty(count, dtype=np.int64)
    if pairs.shape[0]:
        _scene_kernel(
            np.ascontiguousarray(rotations),
            np.ascontiguousarray(positions),
            np.ascontiguousarray(base_ends),
            np.ascontiguousarray(manipulator.platform_joints),
            0.5 * manipulator.leg_diameter,
            tool_ends,
            tool_radius,
            platform,
            bodies,
            pairs,
            all_pairs,
            distances,
            margin,
            chosen,
        )
    else:
        margin[:] = np.inf
        chosen[:] = -1
    # As the compiled kernels: a pose with a leg without a solution has no margin and no pair.
    unsolved = np.isnan(base_ends).any(axis=(1, 2))
    margin[unsolved] = np.nan
    chosen[unsolved] = -1
    return SceneDistances(
        margin=margin - scene.clearance,
        pair=chosen,
        pair_names=names,
        distances=distances if all_pairs else None,
    )


def require_free_home(manipulator: Manipulator, scene: CollisionScene) -> CollisionScene:
    """Return ``scene``, or refuse a scene in which a pair collides at the home pose.

    Parameters
    ----------
    manipulator : Manipulator
        The model the scene belongs to; its home pose is the home position with the identity
        orientation.
    scene : CollisionScene
        Bodies in the platform frame, obstacles in the base frame.

    Returns
    -------
    CollisionScene
        ``scene`` itself.

    Raises
    ------
    ConfigError
        ``collision: <pair> collide at the home pose (distance …, clearance …)``, naming the
        closest pair.
    """
    home = scene_distances(manipulator, scene, np.eye(3), manipulator.home_position)
    if home.margin[0] < 0.0:
        distance = float(home.margin[0]) + scene.clearance
        msg = (
            f"collision: {home.pair_name(0)} collide at the home pose (distance "
            f"{distance:.4g} m, clearance {scene.clearance:g} m)"
        )
        raise ConfigError(msg)
    return scene
