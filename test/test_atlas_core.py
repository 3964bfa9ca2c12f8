"""The per-position atlas values (numpy core) and the atlas without the optional extra."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from hexapod_workspace import (
    AtlasGrid,
    AtlasOptions,
    InputError,
    check,
    projected_workspace,
    torsion_range,
)
from hexapod_workspace.core.workspaces.atlas import (
    dexterous_mask,
    position_capability,
    positions_capability,
)

FAST = AtlasOptions(n_phi=24, tolerance=1e-3)


# ---------------------------------------------------------------------------- grid
def test_box_grid_includes_the_ends_and_counts_positions():
    grid = AtlasGrid.box([-0.1, 0.1, 0.0, 0.25, -1.3, -1.3], 0.05)
    assert grid.shape == (5, 6, 1)  # 0.25 / 0.05 = 5 steps despite rounding; z one plane
    assert grid.size == 30
    np.testing.assert_allclose(grid.x, [-0.1, -0.05, 0.0, 0.05, 0.1], atol=1e-15)
    assert grid.y[-1] == pytest.approx(0.25)
    assert grid.cell_volume == pytest.approx(0.05**3)
    points = grid.points((slice(0, 2), slice(1, 2), slice(None)))
    np.testing.assert_allclose(points, [[-0.1, 0.05, -1.3], [-0.05, 0.05, -1.3]])


@pytest.mark.parametrize(
    ("bounds", "step", "words"),
    [
        ([0.1, -0.1, 0, 0, 0, 0], 0.1, "empty, x1"),
        ([0, 0, 0, 0, -1.0, -1.2], 0.1, "empty, z1"),
        ([0, 0, 0, 0, 0, 0], 0.0, "step"),
        ([0, 0, 0, 0, 0, 0], -0.1, "step"),
        ([0, math.nan, 0, 0, 0, 0], 0.1, "finite"),
        ([0, 1, 0, 0, 0], 0.1, "6 finite"),
    ],
)
def test_box_grid_refuses_bad_boxes(bounds, step, words):
    with pytest.raises(InputError, match=words):
        AtlasGrid.box(bounds, step)


def test_explicit_positions_grid():
    grid = AtlasGrid.from_positions([[0, 0, -1.3], [0.2, 0.2, -0.95]])
    assert grid.dims == ("position",) and grid.shape == (2,) and grid.cell_volume is None
    with pytest.raises(InputError):
        AtlasGrid.from_positions(np.zeros((0, 3)))
    with pytest.raises(InputError):
        AtlasGrid.from_positions([[0, 0, math.inf]])


# ---------------------------------------------------------------------------- values
def test_values_equal_the_single_position_calls(example):
    """Each atlas value is what the public per-position functions return (independent calls)."""
    positions = np.array([[0.0, 0.0, -1.3], [0.2, 0.2, -0.95], [0.0, 0.0, -0.7]])
    columns = positions_capability(example, positions, FAST)
    for row, position in enumerate(positions):
        reachable = bool(check(example, np.zeros((1, 3)), position).reachable[0])
        assert columns["reference_reachable"][row] == float(reachable)
        if not reachable:  # above the reach: empty workspace, every value NaN (never 0)
            for name, values in columns.items():
                if name != "reference_reachable":
                    assert math.isnan(values[row]), name
            continue
        exact = projected_workspace(example, position, method="exact", n_phi=24, tolerance=1e-3)
        zero = projected_workspace(
            example, position, method="torsion_zero", n_phi=24, tolerance=1e-3
        )
        assert columns["tilt_capability"][row] == exact.tilt_min
        assert columns["tilt_max"][row] == exact.tilt_max
        assert columns["solid_angle"][row] == exact.solid_angle
        assert columns["tilt_capability_torsion_zero"][row] == pytest.approx(
            zero.tilt_min, abs=1e-12
        )
        intervals = torsion_range(example, 0.0, 0.0, position, tolerance=1e-3).intervals
        holding = intervals[(intervals[:, 0] <= 0) & (intervals[:, 1] >= 0)][0]
        assert (columns["psi_min"][row], columns["psi_max"][row]) == tuple(holding)
        # Sanity against brute force: a cone a hair inside the capability is all reachable
        # for some torsion at every sampled azimuth; exact >= torsion zero by construction.
        assert columns["tilt_capability"][row] >= columns["tilt_capability_torsion_zero"][row]
    assert "orientation_volume" not in columns  # optional, off by default


def test_capability_cone_is_attainable_by_brute_force(example):
    """Independent check: on the cone θ = capability − tol, every azimuth has a feasible ψ
    on a fine torsion grid (brute-force sampling, not the boundary search)."""
    position = np.array([0.2, 0.2, -0.95])
    values = position_capability(example, position, FAST)
    theta = values["tilt_capability"] - 2e-3
    phi = np.radians(np.arange(0.0, 360.0, 360.0 / 24))
    psi = np.radians(np.arange(-60.0, 60.01, 0.25))
    grid_phi, grid_psi = np.meshgrid(phi, psi, indexing="ij")
    angles = np.column_stack([grid_phi.ravel(), np.full(grid_phi.size, theta), grid_psi.ravel()])
    reachable = check(example, angles, position).reachable.reshape(phi.size, psi.size)
    assert np.all(reachable.any(axis=1))


def test_capability_is_symmetric_under_the_design_rotation(symmetric):
    """The design is invariant under a 120° turn about z: so is the atlas (n_phi = 24 maps
    the azimuth grid onto itself), to the search tolerance."""
    position = np.array([0.15, 0.05, -1.2])
    turn = np.radians(120.0)
    rotation = np.array(
        [[math.cos(turn), -math.sin(turn), 0], [math.sin(turn), math.cos(turn), 0], [0, 0, 1]]
    )
    first = position_capability(symmetric, position, FAST)
    second = position_capability(symmetric, rotation @ position, FAST)
    for name in first:
        assert second[name] == pytest.approx(first[name], abs=3e-3), name


def test_volume_is_optional(example):
    options = AtlasOptions(n_phi=24, tolerance=1e-3, volume=True, n_rays=24)
    values = position_capability(example, [0.0, 0.0, -1.3], options)
    assert values["orientation_volume"] > 0.0


def test_dexterous_mask():
    capability = np.array([0.5, 0.3, np.nan, 0.6])
    assert dexterous_mask(capability, 0.4).tolist() == [True, False, False, True]
    mask = dexterous_mask(
        capability,
        0.4,
        psi_min=np.array([-1.0, -1.0, np.nan, -0.2]),
        psi_max=np.array([1.0, 1.0, np.nan, 1.0]),
        torsion_required=(-0.5, 0.5),
    )
    assert mask.tolist() == [True, False, False, False]
    with pytest.raises(InputError):
        dexterous_mask(capability, -0.1)
    with pytest.raises(InputError):
        dexterous_mask(capability, 0.1, torsion_required=(-0.5, 0.5))


# ---------------------------------------------------------------------------- without the extra
_BLOCK = (
    "import sys\n"
    "class Block:\n"
    "    def find_spec(self, name, path=None, target=None):\n"
    "        if name.split('.')[0] in {'dask', 'distributed', 'xarray', 'zarr'}:\n"
    "            raise ImportError('blocked: ' + name)\n"
    "sys.meta_path.insert(0, Block())\n"
)


def test_package_imports_without_the_atlas_extra_and_says_how_to_get_it():
    code = _BLOCK + (
        "import hexapod_workspace as hw\n"
        "from hexapod_workspace._resources import example_config_path\n"
        "m = hw.load_manipulator(example_config_path())\n"
        "try:\n"
        "    hw.workspace_atlas(m, hw.AtlasGrid.box([0, 0, 0, 0, -1.3, -1.3], 0.1), store='x')\n"
        "except hw.MissingExtraError as error:\n"
        "    print('ERR', error)\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in {'dask', 'xarray', 'zarr'}))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert "-m pip install 'dask[distributed]>=2024.12' 'xarray>=2025.1' 'zarr>=3.0'" in done.stdout
    assert done.stdout.strip().endswith("[]")


def test_cli_without_the_extra_exits_2_with_one_line(tmp_path):
    code = _BLOCK + (
        "from hexapod_workspace.cli import main\n"
        "sys.exit(main(['atlas', '--box', '0', '0', '0', '0', '-1.3', '-1.3', '--step', '0.1',"
        f" '--out', {str(tmp_path / 'a.zarr')!r}]))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1
    assert "-m pip install 'dask[distributed]>=2024.12'" in done.stderr
    assert not (tmp_path / "a.zarr").exists()
