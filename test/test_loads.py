"""Loads at a pose (core.evaluation.loads, the ``loads`` command) against a plain-numpy reference
written from the conventions of docs/theory.md ("Loads"):

* J from central finite differences of the actuator coordinates of test/reference_arch.py (its
  own inverse kinematics from the architectures' formulas, not the package's), over ≥ 10⁵
  random reachable poses per architecture;
* actuator forces from virtual work, τ = −J⁻ᵀ·w, with that J;
* the worst force over the process box against its 64 vertices and random interior wrenches;
* deflection and accuracy against the vertices and random interior points;
* the payload capacity against a dense sweep of the mass.

Finite differences: step h = 1e-7 (m, rad) on inputs of order 1, central, so the truncation
error is ~h²·|q'''|/6 and rounding ~ε·|q|/h ≈ 1e-8 (|q| up to π rad); J is compared with 1e-6
relative to its row. The rows grow like 1/τ near a transmission singularity, where q''' grows
like 1/τ³: poses with |τ| < 0.05 are left out of the comparison (and counted). Measured on the
6-RUS example at |τ| = 0.051, the worst pose: 2.7e-6 at h = 1e-6, 2.7e-8 at 1e-7 (the error
scales as h², truncation, so the kernel's J is the derivative).
"""

from __future__ import annotations

import itertools
import json
import math
import re
import shlex
from pathlib import Path

import numpy as np
import pytest
import reference_arch as ra
import yaml
from cli_support import one_error_line, run_main

from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.core.evaluation.loads import (
    LoadCase,
    actuator_jacobian,
    load_case_from_mapping,
    load_rows,
    loads_at,
)
from hexapod_workspace.errors import ConfigError

CONFIG = Path(__file__).resolve().parents[1] / "config"
EXAMPLES = {"ups": "example_gpm.yaml", "pus": "example_pus.yaml", "rus": "example_rus.yaml"}
POSES = 100_000
STEP = 1e-7
MIN_TRANSMISSION = 0.05


def skew(axis: int) -> np.ndarray:
    e = np.zeros(3)
    e[axis] = 1.0
    return np.array([[0.0, -e[2], e[1]], [e[2], 0.0, -e[0]], [-e[1], e[0], 0.0]])


def turn(axis: int, angle: float) -> np.ndarray:
    """exp(angle·[e_axis]×), Rodrigues, written here."""
    k = skew(axis)
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def random_poses(model: ra.ReferenceModel, count: int, seed: int):
    rng = np.random.default_rng(seed)
    angles = np.column_stack(
        [
            rng.uniform(-math.pi, math.pi, count),
            rng.uniform(0.0, math.radians(25.0), count),
            rng.uniform(-math.radians(25.0), math.radians(25.0), count),
        ]
    )
    positions = model.position + rng.uniform(-0.04, 0.04, (count, 3))
    return ra.rotation_matrices(angles), positions


def coordinates(model: ra.ReferenceModel, rotations, positions) -> np.ndarray:
    platform = positions[:, None, :] + np.einsum("nkl,il->nik", rotations, model.platform_joints)
    q, _ = ra.inverse_kinematics(model, platform)
    return q


def reference_jacobian(model: ra.ReferenceModel, rotations, positions) -> np.ndarray:
    """J (n, 6, 6) by central differences of q along the six twist directions (base frame)."""
    columns = []
    for axis in range(6):
        if axis < 3:
            shift = np.zeros(3)
            shift[axis] = STEP
            plus = coordinates(model, rotations, positions + shift)
            minus = coordinates(model, rotations, positions - shift)
        else:
            plus = coordinates(model, turn(axis - 3, STEP) @ rotations, positions)
            minus = coordinates(model, turn(axis - 3, -STEP) @ rotations, positions)
        change = plus - minus
        if model.architecture == "rus":  # crank angles live on a circle
            change = np.mod(change + math.pi, 2.0 * math.pi) - math.pi
        columns.append(change / (2.0 * STEP))
    return np.stack(columns, axis=-1)


