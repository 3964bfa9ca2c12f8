"""Tool and work frames against an independent transform (plain 4x4 homogeneous matrices).

The reference here composes homogeneous transforms written from the definitions (T&T matrices
from their own Rz·Ry·Rz product), not from hexapod_workspace.core.cell.frames: the platform pose a
tool pose denotes is ``T_OP = T_OC · T_PC⁻¹``, a work-frame pose is ``T_OC = T_OW · T_WC``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from frames_reference import homogeneous, tt

from hexapod_workspace import check
from hexapod_workspace.core.base.rotations import matrix_to_tt
from hexapod_workspace.core.cell.frames import (
    Tool,
    WorkFrame,
    cell_from_mapping,
    platform_pose,
    tool_model,
    tool_pose,
    work_to_base,
)
from hexapod_workspace.core.evaluation.check import check_pose
from hexapod_workspace.core.evaluation.loading import example_manipulator, load_manipulator
from hexapod_workspace.core.model.manipulator import Manipulator
from hexapod_workspace.errors import ConfigError, InputError

TOOL_OFFSET = [0.012, -0.02, -0.16]
TOOL_ANGLES = [0.4, 0.12, -0.3]


@pytest.fixture(scope="module")
def example() -> Manipulator:
    return example_manipulator()


def _tool_poses(rng: np.random.Generator, count: int):
    """Random platform poses near the workspace, and the tool poses they carry (4x4)."""
    t_pc = homogeneous(tt(*TOOL_ANGLES), TOOL_OFFSET)
    for _ in range(count):
        angles = (rng.uniform(-math.pi, math.pi), rng.uniform(0.0, 0.5), rng.uniform(-0.5, 0.5))
        position = np.array([0.0, 0.0, -1.2]) + rng.uniform(-0.15, 0.15, 3)
        t_op = homogeneous(tt(*angles), position)
        yield t_op, t_op @ t_pc


def test_tool_pose_has_the_verdict_and_margins_of_its_platform_pose(example):
    tool = Tool(np.array(TOOL_OFFSET), np.array(TOOL_ANGLES))
    model = tool_model(example, tool)
    rng = np.random.default_rng(18)
    reachable = 0
    for t_op, t_oc in _tool_poses(rng, 60):
        # the reference: the original model at the platform pose
        platform_angles = matrix_to_tt(t_op[:3, :3])
        expected = check(example, platform_angles, t_op[:3, 3])
        # the tool model at the tool pose (position OC, orientation of C)
        got = check(model, matrix_to_tt(t_oc[:3, :3]), t_oc[:3, 3])
        assert got.reachable[0] == expected.reachable[0]
        for name, margin in expected.margins.items():
            assert got.margins[name][0] == pytest.approx(margin[0], abs=1e-9), name
        one = check_pose(model, *matrix_to_tt(t_oc[:3, :3]), t_oc[:3, 3])
        assert one.margins[0] == pytest.approx(expected.margins["leg_length"][0], abs=1e-9)
        reachable += int(expected.reachable[0])
        # the explicit transform agrees with the 4x4 one, both ways
        rotation_p, position_p = platform_pose(t_oc[:3, :3], t_oc[:3, 3], tool)
        np.testing.assert_allclose(rotation_p, t_op[:3, :3], atol=1e-12)
        np.testing.assert_allclose(position_p, t_op[:3, 3], atol=1e-12)
        rotation_c, position_c = tool_pose(t_op[:3, :3], t_op[:3, 3], tool)
        np.testing.assert_allclose(rotation_c, t_oc[:3, :3], atol=1e-12)
        np.testing.assert_allclose(position_c, t_oc[:3, 3], atol=1e-12)
    assert 10 < reachable < 60  # both verdicts occur


def test_identity_tool_is_the_same_model_and_joint_axes_stay_with_the_platform(example):
    assert tool_model(example, Tool()) is example
    tool = Tool(np.array(TOOL_OFFSET), np.array(TOOL_ANGLES))
    model = tool_model(example, tool)
    # the axes are those of the platform frame, rotated into C: R_tool·jB'_i = jB_i
    np.testing.assert_allclose(
        model.platform_joint_axes @ tt(*TOOL_ANGLES).T, example.platform_joint_axes, atol=1e-12
    )
    # the rate bounds' ρ is the joints' distance from the tool centre point
    rho = np.max(np.linalg.norm(example.platform_joints - np.array(TOOL_OFFSET), axis=1))
    assert np.max(np.linalg.norm(model.platform_joints, axis=1)) == pytest.approx(rho)


def test_work_frame_pose_has_the_verdict_and_margins_of_its_base_pose(example):
    origin, angles = np.array([0.05, -0.03, -1.25]), np.array([0.7, 0.05, 0.2])
    work = WorkFrame(origin, angles)
    t_ow = homogeneous(tt(*angles), origin)
    rng = np.random.default_rng(7)
    for _ in range(30):
        local = (rng.uniform(-math.pi, math.pi), rng.uniform(0.0, 0.4), rng.uniform(-0.4, 0.4))
        t_wc = homogeneous(tt(*local), rng.uniform(-0.1, 0.1, 3))
        t_oc = t_ow @ t_wc
        rotation, position = work_to_base(t_wc[:3, :3], t_wc[:3, 3], work)
        np.testing.assert_allclose(rotation, t_oc[:3, :3], atol=1e-12)
        np.testing.assert_allclose(position, t_oc[:3, 3], atol=1e-12)
        expected = check(example, matrix_to_tt(t_oc[:3, :3]), t_oc[:3, 3])
        got = check(example, matrix_to_tt(rotation), position)
        assert got.reachable[0] == expected.reachable[0]
        for name, margin in expected.margins.items():
            assert got.margins[name][0] == pytest.approx(margin[0], abs=1e-9)


def test_cell_parameters_are_read_and_validated():
    cell = cell_from_mapping(
        {
            "tool": {"offset": [0, 0, -0.1], "orientation": [0, 0, 0]},
            "work": {"origin": [0.1, 0, -1.2], "frame_id": "part"},
            "tools": {"T1": {"offset": [0, 0, -0.12]}, "T12": {"offset": [0, 0, -0.2]}},
            "limits": {"actuator_speed_max": [0.05]},
            "geometry": {"ignored": "by the cell reader"},
        }
    )
    assert cell.tool.offset.tolist() == [0, 0, -0.1]
    assert cell.work.frame_id == "part"
    assert sorted(cell.tools) == [1, 12]
    assert cell.select(12).offset.tolist() == [0, 0, -0.2]
    assert cell.actuator_speed_max.tolist() == [0.05] * 6
    with pytest.raises(InputError, match=r"tool 3: not in the tool table .*T1, T12"):
        cell.select(3)
    defaults = cell_from_mapping({})
    assert defaults.tool.is_identity and defaults.work.frame_id == "work" and not defaults.tools
    # tool.number selects the active tool from the table (0: tool.offset / tool.orientation)
    selected = cell_from_mapping(
        {"tool": {"offset": [0, 0, -0.1], "number": 12}, "tools.T12.offset": [0, 0, -0.2]}
    )
    assert selected.tool.number == 12 and selected.tool.offset.tolist() == [0, 0, -0.2]


@pytest.mark.parametrize(
    ("parameters", "message"),
    [
        ({"tools.T2.offset": [0, float("nan"), 0]}, r"^tools\.T2\.offset: expected finite"),
        ({"tools.T2.orientation": [0, 0, 0]}, r"^tools\.T2\.offset: required parameter"),
        ({"tools.2.offset": [0, 0, 0]}, r"^tools\.2\.offset: unknown parameter"),
        ({"tools.T1.ofset": [0, 0, 0]}, r"^tools\.T1\.ofset: unknown parameter"),
        ({"tool.offset": [0, 0]}, r"^tool\.offset: expected 3 numbers"),
        ({"tool.length": 0.1}, r"^tool\.length: unknown parameter \(expected one of tool\."),
        ({"work.orientation": "up"}, r"^work\.orientation: expected numbers, got 'up'"),
        ({"work.frame_id": ""}, r"^work\.frame_id: expected a non-empty string"),
        ({"limits.actuator_speed_max": [-1.0]}, r"^limits\.actuator_speed_max: expected values"),
        ({"limits.actuator_speed_max": [1.0, 2.0]}, r"^limits\.actuator_speed_max: expected 1"),
        ({"tool.number": 3, "tools.T1.offset": [0, 0, 0]}, r"^tool\.number: tool 3 is not .*T1\)"),
        ({"tool.number": -1}, r"^tool\.number: expected an integer >= 0"),
        ({"tool.number": True}, r"^tool\.number: expected an integer >= 0"),
        ({"tool.number": 1.0}, r"^tool\.number: expected an integer >= 0"),
    ],
)
def test_bad_cell_parameters_are_refused_in_one_line(parameters, message):
    with pytest.raises(ConfigError, match=message) as caught:
        cell_from_mapping(parameters)
    assert "\n" not in str(caught.value)


def test_parameters_file_with_cell_sections_is_accepted(tmp_path):
    from hexapod_workspace._resources import example_config_path

    text = example_config_path().read_text(encoding="utf-8")
    extra = (
        "    tool:\n      offset: [0.0, 0.0, -0.15]\n      orientation: [0.0, 0.0, 0.0]\n"
        "    work:\n      origin: [0.0, 0.0, -1.3]\n      frame_id: part\n"
        "    tools:\n      T1:\n        offset: [0.0, 0.0, -0.1]\n"
    )
    text = text.replace("  ros__parameters:\n", "  ros__parameters:\n" + extra, 1)
    text = text.replace("    limits:\n", "    limits:\n      actuator_speed_max: [0.1]\n", 1)
    path = tmp_path / "cell.yaml"
    path.write_text(text, encoding="utf-8")
    assert load_manipulator(path) == example_manipulator()
    misspelt = tmp_path / "bad.yaml"
    misspelt.write_text(text.replace("    tools:\n", "    toolz:\n"), encoding="utf-8")
    with pytest.raises(ConfigError, match="toolz: unknown section"):
        load_manipulator(misspelt)
