#!/usr/bin/env python3
"""Workspace computations: absolute times and the ratio against the paper's literal procedure.

Measured in one run on the packaged example at the on-axis position (0, 0, -1.3) m, all four
constraints on:

* ``torsion_zero``, 360 azimuths, tolerance 1e-6 rad, against a literal implementation of
  Bonev & Ryu's projected algorithm (per-pose checks, delta theta = 0.1 deg, each ray started
  m = 5 steps below the previous boundary; :func:`hexapod_workspace.reference.
  paper_projected_workspace`), which is also compared point by point;
* ``exact``, 360 azimuths;
* the 3-D orientation workspace, 180 rays, delta psi = 1 deg, tolerance 1e-5 rad;
* one torsion range.

Usage: python benchmarks/workspaces.py [--position X Y Z] [--repeats N]
"""

from __future__ import annotations

import argparse
import math
import os
import time

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(variable, "1")

import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

# The literal reference is a test oracle (test/reference.py), not part of the package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))

from reference import paper_projected_workspace  # noqa: E402

from hexapod_workspace import (  # noqa: E402
    Manipulator,
    orientation_workspace,
    projected_workspace,
    torsion_range,
)
from hexapod_workspace._resources import example_config_path  # noqa: E402


def best_of(repeats: int, function):
    best, result = math.inf, None
    for _ in range(repeats):
        started = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - started)
    return best, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--position", nargs=3, type=float, default=[0.0, 0.0, -1.3])
    parser.add_argument("--repeats", type=int, default=3)
    options = parser.parse_args()
    manipulator = Manipulator.from_params_file(example_config_path())
    position = np.array(options.position)
    repeats = options.repeats

    projected_workspace(manipulator, position, n_phi=36)  # warm up
    t_zero, zero = best_of(
        repeats, lambda: projected_workspace(manipulator, position, n_phi=360, tolerance=1e-6)
    )
    t_paper, paper = best_of(1, lambda: paper_projected_workspace(manipulator, position, 360))
    t_exact, exact = best_of(
        repeats, lambda: projected_workspace(manipulator, position, method="exact", n_phi=360)
    )
    t_solid, solid = best_of(
        repeats,
        lambda: orientation_workspace(
            manipulator, position, n_rays=180, psi_step=math.radians(1.0), tolerance=1e-5
        ),
    )
    t_torsion, _ = best_of(
        repeats, lambda: torsion_range(manipulator, 0.5, math.radians(20.0), position)
    )
    deviation = np.degrees(paper - zero.theta)

    print(
        "workspace benchmark, packaged example at position "
        f"({position[0]:g}, {position[1]:g}, {position[2]:g}) m, all four constraints, "
        f"best of {repeats}"
    )
    print(f"{'case':<44} {'time':>10} {'goal':>9}  result")
    rows = [
        (
            "torsion_zero, 360 rays, tol 1e-6 rad",
            t_zero,
            0.020,
            f"tilt {math.degrees(zero.tilt_min):.3f}..{math.degrees(zero.tilt_max):.3f} deg, "
            f"{zero.evaluations} poses",
        ),
        (
            "paper's procedure (literal), 360 rays",
            t_paper,
            None,
            f"0.1 deg grid, boundary {deviation.min():+.3f}..{deviation.max():+.3f} deg from ours",
        ),
        (
            "exact, 360 rays, tol 1e-6 rad",
            t_exact,
            0.5,
            f"tilt {math.degrees(exact.tilt_min):.3f}..{math.degrees(exact.tilt_max):.3f} deg, "
            f"gap <= {math.degrees(float(exact.gap.max())):.3f} deg, {exact.evaluations} poses",
        ),
        (
            "3-D, 180 rays, dpsi 1 deg, tol 1e-5 rad",
            t_solid,
            1.0,
            f"psi {math.degrees(solid.psi_min):.3f}..{math.degrees(solid.psi_max):.3f} deg, "
            f"{len(solid.slices)} slices, {solid.evaluations} poses",
        ),
        ("torsion range, one direction, tol 1e-6", t_torsion, None, ""),
    ]
    for name, seconds, goal, text in rows:
        goal_text = (
            "" if goal is None else f"<= {goal * 1e3:.0f} ms" if goal < 1 else f"<= {goal:g} s"
        )
        status = "" if goal is None else (" met" if seconds <= goal else " NOT met")
        print(f"{name:<44} {seconds * 1e3:8.1f} ms {goal_text:>9}{status:<8} {text}")
    ratio = t_paper / t_zero
    print(
        f"ratio paper's procedure / torsion_zero: {ratio:.0f} x (goal >= 300 x: "
        f"{'met' if ratio >= 300 else 'NOT met'}); the paper reports 20 s (projected) and "
        "40 min (3-D) on a 350 MHz PC"
    )


if __name__ == "__main__":
    main()