def reference_transmission(model: ra.ReferenceModel, rotations, positions) -> np.ndarray:
    platform = positions[:, None, :] + np.einsum("nkl,il->nik", rotations, model.platform_joints)
    q, _ = ra.inverse_kinematics(model, platform)
    base = ra.base_points(model, q)
    n = (platform - base) / np.linalg.norm(platform - base, axis=-1, keepdims=True)
    if model.architecture == "ups":
        return np.ones(q.shape)
    if model.architecture == "pus":
        return np.sum(n * model.rail_directions, axis=-1)
    w, e = model.crank_axes, model.crank_zero_directions
    f = np.cross(w, e)
    tangent = np.cos(q)[..., None] * f - np.sin(q)[..., None] * e
    return np.sum(n * tangent, axis=-1)


@pytest.mark.parametrize("architecture", ["ups", "pus", "rus"])
def test_jacobian_agrees_with_finite_differences_of_the_reference(architecture):
    path = CONFIG / EXAMPLES[architecture]
    reference, manipulator = ra.load(path), load_manipulator(path)
    rotations, positions = random_poses(reference, int(POSES * 1.6), seed=11)
    expected = reference_jacobian(reference, rotations, positions)
    usable = np.all(np.isfinite(expected), axis=(1, 2))
    transmission = reference_transmission(reference, rotations, positions)
    well = usable & np.all(np.abs(transmission) >= MIN_TRANSMISSION, axis=1)
    assert well.sum() >= POSES, (architecture, int(usable.sum()), int(well.sum()))
    got = actuator_jacobian(manipulator, rotations[well], positions[well])
    want = expected[well]
    scale = 1.0 + np.linalg.norm(want, axis=-1, keepdims=True)
    assert np.max(np.abs(got - want) / scale) < 1e-6
    # Where a leg has no solution, J has NaN rows (never a finite wrong value).
    outside = ~np.all(np.isfinite(coordinates(reference, rotations, positions)), axis=1)
    if outside.any():
        rows = actuator_jacobian(manipulator, rotations[outside][:50], positions[outside][:50])
        assert np.all(np.isnan(rows).any(axis=(1, 2)))


def case_for(architecture: str) -> LoadCase:
    """A spindle of 40 kg below the tool tip and a cutting box of ±300 N, ±20 N·m."""
    crank = architecture == "rus"
    return load_case_from_mapping(
        {
            "load.mass": 40.0,
            "load.center_of_mass": [0.01, -0.02, 0.15],
            "process.wrench": [50.0, -20.0, 100.0, 1.0, 0.0, -2.0],
            "process.wrench_range": [300.0, 300.0, 300.0, 20.0, 20.0, 20.0],
            "limits.actuator_force_max": [400.0 if crank else 4000.0],
            "limits.actuator_force_min": [-300.0 if crank else -2500.0],
            "stiffness.actuator": [2e5 if crank else 2e7],
            "limits.deflection_max": 1e-4,
            "accuracy.actuator_error": [1e-4 if crank else 5e-6],
            "limits.accuracy_max": 2e-5,
        }
    )


def vertex_wrenches(case: LoadCase, rotation: np.ndarray) -> np.ndarray:
    r6 = np.zeros((6, 6))
    r6[:3, :3] = r6[3:, 3:] = rotation
    signs = np.array(list(itertools.product((-1.0, 1.0), repeat=6)))
    return (case.wrench + signs * case.wrench_range) @ r6.T


def gravity_wrench(case: LoadCase, rotation: np.ndarray) -> np.ndarray:
    weight = case.mass * case.gravity
    return np.concatenate([weight, np.cross(rotation @ case.center_of_mass, weight)])


def well_conditioned(architecture: str, count: int, seed: int):
    """The model and (R, p, reference J) of random poses where J is finite and cond(J) ≤ 1e6."""
    path = CONFIG / EXAMPLES[architecture]
    reference, manipulator = ra.load(path), load_manipulator(path)
    rotations, positions = random_poses(reference, count, seed=seed)
    jacobians = reference_jacobian(reference, rotations, positions)
    poses = [
        (rotation, position, jac)
        for rotation, position, jac in zip(rotations, positions, jacobians, strict=True)
        if np.all(np.isfinite(jac)) and np.linalg.cond(jac) <= 1e6
    ]
    return manipulator, poses


