"""The package's ``check`` against the plain-numpy reference (test/reference_arch.py), per leg
architecture, over at least 10⁵ random poses each: the packaged example of each architecture
(10⁵ poses over six positions) and one variant with per-leg limits, explicit joint axes, an
enforced singularity margin and architecture-specific changes (4·10⁴ more poses).

Written against the planned public contract only: ``load_manipulator`` reads
the architecture keys; ``check(manipulator, angles, position, singularity=True)`` (σ_min
reported even where not enforced) returns ``margins`` by name
(``leg_length`` for ups, ``actuator`` for pus/rus, ``ik``, ``transmission``, ``base_joint``,
``platform_joint``, ``leg_interference``, ``singularity``), shape (N,), NaN where undefined,
``reachable`` and ``violated`` by name.

Tolerance. Both sides evaluate the same closed forms in double precision on inputs of order
1 m; each margin is a composition of well-conditioned steps except two: the inverse kinematics
near ik = 0 (dq/dΔ = 1/(2√Δ): a rounding of the discriminant, ~1e-16 m², moves q by ~1e-16/√Δ),
and a joint angle near 0 through arccos (error up to √ε ≈ 1.5e-8 rad). Away from those, the
margins agree to ~1e-14; we require 1e-9 (m, rad, or dimensionless for ``transmission`` and
``singularity``), and 1e-6 on the poses whose smallest ik margin is below 1e-6 m (none of the
10⁵ random poses is that close, in practice). ``singularity`` adds ε·‖M‖²/σ_min (at most
3e-14/σ_min), the error of σ_min computed as √λ_min(MᵀM) rather than by an SVD of M: random
poses come within 1e-6 of a singular one. A verdict may differ only where the reference's
deciding margin is within the tolerance of zero (a tie, counted and bounded).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import reference_arch as ra
import yaml

from hexapod_workspace import Manipulator
from hexapod_workspace.core.evaluation.check import check
from hexapod_workspace.core.evaluation.loading import load_manipulator

CONFIG = Path(__file__).resolve().parents[1] / "config"
EXAMPLES = {"ups": "example_gpm.yaml", "pus": "example_pus.yaml", "rus": "example_rus.yaml"}
TOLERANCE = 1e-9
ILL_CONDITIONED_IK = 1e-6  # m: below this ik margin the coordinate itself is ill-conditioned
LOOSE_TOLERANCE = 1e-6
#: σ_min from the eigenvalues of MᵀM (as opposed to an SVD of M) has an absolute error up to
#: ε·‖M‖²/σ_min, ‖M‖² ≤ ‖M‖_F² ≤ 12 (unit rows, moments over ρ ≤ 1): 10 × 12 × 2.2e-16.
SIGMA_ROUNDING = 3e-14
POSITIONS = 6
EXAMPLE_POSES = 100_002
VARIANT_POSES = 40_000


def document(path: Path) -> dict[str, Any]:
    return yaml.safe_load(path.read_text(encoding="utf-8"))


def variant_document(architecture: str, rng: np.random.Generator) -> dict[str, Any]:
    """The example with six different values per limit, explicit (tilted) joint axes, an
    enforced singularity margin and, per architecture, a less regular geometry."""
    path = CONFIG / EXAMPLES[architecture]
    tree = document(path)
    parameters = tree["hexapod_workspace"]["ros__parameters"]
    geometry, limits = parameters["geometry"], parameters["limits"]
    reference = ra.load(path)
    spread = np.linspace(-1.0, 1.0, 6)
    if architecture == "ups":
        limits["leg_length_min"] = (0.80 + 0.01 * spread).tolist()
        limits["leg_length_max"] = (1.45 + 0.02 * spread).tolist()
    else:
        low, high = float(reference.actuator_min[0]), float(reference.actuator_max[0])
        half = 0.5 * (high - low)
        limits["actuator_min"] = (low + 0.1 * half * (spread + 1.0)).tolist()
        limits["actuator_max"] = (high - 0.1 * half * (1.0 - spread)).tolist()
        limits["transmission_min"] = 0.3
        geometry["leg_lengths"] = (reference.leg_lengths * (1.0 + 0.004 * spread)).tolist()
    if architecture == "pus":
        # Rails no longer parallel: each turned by up to 6 deg (normalised by the loader).
        rails = reference.rail_directions + rng.uniform(-0.1, 0.1, (6, 3))
        geometry["rail_directions"] = rails.ravel().tolist()
    if architecture == "rus":
        geometry["crank_lengths"] = (reference.crank_lengths * (1.0 + 0.05 * spread)).tolist()
    limits["singularity_min"] = 0.05
    limits["base_joint_max_angle"] = (0.75 + 0.05 * spread).tolist()
    limits["platform_joint_max_angle"] = (0.75 - 0.05 * spread).tolist()
    tilt = rng.uniform(-0.15, 0.15, (2, 6, 3))
    geometry["base_joint_axes"] = (reference.base_joint_axes + tilt[0]).ravel().tolist()
    geometry["platform_joint_axes"] = (reference.platform_joint_axes + tilt[1]).ravel().tolist()
    return tree


def random_angles(rng: np.random.Generator, count: int) -> np.ndarray:
    return np.column_stack(
        [
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(0.0, math.radians(40.0), count),
            rng.uniform(-math.radians(45.0), math.radians(45.0), count),
        ]
    )


def disagreements(
    label: str,
    reference_model: ra.ReferenceModel,
    manipulator: Manipulator,
    angles: np.ndarray,
    position: np.ndarray,
    counts: dict[str, int],
) -> list[str]:
    """Every difference between the package and the reference on these poses, one line each
    (pose, margin, both values)."""
    result = check(manipulator, angles, position, singularity=True)
    reference = ra.evaluate(reference_model, angles, position)
    lines: list[str] = []

    def note(k: int, what: str) -> None:
        phi, theta, psi = np.degrees(angles[k])
        pose = f"(phi, theta, psi) = ({phi:.6f}, {theta:.6f}, {psi:.6f}) deg"
        lines.append(f"{label} at p = {position.round(6).tolist()} m, {pose}: {what}")

    names = ra.MARGIN_NAMES[reference_model.architecture]
    enforced_singularity = reference_model.singularity_min > 0.0
    required = [n for n in names if n != "singularity" or enforced_singularity]
    missing = [n for n in required if n not in result.margins]
    if missing:
        return [f"{label}: margins {missing} missing (package gives {sorted(result.margins)})"]

    ik = reference.per_leg.get("ik")
    smallest_ik = ik.min(axis=1) if ik is not None else np.full(len(angles), np.inf)
    tolerance = np.where(
        (smallest_ik >= 0.0) & (smallest_ik < ILL_CONDITIONED_IK), LOOSE_TOLERANCE, TOLERANCE
    )
    counts["ill_conditioned"] += int((tolerance > TOLERANCE).sum())
    tie = np.zeros(len(angles), dtype=bool)
    package_violated = result.violated
    for name in names:
        if name not in result.margins:
            continue  # singularity not reported by this package build and not enforced
        ours, theirs = reference.margins[name], np.asarray(result.margins[name], dtype=float)
        if theirs.shape != ours.shape:
            return [f"{label}: margins[{name!r}] has shape {theirs.shape}, expected {ours.shape}"]
        optional = name == "singularity" and not enforced_singularity
        undefined = np.isnan(ours)
        if optional:  # a report the caller did not ask for: null (NaN or +inf) is allowed
            compared = ~undefined & np.isfinite(theirs)
        else:
            for k in np.flatnonzero(undefined != np.isnan(theirs))[:20]:
                note(k, f"{name}: package {theirs[k]!r}, reference {ours[k]!r} (null mismatch)")
            compared = ~undefined & ~np.isnan(theirs)
        both_infinite = np.isinf(ours) & (ours == theirs)
        with np.errstate(invalid="ignore"):
            error = np.where(both_infinite, 0.0, np.abs(theirs - ours))
        allowed = tolerance
        if name == "singularity":
            sigma = np.abs(ours + reference_model.singularity_min)
            allowed = tolerance + SIGMA_ROUNDING / np.maximum(sigma, 1e-300)
        if name == "ik":
            # The sign is the contract (negative exactly when there is no solution); the value
            # is compared below too (the definition in reference_arch's docstring).
            for k in np.flatnonzero((theirs < 0.0) != (ours < 0.0))[:20]:
                note(k, f"ik sign: package {theirs[k]!r}, reference {ours[k]!r}")
        for k in np.flatnonzero(compared & ~(error <= allowed))[:20]:
            note(
                k,
                f"{name}: package {theirs[k]!r}, reference {ours[k]!r}, difference {error[k]:.3e}",
            )
        counts[f"compared {name}"] += int(compared.sum())
        if name in reference.enforced:
            near = compared & (np.abs(ours) <= tolerance)
            tie |= near
            listed = np.array([name in names_k for names_k in package_violated])
            wrong = ~undefined & ~near & (listed != (ours < 0.0))
            for k in np.flatnonzero(wrong)[:20]:
                note(
                    k,
                    f"violated[{name!r}]: package {package_violated[k]}, reference "
                    f"margin {ours[k]!r}",
                )
    counts["ties"] += int(tie.sum())
    unsolved = np.isnan(reference.q).any(axis=1)
    counts["no ik"] += int(unsolved.sum())
    counts["reachable"] += int(reference.reachable.sum())
    counts["poses"] += len(angles)
    for k in np.flatnonzero((result.reachable != reference.reachable) & ~tie)[:20]:
        note(
            k,
            f"reachable: package {bool(result.reachable[k])}, reference "
            f"{bool(reference.reachable[k])} (reference violated {reference.violated()[k]})",
        )
    for k in np.flatnonzero(unsolved)[:2000]:
        if "ik" not in package_violated[k] or result.reachable[k]:
            note(
                k,
                f"no IK solution: package violated {package_violated[k]}, reachable "
                f"{bool(result.reachable[k])}",
            )
            break
    return lines


def run(label: str, path: Path, rng: np.random.Generator, poses: int) -> dict[str, int]:
    manipulator = load_manipulator(path)
    reference_model = ra.load(path)
    counts: dict[str, int] = {
        key: 0 for key in ("poses", "reachable", "no ik", "ties", "ill_conditioned")
    }
    counts.update({f"compared {n}": 0 for n in ra.MARGIN_NAMES[reference_model.architecture]})
    per_position = max(1, poses // POSITIONS)
    lines: list[str] = []
    for index in range(POSITIONS):
        offset = np.zeros(3) if index == 0 else rng.uniform(-0.12, 0.12, 3)
        position = reference_model.home_position + offset
        angles = random_angles(rng, per_position)
        lines += disagreements(label, reference_model, manipulator, angles, position, counts)
    assert not lines, f"{len(lines)} disagreement(s):\n" + "\n".join(lines[:60])
    return counts


def check_mix(counts: dict[str, int]) -> None:
    """The random poses exercise both verdicts (and, for pus/rus, legs without a solution)."""
    assert 0.05 < counts["reachable"] / counts["poses"] < 0.95, counts
    assert counts["ties"] <= 1e-4 * counts["poses"], counts


@pytest.mark.parametrize("architecture", ["ups", "pus", "rus"])
def test_packaged_example_agrees_with_the_reference(architecture):
    rng = np.random.default_rng({"ups": 1701, "pus": 1702, "rus": 1703}[architecture])
    counts = run(architecture, CONFIG / EXAMPLES[architecture], rng, EXAMPLE_POSES)
    assert counts["poses"] >= 100_000
    check_mix(counts)
    if architecture != "ups":
        assert counts["no ik"] > 0, counts


@pytest.mark.parametrize("architecture", ["ups", "pus", "rus"])
def test_variant_agrees_with_the_reference(architecture, tmp_path):
    rng = np.random.default_rng({"ups": 1711, "pus": 1712, "rus": 1713}[architecture])
    path = tmp_path / f"variant_{architecture}.yaml"
    path.write_text(yaml.safe_dump(variant_document(architecture, rng)), encoding="utf-8")
    counts = run(f"{architecture} variant", path, rng, VARIANT_POSES)
    assert counts["poses"] >= 39_996
    assert counts["compared singularity"] > 0.5 * (counts["poses"] - counts["no ik"]), counts
    check_mix(counts)
