"""The leg-architecture parameters of the model (6-PUS, 6-RUS): read, refused with one line
naming the parameter and the value, and served through the CLI (margins by name, ``null`` where
a leg has no inverse-kinematics solution, ``ik`` in ``violated``).

The numbers of the packaged examples come from their own comments (computed with the plain-numpy
reference ``test/reference_arch.py``); the margins of random poses are compared with that
reference in ``test_architectures_reference.py``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import reference_arch as ra
import yaml
from cli_support import one_error_line, run_main

from hexapod_workspace import check
from hexapod_workspace.core.base.rotations import tt_to_matrix
from hexapod_workspace.core.constraints.table import constraint_names
from hexapod_workspace.core.evaluation.loading import load_manipulator, manipulator_from_mapping
from hexapod_workspace.core.model.legs import leg_endpoints
from hexapod_workspace.errors import ConfigError, GeometryError

CONFIG = Path(__file__).resolve().parents[1] / "config"
EXAMPLES = {"pus": CONFIG / "example_pus.yaml", "rus": CONFIG / "example_rus.yaml"}
MOVING_NAMES = (
    "base_joint",
    "platform_joint",
    "leg_interference",
    "singularity",
    "actuator",
    "ik",
    "transmission",
)


def parameters(architecture: str) -> dict[str, Any]:
    tree = yaml.safe_load(EXAMPLES[architecture].read_text(encoding="utf-8"))
    parameters: dict[str, Any] = tree["hexapod_workspace"]["ros__parameters"]
    return parameters


def refusal(architecture: str, section: str, name: str, value: Any) -> str:
    tree = parameters(architecture)
    tree[section][name] = value
    with pytest.raises((GeometryError, ConfigError)) as error:
        manipulator_from_mapping(tree, warn=False)
    text = str(error.value)
    assert "\n" not in text
    return text


@pytest.mark.parametrize("architecture", ["pus", "rus"])
def test_examples_load_with_the_figures_of_their_comments(architecture):
    manipulator = load_manipulator(EXAMPLES[architecture])
    assert manipulator.architecture == architecture
    assert constraint_names(manipulator) == MOVING_NAMES
    home = check(manipulator, np.zeros((1, 3)), manipulator.home_position, singularity=True)
    assert home.reachable[0]
    expected = {
        "pus": {"actuator": 0.4497, "ik": 0.2873, "transmission": 0.6325, "singularity": 0.2686},
        "rus": {"actuator": 1.1866, "ik": 0.1173, "transmission": 0.8409, "singularity": 0.4041},
    }[architecture]
    for name, value in expected.items():
        assert home.margins[name][0] == pytest.approx(value, abs=6e-5), name


@pytest.mark.parametrize("architecture", ["pus", "rus"])
def test_leg_endpoints_close_the_legs(architecture, rng):
    """pose → q → leg ends: every solved leg has its fixed length; unsolved legs are NaN."""
    manipulator = load_manipulator(EXAMPLES[architecture])
    reference = ra.load(EXAMPLES[architecture])
    angles = np.column_stack(
        [rng.uniform(-math.pi, math.pi, 3000), rng.uniform(0, 0.8, 3000), rng.uniform(-1, 1, 3000)]
    )
    base, platform = leg_endpoints(manipulator, tt_to_matrix(angles), manipulator.position)
    lengths = np.linalg.norm(platform - base, axis=-1)
    q, _ = ra.inverse_kinematics(
        reference, ra.platform_points(reference, angles, reference.position)
    )
    solved = ~np.isnan(q)
    assert 0 < np.count_nonzero(~solved) < solved.size  # both kinds occur
    np.testing.assert_allclose(
        lengths[solved], np.broadcast_to(reference.leg_lengths, q.shape)[solved], atol=1e-12
    )
    assert np.all(np.isnan(base[~solved]))
    np.testing.assert_allclose(base[solved], ra.base_points(reference, q)[solved], atol=1e-12)


#: (architecture, section, parameter, bad value, what the one-line refusal says)
REFUSALS = [
    ("pus", "geometry", "rail_directions", [0.0] * 18,
     "geometry.rail_directions: expected non-zero directions, the rail of leg 1 has zero length"),
    ("rus", "geometry", "crank_zero_directions", [1.0, 0.0, 0.0] * 6,
     "geometry.crank_zero_directions: expected each perpendicular to its crank axis"),
    ("pus", "geometry", "branch", [0],
     "geometry.branch: expected +1 or -1 for every leg, got 0 for leg 1"),
    ("rus", "geometry", "branch", [1, 1, 1, 0.5, 1, 1],
     "geometry.branch: expected +1 or -1 for every leg, got 0.5 for leg 4"),
    ("pus", "geometry", "leg_lengths", [0.2],
     "geometry.home_position: expected a pose every leg can reach, leg 1 has no inverse-kin"),
    ("rus", "geometry", "leg_lengths", [2.0],
     "geometry.home_position: expected a pose every leg can reach, leg 1 has no inverse-kin"),
    ("pus", "limits", "leg_length_min", [0.8],
     "limits.leg_length_min: a parameter of geometry.architecture ups, given for pus"),
    ("rus", "geometry", "rail_directions", [1.0, 0.0, 0.0] * 6,
     "geometry.rail_directions: a parameter of geometry.architecture pus, given for rus"),
    ("pus", "geometry", "crank_lengths", [0.1],
     "geometry.crank_lengths: a parameter of geometry.architecture rus, given for pus"),
    ("pus", "geometry", "architecture", "prs",
     "geometry.architecture: expected one of ups, pus, rus, got 'prs'"),
    ("rus", "limits", "actuator_max", [8.0],
     "limits.actuator_min: expected limits.actuator_min < limits.actuator_max < limits.actu"),
    ("pus", "limits", "actuator_max", [-0.5],
     "limits.actuator_min: expected < limits.actuator_max for every leg, got -0.45 >= -0.5 m"),
    ("pus", "limits", "transmission_min", 0.0,
     "limits.transmission_min: expected one value in (0, 1), got 0.0"),
    ("rus", "geometry", "crank_lengths", [0.0],
     "geometry.crank_lengths: expected values > 0 m, got 0 for leg 1"),
]  # fmt: skip


@pytest.mark.parametrize(("architecture", "section", "name", "value", "expected"), REFUSALS)
def test_bad_architecture_parameters_are_refused_in_one_line(
    architecture, section, name, value, expected
):
    assert expected in refusal(architecture, section, name, value)


def test_ups_refuses_the_parameters_of_the_other_architectures(example):
    values = {**example.to_parameters(), "geometry.rail_directions": [1.0, 0.0, 0.0] * 6}
    with pytest.raises(ConfigError, match="geometry.rail_directions: a parameter of"):
        manipulator_from_mapping(values, warn=False)
    # Left empty (how the node holds an unused array parameter) they are not given.
    assert manipulator_from_mapping(example.to_parameters(), warn=False) == example


@pytest.mark.parametrize("architecture", ["pus", "rus"])
def test_parameters_round_trip(architecture):
    manipulator = load_manipulator(EXAMPLES[architecture])
    again = manipulator_from_mapping(manipulator.to_parameters(), warn=False)
    assert again == manipulator
    assert manipulator.to_parameters()["limits.leg_length_min"] == []


def test_missing_architecture_parameter_is_named():
    tree = parameters("rus")
    del tree["geometry"]["crank_axes"]
    with pytest.raises(ConfigError, match="geometry.crank_axes: required parameter is missing"):
        manipulator_from_mapping(tree, warn=False)


@pytest.mark.parametrize("architecture", ["pus", "rus"])
def test_cli_check_json_names_the_margins_and_nulls_the_undefined(architecture):
    """A pose where a leg has no solution: ``ik`` violated, ``null`` for every margin that
    needs that leg's coordinate; a reachable pose: every margin a number."""
    tilt = {"pus": "70", "rus": "60"}[architecture]
    code, out, err = run_main(
        "--config", str(EXAMPLES[architecture]), "--json", "check",
        "--pose", "0", "0", "0", "--pose", "0", tilt, "0", "--singularity",
    )  # fmt: skip
    assert code in (0, 1), err
    poses = json.loads(out)["poses"]
    assert list(poses[0]["margins"]) == list(MOVING_NAMES)
    assert poses[0]["reachable"] is True
    assert all(isinstance(v, float) for v in poses[0]["margins"].values())
    far = poses[1]
    assert far["reachable"] is False
    assert "ik" in far["violated"]
    assert far["margins"]["ik"] < 0.0
    for name in ("actuator", "transmission", "base_joint", "platform_joint", "singularity"):
        assert far["margins"][name] is None, name