@pytest.mark.parametrize("architecture", ["ups", "pus", "rus"])
def test_forces_box_deflection_accuracy_and_capacity_against_enumeration(architecture):
    manipulator, poses = well_conditioned(architecture, 600, seed=5)
    case = case_for(architecture)
    rng = np.random.default_rng(9)
    assert len(poses) >= 300, len(poses)
    for rotation, position, jac in poses:
        got = loads_at(manipulator, case, rotation, position)
        assert not got.singular
        # Virtual work with the reference J: Jᵀτ + w = 0.
        wrenches = gravity_wrench(case, rotation) + vertex_wrenches(case, rotation)
        forces = -np.linalg.solve(jac.T, wrenches.T).T  # (64, 6)
        centre = -np.linalg.solve(
            jac.T, gravity_wrench(case, rotation) + vertex_wrenches(case, rotation).mean(axis=0)
        )
        scale = 1e-6 * (1.0 + np.max(np.abs(forces)))
        assert np.allclose(got.actuator_force, centre, atol=scale)
        # The box's extremes are at its vertices, and interior wrenches stay inside them.
        low, high = (
            got.actuator_force - got.actuator_force_spread,
            got.actuator_force + (got.actuator_force_spread),
        )
        assert np.allclose(forces.min(axis=0), low, atol=scale)
        assert np.allclose(forces.max(axis=0), high, atol=scale)
        assert np.allclose(np.abs(forces).max(axis=0), got.actuator_force_worst, atol=scale)
        inner = gravity_wrench(case, rotation) + vertex_wrenches(case, rotation)[0] * 0.0
        sigma = rng.uniform(-1.0, 1.0, (200, 6))
        r6 = np.zeros((6, 6))
        r6[:3, :3] = r6[3:, 3:] = rotation
        inner = inner + (case.wrench + sigma * case.wrench_range) @ r6.T
        inside = -np.linalg.solve(jac.T, inner.T).T
        assert np.all(inside >= low - scale) and np.all(inside <= high + scale)
        margin = np.min(
            np.minimum(case.force_max - forces.max(axis=0), forces.min(axis=0) - case.force_min)
        )
        assert got.force_margin == pytest.approx(margin, abs=scale)
        # Deflection: K = Jᵀ diag(k) J, δ = K⁻¹·w (process wrench only), at the vertices.
        stiffness = jac.T @ np.diag(case.stiffness) @ jac
        assert np.allclose(got.stiffness, stiffness, rtol=1e-5, atol=1e-6 * np.abs(stiffness).max())
        moves = np.linalg.solve(stiffness, vertex_wrenches(case, rotation).T).T
        assert got.deflection_m == pytest.approx(np.linalg.norm(moves[:, :3], axis=1).max(), 1e-5)
        assert got.deflection_rad == pytest.approx(np.linalg.norm(moves[:, 3:], axis=1).max(), 1e-5)
        # Accuracy: J⁻¹·δq over the error box.
        errors = np.array(list(itertools.product((-1.0, 1.0), repeat=6))) * case.actuator_error
        tool = np.linalg.solve(jac, errors.T).T
        assert got.accuracy_m == pytest.approx(np.linalg.norm(tool[:, :3], axis=1).max(), 1e-5)
        assert got.accuracy_rad == pytest.approx(np.linalg.norm(tool[:, 3:], axis=1).max(), 1e-5)
        inner_errors = rng.uniform(-1.0, 1.0, (200, 6)) * case.actuator_error
        inner_tool = np.linalg.solve(jac, inner_errors.T).T
        assert np.linalg.norm(inner_tool[:, :3], axis=1).max() <= got.accuracy_m * (1 + 1e-9)


def holds(jac: np.ndarray, case: LoadCase, rotation: np.ndarray, mass: float) -> bool:
    """Every vertex of the process box held with this mass (the reference's own statics)."""
    weight = mass * case.gravity
    gravity = np.concatenate([weight, np.cross(rotation @ case.center_of_mass, weight)])
    forces = -np.linalg.solve(jac.T, (gravity + vertex_wrenches(case, rotation)).T).T
    return bool(np.all(forces <= case.force_max) and np.all(forces >= case.force_min))


