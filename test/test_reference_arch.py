"""The plain-numpy architecture reference (test/reference_arch.py) checked on its own.

Nothing here uses the package: closure of the inverse kinematics, the ik margin against dense
sampling of the rail or crank circle, the segment distance against dense sampling and hand
values, M and τ against finite differences of the inverse kinematics, a configuration singular
by line geometry, the symmetries of the packaged examples, and the examples' home figures.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import reference_arch as ra

CONFIG = Path(__file__).resolve().parents[1] / "config"
EXAMPLES = {name: CONFIG / f"example_{name}.yaml" for name in ("gpm", "pus", "rus")}


@pytest.fixture(scope="module")
def models() -> dict[str, ra.ReferenceModel]:
    return {name: ra.load(path) for name, path in EXAMPLES.items()}


def random_poses(rng: np.random.Generator, count: int, tilt_deg: float, torsion_deg: float):
    return np.column_stack(
        [
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(0.0, math.radians(tilt_deg), count),
            rng.uniform(-math.radians(torsion_deg), math.radians(torsion_deg), count),
        ]
    )


def polar(radius: float, azimuths_deg, height: float) -> np.ndarray:
    angles = np.radians(np.asarray(azimuths_deg, dtype=float))
    return np.column_stack(
        [radius * np.cos(angles), radius * np.sin(angles), np.full(angles.size, height)]
    )


# ------------------------------------------------------------------------------------------
# Rotation, segment distance
# ------------------------------------------------------------------------------------------


def test_rotation_is_tilt_and_torsion(rng):
    angles = random_poses(rng, 200, 180.0, 180.0)
    rotations = ra.rotation_matrices(angles)
    identity = np.broadcast_to(np.eye(3), rotations.shape)
    np.testing.assert_allclose(rotations @ rotations.transpose(0, 2, 1), identity, atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(rotations), 1.0, atol=1e-14)
    phi, theta, psi = angles.T
    approach = np.column_stack(
        [np.cos(phi) * np.sin(theta), np.sin(phi) * np.sin(theta), np.cos(theta)]
    )
    np.testing.assert_allclose(rotations[:, :, 2], approach, atol=1e-14)
    # At θ = 0 the rotation is Rz(ψ) whatever φ (the representation singularity).
    flat = ra.rotation_matrices([[1.0, 0.0, 0.3], [-2.0, 0.0, 0.3]])
    np.testing.assert_allclose(flat[0], flat[1], atol=1e-15)


def dense_segment_distance(p0, p1, q0, q1, samples=4001) -> float:
    """Every sample of one segment to the other segment exactly (point to segment), both ways."""
    s = np.linspace(0.0, 1.0, samples)[:, None]
    best = math.inf
    for (a0, a1), (b0, b1) in (((p0, p1), (q0, q1)), ((q0, q1), (p0, p1))):
        points = a0 + s * (a1 - a0)
        n = len(points)
        distance = ra._point_segment(points, np.tile(b0, (n, 1)), np.tile(b1, (n, 1)))
        best = min(best, float(distance.min()))
    return best


def test_segment_distance_against_dense_sampling(rng):
    cases = [rng.normal(size=(4, 3)) for _ in range(150)]
    for _ in range(40):  # parallel, collinear, degenerate, crossing
        p0, p1, q0 = rng.normal(size=(3, 3))
        cases.append(np.array([p0, p1, q0, q0 + rng.uniform(-2, 2) * (p1 - p0)]))
        cases.append(np.array([p0, p1, p0 + 1.5 * (p1 - p0), p0 + 2.5 * (p1 - p0)]))
        cases.append(np.array([p0, p0, q0, p1]))
        cases.append(np.array([p0, p0, q0, q0]))
        centre, u, v = rng.normal(size=(3, 3))
        cases.append(np.array([centre - u, centre + u, centre - v, centre + v]))
    cases_array = np.array(cases)
    exact = ra.segment_distance(*cases_array.transpose(1, 0, 2))
    for k, (p0, p1, q0, q1) in enumerate(cases_array):
        sampled = dense_segment_distance(p0, p1, q0, q1)
        spacing = max(np.linalg.norm(p1 - p0), np.linalg.norm(q1 - q0)) / 4000
        assert exact[k] <= sampled + 1e-12, k  # the exact minimum is below every sample
        assert sampled - exact[k] <= spacing, k  # and sampling gets within its spacing


def test_segment_distance_hand_values():
    cases = [
        # skew perpendicular, one unit apart
        (([-1, 0, 0], [1, 0, 0], [0, -1, 1], [0, 1, 1]), 1.0),
        # parallel, overlapping: the distance between the lines
        (([0, 0, 0], [2, 0, 0], [1, 0.5, 0], [3, 0.5, 0]), 0.5),
        # parallel, apart along the axis: end to end
        (([0, 0, 0], [1, 0, 0], [3, 0, 4], [5, 0, 4]), math.hypot(2.0, 4.0)),
        # collinear, apart: the gap
        (([0, 0, 0], [1, 0, 0], [2.5, 0, 0], [4, 0, 0]), 1.5),
        # two points
        (([1, 2, 3], [1, 2, 3], [4, 6, 3], [4, 6, 3]), 5.0),
        # crossing: zero
        (([-1, -1, 0], [1, 1, 0], [-1, 1, 0], [1, -1, 0]), 0.0),
    ]
    for ends, expected in cases:
        assert float(ra.segment_distance(*(np.array(e, float) for e in ends))) == pytest.approx(
            expected, abs=1e-15
        )


# ------------------------------------------------------------------------------------------
# Inverse kinematics
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["pus", "rus"])
def test_ik_round_trip_both_branches(models, rng, name):
    model = models[name]
    angles = random_poses(rng, 4000, 40.0, 45.0)
    offsets = rng.uniform(-0.15, 0.15, (angles.shape[0], 1, 3))
    platform = ra.platform_points(model, angles, model.home_position) + offsets
    solvable = 0
    for branch in (np.ones(6), -np.ones(6)):
        q, ik = ra.inverse_kinematics(model, platform, branch)
        assert np.array_equal(np.isnan(q), ik < 0.0)  # a coordinate exactly when ik >= 0
        closure = np.linalg.norm(platform - ra.base_points(model, q), axis=-1)
        ok = ~np.isnan(q)
        np.testing.assert_allclose(
            closure[ok], np.broadcast_to(model.leg_lengths, q.shape)[ok], rtol=0.0, atol=1e-12
        )
        solvable += int(ok.sum())
    assert 0.3 < solvable / (2 * 6 * angles.shape[0]) < 0.999  # both outcomes are exercised
    # The two branches differ (they meet only on the ik = 0 boundary).
    plus, _ = ra.inverse_kinematics(model, platform, np.ones(6))
    minus, _ = ra.inverse_kinematics(model, platform, -np.ones(6))
    both = ~np.isnan(plus)
    assert np.all(np.abs(plus[both] - minus[both]) > 0.0)


def test_rus_angle_in_the_window_centred_on_the_range(models, rng):
    model = models["rus"]
    platform = ra.platform_points(model, random_poses(rng, 2000, 30.0, 40.0), model.home_position)
    q, _ = ra.inverse_kinematics(model, platform)
    centre = 0.5 * (model.actuator_min + model.actuator_max)
    ok = ~np.isnan(q)
    assert np.all((q - centre)[ok] >= -math.pi) and np.all((q - centre)[ok] < math.pi)


def locus(model: ra.ReferenceModel, samples: int) -> np.ndarray:
    """Dense samples of each leg's moving base joint: (samples, 6, 3). Rails are sampled over
    ±3 m about A0 (far beyond any leg), cranks over the whole circle."""
    if model.architecture == "pus":
        q = np.linspace(-3.0, 3.0, samples)
    else:
        q = np.linspace(-math.pi, math.pi, samples)
    return ra.base_points(model, np.repeat(q[:, None], 6, axis=1))


@pytest.mark.parametrize("name", ["pus", "rus"])
def test_ik_margin_against_dense_sampling_of_the_locus(models, rng, name):
    model = models[name]
    angles = random_poses(rng, 100, 60.0, 60.0)
    platform = ra.platform_points(model, angles, model.home_position)
    platform = platform + rng.uniform(-0.2, 0.2, (angles.shape[0], 1, 3))
    _, ik = ra.inverse_kinematics(model, platform)
    samples = locus(model, 50_001)
    spacing = 6.0 / 50_000 if name == "pus" else 2 * math.pi * model.crank_lengths.max() / 50_000
    for k in range(angles.shape[0]):
        distances = np.linalg.norm(samples - platform[k], axis=-1)  # (samples, 6)
        nearest, farthest = distances.min(axis=0), distances.max(axis=0)
        length = model.leg_lengths
        expected = (
            length - nearest if name == "pus" else np.minimum(length - nearest, farthest - length)
        )
        # Sampling finds distances at most half a spacing worse than the exact range.
        np.testing.assert_allclose(ik[k], expected, atol=spacing)
        outside = (nearest > length) | (farthest < length)
        clear = np.abs(ik[k]) > spacing  # away from the sampling's blind band
        np.testing.assert_array_equal((ik[k] < 0.0)[clear], outside[clear])
    assert (ik < 0).any() and (ik >= 0).any()


def test_no_solution_gives_negative_ik_and_undefined_margins(models, rng):
    for name in ("pus", "rus"):
        model = models[name]
        angles = random_poses(rng, 3000, 60.0, 60.0)
        result = ra.evaluate(model, angles, model.home_position + np.array([0.1, -0.05, 0.08]))
        unsolved = np.isnan(result.q).any(axis=1)
        assert unsolved.any() and (~unsolved).any()
        np.testing.assert_array_equal(result.margins["ik"] < 0.0, unsolved)
        assert np.all(np.isfinite(result.margins["ik"]))
        for margin in set(result.margins) - {"ik"}:
            np.testing.assert_array_equal(np.isnan(result.margins[margin]), unsolved)
        assert not result.reachable[unsolved].any()
        violated = result.violated()
        assert all("ik" in violated[k] for k in np.flatnonzero(unsolved))


# ------------------------------------------------------------------------------------------
# Jacobian rows and transmission against finite differences
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["gpm", "pus", "rus"])
def test_plucker_rows_and_transmission_give_the_actuator_rates(models, rng, name):
    """For a platform twist (v, ω): ḃ_i = v + ω × R b_i and n_i·Ḃ_i = M_i·(v, ρω). The actuated
    rate is q̇ = n·Ḃ (ups), n·Ḃ/τ (pus), n·Ḃ/(r τ) (rus). Central differences of the reference
    inverse kinematics along random twists must match (error O(h²))."""
    model = models[name]
    h = 1e-6
    checked = 0
    for _ in range(40):
        angles = random_poses(rng, 1, 15.0, 20.0)[0]
        position = model.home_position + rng.uniform(-0.05, 0.05, 3)
        rotation = ra.rotation_matrices(angles)[0]
        v, omega = rng.normal(size=3), rng.normal(size=3)

        def coordinates(step: float, rotation=rotation, position=position, v=v, omega=omega):
            turn = ra._rotate_about(
                omega / np.linalg.norm(omega), np.array(step * np.linalg.norm(omega)), rotation.T
            ).T  # exp(step [ω]×) · R
            platform = (position + step * v) + model.platform_joints @ turn.T
            return ra.inverse_kinematics(model, platform[None])[0][0]

        rate = (coordinates(h) - coordinates(-h)) / (2 * h)
        result = ra.evaluate(model, angles[None], position)
        platform = position + model.platform_joints @ rotation.T
        ends = ra.base_points(model, result.q)[0]
        n = (platform - ends) / np.linalg.norm(platform - ends, axis=1)[:, None]
        moments = np.cross(model.platform_joints @ rotation.T, n) / model.rho
        jacobian = np.hstack([n, moments])
        along = jacobian @ np.concatenate([v, model.rho * omega])
        if name == "gpm":
            expected = along
        elif name == "pus":
            expected = along / np.sum(n * model.rail_directions, axis=1)
        else:
            tangent = np.cross(model.crank_axes, ends - model.base_joints)
            expected = along / np.sum(n * tangent, axis=1)
        if np.isnan(rate).any():
            continue
        np.testing.assert_allclose(rate, expected, rtol=1e-5, atol=1e-6)
        # σ_min of this M is the reference's singularity margin (+ singularity_min).
        assert result.margins["singularity"][0] + model.singularity_min == pytest.approx(
            np.linalg.svd(jacobian, compute_uv=False).min(), abs=1e-13
        )
        checked += 1
    assert checked >= 30


def test_legs_meeting_one_line_are_singular():
    """Six leg lines that all meet one line have rank(M) ≤ 5 (line geometry): the twist about
    that line moves no leg. Platform joints at 0.45 × the rail's y, rails at z = 0, platform
    joints 0.55 m below: every leg's yz-projection passes through (y, z) = (0, −1.0), so every
    leg line meets the line {y = 0, z = −1.0} parallel to the rails."""
    rails_y = np.array([-0.60, -0.40, -0.15, 0.15, 0.40, 0.60])
    side = np.array([1.0, -1.0, 1.0, 1.0, -1.0, 1.0])
    b = np.column_stack([0.12 * side, 0.45 * rails_y, np.full(6, 0.25)])
    home = np.array([0.0, 0.0, -0.80])
    reach = np.sqrt(0.9**2 - (rails_y - 0.45 * rails_y) ** 2 - 0.55**2)
    base = np.column_stack([0.12 * side + side * reach, rails_y, np.zeros(6)])
    flat = {
        "geometry.architecture": "pus",
        "geometry.base_joints": base.ravel().tolist(),
        "geometry.platform_joints": b.ravel().tolist(),
        "geometry.rail_directions": [1.0, 0.0, 0.0] * 6,
        "geometry.leg_lengths": [0.9],
        "geometry.branch": side.tolist(),
        "geometry.home_position": home.tolist(),
        "limits.actuator_min": [-0.4],
        "limits.actuator_max": [0.4],
        "limits.base_joint_max_angle": [0.79],
        "limits.platform_joint_max_angle": [0.79],
    }
    model = ra.model_from_parameters(flat)
    result = ra.evaluate(model, [[0.0, 0.0, 0.0]], home)
    np.testing.assert_allclose(result.q, 0.0, atol=1e-15)
    assert abs(result.margins["singularity"][0]) < 1e-14
    # A tilt about the y-axis breaks the concurrency: regular again.
    tilted = ra.evaluate(model, [[0.0, 0.1, 0.0]], home)
    assert tilted.margins["singularity"][0] > 1e-4


# ------------------------------------------------------------------------------------------
# Symmetries
# ------------------------------------------------------------------------------------------


def exact_rus() -> ra.ReferenceModel:
    """The rus example from its polar description (the YAML carries 6 decimals)."""
    flat = ra.read_parameters(EXAMPLES["rus"])
    azimuths = np.array([-12.0, 12.0, 108.0, 132.0, 228.0, 252.0])
    tangent = np.column_stack(
        [-np.sin(np.radians(azimuths)), np.cos(np.radians(azimuths)), np.zeros(6)]
    )
    zero = np.array([-1, 1, -1, 1, -1, 1])[:, None] * tangent
    flat["geometry.base_joints"] = polar(0.42, azimuths, 0.0).ravel().tolist()
    flat["geometry.platform_joints"] = polar(0.30, [-50, 50, 70, 170, 190, 290], 0.0).ravel()
    flat["geometry.crank_zero_directions"] = zero.ravel().tolist()
    flat["geometry.crank_axes"] = np.cross(zero, [0.0, 0.0, 1.0]).ravel().tolist()
    return ra.model_from_parameters(flat)


def test_rus_example_matches_its_polar_description(models):
    exact, rounded = exact_rus(), models["rus"]
    for field in ("base_joints", "platform_joints", "crank_axes", "crank_zero_directions"):
        np.testing.assert_allclose(getattr(rounded, field), getattr(exact, field), atol=6e-7)


def test_rus_120_degree_symmetry(rng):
    """Rotating the pose by 120° about z (position on the axis) maps leg i to leg i + 2: the
    margins are unchanged and the crank angles are permuted."""
    model = exact_rus()
    angles = random_poses(rng, 3000, 30.0, 35.0)
    turned = angles + np.array([2 * math.pi / 3, 0.0, 0.0])
    position = np.array([0.0, 0.0, 0.50])
    before, after = ra.evaluate(model, angles, position), ra.evaluate(model, turned, position)
    for name in before.margins:
        np.testing.assert_allclose(
            after.margins[name], before.margins[name], atol=1e-12, err_msg=name
        )
    np.testing.assert_allclose(after.q, np.roll(before.q, 2, axis=1), atol=1e-12)
    assert 0.05 < before.reachable.mean() < 0.95


def test_gpm_120_degree_symmetry(rng):
    flat = ra.read_parameters(EXAMPLES["gpm"])
    flat["geometry.base_joints"] = polar(0.55, [-12, 12, 108, 132, 228, 252], 0.0).ravel()
    flat["geometry.platform_joints"] = polar(0.30, [-48, 48, 72, 168, 192, 288], 0.1).ravel()
    model = ra.model_from_parameters(flat)
    angles = random_poses(rng, 3000, 40.0, 60.0)
    position = np.array([0.0, 0.0, -1.2])
    before = ra.evaluate(model, angles, position)
    after = ra.evaluate(model, angles + np.array([2 * math.pi / 3, 0.0, 0.0]), position)
    for name in before.margins:
        np.testing.assert_allclose(after.margins[name], before.margins[name], atol=1e-12)


def test_pus_mirror_symmetry(models, rng):
    """The pus example is symmetric about the plane y = 0 with legs i <-> 7 - i (exactly, in
    decimals). Mirroring S = diag(1, −1, 1): S Rz(a) S = Rz(−a), S Ry(θ) S = Ry(θ), so the pose
    (φ, θ, ψ) at (x, y, z) maps to (−φ, θ, −ψ) at (x, −y, z), with the same rails and branches."""
    model = models["pus"]
    angles = random_poses(rng, 3000, 35.0, 40.0)
    for position in (model.home_position, model.home_position + np.array([0.2, 0.07, 0.05])):
        mirrored_position = position * [1.0, -1.0, 1.0]
        before = ra.evaluate(model, angles, position)
        after = ra.evaluate(model, angles * [-1.0, 1.0, -1.0], mirrored_position)
        for name in before.margins:
            np.testing.assert_allclose(
                after.margins[name], before.margins[name], atol=1e-12, err_msg=name
            )
        np.testing.assert_allclose(after.q, before.q[:, ::-1], atol=1e-12)
        assert 0.05 < before.reachable.mean() < 0.95


def test_pus_translation_along_the_rails(models, rng):
    """All rails are along x: moving the head by Δx moves every slide by Δx and changes no
    margin but the stroke."""
    model = models["pus"]
    angles = random_poses(rng, 2000, 35.0, 40.0)
    shift = np.array([0.173, 0.0, 0.0])
    before = ra.evaluate(model, angles, model.home_position)
    after = ra.evaluate(model, angles, model.home_position + shift)
    np.testing.assert_allclose(after.q, before.q + shift[0], atol=1e-12)
    for name in set(before.margins) - {"actuator"}:
        np.testing.assert_allclose(after.margins[name], before.margins[name], atol=1e-12)


# ------------------------------------------------------------------------------------------
# The packaged examples are sensible machines
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("name", "tilt_deg", "sigma"), [("pus", 17.0, 0.25), ("rus", 19.5, 0.38)])
def test_example_home_pose_and_tilt(models, name, tilt_deg, sigma):
    """Home pose reachable with every margin clearly positive, transmission far above its 0.1
    floor, σ_min(M) well away from 0, and a tool tilt of ``tilt_deg`` reachable at ψ = 0 in
    every direction at the home position (figures in the YAML header)."""
    model = models[name]
    home = ra.evaluate(model, [[0.0, 0.0, 0.0]], model.home_position)
    assert home.reachable[0]
    assert home.margins["transmission"][0] > 0.5
    assert home.margins["singularity"][0] > sigma
    assert home.margins["leg_interference"][0] > 0.05
    assert home.margins["ik"][0] > 0.1
    phi = np.radians(np.arange(0.0, 360.0, 2.0))
    theta = np.radians(np.linspace(0.0, tilt_deg, 30))
    grid = np.array([(a, t, 0.0) for a in phi for t in theta])
    cone = ra.evaluate(model, grid, model.home_position)
    assert cone.reachable.all()
    assert np.nanmin(cone.margins["singularity"]) > 0.05


def test_gpm_example_reference_matches_the_readme_hand_calculation(models):
    # README / test_constraints: |L_1| at home = sqrt(0.337242² + 0.108592² + 1.2²).
    home = ra.evaluate(models["gpm"], [[0.0, 0.0, 0.0]], [0.0, 0.0, -1.3])
    length = math.sqrt(0.337242**2 + 0.108592**2 + 1.2**2)
    assert home.margins["leg_length"][0] == pytest.approx(1.45 - length, abs=1e-6)
    assert home.margins["base_joint"][0] == pytest.approx(0.7854, abs=1e-12)
