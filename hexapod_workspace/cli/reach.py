"""``reach`` and ``axis-limits``: how far the tool can move from a pose along a direction or
along the six axes of a frame (:mod:`hexapod_workspace.core.cell.reach`).

JSON (``--json``):

* ``reach``: ``plus``, ``minus`` (the largest t ≥ 0 in each sense, units of t: the direction is
  used as given), ``limited_by_plus``, ``limited_by_minus`` (constraint names; empty when the
  search bound was reached), ``t_max``, ``start_reachable``, ``frame``, ``position`` (m, in the
  frame), ``pose_deg`` (T&T; a pose given in another convention, ``--angles``, adds ``angles``
  and ``pose_given`` with its own keys, ``u_deg``, ``qx``), ``direction`` ([DX, DY, DZ] m and
  [RX, RY, RZ] rad per unit t), ``tolerance_mm`` and ``tolerance_deg`` (the accuracies of
  ``--tol-mm`` and ``--tol-deg``), ``accuracy_t`` (the step in t they give), ``tool``,
  ``work_frame``.
* ``axis-limits``: ``{"frame": ..., "axes": {"x": {"plus", "minus", "limited_by_plus",
  "limited_by_minus"}, "y", "z", "rx", "ry", "rz"}, ...}`` with translations in m and rotations
  in degrees (magnitudes ≥ 0), about axes through the tool centre point.

Exit codes as for ``check``: 0 the pose is reachable (the limits are given), 1 it is not (both
reaches 0, the violated constraints on stderr), 2 bad input.
"""

from __future__ import annotations

import argparse
import json
import math
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from .._resources import example_config_path
from ..core.cell.frames import (
    CellFrames,
    Tool,
    cell_from_params_file,
    require_plausible_cell,
    tool_model,
    work_to_base,
)
from ..core.cell.reach import (
    AXES,
    DEFAULT_T_MAX,
    DEFAULT_T_MAX_ROTATION,
    DEFAULT_TOL_ROTATION,
    DEFAULT_TOL_TRANSLATION,
    Reach,
    axis_limits,
    reach,
)
from ..core.model.manipulator import Manipulator
from .cam import tool_json, work_json
from .commands import PROG
from .inputs import (
    CliError,
    GivenPoses,
    add_angles_option,
    configured_manipulator,
    finite,
    pose_flag,
    tool_position,
)

__all__ = [
    "AXIS_LIMITS_DESCRIPTION",
    "AXIS_LIMITS_HELP",
    "REACH_DESCRIPTION",
    "REACH_HELP",
    "axis_limits_arguments",
    "cmd_axis_limits",
    "cmd_reach",
    "reach_arguments",
]

REACH_HELP = "how far the tool can move from a pose along a direction (certified)"
REACH_DESCRIPTION = (
    "From the pose (--position, --pose), the pose moves as p(t) = p + t*(DX, DY, DZ) and "
    "R(t) = Rot(t*(RX, RY, RZ))*R (a rotation vector in rad about an axis through the tool "
    "centre point), in the frame given; the largest t >= 0 in each sense before a constraint "
    "is violated, certified like a move of check-path. Exit 0 reachable pose, 1 unreachable, "
    "2 bad input."
)
AXIS_LIMITS_HELP = "the +/- reach along the six axes of a frame (soft limits at a pose)"
AXIS_LIMITS_DESCRIPTION = (
    "Translations along x, y, z (m) and rotations about x, y, z through the tool centre point "
    "(deg) of the base, work or tool frame, from the pose (--position, --pose). Exit 0 "
    "reachable pose, 1 unreachable, 2 bad input."
)


def _common(parser: argparse.ArgumentParser, frames: tuple[str, ...]) -> None:
    parser.add_argument(
        "--pose",
        nargs="+",
        type=float,
        metavar="V",
        help="orientation of the tool: PHI THETA PSI, Tilt-and-Torsion angles, degrees, or the "
        "3 angles (4 quaternion components) of --angles (default: the identity, 0 0 0)",
    )
    add_angles_option(parser)
    parser.add_argument(
        "--frame",
        choices=frames,
        default="base",
        help="frame of --position, --pose and the direction or axes (default: base)",
    )
    parser.add_argument(
        "--tool",
        type=int,
        metavar="N",
        help="the tool of the tool table tools.T<N> (default: tool.*)",
    )
    parser.add_argument(
        "--tol-mm",
        type=float,
        metavar="T",
        help=f"accuracy of the translation limits (and of a direction's translation), mm "
        f"(default {DEFAULT_TOL_TRANSLATION * 1e3:g}), whatever the tool's distance from the "
        "platform joints",
    )
    parser.add_argument(
        "--tol-deg",
        type=float,
        metavar="T",
        help=f"accuracy of the rotation limits (and of a direction's rotation), degrees "
        f"(default {math.degrees(DEFAULT_TOL_ROTATION):g})",
    )


