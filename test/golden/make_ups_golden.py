"""Golden 6-UPS answers of the packaged example, computed by the code *before* the constraint table.

Run from a checkout of commit 3c6da1e (the last main commit before the constraint table, the
architectures and the singularity margin), e.g.::

    git archive 3c6da1e | tar -x -C /tmp/src
    PYTHONPATH=/tmp/src NUMBA_CACHE_DIR=/tmp/numba python test/golden/make_ups_golden.py OUT.npz

test/test_ups_golden.py compares today's code against the stored file (verdicts identical,
margins within 1e-12, workspace boundaries within 1e-12 rad). The ``*_off_volume`` entries were
since replaced by this script's answers at the commit that searches the torsion extremes in 16
directions (its test's docstring says why).
"""

from __future__ import annotations

import sys

import numpy as np

from hexapod_workspace import (
    check,
    check_path,
    orientation_workspace,
    projected_workspace,
    torsion_range,
)
from hexapod_workspace.core.evaluation.loading import example_manipulator, manipulator_from_mapping

CONSTRAINTS = ("leg_length", "base_joint", "platform_joint", "leg_interference")


def poses(count: int = 4000) -> np.ndarray:
    """Seeded poses around the workspace (phi, theta, psi), rad."""
    rng = np.random.default_rng(17)
    return np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, 1.2, count),
            rng.uniform(-2.0, 2.0, count),
        ]
    )


def positions(count: int = 4000) -> np.ndarray:
    rng = np.random.default_rng(18)
    return np.array([0.0, 0.0, -1.2]) + rng.normal(scale=0.15, size=(count, 3))


def answers() -> dict[str, np.ndarray]:
    """Every golden array, by name, computed by the code that is imported."""
    m = example_manipulator()
    diameter = manipulator_from_mapping({**m.to_parameters(), "limits.leg_diameter": 0.05})
    arrays: dict[str, np.ndarray] = {"angles": poses()}
    for label, machine in (("example", m), ("diameter", diameter)):
        result = check(machine, arrays["angles"])
        arrays[f"{label}_reachable"] = result.reachable
        for name in CONSTRAINTS:
            arrays[f"{label}_margin_{name}"] = result.margins[name]
            arrays[f"{label}_leg_{name}"] = result.limiting_legs[name]
        arrays[f"{label}_limiting_constraint"] = result.limiting_constraint
        arrays[f"{label}_limiting_leg"] = result.limiting_leg
        arrays[f"{label}_pair"] = result.limiting_pair
        for position_label, position in (("on", (0.0, 0.0, -1.3)), ("off", (0.2, 0.2, -0.95))):
            key = f"{label}_{position_label}"
            for method in ("torsion_zero", "exact"):
                workspace = projected_workspace(machine, position, method=method, n_phi=90)
                arrays[f"{key}_{method}_theta"] = workspace.theta
                arrays[f"{key}_{method}_psi"] = workspace.psi
                arrays[f"{key}_{method}_limiting"] = np.array(workspace.limiting)
            volume = orientation_workspace(machine, position, n_rays=36, psi_step=0.05)
            arrays[f"{key}_volume"] = np.array([volume.psi_min, volume.psi_max, volume.volume])
            ranges = torsion_range(machine, 0.7, 0.3, position)
            arrays[f"{key}_torsion"] = np.array(ranges.intervals, dtype=float).ravel()
    waypoints = positions(40)
    angles = poses(40) * np.array([1.0, 0.5, 0.5])
    path = check_path(m, waypoints, angles=angles)
    arrays["path_ok"] = path.segments.ok
    arrays["path_first_bad"] = path.segments.first_violation_s
    arrays["path_bound"] = path.segments.min_relative_margin_bound
    arrays["path_min"] = path.segments.min_relative_margin
    return arrays


def main(out: str) -> None:
    np.savez_compressed(out, **answers())


if __name__ == "__main__":
    main(sys.argv[1])
