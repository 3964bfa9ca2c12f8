"""Plain-numpy reference of the three leg architectures (6-UPS, 6-PUS, 6-RUS), slow on purpose.

Written from the architectures' formulas (leg inverse kinematics, actuator, transmission and
singularity margins as specified for the package) and the conventions of docs/theory.md, not
from the package's kernels, and importing nothing from the package: it reads the ROS 2
parameters file itself, computes the default joint axes itself and has its own exact segment
distance. The tests use it as independent evidence for the compiled code
(``test_architectures_reference.py``) and check it on its own (``test_reference_arch.py``).
Vectorised over poses only where that changes nothing but the speed (one numpy row per pose,
explicit loops over the six legs and the 15 leg pairs).

Model (SI units, base frame unless said otherwise)
--------------------------------------------------
Pose: T&T angles (φ, θ, ψ), ``R = Rz(φ)·Ry(θ)·Rz(−φ)·Rz(ψ)``, position ``p`` (OC). Platform
joints ``B_i = p + R·b_i`` (``b_i`` = ``geometry.platform_joints``, mobile frame).

- ``ups``: base joints fixed, ``A_i = a_i`` (``geometry.base_joints``); the actuated coordinate
  is the leg length ``ℓ_i = |B_i − A_i|``; margin ``leg_length`` = min(ℓ − ℓmin, ℓmax − ℓ).
- ``pus``: ``A_i(q) = A0_i + q·u_i`` (``A0_i`` = ``geometry.base_joints``, unit ``u_i`` =
  ``geometry.rail_directions``), fixed leg length ``L_i``; with ``d = B_i − A0_i``,
  ``q = u·d + branch·sqrt((u·d)² − |d|² + L²)``.
- ``rus``: crank end ``C_i(q) = A0_i + r·(cos q·e_i + sin q·f_i)``, ``f_i = w_i × e_i``; with
  ``a = 2r·d·e``, ``b = 2r·d·f``, ``c = |d|² + r² − L²``: ``a cos q + b sin q = c``,
  ``q = atan2(b, a) + branch·arccos(c/√(a² + b²))``, taken in the 2π window centred on
  ``[actuator_min, actuator_max]``.

Margins (≥ 0 holds; per pose, the minimum over legs or pairs)
-------------------------------------------------------------
- ``actuator`` (pus, rus): min(q − q_min, q_max − q), m or rad.
- ``ik`` (pus, rus): how far ``L_i`` lies inside the range of distances from ``B_i`` to the
  locus of the moving base joint, m. pus: the locus is the rail line, distances [h, ∞) with
  ``h = |d − (u·d)u|``, so ``ik_i = L − h`` (``(u·d)² − |d|² + L² = L² − h²`` has its sign).
  rus: the locus is the crank circle, distances [d_min, d_max] with
  ``d_min² = d_∥² + (|d_⊥| − r)²``, ``d_max² = d_∥² + (|d_⊥| + r)²`` (d_∥ along w, d_⊥ in the
  crank plane), i.e. ``|d|² + r² ∓ √(a² + b²)``, so ``ik_i = min(L − d_min, d_max − L)``,
  negative exactly when ``|c| > √(a² + b²)``. Both are 1-Lipschitz in ``B_i``.
- ``transmission`` (pus, rus): ``|τ_i| − limits.transmission_min``, ``τ = n·u`` (pus),
  ``τ = n·(w × (C − A0))/r`` (rus), ``n_i = (B_i − A_i(q_i))/L_i``.
- ``base_joint``: α_i − angle(jA_i, n_i), measured at the moving joint: pus, the axis translates
  with the slide (constant); rus, the axis is given at q = 0 and turned by q about w_i.
- ``platform_joint``: β_i − angle(R·jB_i, −n_i).
- ``leg_interference``: min over pairs of the exact distance between the leg segments
  ``A_i(q_i)B_i`` (rods ``C_iB_i`` for rus) minus the leg diameter D; +inf when D = 0.
- ``singularity``: σ_min(M) − ``limits.singularity_min``, M rows ``(n_iᵀ, ((R·b_i) × n_i)ᵀ/ρ)``,
  ρ = max_i |b_i|, by :func:`numpy.linalg.svd`. Enforced only when singularity_min > 0.

Joint axes default to the leg directions at the home pose (``geometry.home_position``, R = I):
jA_i = n_i (rus: turned back by −q_i to the crank's zero position), jB_i = −n_i.

Where some leg has no inverse-kinematics solution, its q is NaN, ``ik`` is negative, and every
margin that needs that leg's q (all but ``ik``) is NaN for the pose.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "ARCHITECTURES",
    "MARGIN_NAMES",
    "ReferenceModel",
    "ReferenceResult",
    "base_points",
    "evaluate",
    "inverse_kinematics",
    "model_from_parameters",
    "platform_points",
    "read_parameters",
    "rotation_matrices",
    "segment_distance",
]

ARCHITECTURES = ("ups", "pus", "rus")

#: Margin names per architecture (the stroke margin is ``leg_length`` for ups, as today).
MARGIN_NAMES: dict[str, tuple[str, ...]] = {
    "ups": ("leg_length", "base_joint", "platform_joint", "leg_interference", "singularity"),
    "pus": (
        "actuator",
        "ik",
        "transmission",
        "base_joint",
        "platform_joint",
        "leg_interference",
        "singularity",
    ),
}
MARGIN_NAMES["rus"] = MARGIN_NAMES["pus"]

PAIRS = [(i, j) for i in range(6) for j in range(i + 1, 6)]


# --------------------------------------------------------------------------------------------
# Parameters file
# --------------------------------------------------------------------------------------------


def _flatten(tree: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in tree.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            flat.update(_flatten(value, name + "."))
        else:
            flat[name] = value
    return flat


def read_parameters(path: str | Path) -> dict[str, Any]:
    """Dotted parameter names of a ROS 2 parameters file (``/**`` then the node's own section)."""
    document = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    flat: dict[str, Any] = {}
    for root in ("/**", "/hexapod_workspace", "hexapod_workspace"):
        if root in document:
            flat.update(_flatten(document[root]["ros__parameters"]))
    if not flat:
        msg = f"{path}: no hexapod_workspace section"
        raise ValueError(msg)
    return flat


def _per_leg(flat: Mapping[str, Any], name: str, default: Any = None) -> NDArray[np.float64]:
    value = flat.get(name, default)
    if value is None:
        msg = f"{name}: required"
        raise ValueError(msg)
    array = np.atleast_1d(np.asarray(value, dtype=float)).ravel()
    if array.size not in (1, 6):
        msg = f"{name}: expected 1 or 6 numbers, got {array.size}"
        raise ValueError(msg)
    return np.broadcast_to(array, (6,)).copy()


def _joints(flat: Mapping[str, Any], name: str) -> NDArray[np.float64]:
    array = np.asarray(flat[name], dtype=float).ravel()
    if array.size != 18:
        msg = f"{name}: expected 18 numbers, got {array.size}"
        raise ValueError(msg)
    return array.reshape(6, 3)


def _unit_rows(rows: NDArray[np.float64]) -> NDArray[np.float64]:
    return rows / np.linalg.norm(rows, axis=-1, keepdims=True)


# --------------------------------------------------------------------------------------------
# Model
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ReferenceModel:
    """One manipulator, every array per leg (row i = leg i + 1), SI units, base frame.

    ``actuator_min/max`` hold ``limits.leg_length_min/max`` for ups. Arrays of another
    architecture are None. ``base_joint_axes`` are the rus axes at q = 0.
    """

    architecture: str
    base_joints: NDArray[np.float64]  # (6, 3) a_i (ups) or A0_i, m
    platform_joints: NDArray[np.float64]  # (6, 3) b_i, mobile frame, m
    home_position: NDArray[np.float64]  # (3,), m
    position: NDArray[np.float64]  # (3,) pose.position, m
    actuator_min: NDArray[np.float64]  # (6,), m or rad
    actuator_max: NDArray[np.float64]  # (6,)
    base_joint_max_angle: NDArray[np.float64]  # (6,), rad
    platform_joint_max_angle: NDArray[np.float64]  # (6,), rad
    base_joint_axes: NDArray[np.float64]  # (6, 3) unit
    platform_joint_axes: NDArray[np.float64]  # (6, 3) unit, mobile frame
    leg_diameter: float
    transmission_min: float
    singularity_min: float
    leg_lengths: NDArray[np.float64] | None = None  # (6,) L_i, m (pus, rus)
    branch: NDArray[np.float64] | None = None  # (6,) ±1 (pus, rus)
    rail_directions: NDArray[np.float64] | None = None  # (6, 3) unit u_i (pus)
    crank_axes: NDArray[np.float64] | None = None  # (6, 3) unit w_i (rus)
    crank_zero_directions: NDArray[np.float64] | None = None  # (6, 3) unit e_i (rus)
    crank_lengths: NDArray[np.float64] | None = None  # (6,) r_i, m (rus)

    @property
    def rho(self) -> float:
        """ρ = max_i |b_i|, m."""
        return float(np.linalg.norm(self.platform_joints, axis=1).max())


def model_from_parameters(flat: Mapping[str, Any]) -> ReferenceModel:
    """A :class:`ReferenceModel` from dotted parameter names (the specified defaults of the
    architecture keys)."""
    architecture = str(flat.get("geometry.architecture", "ups"))
    if architecture not in ARCHITECTURES:
        msg = f"geometry.architecture: expected one of {ARCHITECTURES}, got {architecture!r}"
        raise ValueError(msg)
    home = np.asarray(flat["geometry.home_position"], dtype=float)
    position = np.asarray(flat.get("pose.position", home), dtype=float)
    stroke = (
        ("leg_length_min", "leg_length_max")
        if architecture == "ups"
        else (
            "actuator_min",
            "actuator_max",
        )
    )
    fields: dict[str, Any] = {
        "architecture": architecture,
        "base_joints": _joints(flat, "geometry.base_joints"),
        "platform_joints": _joints(flat, "geometry.platform_joints"),
        "home_position": home,
        "position": position,
        "actuator_min": _per_leg(flat, f"limits.{stroke[0]}"),
        "actuator_max": _per_leg(flat, f"limits.{stroke[1]}"),
        "base_joint_max_angle": _per_leg(flat, "limits.base_joint_max_angle"),
        "platform_joint_max_angle": _per_leg(flat, "limits.platform_joint_max_angle"),
        "leg_diameter": float(flat.get("limits.leg_diameter", 0.0)),
        "transmission_min": float(flat.get("limits.transmission_min", 0.1)),
        "singularity_min": float(flat.get("limits.singularity_min", 0.0)),
        # Placeholders until the home pose gives the defaults (replaced below).
        "base_joint_axes": np.zeros((6, 3)),
        "platform_joint_axes": np.zeros((6, 3)),
    }
    if architecture != "ups":
        fields["leg_lengths"] = _per_leg(flat, "geometry.leg_lengths")
        fields["branch"] = _per_leg(flat, "geometry.branch", [1.0])
    if architecture == "pus":
        fields["rail_directions"] = _unit_rows(_joints(flat, "geometry.rail_directions"))
    if architecture == "rus":
        fields["crank_axes"] = _unit_rows(_joints(flat, "geometry.crank_axes"))
        fields["crank_zero_directions"] = _unit_rows(
            _joints(flat, "geometry.crank_zero_directions")
        )
        fields["crank_lengths"] = _per_leg(flat, "geometry.crank_lengths")
    model = ReferenceModel(**fields)

    # Default joint axes: the leg directions at the home pose (identity orientation).
    home_angles = np.zeros((1, 3))
    q, _ = inverse_kinematics(model, platform_points(model, home_angles, home))
    if np.isnan(q).any():
        msg = f"geometry.home_position: no inverse-kinematics solution for legs {np.isnan(q[0])}"
        raise ValueError(msg)
    ends = base_points(model, q)[0]
    directions = _unit_rows(platform_points(model, home_angles, home)[0] - ends)
    given_base = np.asarray(flat.get("geometry.base_joint_axes", []), dtype=float)
    given_platform = np.asarray(flat.get("geometry.platform_joint_axes", []), dtype=float)
    if given_base.size:
        base_axes = _unit_rows(given_base.reshape(6, 3))
    elif architecture == "rus":
        base_axes = _rotate_about(model.crank_axes, -q[0], directions)  # type: ignore[arg-type]
    else:
        base_axes = directions
    platform_axes = _unit_rows(given_platform.reshape(6, 3)) if given_platform.size else -directions
    return ReferenceModel(
        **{**fields, "base_joint_axes": base_axes, "platform_joint_axes": platform_axes}
    )


def load(path: str | Path) -> ReferenceModel:
    """The reference model of a parameters file."""
    return model_from_parameters(read_parameters(path))


# --------------------------------------------------------------------------------------------
# Kinematics
# --------------------------------------------------------------------------------------------


def rotation_matrices(angles: ArrayLike) -> NDArray[np.float64]:
    """R = Rz(φ)·Ry(θ)·Rz(−φ)·Rz(ψ) as four explicit matrix products, shape (N, 3, 3)."""
    angles = np.atleast_2d(np.asarray(angles, dtype=float))

    def rz(angle: NDArray[np.float64]) -> NDArray[np.float64]:
        c, s = np.cos(angle), np.sin(angle)
        m = np.zeros((angle.size, 3, 3))
        m[:, 0, 0], m[:, 0, 1], m[:, 1, 0], m[:, 1, 1], m[:, 2, 2] = c, -s, s, c, 1.0
        return m

    def ry(angle: NDArray[np.float64]) -> NDArray[np.float64]:
        c, s = np.cos(angle), np.sin(angle)
        m = np.zeros((angle.size, 3, 3))
        m[:, 0, 0], m[:, 0, 2], m[:, 2, 0], m[:, 2, 2], m[:, 1, 1] = c, s, -s, c, 1.0
        return m

    phi, theta, psi = angles[:, 0], angles[:, 1], angles[:, 2]
    return rz(phi) @ ry(theta) @ rz(-phi) @ rz(psi)


def platform_points(
    model: ReferenceModel, angles: ArrayLike, position: ArrayLike
) -> NDArray[np.float64]:
    """B_i = p + R·b_i, shape (N, 6, 3), m, base frame; ``position`` (3,) or one per pose (N, 3)."""
    rotations = rotation_matrices(angles)
    p = np.asarray(position, dtype=float)[..., None, :]
    return p + np.einsum("nkl,il->nik", rotations, model.platform_joints)


def _rotate_about(
    axes: NDArray[np.float64], angles: NDArray[np.float64], vectors: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Rodrigues: ``vectors`` (..., 6, 3) turned by ``angles`` (..., 6) about unit ``axes``."""
    c, s = np.cos(angles)[..., None], np.sin(angles)[..., None]
    along = np.sum(axes * vectors, axis=-1, keepdims=True) * axes
    return c * vectors + s * np.cross(axes, vectors) + (1.0 - c) * along


def inverse_kinematics(
    model: ReferenceModel, platform: NDArray[np.float64], branch: NDArray[np.float64] | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Actuated coordinates and the per-leg ``ik`` margin of platform joints (N, 6, 3).

    Returns
    -------
    q : ndarray, shape (N, 6)
        ups: leg length, m; pus: slide position along the rail, m; rus: crank angle in the
        window centred on the range, rad. NaN where the leg has no solution.
    ik : ndarray, shape (N, 6)
        Per-leg ik margin, m (+inf for ups, which always has a solution).
    """
    d = platform - model.base_joints  # (N, 6, 3): B_i − A0_i
    if model.architecture == "ups":
        return np.linalg.norm(d, axis=-1), np.full(d.shape[:2], np.inf)
    assert model.leg_lengths is not None and model.branch is not None
    branch = model.branch if branch is None else branch
    length = model.leg_lengths
    if model.architecture == "pus":
        u = model.rail_directions
        ud = np.sum(d * u, axis=-1)
        h = np.linalg.norm(d - ud[..., None] * u, axis=-1)  # distance from B_i to the rail line
        ik = length - h
        # (u·d)² − |d|² + L² = L² − h², computed so that its sign is exactly that of ik.
        discriminant = ik * (length + h)
        with np.errstate(invalid="ignore"):
            q = np.where(ik >= 0.0, ud + branch * np.sqrt(discriminant), np.nan)
        return q, ik
    assert model.crank_lengths is not None
    r = model.crank_lengths
    w, e = model.crank_axes, model.crank_zero_directions
    f = np.cross(w, e)
    a = 2.0 * r * np.sum(d * e, axis=-1)
    b = 2.0 * r * np.sum(d * f, axis=-1)
    c = np.sum(d * d, axis=-1) + r * r - length * length
    along = np.sum(d * w, axis=-1)
    across = np.linalg.norm(d - along[..., None] * w, axis=-1)
    d_min = np.hypot(along, across - r)
    d_max = np.hypot(along, across + r)
    ik = np.minimum(length - d_min, d_max - length)
    k = np.hypot(a, b)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.clip(c / k, -1.0, 1.0)
        q_raw = np.arctan2(b, a) + branch * np.arccos(ratio)
    centre = 0.5 * (model.actuator_min + model.actuator_max)
    q = centre + np.mod(q_raw - centre + math.pi, 2.0 * math.pi) - math.pi
    return np.where(ik >= 0.0, q, np.nan), ik


def base_points(model: ReferenceModel, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The moving base-side end of each leg for coordinates q (N, 6): shape (N, 6, 3), m.

    ups: a_i; pus: A_i(q) = A0_i + q·u_i; rus: C_i(q) = A0_i + r(cos q·e_i + sin q·(w_i × e_i)).
    """
    q = np.asarray(q, dtype=float)
    if model.architecture == "ups":
        return np.broadcast_to(model.base_joints, (*q.shape, 3)).copy()
    if model.architecture == "pus":
        return model.base_joints + q[..., None] * model.rail_directions
    assert model.crank_lengths is not None
    e, f = model.crank_zero_directions, np.cross(model.crank_axes, model.crank_zero_directions)
    r = model.crank_lengths[:, None]
    return model.base_joints + r * (np.cos(q)[..., None] * e + np.sin(q)[..., None] * f)


# --------------------------------------------------------------------------------------------
# Exact segment distance (interior critical point, else the best of the four edges)
# --------------------------------------------------------------------------------------------


def _point_segment(
    x: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Distance from points x to segments [a, b], all (N, 3); zero-length segments allowed."""
    ab = b - a
    length2 = np.sum(ab * ab, axis=-1)
    safe = np.where(length2 > 0.0, length2, 1.0)
    t = np.clip(np.sum((x - a) * ab, axis=-1) / safe, 0.0, 1.0)
    t = np.where(length2 > 0.0, t, 0.0)
    return np.linalg.norm(x - (a + t[..., None] * ab), axis=-1)


def segment_distance(
    p0: ArrayLike, p1: ArrayLike, q0: ArrayLike, q1: ArrayLike
) -> NDArray[np.float64]:
    """Exact minimum distance between segments [p0, p1] and [q0, q1], arrays (..., 3).

    |P(s) − Q(t)|² is a convex quadratic on the unit square: its minimum is either the
    stationary point, when that lies strictly inside, or on one of the four edges, where it is a
    point-to-segment distance. Near-parallel segments (a·e − b² ≤ 1e-12·a·e) skip the interior
    point: the quadratic is then flat along the valley to within 1e-12·|d1|²·|d2|² and an edge
    attains its minimum to that accuracy (exactly for parallel or degenerate segments).
    """
    p0, p1, q0, q1 = (np.asarray(v, dtype=float) for v in (p0, p1, q0, q1))
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = np.sum(d1 * d1, axis=-1)
    b = np.sum(d1 * d2, axis=-1)
    e = np.sum(d2 * d2, axis=-1)
    c = np.sum(d1 * r, axis=-1)
    f = np.sum(d2 * r, axis=-1)
    best = np.minimum.reduce(
        [
            _point_segment(p0, q0, q1),
            _point_segment(p1, q0, q1),
            _point_segment(q0, p0, p1),
            _point_segment(q1, p0, p1),
        ]
    )
    denominator = a * e - b * b
    regular = denominator > 1e-12 * a * e
    safe = np.where(regular, denominator, 1.0)
    s = (b * f - c * e) / safe
    t = (a * f - b * c) / safe
    interior = regular & (s > 0.0) & (s < 1.0) & (t > 0.0) & (t < 1.0)
    gap = np.linalg.norm(r + s[..., None] * d1 - t[..., None] * d2, axis=-1)
    return np.where(interior, np.minimum(best, gap), best)


# --------------------------------------------------------------------------------------------
# Margins
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ReferenceResult:
    """Margins of N poses at one position.

    ``margins[name]`` shape (N,) (NaN where undefined), ``per_leg[name]`` shape (N, 6) for the
    per-leg constraints, ``q`` (N, 6) actuated coordinates, ``reachable`` (N,) bool.
    """

    margins: dict[str, NDArray[np.float64]]
    per_leg: dict[str, NDArray[np.float64]]
    q: NDArray[np.float64]
    enforced: tuple[str, ...]
    reachable: NDArray[np.bool_]

    def violated(self) -> list[list[str]]:
        """Per pose, the enforced constraints whose margin is negative or NaN."""
        bad = {name: ~(self.margins[name] >= 0.0) for name in self.enforced}
        return [[name for name in self.enforced if bad[name][k]] for k in range(len(self.q))]


def _angle(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Angle between vectors (..., 3) by atan2(|u × v|, u·v), accurate near 0 and π."""
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))


def evaluate(model: ReferenceModel, angles: ArrayLike, position: ArrayLike) -> ReferenceResult:
    """Every margin of the poses ``angles`` (N, 3) (φ, θ, ψ in rad) at ``position``, m: one (3,)
    for all poses or one per pose (N, 3)."""
    angles = np.atleast_2d(np.asarray(angles, dtype=float))
    count = angles.shape[0]
    rotations = rotation_matrices(angles)
    platform = platform_points(model, angles, position)
    q, ik = inverse_kinematics(model, platform)
    ends = base_points(model, q)  # NaN rows where q is NaN
    legs = platform - ends
    lengths = np.linalg.norm(legs, axis=-1)
    n = legs / lengths[..., None]

    per_leg: dict[str, NDArray[np.float64]] = {}
    stroke = np.minimum(q - model.actuator_min, model.actuator_max - q)
    if model.architecture == "ups":
        per_leg["leg_length"] = stroke
    else:
        per_leg["actuator"] = stroke
        per_leg["ik"] = ik
        if model.architecture == "pus":
            tau = np.sum(n * model.rail_directions, axis=-1)
        else:
            assert model.crank_lengths is not None
            arm = np.cross(model.crank_axes, ends - model.base_joints)
            tau = np.sum(n * arm, axis=-1) / model.crank_lengths
        per_leg["transmission"] = np.abs(tau) - model.transmission_min
    if model.architecture == "rus":
        base_axes = _rotate_about(
            model.crank_axes, q, np.broadcast_to(model.base_joint_axes, legs.shape)
        )
    else:
        base_axes = np.broadcast_to(model.base_joint_axes, legs.shape)
    per_leg["base_joint"] = model.base_joint_max_angle - _angle(base_axes, n)
    platform_axes = np.einsum("nkl,il->nik", rotations, model.platform_joint_axes)
    per_leg["platform_joint"] = model.platform_joint_max_angle - _angle(platform_axes, -n)

    margins = {name: per_leg[name].min(axis=1) for name in per_leg}  # NaN propagates
    if model.leg_diameter > 0.0:
        pairs = np.stack(
            [
                segment_distance(ends[:, i], platform[:, i], ends[:, j], platform[:, j])
                for i, j in PAIRS
            ],
            axis=1,
        )
        per_leg["leg_pairs"] = pairs - model.leg_diameter  # (N, 15), pairs in PAIRS order
        margins["leg_interference"] = per_leg["leg_pairs"].min(axis=1)
    else:
        margins["leg_interference"] = np.full(count, np.inf)

    moments = np.cross(np.einsum("nkl,il->nik", rotations, model.platform_joints), n) / model.rho
    jacobian = np.concatenate([n, moments], axis=-1)  # (N, 6, 6): row i = Plücker line of leg i
    finite = np.isfinite(jacobian).all(axis=(1, 2))
    sigma = np.full(count, np.nan)
    if finite.any():
        sigma[finite] = np.linalg.svd(jacobian[finite], compute_uv=False)[:, -1]
    margins["singularity"] = sigma - model.singularity_min

    names = MARGIN_NAMES[model.architecture]
    margins = {name: margins[name] for name in names}
    enforced = tuple(name for name in names if name != "singularity" or model.singularity_min > 0.0)
    reachable = np.logical_and.reduce([margins[name] >= 0.0 for name in enforced])
    return ReferenceResult(margins, per_leg, q, enforced, reachable)
