"""Model construction and validation: one test per rule, each error naming the parameter."""

from __future__ import annotations

import math
import re
import textwrap
import warnings

import numpy as np
import pytest

from hexapod_workspace import ConfigError, GeometryError, HomePoseWarning, Manipulator
from hexapod_workspace.core.base.params import load_params_file
from hexapod_workspace.core.evaluation.loading import (
    example_manipulator,
    load_manipulator,
    manipulator_from_mapping,
)


def build(parameters: dict, **changes) -> Manipulator:
    values = dict(parameters)
    values.update(changes)
    return manipulator_from_mapping(values, warn=False)


def test_example_loads_with_defaults_from_the_home_pose(example):
    assert example.base_joints.shape == (6, 3)
    assert example.platform_joints.shape == (6, 3)
    np.testing.assert_allclose(np.linalg.norm(example.base_joint_axes, axis=1), 1.0)
    # Default axes: the leg directions at the home pose (docs/theory.md, Conventions).
    legs = example.home_position + example.platform_joints - example.base_joints
    directions = legs / np.linalg.norm(legs, axis=1, keepdims=True)
    np.testing.assert_allclose(example.base_joint_axes, directions)
    np.testing.assert_allclose(example.platform_joint_axes, -directions)
    assert example.frame_id == "base"
    np.testing.assert_array_equal(example.position, [0.0, 0.0, -1.3])


def test_nested_and_dotted_mappings_are_the_same(example_parameters):
    nested: dict = {}
    for name, value in example_parameters.items():
        node = nested
        *groups, leaf = name.split(".")
        for group in groups:
            node = node.setdefault(group, {})
        node[leaf] = value
    assert manipulator_from_mapping(nested) == manipulator_from_mapping(example_parameters)


def test_to_parameters_round_trip(example):
    assert manipulator_from_mapping(example.to_parameters()) == example


def test_explicit_axes_round_trip_and_are_normalised(example_parameters):
    axes = [0.0, 0.0, -2.0] * 6
    model = build(example_parameters, **{"geometry.base_joint_axes": axes})
    np.testing.assert_allclose(model.base_joint_axes, np.tile([0.0, 0.0, -1.0], (6, 1)))
    assert manipulator_from_mapping(model.to_parameters(), warn=False) == model


def test_params_file_root_keys(tmp_path, example_parameters):
    for root in ("hexapod_workspace", "/**", "/hexapod_workspace"):
        path = tmp_path / "params.yaml"
        lines = [f"{root!r}:", "  ros__parameters:"]
        lines += [f"    {name}: {value!r}" for name, value in example_parameters.items()]
        path.write_text("\n".join(lines) + "\n")
        assert (
            load_params_file(path)["limits.leg_diameter"]
            == example_parameters["limits.leg_diameter"]
        )
        load_manipulator(path)


def test_params_file_without_node_section(tmp_path):
    path = tmp_path / "other.yaml"
    path.write_text("other_node:\n  ros__parameters: {a: 1}\n")
    with pytest.raises(ConfigError, match="no section for this node"):
        load_params_file(path)


