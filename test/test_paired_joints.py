"""Paired joints: legs that share a joint centre, as builders draw the 6-3 and 3-3 designs.

The machine is LinuxCNC's hexapod simulation (``configs/sim/axis/vismach/hexapod-sim``:
``kinematics.hal`` at LinuxCNC/linuxcnc 99e6bc9c, the same coordinates as the defaults of
``src/emc/kinematics/genhexkins.h``; ``hexapod.ini`` at 14b07146: inches, ``HOME = 0 0 20``,
every strut 29.7466 in long there), whose base joints are three pairs. Its strut limits in the
INI are ±1000 (open); 25–35 in, 40° joint cones, 1.5 in legs and 4 in of joint at each shared
end are assumed here, as a builder of that machine would state them.

Independent evidence: the margins against :func:`reference.pose_margins_literal` (free lengths
from their definition in arc length, distances by end points and the interior critical point),
the certificate of moves against dense sampling, the rate bound against finite differences.
"""

from __future__ import annotations

import numpy as np
import pytest
from reference import pose_margins_literal
from test_paths import dense_poses

from hexapod_workspace import GeometryError, Manipulator, check, check_path
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.cell.scene_view import scene_view
from hexapod_workspace.core.constraints.table import INDEX, rate_bounds
from hexapod_workspace.core.evaluation.check import pose_margins
from hexapod_workspace.core.evaluation.loading import load_manipulator, manipulator_from_mapping

INCH = 0.0254
#: genhexkins.base.N / genhexkins.platform.N of kinematics.hal, inches.
LINUXCNC_BASE = np.array(
    [
        [-22.950, 13.250, 0.0],
        [22.950, 13.250, 0.0],
        [22.950, 13.250, 0.0],
        [0.000, -26.500, 0.0],
        [0.000, -26.500, 0.0],
        [-22.950, 13.250, 0.0],
    ]
)
LINUXCNC_PLATFORM = np.array(
    [
        [-1.000, 11.500, 0.0],
        [1.000, 11.500, 0.0],
        [10.459, -4.884, 0.0],
        [9.459, -6.616, 0.0],
        [-9.459, -6.616, 0.0],
        [-10.459, -4.884, 0.0],
    ]
)
HOME = np.array([0.0, 0.0, 20.0]) * INCH
INTERFERENCE = INDEX["leg_interference"]


def parameters(base=LINUXCNC_BASE, platform=LINUXCNC_PLATFORM, **changes) -> dict:
    """Dotted parameters of the LinuxCNC machine in metres (``changes`` override them)."""
    values = {
        "geometry.base_joints": (base * INCH).ravel().tolist(),
        "geometry.platform_joints": (platform * INCH).ravel().tolist(),
        "geometry.home_position": HOME.tolist(),
        "geometry.paired_joint_length": 4.0 * INCH,
        "limits.leg_length_min": [25.0 * INCH],
        "limits.leg_length_max": [35.0 * INCH],
        "limits.base_joint_max_angle": [np.radians(40.0)],
        "limits.platform_joint_max_angle": [np.radians(40.0)],
        "limits.leg_diameter": 1.5 * INCH,
    }
    values.update(changes)
    return values


def three_three() -> np.ndarray:
    """The platform joints of a 3-3 machine on LinuxCNC's base (whose legs 2–3, 4–5 and 6–1
    share a base joint): legs 1–2, 3–4 and 5–6 share a platform joint, the zig-zag 3-3 layout
    (no two legs share both joints)."""
    platform = LINUXCNC_PLATFORM.copy()
    platform[[0, 1]] = [0.0, 11.5, 0.0]
    platform[[2, 3]] = [9.959, -5.75, 0.0]
    platform[[4, 5]] = [-9.959, -5.75, 0.0]
    return platform


@pytest.fixture(scope="module")
def linuxcnc() -> Manipulator:
    return manipulator_from_mapping(parameters())


