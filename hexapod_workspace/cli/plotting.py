"""Figures of the workspaces (matplotlib, non-interactive Agg backend), in degrees.

* :func:`plot_projected`: polar plot of the boundary tilt θ against the azimuth φ, one curve per
  method (the paper's Fig. 6 style), so ``torsion_zero`` and ``exact`` can be overlaid.
* :func:`plot_orientation`: the paper's Fig. 4/5: a perspective view of the closed surface in
  the cylindrical picture (θ cos φ, θ sin φ, ψ) and a top view with every slice and the ψ = 0
  section in bold.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..core.orientation import OrientationWorkspace
from ..core.projected import ProjectedWorkspace

__all__ = ["plot_orientation", "plot_projected"]

_STYLE = {"torsion_zero": ("tab:blue", "-"), "exact": ("tab:red", "--")}


def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def _position_text(position: np.ndarray) -> str:
    return "position ({:.3f}, {:.3f}, {:.3f}) m".format(*np.asarray(position, dtype=float))


def plot_projected(
    workspaces: Sequence[ProjectedWorkspace], path: str | Path, *, title: str | None = None
) -> Path:
    """Polar plot of the projected orientation workspace(s), θ against φ in degrees.

    Parameters
    ----------
    workspaces : sequence of ProjectedWorkspace
        Usually the two methods at the same position.
    path : str or pathlib.Path
        PNG file to write.
    title : str, optional

    Returns
    -------
    pathlib.Path
    """
    plt = _pyplot()
    figure = plt.figure(figsize=(6.4, 6.4))
    axes = figure.add_subplot(projection="polar")
    for workspace in workspaces:
        color, line = _STYLE.get(workspace.method, ("black", "-"))
        phi = np.append(workspace.phi, workspace.phi[0])
        theta = np.degrees(np.append(workspace.theta, workspace.theta[0]))
        label = (
            f"{workspace.method}: θ {np.degrees(workspace.tilt_min):.2f}°–"
            f"{np.degrees(workspace.tilt_max):.2f}°, Ω {workspace.solid_angle:.3f} sr"
        )
        axes.plot(phi, theta, color=color, linestyle=line, linewidth=1.6, label=label)
    axes.set_rlabel_position(112.5)
    axes.set_title(
        title
        or f"Projected orientation workspace: tilt θ [deg] vs azimuth φ\n"
        f"{_position_text(workspaces[0].position)}",
        fontsize=10,
    )
    axes.legend(loc="lower center", bbox_to_anchor=(0.5, -0.18), fontsize=8)
    figure.tight_layout()
    path = Path(path)
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def plot_orientation(
    workspace: OrientationWorkspace, path: str | Path, *, title: str | None = None
) -> Path:
    """Perspective view of the orientation workspace's closed surface and its top view.

    Parameters
    ----------
    workspace : OrientationWorkspace
    path : str or pathlib.Path
        PNG file to write.
    title : str, optional

    Returns
    -------
    pathlib.Path
    """
    plt = _pyplot()
    figure = plt.figure(figsize=(12.0, 5.6))
    surface_axes = figure.add_subplot(1, 2, 1, projection="3d")
    top_axes = figure.add_subplot(1, 2, 2)
    rings = [np.degrees(piece.xy()) for piece in workspace.slices]
    psi = np.degrees([piece.psi for piece in workspace.slices])
    if rings:
        # Close every ring, and the solid with its extreme-torsion apexes.
        x = np.array([np.append(ring[:, 0], ring[0, 0]) for ring in rings])
        y = np.array([np.append(ring[:, 1], ring[0, 1]) for ring in rings])
        z = np.repeat(psi[:, None], x.shape[1], axis=1)
        # Apexes: where the extreme torsions are attained (else the end rings' centres).
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
        z = np.vstack(
            [
                np.full(z.shape[1], np.degrees(workspace.psi_min)),
                z,
                np.full(z.shape[1], np.degrees(workspace.psi_max)),
            ]
        )
        stride = max(1, x.shape[0] // 60)
        surface_axes.plot_surface(
            x,
            y,
            z,
            rstride=stride,
            cstride=max(1, x.shape[1] // 60),
            cmap="viridis",
            linewidth=0.1,
            edgecolor="k",
            alpha=0.85,
        )
    surface_axes.set_xlabel("θ cos φ [deg]")
    surface_axes.set_ylabel("θ sin φ [deg]")
    surface_axes.set_zlabel("ψ [deg]")
    surface_axes.set_title("Orientation workspace (cylindrical picture)", fontsize=10)
    surface_axes.view_init(elev=22, azim=-60)

    zero = int(np.argmin(np.abs(psi))) if rings else -1
    for index, ring in enumerate(rings):
        if index == zero:
            continue
        closed = np.vstack([ring, ring[:1]])
        top_axes.plot(closed[:, 0], closed[:, 1], color="0.75", linewidth=0.4)
    if rings:
        closed = np.vstack([rings[zero], rings[zero][:1]])
        top_axes.plot(
            closed[:, 0], closed[:, 1], color="black", linewidth=2.4, label=f"ψ = {psi[zero]:g}°"
        )
        top_axes.legend(loc="upper right", fontsize=8)
    top_axes.set_aspect("equal")
    top_axes.set_xlabel("θ cos φ [deg]")
    top_axes.set_ylabel("θ sin φ [deg]")
    top_axes.grid(True, linewidth=0.3)
    top_axes.set_title("Top view (all slices; ψ = 0 section in bold)", fontsize=10)
    figure.suptitle(
        title
        or f"{_position_text(workspace.position)}: ψ ∈ [{np.degrees(workspace.psi_min):.2f}°, "
        f"{np.degrees(workspace.psi_max):.2f}°], volume {workspace.volume:.4f} rad³",
        fontsize=11,
    )
    figure.tight_layout()
    path = Path(path)
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path
