"""The atlas figures: the slice maps outline exactly the grid cells the
dexterous volume counts (a single cell as a square, with the counts in each panel's title), and
the 3-D view is an opaque section fitted to the reachable cells (no blank quarter)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.figure import Figure

from hexapod_workspace import AtlasGrid
from hexapod_workspace.cli import atlas_plots


def _perimeter(inside: np.ndarray) -> int:
    """Cell edges between a cell of the set and one outside it or the border (independent of
    the plotting code: differences of the padded mask along each axis)."""
    padded = np.pad(inside.astype(int), 1)
    return int(np.abs(np.diff(padded, axis=0)).sum() + np.abs(np.diff(padded, axis=1)).sum())


def test_a_single_cell_is_outlined_as_a_square_not_a_dot():
    inside = np.zeros((3, 3), dtype=bool)
    inside[1, 1] = True
    x = y = np.array([-0.1, 0.0, 0.1])
    segments = atlas_plots._cell_outline(inside, x, y, 0.05)
    corners = {point for segment in segments for point in segment}
    assert len(segments) == 4
    assert corners == {(-0.05, -0.05), (-0.05, 0.05), (0.05, -0.05), (0.05, 0.05)}


def test_the_outline_is_the_boundary_of_the_set_of_cells():
    rng = np.random.default_rng(16)
    for _ in range(20):
        inside = rng.random((7, 9)) < 0.5
        x, y = np.arange(9) * 0.1, np.arange(7) * 0.1
        segments = atlas_plots._cell_outline(inside, x, y, 0.05)
        assert len(segments) == _perimeter(inside)
        lengths = [np.hypot(b[0] - a[0], b[1] - a[1]) for a, b in segments]
        assert np.allclose(lengths, 0.1)


@pytest.fixture
def atlas():
    """A small box atlas with an axisymmetric capability falling off from the axis, NaN where
    the reference is unreachable, and one z slice where only the axis cell reaches 20°."""
    grid = AtlasGrid.box([-0.3, 0.3, -0.3, 0.3, -1.4, -1.2], 0.1)
    x, y, z = np.meshgrid(*grid.box_axes, indexing="ij")
    radius = np.hypot(x, y)
    capability = 35.0 - 60.0 * radius
    capability[:, :, 0] = np.where(radius[:, :, 0] < 0.05, 20.5, 15.0)  # z = -1.4: one >= 20
    reachable = radius < 0.35
    capability[~reachable] = np.nan
    dataset = {
        "tilt_capability": SimpleNamespace(values=np.radians(capability)),
        "reference_reachable": SimpleNamespace(values=reachable),
    }
    return dataset, grid, capability, reachable


def _drawn(monkeypatch, plot, *args) -> Figure:
    saved: list[Figure] = []
    monkeypatch.setattr(Figure, "savefig", lambda self, *a, **k: saved.append(self))
    plot(*args)
    (figure,) = saved
    return figure


def test_slice_titles_count_the_cells_the_volume_counts(monkeypatch, tmp_path, atlas):
    dataset, grid, capability, _ = atlas
    figure = _drawn(
        monkeypatch, atlas_plots.plot_tilt_slices, dataset, grid, [20, 30], tmp_path / "s.png"
    )
    titles = [axis.get_title() for axis in figure.axes if axis.get_visible() and axis.get_title()]
    z = grid.box_axes[2]
    assert len(titles) == z.size
    for k, title in zip(range(z.size - 1, -1, -1), titles, strict=True):  # top slice first
        with np.errstate(invalid="ignore"):
            counts = [int((capability[:, :, k] >= level).sum()) for level in (20, 30)]
        assert title == f"z = {z[k]:.3f} m\ncells ≥ 20°: {counts[0]}, ≥ 30°: {counts[1]}"
    assert titles[-1].endswith("cells ≥ 20°: 1, ≥ 30°: 0")  # the lone cell, outlined


def test_the_3d_view_is_fitted_to_the_reachable_cells_of_the_section(monkeypatch, tmp_path, atlas):
    dataset, grid, _, reachable = atlas
    figure = _drawn(
        monkeypatch, atlas_plots.plot_dexterous_3d, dataset, grid, [20, 30], tmp_path / "d.png"
    )
    (axis,) = figure.axes
    step = grid.step
    x, y, z = np.meshgrid(*grid.box_axes, indexing="ij")
    kept = reachable & (y > -0.25 * step)  # the section: the half y < 0 removed
    for limits, values in zip(
        (axis.get_xlim(), axis.get_ylim(), axis.get_zlim()), (x, y, z), strict=True
    ):
        low, high = values[kept].min() - step / 2, values[kept].max() + step / 2
        assert limits == pytest.approx((low, high)), (limits, low, high)
    labels = [text.get_text() for text in figure.legends[0].get_texts()]
    assert labels[0] == "reference reachable, tilt capability < 20°"
    assert labels[1].startswith("tilt capability ≥ 20°: ")
