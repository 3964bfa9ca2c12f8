"""The scene as drawn (core/scene_view, the CLI's scene command and check-path's scene plot).

The closest leg pair is checked against the compiled kernels' leg_interference margin, the
collision pair against scene_distances, and the drawn closest points against the distance they
must realise; the CLI writes real PNG files without pyplot.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
from cli_support import run_cli

from hexapod_workspace import check
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.cell.scene_view import scene_view
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.core.model.collision import (
    collision_scene,
    require_free_home,
    scene_distances,
)

SCENE = {
    "collision.clearance": 0.005,
    "collision.platform.radius": 0.33,
    "collision.platform.z_min": 0.08,
    "collision.platform.z_max": 0.14,
    "collision.tool.radius": 0.04,
    "collision.tool.length": 0.25,
    "collision.obstacles.names": ["vise", "ball"],
    "collision.obstacles.vise.shape": "box",
    "collision.obstacles.vise.position": [0.0, 0.0, -1.75],
    "collision.obstacles.vise.size": [0.3, 0.2, 0.1],
    "collision.obstacles.ball.shape": "sphere",
    "collision.obstacles.ball.position": [0.45, 0.0, -1.5],
    "collision.obstacles.ball.radius": 0.08,
}


def test_closest_pair_matches_the_kernels_and_the_collision_distances():
    model = load_manipulator(example_config_path())
    scene = require_free_home(model, collision_scene(SCENE))
    rng = np.random.default_rng(3)
    for _ in range(60):
        angles = np.array([rng.uniform(-np.pi, np.pi), rng.uniform(0, 0.5), rng.uniform(-1, 1)])
        position = np.array([0.0, 0.0, -1.3]) + rng.uniform(-0.15, 0.15, 3)
        rotation = tt_to_matrix(angles)
        alone = scene_view(model, rotation, position)
        kernel = check(model, angles, position).margins["leg_interference"][0]
        assert alone.closest is not None and alone.closest.constraint == "leg_interference"
        np.testing.assert_allclose(alone.closest.margin, kernel, atol=1e-9)
        a, b = alone.closest.points
        np.testing.assert_allclose(np.linalg.norm(b - a) - model.leg_diameter, kernel, atol=1e-9)
        view = scene_view(model, rotation, position, scene)
        collision = scene_distances(model, scene, rotation, position)
        expected = min(kernel, float(collision.margin[0]))
        np.testing.assert_allclose(view.closest.margin, expected, atol=1e-12)
        if view.closest.constraint == "collision" and view.closest.margin > 0:
            # the drawn points realise the distance (alternating projections converged)
            a, b = view.closest.points
            distance = view.closest.margin + scene.clearance
            np.testing.assert_allclose(np.linalg.norm(b - a), distance, atol=1e-4)
        assert [b.name for b in view.bodies] == [
            *(f"leg {k}" for k in range(1, 7)),
            "platform",
            "tool",
            "vise",
            "ball",
        ]


def test_scene_command_writes_the_picture_and_names_the_pair(tmp_path):
    plot = tmp_path / "scene.png"
    done = run_cli("scene", "--pose", "0", "20", "0", "--plot", str(plot), "--json")
    assert done.returncode == 0, done.stderr
    document = json.loads(done.stdout)
    assert document["closest_pair"] == "leg 1 vs leg 6"
    assert document["constraint"] == "leg_interference" and not document["violated"]
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    refused = run_cli("scene", "--pose", "0", "nan", "0", "--plot", str(plot))
    assert refused.returncode == 2 and "--pose" in refused.stderr


def test_check_path_plot_draws_the_first_violation(tmp_path):
    path = tmp_path / "path.csv"
    path.write_text(
        "x,y,z,phi_deg,theta_deg,psi_deg\n0,0,-1.3,0,0,0\n0.1,0,-1.3,0,30,0\n0.2,0,-1.25,0,60,0\n"
    )
    plot = tmp_path / "path.png"
    done = run_cli("check-path", str(path), "--plot", str(plot))
    assert done.returncode == 1
    scene = tmp_path / "path-scene.png"
    assert f"scene at the first violation: {scene}" in done.stdout
    assert scene.read_bytes()[:4] == b"\x89PNG"


def test_scene_plot_uses_no_pyplot(tmp_path):
    code = (
        "import sys, numpy as np\n"
        "from hexapod_workspace import load_manipulator\n"
        "from hexapod_workspace._resources import example_config_path\n"
        "from hexapod_workspace.cli.scene import view_at\n"
        "from hexapod_workspace.cli.scene_plot import plot_scene\n"
        "m = load_manipulator(example_config_path())\n"
        f"plot_scene(view_at(m, [0, 0.2, 0], [0, 0, -1.3], None), {str(tmp_path / 'a.png')!r})\n"
        "print('matplotlib.pyplot' in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "False"