def test_linuxcnc_hexapod_is_accepted_with_its_three_base_pairs(linuxcnc):
    shared = {
        (int(i) + 1, int(j) + 1)
        for i, j, s in zip(*np.triu_indices(6, 1), linuxcnc.shared_base_pairs, strict=True)
        if s
    }
    assert shared == {(1, 6), (2, 3), (4, 5)}
    assert not linuxcnc.shared_platform_pairs.any()
    # The strut lengths at HOME are the INI's HOME_OFFSET (29.7466 in, rounded from the
    # three-decimal coordinates): the conversion of the machine is LinuxCNC's.
    legs = HOME + linuxcnc.platform_joints - linuxcnc.base_joints
    np.testing.assert_allclose(np.linalg.norm(legs, axis=1) / INCH, 29.7466, atol=5e-4)
    result = check(linuxcnc, [0.0, 0.0, 0.0], HOME)
    assert result.reachable[0]
    # The interference of the shared pairs is that of their free lengths: positive at home.
    assert result.margins["leg_interference"][0] > 0.0


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        (
            {"geometry.paired_joint_length": 0.0},
            "geometry.paired_joint_length: required when legs share a joint and "
            "limits.leg_diameter > 0 (legs 1 and 6 share a base joint)",
        ),
        (
            {"geometry.paired_joint_length": 26.0 * INCH},
            "geometry.paired_joint_length: expected less than 0.635 m (leg 1: "
            "limits.leg_length_min 0.635 m over its 1 shared joint(s)",
        ),
        (
            {"geometry.paired_joint_length": 101.6},
            "geometry.paired_joint_length: expected m",
        ),
        (
            {"geometry.base_joints": (np.repeat(LINUXCNC_BASE[:1], 6, axis=0) * INCH).ravel()},
            "geometry.base_joints: expected at most three legs per joint centre, joints 1, 2, "
            "3, 4, 5 and 6 coincide",
        ),
        (
            {"geometry.platform_joints": (LINUXCNC_PLATFORM[[0, 2, 2, 3, 4, 5]] * INCH).ravel()},
            "geometry.platform_joints: legs 2 and 3 share both their base and their platform joint",
        ),
    ],
)
def test_paired_joint_refusals_name_the_parameter(changes, message):
    with pytest.raises(GeometryError) as raised:
        manipulator_from_mapping(parameters(**changes))
    assert str(raised.value).startswith(message), str(raised.value)
    assert "\n" not in str(raised.value)


def test_a_paired_joint_length_without_shared_joints_is_refused(example_parameters):
    with pytest.raises(GeometryError, match=r"^geometry.paired_joint_length: given \(0.05 m\), "):
        manipulator_from_mapping({**example_parameters, "geometry.paired_joint_length": 0.05})


def test_shared_joints_need_no_length_when_interference_is_off():
    model = manipulator_from_mapping(
        parameters(**{"geometry.paired_joint_length": 0.0, "limits.leg_diameter": 0.0})
    )
    assert model.paired_joint_length == 0.0
    assert np.isinf(check(model, [0.0, 0.2, 0.0], HOME).margins["leg_interference"][0])


def test_paired_joints_of_moving_base_joints_are_refused():
    pus = load_manipulator(example_config_path().parent / "example_pus.yaml").to_parameters()
    base = np.reshape(pus["geometry.base_joints"], (6, 3))
    base[1] = base[0]
    with pytest.raises(GeometryError, match="paired joints are modelled for geometry.architecture"):
        manipulator_from_mapping({**pus, "geometry.base_joints": base.ravel().tolist()})


@pytest.mark.parametrize("layout", ["6-3", "3-3"])
def test_free_length_interference_agrees_with_the_literal_reference(layout):
    platform = LINUXCNC_PLATFORM if layout == "6-3" else three_three()
    model = manipulator_from_mapping(parameters(platform=platform), warn=False)
    rng = np.random.default_rng(20261203)
    count = 300
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, np.radians(45.0), count),
            rng.uniform(-0.8, 0.8, count),
        ]
    )
    positions = HOME + rng.uniform(-0.15, 0.15, (count, 3))
    literal = np.array(
        [
            pose_margins_literal(model, a, p)["leg_interference"]
            for a, p in zip(angles, positions, strict=True)
        ]
    )
    per_pose = pose_margins(model, tt_to_matrix(angles), positions)
    np.testing.assert_allclose(per_pose.margins[INTERFERENCE], literal, rtol=0, atol=1e-12)
    batch = np.array(
        [
            check(model, a, p).margins["leg_interference"][0]
            for a, p in zip(angles, positions, strict=True)
        ]
    )
    np.testing.assert_allclose(batch, literal, rtol=0, atol=1e-12)
    # The shared pairs do limit (the free lengths are exercised); on the 6-3 machine whole legs
    # limit too (both kinds of pair are compared).
    pairs = per_pose.limiting_pairs
    shared = model.shared_base_pairs | model.shared_platform_pairs
    index = {
        (int(i), int(j)): k for k, (i, j) in enumerate(zip(*np.triu_indices(6, 1), strict=True))
    }
    limited_by_shared = [shared[index[(int(i), int(j))]] for i, j in pairs]
    assert 0 < sum(limited_by_shared) < (count if layout == "6-3" else count + 1)


