"""Reach along a pose-space direction: the segment to the reach holds (dense samples), a pose
just beyond it violates the named constraint, and the rotation about the tool axis agrees with
the torsion range (an independent search)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hexapod_workspace import check
from hexapod_workspace.core.base.rotations import matrix_to_tt, tt_to_matrix
from hexapod_workspace.core.cell.frames import Tool, WorkFrame, tool_model
from hexapod_workspace.core.cell.reach import AXES, axis_limits, reach
from hexapod_workspace.core.evaluation.loading import example_manipulator
from hexapod_workspace.core.model.manipulator import Manipulator
from hexapod_workspace.core.workspaces.orientation import torsion_range
from hexapod_workspace.errors import InputError

TOLERANCE = math.radians(0.01)


def rodrigues(vector: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Rot(t·r), (n, 3, 3), written here from the formula."""
    angle = np.linalg.norm(vector)
    if angle == 0.0:
        return np.broadcast_to(np.eye(3), (len(t), 3, 3))
    x, y, z = vector / angle
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    a = t * angle
    return np.eye(3) + np.sin(a)[:, None, None] * k + (1 - np.cos(a))[:, None, None] * (k @ k)


def reachable_along(model, rotation, position, d, r, t):
    rotations = rodrigues(r, t) @ rotation
    flags = []
    for k, tk in enumerate(t):
        result = check(model, matrix_to_tt(rotations[k]), position + tk * d)
        flags.append((bool(result.reachable[0]), result.violated[0]))
    return flags


@pytest.fixture(scope="module")
def model() -> Manipulator:
    return tool_model(example_manipulator(), Tool(np.array([0.0, 0.0, -0.1])))


