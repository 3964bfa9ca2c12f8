"""Figures of a workspace atlas (matplotlib, Agg backend), angles in degrees, lengths in m.

* :func:`plot_tilt_slices`: one heat map of the tilt capability per z slice (x, y in m) with
  the contour of every required tilt θ_req; positions where the reference orientation is
  unreachable are left blank (hatched), never drawn as zero.
* :func:`plot_dexterous_3d`: a 3-D view of the dexterous workspace (grid cells whose tilt
  capability is at least θ_req), one colour per θ_req, with the reachable region as a frame of
  reference.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..core.atlas import AtlasGrid

__all__ = ["plot_atlas", "plot_dexterous_3d", "plot_tilt_slices"]

#: At most this many z slices in the heat-map figure (evenly chosen when there are more).
MAX_SLICES = 12
_LEVEL_COLORS = ("red", "black", "magenta", "white")


def _slices(count: int) -> list[int]:
    if count <= MAX_SLICES:
        return list(range(count))
    return sorted({round(k) for k in np.linspace(0, count - 1, MAX_SLICES)})


def plot_tilt_slices(
    dataset: Any, grid: AtlasGrid, tilts_deg: Sequence[float], path: str | Path
) -> Path:
    """Heat maps of ``tilt_capability`` per z slice with the θ_req contours; returns the PNG."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch, Rectangle

    capability = np.degrees(dataset["tilt_capability"].values)  # (nx, ny, nz)
    x, y, z = grid.x, grid.y, grid.z
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
        if x.size > 1 and y.size > 1:
            filled = np.where(np.isfinite(values), values, -1.0)  # unreachable: below any level
            for level, color in zip(tilts_deg, _LEVEL_COLORS, strict=False):
                if filled.max() >= level > filled.min():
                    lines = axis.contour(
                        x, y, filled, levels=[level], colors=[color], linewidths=1.6, zorder=2
                    )
                    axis.clabel(lines, fmt=f"{level:g}°", fontsize=7)
        axis.set_title(f"z = {z[k]:.3f} m", fontsize=10)
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
    handles = [Patch(facecolor="0.85", hatch="//", edgecolor="0.6", label="reference unreachable")]
    handles += [
        Line2D([], [], color=color, linewidth=1.6, label=f"θ_req = {level:g}°")
        for level, color in zip(tilts_deg, _LEVEL_COLORS, strict=False)
    ]
    figure.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8)
    figure.suptitle("Tilt capability (largest cone of tool directions all attainable) per z slice")
    path = Path(path)
    figure.savefig(path, dpi=110, facecolor="white")
    return path


def plot_dexterous_3d(
    dataset: Any, grid: AtlasGrid, tilts_deg: Sequence[float], path: str | Path
) -> Path:
    """3-D view of the dexterous workspace per θ_req (grid cells as voxels); returns the PNG."""
    import matplotlib as mpl
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    capability = np.degrees(dataset["tilt_capability"].values)
    reachable = dataset["reference_reachable"].values.astype(bool)
    step = grid.step or 1.0
    edges = [
        np.append(axis - 0.5 * step, axis[-1] + 0.5 * step) for axis in (grid.x, grid.y, grid.z)
    ]
    xe, ye, ze = np.meshgrid(*edges, indexing="ij")
    figure = Figure(figsize=(7.5, 6.8))
    axis = figure.add_subplot(projection="3d")
    colors = mpl.colormaps["plasma"](np.linspace(0.15, 0.85, max(1, len(tilts_deg))))
    handles = []
    levels = sorted(tilts_deg)
    # Cut away the quadrant facing the viewer (x > 0, y < 0) so that inner shells show.
    xs, ys, _ = np.meshgrid(grid.x, grid.y, grid.z, indexing="ij")
    kept = ~((xs > 0.25 * step) & (ys < -0.25 * step))
    with np.errstate(invalid="ignore"):
        for index, level in enumerate(levels):
            inside = (capability >= level) & kept
            if index + 1 < len(levels):
                inside &= ~(capability >= levels[index + 1])  # nested: draw each shell once
            if inside.any():
                axis.voxels(
                    xe,
                    ye,
                    ze,
                    inside,
                    facecolors=(*colors[index][:3], 0.55),
                    edgecolor=(0, 0, 0, 0.15),
                    linewidth=0.3,
                )
            volume = float((capability >= level).sum()) * step**3
            label = f"tilt capability ≥ {level:g}°: {volume:.4f} m³"
            handles.append(Patch(facecolor=colors[index], alpha=0.55, label=label))
    lowest = levels[0] if levels else np.inf
    with np.errstate(invalid="ignore"):
        outline = reachable & ~(capability >= lowest) & kept
    if outline.any():
        axis.voxels(
            xe,
            ye,
            ze,
            outline,
            facecolors=(0.6, 0.6, 0.6, 0.06),
            edgecolor=(0.4, 0.4, 0.4, 0.08),
            linewidth=0.2,
        )
        below = f", tilt capability < {lowest:g}°" if levels else ""
        handles.append(Patch(facecolor=(0.6, 0.6, 0.6, 0.3), label=f"reference reachable{below}"))
    axis.set_xlabel("x [m]")
    axis.set_ylabel("y [m]")
    axis.set_zlabel("z [m]")
    spans = [e[-1] - e[0] for e in edges]
    axis.set_box_aspect(spans)
    axis.view_init(elev=22, azim=-60)
    axis.legend(handles=handles, loc="upper left", fontsize=8)
    axis.set_title(
        f"Dexterous workspace: grid cells of {step * 1e3:g} mm, front quadrant (x > 0, y < 0) "
        "cut away",
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