@pytest.mark.parametrize("architecture", ["ups", "pus", "rus"])
def test_payload_capacity_against_a_dense_sweep_of_the_mass(architecture):
    manipulator, poses = well_conditioned(architecture, 60, seed=21)
    case = case_for(architecture)
    seen = {"zero": 0, "positive": 0}
    for rotation, position, jac in poses:
        capacity = loads_at(manipulator, case, rotation, position).payload_capacity
        assert capacity is not None and capacity >= 0.0
        if capacity == 0.0:
            seen["zero"] += 1
            assert not holds(jac, case, rotation, 0.0) or not holds(jac, case, rotation, 1e-3)
            continue
        seen["positive"] += 1
        masses = np.linspace(0.0, capacity * (1.0 - 1e-6), 400)
        assert all(holds(jac, case, rotation, m) for m in masses)
        assert not holds(jac, case, rotation, capacity * (1.0 + 1e-6) + 1e-9)
    assert seen["positive"] >= 10, seen


def test_a_pose_out_of_reach_is_singular_never_a_finite_answer():
    manipulator = load_manipulator(CONFIG / EXAMPLES["pus"])
    case = case_for("pus")
    far = manipulator.position + np.array([0.0, 0.0, -5.0])
    got = loads_at(manipulator, case, np.eye(3), far)
    assert got.singular
    assert got.force_margin == -math.inf and got.payload_capacity == 0.0
    assert np.all(np.isinf(got.actuator_force_worst)) and got.deflection_m == math.inf


def test_a_symmetric_vertical_load_is_shared_by_the_six_legs():
    """Statics by hand: at the home pose of the axisymmetric example (a 120° symmetric design,
    legs mirrored in pairs), a weight through the axis has no moment about it that any leg
    could take alone; every leg carries F = M·g / (6·n_z) along its direction (n_z the
    vertical component of its unit direction from base to platform): negative, a pull, on this
    machine whose platform hangs below its base."""
    manipulator = load_manipulator(CONFIG / EXAMPLES["ups"])
    case = LoadCase(mass=10.0)
    got = loads_at(manipulator, case, np.eye(3), manipulator.home_position)
    legs = manipulator.platform_joints + manipulator.home_position - manipulator.base_joints
    n_z = legs[:, 2] / np.linalg.norm(legs, axis=1)
    assert np.allclose(got.actuator_force, 10.0 * 9.81 / (6.0 * n_z), rtol=1e-9)
    # Ceiling against pedestal: gravity reversed, every force changes sign.
    flipped = loads_at(
        manipulator,
        LoadCase(mass=10.0, gravity=np.array([0.0, 0.0, 9.81])),
        np.eye(3),
        manipulator.home_position,
    )
    assert np.allclose(flipped.actuator_force, -got.actuator_force)


@pytest.mark.parametrize(
    ("name", "value", "expected"),
    [
        ("load.mass", -1.0, "load.mass: expected one number >= 0 (kg), got -1.0"),
        ("load.center_of_mass", [0.0, 1.0], "load.center_of_mass: expected 3 numbers"),
        ("process.wrench_range", [1, 1, 1, 1, 1, -1], "process.wrench_range: expected half-widths"),
        ("limits.actuator_force_max", [1, 2], "limits.actuator_force_max: expected 1 or 6"),
        ("limits.actuator_force_max", [0.0], "limits.actuator_force_max: expected values > 0"),
        ("limits.deflection_max", 1e-4, "limits.deflection_max: needs stiffness.actuator"),
        ("limits.accuracy_max", 1e-5, "limits.accuracy_max: needs accuracy.actuator_error"),
        ("limits.actuator_force_min", [-5.0], "limits.actuator_force_min: needs"),
    ],
)
def test_a_bad_loads_parameter_is_refused_in_one_line_naming_it(name, value, expected):
    with pytest.raises(ConfigError) as caught:
        load_case_from_mapping({name: value})
    assert str(caught.value).startswith(expected)
    assert "\n" not in str(caught.value)


def test_force_min_must_lie_below_force_max():
    with pytest.raises(ConfigError, match="limits.actuator_force_min: expected each below"):
        load_case_from_mapping(
            {"limits.actuator_force_max": [100.0], "limits.actuator_force_min": [150.0]}
        )


