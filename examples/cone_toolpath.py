#!/usr/bin/env python3
"""A 5-axis toolpath around the packaged example where ψ ≡ 0 fails and a planned torsion passes.

The tool tip follows a helix of radius 20 mm around the off-axis point (0.2, 0.2, −0.95) m,
two turns rising 10 mm towards the base, and the tool axis sweeps a cone of half-angle 17°
about the base z-axis in step with the helix (a ball-end tool with a constant lead angle, the
axis always tilted away from the helix centre). The paper's recommendation, "assign φ and θ and keep
ψ = 0", fails on part of it; :func:`hexapod_workspace.plan_torsion` chooses the torsion at every
waypoint so that every waypoint and every move (slerp) is certified reachable, changing the
torsion by at most 5° per move (``max_dpsi``; ``check-path --max-dpsi-deg 5``).

Writes ``cone_toolpath.csv`` (columns x,y,z,i,j,k: the input of
``hexapod-workspace check-path``), the plot, and prints the numbers of the README section.

Usage: python examples/cone_toolpath.py [--out DIR] [--waypoints N]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from hexapod_workspace import plan_torsion
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.cli.check_path import plot_path
from hexapod_workspace.core.base.rotations import approach_vector
from hexapod_workspace.core.evaluation.loading import load_manipulator

CENTER = np.array([0.2, 0.2, -0.95])  # m, the demo's off-axis position
RADIUS = 0.02  # m
RISE = 0.01  # m over the whole helix (towards the base)
TURNS = 2
TILT = math.radians(17.0)  # half-angle of the cone of tool axes
MAX_DPSI = math.radians(5.0)  # largest torsion change per move of the plan


def toolpath(count: int) -> tuple[np.ndarray, np.ndarray]:
    """Positions (N, 3), m, and tool axes (N, 3) of the helix."""
    angle = np.linspace(0.0, TURNS * 2.0 * np.pi, count)
    positions = CENTER + np.column_stack(
        [
            RADIUS * np.cos(angle),
            RADIUS * np.sin(angle),
            RISE * angle / angle[-1],
        ]
    )
    return positions, approach_vector(angle, TILT)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="examples_out", help="output folder")
    parser.add_argument("--waypoints", type=int, default=720)
    parser.add_argument("--plot", help="PNG path (default: OUT/cone_toolpath.png)")
    options = parser.parse_args()
    out = Path(options.out)
    out.mkdir(parents=True, exist_ok=True)
    manipulator = load_manipulator(example_config_path())
    positions, axes = toolpath(options.waypoints)
    csv = out / "cone_toolpath.csv"
    np.savetxt(
        csv,
        np.column_stack([positions, axes]),
        delimiter=",",
        header="x,y,z,i,j,k",
        comments="",
        fmt="%.9f",
    )
    plan = plan_torsion(manipulator, positions, axes, max_dpsi=MAX_DPSI)
    baseline = plan.baseline
    plot = Path(options.plot) if options.plot else out / "cone_toolpath.png"
    plot_path(plan, baseline, manipulator, plot)
    print(
        f"toolpath: {len(positions)} waypoints, helix r = {RADIUS * 1e3:g} mm around "
        f"{CENTER.tolist()} m, {TURNS} turns rising {RISE * 1e3:g} mm, "
        f"tool axes on a {math.degrees(TILT):g} deg cone"
    )
    print(
        f"psi = 0: {len(baseline.failed_waypoints)} of {len(positions)} waypoints and "
        f"{len(baseline.failed_segments)} of {len(positions) - 1} moves fail; smallest "
        f"relative margin {baseline.waypoints.relative.min():.3f}"
    )
    if plan.ok:
        psi = np.degrees(plan.psi)
        path = plan.path
        print(
            f"planned torsion: every waypoint and move certified ok: {path.ok}; psi "
            f"{psi.min():.1f} .. {psi.max():.1f} deg (grid {math.degrees(plan.psi_step):g} "
            f"deg), largest change per move {np.abs(np.diff(psi)).max():.1f} deg"
        )
        print(
            f"  smallest relative margin: certified {plan.objective:.3f} (objective), "
            f"{path.segments.min_relative_margin_bound.min():.3f} re-checked, "
            f"{path.waypoints.relative.min():.3f} at the waypoints"
        )
        print(f"  planned in {plan.elapsed:.2f} s ({plan.moves_checked} moves checked in full)")
    else:
        print(f"no plan: {plan.breakpoint.reason}")
    print(f"wrote {csv} and {plot}")


if __name__ == "__main__":
    main()
