"""One unit rule (issue #35 item 11): a value that fits the machine only once divided by 1000 is
refused with the unit hint (exit 2), in the CLI and the node alike.

Each case below was accepted on main before the rule: the leg limit and the speed were taken as
given (a leg 0.75 m too long declared reachable), the offset, origin and positions gave
"unreachable" (exit 1) instead of the hint.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from cli_support import one_error_line, run_main

from hexapod_workspace import Manipulator
from hexapod_workspace.core.base.validation import machine_size, millimetre_reason
from hexapod_workspace.core.cell.frames import cell_from_mapping, cell_unit_reason
from hexapod_workspace.core.evaluation.loading import manipulator_from_mapping
from hexapod_workspace.errors import ConfigError, GeometryError


def config(tmp_path: Path, example: Manipulator, changes: dict[str, object] | None = None) -> Path:
    parameters = {**example.to_parameters(), **(changes or {})}
    path = tmp_path / "mm.yaml"
    path.write_text(
        "hexapod_workspace:\n  ros__parameters:\n"
        + "".join(f"    {name}: {value!r}\n" for name, value in parameters.items()),
        encoding="utf-8",
    )
    return path


CASES = [
    ({"limits.leg_length_max": [1500.0]}, "limits.leg_length_max"),
    ({"limits.actuator_speed_max": [50.0]}, "limits.actuator_speed_max"),
    ({"tool.offset": [0.0, 0.0, 150.0]}, "tool.offset"),
    ({"work.origin": [500.0, 0.0, 0.0]}, "work.origin"),
    ({"tools.T1.offset": [0.0, 0.0, 120.0]}, "tools.T1.offset"),
]


@pytest.mark.parametrize(("changes", "name"), CASES, ids=[n for _, n in CASES])
def test_a_parameter_in_millimetres_is_refused_with_the_hint(tmp_path, example, changes, name):
    path = config(tmp_path, example, changes)
    code, out, err = run_main("--config", str(path), "check", "--pose", "0", "0", "0")
    assert (code, out) == (2, "")
    line = one_error_line(err)
    assert f"{name}: expected m" in line
    assert "fits once divided by 1000" in line and "millimetres" in line


def test_the_same_values_in_metres_are_accepted(tmp_path, example):
    path = config(tmp_path, example)
    text = path.read_text(encoding="utf-8") + (
        "    limits.actuator_speed_max: [0.05]\n    tool.offset: [0.0, 0.0, 0.15]\n"
        "    work.origin: [0.5, 0.0, 0.0]\n"
    )
    path.write_text(text, encoding="utf-8")
    code, _, err = run_main("--config", str(path), "check", "--pose", "0", "0", "0")
    assert code == 0, err


def test_positions_in_millimetres_get_the_hint_not_unreachable(tmp_path):
    code, _, err = run_main("check", "--pose", "0", "0", "0", "--position", "0", "0", "-1300")
    assert code == 2
    assert "--position: expected m" in one_error_line(err)
    rows = "\n".join(f"{x},0,-1300,0,0,0" for x in (0.0, 10.0))
    path = tmp_path / "mm.csv"
    path.write_text(f"x,y,z,phi_deg,theta_deg,psi_deg\n{rows}\n", encoding="utf-8")
    code, _, err = run_main("check-path", str(path))
    assert code == 2
    line = one_error_line(err)
    assert f"path file {path}: x,y,z: expected m" in line and "divided by 1000" in line


def test_the_rule_is_one_function_for_the_model_and_the_cell(example):
    # manipulator_from_mapping (the node builds its model through it) refuses the limit ...
    parameters = {**example.to_parameters(), "limits.leg_length_max": [1500.0]}
    with pytest.raises(GeometryError, match=r"limits\.leg_length_max: expected m .* divided"):
        manipulator_from_mapping(parameters)
    # ... and the cell's values go through the same rule against the same size.
    cell = cell_from_mapping({"limits.actuator_speed_max": [50.0]})
    reason = cell_unit_reason(example, cell)
    assert reason is not None and reason.startswith("limits.actuator_speed_max: expected m/s")
    size = machine_size(example.base_joints, example.platform_joints, example.home_position)
    assert millimetre_reason("x", 0.5, size) is None  # fits as given
    assert millimetre_reason("x", 1e7, size) is None  # fits neither way: not a unit hint


def test_the_node_reads_parameters_through_the_same_rule(example):
    pytest.importorskip("rcl_interfaces.msg")
    from hexapod_workspace.ros.parameters import parameter_specs, state_from

    values = {name: spec.default for name, spec in parameter_specs().items()}
    state_from(values)  # the defaults are accepted
    for name, value in (
        ("limits.actuator_speed_max", [50.0]),
        ("work.origin", [500.0, 0.0, 0.0]),
        ("limits.leg_length_max", [1500.0]),
    ):
        with pytest.raises(ConfigError, match=rf"{name}: expected m.*divided by 1000"):
            state_from({**values, name: value})