def test_params_file_invalid_yaml(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("hexapod_workspace: [unclosed\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_params_file(path)


def test_params_file_missing(tmp_path):
    with pytest.raises(ConfigError, match="cannot read"):
        load_params_file(tmp_path / "absent.yaml")


# ----------------------------------------------------------------- one test per rule
def test_joint_array_must_be_6x3(example_parameters):
    with pytest.raises(GeometryError) as error:
        build(example_parameters, **{"geometry.base_joints": [0.0] * 17})
    assert str(error.value) == (
        "geometry.base_joints: expected 18 numbers (6 joints × x, y, z), got 17"
    )
    with pytest.raises(GeometryError, match="geometry.platform_joints: expected 18"):
        build(example_parameters, **{"geometry.platform_joints": [[0.0, 0.0, 0.0]] * 5})


def test_joint_array_accepts_6x3_nested(example_parameters, example):
    nested = np.reshape(example_parameters["geometry.base_joints"], (6, 3)).tolist()
    assert build(example_parameters, **{"geometry.base_joints": nested}) == example


@pytest.mark.parametrize(
    "name",
    [
        "limits.leg_length_min",
        "limits.leg_length_max",
        "limits.base_joint_max_angle",
        "limits.platform_joint_max_angle",
    ],
)
def test_limit_lists_have_length_1_or_6(example_parameters, name):
    with pytest.raises(GeometryError) as error:
        build(example_parameters, **{name: [0.5, 0.6]})
    assert str(error.value) == f"{name}: expected 1 or 6 numbers, got 2"
    build(example_parameters, **{name: [example_parameters[name][0]] * 6})


def test_leg_length_min_below_max(example_parameters):
    with pytest.raises(GeometryError) as error:
        build(example_parameters, **{"limits.leg_length_min": [0.8, 0.8, 0.8, 1.5, 0.8, 0.8]})
    assert "leg_length_min: expected < limits.leg_length_max" in str(error.value)
    assert "1.5 >= 1.45 m for leg 4" in str(error.value)


def test_leg_length_min_not_negative(example_parameters):
    with pytest.raises(GeometryError, match="leg_length_min: expected values >= 0 m, got -0.1"):
        build(example_parameters, **{"limits.leg_length_min": [-0.1]})


@pytest.mark.parametrize("angle", [0.0, -0.1, math.pi, 4.0])
@pytest.mark.parametrize("name", ["limits.base_joint_max_angle", "limits.platform_joint_max_angle"])
def test_joint_angles_in_open_interval(example_parameters, name, angle):
    with pytest.raises(GeometryError) as error:
        build(example_parameters, **{name: [angle]})
    assert str(error.value).startswith(f"{name}: expected angles in (0, pi) rad, got {angle:g}")


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize(
    "name", ["geometry.base_joints", "geometry.home_position", "limits.leg_diameter"]
)
def test_numbers_must_be_finite(example_parameters, name, bad):
    value = example_parameters[name]
    value = [bad, *value[1:]] if isinstance(value, list) else bad
    with pytest.raises(ConfigError, match=f"{name}: expected finite numbers"):
        build(example_parameters, **{name: value})


@pytest.mark.parametrize("bad", ["1.0", True, [1.0, "x", 2.0], b"123"])
def test_numbers_must_be_numbers(example_parameters, bad):
    with pytest.raises(ConfigError, match="pose.position: expected"):
        build(example_parameters, **{"pose.position": bad})


def test_axes_must_be_non_zero(example_parameters):
    axes = [0.0, 0.0, 1.0] * 6
    axes[9:12] = [0.0, 0.0, 0.0]
    with pytest.raises(GeometryError) as error:
        build(example_parameters, **{"geometry.platform_joint_axes": axes})
    assert str(error.value) == (
        "geometry.platform_joint_axes: expected non-zero axes, axis of joint 4 is zero"
    )


def test_axes_must_have_18_numbers(example_parameters):
    with pytest.raises(GeometryError, match="base_joint_axes: expected 18 numbers .* got 3"):
        build(example_parameters, **{"geometry.base_joint_axes": [0.0, 0.0, 1.0]})


def test_leg_diameter_not_negative(example_parameters):
    with pytest.raises(GeometryError) as error:
        build(example_parameters, **{"limits.leg_diameter": -0.01})
    assert str(error.value) == "limits.leg_diameter: expected a value >= 0 m, got -0.01"


def test_zero_length_leg_at_home_is_refused(example_parameters):
    base = np.reshape(example_parameters["geometry.base_joints"], (6, 3))
    platform = np.reshape(example_parameters["geometry.platform_joints"], (6, 3))
    home = base[2] - platform[2]  # leg 3 collapses to a point at the home pose
    with pytest.raises(GeometryError, match="leg 3 has zero length"):
        build(example_parameters, **{"geometry.home_position": home.tolist()})


def test_missing_parameter(example_parameters):
    values = dict(example_parameters)
    del values["limits.leg_length_max"]
    with pytest.raises(ConfigError, match="limits.leg_length_max: required parameter is missing"):
        manipulator_from_mapping(values)


def test_unknown_model_parameter(example_parameters):
    with pytest.raises(ConfigError, match="limits.leg_lenght_max: unknown parameter"):
        build(example_parameters, **{"limits.leg_lenght_max": [1.0]})


def test_node_parameters_outside_the_model_are_ignored(example_parameters, example):
    extra = {"resolution.n_phi": 360, "recording.enabled": True, "use_sim_time": False}
    assert build(example_parameters, **extra) == example


def test_position_defaults_to_home(example_parameters):
    values = dict(example_parameters)
    del values["pose.position"]
    model = manipulator_from_mapping(values)
    np.testing.assert_array_equal(model.position, model.home_position)


def test_unreachable_home_pose_warns_but_builds(example_parameters):
    with pytest.warns(HomePoseWarning, match="home pose .* unreachable: leg_length violated"):
        model = manipulator_from_mapping({**example_parameters, "limits.leg_length_max": [1.2]})
    assert model.leg_length_max[0] == 1.2


def test_reachable_home_pose_does_not_warn(example_parameters):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        manipulator_from_mapping(example_parameters)


def test_arrays_are_read_only(example):
    with pytest.raises(ValueError, match="read-only"):
        example.base_joints[0, 0] = 1.0


def test_yaml_example_is_commented():
    from hexapod_workspace._resources import example_config_path

    text = example_config_path().read_text()
    keys = [line for line in text.splitlines() if line.strip().endswith(":") or ": " in line]
    assert len(keys) > 10
    # Every key line of the example is preceded by a comment line (a user reads the file to
    # learn its keys).
    lines = text.splitlines()
    for index, line in enumerate(lines):
        stripped = line.strip()
        is_key = stripped and not stripped.startswith(("#", "-")) and ":" in stripped.split()[0]
        if is_key and index > 0 and not stripped.startswith("hexapod_workspace"):
            previous = lines[index - 1].strip()
            assert previous.startswith("#") or stripped in {
                "ros__parameters:",
                "geometry:",
                "limits:",
                "pose:",
            }, textwrap.shorten(line, 60)


# ---------------------------------------------------------------------------- unknown names
def _write(tmp_path, parameters: dict, extra: str = "") -> object:
    lines = ["hexapod_workspace:", "  ros__parameters:"]
    lines += [f"    {name}: {value!r}" for name, value in parameters.items()]
    path = tmp_path / "params.yaml"
    path.write_text("\n".join(lines) + "\n" + extra)
    return path


@pytest.mark.parametrize(
    ("name", "reason"),
    [
        (
            "limitz.leg_length_min",
            "limitz: unknown section (expected one of accuracy, axis_limits, check, collision, "
            "frame_id, ",
        ),
        ("limits.leg_lenght_min", "limits.leg_lenght_min: unknown parameter (expected one of "),
        ("resolution.n_phy", "resolution.n_phy: unknown parameter (expected one of resolution."),
        ("frame_id.x", "frame_id: expected a value, got a section"),
        ("recordings.enabled", "recordings: unknown section"),
    ],
)
def test_unknown_names_in_a_file_are_named_at_their_level(tmp_path, example, name, reason):
    """Every level of the file is checked; a misspelt section is named."""
    parameters = {**example.to_parameters(), name: 1.0}
    with pytest.raises(ConfigError, match=re.escape(reason)):
        load_manipulator(_write(tmp_path, parameters))


def test_node_and_ros_parameters_are_known_in_a_file(tmp_path, example):
    parameters = {
        **example.to_parameters(),
        "resolution.n_phi": 90,
        "recording.enabled": False,
        "use_sim_time": False,
        "qos_overrides./hexapod_workspace/reachability.publisher.depth": 5,
    }
    assert load_manipulator(_write(tmp_path, parameters)) == example


def test_unknown_key_next_to_ros__parameters(tmp_path, example):
    path = _write(tmp_path, example.to_parameters(), "  ros_parameters:\n    frame_id: x\n")
    with pytest.raises(ConfigError, match="unknown key 'ros_parameters' in section"):
        load_manipulator(path)


@pytest.mark.parametrize("name", ["geometry.base_joints", "limits.leg_length_max", "pose.position"])
def test_lengths_beyond_a_million_metres_are_refused(example_parameters, name):
    """Margins must stay finite numbers; absurd geometry is refused with its name."""
    parameters = dict(example_parameters)
    value = np.array(parameters.get(name, [1.0]), dtype=float)
    parameters[name] = (value * 1e300).tolist()
    with pytest.raises(GeometryError, match=re.escape(f"{name}: expected values within")):
        manipulator_from_mapping(parameters)


def test_example_from_any_working_directory(tmp_path, monkeypatch, example):
    """The API snippets (README, Getting started) use the packaged example, not a relative path."""
    monkeypatch.chdir(tmp_path)
    assert example_manipulator() == example


def test_a_clone_named_like_the_package_does_not_shadow_it(tmp_path):
    """Python started in the folder above a clone named hexapod_workspace imports the
    package (editable install in compat mode), not the clone as an empty namespace package."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    (tmp_path / "hexapod_workspace").symlink_to(root, target_is_directory=True)
    done = subprocess.run(
        [sys.executable, "-c", "from hexapod_workspace import Manipulator; print(Manipulator)"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0, done.stderr


def _rz(a: float) -> np.ndarray:
    return np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])


def _ry(a: float) -> np.ndarray:
    return np.array([[np.cos(a), 0.0, np.sin(a)], [0.0, 1.0, 0.0], [-np.sin(a), 0.0, np.cos(a)]])


def test_leg_endpoints_follow_the_pose_written_out_per_leg() -> None:
    """leg_endpoints against B_i = p + R·b_i written out leg by leg with a plain rotation."""
    from hexapod_workspace.core.base.rotations import tt_to_matrix
    from hexapod_workspace.core.model.legs import leg_endpoints

    m = example_manipulator()
    angles = np.radians([[30.0, 20.0, 10.0], [0.0, 0.0, 0.0]])
    position = np.array([0.05, -0.02, -1.2])
    base, platform = leg_endpoints(m, tt_to_matrix(angles), position)
    assert base.shape == platform.shape == (2, 6, 3)
    for n, (phi, theta, psi) in enumerate(angles):
        r = _rz(phi) @ _ry(theta) @ _rz(-phi) @ _rz(psi)
        for k in range(6):
            expected = position + r @ m.platform_joints[k]
            np.testing.assert_allclose(platform[n, k], expected, atol=1e-15)
            np.testing.assert_array_equal(base[n, k], m.base_joints[k])
