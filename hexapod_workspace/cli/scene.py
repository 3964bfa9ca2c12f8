"""``scene``: the machine at one pose, with the tool, the obstacles and the closest pair, drawn.

``hexapod-workspace scene --pose PHI THETA PSI [--position X Y Z] --plot FILE.png`` draws the
scene of ``--config`` at the pose (:mod:`.scene_plot`) and prints the closest pair and its
margin (``--json``: ``closest_pair``, ``constraint``, ``margin_m``). It is a picture: the
verdict of a pose is ``check``'s. Exit 0, 2 on bad input.

The collision scene comes from the file's ``collision.*`` parameters (:func:`config_scene`);
without them the machine is drawn alone (legs, the platform as the polygon of its joints, the
tool axis) with the closest leg pair when ``limits.leg_diameter`` > 0. The cone of attainable
tool directions at the position is drawn unless ``--no-cone`` (``--method``, 72 azimuths).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..core.base.params import load_params_file
from ..core.base.resolution import Method
from ..core.base.rotations import tt_to_matrix
from ..core.cell.frames import cell_from_params_file
from ..core.cell.scene_view import SceneView, cone_of, scene_view
from ..core.model.collision import CollisionScene, collision_scene, require_free_home
from ..core.model.manipulator import Manipulator
from ..core.workspaces.projected import projected_workspace
from ..errors import UnreachableReferenceError
from .inputs import (
    PLOT_FORMATS,
    CliError,
    configured_manipulator,
    finite,
    output_file,
)
from .reports import write_json

__all__ = ["CONE_AZIMUTHS", "cmd_scene", "config_scene", "scene_arguments", "view_at"]

#: Azimuths of the drawn cone of tool directions (every 5°).
CONE_AZIMUTHS = 72

SCENE_HELP = "draw the machine, the tool, the obstacles and the closest pair at one pose"
SCENE_DESCRIPTION = (
    "A 3-D picture of the scene at the pose (phi, theta, psi in degrees) and the position: legs, "
    "platform, tool, the obstacles of collision.* in --config, the closest pair (red when "
    "violated) and the cone of attainable tool directions at the tool centre point. Prints the "
    "closest pair and its margin; the verdict of a pose is check's."
)


def config_scene(config: str | Path | None, manipulator: Manipulator) -> CollisionScene | None:
    """The collision scene of a parameters file (None when it has no ``collision.*``).

    Obstacles given in the work frame are placed with the file's ``work.*`` frame.
    """
    if not config:
        return None
    parameters = load_params_file(config)
    if not any(name.startswith("collision.") for name in parameters):
        return None
    work = cell_from_params_file(config).work
    transform = np.eye(4)
    transform[:3, :3], transform[:3, 3] = work.rotation, work.origin
    return require_free_home(manipulator, collision_scene(parameters, work_transform=transform))


def view_at(
    manipulator: Manipulator,
    angles: Any,
    position: Any,
    scene: CollisionScene | None,
    *,
    cone_method: str | None = Method.TORSION_ZERO.value,
) -> SceneView:
    """The scene at (φ, θ, ψ) (rad) and ``position`` (m), with the cone unless ``cone_method``
    is None or the reference orientation is unreachable there (no cone can be drawn)."""
    position = np.asarray(position, dtype=np.float64)
    cone = None
    if cone_method is not None:
        try:
            workspace = projected_workspace(
                manipulator, position, method=cone_method, n_phi=CONE_AZIMUTHS
            )
            cone = cone_of(workspace, manipulator, scene)
        except UnreachableReferenceError:
            cone = None
    return scene_view(
        manipulator, tt_to_matrix(np.asarray(angles, dtype=float)), position, scene, cone=cone
    )


def scene_arguments(parser: argparse.ArgumentParser) -> None:
    """The ``scene`` command's own options."""
    parser.add_argument(
        "--pose",
        nargs=3,
        type=float,
        default=[0.0, 0.0, 0.0],
        metavar=("PHI", "THETA", "PSI"),
        help="the pose in Tilt-and-Torsion angles, degrees (default: 0 0 0)",
    )
    parser.add_argument(
        "--method",
        choices=[method.value for method in Method],
        default=Method.TORSION_ZERO.value,
        help="projected workspace drawn as the cone of tool directions (default: %(default)s)",
    )
    parser.add_argument("--no-cone", action="store_true", help="do not draw the cone")
    parser.add_argument(
        "--plot",
        metavar="FILE",
        required=True,
        help=f"the picture; FILE ends in {', '.join(PLOT_FORMATS)} and its folder exists",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="replace an existing --plot file even when it is not one of ours",
    )


