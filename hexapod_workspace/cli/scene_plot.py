"""The scene in 3-D: machine, tool, obstacles, the closest pair, the cone of tool directions.

Draws a :class:`~hexapod_workspace.core.cell.scene_view.SceneView` on a 3-D axes of matplotlib's
object API (no pyplot, no global backend: the module is safe inside applications that use
matplotlib themselves). Used by ``scene --plot`` (one pose) and by ``check-path --plot`` (the
machine at the path's first violation, beside the margins).

Reading the picture: legs grey, the platform and the tool blue, obstacles brown; the two bodies
of the closest pair red when the pair is violated (margin < 0), orange otherwise, joined by a
dashed line between their closest points and named with the margin in mm in the title; the cone
of attainable tool directions at the tool centre point translucent green. Axes in m, base frame,
equal scale on the three axes (a cylinder looks round).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from ..core.base.rotations import matrix_to_tt
from ..core.cell.scene_view import Body, SceneView

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d import Axes3D

__all__ = ["draw_scene", "plot_scene", "scene_figure", "scene_title"]

#: Colours: machine, leg, obstacle, closest pair violated / not violated, cone.
MACHINE, LEG, OBSTACLE = "tab:blue", "0.45", "tab:brown"
VIOLATED, CLOSEST, CONE = "tab:red", "tab:orange", "tab:green"
_SEGMENTS = 24  # around a circle


def _circle_frame(body: Body) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    return body.rotation[:, 0], body.rotation[:, 1]


def _tube(
    a: NDArray[np.float64], b: NDArray[np.float64], radius: float, rotation: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Surface grid of a cylinder of ``radius`` from a to b (rotation's x, y span the section)."""
    angle = np.linspace(0.0, 2.0 * np.pi, _SEGMENTS + 1)
    ring = radius * (
        np.outer(np.cos(angle), rotation[:, 0]) + np.outer(np.sin(angle), rotation[:, 1])
    )
    grid = np.stack([a + ring, b + ring])  # (2, k, 3)
    return grid[..., 0], grid[..., 1], grid[..., 2]


