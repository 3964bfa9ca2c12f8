"""Figures of the workspaces, in degrees (matplotlib's object API: no pyplot, no global backend).

* :func:`plot_projected`: polar plot of the boundary tilt θ against the azimuth φ, one curve per
  method (the paper's Fig. 6 style), so ``torsion_zero`` and ``exact`` can be overlaid.
* :func:`plot_orientation`: the paper's Fig. 4/5: a perspective view of the closed surface in
  the cylindrical picture (θ cos φ, θ sin φ, ψ), and a top view with slice outlines every few
  degrees of ψ, both coloured by ψ on one colour bar, the ψ = 0 section in bold.

Figures are built with :class:`matplotlib.figure.Figure` and written by ``savefig``: importing or
calling this module never changes matplotlib's global state (backend, pyplot figures), so it is
safe inside applications that use matplotlib themselves. The file format follows the suffix
(``.png``, ``.pdf``, ``.svg``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.workspaces.orientation import OrientationWorkspace
from ..core.workspaces.projected import ProjectedWorkspace

if TYPE_CHECKING:
    from matplotlib.projections.polar import PolarAxes
    from mpl_toolkits.mplot3d import Axes3D

__all__ = [
    "label_rings",
    "orientation_figure",
    "plot_orientation",
    "plot_projected",
    "projected_figure",
]

_STYLE: dict[str, dict[str, Any]] = {
    # exact underneath (wider, dashed), torsion_zero on top: both stay visible where they meet
    "exact": {"color": "tab:red", "linestyle": "--", "linewidth": 2.2, "zorder": 3},
    "torsion_zero": {"color": "tab:blue", "linestyle": "-", "linewidth": 1.4, "zorder": 4},
}
#: Slice outlines drawn in the top view: about this many, evenly spaced in ψ.
_TOP_VIEW_OUTLINES = 24


def _position_text(position: NDArray[np.float64]) -> str:
    return "position ({:.3f}, {:.3f}, {:.3f}) m".format(*np.asarray(position, dtype=float))


def _nice_step(span: float, count: int) -> float:
    """A 1-2-5 step giving about ``count`` intervals over ``span``."""
    raw = max(span, 1e-9) / count
    magnitude = 10.0 ** math.floor(math.log10(raw))
    return next(m * magnitude for m in (1.0, 2.0, 2.5, 5.0, 10.0) if m * magnitude >= raw)


def _curve_distances(
    curves: Sequence[tuple[NDArray, NDArray]], ticks: NDArray, angle: float
) -> NDArray[np.float64]:
    """Per tick radius, the distance (deg) to the nearest curve along the spoke at ``angle``."""
    radii = np.array([np.interp(angle, phi, theta, period=360.0) for phi, theta in curves])
    return np.min(np.abs(ticks[:, None] - radii[None, :]), axis=1)


#: Azimuths (deg) where ring labels may sit: between the 45° spokes, away from the φ labels.
_LABEL_ANGLES = np.arange(22.5, 360.0, 45.0)


def _ring_labels(
    curves: Sequence[tuple[NDArray, NDArray]], ticks: NDArray, top: float
) -> list[tuple[float, float, str]]:
    """Where to write each ring's label: (azimuth deg, radius deg, vertical alignment).

    Every ring is labelled. All labels sit on the one spoke where they are farthest from the
    curves; a label that would still sit on a curve there (curves hugging a ring, e.g. 38-39.5°
    against the 40° ring) moves just off the ring, to the side away from the curves, so the
    reader sees which ring is which without text over a curve.
    """
    clearance = [float(np.min(_curve_distances(curves, ticks, float(a)))) for a in _LABEL_ANGLES]
    angle = float(_LABEL_ANGLES[int(np.argmax(clearance))])
    radii = np.array([np.interp(angle, phi, theta, period=360.0) for phi, theta in curves])
    labels = []
    for tick, distance in zip(ticks, _curve_distances(curves, ticks, angle), strict=True):
        if distance >= 0.035 * top:
            labels.append((angle, float(tick), "center"))
        elif np.all(radii <= tick):  # curves inside the ring: label outside it
            labels.append((angle, float(tick) + 0.02 * top, "bottom"))
        else:
            labels.append((angle, float(tick) - 0.02 * top, "top"))
    return labels


def label_rings(axes: Any, curves: Sequence[tuple[ArrayLike, ArrayLike]]) -> None:
    """Radial axis and ring labels of a polar plot of tilts (deg) against azimuths (deg).

    The axis runs from 0 to a round value at least 10 % above the largest tilt (no curve on the
    frame); every ring but the frame is labelled, where :func:`_ring_labels` finds room.

    Parameters
    ----------
    axes : matplotlib PolarAxes
    curves : sequence of (phi, theta)
        What is drawn: azimuths and tilts in degrees, arrays of shape (n,) (curves or points).
    """
    ordered = []
    for phi, theta in curves:
        phi = np.mod(np.asarray(phi, dtype=float), 360.0)
        order = np.argsort(phi)
        ordered.append((phi[order], np.asarray(theta, dtype=float)[order]))
    largest = max((float(np.max(theta)) for _, theta in ordered if theta.size), default=1.0)
    step = _nice_step(largest, 5)
    top = step * math.ceil(largest * 1.1 / step)
    ticks = np.arange(step, top - step / 2, step)  # none on the frame
    axes.set_ylim(0.0, top)
    axes.set_yticks(ticks, [""] * len(ticks))  # the rings; their labels are placed below
    for (angle, radius, align), tick in zip(_ring_labels(ordered, ticks, top), ticks, strict=True):
        axes.text(
            math.radians(angle),
            radius,
            f"{tick:g}°",
            ha="center",
            va=align,
            fontsize=8,
            zorder=5,
            bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.85, "pad": 0.8},
        )


def plot_projected(
    workspaces: Sequence[ProjectedWorkspace], path: str | Path, *, title: str | None = None
) -> Path:
    """Polar plot of the projected orientation workspace(s), θ against φ in degrees.

    The radial axis runs from 0 to a round value above the largest tilt, so no curve lies on
    the frame; every ring is labelled, at the azimuth where the labels are farthest from the
    curves, and a label that would sit on a curve moves just off its ring (:func:`_ring_labels`).

    Parameters
    ----------
    workspaces : sequence of ProjectedWorkspace
        Usually the two methods at the same position.
    path : str or pathlib.Path
        Image file to write (format from the suffix).
    title : str, optional

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path = Path(path)
    projected_figure(workspaces, title=title).savefig(path, dpi=120)
    return path