def loads_file(tmp_path: Path, extra: dict, name: str = "loads.yaml") -> Path:
    document = yaml.safe_load((CONFIG / EXAMPLES["ups"]).read_text())
    document["hexapod_workspace"]["ros__parameters"].update(extra)
    path = tmp_path / name
    path.write_text(yaml.safe_dump(document))
    return path


WORKED = {
    "load": {"mass": 40.0, "center_of_mass": [0.0, 0.0, 0.2]},
    "process": {"wrench_range": [300.0, 300.0, 300.0, 0.0, 0.0, 0.0]},
    "limits": {
        **yaml.safe_load((CONFIG / EXAMPLES["ups"]).read_text())["hexapod_workspace"][
            "ros__parameters"
        ]["limits"],
        "actuator_force_max": [700.0],
    },
    "stiffness": {"actuator": [3.0e7]},
    "accuracy": {"actuator_error": [2e-6]},
}


def test_loads_command_answers_the_pose_and_the_searches_refuse_its_limits(tmp_path):
    path = loads_file(tmp_path, WORKED)
    code, out, err = run_main("--config", str(path), "--json", "loads", "--pose", "0", "0", "0")
    assert code == 0, err
    document = json.loads(out)
    assert len(document["actuator_force_n"]) == 6 and document["singular"] is False
    assert document["payload_capacity_kg"] > 40.0 and document["force_margin_n"] > 0.0
    assert document["deflection_m"] > 0.0 and document["accuracy_m"] > 0.0
    assert np.asarray(document["stiffness"]).shape == (6, 6)
    # A tilt the geometry allows but legs of 700 N do not carry (the worked example).
    code, out, err = run_main("--config", str(path), "--json", "loads", "--pose", "0", "30", "0")
    assert code == 1 and "actuator_force" in json.loads(out)["violated"]
    assert "limits exceeded at this pose: actuator_force" in err
    code, _, err = run_main("--config", str(path), "projected", "--n-phi", "8")
    assert code == 2
    assert one_error_line(err).endswith(
        "limits.actuator_force_max: a loads limit, read by 'hexapod-workspace loads' and "
        "'check' only (and the node's pose verdicts); the workspace searches and motions do "
        "not take it as a constraint yet (leave it out of this file)"
    )
    # Without the limits, the same file's loads do not change a geometric verdict.
    relaxed = dict(WORKED, limits=dict(WORKED["limits"], actuator_force_max=[]))
    relaxed_path = loads_file(tmp_path, relaxed, "relaxed.yaml")
    code, out, err = run_main(
        "--config", str(relaxed_path), "--json", "check", "--pose", "0", "30", "0"
    )
    assert code == 0, err
    assert "loads" not in json.loads(out)["poses"][0]
    code, text, _ = run_main("--config", str(path), "loads", "--pose", "0", "0", "0")
    assert code == 0 and "payload capacity" in text and "deflection" in text