def test_cli_refuses_a_bad_architecture_file_with_exit_2(tmp_path):
    tree = yaml.safe_load(EXAMPLES["pus"].read_text(encoding="utf-8"))
    tree["hexapod_workspace"]["ros__parameters"]["geometry"]["branch"] = [0]
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(tree), encoding="utf-8")
    code, _, err = run_main("--config", str(path), "check", "--pose", "0", "0", "0")
    assert code == 2
    assert "geometry.branch: expected +1 or -1 for every leg, got 0 for leg 1" in one_error_line(
        err
    )


@pytest.mark.parametrize("architecture", ["pus", "rus"])
def test_rate_bounds_hold_along_moves(architecture, rng):
    """Finite differences of every margin along dense moves stay below the rates derived in
    the constraint table's documentation (written out here, not read from the table), with
    τ_f the smallest |τ| met along the move: Q = V/τ_f (pus) or V/(r_min·τ_f) (rus),
    K = V/(r_min·τ_f) (rus), N = V(1 + 1/τ_f)/L_min, E = V/τ_f."""
    path = EXAMPLES[architecture]
    model = manipulator_from_mapping(
        {**load_manipulator(path).to_parameters(), "limits.singularity_min": 0.01},
        warn=False,
    )
    rho = float(np.max(np.linalg.norm(model.platform_joints, axis=1)))
    length = float(np.min(model.leg_lengths))
    crank = 1.0 / float(np.min(model.crank_lengths)) if architecture == "rus" else 0.0
    steps = 2001
    s = np.linspace(0.0, 1.0, steps)
    checked = 0
    for _ in range(30):
        a0 = np.array(
            [rng.uniform(-math.pi, math.pi), rng.uniform(0, 0.35), rng.uniform(-0.4, 0.4)]
        )
        a1 = np.array(
            [rng.uniform(-math.pi, math.pi), rng.uniform(0, 0.35), rng.uniform(-0.4, 0.4)]
        )
        p0 = model.position + rng.uniform(-0.04, 0.04, 3)
        p1 = model.position + rng.uniform(-0.04, 0.04, 3)
        angles = a0 + s[:, None] * (a1 - a0)
        positions = p0 + s[:, None] * (p1 - p0)
        rotations = tt_to_matrix(angles)
        results = [check(model, angles[k], positions[k]).margins for k in range(steps)]
        margins = {name: np.array([r[name][0] for r in results]) for name in MOVING_NAMES}
        if np.any(np.isnan(margins["actuator"])):
            continue  # a leg loses its solution on the way: no rate there
        checked += 1
        relative = np.einsum("nji,njk->nik", rotations[:-1], rotations[1:])
        cosine = np.clip((np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
        omega = np.arccos(cosine).max() * (steps - 1)
        speed = np.linalg.norm(p1 - p0) + rho * omega
        tau_f = float(np.min(margins["transmission"])) + model.transmission_min
        turn = speed * (1.0 + 1.0 / tau_f) / length
        bounds = {
            "actuator": speed / tau_f * (crank if architecture == "rus" else 1.0),
            "ik": speed,
            "transmission": turn + speed * crank / tau_f,
            "base_joint": turn + speed * crank / tau_f,
            "platform_joint": turn + omega,
            "leg_interference": 2.0 * speed / tau_f,
            "singularity": math.sqrt(12.0) * (turn + omega),
        }
        for name, bound in bounds.items():
            rate = np.abs(np.diff(margins[name])).max() * (steps - 1)
            assert rate <= bound * (1 + 1e-3) + 1e-9, (name, rate, bound)
    assert checked >= 10


@pytest.mark.parametrize("singularity_min", [0.0, 0.05])
@pytest.mark.parametrize("architecture", ["pus", "rus"])
def test_batch_check_equals_the_one_pose_kernel(architecture, singularity_min, rng):
    """The vectorised block path (legs without a solution included: NaN margins, the first
    unsolved leg) gives exactly what the one-pose kernel gives."""
    from hexapod_workspace.core.constraints.table import INDEX
    from hexapod_workspace.core.evaluation.check import check_pose

    base = load_manipulator(EXAMPLES[architecture]).to_parameters()
    model = manipulator_from_mapping({**base, "limits.singularity_min": singularity_min})
    angles = np.column_stack(
        [rng.uniform(-math.pi, math.pi, 800), rng.uniform(0, 0.9, 800), rng.uniform(-1, 1, 800)]
    )
    batch = check(model, angles, model.position)
    unsolved = np.isnan(batch.margins["actuator"])
    assert 0.05 < unsolved.mean() < 0.95
    for k in range(len(angles)):
        one = check_pose(model, *angles[k], model.position)
        for name in batch.margins:
            np.testing.assert_equal(batch.margins[name][k], one.margins[INDEX[name]], name)
            assert batch.limiting_legs[name][k] == one.limiting_legs[INDEX[name]], name
        assert tuple(batch.limiting_pair[k]) == one.limiting_pair
        assert bool(batch.reachable[k]) == one.reachable
        assert batch.limiting_constraint[k] == one.limiting_constraint
