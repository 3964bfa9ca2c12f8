"""Figures of a workspace atlas (matplotlib, Agg backend), angles in degrees, lengths in m.

* :func:`plot_tilt_slices`: one heat map of the tilt capability per z slice (x, y in m) with
  the outline of the grid cells that reach every required tilt θ_req (the cells the dexterous
  volume counts, a single cell as a square) and their count; positions where the reference
  orientation is unreachable are left blank (hatched), never drawn as zero.
* :func:`plot_dexterous_3d`: a 3-D section view of the dexterous workspace (grid cells whose
  tilt capability is at least θ_req, opaque, one colour per θ_req, inside the reachable cells
  in grey), the half y < 0 removed so the nested sets show side by side.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ..core.workspaces.atlas import AtlasGrid

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from mpl_toolkits.mplot3d import Axes3D

__all__ = ["plot_atlas", "plot_dexterous_3d", "plot_tilt_slices"]

#: At most this many z slices in the heat-map figure (evenly chosen when there are more).
MAX_SLICES = 12
_LEVEL_COLORS = ("red", "black", "magenta", "white")


def _slices(count: int) -> list[int]:
    if count <= MAX_SLICES:
        return list(range(count))
    return sorted({round(k) for k in np.linspace(0, count - 1, MAX_SLICES)})


def _cell_outline(
    inside: np.ndarray, x: np.ndarray, y: np.ndarray, half: float
) -> list[list[tuple[float, float]]]:
    """Edges (line segments, m) between the grid cells of ``inside`` (rows y, columns x) and
    the others or the border: the exact outline of the set the dexterous volume counts, one
    square per cell at most (an interpolated contour would shrink a single cell to a dot)."""
    rows, columns = inside.shape
    padded = np.zeros((rows + 2, columns + 2), dtype=bool)
    padded[1:-1, 1:-1] = inside
    segments = []
    for i, j in zip(*np.nonzero(inside), strict=True):
        cx, cy = float(x[j]), float(y[i])
        left, right, low, high = cx - half, cx + half, cy - half, cy + half
        if not padded[i + 1, j]:
            segments.append([(left, low), (left, high)])
        if not padded[i + 1, j + 2]:
            segments.append([(right, low), (right, high)])
        if not padded[i, j + 1]:
            segments.append([(left, low), (right, low)])
        if not padded[i + 2, j + 1]:
            segments.append([(left, high), (right, high)])
    return segments


def plot_tilt_slices(
    dataset: Any, grid: AtlasGrid, tilts_deg: Sequence[float], path: str | Path
) -> Path:
    """Heat maps of ``tilt_capability`` per z slice with the θ_req contours; returns the PNG."""
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch, Rectangle

    capability = np.degrees(dataset["tilt_capability"].values)  # (nx, ny, nz)
    x, y, z = grid.box_axes
    chosen = _slices(z.size)[::-1]  # top slice first (z up)
    columns = min(4, len(chosen))
    rows = -(-len(chosen) // columns)
    figure = Figure(figsize=(3.3 * columns + 1.2, 3.1 * rows + 0.9), layout="constrained")
    axes = figure.subplots(rows, columns, squeeze=False, sharex=True, sharey=True)
    known = capability[np.isfinite(capability)]
    vmax = float(known.max()) if known.size else 1.0
    half = 0.5 * (grid.step or 1.0)
    extent = (x[0] - half, x[-1] + half, y[0] - half, y[-1] + half)
    image = None
    for axis, k in zip(axes.flat, chosen, strict=False):
        values = capability[:, :, k].T  # rows y, columns x
        axis.set_facecolor("0.85")
        axis.add_patch(
            Rectangle(
                (extent[0], extent[2]),
                extent[1] - extent[0],
                extent[3] - extent[2],
                hatch="//",
                fill=False,
                edgecolor="0.6",
                linewidth=0,
                zorder=0,
            )
        )
        image = axis.imshow(
            np.ma.masked_invalid(values),
            origin="lower",
            extent=extent,
            cmap="viridis",
            vmin=0.0,
            vmax=vmax,
            interpolation="nearest",
            zorder=1,
        )
        counts = []
        with np.errstate(invalid="ignore"):
            for level, color in zip(tilts_deg, _LEVEL_COLORS, strict=False):
                inside = values >= level  # NaN (unreachable) is never inside
                segments = _cell_outline(inside, x, y, half)
                if segments:
                    axis.add_collection(
                        LineCollection(segments, colors=color, linewidths=1.8, zorder=2)
                    )
                counts.append(f"≥ {level:g}°: {int(inside.sum())}")
        cells = f"\ncells {', '.join(counts)}" if counts else ""
        axis.set_title(f"z = {z[k]:.3f} m{cells}", fontsize=9)
        axis.set_aspect("equal")
    for axis in axes.flat[len(chosen) :]:
        axis.set_visible(False)
    for axis in axes[-1, :]:
        axis.set_xlabel("x [m]")
    for axis in axes[:, 0]:
        axis.set_ylabel("y [m]")
    if image is not None:
        bar = figure.colorbar(image, ax=axes, shrink=0.9)
        bar.set_label("tilt capability [deg]")
    handles: list[Artist] = [
        Patch(facecolor="0.85", hatch="//", edgecolor="0.6", label="reference unreachable")
    ]
    handles += [
        Line2D([], [], color=color, linewidth=1.8, label=f"cells with tilt capability ≥ {level:g}°")
        for level, color in zip(tilts_deg, _LEVEL_COLORS, strict=False)
    ]
    figure.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8)
    figure.suptitle(
        "Tilt capability (largest cone of tool directions all attainable) per z slice; the "
        "outlines enclose the grid cells the dexterous volume counts (a lone square: one cell)",
        fontsize=10,
    )
    path = Path(path)
    figure.savefig(path, dpi=110, facecolor="white")
    return path


def plot_dexterous_3d(
    dataset: Any, grid: AtlasGrid, tilts_deg: Sequence[float], path: str | Path
) -> Path:
    """Section view of the dexterous workspace per θ_req (grid cells as voxels); returns the PNG.

    The cells are opaque and nested: reachable (grey), then one colour per θ_req. The half
    y < 0 is removed, so the viewer looks at the section through the axis (the y = 0 row of
    cells) and sees the nested sets side by side; the box is fitted to the reachable cells.
    """
    import matplotlib as mpl
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    capability = np.degrees(dataset["tilt_capability"].values)
    reachable = dataset["reference_reachable"].values.astype(bool)
    step = grid.step or 1.0
    edges = [np.append(axis - 0.5 * step, axis[-1] + 0.5 * step) for axis in grid.box_axes]
    xe, ye, ze = np.meshgrid(*edges, indexing="ij")
    figure = Figure(figsize=(7.8, 5.6), layout="constrained")
    axis = cast("Axes3D", figure.add_subplot(projection="3d"))
    colors = mpl.colormaps["plasma"](np.linspace(0.15, 0.85, max(1, len(tilts_deg))))
    levels = sorted(tilts_deg)
    _, ys, _ = np.meshgrid(*grid.box_axes, indexing="ij")
    kept = ys > -0.25 * step  # the half facing the viewer removed: a section through the axis
    shells = []  # (cells, face colour, legend label), outermost first
    with np.errstate(invalid="ignore"):
        lowest = levels[0] if levels else np.inf
        below = f", tilt capability < {lowest:g}°" if levels else ""
        shells.append(
            (
                reachable & ~(capability >= lowest),
                (0.78, 0.78, 0.78, 1.0),
                f"reference reachable{below}",
            )
        )
        for index, level in enumerate(levels):
            inside = capability >= level
            volume = float(inside.sum()) * step**3
            if index + 1 < len(levels):
                inside &= ~(capability >= levels[index + 1])  # nested: each cell drawn once
            shells.append(
                (
                    inside,
                    (*colors[index][:3], 1.0),
                    f"tilt capability ≥ {level:g}°: {volume:.4f} m³",
                )
            )
    handles = []
    for cells, color, label in shells:
        if (cells & kept).any():
            axis.voxels(
                xe, ye, ze, cells & kept, facecolors=color, edgecolor=(0, 0, 0, 0.25), linewidth=0.3
            )
        handles.append(Patch(facecolor=color, edgecolor=(0, 0, 0, 0.4), label=label))
    # The box around the reachable cells (kept half), not the whole requested grid.
    shown = reachable & kept
    if shown.any():
        occupied = np.nonzero(shown)
        bounds = [
            (float(edge[k.min()]), float(edge[k.max() + 1]))
            for edge, k in zip(edges, occupied, strict=True)
        ]
        limits = (axis.set_xlim, axis.set_ylim, axis.set_zlim)
        for setter, (low, high) in zip(limits, bounds, strict=True):
            setter(low, high)
        axis.set_box_aspect([high - low for low, high in bounds], zoom=0.95)
    axis.set_xlabel("x [m]")
    axis.set_ylabel("y [m]")
    axis.set_zlabel("z [m]")
    axis.view_init(elev=18, azim=-62)
    figure.legend(handles=handles, loc="outside lower center", fontsize=8, ncols=1)
    figure.suptitle(
        f"Dexterous workspace in grid cells of {step * 1e3:g} mm: section through the axis "
        "(the half y < 0 removed)",
        fontsize=10,
    )
    path = Path(path)
    figure.savefig(path, dpi=110, facecolor="white")
    return path


def plot_atlas(
    dataset: Any, grid: AtlasGrid, tilts_deg: Sequence[float], folder: Path
) -> list[Path]:
    """Both figures into ``folder`` (created): ``atlas_tilt_slices.png``, ``atlas_dexterous.png``.

    Explicit-position atlases have no slices or cells: nothing is drawn for them.
    """
    if not grid.is_box:
        return []
    folder.mkdir(parents=True, exist_ok=True)
    return [
        plot_tilt_slices(dataset, grid, tilts_deg, folder / "atlas_tilt_slices.png"),
        plot_dexterous_3d(dataset, grid, tilts_deg, folder / "atlas_dexterous.png"),
    ]