def test_check_counts_the_loads_limits_in_each_verdict_with_the_loads_margins(tmp_path):
    """The worked example through ``check``: at θ = 30° the geometry holds but legs of 700 N do
    not (exit 1, ``actuator_force`` violated, leg 6 limiting) and the tool deflects 91.8 µm
    under the process box, over a limit of 80 µm (65.6 µm at the home pose); the margins are
    those ``loads`` gives at the same pose, the deflection and accuracy rows the limit less the
    worst translation ``loads`` reports."""
    limits = dict(WORKED["limits"], deflection_max=8e-5, accuracy_max=2e-5)
    path = loads_file(tmp_path, dict(WORKED, limits=limits))
    code, out, err = run_main(
        "--config", str(path), "--json", "check", "--pose", "0", "0", "0", "--pose", "0", "30", "0"
    )
    assert code == 1, err
    assert "1 of 2 poses unreachable or beyond the loads' limits" in err
    home, tilted = json.loads(out)["poses"]
    assert home["reachable"] is True and home["violated"] == []
    assert tilted["reachable"] is False
    assert tilted["violated"] == ["actuator_force", "deflection"]
    assert not any(v < 0 for v in tilted["margins"].values() if v is not None)
    for pose, document in zip(("0", "30"), (home, tilted), strict=True):
        _, answer, _ = run_main("--config", str(path), "--json", "loads", "--pose", "0", pose, "0")
        loads = json.loads(answer)
        assert set(document["loads"]) == {
            "actuator_force",
            "deflection",
            "accuracy",
            "limiting_actuator",
        }
        assert document["loads"]["actuator_force"] == pytest.approx(loads["force_margin_n"])
        assert document["loads"]["limiting_actuator"] == loads["limiting_actuator"]
        assert document["loads"]["deflection"] == pytest.approx(8e-5 - loads["deflection_m"])
        assert document["loads"]["accuracy"] == pytest.approx(2e-5 - loads["accuracy_m"])
    assert tilted["loads"]["actuator_force"] == pytest.approx(-30.9, abs=0.05)
    assert tilted["loads"]["limiting_actuator"] == 6
    # The table shows the rows in N and mm and counts them in its verdict.
    code, text, _ = run_main("--config", str(path), "check", "--pose", "0", "30", "0")
    assert code == 1
    assert "force" in text and "[N]" in text and "deflection" in text
    assert "0/1 poses reachable and within the loads' limits" in text
    assert text.splitlines()[4].endswith("actuator_force,deflection")
    # The log's check messages carry no loads rows: refused before any work.
    record = tmp_path / "check.mcap"
    code, _, err = run_main(
        "--config", str(path), "check", "--pose", "0", "0", "0", "--record", str(record)
    )
    assert code == 2 and not record.exists()
    assert "--record: the log's check messages carry no loads rows" in one_error_line(err)


@pytest.mark.parametrize(("name", "unit"), [("pus", "[N]"), ("rus", "[N·m]")])
def test_check_gives_no_finite_force_margin_where_a_leg_has_no_solution(tmp_path, name, unit):
    """At θ = 60° a leg of the 6-PUS and 6-RUS examples has no inverse-kinematics solution: the
    force margin is −∞ (``null``), never a finite value, and counts as violated; at home it is
    what ``loads`` answers, in the architecture's unit."""
    document = yaml.safe_load((CONFIG / EXAMPLES[name]).read_text())
    parameters = document["hexapod_workspace"]["ros__parameters"]
    parameters["load"] = {"mass": 5.0}
    parameters["limits"]["actuator_force_max"] = [200.0]
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(document))
    code, out, _ = run_main(
        "--config", str(path), "--json", "check", "--pose", "0", "0", "0", "--pose", "0", "60", "0"
    )
    assert code == 1
    home, far = json.loads(out)["poses"]
    _, answer, _ = run_main("--config", str(path), "--json", "loads", "--pose", "0", "0", "0")
    assert home["reachable"] is True
    assert home["loads"]["actuator_force"] == pytest.approx(json.loads(answer)["force_margin_n"])
    assert set(home["loads"]) == {"actuator_force", "limiting_actuator"}
    assert far["margins"]["ik"] < 0.0 and far["loads"]["actuator_force"] is None
    assert far["reachable"] is False and far["violated"][-2:] == ["transmission", "actuator_force"]
    _, text, _ = run_main("--config", str(path), "check", "--pose", "0", "0", "0")
    names, units, row = text.splitlines()[2:5]
    assert names.split()[-4:] == ["force", "limiting", "force", "violated"]
    assert units.split()[-3:] == [unit, "leg", "actuator"]
    assert row.split()[-2] == str(home["loads"]["limiting_actuator"])  # the JSON's actuator


def test_a_centre_of_mass_in_millimetres_is_refused_with_the_unit_hint(tmp_path):
    path = loads_file(tmp_path, {"load": {"mass": 40.0, "center_of_mass": [0.0, 0.0, 200.0]}})
    code, _, err = run_main("--config", str(path), "loads", "--pose", "0", "0", "0")
    assert code == 2
    line = one_error_line(err)
    assert f"parameters file {path}: load.center_of_mass: expected m" in line
    assert "it looks like millimetres" in line