def _moves(count: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    positions = HOME + rng.uniform(-0.12, 0.12, (count, 3))
    angles = np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, np.radians(35.0), count),
            rng.uniform(-0.7, 0.7, count),
        ]
    )
    return positions, angles


@pytest.mark.parametrize("layout", ["6-3", "3-3"])
def test_moves_of_a_paired_machine_are_certified_against_dense_sampling(layout):
    platform = LINUXCNC_PLATFORM if layout == "6-3" else three_three()
    # Legs of 3 in: the shared pairs' free lengths limit many moves.
    model = manipulator_from_mapping(
        parameters(platform=platform, **{"limits.leg_diameter": 3.0 * INCH}), warn=False
    )
    positions, angles = _moves(120, seed=7)
    result = check_path(model, positions, angles=angles)
    samples = 4001
    s = np.linspace(0.0, 1.0, samples)
    missed = 0
    caught = 0
    for k in range(positions.shape[0] - 1):
        rotations, where = dense_poses(
            positions[k], positions[k + 1], angles[k], angles[k + 1], "slerp", s
        )
        dense = pose_margins(model, rotations, where)
        if result.segments.ok[k]:
            # Certified: no sample violates by more than the tolerance's worth of margin.
            worst = float(np.min(dense.margins[INTERFERENCE]))
            missed += worst < -1e-6
        elif result.segments.limiting_constraint[k] == INTERFERENCE:
            caught += 1
            # The reported first violation is a pose that violates.
            assert not check(
                model, result.segments.violation_angles[k], result.segments.violation_positions[k]
            ).reachable[0]
    assert missed == 0
    assert caught >= 3


@pytest.mark.parametrize("layout", ["6-3", "3-3"])
def test_the_rate_bound_of_free_lengths_holds_against_finite_differences(layout):
    platform = LINUXCNC_PLATFORM if layout == "6-3" else three_three()
    model = manipulator_from_mapping(
        parameters(platform=platform, **{"geometry.paired_joint_length": 8.0 * INCH}), warn=False
    )
    rho = float(np.max(np.linalg.norm(model.platform_joints, axis=1)))
    rng = np.random.default_rng(11)
    s = np.linspace(0.0, 1.0, 4001)
    worst = 0.0
    for _ in range(60):
        p0 = HOME + rng.uniform(-0.1, 0.1, 3)
        p1 = p0 + rng.uniform(-0.05, 0.05, 3)
        a0 = rng.uniform([-np.pi, 0.0, -0.5], [np.pi, 0.5, 0.5])
        a1 = a0 + rng.uniform(-0.3, 0.3, 3)
        rotations, where = dense_poses(p0, p1, a0, a1, "slerp", s)
        margins = pose_margins(model, rotations, where).margins[INTERFERENCE]
        relative = rotations[0].T @ rotations[-1]
        omega = float(np.arccos(np.clip((np.trace(relative) - 1.0) / 2.0, -1.0, 1.0)))
        speed = float(np.linalg.norm(p1 - p0)) + rho * omega  # V per unit s
        legs = (
            where[:, None, :]
            + np.einsum("nij,kj->nki", rotations, model.platform_joints)
            - model.base_joints
        )
        turn = speed / float(np.min(np.linalg.norm(legs, axis=2)))  # N = V/ℓ_f
        bound = rate_bounds(model, np.array([speed]), np.array([turn]), np.array([omega]))
        observed = float(np.max(np.abs(np.diff(margins)))) / (s[1] - s[0])
        worst = max(worst, observed / float(bound[INTERFERENCE, 0]))
    assert 0.0 < worst <= 1.0


def test_the_scene_s_closest_legs_are_the_margin_s(linuxcnc):
    """The picture and the markers name the pair and the margin the check gives (free lengths
    for the shared pairs, not the zero distance at their joint)."""
    rng = np.random.default_rng(3)
    shared_named = 0
    for _ in range(40):
        angles = rng.uniform([-np.pi, 0.0, -0.6], [np.pi, 0.6, 0.6])
        position = HOME + rng.uniform(-0.1, 0.1, 3)
        margins = pose_margins(linuxcnc, tt_to_matrix(angles)[None], position)
        view = scene_view(linuxcnc, tt_to_matrix(angles), position)
        assert view.closest is not None and view.closest.constraint == "leg_interference"
        assert view.closest.margin == pytest.approx(margins.margins[INTERFERENCE][0], abs=1e-12)
        # (Legs 1–2, 3–4 and 5–6 end 2 in apart at the platform: their distance ties, and
        # either picture of a tie is right; the margin is the check's.)
        shared_named += view.closest.name in ("leg 1 vs leg 6", "leg 2 vs leg 3", "leg 4 vs leg 5")
    assert shared_named > 0