def projected_figure(workspaces: Sequence[ProjectedWorkspace], *, title: str | None = None) -> Any:
    """The figure of :func:`plot_projected` (a :class:`matplotlib.figure.Figure`), not saved."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.4, 6.8), layout="constrained")
    axes = cast("PolarAxes", figure.add_subplot(projection="polar"))
    curves = []
    for workspace in workspaces:
        style = _STYLE.get(workspace.method, {"color": "black", "linestyle": "-"})
        phi = np.append(workspace.phi, workspace.phi[0])
        theta = np.degrees(np.append(workspace.theta, workspace.theta[0]))
        label = (
            f"{workspace.method}: θ {np.degrees(workspace.tilt_min):.2f}°–"
            f"{np.degrees(workspace.tilt_max):.2f}°, Ω {workspace.solid_angle:.3f} sr"
        )
        axes.plot(phi, theta, label=label, **style)
        curves.append((np.degrees(workspace.phi), theta[:-1]))
    label_rings(axes, curves)
    axes.set_xticks(np.radians(np.arange(0, 360, 45)))
    axes.grid(True, linewidth=0.4)
    axes.set_title(
        title
        or "Projected orientation workspace: tilt θ against azimuth φ\n"
        f"{_position_text(workspaces[0].position)}",
        fontsize=10,
    )
    figure.legend(loc="outside lower center", fontsize=8)
    return figure


def _closed(ring: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.vstack([ring, ring[:1]])


def plot_orientation(
    workspace: OrientationWorkspace, path: str | Path, *, title: str | None = None
) -> Path:
    """Perspective view of the orientation workspace's closed surface and its top view.

    Both panels colour by the torsion ψ on one colour bar. The top view draws about
    :data:`_TOP_VIEW_OUTLINES` slice outlines evenly spaced in ψ (all slices at once would
    merge into a moiré) and the ψ = 0 section in bold black.

    Parameters
    ----------
    workspace : OrientationWorkspace
    path : str or pathlib.Path
        Image file to write (format from the suffix).
    title : str, optional

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path = Path(path)
    orientation_figure(workspace, title=title).savefig(path, dpi=110)
    return path


