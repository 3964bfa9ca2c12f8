"""The lazy collision margin of the ray searches (``kernels.searches.search_rays``): the search that
evaluates the margin only where its Lipschitz bound cannot decide a probe, against the same
search evaluating it at every probe (``RaySearch.lazy_collision = False``) and against dense
sampling of the package's own pose check along each ray.

What would fail if the shortcut missed something: a ray whose first violation (a leg or the
tool meeting an obstacle) lies between two probes where only the bound was used would report a
boundary beyond the first violated dense sample, or disagree with the eager search.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from test_collision_evidence import machines

from hexapod_workspace import Manipulator
from hexapod_workspace.core.base.params import flatten, load_params_file
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.constraints.table import COLLISION
from hexapod_workspace.core.evaluation.check import check
from hexapod_workspace.core.evaluation.loading import load_manipulator, manipulator_from_mapping
from hexapod_workspace.core.model.collision.scene import _tool_ends
from hexapod_workspace.core.workspaces.orientation import torsion_range
from hexapod_workspace.core.workspaces.search import DEFAULT_MIN_STEP, RaySearch

EXAMPLE = Path(__file__).resolve().parents[1] / "config" / "example_collision.yaml"
TOLERANCE = 1e-6  # rad
SPACING = 2.5e-4  # rad: dense sampling step, below half the march's shortest step


def violated(manipulator: Manipulator, angles: np.ndarray, position: np.ndarray) -> np.ndarray:
    """Whether each pose violates a constraint, by the pose check (NaN margins violate)."""
    margins = check(manipulator, np.atleast_2d(angles), position).margins
    stacked = np.column_stack(list(margins.values()))
    return ~np.all(stacked >= 0.0, axis=1)


def first_band(bad: np.ndarray, s: np.ndarray, after: float) -> float:
    """Start of the first run of violated samples at or beyond ``after`` wider than the march's
    shortest step (narrower bands may be stepped over, with or without laziness), +inf if none."""
    k = int(np.searchsorted(s, after))
    while k < len(s):
        if not bad[k]:
            k += 1
            continue
        end = k
        while end + 1 < len(s) and bad[end + 1]:
            end += 1
        if s[end] - s[k] + SPACING >= DEFAULT_MIN_STEP or end == len(s) - 1:
            return float(s[k])
        k = end + 1
    return math.inf


def compare(manipulator: Manipulator, position, origins, directions, s_end: float) -> int:
    """Lazy and eager searches along the rays agree to the tolerance and with dense sampling;
    returns how many rays met a violation (so a test can insist that some do)."""
    results = []
    counts = []
    for lazy in (True, False):
        search = RaySearch(manipulator, position)
        search.lazy_collision = lazy
        results.append(search.rays("tt", origins, directions, s_end, TOLERANCE))
        counts.append((search.evaluations, search.collision_evaluations))
    lazy, eager = results
    assert counts[1][1] == counts[1][0]  # eager: the margin at every probe
    assert counts[0][1] < counts[0][0]  # lazy: it was left out somewhere
    np.testing.assert_array_equal(lazy.start_feasible, eager.start_feasible)
    met = 0
    for i in range(len(origins)):
        if not lazy.start_feasible[i]:
            continue
        s = np.arange(0.0, s_end + SPACING, SPACING)
        angles = origins[i] + s[:, None] * directions[i]
        bad = violated(manipulator, angles, position)
        band = first_band(bad, s, 0.0)
        for result in (lazy, eager):
            found = result.feasible[i]
            # The reported point is feasible, the one a tolerance beyond it violated.
            point = origins[i] + found * directions[i]
            assert not violated(manipulator, point, position)[0], (i, found)
            if np.isfinite(result.violated[i]):
                beyond = origins[i] + result.violated[i] * directions[i]
                assert violated(manipulator, beyond, position)[0], (i, result.violated[i])
                assert result.violated[i] - found <= TOLERANCE * (1 + 1e-9)
            # No band wider than the shortest step before the reported point.
            assert found <= band + 1e-12, (i, found, band)
        if np.isfinite(band):
            met += 1
        # Where the first band is the first crossing of both, they report it to the tolerance.
        if np.isfinite(lazy.violated[i]) and np.isfinite(eager.violated[i]):
            first = min(lazy.feasible[i], eager.feasible[i])
            if first_band(bad, s, 0.0) >= first - SPACING:
                assert abs(lazy.feasible[i] - eager.feasible[i]) <= TOLERANCE + 1e-12, i
            if abs(lazy.feasible[i] - eager.feasible[i]) <= TOLERANCE:
                assert lazy.limiting[i] == eager.limiting[i], i
    return met


@pytest.mark.parametrize(
    ("architecture", "tool_length", "legs", "gap"),
    [
        ("ups", 0.25, (0, 3), 0.004),
        ("ups", 0.35, (1, 2, 5), 0.02),
        ("pus", 0.3, (0, 4), 0.006),
        ("rus", 0.2, (0, 2, 4), 0.008),
    ],
)
def test_lazy_rays_against_eager_search_and_dense_sampling(architecture, tool_length, legs, gap):
    """Tilt rays through scenes with a tool and spheres beside the legs (so that tilts sweep
    legs through them) for each leg architecture: the lazy and the eager search agree, and no
    violated band wider than the shortest step lies before a reported boundary."""
    manipulator, model, _ = machines(architecture, tool_length, legs, gap)
    rng = np.random.default_rng(len(legs) * 100 + int(gap * 1e4))
    count = 24
    phi = rng.uniform(-np.pi, np.pi, count)
    psi = rng.uniform(-0.3, 0.3, count)
    origins = np.column_stack([phi, np.zeros(count), psi])
    directions = np.tile([0.0, 1.0, 0.0], (count, 1))
    met = compare(manipulator, model.home_position, origins, directions, 1.2)
    assert met > count // 2


def grazing_machine() -> tuple[Manipulator, np.ndarray, float]:
    """The example machine with a tool and one small ball that the tool's far end grazes along
    the tilt ray φ = 0 around θ = 0.3 rad: the collision margin is negative on a band about
    0.04 rad wide, far from where it is at home, with no other constraint near."""
    from hexapod_workspace._resources import example_config_path

    parameters = load_params_file(example_config_path())
    base = manipulator_from_mapping(parameters)
    position = np.asarray(base.home_position, dtype=float)
    tool_radius, radius, clearance, depth = 0.04, 0.004, 0.002, 0.0005
    tool = {"radius": tool_radius, "length": 0.25}
    probe = manipulator_from_mapping(
        {**parameters, **flatten({"collision": {"clearance": clearance, "tool": tool}})}
    )
    assert probe.collision is not None
    ends = _tool_ends(probe.collision)
    s_star = 0.3
    rotation = tt_to_matrix(np.array([[0.0, s_star, 0.0]]))[0]
    ahead = tt_to_matrix(np.array([[0.0, s_star + 1e-6, 0.0]]))[0]
    end = position + rotation @ ends[1]
    velocity = (ahead - rotation) @ ends[1]
    axis = rotation @ (ends[1] - ends[0])
    side = np.cross(axis, velocity)
    side /= np.linalg.norm(side)
    centre = end + (tool_radius + radius + clearance - depth) * side
    obstacles = {
        "names": ["ball"],
        "ball": {"shape": "sphere", "position": centre.tolist(), "radius": radius},
    }
    scene = {"collision": {"clearance": clearance, "tool": tool, "obstacles": obstacles}}
    return manipulator_from_mapping({**parameters, **flatten(scene)}), position, s_star


def test_a_ray_grazing_a_ball_between_probes_is_caught() -> None:
    """The tool's end grazes a ball on a narrow band of one ray, at a tilt where the bound from
    home would allow a long step: the lazy search stops at the band like the eager one."""
    manipulator, position, s_star = grazing_machine()
    s = np.arange(0.0, 0.6, SPACING)
    angles = np.column_stack([np.zeros_like(s), s, np.zeros_like(s)])
    bad = violated(manipulator, angles, position)
    start = first_band(bad, s, 0.0)
    assert abs(start - s_star) < 0.05 and not bad[int(np.searchsorted(s, s_star + 0.05))]
    collision = check(manipulator, angles, position).margins["collision"]
    assert np.all(collision[s < start - 0.01] > 0.0)
    # Nine rays a few mrad apart (neighbours lend each other their evaluated margins), the
    # middle one through the graze.
    origins = np.column_stack([np.linspace(-0.004, 0.004, 9), np.zeros(9), np.zeros(9)])
    directions = np.tile([0.0, 1.0, 0.0], (9, 1))
    assert compare(manipulator, position, origins, directions, 0.6) >= 1
    search = RaySearch(manipulator, position)
    found = search.rays("tt", origins, directions, 0.6, TOLERANCE)
    assert start - SPACING - TOLERANCE <= found.feasible[4] <= start
    assert found.limiting[4] == COLLISION


def test_torsion_scan_lazy_against_eager_and_dense_sampling() -> None:
    """The torsion scan bounds the collision margin from its earlier samples (Lipschitz in ψ at
    rate ρ_c: turning ψ turns the platform by |Δψ| about the tool axis). On the worked example
    (the spindle meets leg 3 near φ 90°, θ 30°) over 36 tool directions, the lazy scan's
    torsion intervals equal dense sampling's away from their ends, and equal the eager scan's
    (every sample evaluated) to the tolerance."""
    cell = load_manipulator(EXAMPLE)
    home = np.array([0.0, 0.0, -1.3])
    tolerance = 1e-4
    psi = np.linspace(-math.pi, math.pi, 20_001)
    # Turning ψ at fixed (φ, θ) is a rotation by |Δψ|, the fact the lazy bound rests on.
    a = tt_to_matrix([[1.2, 0.5, -0.4]])[0]
    b = tt_to_matrix([[1.2, 0.5, 0.3]])[0]
    assert math.acos((np.trace(a.T @ b) - 1.0) / 2.0) == pytest.approx(0.7, abs=1e-12)
    with_collision_edge = 0
    for phi in np.radians(np.arange(0.0, 360.0, 30.0)):
        for theta in np.radians([20.0, 28.0, 32.0]):
            ranges = {}
            for lazy in (True, False):
                RaySearch.lazy_collision = lazy
                try:
                    ranges[lazy] = torsion_range(cell, phi, theta, home, tolerance=tolerance)
                finally:
                    RaySearch.lazy_collision = True
            angles = np.column_stack([np.full_like(psi, phi), np.full_like(psi, theta), psi])
            result = check(cell, angles, home)
            dense = result.reachable
            for found in ranges.values():
                inside = np.zeros_like(dense)
                near = np.zeros_like(dense)
                for low, high in found.intervals:
                    inside |= (psi >= low) & (psi <= high)
                    near |= (np.abs(psi - low) < 2e-4) | (np.abs(psi - high) < 2e-4)
                assert np.all(inside[~near] == dense[~near]), (phi, theta)
            lazy_ends = np.array(ranges[True].intervals).ravel()
            eager_ends = np.array(ranges[False].intervals).ravel()
            assert lazy_ends.shape == eager_ends.shape, (phi, theta)
            np.testing.assert_allclose(lazy_ends, eager_ends, atol=2 * tolerance)
            # Count the directions where the collision row decides a transition.
            collision = result.margins["collision"]
            if np.any(np.diff(np.sign(collision)) != 0):
                with_collision_edge += 1
    assert with_collision_edge >= 3
