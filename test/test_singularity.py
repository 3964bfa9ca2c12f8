"""The singularity margin: σ_min of the homogenised Plücker matrix of the legs, certified.

Independent evidence: numpy's SVD of the matrix written from its definition
(``reference.singularity_literal``), finite differences against the rate bound derived in
``core/constraints/table.py``, and boundaries and moves against dense sampling.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from reference import _rotation, singularity_literal

from hexapod_workspace import (
    ConfigError,
    check,
    check_path,
    projected_workspace,
    torsion_range,
)
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.constraints.table import INDEX, SINGULARITY
from hexapod_workspace.core.evaluation.check import check_pose, inverse_kinematics, pose_margins
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping

LIMIT = 0.4  # limits the example near (0, 0, -1.3) m: σ_min 0.46 at the centre, 0.36 at the edge


@pytest.fixture(scope="module")
def limited(example):
    return manipulator_from_mapping(
        {**example.to_parameters(), "limits.singularity_min": LIMIT}, warn=False
    )


def _angles(rng, count):
    return np.column_stack(
        [
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(0.0, 0.8, count),
            rng.uniform(-1.5, 1.5, count),
        ]
    )


def _literal(manipulator, angles, position):
    rotation = _rotation(*angles)
    legs = [
        position + rotation @ manipulator.platform_joints[i] - manipulator.base_joints[i]
        for i in range(6)
    ]
    return singularity_literal(manipulator, rotation, legs)


def test_enforced_margin_equals_the_svd_of_the_definition(limited, rng):
    for position in (limited.position, np.array([0.2, 0.2, -0.95])):
        angles = _angles(rng, 1500)
        result = check(limited, angles, position)
        literal = np.array([_literal(limited, a, position) for a in angles])
        np.testing.assert_allclose(result.margins["singularity"], literal, rtol=0, atol=1e-10)
        others = np.all(
            [result.margins[n] >= 0 for n in result.margins if n != "singularity"], axis=0
        )
        np.testing.assert_array_equal(result.reachable, others & (literal >= 0.0))
        assert "singularity" in {name for names in result.violated for name in names}
        assert np.all(result.limiting_legs["singularity"] == 0)
    one = check_pose(limited, 0.3, 0.5, 0.2)
    batch = check(limited, [0.3, 0.5, 0.2])
    assert tuple(one.margins[INDEX[name]] for name in batch.margins) == tuple(
        batch.margins[name][0] for name in batch.margins
    )


def _hard_matrices(rng):
    """6×6 matrices on which an eigensolver for λ_min(MᵀM) can go wrong, with what they test:
    rows like the legs' Plücker rows; σ_min from 1e-8 to 0.1 with the next one within a factor
    1.5 (near singular, a close pair); all six singular values equal to 1e-9 (a cluster);
    orthogonal (six equal singular values); a repeated row (rank 5); zero."""
    plucker = []
    for _ in range(4000):
        n = rng.normal(size=(6, 3))
        n /= np.linalg.norm(n, axis=1)[:, None]
        b = rng.normal(size=(6, 3))
        plucker.append(np.hstack([n, np.cross(b, n) / np.linalg.norm(b, axis=1).max()]))
    shaped = []
    for kind in ("near", "cluster"):
        for m in plucker[:500]:
            u, s, vt = np.linalg.svd(m)
            if kind == "near":
                s[-1] = 10.0 ** rng.uniform(-8.0, -1.0)
                s[-2] = s[-1] * rng.uniform(1.0, 1.5)
            else:
                s[:] = s[0] * (1.0 + 1e-9 * rng.normal(size=6))
            shaped.append((u * s) @ vt)
    orthogonal = list(np.linalg.qr(rng.normal(size=(200, 6, 6)))[0])
    repeated = [m.copy() for m in plucker[:200]]
    for m in repeated:
        m[5] = m[4]
    return np.array(plucker + shaped + orthogonal + repeated + [np.zeros((6, 6))])


def test_smallest_singular_value_kernel_against_numpy_svd(rng):
    """The kernel's σ_min (Householder tridiagonalisation + Laguerre's iteration from below)
    against LAPACK's SVD, on the matrices of :func:`_hard_matrices`: λ_min = σ_min² within
    256 ε·‖MᵀM‖. Forming G = MᵀM in floating point moves each entry by at most
    6ε·(|M|ᵀ|M|)_ij, so its eigenvalues by at most 36 ε·‖G‖ (‖|M|‖² ≤ 6‖M‖²); the reduction and
    the iteration add a few ε·‖G‖ (numpy's eigvalsh of the same G is off by as much on the
    clusters). NaN in, NaN out."""
    from hexapod_workspace.core.kernels.singularity import ROWS_SCRATCH, _smallest_singular_value

    matrices = _hard_matrices(rng)
    expected = np.linalg.svd(matrices, compute_uv=False)
    rows = np.empty(ROWS_SCRATCH)
    got = np.empty(len(matrices))
    for index, m in enumerate(matrices):
        rows[:36] = m.reshape(-1)
        got[index] = _smallest_singular_value(rows)
    norm = expected[:, 0] ** 2
    error = np.abs(got**2 - expected[:, -1] ** 2)
    assert np.all(error <= 256 * np.finfo(float).eps * np.maximum(norm, 1e-300)), error.max()
    # where σ_min is not tiny, σ itself to 1e-12 (the margins' tests ask 1e-10)
    wide = expected[:, -1] > 1e-3
    np.testing.assert_allclose(got[wide], expected[wide, -1], rtol=0, atol=1e-12)
    rows[:36] = matrices[0].reshape(-1)
    rows[7] = np.nan
    assert math.isnan(_smallest_singular_value(rows))


def test_free_when_zero_and_a_report_on_request(example, rng):
    angles = _angles(rng, 2000)
    plain = check(example, angles)
    assert np.all(np.isinf(plain.margins["singularity"]))
    reported = check(example, angles, singularity=True)
    np.testing.assert_array_equal(reported.reachable, plain.reachable)
    assert np.all(reported.margins["singularity"] >= 0.0)
    literal = np.array([_literal(example, a, example.position) for a in angles[:300]])
    np.testing.assert_allclose(reported.margins["singularity"][:300], literal, atol=1e-10)


def test_rate_bound_holds_along_rays_and_moves(limited, rng):
    """|Δσ| ≤ √12·(V/ℓ_f + Ω)·Δs, V = joint speed, ℓ_f the shortest leg on the way."""
    rho = max(np.linalg.norm(limited.platform_joints, axis=1))
    steps = 2001
    s = np.linspace(0.0, 1.0, steps)
    for _ in range(20):
        a0, a1 = _angles(rng, 2)
        p0 = limited.position + rng.uniform(-0.1, 0.1, 3)
        p1 = limited.position + rng.uniform(-0.1, 0.1, 3)
        angles = a0 + s[:, None] * (a1 - a0)
        positions = p0 + s[:, None] * (p1 - p0)
        rotations = tt_to_matrix(angles)
        margins = pose_margins(limited, rotations, positions).margins[SINGULARITY]
        lengths = inverse_kinematics(limited, rotations, positions).lengths
        # Angular rate from consecutive rotations, an upper estimate of Ω over each step.
        relative = np.einsum("nji,njk->nik", rotations[:-1], rotations[1:])
        cosine = np.clip((np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
        omega = np.arccos(cosine).max() * (steps - 1)
        speed = np.linalg.norm(p1 - p0) + rho * omega
        bound = math.sqrt(12.0) * (speed / lengths.min() + omega)
        rate = np.abs(np.diff(margins)).max() * (steps - 1)
        assert rate <= bound * (1 + 1e-3) + 1e-9


def test_boundaries_against_dense_sampling(limited):
    position = np.array([0.0, 0.0, -1.3])
    workspace = projected_workspace(limited, position, n_phi=24, tolerance=1e-6)
    assert "singularity" in workspace.limiting
    free = projected_workspace(
        manipulator_from_mapping({**limited.to_parameters(), "limits.singularity_min": 0.0}),
        position,
        n_phi=24,
    )
    assert np.all(workspace.theta <= free.theta + 1e-9)
    assert np.any(workspace.theta < free.theta - 1e-3)
    for phi, theta in zip(workspace.phi, workspace.theta, strict=True):
        tilts = np.linspace(0.0, theta, 4000)
        poses = np.column_stack([np.full(tilts.size, phi), tilts, np.zeros(tilts.size)])
        assert check(limited, poses, position).reachable.all()
        assert not check(limited, [phi, theta + 2e-6, 0.0], position).reachable[0]
    # The torsion range at one direction: every interval reachable inside, not just beyond.
    ranges = torsion_range(limited, 0.7, 0.3, position)
    for low, high in ranges.intervals:
        psi = np.linspace(low, high, 3000)
        poses = np.column_stack([np.full(psi.size, 0.7), np.full(psi.size, 0.3), psi])
        assert check(limited, poses, position).reachable.all()


def test_moves_against_dense_sampling(limited, rng):
    count = 60
    positions = limited.position + rng.uniform(-0.08, 0.08, (count, 3))
    angles = _angles(rng, count) * np.array([1.0, 0.5, 0.4])
    result = check_path(limited, positions, angles=angles, interpolation="tilt-torsion")
    reasons = {name for names in result.segments.violated for name in names}
    assert "singularity" in reasons
    s = np.linspace(0.0, 1.0, 20_000)
    rate = result.segments.angular_rate + result.segments.translation / 0.3
    for k in range(count - 1):
        delta = angles[k + 1] - angles[k]
        delta[[0, 2]] = (delta[[0, 2]] + math.pi) % (2 * math.pi) - math.pi
        poses = tt_to_matrix(angles[k] + s[:, None] * delta)
        where = positions[k] + s[:, None] * (positions[k + 1] - positions[k])
        violated = ~pose_margins(limited, poses, where).reachable
        if result.segments.ok[k]:
            assert not violated.any(), k
        elif violated.any():
            first = s[np.argmax(violated)]
            tolerance_s = result.tolerance / rate[k]
            assert result.segments.first_violation_s[k] <= first + tolerance_s + 1e-4


@pytest.mark.parametrize("value", [-0.1, 1.5, math.nan, [0.1, 0.2]])
def test_bad_limit_is_refused_naming_it(example, value):
    with pytest.raises(ConfigError, match="limits.singularity_min"):
        manipulator_from_mapping({**example.to_parameters(), "limits.singularity_min": value})


def test_cli_reports_singularity_on_request(tmp_path, example):
    from cli_support import run_main

    code, out, err = run_main("--json", "check", "--pose", "0", "10", "0")
    assert code == 0, err
    assert json.loads(out)["poses"][0]["margins"]["singularity"] is None
    code, out, err = run_main("--json", "check", "--singularity", "--pose", "0", "10", "0")
    assert code == 0, err
    reported = json.loads(out)["poses"][0]["margins"]["singularity"]
    expected = check(example, np.radians([0.0, 10.0, 0.0]), singularity=True)
    assert reported == pytest.approx(expected.margins["singularity"][0], abs=1e-11)
    # sigma_min is 0.4615 at home and 0.4460 at (0, 10, 0) deg: a limit between them keeps the
    # home pose reachable (a model whose home pose is not is refused) and refuses the pose.
    parameters = {**example.to_parameters(), "limits.singularity_min": 0.455}
    config = tmp_path / "limited.yaml"
    config.write_text(
        "/**:\n  ros__parameters:\n"
        + "".join(f"    {name}: {value!r}\n" for name, value in parameters.items())
    )
    code, out, err = run_main("--config", str(config), "--json", "check", "--pose", "0", "10", "0")
    assert code == 1
    assert json.loads(out)["poses"][0]["violated"] == ["singularity"]


def test_a_reported_singularity_margin_never_limits_a_pose(example):
    """Asked for as a report (limits.singularity_min 0), the singularity margin is shown but
    neither the verdicts nor the limiting constraint and leg change."""
    rng = np.random.default_rng(20261124)
    angles = np.column_stack(
        [rng.uniform(-np.pi, np.pi, 5000), rng.uniform(0.0, 1.2, 5000), rng.uniform(-1, 1, 5000)]
    )
    plain = check(example, angles)
    reported = check(example, angles, singularity=True)
    assert np.all(np.isfinite(reported.margins["singularity"]))
    np.testing.assert_array_equal(plain.reachable, reported.reachable)
    np.testing.assert_array_equal(plain.limiting_constraint, reported.limiting_constraint)
    np.testing.assert_array_equal(plain.limiting_leg, reported.limiting_leg)
