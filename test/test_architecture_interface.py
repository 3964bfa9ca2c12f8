"""The declared interface of a leg architecture (``core/model/architectures``), checked against the
plain-numpy reference ``test/reference_arch.py`` written from the formulas.

Every constant and the lever a module declares selects a rate gain in the searches' and the
moves' bounds (``constraints/table.py``, ``motions/speeds.py``, ``motions/certificate.py``) and
the Jacobian row of the loads (``evaluation/loads.py``), so each is measured here, not restated:
``dq_i = n_i·dB_i / (r_i·τ_i)`` by central differences of the reference inverse kinematics along
the leg line; ``MOVING_BASE`` and ``TURNING_BASE`` by moving the actuator; the units by what q
is (a length changes with the machine's scale, an angle does not).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import reference_arch as ra

from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.core.model.architectures import ARCHITECTURES, CODES, module
from hexapod_workspace.core.model.legs import leg_endpoints
from hexapod_workspace.core.motions.speeds import ACTUATOR_MODELS

CONFIG = Path(__file__).resolve().parents[1] / "config"
EXAMPLES = {
    "ups": CONFIG / "example_gpm.yaml",
    "pus": CONFIG / "example_pus.yaml",
    "rus": CONFIG / "example_rus.yaml",
}
#: Poses (φ, θ, ψ), degrees, inside each example's workspace (the home pose and small tilts).
POSES_DEG = np.array([[0.0, 0.0, 0.0], [30.0, 5.0, 3.0], [200.0, 8.0, -4.0], [95.0, 3.0, 6.0]])


def test_the_registry_lists_every_architecture_once_with_a_code_and_an_actuator_model():
    assert set(ARCHITECTURES) == set(CODES) == set(ACTUATOR_MODELS) == set(EXAMPLES)
    assert sorted(CODES.values()) == list(range(len(ARCHITECTURES)))
    for name in ARCHITECTURES:
        assert ACTUATOR_MODELS[name].unit == module(name).ACTUATOR_UNIT


@pytest.mark.parametrize("name", ARCHITECTURES)
def test_the_lever_and_the_transmission_give_the_reference_actuator_rate(name):
    manipulator = load_manipulator(EXAMPLES[name])
    reference = ra.load(EXAMPLES[name])
    legs = module(name)
    rotations = tt_to_matrix(np.radians(POSES_DEG))
    _, platform = leg_endpoints(manipulator, rotations, manipulator.position)
    q, ik = legs.inverse_kinematics(manipulator, platform)
    assert np.all(ik >= 0.0), "the poses must be reachable by every leg"
    leg = platform - legs.base_ends(manipulator, q)
    n = leg / np.linalg.norm(leg, axis=-1, keepdims=True)
    predicted = 1.0 / (legs.actuator_lever(manipulator) * legs.transmission(manipulator, n, q))
    h = 1e-6
    q_plus, _ = ra.inverse_kinematics(reference, platform + h * n)
    q_minus, _ = ra.inverse_kinematics(reference, platform - h * n)
    measured = (q_plus - q_minus) / (2.0 * h)
    np.testing.assert_allclose(measured, predicted, rtol=1e-6)


@pytest.mark.parametrize("name", ARCHITECTURES)
def test_moving_and_turning_base_say_what_the_actuator_does_to_the_base_side_end(name):
    manipulator = load_manipulator(EXAMPLES[name])
    reference = ra.load(EXAMPLES[name])
    legs = module(name)
    points = ra.platform_points(reference, [[0.0, 0.0, 0.0]], reference.position)
    q = ra.inverse_kinematics(reference, points)[0]
    moved = q + 0.01
    ends_moved = not np.allclose(ra.base_points(reference, q), ra.base_points(reference, moved))
    axes = legs.base_axes(manipulator, q)
    axes_turned = not np.allclose(axes, legs.base_axes(manipulator, moved))
    assert legs.MOVING_BASE is ends_moved
    assert legs.TURNING_BASE is axes_turned
    # The package's base ends are the reference's.
    np.testing.assert_allclose(legs.base_ends(manipulator, q), ra.base_points(reference, q))


@pytest.mark.parametrize("name", ARCHITECTURES)
def test_the_units_are_those_of_the_actuated_coordinate(name):
    """A length scales with the machine, an angle does not: scale every length of the example by
    2 and compare q at the scaled pose."""
    reference = ra.load(EXAMPLES[name])
    legs = module(name)
    points = ra.platform_points(reference, np.radians([[30.0, 5.0, 3.0]]), reference.position)
    q, _ = ra.inverse_kinematics(reference, points)
    lengths = ("base_joints", "platform_joints", "home_position", "position", "leg_lengths")
    scaled = replace(
        reference,
        **{
            key: 2.0 * value
            for key in (*lengths, "crank_lengths")
            if (value := getattr(reference, key)) is not None
        },
    )
    q_scaled, _ = ra.inverse_kinematics(scaled, 2.0 * points)
    is_length = bool(np.allclose(q_scaled, 2.0 * q)) and not np.allclose(q, 0.0)
    is_angle = bool(np.allclose(q_scaled, q))
    assert is_length != is_angle
    declared = (legs.ACTUATOR_UNIT, legs.FORCE_UNIT)
    assert declared == (("m", "N") if is_length else ("rad", "N·m"))
