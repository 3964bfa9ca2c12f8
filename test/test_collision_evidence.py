"""The ``collision`` row in the certified searches, against dense sampling with a plain-numpy
reference (not the package's kernels):

- moving base joints (6-PUS, 6-RUS packaged examples) with a scene: certified moves and the
  projected boundary;
- the orientation and the projected workspaces of 6-UPS with a scene: every boundary point's
  ray is collision-free and reachable on a dense grid up to the boundary, and the pose one
  tolerance beyond is violated.

The reference is ``test/reference_arch.py`` (kinematics and the other margins, from the
formulas) plus the distances of this file: the scene is a tool capsule and sphere obstacles,
so that every pair is a segment against a segment or a point (closed forms in numpy: leg
capsules from the reference's own base-side ends, so a slide or crank moves the leg body).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import reference_arch as ra
from test_architectures_boundaries import interpolate

from hexapod_workspace import check_path, projected_workspace
from hexapod_workspace.core.base.params import flatten, load_params_file
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping
from hexapod_workspace.core.workspaces.orientation import orientation_workspace

CONFIG = Path(__file__).resolve().parents[1] / "config"
EXAMPLES = {"ups": "example_gpm.yaml", "pus": "example_pus.yaml", "rus": "example_rus.yaml"}
TOLERANCE = 1e-6  # rad: boundary tolerance asked of the package
GRID = 1e-3  # rad: the reference's sampling step
CLEARANCE = 0.002  # m
TOOL_RADIUS = 0.03  # m
#: Waypoint cone of the move test, (tilt, |torsion|) in rad (as in the architectures' test).
WAYPOINTS = {"pus": (math.radians(35.0), 0.6), "rus": (math.radians(22.0), 0.35)}


def scene(
    model: ra.ReferenceModel, tool_length: float, legs: tuple[int, ...], gap: float = 0.012
) -> dict:
    """A tool of ``tool_length`` and one small sphere beside each leg in ``legs`` (0-based),
    placed 60 % of the way up the leg at the home pose and pushed outwards so that it clears
    the leg by ``gap`` (m) at home and tilts sweep the leg through it."""
    home = np.zeros((1, 3))
    platform = ra.platform_points(model, home, model.home_position)
    q, _ = ra.inverse_kinematics(model, platform)
    base = ra.base_points(model, q)
    names = [f"ball{k + 1}" for k in legs]
    obstacles: dict = {"names": names}
    for name, k in zip(names, legs, strict=True):
        a, b = base[0, k], platform[0, k]
        point = a + 0.6 * (b - a)
        along = (b - a) / np.linalg.norm(b - a)
        outward = np.array([point[0], point[1], 0.0])
        outward -= np.dot(outward, along) * along  # perpendicular to the leg
        outward /= np.linalg.norm(outward)
        radius = 0.02
        centre = point + (0.5 * model.leg_diameter + radius + gap) * outward
        obstacles[name] = {"shape": "sphere", "position": centre.tolist(), "radius": radius}
    return {
        "collision": {
            "clearance": CLEARANCE,
            "tool": {"radius": TOOL_RADIUS, "length": tool_length},
            "obstacles": obstacles,
        }
    }


def machines(architecture: str, tool_length: float, legs: tuple[int, ...], gap: float = 0.012):
    path = CONFIG / EXAMPLES[architecture]
    model = ra.load(path)
    collision = scene(model, tool_length, legs, gap)
    parameters = {**load_params_file(path), **flatten(collision)}
    return manipulator_from_mapping(parameters, warn=False), model, collision["collision"]


def reference_collision(model: ra.ReferenceModel, collision: dict, angles, position) -> np.ndarray:
    """Smallest signed distance over the pairs minus the clearance, shape (N,), m (NaN where a
    leg has no inverse-kinematics solution)."""
    angles = np.atleast_2d(np.asarray(angles, dtype=float))
    rotations = ra.rotation_matrices(angles)
    p = np.broadcast_to(np.asarray(position, dtype=float), (angles.shape[0], 3))
    platform = ra.platform_points(model, angles, p)
    q, _ = ra.inverse_kinematics(model, platform)
    base = ra.base_points(model, q)
    leg_radius = 0.5 * model.leg_diameter
    tool = collision["tool"]
    t0 = p
    t1 = p + tool["length"] * rotations[:, :, 2]
    values = []
    for k in range(6):
        distance = ra.segment_distance(t0, t1, base[:, k], platform[:, k])
        values.append(distance - tool["radius"] - leg_radius)
    obstacles = collision["obstacles"]
    for name in obstacles["names"]:
        centre = np.broadcast_to(np.asarray(obstacles[name]["position"]), t0.shape)
        radius = obstacles[name]["radius"]
        values.append(ra._point_segment(centre, t0, t1) - tool["radius"] - radius)
        for k in range(6):
            distance = ra._point_segment(centre, base[:, k], platform[:, k])
            values.append(distance - leg_radius - radius)
    return np.min(np.column_stack(values), axis=1) - collision["clearance"]


def reachable(model, collision, angles, position) -> np.ndarray:
    clear = reference_collision(model, collision, angles, position) >= 0.0
    return ra.evaluate(model, np.asarray(angles, dtype=float), position).reachable & clear


def test_reference_scene_agrees_with_the_kernels() -> None:
    """The reference's collision margin equals the package's on random poses (every
    architecture): the two sides of the dense comparisons below measure the same thing."""
    from hexapod_workspace.core.evaluation.check import check

    rng = np.random.default_rng(5)
    for architecture, legs in (("ups", (0, 3)), ("pus", (1, 4)), ("rus", (2,))):
        manipulator, model, collision = machines(architecture, 0.25, legs)
        angles = np.column_stack(
            [rng.uniform(-np.pi, np.pi, 400), rng.uniform(0, 0.5, 400), rng.uniform(-0.4, 0.4, 400)]
        )
        found = check(manipulator, angles, model.home_position).margins["collision"]
        expected = reference_collision(model, collision, angles, model.home_position)
        solved = np.isfinite(expected)
        assert solved.sum() > 50, architecture
        np.testing.assert_allclose(found[solved], expected[solved], atol=1e-9, rtol=0)
        assert np.all(np.isnan(found[~solved]))


@pytest.mark.parametrize(
    ("architecture", "tool_length", "legs"), [("pus", 0.3, (0,)), ("rus", 0.2, (0, 2, 4))]
)
def test_moving_base_moves_with_a_scene_against_dense_sampling(architecture, tool_length, legs):
    """Certified moves of 6-PUS/6-RUS with a tool and obstacles beside the legs: a move
    certified ok is reachable and collision-free at 1,000 evenly spaced poses; a refused move's
    reported violation is violated for the reference, and the reference finds nothing violated
    before it (up to a few tolerance steps). Some moves must be stopped by the collision row."""
    manipulator, model, collision = machines(architecture, tool_length, legs)
    rng = np.random.default_rng(2121)
    count = 40
    tilt, torsion = WAYPOINTS[architecture]
    angles = np.column_stack(
        [
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(math.radians(2.0), tilt, count),
            rng.uniform(-torsion, torsion, count),
        ]
    )
    points = model.home_position + rng.uniform(-0.04, 0.04, (count, 3))
    result = check_path(
        manipulator, points, angles=angles, interpolation="tilt-torsion", tolerance=TOLERANCE
    )
    segments = result.segments
    np.testing.assert_array_equal(
        result.waypoints.reachable, reachable(model, collision, angles, points)
    )
    s = np.linspace(0.0, 1.0, 1000)
    seen = {"ok": 0, "located": 0, "collision": 0}
    for m in range(count - 1):
        poses, where = interpolate(angles[m], angles[m + 1], points[m], points[m + 1], s)
        verdict = reachable(model, collision, poses, where)
        if segments.ok[m]:
            assert verdict.all(), (m, s[~verdict][:5])
            seen["ok"] += 1
            continue
        first = float(segments.first_violation_s[m])
        assert not reachable(
            model, collision, segments.violation_angles[m][None], segments.violation_positions[m]
        )[0]
        if "collision" in segments.violated[m]:
            seen["collision"] += 1
        rate = segments.angular_rate[m] + segments.translation[m] / model.rho
        step = 4 * TOLERANCE / max(rate, 1e-12)
        if first - step > 0.0:
            before = np.linspace(0.0, first - step, 1000)
            poses, where = interpolate(angles[m], angles[m + 1], points[m], points[m + 1], before)
            assert reachable(model, collision, poses, where).all(), (m, first)
            seen["located"] += 1
    assert seen["ok"] >= 3 and seen["located"] >= 3 and seen["collision"] >= 1, seen


def ray_checks(model, collision, phi, theta, position, limit=math.pi) -> None:
    """Every pose of the ray (φ, 0..θ, ψ = 0) reachable on the grid; one tolerance beyond not."""
    for f, t in zip(phi, theta, strict=True):
        ray = np.linspace(0.0, t, max(2, math.ceil(t / GRID) + 1))
        inside = np.column_stack([np.full(ray.size, f), ray, np.zeros(ray.size)])
        assert reachable(model, collision, inside, position).all(), (f, t)
        if t < limit:
            beyond = [[f, t + 1.01 * TOLERANCE, 0.0]]
            assert not reachable(model, collision, beyond, position)[0], (f, t)


@pytest.mark.parametrize(
    ("architecture", "tool_length", "legs", "gap"),
    [("pus", 0.3, (0, 2, 4), 0.012), ("rus", 0.2, (0,), 0.008)],
)
def test_moving_base_projected_boundary_with_a_scene(architecture, tool_length, legs, gap):
    """The projected boundary (ψ ≡ 0) of 6-PUS/6-RUS with the scene: reachable rays, violated
    one tolerance beyond, and at least one boundary point where the collision row limits."""
    manipulator, model, collision = machines(architecture, tool_length, legs, gap)
    position = model.home_position
    workspace = projected_workspace(
        manipulator, position, method="torsion_zero", n_phi=36, tolerance=TOLERANCE
    )
    ray_checks(model, collision, workspace.phi, workspace.theta, position)
    boundary = np.column_stack([workspace.phi, workspace.theta, np.zeros(workspace.phi.size)])
    beyond = boundary + np.array([0.0, 1.01 * TOLERANCE, 0.0])
    hit = reference_collision(model, collision, beyond, position) < 0.0
    assert hit.any(), "the scene must limit some of the boundary"


def test_ups_projected_workspace_with_a_scene_against_dense_sampling() -> None:
    """6-UPS with a long tool and a ball beside leg 1: the projected boundary (ψ ≡ 0) against
    the reference's dense rays; the exact method's boundary poses are reachable."""
    manipulator, model, collision = machines("ups", 0.45, (0,))
    for position in (model.home_position,):
        workspace = projected_workspace(
            manipulator, position, method="torsion_zero", n_phi=36, tolerance=TOLERANCE
        )
        ray_checks(model, collision, workspace.phi, workspace.theta, position)
        boundary = np.column_stack([workspace.phi, workspace.theta, np.zeros(workspace.phi.size)])
        beyond = boundary + np.array([0.0, 1.01 * TOLERANCE, 0.0])
        assert (reference_collision(model, collision, beyond, position) < 0.0).any()
        exact = projected_workspace(
            manipulator, position, method="exact", n_phi=24, tolerance=TOLERANCE
        )
        poses = np.column_stack([exact.phi, exact.theta, exact.psi])
        assert reachable(model, collision, poses, position).all()


def test_ups_orientation_workspace_with_a_scene_against_dense_sampling() -> None:
    """Each slice of the orientation workspace with the scene: the segment from the slice's
    centre to every boundary point is reachable on a dense grid, the point one tolerance further
    along the ray is not (unless the ray ends at θ = π), and the collision row limits some."""
    manipulator, model, collision = machines("ups", 0.45, (0, 2, 4))
    position = model.home_position
    workspace = orientation_workspace(
        manipulator, position, n_rays=24, psi_step=0.25, tolerance=TOLERANCE
    )
    limited = 0
    assert len(workspace.slices) >= 3
    for piece in workspace.slices:
        for end in piece.xy():
            direction = end - piece.center
            length = float(np.linalg.norm(direction))
            samples = np.linspace(0.0, 1.0, max(2, math.ceil(length / GRID) + 1))
            xy = piece.center + samples[:, None] * direction
            theta = np.hypot(xy[:, 0], xy[:, 1])
            angles = np.column_stack(
                [np.arctan2(xy[:, 1], xy[:, 0]), theta, np.full(theta.size, piece.psi)]
            )
            assert reachable(model, collision, angles, position).all(), (piece.psi, end)
            if length > 0.0:
                out = end + 1.01 * TOLERANCE * direction / length
                theta_out = float(np.hypot(*out))
                if theta_out < math.pi:
                    beyond = [[math.atan2(out[1], out[0]), theta_out, piece.psi]]
                    assert not reachable(model, collision, beyond, position)[0]
                    limited += bool(reference_collision(model, collision, beyond, position)[0] < 0)
    assert limited >= 1, "the scene must limit some of the boundary"
