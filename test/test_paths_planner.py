"""The torsion planner's compiled programmes against the numpy ones they replaced.

Oracle: ``test/planner_reference.py`` (the numpy programmes, verbatim from before the kernels).
On seeded random tables with many ties (few distinct levels, symmetric torsion offsets of equal
travel) the kernels must give the same tables, the same candidate moves in the same order and the
same plans; end to end, ``plan_torsion`` must give the same plan, objective, checks and break
points with either.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import planner_reference as reference

from hexapod_workspace import plan_torsion
from hexapod_workspace.core.base.rotations import approach_vector, wrap_angle
from hexapod_workspace.core.kernels import planner as kernels
from hexapod_workspace.core.motions import planner as paths
from hexapod_workspace.core.motions.planner import _best_first

OFF_AXIS = np.array([0.2, 0.2, -0.95])


def random_tables(rng: np.random.Generator, count: int, size: int, reach: int | None):
    """Planner tables as ``_Planner`` builds them: waypoint levels (NONE where a torsion is
    unreachable), banded moves between reachable ends, unknown moves at the smaller end level,
    known moves at or below it, some moves checked and refused (NO)."""
    if reach is None or 2 * reach + 1 >= size:
        offsets = np.arange(size) - size // 2
    else:
        offsets = np.arange(-reach, reach + 1)
    dest = (np.arange(size)[:, None] + offsets[None, :]) % size
    source = (np.arange(size)[:, None] - offsets[None, :]) % size
    travel = np.abs(wrap_angle(offsets * (2.0 * np.pi / size)))
    feasible = rng.random((count, size)) < 0.6
    levels = np.where(feasible, rng.integers(-3, 6, (count, size)), kernels.NONE).astype(np.int32)
    shape = (count - 1, size, offsets.size)
    pairs = feasible[:-1, :, None] & feasible[1:][:, dest]
    optimistic = np.minimum(levels[:-1, :, None], levels[1:][:, dest])
    draw = rng.random(shape)
    status = np.where(
        pairs, np.where(draw < 0.4, kernels.KNOWN, np.where(draw < 0.8, kernels.UNKNOWN, 0)), 0
    ).astype(np.uint8)
    lowered = optimistic - rng.integers(0, 3, shape)
    value = np.where(
        status == kernels.KNOWN,
        lowered,
        np.where(status == kernels.UNKNOWN, optimistic, kernels.NONE),
    ).astype(np.int32)
    return levels, status, value, dest, source, travel, offsets


CASES = [(seed, size, reach) for seed in range(6) for size, reach in ((7, None), (12, 2), (9, 0))]


@pytest.mark.parametrize(("seed", "size", "reach"), CASES)
def test_compiled_programmes_equal_numpy(seed, size, reach):
    rng = np.random.default_rng(seed)
    count = int(rng.integers(2, 40))
    levels, status, value, dest, source, travel, offsets = random_tables(rng, count, size, reach)
    for optimistic in (False, True):
        compiled = np.empty(levels.shape, dtype=np.int32)
        kernels.forward(levels[0], status, value, dest, optimistic, compiled)
        expected = reference.forward(levels[0], status, value, source, offsets.size, optimistic)
        np.testing.assert_array_equal(compiled, expected)
    back = np.empty(levels.shape, dtype=np.int32)
    kernels.backward(levels, status, value, dest, back)
    np.testing.assert_array_equal(back, reference.backward(levels[-1], status, value, dest))

    reach_optimistic = reference.forward(levels[0], status, value, source, offsets.size, True)
    best = int(reference.forward(levels[0], status, value, source, offsets.size, False)[-1].max())
    for threshold in (best, max(best - 2, kernels.NONE), 0):
        k, g, b, through = kernels.candidates(
            reach_optimistic, back, status, value, dest, threshold
        )
        ek, eg, eb, e_through = reference.candidates(
            reach_optimistic, back, status, value, dest, threshold, batch=10**9
        )
        np.testing.assert_array_equal(np.stack([k, g, b]), np.stack([ek, eg, eb]))
        np.testing.assert_array_equal(through, e_through[ek, eg, eb])
        # The batch chosen from them: largest first, ties in (k, g, b) order.
        for batch in (1, 3, 10):
            top = _best_first(through, batch)
            bk, bg, bb, _ = reference.candidates(
                reach_optimistic, back, status, value, dest, threshold, batch
            )
            np.testing.assert_array_equal(
                np.stack([k[top], g[top], b[top]]), np.stack([bk, bg, bb])
            )

    if best != kernels.NONE:
        scale = float(count) * 4.0
        for level in (best, best - 1):
            path = kernels.smoothest(levels[0], status, value, dest, travel, level, scale)
            expected = reference.smoothest(levels[0], status, value, source, travel, level)
            np.testing.assert_array_equal(path, expected)


@pytest.mark.parametrize("seed", range(5))
def test_best_first_is_the_stable_argsort(seed):
    rng = np.random.default_rng(seed)
    values = rng.integers(-4, 4, int(rng.integers(1, 300))).astype(np.int32)
    for count in (1, 2, 17, 299, 400):
        expected = np.argsort(-values.astype(np.int64), kind="stable")[:count]
        np.testing.assert_array_equal(_best_first(values, count), expected)


def cone(count: int, tilt_deg: float):
    t = np.linspace(0.0, 2.0 * np.pi, count)
    positions = OFF_AXIS + np.column_stack([0.02 * np.cos(t), 0.02 * np.sin(t), 0 * t])
    return positions, approach_vector(t, np.radians(tilt_deg))


@pytest.mark.parametrize(
    ("count", "tilt", "step_deg", "max_dpsi_deg", "interpolation", "batch"),
    [
        (40, 17.0, 5.0, None, "slerp", None),  # no torsion limit: every grid pair a candidate
        (40, 17.0, 5.0, None, "slerp", 60),  # many batches, each the best 60 of the candidates
        (40, 17.0, 5.0, 5.0, "slerp", 25),
        (25, 17.0, 7.5, None, "tilt-torsion", 40),
        (25, 19.0, 7.5, None, "slerp", 100),  # the best plan's margin is level 0
        (25, 22.0, 7.5, None, "slerp", None),  # no plan: waypoint 1 has no torsion
    ],
)
def test_plans_equal_the_numpy_planner(
    example, monkeypatch, count, tilt, step_deg, max_dpsi_deg, interpolation, batch
):
    if batch is not None:
        monkeypatch.setattr(paths, "CHECK_BATCH", batch)
    positions, axes = cone(count, tilt)
    options = {
        "psi_step": np.radians(step_deg),
        "max_dpsi": None if max_dpsi_deg is None else np.radians(max_dpsi_deg),
        "interpolation": interpolation,
    }
    assert_same_plans(example, positions, axes, options)


def assert_same_plans(example, positions, axes, options) -> None:
    plan = plan_torsion(example, positions, axes, **options)
    with reference.numpy_planner():
        expected = plan_torsion(example, positions, axes, **options)
    assert plan.ok == expected.ok
    assert plan.objective == expected.objective
    assert plan.moves_checked == expected.moves_checked
    assert plan.breakpoint == expected.breakpoint
    if plan.ok:
        np.testing.assert_array_equal(plan.psi, expected.psi)


def test_segment_break_equals_the_numpy_planner(example):
    # test_paths' case: feasible torsions far apart at waypoints 1 and 2, max_dpsi forbids it.
    positions = np.tile(OFF_AXIS, (3, 1))
    directions = np.radians([[140.0, 24.0], [140.0, 24.0], [-120.0, 35.0]])
    axes = approach_vector(directions[:, 0], directions[:, 1])
    options = {"psi_step": np.radians(15.0), "max_dpsi": np.radians(15.0)}
    plan = plan_torsion(example, positions, axes, **options)
    assert plan.breakpoint is not None and plan.breakpoint.kind == "segment"
    assert_same_plans(example, positions, axes, options)