def reach_arguments(parser: argparse.ArgumentParser) -> None:
    """``reach``'s own options."""
    _common(parser, ("base", "work"))
    parser.add_argument(
        "--direction",
        nargs=6,
        type=float,
        required=True,
        metavar=("DX", "DY", "DZ", "RX", "RY", "RZ"),
        help="m and rad per unit t, used as given (not normalised)",
    )
    parser.add_argument(
        "--t-max",
        type=float,
        default=DEFAULT_T_MAX,
        metavar="T",
        help="search bound for t (default %(default)g; t_max*|(RX, RY, RZ)| < pi)",
    )


def axis_limits_arguments(parser: argparse.ArgumentParser) -> None:
    """``axis-limits``' own options."""
    _common(parser, ("base", "work", "tool"))
    parser.add_argument(
        "--max-translation",
        type=float,
        default=DEFAULT_T_MAX,
        metavar="M",
        help="search bound of the translations, m (default %(default)g)",
    )
    parser.add_argument(
        "--max-rotation-deg",
        type=float,
        default=math.degrees(DEFAULT_T_MAX_ROTATION),
        metavar="D",
        help="search bound of the rotations, degrees, below 180 (default %(default)g)",
    )


def _pose(
    options: argparse.Namespace, err: IO[str]
) -> tuple[
    Manipulator,
    CellFrames,
    Tool,
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.float64],
    tuple[float, float],
]:
    """Model (tool frame), cell, tool, rotation and position in the base frame, frame rotation,
    accuracies (m, rad)."""
    platform = configured_manipulator(options.config, None, err, with_tool=False)
    cell = require_plausible_cell(
        platform, cell_from_params_file(options.config or example_config_path())
    )
    tool = cell.tool if options.tool is None else cell.select(options.tool)
    manipulator = tool_model(platform, tool)
    position = tool_position(options.position, manipulator, platform)
    rotation = _given_pose(options).matrices()[0]
    frame_rotation = np.eye(3)
    if options.frame == "work":
        if options.position is None:
            msg = "--frame work: give --position X Y Z in the work frame"
            raise CliError(msg)
        rotation, position = work_to_base(rotation, position, cell.work)
        frame_rotation = cell.work.rotation
    accuracies = (
        _accuracy(options.tol_mm, "--tol-mm", "mm", 1e-3, DEFAULT_TOL_TRANSLATION),
        _accuracy(options.tol_deg, "--tol-deg", "degrees", math.radians(1.0), DEFAULT_TOL_ROTATION),
    )
    return manipulator, cell, tool, rotation, position, frame_rotation, accuracies


def _accuracy(value: float | None, flag: str, unit: str, factor: float, default: float) -> float:
    """An accuracy typed in ``unit``, > 0, in SI (m or rad)."""
    if value is None:
        return default
    number = float(finite([value], flag, unit)[0])
    if not number > 0.0:
        msg = f"{flag}: expected a value > 0 {unit}, got {number:g}"
        raise CliError(msg)
    return number * factor


def _given_pose(options: argparse.Namespace) -> GivenPoses:
    """``--pose`` in the convention of ``--angles`` (default: the identity)."""
    convention = options.angles or "tt"
    if options.pose is None:
        identity = [0.0, 0.0, 0.0, 1.0] if convention == "quaternion" else [0.0, 0.0, 0.0]
        return GivenPoses(convention, np.array([identity]))
    return pose_flag(options.pose, convention)


def _frames_json(options: argparse.Namespace, cell: CellFrames, tool: Tool) -> dict[str, Any]:
    """The pose and frames of the answer: ``pose_deg`` (T&T, as typed for tt) and, for a pose
    given in another convention, ``angles`` and ``pose_given`` (its own keys: ``u_deg``)."""
    given = _given_pose(options)
    document: dict[str, Any] = {
        "frame": options.frame,
        "position": None if options.position is None else list(options.position),
        "pose_deg": given.tt_degrees()[0].tolist(),
    }
    if not given.is_tt:
        document["angles"] = given.convention
        document["pose_given"] = dict(zip(given.keys, given.values[0].tolist(), strict=True))
    return {**document, "tool": tool_json(tool), "work_frame": work_json(cell.work)}


