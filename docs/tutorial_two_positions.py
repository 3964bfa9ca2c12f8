"""Bonev & Ryu's two positions with the packaged example GPM: the tutorial's figures and table.

Usage: python docs/tutorial_two_positions.py [OUT_DIR]   (default: tutorial_out)

The documentation build runs this very file (``docs/_ext/hexapod_docs.py``) and shows its
figures and what it prints, so the tutorial page cannot differ from what the code does.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from hexapod_workspace import example_manipulator, orientation_workspace, projected_workspace
from hexapod_workspace.cli.plotting import plot_orientation, plot_projected

out_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("tutorial_out")
out_dir.mkdir(parents=True, exist_ok=True)

# The packaged example (config/example_gpm.yaml): axisymmetric, the platform
# hanging below the base, at the scale of the paper's Fig. 1.
machine = example_manipulator()

# The paper analyses its machine on the axis of symmetry and off it.
positions = {"on_axis": (0.0, 0.0, -1.3), "off_axis": (0.2, 0.2, -0.95)}

print("case      position [m]        tilt psi=0 [deg]  tilt exact [deg]  psi [deg]")
for name, position in positions.items():
    # The paper's projected workspace: first violation per azimuth at psi = 0 ...
    paper = projected_workspace(machine, position)
    # ... and the true shadow of the workspace (the best torsion per azimuth).
    exact = projected_workspace(machine, position, method="exact")
    # The 3-D orientation workspace, cylindrical picture (theta, phi polar; psi up).
    solid = orientation_workspace(machine, position)

    plot_projected([paper, exact], out_dir / f"projected_{name}.png")
    plot_orientation(solid, out_dir / f"orientation_{name}.png")

    def deg(*angles: float) -> str:
        return "..".join(f"{math.degrees(angle):.2f}" for angle in angles)

    where = "(" + ", ".join(f"{v:g}" for v in position) + ")"
    print(
        f"{name:9} {where:19} {deg(paper.tilt_min, paper.tilt_max):17} "
        f"{deg(exact.tilt_min, exact.tilt_max):17} {deg(solid.psi_min, solid.psi_max)}"
    )
    assert exact.gap is not None
    gap = math.degrees(float(np.max(exact.gap)))
    print(f"{'':10}psi = 0 inside exact by up to {gap:.2f} deg, volume {solid.volume:.4f} rad^3")