def orientation_figure(workspace: OrientationWorkspace, *, title: str | None = None) -> Any:
    """The figure of :func:`plot_orientation` (a :class:`matplotlib.figure.Figure`), not saved."""
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator
    from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the 3d projection)

    figure = Figure(figsize=(13.5, 5.8), layout="constrained")
    # wspace: the 3-D panel's ψ label stands out to its right, past what the layout measures;
    # the gap keeps it clear of the top view's θ sin φ label.
    figure.get_layout_engine().set(wspace=0.12)  # type: ignore[call-arg, union-attr]
    grid = figure.add_gridspec(1, 2, width_ratios=(1.0, 1.0))
    surface_axes = cast("Axes3D", figure.add_subplot(grid[0, 0], projection="3d"))
    top_axes = figure.add_subplot(grid[0, 1])
    rings = [np.degrees(piece.xy()) for piece in workspace.slices]
    psi = np.degrees([piece.psi for piece in workspace.slices])
    cmap = colormaps["viridis"]
    low, high = np.degrees(workspace.psi_min), np.degrees(workspace.psi_max)
    norm = Normalize(vmin=min(low, -1e-9), vmax=max(high, 1e-9))
    if rings and all(len(ring) == len(rings[0]) for ring in rings):
        # Close every ring, and the solid with its extreme-torsion apexes.
        x = np.array([np.append(ring[:, 0], ring[0, 0]) for ring in rings])
        y = np.array([np.append(ring[:, 1], ring[0, 1]) for ring in rings])
        z = np.repeat(psi[:, None], x.shape[1], axis=1)
        bottom = (
            rings[0].mean(axis=0)
            if workspace.psi_min_point is None
            else np.degrees(workspace.psi_min_point)
        )
        top = (
            rings[-1].mean(axis=0)
            if workspace.psi_max_point is None
            else np.degrees(workspace.psi_max_point)
        )
        x = np.vstack([np.full(x.shape[1], bottom[0]), x, np.full(x.shape[1], top[0])])
        y = np.vstack([np.full(y.shape[1], bottom[1]), y, np.full(y.shape[1], top[1])])
        z = np.vstack([np.full(z.shape[1], low), z, np.full(z.shape[1], high)])
        surface_axes.plot_surface(
            x,
            y,
            z,
            rstride=max(1, x.shape[0] // 60),
            cstride=max(1, x.shape[1] // 60),
            cmap=cmap,
            norm=norm,
            linewidth=0.1,
            edgecolor=(0.0, 0.0, 0.0, 0.25),
            antialiased=True,
        )
    for axis in (surface_axes.xaxis, surface_axes.yaxis, surface_axes.zaxis):
        axis.set_major_locator(MaxNLocator(5))
    surface_axes.set_xlabel("θ cos φ [deg]")
    surface_axes.set_ylabel("θ sin φ [deg]")
    surface_axes.set_zlabel("ψ [deg]")
    surface_axes.set_title("Orientation workspace (cylindrical picture)", fontsize=10)
    surface_axes.view_init(elev=22, azim=-60)
    surface_axes.set_box_aspect(None, zoom=0.88)  # keeps the ψ label inside its own panel

    if rings:
        zero = int(np.argmin(np.abs(psi)))
        every = max(1, math.ceil(len(rings) / _TOP_VIEW_OUTLINES))
        shown = [k for k in range(zero % every, len(rings), every) if k != zero]
        outlines = LineCollection(
            [_closed(rings[k]) for k in shown], linewidths=0.9, colors=cmap(norm(psi[shown]))
        )
        top_axes.add_collection(outlines)
        bold = _closed(rings[zero])
        top_axes.plot(
            bold[:, 0], bold[:, 1], color="black", linewidth=2.4, label=f"ψ = {psi[zero]:g}°"
        )
        top_axes.plot(
            [],
            [],
            color=cmap(0.5),
            linewidth=0.9,
            label=f"ψ every {every * np.degrees(workspace.psi_step):g}°",
        )
        top_axes.legend(loc="upper right", fontsize=8)
        top_axes.autoscale_view()
    top_axes.set_aspect("equal", adjustable="datalim")
    top_axes.set_xlabel("θ cos φ [deg]")
    top_axes.set_ylabel("θ sin φ [deg]")
    top_axes.grid(True, linewidth=0.3)
    top_axes.set_title("Top view: slice outlines, ψ = 0 section in bold", fontsize=10)
    colorbar = figure.colorbar(
        ScalarMappable(norm=norm, cmap=cmap), ax=[surface_axes, top_axes], shrink=0.8, pad=0.02
    )
    colorbar.set_label("torsion ψ [deg]")
    figure.suptitle(
        title
        or f"{_position_text(workspace.position)}: ψ ∈ [{low:.2f}°, {high:.2f}°], "
        f"volume {workspace.volume:.4f} rad³",
        fontsize=11,
    )
    return figure