def _pose_line(options: argparse.Namespace, out: IO[str]) -> None:
    """For a pose given in another convention than T&T, one line: as given, then in T&T."""
    given = _given_pose(options)
    if given.is_tt:
        return
    phi, theta, psi = given.tt_degrees()[0].tolist()
    out.write(f"pose: {given.echo()} = phi {phi:.6g}, theta {theta:.6g}, psi {psi:.6g} deg (tt)\n")


def _limits_json(result: Reach, scale: float = 1.0) -> dict[str, Any]:
    return {
        "plus": result.plus * scale,
        "minus": result.minus * scale,
        "limited_by_plus": result.limited_by_plus,
        "limited_by_minus": result.limited_by_minus,
    }


def _unreachable(result: Reach, err: IO[str]) -> int:
    if result.start_reachable:
        return 0
    err.write(f"{PROG}: the pose is unreachable ({', '.join(result.limited_by_plus)})\n")
    return 1


def cmd_reach(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``reach``: the largest steps along ±direction from the pose."""
    manipulator, cell, tool, rotation, position, frame_rotation, accuracy = _pose(options, err)
    direction = finite(options.direction, "--direction", "m and rad")
    t_max = float(finite([options.t_max], "--t-max", "units of t")[0])
    result = reach(
        manipulator,
        rotation,
        position,
        frame_rotation @ direction[:3],
        frame_rotation @ direction[3:],
        t_max=t_max,
        tol_translation=accuracy[0],
        tol_rotation=accuracy[1],
    )
    document = {
        **_limits_json(result),
        "t_max": result.t_max,
        "start_reachable": result.start_reachable,
        "direction": {"translation": direction[:3].tolist(), "rotation": direction[3:].tolist()},
        "tolerance_mm": accuracy[0] * 1e3,
        "tolerance_deg": math.degrees(accuracy[1]),
        "accuracy_t": result.accuracy,
        **_frames_json(options, cell, tool),
    }
    if options.json:
        out.write(json.dumps(document, allow_nan=False) + "\n")
    else:
        _pose_line(options, out)
        for sense in ("plus", "minus"):
            names = document[f"limited_by_{sense}"]
            why = ", ".join(names) if names else f"search bound t_max = {t_max:g} reached"
            out.write(f"{sense:>5}: t = {document[sense]:.6g} ({why})\n")
    return _unreachable(result, err)


def cmd_axis_limits(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``axis-limits``: the ± reach along the six axes of a frame."""
    manipulator, cell, tool, rotation, position, _, accuracy = _pose(options, err)
    t_max = float(finite([options.max_translation], "--max-translation", "m")[0])
    rotation_max = float(finite([options.max_rotation_deg], "--max-rotation-deg", "degrees")[0])
    if not 0.0 < rotation_max < 180.0:
        msg = f"--max-rotation-deg: expected a value in (0, 180) degrees, got {rotation_max:g}"
        raise CliError(msg)
    limits = axis_limits(
        manipulator,
        rotation,
        position,
        frame=options.frame,
        work=cell.work,
        t_max=t_max,
        t_max_rotation=math.radians(rotation_max),
        tol_translation=accuracy[0],
        tol_rotation=accuracy[1],
    )
    document = {
        **_frames_json(options, cell, tool),
        "axes": {
            name: _limits_json(limits[name], 1.0 if k < 3 else math.degrees(1.0))
            for k, name in enumerate(AXES)
        },
        "max_translation": t_max,
        "max_rotation_deg": rotation_max,
        "tolerance_mm": accuracy[0] * 1e3,
        "tolerance_deg": math.degrees(accuracy[1]),
    }
    if options.json:
        out.write(json.dumps(document, allow_nan=False) + "\n")
    else:
        _pose_line(options, out)
        out.write(f"axis limits in the {options.frame} frame (translations m, rotations deg)\n")
        for k, name in enumerate(AXES):
            axis = document["axes"][name]
            unit = "m" if k < 3 else "deg"
            out.write(
                f"  {name:>2}: -{axis['minus']:.5g} .. +{axis['plus']:.5g} {unit}  "
                f"(- {', '.join(axis['limited_by_minus']) or 'bound'}; "
                f"+ {', '.join(axis['limited_by_plus']) or 'bound'})\n"
            )
    return _unreachable(limits["x"], err)