@pytest.mark.parametrize(
    "command",
    [
        ("loads", "--pose", "0", "0", "0"),
        ("check", "--pose", "0", "0", "0"),
        ("projected", "--n-phi", "8"),
        ("torsion-range", "--direction", "0", "0"),
    ],
    ids=lambda command: command[0],
)
def test_every_command_refuses_a_bad_loads_parameter_naming_the_file(tmp_path, command):
    """A bad loads value is bad input for every command, not only for those that read the
    loads: it is refused (exit 2), never passed over."""
    path = loads_file(tmp_path, {"load": {"mass": -3.0}})
    code, _, err = run_main("--config", str(path), *command)
    assert code == 2
    line = one_error_line(err)
    assert f"parameters file {path}: load.mass: expected one number >= 0 (kg)" in line


LOADS_PAGE = (Path(__file__).resolve().parents[1] / "docs" / "loads.md").read_text(encoding="utf-8")


def test_the_worked_example_of_the_loads_page_is_what_the_command_prints(tmp_path):
    """docs/loads.md: its YAML block added to the packaged example gives the lines it shows."""
    block = re.search(r"```yaml\n(.*?)```", LOADS_PAGE, re.DOTALL)
    assert block is not None
    added = yaml.safe_load(block.group(1))
    document = yaml.safe_load((CONFIG / EXAMPLES["ups"]).read_text())
    parameters = document["hexapod_workspace"]["ros__parameters"]
    for group, values in added.items():
        parameters.setdefault(group, {}).update(values)
    (tmp_path / "spindle.yaml").write_text(yaml.safe_dump(document))
    examples = re.findall(
        r"```text\n\$ (hexapod-workspace [^\n]*)\n(.*?)```", LOADS_PAGE, re.DOTALL
    )
    assert len(examples) == 3
    for command, shown in examples:
        lines = shown.splitlines()
        status = 0
        if "$ echo $?" in lines:
            at = lines.index("$ echo $?")
            status, lines = int(lines[at + 1]), lines[:at]
        args = shlex.split(command)[1:]
        args[args.index("spindle.yaml")] = str(tmp_path / "spindle.yaml")
        code, out, _ = run_main(*args)
        assert code == status, command
        assert out.splitlines() == lines, command


@pytest.mark.parametrize("architecture", ["ups", "pus", "rus"])
def test_the_batch_rows_are_the_per_pose_loads(architecture):
    """load_rows evaluates every pose at once; each row equals what loads_at gives pose by pose,
    at random poses that include legs without a solution and near-singular ones (-inf)."""
    path = CONFIG / EXAMPLES[architecture]
    reference, manipulator = ra.load(path), load_manipulator(path)
    rotations, positions = random_poses(reference, 400, seed=11)
    # and two poses without a regular J: the 6-UPS legs in the base plane (its platform joints
    # 0.1 m above the platform frame's origin), a position no 6-PUS or 6-RUS leg reaches
    rotations = np.concatenate([rotations, np.stack([np.eye(3), np.eye(3)])])
    far = np.asarray(reference.position, dtype=float) + np.array([0.0, 0.0, -3.0])
    positions = np.concatenate([positions, [[0.0, 0.0, -0.1], far]])
    case = case_for(architecture)
    rows = load_rows(manipulator, case, rotations, positions)
    assert rows is not None and list(rows.margins) == ["actuator_force", "deflection", "accuracy"]
    singular = 0
    for k, (rotation, position) in enumerate(zip(rotations, positions, strict=True)):
        one = loads_at(manipulator, case, rotation, position)
        expected = {
            "actuator_force": one.force_margin,
            "deflection": case.deflection_max - one.deflection_m,
            "accuracy": case.accuracy_max - one.accuracy_m,
        }
        singular += one.singular
        for name, value in expected.items():
            got = rows.margins[name][k]
            if math.isinf(value):
                assert got == value, (name, k)
            else:
                assert got == pytest.approx(value, rel=1e-9, abs=1e-12 * max(1.0, abs(value)))
        assert rows.limiting_actuator[k] == one.limiting_actuator
    assert 0 < singular < len(rotations), "need both regular and singular poses"
    # one pose at a time gives the same rows
    single = load_rows(manipulator, case, rotations[:1], positions[0])
    assert single is not None
    assert single.margins["deflection"][0] == rows.margins["deflection"][0]
