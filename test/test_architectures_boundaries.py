"""Boundaries, torsion ranges and certified moves of each architecture against dense sampling
with the plain-numpy reference (test/reference_arch.py), not with the package's own ``check``.

For each packaged example, at its home position and at one off-centre position:

- ``projected_workspace`` (torsion_zero): every boundary point's ray is reachable on a grid of
  1e-3 rad from θ = 0 up to the boundary, and the reference finds the pose one tolerance beyond
  the boundary violated; ``exact``: every reported boundary pose is reachable.
- ``torsion_range``: on a 1e-3 rad grid of ψ, the reference's verdict is "inside an interval"
  except within a tolerance of an interval end.
- ``check_path`` (tilt-torsion interpolation, position linear): a move certified ok is reachable
  at 1,000 evenly spaced poses (ends included); a move with a violation is reachable on a dense
  grid up to a few tolerance steps before the reported first violation, and the reported
  violation pose is violated for the reference too.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import reference_arch as ra

from hexapod_workspace import check_path, projected_workspace, torsion_range
from hexapod_workspace.core.evaluation.loading import load_manipulator

CONFIG = Path(__file__).resolve().parents[1] / "config"
EXAMPLES = {"ups": "example_gpm.yaml", "pus": "example_pus.yaml", "rus": "example_rus.yaml"}
OFFSETS = {"ups": (0.2, 0.2, 0.35), "pus": (0.15, -0.08, 0.06), "rus": (0.04, 0.03, 0.02)}
TOLERANCE = 1e-6  # rad: boundary tolerance asked of the package
GRID = 1e-3  # rad: the reference's sampling step
#: Waypoint cone of the move test, (tilt, |torsion|) in rad: a little wider than each example's
#: workspace, so that about half the waypoints are reachable.
WAYPOINTS = {
    "ups": (math.radians(45.0), 0.6),
    "pus": (math.radians(35.0), 0.6),
    "rus": (math.radians(22.0), 0.35),
}


def machines(architecture: str):
    path = CONFIG / EXAMPLES[architecture]
    model = ra.load(path)
    positions = (model.home_position, model.home_position + np.array(OFFSETS[architecture]))
    return load_manipulator(path), model, positions


def reachable(model: ra.ReferenceModel, angles, position) -> np.ndarray:
    return ra.evaluate(model, np.asarray(angles, dtype=float), position).reachable


@pytest.mark.parametrize("architecture", ["ups", "pus", "rus"])
def test_projected_boundaries_against_reference_sampling(architecture):
    manipulator, model, positions = machines(architecture)
    for position in positions:
        workspace = projected_workspace(
            manipulator, position, method="torsion_zero", n_phi=36, tolerance=TOLERANCE
        )
        assert 0.0 < workspace.tilt_min < math.pi
        for phi, theta in zip(workspace.phi, workspace.theta, strict=False):
            ray = np.linspace(0.0, theta, max(2, math.ceil(theta / GRID) + 1))
            inside = np.column_stack([np.full(ray.size, phi), ray, np.zeros(ray.size)])
            assert reachable(model, inside, position).all(), (position, phi, theta)
            if theta < math.pi:
                beyond = [[phi, theta + 1.01 * TOLERANCE, 0.0]]
                assert not reachable(model, beyond, position)[0], (position, phi, theta)
        exact = projected_workspace(
            manipulator, position, method="exact", n_phi=24, tolerance=TOLERANCE
        )
        boundary = np.column_stack([exact.phi, exact.theta, exact.psi])
        assert reachable(model, boundary, position).all()
        assert np.all(exact.theta >= 0.0)


@pytest.mark.parametrize("architecture", ["ups", "pus", "rus"])
def test_torsion_ranges_against_reference_sampling(architecture):
    manipulator, model, positions = machines(architecture)
    psi = np.linspace(-math.pi, math.pi, math.ceil(2 * math.pi / GRID) + 1)
    rng = np.random.default_rng(17)
    for position in positions:
        for phi, theta in zip(
            rng.uniform(-math.pi, math.pi, 4), np.radians([0.0, 5.0, 10.0, 14.0]), strict=False
        ):
            intervals = torsion_range(manipulator, phi, theta, position, tolerance=TOLERANCE)
            inside = np.zeros(psi.size, dtype=bool)
            near_end = np.zeros(psi.size, dtype=bool)
            for low, high in intervals.intervals:
                inside |= (psi >= low) & (psi <= high)
                near_end |= np.minimum(np.abs(psi - low), np.abs(psi - high)) <= 2 * TOLERANCE
            poses = np.column_stack([np.full(psi.size, phi), np.full(psi.size, theta), psi])
            verdict = reachable(model, poses, position)
            wrong = (verdict != inside) & ~near_end
            assert not wrong.any(), (position, phi, theta, psi[wrong][:5], intervals.intervals)
            assert inside.any()


def interpolate(angles0, angles1, position0, position1, s):
    """The tilt-torsion interpolation: T&T angles linear with wrapped Δφ, Δψ; position linear."""
    delta = np.asarray(angles1) - np.asarray(angles0)
    delta[[0, 2]] = (delta[[0, 2]] + math.pi) % (2 * math.pi) - math.pi
    s = np.asarray(s)[:, None]
    return angles0 + s * delta, position0 + s * (np.asarray(position1) - position0)


@pytest.mark.parametrize("architecture", ["ups", "pus", "rus"])
def test_certified_moves_against_reference_sampling(architecture):
    manipulator, model, positions = machines(architecture)
    rng = np.random.default_rng(1717)
    # Waypoints drawn from a cone wider than the workspace: some are unreachable, so the moves
    # out of a reachable waypoint into an unreachable one locate a first violation, and the
    # moves between reachable ones are mostly certified ok.
    count = 40
    tilt, torsion = WAYPOINTS[architecture]
    angles = np.column_stack(
        [
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(math.radians(2.0), tilt, count),
            rng.uniform(-torsion, torsion, count),
        ]
    )
    points = positions[0] + rng.uniform(-0.06, 0.06, (count, 3))
    result = check_path(
        manipulator, points, angles=angles, interpolation="tilt-torsion", tolerance=TOLERANCE
    )
    segments = result.segments
    np.testing.assert_array_equal(result.waypoints.reachable, reachable(model, angles, points))
    s = np.linspace(0.0, 1.0, 1000)
    seen = {"ok": 0, "violated": 0, "located": 0}
    for m in range(count - 1):
        poses, where = interpolate(angles[m], angles[m + 1], points[m], points[m + 1], s)
        verdict = reachable(model, poses, where)
        if segments.ok[m]:
            assert verdict.all(), (m, s[~verdict][:5])
            seen["ok"] += 1
            continue
        first = float(segments.first_violation_s[m])
        assert not ra.evaluate(
            model, segments.violation_angles[m][None], segments.violation_positions[m]
        ).reachable[0]
        # The true first violation is within one tolerance step before ``first``: in s, a
        # tolerance of platform rotation is TOLERANCE / (Ω + |Δp| / ρ) at most.
        rate = segments.angular_rate[m] + segments.translation[m] / model.rho
        step = 4 * TOLERANCE / max(rate, 1e-12)
        before = np.linspace(0.0, max(first - step, 0.0), 1000)
        poses, where = interpolate(angles[m], angles[m + 1], points[m], points[m + 1], before)
        if first - step > 0.0:
            assert reachable(model, poses, where).all(), (m, first)
            seen["located"] += 1
        seen["violated"] += 1
    assert seen["ok"] >= 3 and seen["located"] >= 3, seen
