"""The figure of docs/collision.md, "Seeing the scene": the example machine with the page's
collision scene (platform, tool, a vise and a column), the vise raised so that the tool, tilted
15° at 1.45 m below the base, touches it within the clearance: the pair in violation is drawn in
red. Drawn by the CLI's scene plot; run by the docs build (``docs/_ext/hexapod_docs.py``) with
the output folder as argument.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from hexapod_workspace._resources import example_config_path
from hexapod_workspace.cli.scene import view_at
from hexapod_workspace.cli.scene_plot import plot_scene
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.core.model.collision import collision_scene, require_free_home

#: The scene of the page's YAML example (collision.* as the parameters file gives them), with
#: the vise's top at z = -1.49 m instead of -1.70 m.
SCENE = {
    "collision.clearance": 0.005,
    "collision.platform.radius": 0.33,
    "collision.platform.z_min": 0.08,
    "collision.platform.z_max": 0.14,
    "collision.tool.radius": 0.04,
    "collision.tool.length": 0.25,
    "collision.obstacles.names": ["vise", "column"],
    "collision.obstacles.vise.shape": "box",
    "collision.obstacles.vise.position": [0.0, 0.0, -1.54],
    "collision.obstacles.vise.size": [0.3, 0.2, 0.1],
    "collision.obstacles.column.shape": "cylinder",
    "collision.obstacles.column.position": [0.75, 0.0, -0.8],
    "collision.obstacles.column.radius": 0.1,
    "collision.obstacles.column.length": 1.2,
}


def main(out_dir: Path) -> None:
    manipulator = load_manipulator(example_config_path())
    scene = require_free_home(manipulator, collision_scene(SCENE))
    view = view_at(manipulator, np.radians([0.0, 15.0, 0.0]), [0.05, 0.0, -1.45], scene)
    path = plot_scene(view, out_dir / "scene.png")
    pair = view.closest
    assert pair is not None
    print(f"{pair.name}: {1000.0 * pair.margin:.1f} mm ({pair.constraint}); {path.name}")


if __name__ == "__main__":
    folder = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    folder.mkdir(parents=True, exist_ok=True)
    main(folder)
