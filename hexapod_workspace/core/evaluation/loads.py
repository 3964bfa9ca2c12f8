"""Loads at one pose: actuator forces under the payload and a process wrench, the payload the
actuators hold, stiffness and deflection at the tool, and the accuracy actuator errors allow.

Conventions (docs/theory.md, "Loads"; every quantity in the base frame unless named):

* **Jacobian.** ``J`` (6×6) maps the twist of the tool centre point ``[v; ω]`` (m/s, rad/s,
  base frame) to actuator rates ``q̇`` (m/s for legs and slides, rad/s for cranks). Leg i joins
  its base-side end ``A_i`` to ``B_i = p + R·b_i``; with the unit leg direction
  ``n_i = (B_i − A_i)/|B_i − A_i|`` its platform end moves along the leg at
  ``n_i·Ḃ_i = n_i·v + ((R·b_i) × n_i)·ω``, and the architecture's transmission turns that into
  the actuator's rate (:mod:`hexapod_workspace.core.model.architectures`): ``q̇ = n·Ḃ`` (6-UPS,
  the leg length), ``q̇ = n·Ḃ/τ`` with ``τ = n·u`` (6-PUS slides), ``q̇ = n·Ḃ/(r·τ)`` with
  ``τ = n·(w × (C − A0))/r`` (6-RUS cranks). So row i of J is
  ``[n_i, (R·b_i) × n_i] / d_i`` with ``d_i = 1``, ``τ_i`` or ``r_i·τ_i``.
* **Statics.** A wrench ``w = [f; m]`` on the platform at the tool centre point is held by
  actuator forces ``τ`` with ``Jᵀτ + w = 0`` (virtual work), so ``τ = −J⁻ᵀ·w``; ``τ_i > 0``
  pushes (drives q_i up). N for legs and slides, N·m for cranks. Gravity on the load (mass M at
  ``c``, ``load.center_of_mass`` in the model's mobile frame) is ``[M·g; (R·c) × M·g]``.
* **Process box.** The process wrench is ``w₀ + diag(σ)·r`` in the tool frame, ``|σ_j| ≤ 1``
  (``process.wrench``, ``process.wrench_range``), rotated into the base frame by
  ``R₆ = diag(R, R)``. τ is affine in σ, so over the box
  ``τ_i ∈ [τ_i⁰ − s_i, τ_i⁰ + s_i]`` exactly, ``τ⁰ = −J⁻ᵀ(w_grav + R₆·w₀)``,
  ``s_i = Σ_j |(J⁻ᵀ·R₆)_ij|·r_j`` (each end reached at a vertex σ = ±sign).
* **Stiffness.** ``K = Jᵀ·diag(k)·J`` (``stiffness.actuator``): an actuator force τ_i shortens
  actuator i by ``τ_i/k_i``, which moves the tool by ``J⁻¹·δq``, so the deflection under the
  process wrench is ``δ = K⁻¹·w``. Its norm is convex in σ, so its largest value over the box is
  at one of the 64 vertices (enumerated). Gravity is left out: it is the machine's own
  calibration.
* **Accuracy.** Actuator errors ``|δq_i| ≤ e_i`` (``accuracy.actuator_error``) move the tool by
  ``J⁻¹·δq``; the largest translation and rotation over that box are at its 64 vertices.
* **Payload capacity.** τ⁰ is affine in M: ``τ⁰(M) = M·a + b``. The actuators hold every mass
  in [0, M] when, for each i, ``force_min_i ≤ M·a_i + b_i − s_i`` and
  ``M·a_i + b_i + s_i ≤ force_max_i`` for all those masses: half-lines in M, so the largest such
  M is a closed form (0 when even no load is held, +inf when gravity is zero).

Near a singularity J⁻¹ grows without bound: poses where J is numerically singular (σ_min/σ_max
below :data:`SINGULAR_RATIO`) or a leg has no inverse-kinematics solution answer forces,
deflections and errors of +inf, a force margin of −inf and a capacity of 0, never a finite
wrong value.

**Rows at poses.** :func:`load_rows` gives the three limits a case sets as margins at N poses,
the way ``hexapod-workspace check`` reports them beside the geometric rows: ``actuator_force``
(N or N·m, the smallest distance of the worst τ_i over the process box to its limits, the
limiting actuator named), ``deflection`` and ``accuracy`` (m, the limit less the worst
translation). Each is exact at its pose (no sampling inside a pose). They are not rows of
:mod:`~hexapod_workspace.core.constraints` yet: the searches, the move certificate and the
planner need their rate bounds, so the loader refuses a loads limit for every command but
``check`` and ``loads``.

This module is numpy only.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import ConfigError
from ..base.params import flatten
from ..base.validation import machine_size, millimetre_reason
from ..base.values import describe, frozen, numbers
from ..model.architectures import module as architecture_module
from ..model.legs import leg_endpoints
from ..model.manipulator import Manipulator

__all__ = [
    "LOAD_LIMITS",
    "LOAD_PARAMETERS",
    "LOAD_ROWS",
    "SINGULAR_RATIO",
    "LoadCase",
    "LoadRows",
    "Loads",
    "actuator_jacobian",
    "load_case_from_mapping",
    "load_rows",
    "loads_at",
    "require_plausible_loads",
]

#: The parameters of the loads (``load.*``, ``process.*``, ``stiffness.*``, ``accuracy.*`` and
#: the three limits), with their defaults; an empty list or 0 limit means "not set".
LOAD_PARAMETERS: dict[str, Any] = {
    "load.mass": 0.0,
    "load.center_of_mass": [0.0, 0.0, 0.0],
    "load.gravity": [0.0, 0.0, -9.81],
    "process.wrench": [0.0] * 6,
    "process.wrench_range": [0.0] * 6,
    "limits.actuator_force_max": [],
    "limits.actuator_force_min": [],
    "stiffness.actuator": [],
    "limits.deflection_max": 0.0,
    "accuracy.actuator_error": [],
    "limits.accuracy_max": 0.0,
}
#: The limits among them: the loads' constraints, read by ``hexapod-workspace loads``.
LOAD_LIMITS = (
    "limits.actuator_force_max",
    "limits.actuator_force_min",
    "limits.deflection_max",
    "limits.accuracy_max",
)
#: σ_min(J)/σ_max(J) below which J is taken as singular (forces +inf).
SINGULAR_RATIO = 1e-12
#: The 64 sign vertices of a six-dimensional box, shape (64, 6).
_VERTICES = np.array(list(itertools.product((-1.0, 1.0), repeat=6)))


@dataclass(frozen=True)
class LoadCase:
    """The loads of one set-up: payload, mounting, process wrench, actuator limits.

    Attributes
    ----------
    mass : float
        M ≥ 0, kg.
    center_of_mass : ndarray, shape (3,)
        c, the load's centre of mass in the model's mobile frame (origin at the tool centre
        point), m.
    gravity : ndarray, shape (3,)
        g, base frame, m/s² ([0, 0, −9.81] on a pedestal, [0, 0, 9.81] on a ceiling).
    wrench, wrench_range : ndarray, shape (6,)
        Centre w₀ and half-widths r ≥ 0 of the process wrench box [f; m], tool frame, N and N·m.
    force_max, force_min : ndarray, shape (6,), or None
        Actuator force limits (push, pull), N or N·m; None when not set.
    stiffness : ndarray, shape (6,), or None
        Axial actuator stiffness k_i > 0, N/m (legs, slides) or N·m/rad (cranks).
    deflection_max : float
        Largest tool translation under the process box, m; 0: not a limit.
    actuator_error : ndarray, shape (6,), or None
        Actuator error bound e_i ≥ 0, m or rad.
    accuracy_max : float
        Largest tool translation from actuator errors, m; 0: not a limit.
    """

    mass: float = 0.0
    center_of_mass: NDArray[np.float64] = field(default_factory=lambda: frozen(np.zeros(3)))
    gravity: NDArray[np.float64] = field(
        default_factory=lambda: frozen(np.array([0.0, 0.0, -9.81]))
    )
    wrench: NDArray[np.float64] = field(default_factory=lambda: frozen(np.zeros(6)))
    wrench_range: NDArray[np.float64] = field(default_factory=lambda: frozen(np.zeros(6)))
    force_max: NDArray[np.float64] | None = None
    force_min: NDArray[np.float64] | None = None
    stiffness: NDArray[np.float64] | None = None
    deflection_max: float = 0.0
    actuator_error: NDArray[np.float64] | None = None
    accuracy_max: float = 0.0

    @property
    def limited_rows(self) -> tuple[str, ...]:
        """The rows of :data:`LOAD_ROWS` whose limit this case sets (empty: no loads limit)."""
        wanted = (self.force_max is not None, self.deflection_max > 0.0, self.accuracy_max > 0.0)
        return tuple(name for name, on in zip(LOAD_ROWS, wanted, strict=True) if on)

    def in_tool_frame(self, offset: ArrayLike, rotation: ArrayLike) -> LoadCase:
        """The same case with the centre of mass given in the platform frame P re-expressed in
        a tool frame C (``PC = offset``, C's axes ``rotation`` in P): ``c' = Rᵀ(c − t)``."""
        r = np.asarray(rotation, dtype=np.float64)
        c = r.T @ (self.center_of_mass - np.asarray(offset, dtype=np.float64))
        return replace(self, center_of_mass=frozen(c))


def _count(name: str, value: Any, sizes: tuple[int, ...], what: str) -> NDArray[np.float64]:
    array = numbers(name, value)
    if array.size not in sizes:
        expected = " or ".join(str(s) for s in sizes)
        msg = f"{name}: expected {expected} numbers ({what}), got {array.size}"
        raise ConfigError(msg)
    return array


def _per_actuator(
    name: str, value: Any, what: str, *, positive: bool
) -> NDArray[np.float64] | None:
    """1 (shared) or 6 numbers, or None for an empty list; > 0 (or ≥ 0) each."""
    array = numbers(name, value)
    if array.size == 0:
        return None
    if array.size not in (1, 6):
        msg = f"{name}: expected 1 or 6 numbers ({what}) or an empty list, got {array.size}"
        raise ConfigError(msg)
    bad = array <= 0.0 if positive else array < 0.0
    if np.any(bad):
        sign = "> 0" if positive else ">= 0"
        msg = f"{name}: expected values {sign} ({what}), got {describe(array.tolist())}"
        raise ConfigError(msg)
    return frozen(np.broadcast_to(array, (6,)))


def _scalar(name: str, value: Any, what: str) -> float:
    array = numbers(name, value)
    if array.size != 1 or float(array[0]) < 0.0:
        msg = f"{name}: expected one number >= 0 ({what}), got {describe(value)}"
        raise ConfigError(msg)
    return float(array[0])


def load_case_from_mapping(parameters: Mapping[str, Any]) -> LoadCase:
    """The loads of a parameters mapping (nested or dotted; other names are ignored).

    Parameters
    ----------
    parameters : Mapping
        As :func:`~hexapod_workspace.core.evaluation.loading.manipulator_from_mapping` takes
        them; the names of :data:`LOAD_PARAMETERS` are read, absent ones take their defaults.

    Returns
    -------
    LoadCase
        Its centre of mass in the platform frame (``LoadCase.in_tool_frame`` moves it).

    Raises
    ------
    ConfigError
        One line naming the parameter, what was expected and what was given: a negative mass,
        a force minimum not below its maximum, a deflection or accuracy limit without the
        stiffness or errors it needs, a wrong count.
    """
    flat = flatten(parameters)
    values = {name: flat.get(name, default) for name, default in LOAD_PARAMETERS.items()}
    mass = _scalar("load.mass", values["load.mass"], "kg")
    com = _count("load.center_of_mass", values["load.center_of_mass"], (3,), "x, y, z in m")
    gravity = _count("load.gravity", values["load.gravity"], (3,), "m/s², base frame")
    wrench = _count("process.wrench", values["process.wrench"], (6,), "fx fy fz N, mx my mz N·m")
    spread = _count(
        "process.wrench_range", values["process.wrench_range"], (6,), "half-widths, N and N·m"
    )
    if np.any(spread < 0.0):
        msg = f"process.wrench_range: expected half-widths >= 0, got {describe(spread.tolist())}"
        raise ConfigError(msg)
    force_max = _per_actuator(
        "limits.actuator_force_max", values["limits.actuator_force_max"], "N or N·m", positive=True
    )
    force_min = None
    low = numbers("limits.actuator_force_min", values["limits.actuator_force_min"])
    if low.size:
        if force_max is None:
            msg = "limits.actuator_force_min: needs limits.actuator_force_max (the push limit)"
            raise ConfigError(msg)
        if low.size not in (1, 6):
            msg = f"limits.actuator_force_min: expected 1 or 6 numbers (N or N·m), got {low.size}"
            raise ConfigError(msg)
        force_min = frozen(np.broadcast_to(low, (6,)))
        if np.any(force_min >= force_max):
            msg = (
                "limits.actuator_force_min: expected each below limits.actuator_force_max "
                f"{describe(force_max.tolist())}, got {describe(force_min.tolist())}"
            )
            raise ConfigError(msg)
    elif force_max is not None:
        force_min = frozen(-force_max)
    stiffness = _per_actuator(
        "stiffness.actuator", values["stiffness.actuator"], "N/m or N·m/rad", positive=True
    )
    deflection_max = _scalar("limits.deflection_max", values["limits.deflection_max"], "m")
    if deflection_max > 0.0 and stiffness is None:
        msg = "limits.deflection_max: needs stiffness.actuator (N/m or N·m/rad per actuator)"
        raise ConfigError(msg)
    error = _per_actuator(
        "accuracy.actuator_error", values["accuracy.actuator_error"], "m or rad", positive=False
    )
    accuracy_max = _scalar("limits.accuracy_max", values["limits.accuracy_max"], "m")
    if accuracy_max > 0.0 and error is None:
        msg = "limits.accuracy_max: needs accuracy.actuator_error (m or rad per actuator)"
        raise ConfigError(msg)
    return LoadCase(
        mass=mass,
        center_of_mass=frozen(com),
        gravity=frozen(gravity),
        wrench=frozen(wrench),
        wrench_range=frozen(spread),
        force_max=force_max,
        force_min=force_min,
        stiffness=stiffness,
        deflection_max=deflection_max,
        actuator_error=error,
        accuracy_max=accuracy_max,
    )


def require_plausible_loads(manipulator: Manipulator, case: LoadCase) -> LoadCase:
    """Refuse a centre of mass that fits the machine only once divided by 1000 (written in
    millimetres), with the unit hint of
    :func:`~hexapod_workspace.core.base.validation.millimetre_reason`; the case otherwise.

    Parameters
    ----------
    manipulator : Manipulator
        The platform-frame model (its size, m).
    case : LoadCase
        As :func:`load_case_from_mapping` read it (centre of mass in the platform frame).

    Raises
    ------
    ConfigError
        One line naming ``load.center_of_mass``.
    """
    size = machine_size(
        manipulator.base_joints, manipulator.platform_joints, manipulator.home_position
    )
    reason = millimetre_reason("load.center_of_mass", case.center_of_mass, size)
    if reason is not None:
        raise ConfigError(reason)
    return case


def actuator_jacobian(
    manipulator: Manipulator, rotations: ArrayLike, positions: ArrayLike
) -> NDArray[np.float64]:
    """J at n poses: actuator rates per unit twist of the mobile frame's origin.

    Parameters
    ----------
    manipulator : Manipulator
    rotations : array_like, shape (n, 3, 3) or (3, 3)
        R, mobile frame to base frame.
    positions : array_like, shape (n, 3) or (3,)
        p, the mobile frame's origin (the tool centre point of a tool-frame model), base frame, m.

    Returns
    -------
    ndarray, shape (n, 6, 6)
        Row i ``[n_i, (R·b_i) × n_i] / d_i`` (module documentation): columns 0-2 per m/s of v,
        3-5 per rad/s of ω (base frame); rows in m/s (legs, slides) or rad/s (cranks). NaN rows
        for legs without an inverse-kinematics solution.
    """
    r = np.asarray(rotations, dtype=np.float64)
    base, platform = leg_endpoints(manipulator, r, positions)
    r = r[None] if r.ndim == 2 else r
    arm = np.einsum("nij,kj->nki", r, manipulator.platform_joints)  # R·b_i, (n, 6, 3)
    leg = platform - base
    n = leg / np.linalg.norm(leg, axis=-1, keepdims=True)
    legs = architecture_module(manipulator.architecture)
    q, _ = legs.inverse_kinematics(manipulator, platform)
    divisor = legs.transmission(manipulator, n, q) * legs.actuator_lever(manipulator)
    rows = np.concatenate([n, np.cross(arm, n)], axis=-1) / divisor[..., None]
    return np.asarray(rows, dtype=np.float64)


@dataclass(frozen=True)
class Loads:
    """The loads at one pose (:func:`loads_at`); +inf forces and deflections at a singular
    pose or one a leg cannot reach.

    Attributes
    ----------
    jacobian : ndarray, shape (6, 6)
        J (module documentation).
    singular : bool
        J numerically singular, or a leg without an inverse-kinematics solution.
    actuator_force : ndarray, shape (6,)
        τ⁰ = −J⁻ᵀ(w_grav + R₆·w₀): gravity plus the process centre, N or N·m (> 0 pushes).
    actuator_force_spread : ndarray, shape (6,)
        s_i: τ_i ranges over [τ⁰_i − s_i, τ⁰_i + s_i] over the process box.
    actuator_force_worst : ndarray, shape (6,)
        |τ⁰_i| + s_i, the largest |τ_i| over the box.
    force_margin : float or None
        min_i min(force_max_i − (τ⁰_i + s_i), (τ⁰_i − s_i) − force_min_i), N or N·m (< 0: an
        actuator cannot hold the load); None without force limits.
    limiting_actuator : int
        1-based actuator of ``force_margin`` (of the largest worst force without limits).
    payload_capacity : float or None
        The largest M such that every mass in [0, M] (this centre of mass and gravity, the
        process box included) is held, kg; 0 when not even no load is; None without limits.
    stiffness : ndarray, shape (6, 6) or None
        K = Jᵀ·diag(k)·J (rows/columns: translation N/m, rotation N·m/rad), base frame.
    deflection_m, deflection_rad : float or None
        Largest translation (m) and rotation (rad) of δ = K⁻¹·w over the process box's vertices.
    accuracy_m, accuracy_rad : float or None
        Largest translation and rotation of J⁻¹·δq over the error box's vertices.
    """

    jacobian: NDArray[np.float64]
    singular: bool
    actuator_force: NDArray[np.float64]
    actuator_force_spread: NDArray[np.float64]
    actuator_force_worst: NDArray[np.float64]
    force_margin: float | None
    limiting_actuator: int
    payload_capacity: float | None
    stiffness: NDArray[np.float64] | None
    deflection_m: float | None
    deflection_rad: float | None
    accuracy_m: float | None
    accuracy_rad: float | None


def _regular(jacobian: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Per pose, J (N, 6, 6) finite and not numerically singular (σ_min > SINGULAR_RATIO·σ_max)."""
    finite = np.all(np.isfinite(jacobian), axis=(1, 2))
    sigma = np.linalg.svd(np.where(finite[:, None, None], jacobian, np.eye(6)), compute_uv=False)
    regular: NDArray[np.bool_] = finite & (sigma[:, -1] > SINGULAR_RATIO * sigma[:, 0])
    return regular


def _rotation6(rotations: NDArray[np.float64]) -> NDArray[np.float64]:
    """R₆ = diag(R, R) per pose, (N, 6, 6)."""
    rotation6 = np.zeros((rotations.shape[0], 6, 6))
    rotation6[:, :3, :3] = rotation6[:, 3:, 3:] = rotations
    return rotation6


def _forces(
    inverse: NDArray[np.float64],
    rotations: NDArray[np.float64],
    rotation6: NDArray[np.float64],
    case: LoadCase,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Per pose (N, 6) each: the actuator forces per kg of payload, those of the process
    centre, and their spread over the process box (τ = −J⁻ᵀ·w, module documentation)."""
    to_forces = -np.swapaxes(inverse, 1, 2)
    g = case.gravity
    weight = np.concatenate(
        [np.broadcast_to(g, (rotations.shape[0], 3)), np.cross(rotations @ case.center_of_mass, g)],
        axis=1,
    )
    per_mass = np.einsum("nij,nj->ni", to_forces, weight)
    fixed = np.einsum("nij,nj->ni", to_forces, rotation6 @ case.wrench)
    spread: NDArray[np.float64] = np.abs(to_forces @ rotation6) @ case.wrench_range
    return per_mass, fixed, spread


def _force_distances(
    force: NDArray[np.float64],
    spread: NDArray[np.float64],
    low: NDArray[np.float64],
    high: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Per actuator, the distance of the force range [force − spread, force + spread] to the
    limits [low, high] (< 0: a limit is exceeded somewhere over the process box)."""
    distances: NDArray[np.float64] = np.minimum(high - (force + spread), (force - spread) - low)
    return distances


def _compliance(
    inverse: NDArray[np.float64], stiffness: NDArray[np.float64]
) -> NDArray[np.float64]:
    """K⁻¹ = J⁻¹·diag(1/k)·J⁻ᵀ per pose, (N, 6, 6)."""
    result: NDArray[np.float64] = inverse @ (np.swapaxes(inverse, 1, 2) / stiffness[:, None])
    return result


def _capacity(
    per_mass: NDArray[np.float64],
    fixed: NDArray[np.float64],
    spread: NDArray[np.float64],
    low: NDArray[np.float64],
    high: NDArray[np.float64],
) -> float:
    """The largest M ≥ 0 with low ≤ M·a + b − s and M·a + b + s ≤ high for all of [0, M]."""
    if np.any(fixed + spread > high) or np.any(fixed - spread < low):
        return 0.0
    capacity = math.inf
    for a, b, s, lo, hi in zip(per_mass, fixed, spread, low, high, strict=True):
        if a > 0.0:
            capacity = min(capacity, (hi - s - b) / a)
        elif a < 0.0:
            capacity = min(capacity, (lo + s - b) / a)
    return max(capacity, 0.0)


def _largest(
    inverse: NDArray[np.float64], centre: NDArray[np.float64], half: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per pose, the largest |translation| and |rotation| of ``inverse[n] @ (centre + σ∘half)``
    over σ ∈ {±1}⁶ (``inverse`` (N, 6, 6); (N,) each)."""
    moves = np.einsum("vj,nij->nvi", centre + _VERTICES * half, inverse)
    return (
        np.max(np.linalg.norm(moves[..., :3], axis=-1), axis=1),
        np.max(np.linalg.norm(moves[..., 3:], axis=-1), axis=1),
    )


def loads_at(
    manipulator: Manipulator, case: LoadCase, rotation: ArrayLike, position: ArrayLike
) -> Loads:
    """Actuator forces, payload capacity, stiffness, deflection and accuracy at one pose.

    Parameters
    ----------
    manipulator : Manipulator
        The model whose mobile frame's origin is the tool centre point (a tool-frame model).
    case : LoadCase
        Its centre of mass in the same mobile frame.
    rotation : array_like, shape (3, 3)
        R of the tool frame, base frame.
    position : array_like, shape (3,)
        The tool centre point, base frame, m.

    Returns
    -------
    Loads
    """
    r = np.asarray(rotation, dtype=np.float64).reshape(1, 3, 3)
    jacobians = actuator_jacobian(manipulator, r, position)
    jacobian = jacobians[0]
    singular = not bool(_regular(jacobians)[0])
    inf6 = np.full(6, math.inf)
    limited = case.force_max is not None and case.force_min is not None
    if singular:
        return Loads(
            jacobian=jacobian,
            singular=True,
            actuator_force=inf6,
            actuator_force_spread=inf6,
            actuator_force_worst=inf6,
            force_margin=-math.inf if limited else None,
            limiting_actuator=1,
            payload_capacity=0.0 if limited else None,
            stiffness=None if case.stiffness is None else np.full((6, 6), np.nan),
            deflection_m=None if case.stiffness is None else math.inf,
            deflection_rad=None if case.stiffness is None else math.inf,
            accuracy_m=None if case.actuator_error is None else math.inf,
            accuracy_rad=None if case.actuator_error is None else math.inf,
        )
    inverses = np.asarray(np.linalg.inv(jacobians), dtype=np.float64)  # J⁻¹: motion -> twist
    rotation6 = _rotation6(r)
    masses, fixeds, spreads = _forces(inverses, r, rotation6, case)
    per_mass, fixed, spread = masses[0], fixeds[0], spreads[0]
    force = case.mass * per_mass + fixed
    worst = np.abs(force) + spread
    margin: float | None = None
    capacity: float | None = None
    limiting = int(np.argmax(worst)) + 1
    if case.force_max is not None and case.force_min is not None:
        each = _force_distances(force, spread, case.force_min, case.force_max)
        margin = float(np.min(each))
        limiting = int(np.argmin(each)) + 1
        capacity = _capacity(per_mass, fixed, spread, case.force_min, case.force_max)
    stiffness = deflection_m = deflection_rad = None
    if case.stiffness is not None:
        stiffness = jacobian.T @ (case.stiffness[:, None] * jacobian)
        moved, turned = _largest(
            _compliance(inverses, case.stiffness) @ rotation6, case.wrench, case.wrench_range
        )
        deflection_m, deflection_rad = float(moved[0]), float(turned[0])
    accuracy_m = accuracy_rad = None
    if case.actuator_error is not None:
        moved, turned = _largest(inverses, np.zeros(6), case.actuator_error)
        accuracy_m, accuracy_rad = float(moved[0]), float(turned[0])
    return Loads(
        jacobian=jacobian,
        singular=False,
        actuator_force=force,
        actuator_force_spread=spread,
        actuator_force_worst=worst,
        force_margin=margin,
        limiting_actuator=limiting,
        payload_capacity=capacity,
        stiffness=stiffness,
        deflection_m=deflection_m,
        deflection_rad=deflection_rad,
        accuracy_m=accuracy_m,
        accuracy_rad=accuracy_rad,
    )


#: The loads' rows, in report order: the actuator force margin (N, or N·m for cranks), the
#: deflection margin and the accuracy margin (m).
LOAD_ROWS = ("actuator_force", "deflection", "accuracy")


@dataclass(frozen=True)
class LoadRows:
    """The loads' limits of one case as margins at N poses (module documentation, *Rows at
    poses*).

    Attributes
    ----------
    margins : dict of str to ndarray, shape (N,)
        The rows the case sets, in :data:`LOAD_ROWS` order: ``actuator_force`` (N or N·m),
        ``deflection`` and ``accuracy`` (m); >= 0 holds; −inf at a singular pose or where a leg
        has no inverse-kinematics solution.
    limiting_actuator : ndarray, shape (N,), int
        1-based actuator of ``actuator_force`` (0 when that row is not set).
    force_unit : str
        ``"N"`` or ``"N·m"`` (the architecture's).
    """

    margins: dict[str, NDArray[np.float64]]
    limiting_actuator: NDArray[np.int64]
    force_unit: str

    @functools.cached_property
    def holds(self) -> NDArray[np.bool_]:
        """(N,) bool: every row holds (NaN does not)."""
        held = np.ones(self.limiting_actuator.shape, dtype=bool)
        for margin in self.margins.values():
            held &= margin >= 0.0
        return held

    @functools.cached_property
    def violated(self) -> list[list[str]]:
        """Per pose, the names of the violated rows (:data:`LOAD_ROWS` order)."""
        broken = {name: ~(margin >= 0.0) for name, margin in self.margins.items()}
        return [
            [name for name in self.margins if broken[name][k]]
            for k in range(self.limiting_actuator.shape[0])
        ]


def load_rows(
    manipulator: Manipulator, case: LoadCase, rotations: ArrayLike, positions: ArrayLike
) -> LoadRows | None:
    """The limits ``case`` sets as margins at N poses, None when it sets none.

    Parameters
    ----------
    manipulator, case : Manipulator, LoadCase
        As for :func:`loads_at` (a tool-frame model, the centre of mass in its mobile frame).
    rotations : array_like, shape (N, 3, 3)
        R of the tool frame at each pose, base frame.
    positions : array_like, shape (3,) or (N, 3)
        The tool centre point, base frame, m.

    Returns
    -------
    LoadRows or None
    """
    names = case.limited_rows
    if not names:
        return None
    r = np.asarray(rotations, dtype=np.float64).reshape(-1, 3, 3)
    count = r.shape[0]
    p = np.broadcast_to(np.asarray(positions, dtype=np.float64), (count, 3))
    jacobian = actuator_jacobian(manipulator, r, p)
    # loads_at's formulas for every pose at once; singular poses answer -inf
    regular = _regular(jacobian)
    inverse: NDArray[np.float64] = np.linalg.inv(
        np.where(regular[:, None, None], jacobian, np.eye(6))
    )
    rotation6 = _rotation6(r)
    margins: dict[str, NDArray[np.float64]] = {}
    limiting: NDArray[np.int64] = np.zeros(count, dtype=np.int64)
    if "actuator_force" in names:
        assert case.force_max is not None and case.force_min is not None
        per_mass, fixed, spread = _forces(inverse, r, rotation6, case)
        force = case.mass * per_mass + fixed
        each = _force_distances(force, spread, case.force_min, case.force_max)
        margins["actuator_force"] = np.where(regular, np.min(each, axis=1), -math.inf)
        limiting = np.where(regular, np.argmin(each, axis=1) + 1, 1).astype(np.int64)
    if "deflection" in names:
        assert case.stiffness is not None
        compliance = _compliance(inverse, case.stiffness) @ rotation6
        worst, _ = _largest(compliance, case.wrench, case.wrench_range)
        margins["deflection"] = np.where(regular, case.deflection_max - worst, -math.inf)
    if "accuracy" in names:
        assert case.actuator_error is not None
        worst, _ = _largest(inverse, np.zeros(6), case.actuator_error)
        margins["accuracy"] = np.where(regular, case.accuracy_max - worst, -math.inf)
    unit = architecture_module(manipulator.architecture).FORCE_UNIT
    return LoadRows(margins=margins, limiting_actuator=limiting, force_unit=unit)