def cmd_scene(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``scene``: draw the scene at the pose; print the closest pair."""
    from .scene_plot import plot_scene

    plot = output_file(options.plot, "--plot", force=options.force, suffixes=PLOT_FORMATS)
    manipulator = configured_manipulator(options.config, options.position, err)
    angles = np.radians(finite(options.pose, "--pose", "degrees"))
    scene = config_scene(options.config, manipulator)
    try:
        view = view_at(
            manipulator,
            angles,
            manipulator.position,
            scene,
            cone_method=None if options.no_cone else options.method,
        )
    except ValueError as error:  # pragma: no cover - the inputs were validated above
        raise CliError(str(error)) from error
    plot_scene(view, plot)
    pair = view.closest
    document = {
        "position": view.position.tolist(),
        "angles_deg": np.degrees(angles).tolist(),
        "collision_scene": scene is not None,
        "closest_pair": pair.name if pair is not None else None,
        "constraint": pair.constraint if pair is not None else None,
        "margin_m": pair.margin if pair is not None else None,
        "violated": bool(pair.violated) if pair is not None else False,
        "plot": str(plot),
    }
    if options.json:
        write_json(document, out)
        return 0
    if pair is None:
        out.write("no pair checked (no collision scene and limits.leg_diameter is 0)\n")
    else:
        state = "VIOLATED" if pair.violated else "closest pair"
        out.write(
            f"{state}: {pair.name}, margin {1000.0 * pair.margin:.2f} mm ({pair.constraint})\n"
        )
    out.write(f"  plot: {plot}\n")
    return 0


def first_violation(result: Any) -> tuple[str, np.ndarray, np.ndarray] | None:
    """Where a checked path first fails, in path order: (what, angles (3,) rad, position (3,) m).

    ``what`` is ``"waypoint k"`` or ``"move k at s = …"`` (0-based, as the report); None when
    the path runs.
    """
    from ..core.motions.results import reported_parts

    path, _ = reported_parts(result)
    waypoints, segments = path.waypoints, path.segments
    for k in range(len(waypoints.reachable)):
        if not waypoints.reachable[k]:
            why = f"{', '.join(waypoints.violated[k])}, leg {waypoints.limiting_leg[k]}"
            return f"waypoint {k} ({why})", waypoints.angles[k], waypoints.positions[k]
        if k < len(segments) and not segments.ok[k]:
            s = float(segments.first_violation_s[k])
            why = f"{', '.join(segments.violated[k])}, leg {segments.limiting_leg[k]}"
            return (
                f"move {k} at s = {s:.4f} ({why})",
                segments.violation_angles[k],
                segments.violation_positions[k],
            )
    return None


def scene_plot_path(plot: Path) -> Path:
    """The file of the scene at a path's first violation, beside ``plot``: ``NAME-scene.png``."""
    return plot.with_name(f"{plot.stem}-scene{plot.suffix}")


def plot_first_violation(
    result: Any, manipulator: Manipulator, config: str | Path | None, plot: Path, *, force: bool
) -> Path | None:
    """Draw the machine at the first violation of a checked path into
    :func:`scene_plot_path` (``plot``'s name with ``-scene``); None when the path runs."""
    from .scene_plot import plot_scene, scene_title

    where = first_violation(result)
    if where is None:
        return None
    target = output_file(scene_plot_path(plot), "--plot", force=force, suffixes=PLOT_FORMATS)
    what, angles, position = where
    view = view_at(
        manipulator, angles, position, config_scene(config, manipulator), cone_method=None
    )
    return plot_scene(view, target, title=f"first violation: {what}\n{scene_title(view)}")
