"""Workspace algorithms against brute-force sampling, symmetry and bracketing.

Golden evidence here is independent of the search: dense sampling with :func:`check`
(reachable just inside and along each ray, violated just outside), symmetries of the exact
axisymmetric design, and grid searches over torsion.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from hexapod_workspace import (
    InputError,
    ResolutionError,
    UnreachableReferenceError,
    check,
    orientation_workspace,
    projected_workspace,
    torsion_range,
)
from hexapod_workspace.core.evaluation.loading import load_manipulator

ON_AXIS = np.array([0.0, 0.0, -1.3])
OFF_AXIS = np.array([0.2, 0.2, -0.95])


def reachable(model, angles, position) -> np.ndarray:
    return check(model, np.atleast_2d(angles), position).reachable


@pytest.fixture(scope="module")
def tz_on(example):
    return projected_workspace(example, ON_AXIS, n_phi=120, tolerance=1e-6)


@pytest.fixture(scope="module")
def tz_off(example):
    return projected_workspace(example, OFF_AXIS, n_phi=120, tolerance=1e-6)


@pytest.fixture(scope="module")
def exact_off(example):
    return projected_workspace(example, OFF_AXIS, method="exact", n_phi=120, tolerance=1e-6)


@pytest.fixture(scope="module")
def solid_off(example):
    return orientation_workspace(
        example, OFF_AXIS, n_rays=72, psi_step=math.radians(4.0), tolerance=1e-6
    )


# ---------------------------------------------------------------- projected, torsion zero
@pytest.mark.parametrize("which", ["tz_on", "tz_off"])
def test_torsion_zero_boundary_against_sampling(example, request, which):
    workspace = request.getfixturevalue(which)
    tol = workspace.tolerance
    inside = np.column_stack([workspace.phi, workspace.theta, np.zeros(workspace.n_phi)])
    outside = inside + np.array([0.0, tol, 0.0])
    assert reachable(example, inside, workspace.position).all()
    assert not reachable(example, outside, workspace.position).any()
    # Reachable along every ray from theta = 0 (2000 samples each).
    fractions = np.linspace(0.0, 1.0, 2000)
    along = np.column_stack(
        [
            np.repeat(workspace.phi, fractions.size),
            np.outer(workspace.theta, fractions).ravel(),
            np.zeros(workspace.n_phi * fractions.size),
        ]
    )
    assert reachable(example, along, workspace.position).all()
    assert set(workspace.limiting) <= {
        "leg_length",
        "base_joint",
        "platform_joint",
        "leg_interference",
    }


def test_torsion_zero_summary(tz_off):
    assert tz_off.tilt_min == tz_off.theta.min()
    assert tz_off.tilt_max == tz_off.theta.max()
    # Solid angle: the rectangle rule of the closed form 2*pi*(1 - cos theta) of a cone.
    expected = 2.0 * math.pi * np.mean(1.0 - np.cos(tz_off.theta))
    assert tz_off.solid_angle == pytest.approx(expected)
    np.testing.assert_allclose(tz_off.phi, 2 * math.pi * np.arange(120) / 120)
    np.testing.assert_array_equal(tz_off.psi, 0.0)


@pytest.mark.parametrize("position", [ON_AXIS, OFF_AXIS])
def test_paper_procedure_agrees_within_its_step(example, position):
    from reference import paper_projected_workspace

    ours = projected_workspace(example, position, n_phi=24, tolerance=1e-7)
    paper = paper_projected_workspace(example, position, n_phi=24)
    # The paper's walk reports the first violated grid point: within one 0.1 deg step beyond.
    step = math.radians(0.1)
    assert np.all(paper >= ours.theta - 1e-9)
    assert np.all(paper <= ours.theta + step + 1e-7)


# ---------------------------------------------------------------- projected, exact
def test_exact_is_never_inside_torsion_zero(tz_off, exact_off):
    assert np.all(exact_off.theta >= tz_off.theta)
    np.testing.assert_allclose(exact_off.gap, exact_off.theta - tz_off.theta, atol=2e-6)
    assert exact_off.solid_angle >= tz_off.solid_angle


def test_exact_boundary_against_sampling(example, exact_off):
    tol = exact_off.tolerance
    inside = np.column_stack([exact_off.phi, exact_off.theta, exact_off.psi])
    assert reachable(example, inside, OFF_AXIS).all()
    outside = inside + np.array([0.0, tol, 0.0])
    assert not reachable(example, outside, OFF_AXIS).any()
    # The path to each point: torsion at theta = 0, then tilt at constant (phi, psi).
    fractions = np.linspace(0.0, 1.0, 500)
    tilt_path = np.column_stack(
        [
            np.repeat(exact_off.phi, fractions.size),
            np.outer(exact_off.theta, fractions).ravel(),
            np.repeat(exact_off.psi, fractions.size),
        ]
    )
    torsion_path = np.column_stack(
        [
            np.zeros(exact_off.n_phi * fractions.size),
            np.zeros(exact_off.n_phi * fractions.size),
            np.outer(exact_off.psi, fractions).ravel(),
        ]
    )
    assert reachable(example, tilt_path, OFF_AXIS).all()
    assert reachable(example, torsion_path, OFF_AXIS).all()


def test_exact_matches_a_brute_force_torsion_grid(example, exact_off):
    """For a few azimuths: max over a 1 deg torsion grid of the first violated tilt found by
    dense sampling (0.02 deg) is not above the exact result (beyond the sampling steps)."""
    tilt = np.radians(np.arange(0.0, 60.0, 0.02))
    psi_grid = np.radians(np.arange(-100.0, 100.01, 1.0))
    for k in (17, 45, 80):
        phi = exact_off.phi[k]
        angles = np.column_stack(
            [
                np.full(tilt.size * psi_grid.size, phi),
                np.tile(tilt, psi_grid.size),
                np.repeat(psi_grid, tilt.size),
            ]
        )
        ok = reachable(example, angles, OFF_AXIS).reshape(psi_grid.size, tilt.size)
        start_ok = ok[:, 0]
        first_bad = np.where(ok.all(axis=1), tilt.size, np.argmin(ok, axis=1))
        boundary = np.where(start_ok, tilt[np.maximum(first_bad - 1, 0)], 0.0)
        brute = boundary.max()
        # Exact is at least as good as the grid (up to the tilt and torsion sampling) ...
        assert exact_off.theta[k] >= brute - math.radians(0.05), k
        # ... and not better than what the grid sees within its resolution.
        assert exact_off.theta[k] <= brute + math.radians(1.0), k


# ---------------------------------------------------------------- symmetry
def test_projected_boundary_is_120_degree_periodic(symmetric):
    workspace = projected_workspace(symmetric, [0.0, 0.0, -1.25], n_phi=360, tolerance=1e-8)
    for shift in (120, 240):
        np.testing.assert_allclose(np.roll(workspace.theta, shift), workspace.theta, atol=2e-8)
    exact = projected_workspace(
        symmetric, [0.0, 0.0, -1.25], method="exact", n_phi=36, tolerance=1e-8
    )
    np.testing.assert_allclose(np.roll(exact.theta, 12), exact.theta, atol=1e-5)


def test_orientation_workspace_is_symmetric_in_torsion(symmetric):
    """The design has the mirror plane y = 0 as well: (phi, theta, psi) -> (-phi, theta, -psi)
    maps the workspace onto itself, so psi_min = -psi_max and mirrored slices match."""
    solid = orientation_workspace(
        symmetric, [0.0, 0.0, -1.25], n_rays=60, psi_step=math.radians(5.0), tolerance=1e-8
    )
    assert solid.psi_min == pytest.approx(-solid.psi_max, abs=1e-6)
    by_psi = {round(math.degrees(piece.psi), 6): piece for piece in solid.slices}
    for value, piece in by_psi.items():
        mirror = by_psi[round(-value, 6) + 0.0]
        assert piece.area() == pytest.approx(mirror.area(), rel=1e-6)
        np.testing.assert_allclose(piece.center * [1, -1], mirror.center, atol=1e-6)


# ---------------------------------------------------------------- orientation workspace
def test_slices_against_sampling(example, solid_off):
    tol = solid_off.tolerance
    n = solid_off.n_rays
    directions = np.column_stack(
        [np.cos(2 * np.pi * np.arange(n) / n), np.sin(2 * np.pi * np.arange(n) / n)]
    )
    for piece in solid_off.slices:
        xy = piece.xy()
        psi = np.full(n, piece.psi)
        inside = np.column_stack([piece.phi, piece.theta, psi])
        assert reachable(example, inside, OFF_AXIS).all(), piece.psi
        beyond = xy + tol * directions
        theta = np.hypot(beyond[:, 0], beyond[:, 1])
        outside = np.column_stack([np.arctan2(beyond[:, 1], beyond[:, 0]), theta, psi])
        assert not reachable(example, outside, OFF_AXIS).any(), piece.psi
        # Along each ray from the slice centre.
        fractions = np.linspace(0.0, 1.0, 60)[:, None, None]
        points = (piece.center + fractions * (xy - piece.center)).reshape(-1, 2)
        along = np.column_stack(
            [
                np.arctan2(points[:, 1], points[:, 0]),
                np.hypot(points[:, 0], points[:, 1]),
                np.full(points.shape[0], piece.psi),
            ]
        )
        assert reachable(example, along, OFF_AXIS).all(), piece.psi


def test_psi_limits_are_bracketed(example, solid_off):
    tol = solid_off.tolerance
    for value, point, sign in (
        (solid_off.psi_max, solid_off.psi_max_point, 1.0),
        (solid_off.psi_min, solid_off.psi_min_point, -1.0),
    ):
        phi, theta = math.atan2(point[1], point[0]), math.hypot(*point)
        assert reachable(example, [phi, theta, value], OFF_AXIS).all()
        assert not reachable(example, [phi, theta, value + sign * tol], OFF_AXIS).any()
        # Beyond the limit (by 0.05 deg), no direction at all is reachable: a 0.25 deg grid of
        # the whole disk theta <= 80 deg.
        grid = np.radians(np.arange(-80.0, 80.0, 0.25))
        x, y = np.meshgrid(grid, grid)
        keep = np.hypot(x, y) <= math.radians(80.0)
        x, y = x[keep], y[keep]
        beyond = np.column_stack(
            [np.arctan2(y, x), np.hypot(x, y), np.full(x.size, value + sign * math.radians(0.05))]
        )
        assert not reachable(example, beyond, OFF_AXIS).any()
    assert solid_off.slices[0].psi >= solid_off.psi_min
    assert solid_off.slices[-1].psi <= solid_off.psi_max
    assert solid_off.psi_max - solid_off.slices[-1].psi < solid_off.psi_step
    assert solid_off.slices[0].psi - solid_off.psi_min < solid_off.psi_step


def test_volume_and_boundary_points(solid_off):
    points = solid_off.boundary_points()
    assert points.shape == (len(solid_off.slices) * solid_off.n_rays, 6)
    np.testing.assert_allclose(points[:, 0], points[:, 4] * np.cos(points[:, 3]), atol=1e-12)
    np.testing.assert_allclose(points[:, 1], points[:, 4] * np.sin(points[:, 3]), atol=1e-12)
    np.testing.assert_array_equal(points[:, 2], points[:, 5])
    areas = np.array([piece.area() for piece in solid_off.slices])
    psis = np.array([piece.psi for piece in solid_off.slices])
    # Volume between the end slices is the trapezoid of the slice areas, plus the end cones.
    inner = np.trapezoid(areas, psis)
    assert (
        inner
        < solid_off.volume
        < inner + areas[0] * solid_off.psi_step + areas[-1] * solid_off.psi_step
    )
    # Slices are ordered and evenly stepped from psi = 0.
    steps = np.diff(psis)
    np.testing.assert_allclose(steps, solid_off.psi_step)
    assert np.any(np.isclose(psis, 0.0))


def test_slice_centres_are_previous_centroids(example, solid_off):
    from hexapod_workspace.core.workspaces.orientation import _polygon_area_centroid

    slices = solid_off.slices
    zero = int(np.argmin(np.abs([piece.psi for piece in slices])))
    for index in range(zero + 1, len(slices)):
        _, centroid = _polygon_area_centroid(slices[index - 1].xy())
        # The centroid, unless it was unreachable in the new slice (a pulled point is used).
        if reachable(
            example,
            [math.atan2(centroid[1], centroid[0]), math.hypot(*centroid), slices[index].psi],
            OFF_AXIS,
        ).all():
            np.testing.assert_allclose(slices[index].center, centroid, atol=1e-12)


# ---------------------------------------------------------------- torsion range
@pytest.mark.parametrize(("phi_deg", "theta_deg"), [(30.0, 20.0), (200.0, 35.0), (0.0, 0.0)])
def test_torsion_intervals_at_their_ends(example, phi_deg, theta_deg):
    found = torsion_range(example, math.radians(phi_deg), math.radians(theta_deg), OFF_AXIS)
    tol = found.tolerance
    phi, theta = found.phi, found.theta
    assert found.intervals.shape[0] >= 1
    for low, high in found.intervals:
        assert reachable(example, [[phi, theta, low], [phi, theta, high]], OFF_AXIS).all()
        if low > -math.pi:
            assert not reachable(example, [phi, theta, low - tol], OFF_AXIS).any()
        if high < math.pi:
            assert not reachable(example, [phi, theta, high + tol], OFF_AXIS).any()
    # Dense sampling agrees away from the ends.
    psi = np.linspace(-math.pi, math.pi, 20001)
    ok = reachable(
        example, np.column_stack([np.full(psi.size, phi), np.full(psi.size, theta), psi]), OFF_AXIS
    )
    inside = np.zeros(psi.size, dtype=bool)
    near_end = np.zeros(psi.size, dtype=bool)
    for low, high in found.intervals:
        inside |= (psi >= low) & (psi <= high)
        near_end |= (np.abs(psi - low) < 1e-3) | (np.abs(psi - high) < 1e-3)
    np.testing.assert_array_equal(ok[~near_end], inside[~near_end])


def test_torsion_range_with_no_feasible_torsion(example):
    found = torsion_range(example, 0.0, math.radians(80.0), OFF_AXIS)
    assert found.intervals.shape == (0, 2)


# ---------------------------------------------------------------- refusals
@pytest.mark.parametrize(
    "call",
    [
        lambda m: projected_workspace(m, [0.0, 0.0, -0.5]),
        lambda m: projected_workspace(m, [0.0, 0.0, -0.5], method="exact"),
        lambda m: orientation_workspace(m, [0.0, 0.0, -0.5]),
    ],
)
def test_unreachable_reference_is_refused(example, call):
    with pytest.raises(UnreachableReferenceError, match=r"unreachable at position .* empty"):
        call(example)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda m: projected_workspace(m, n_phi=2), "n_phi: expected 3 to 7200"),
        (lambda m: projected_workspace(m, n_phi=10**6), "n_phi: expected 3 to 7200"),
        (lambda m: projected_workspace(m, n_phi=36.5), "n_phi: expected an integer"),
        (lambda m: projected_workspace(m, tolerance=0.0), "tolerance: expected"),
        (lambda m: projected_workspace(m, tolerance=math.nan), "tolerance: expected"),
        (lambda m: orientation_workspace(m, n_rays=100000), "n_rays: expected 3 to 7200"),
        (lambda m: orientation_workspace(m, psi_step=0.0), "psi_step: expected"),
        (lambda m: orientation_workspace(m, psi_step=math.inf), "psi_step: expected"),
        (
            lambda m: orientation_workspace(m, n_rays=7200, psi_step=1e-3),
            "exceed 5000000 boundary points",
        ),
    ],
)
def test_absurd_resolutions_are_refused(example, call, message):
    with pytest.raises(ResolutionError, match=message):
        call(example)


@pytest.mark.parametrize(
    "call",
    [
        lambda m: projected_workspace(m, [0.0, math.nan, -1.3]),
        lambda m: projected_workspace(m, method="paper"),
        lambda m: torsion_range(m, math.nan, 0.1),
        lambda m: torsion_range(m, 0.0, 4.0),
    ],
)
def test_bad_requests_are_refused(example, call):
    with pytest.raises(InputError):
        call(example)


def first_root(k0, k1, k2, level):
    """First theta in (0, pi] with k0 + k1 cos(theta) + k2 sin(theta) = level, else inf.

    Writing k1 cos + k2 sin = A cos(theta - delta): theta = delta +- arccos((level - k0) / A).
    """
    amplitude = math.hypot(k1, k2)
    if amplitude == 0.0 or abs(level - k0) > amplitude:
        return math.inf
    delta = math.atan2(k2, k1)
    spread = math.acos((level - k0) / amplitude)
    roots = []
    for base in (delta + spread, delta - spread):
        for turn in (-2.0, 0.0, 2.0):
            value = base + turn * math.pi
            if 1e-12 < value <= math.pi:
                roots.append(value)
    return min(roots, default=math.inf)


def test_leg_length_boundary_closed_form(example, tz_off):
    """Along a ray (phi fixed, psi = 0) each squared leg length is exactly
    K0 + K1 cos(theta) + K2 sin(theta) (R is linear in cos and sin of theta). Where the search
    reports leg_length as the limiting constraint, its boundary must equal the first root of
    l_i(theta)^2 = l_min^2 or l_max^2 over the legs (from three samples, solved in closed form)."""
    from hexapod_workspace.core.base.rotations import tt_to_matrix
    from hexapod_workspace.core.evaluation.check import inverse_kinematics

    checked = 0
    for k in np.flatnonzero(np.array(tz_off.limiting) == "leg_length"):
        phi = tz_off.phi[k]
        samples = np.array([0.0, math.pi / 2, math.pi])
        angles = np.column_stack([np.full(3, phi), samples, np.zeros(3)])
        squared = inverse_kinematics(example, tt_to_matrix(angles), OFF_AXIS).lengths ** 2
        # l^2(0) = K0 + K1, l^2(pi/2) = K0 + K2, l^2(pi) = K0 - K1.
        k0 = (squared[0] + squared[2]) / 2.0
        k1 = (squared[0] - squared[2]) / 2.0
        k2 = squared[1] - k0
        # The identity holds at other tilts too (the closed form is exact).
        probe = np.array([[phi, 0.37, 0.0]])
        direct = inverse_kinematics(example, tt_to_matrix(probe), OFF_AXIS).lengths[0] ** 2
        np.testing.assert_allclose(direct, k0 + k1 * math.cos(0.37) + k2 * math.sin(0.37))
        closed = min(
            first_root(k0[i], k1[i], k2[i], level)
            for i in range(6)
            for level in (example.leg_length_min[i] ** 2, example.leg_length_max[i] ** 2)
        )
        assert tz_off.theta[k] <= closed <= tz_off.theta[k] + tz_off.tolerance + 1e-12
        checked += 1
    assert checked >= 5


def _machine(example, symmetric, name):
    from hexapod_workspace._resources import data_path

    if name == "ups-off-axis":
        return example, OFF_AXIS
    if name == "ups-symmetric":  # its torsion extremes lie on theta = 0 (120 deg symmetry)
        return symmetric, ON_AXIS
    model = load_manipulator(data_path("config", f"example_{name}.yaml"))
    return model, model.position


@pytest.mark.parametrize("name", ["ups-off-axis", "ups-symmetric", "pus", "rus"])
def test_torsion_extremes_have_witnesses_and_nothing_reachable_beyond(example, symmetric, name):
    """Each torsion extreme of the 3-D workspace comes with a witness pose that ``check``
    finds reachable, and dense sampling finds nothing reachable beyond the extreme by more
    than the tolerance: a 0.002 deg grid 0.2 deg around the witness, a 0.25 deg grid of
    the whole disk theta <= 80 deg."""
    model, position = _machine(example, symmetric, name)
    solid = orientation_workspace(
        model, position, n_rays=48, psi_step=math.radians(5.0), tolerance=1e-6
    )
    tol = solid.tolerance
    for value, witness, sign in (
        (solid.psi_max, solid.psi_max_witness, 1.0),
        (solid.psi_min, solid.psi_min_witness, -1.0),
    ):
        assert witness is not None and witness[2] == value
        assert reachable(model, witness, position).all(), (name, np.degrees(witness))
        x0, y0 = witness[1] * math.cos(witness[0]), witness[1] * math.sin(witness[0])
        near = np.radians(np.arange(-0.2, 0.2001, 0.002))
        coarse = np.radians(np.arange(-80.0, 80.0, 0.25))
        points = [np.meshgrid(x0 + near, y0 + near), np.meshgrid(coarse, coarse)]
        x = np.concatenate([p[0].ravel() for p in points])
        y = np.concatenate([p[1].ravel() for p in points])
        keep = np.hypot(x, y) <= math.radians(80.0)
        beyond = np.column_stack(
            [
                np.arctan2(y[keep], x[keep]),
                np.hypot(x[keep], y[keep]),
                np.full(int(keep.sum()), value + sign * 2.0 * tol),
            ]
        )
        assert not reachable(model, beyond, position).any(), name