def _sphere(
    centre: NDArray[np.float64], radius: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    u = np.linspace(0.0, 2.0 * np.pi, _SEGMENTS + 1)
    v = np.linspace(0.0, np.pi, _SEGMENTS // 2 + 1)
    x = centre[0] + radius * np.outer(np.cos(u), np.sin(v))
    y = centre[1] + radius * np.outer(np.sin(u), np.sin(v))
    z = centre[2] + radius * np.outer(np.ones_like(u), np.cos(v))
    return x, y, z


def _box_faces(body: Body) -> list[NDArray[np.float64]]:
    half = 0.5 * body.size
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    corners = body.centre + (signs * half) @ body.rotation.T
    faces = [
        [0, 1, 3, 2],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 3, 7, 5],
    ]
    return [corners[face] for face in faces]


def _draw_body(axes: Axes3D, body: Body, colour: str, alpha: float) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if body.kind == "segment":
        a, b = body.points
        if body.radius > 0.0:
            axes.plot_surface(
                *_tube(a, b, body.radius, body.rotation),
                color=colour,
                alpha=alpha,
                linewidth=0,
                shade=True,
            )
            if not body.moving or body.name == "tool":  # a capsule's round ends
                for end in (a, b):
                    axes.plot_surface(
                        *_sphere(end, body.radius),
                        color=colour,
                        alpha=alpha,
                        linewidth=0,
                        shade=True,
                    )
        else:
            axes.plot(*np.transpose(body.points), color=colour, linewidth=2.0)
    elif body.kind == "cylinder":
        axis = body.rotation[:, 2] * 0.5 * body.length
        a, b = body.centre - axis, body.centre + axis
        axes.plot_surface(
            *_tube(a, b, body.radius, body.rotation),
            color=colour,
            alpha=alpha,
            linewidth=0,
            shade=True,
        )
        x, y = _circle_frame(body)
        angle = np.linspace(0.0, 2.0 * np.pi, _SEGMENTS + 1)
        ring = body.radius * (np.outer(np.cos(angle), x) + np.outer(np.sin(angle), y))
        axes.add_collection3d(
            Poly3DCollection([a + ring, b + ring], facecolor=colour, alpha=alpha, edgecolor="none")
        )
        for end in (a, b):
            axes.plot(*np.transpose(end + ring), color=colour, linewidth=1.0)
    elif body.kind == "box":
        axes.add_collection3d(
            Poly3DCollection(
                _box_faces(body), facecolor=colour, alpha=alpha, edgecolor="0.2", linewidth=0.5
            )
        )
    elif body.kind == "sphere":
        axes.plot_surface(
            *_sphere(body.centre, body.radius), color=colour, alpha=alpha, linewidth=0, shade=True
        )
    elif body.kind == "polygon":
        closed = np.vstack([body.points, body.points[:1]])
        axes.add_collection3d(
            Poly3DCollection([body.points], facecolor=colour, alpha=0.25 * alpha, edgecolor=colour)
        )
        axes.plot(*np.transpose(closed), color=colour, linewidth=1.5)


def _extent(view: SceneView) -> NDArray[np.float64]:
    """Corners of a box holding every body (m), shape (2, 3)."""
    points = [view.position[None]]
    corners = np.array([[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]])
    for body in view.bodies:
        if body.points.size:  # segments and polygons: their points, widened by the radius
            points += [body.points + body.radius * c for c in corners]
            continue
        reach = max(body.radius, 0.5 * float(np.linalg.norm(body.size)), 0.5 * body.length)
        points.append(body.centre[None] + reach * corners)
    return np.array([np.min(np.vstack(points), axis=0), np.max(np.vstack(points), axis=0)])


def scene_title(view: SceneView) -> str:
    """Two lines: the pose, then the closest pair and its margin."""
    phi, theta, psi = np.degrees(matrix_to_tt(view.rotation))
    x, y, z = view.position
    lines = [
        f"C = ({x:.3f}, {y:.3f}, {z:.3f}) m, (φ, θ, ψ) = ({phi:.1f}°, {theta:.1f}°, {psi:.1f}°)"
    ]
    pair = view.closest
    if pair is not None:
        state = "VIOLATED" if pair.violated else "closest pair"
        lines.append(
            f"{state}: {pair.name}, margin {1000.0 * pair.margin:.1f} mm ({pair.constraint})"
        )
    elif not view.has_scene:
        lines.append("no collision scene and no leg diameter: no pair checked")
    return "\n".join(lines)


def draw_scene(axes: Axes3D, view: SceneView, *, title: str | None = None) -> None:
    """Draw ``view`` on a 3-D axes (see the module documentation for the colours)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    pair = view.closest
    highlight = (
        {}
        if pair is None
        else dict.fromkeys((pair.first, pair.second), VIOLATED if pair.violated else CLOSEST)
    )
    for body in view.bodies:
        colour = highlight.get(body.name)
        if colour is None:
            colour = (
                OBSTACLE if not body.moving else LEG if body.name.startswith("leg") else MACHINE
            )
        alpha = 0.9 if body.name in highlight else 0.35
        if body.name == "platform" and body.name not in highlight:
            alpha = 0.2  # see the tool and the cone through it
        _draw_body(axes, body, colour, alpha)
    # The base: the polygon of the legs' base ends (where they are at this pose).
    base = np.array([view.body(f"leg {k}").points[0] for k in range(1, 7)])
    axes.plot(*np.transpose(np.vstack([base, base[:1]])), color="0.3", linewidth=1.0)
    for k, end in enumerate(base, start=1):  # leg numbers, as the reports name them
        axes.text(*end, f" {k}", fontsize=9, color="0.1", va="bottom")
    if view.cone is not None:
        axes.add_collection3d(
            Poly3DCollection(
                list(view.cone.triangles()), facecolor=CONE, alpha=0.3, edgecolor="none"
            )
        )
        rim = view.cone.apex + view.cone.length * view.cone.directions
        axes.plot(*np.transpose(np.vstack([rim, rim[:1]])), color=CONE, linewidth=1.0)
    axes.scatter(*view.position, color="black", s=12)
    axes.text(*view.position, "  C", fontsize=8)
    if pair is not None:
        colour = VIOLATED if pair.violated else CLOSEST
        axes.plot(*np.transpose(pair.points), color=colour, linestyle="--", linewidth=1.5)
        axes.scatter(*np.transpose(pair.points), color=colour, s=16)
    for body in view.bodies:
        if not body.moving:
            # beside the body (+x, towards the viewer's right), where the machine seldom is
            side = max(0.5 * float(np.linalg.norm(body.size[:2])), body.radius) + 0.06
            axes.text(
                *(body.centre + np.array([side, 0.0, 0.0])),
                body.name,
                fontsize=8,
                color="0.15",
                ha="left",
                va="center",
            )
    low, high = _extent(view)
    axes.set_xlim(low[0], high[0])
    axes.set_ylim(low[1], high[1])
    axes.set_zlim(low[2], high[2])
    axes.set_box_aspect(tuple(high - low), zoom=1.15)  # one scale on the three axes
    axes.view_init(elev=12.0, azim=-58.0)
    from matplotlib.ticker import MaxNLocator

    for axis in (axes.xaxis, axes.yaxis, axes.zaxis):
        axis.set_major_locator(MaxNLocator(5))  # labels that do not run into each other
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.set_zlabel("z (m)")
    axes.set_title(scene_title(view) if title is None else title, fontsize=9)


def scene_figure(view: SceneView, *, title: str | None = None) -> Any:
    """A :class:`matplotlib.figure.Figure` with the scene and a legend, not saved."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(8.0, 6.8), layout="constrained")
    axes = cast("Axes3D", figure.add_subplot(projection="3d"))
    draw_scene(axes, view, title=title)
    add_legend(figure, view)
    return figure


def add_legend(figure: Any, view: SceneView) -> None:
    """The colour key of :func:`draw_scene` (only what is drawn)."""
    from matplotlib.lines import Line2D

    entries = [(LEG, "legs"), (MACHINE, "platform, tool")]
    if any(not body.moving for body in view.bodies):
        entries.append((OBSTACLE, "obstacles"))
    if view.closest is not None:
        colour = VIOLATED if view.closest.violated else CLOSEST
        entries.append((colour, "pair in violation" if view.closest.violated else "closest pair"))
    if view.cone is not None:
        entries.append((CONE, f"tool directions ({view.cone.method})"))
    handles = [Line2D([], [], color=c, linewidth=6) for c, _ in entries]
    figure.legend(  # below the axes, so it hides no leg label
        handles,
        [label for _, label in entries],
        loc="outside right upper",
        ncols=1,
        fontsize=8,
    )


def plot_scene(view: SceneView, path: str | Path, *, title: str | None = None) -> Path:
    """Write the scene figure to ``path`` (PNG, PDF or SVG by the suffix)."""
    path = Path(path)
    scene_figure(view, title=title).savefig(path, dpi=120, bbox_inches="tight", pad_inches=0.3)
    return path