@pytest.mark.parametrize(
    ("d", "r"),
    [
        ([1.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
        ([0.0, 0.3, -0.5], [0.2, 0.0, 0.4]),
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
    ],
)
def test_reach_holds_up_to_it_and_is_violated_just_beyond(model, d, r):
    rotation, position = tt_to_matrix([0.3, 0.1, 0.05]), np.array([0.02, -0.01, -1.25])
    d, r = np.array(d), np.array(r)
    result = reach(model, rotation, position, d, r, t_max=1.0, tolerance=TOLERANCE)
    assert result.start_reachable
    rho = np.max(np.linalg.norm(model.platform_joints, axis=1))
    step = TOLERANCE / (np.linalg.norm(r) + np.linalg.norm(d) / rho)
    for sign, t_reach, names in (
        (1.0, result.plus, result.limited_by_plus),
        (-1.0, result.minus, result.limited_by_minus),
    ):
        assert 0.0 < t_reach < 1.0 and names
        inside = reachable_along(
            model, rotation, position, sign * d, sign * r, np.linspace(0, t_reach, 400)
        )
        assert all(ok for ok, _ in inside)
        beyond = reachable_along(
            model, rotation, position, sign * d, sign * r, t_reach + np.linspace(0, 2 * step, 41)
        )
        violated = [v for ok, v in beyond if not ok]
        assert violated and set(violated[0]) & set(names)


def test_rotation_about_the_tool_axis_matches_the_torsion_range(model):
    position = np.array([0.0, 0.0, -1.2])
    limits = axis_limits(
        model, np.eye(3), position, frame="tool", t_max_rotation=3.0, tolerance=TOLERANCE
    )
    assert tuple(limits) == AXES
    (interval,) = [
        iv for iv in torsion_range(model, 0.0, 0.0, position).intervals if iv[0] <= 0 <= iv[1]
    ]
    assert limits["rz"].plus == pytest.approx(interval[1], abs=3 * TOLERANCE)
    assert limits["rz"].minus == pytest.approx(-interval[0], abs=3 * TOLERANCE)
    # the work frame's axes are those given: identity work frame = base frame
    base = axis_limits(model, np.eye(3), position, frame="base", tolerance=TOLERANCE)
    work = axis_limits(model, np.eye(3), position, frame="work", work=WorkFrame())
    for name in AXES:
        assert work[name].plus == pytest.approx(base[name].plus, abs=1e-6)


def test_unreachable_start_and_bad_directions(model):
    far = np.array([0.0, 0.0, -2.5])
    result = reach(model, np.eye(3), far, [1.0, 0, 0], [0, 0, 0])
    assert not result.start_reachable and result.plus == 0.0 and result.minus == 0.0
    assert "leg_length" in result.limited_by_plus
    with pytest.raises(InputError, match=r"^direction: expected a non-zero direction"):
        reach(model, np.eye(3), [0, 0, -1.2], [0, 0, 0], [0, 0, 0])
    with pytest.raises(InputError, match=r"^t_max: expected t_max·\|r\| < pi"):
        reach(model, np.eye(3), [0, 0, -1.2], [0, 0, 0], [0, 0, 4.0])
    with pytest.raises(InputError, match=r"^frame: expected base, work or tool"):
        axis_limits(model, np.eye(3), [0, 0, -1.2], frame="world")


# ---------------------------------------------------------------------------- accuracy per unit
def _first_violation(flags: list[bool], grid: np.ndarray) -> float:
    """The first sampled t that is unreachable (inf when every sample is reachable)."""
    bad = [t for t, ok in zip(grid.tolist(), flags, strict=True) if not ok]
    return bad[0] if bad else math.inf


@pytest.fixture(scope="module")
def far_pivot() -> Manipulator:
    """The pivot (tool centre point) 3 m from the platform joints: an angle tolerance of the
    platform would make the translation limits 3 m × angle short."""
    model = tool_model(example_manipulator(), Tool(np.array([0.0, 0.0, -3.0])))
    rho = float(np.max(np.linalg.norm(model.platform_joints, axis=1)))
    assert rho >= 3.0
    return model


def test_translation_limit_is_within_tol_mm_of_the_sampled_boundary(far_pivot):
    rotation, position = np.eye(3), np.array(far_pivot.home_position)
    limits = axis_limits(far_pivot, rotation, position)  # defaults: 0.01 mm, 0.001 deg
    for name, unit in (("x", np.array([1.0, 0.0, 0.0])), ("z", np.array([0.0, 0.0, 1.0]))):
        found = limits[name].plus
        assert limits[name].limited_by_plus, name  # a constraint limits it (not the bound)
        coarse = np.linspace(0.0, found, 200)
        assert all(
            bool(check(far_pivot, np.zeros((1, 3)), position + t * unit).reachable[0])
            for t in coarse
        ), name
        fine = found + np.arange(0.0, 0.05e-3, 0.5e-6)  # 0.5 µm samples past the limit
        flags = [
            bool(check(far_pivot, np.zeros((1, 3)), position + t * unit).reachable[0]) for t in fine
        ]
        boundary = _first_violation(flags, fine)
        assert boundary - found <= 1e-5 + 0.5e-6, (name, (boundary - found) * 1e3)


def test_rotation_limit_is_within_tol_deg_of_the_sampled_boundary(far_pivot):
    rotation, position = np.eye(3), np.array(far_pivot.home_position)
    tol = math.radians(0.001)
    limits = axis_limits(far_pivot, rotation, position, tol_rotation=tol)
    for name, axis in (("rx", np.array([1.0, 0.0, 0.0])), ("ry", np.array([0.0, 1.0, 0.0]))):
        found = limits[name].plus
        assert limits[name].limited_by_plus, name
        grid = np.concatenate(
            [np.linspace(0.0, found, 2000), found + np.arange(0.0, 20 * tol, tol / 20)]
        )
        rotations = rodrigues(axis, grid) @ rotation
        reachable = check(far_pivot, matrix_to_tt(rotations), position).reachable
        assert np.all(reachable[:2000]), name
        boundary = _first_violation(reachable.tolist(), grid)
        assert boundary - found <= tol + tol / 20, (name, math.degrees(boundary - found))


def test_cli_tolerances_are_per_unit(far_pivot, tmp_path):
    import json

    from cli_support import run_main

    config = tmp_path / "far.yaml"
    parameters = {**example_manipulator().to_parameters(), "tool.offset": [0, 0, -3.0]}
    config.write_text(
        "hexapod_workspace:\n  ros__parameters:\n"
        + "".join(f"    {name}: {value!r}\n" for name, value in parameters.items()),
        encoding="utf-8",
    )
    home = [repr(v) for v in far_pivot.home_position.tolist()]
    code, out, err = run_main(
        "--json", "--config", str(config), "axis-limits", "--position", *home, "--tol-mm", "0.005"
    )
    assert code == 0, err
    document = json.loads(out)
    assert document["tolerance_mm"] == 0.005 and document["tolerance_deg"] == pytest.approx(0.001)
    expected = axis_limits(
        far_pivot, np.eye(3), np.array(far_pivot.home_position), tol_translation=5e-6
    )
    assert document["axes"]["x"]["plus"] == pytest.approx(expected["x"].plus, abs=1e-12)
    code, _, err = run_main("--config", str(config), "axis-limits", "--tol-mm", "0")
    assert code == 2 and "--tol-mm: expected a value > 0 mm, got 0" in err
