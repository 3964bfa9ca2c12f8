"""Certified checks of waypoints and toolpaths (fixed orientations at every waypoint).

The certificate is :mod:`hexapod_workspace.core.motions.certificate`; the interpolations are those
of
:mod:`hexapod_workspace.core.motions.interpolation`.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import ResolutionError
from ..base.rotations import matrix_to_tt, tt_to_matrix
from ..constraints.table import COLLISION, SINGULARITY, applicable
from ..evaluation.check import (
    CONSTRAINT_NAMES,
    PoseMargins,
    collision_pair_names,
    pose_margins,
    relative_margins,
)
from ..model.manipulator import Manipulator
from .certificate import (
    DEFAULT_MAX_SAMPLE_ANGLE,
    DEFAULT_PATH_TOLERANCE,
    _Certifier,
    _check_moves,
    _MoveCheck,
)
from .interpolation import (
    _Moves,
    _orientations,
    _validate_curves,
    _validate_interpolation,
    _validate_positions,
    _validate_tolerance,
)
from .results import PathCheck, SegmentChecks, TorsionPlan, WaypointChecks

__all__ = ["check_path", "check_waypoints", "report_singularity"]


def _waypoint_checks(
    certifier: _Certifier, positions: NDArray[np.float64], rotations: NDArray[np.float64]
) -> tuple[WaypointChecks, PoseMargins]:
    found = certifier.margins(rotations, positions)
    relative = relative_margins(certifier.manipulator, found.margins)
    limiting = np.argmin(np.where(np.isnan(relative), -np.inf, relative), axis=0)
    columns = np.arange(positions.shape[0])
    enabled = certifier.manipulator.leg_diameter > 0.0
    result = WaypointChecks(
        positions=positions,
        angles=matrix_to_tt(rotations),
        reachable=found.reachable,
        margins={CONSTRAINT_NAMES[k]: found.margins[k] for k in applicable(certifier.manipulator)},
        relative=certifier.relative(found.margins),
        limiting_constraint=limiting,
        limiting_leg=np.where(limiting == COLLISION, 0, found.limiting_legs[limiting, columns] + 1),
        limiting_pair=found.limiting_pairs + 1 if enabled else found.limiting_pairs,
        collision_pair=_pair_names(certifier.manipulator, found.limiting_legs[COLLISION]),
    )
    return result, found


def _pair_names(manipulator: Manipulator, pairs: NDArray[np.int64]) -> tuple[str, ...]:
    """Names of 0-based collision pair indices (−1: none); () when the model has no scene."""
    names = collision_pair_names(manipulator)
    if not names:
        return ()
    return tuple(names[k] if k >= 0 else "" for k in pairs.tolist())


def check_waypoints(
    manipulator: Manipulator,
    positions: ArrayLike,
    *,
    angles: ArrayLike | None = None,
    quaternions: ArrayLike | None = None,
    rotations: ArrayLike | None = None,
) -> WaypointChecks:
    """Check N poses, each at its own position (what ROS poses are), without the moves.

    Parameters are those of :func:`check_path` (N ≥ 1).

    Returns
    -------
    WaypointChecks

    Raises
    ------
    InputError
        As :func:`check_path`.
    """
    positions = _validate_positions(positions, minimum=1)
    matrices = _orientations(positions.shape[0], angles, quaternions, rotations)
    return _waypoint_checks(_Certifier(manipulator), positions, matrices)[0]


def check_path(
    manipulator: Manipulator,
    positions: ArrayLike,
    *,
    angles: ArrayLike | None = None,
    quaternions: ArrayLike | None = None,
    rotations: ArrayLike | None = None,
    interpolation: str = "slerp",
    tolerance: float = DEFAULT_PATH_TOLERANCE,
    max_sample_angle: float = DEFAULT_MAX_SAMPLE_ANGLE,
    arcs: ArrayLike | None = None,
    beziers: ArrayLike | None = None,
) -> PathCheck:
    """Check a path of N waypoints and the N − 1 moves between them, certified.

    Parameters
    ----------
    manipulator : Manipulator
    positions : array_like, shape (N, 3)
        Tool-tip positions OC, base frame, m (N ≥ 2).
    angles : array_like, shape (N, 3), optional
        Orientations as T&T angles (φ, θ, ψ), rad (any finite values; reduced first).
    quaternions : array_like, shape (N, 4), optional
        Orientations as quaternions (x, y, z, w), any non-zero norm.
    rotations : array_like, shape (N, 3, 3), optional
        Orientations as rotation matrices (mobile frame in base frame).
        Exactly one of ``angles``, ``quaternions``, ``rotations`` is given.
    interpolation : {"slerp", "tilt-torsion"}
        Orientation between waypoints (see the module documentation).
    tolerance : float
        Width (rad of platform rotation, or ρ·tolerance of joint travel) below which a violated
        band may be missed; also the accuracy of the first violation. 1e-9 to 0.1.
    max_sample_angle : float
        Largest motion (rad-equivalent) between poses evaluated for the sampled minimum margin.
    arcs : array_like, shape (N − 1, 7), optional
        Moves that are arcs (CAM's ``CIRCLE``): per move, centre (m, base frame), axis and
        angle φ (rad, right-handed about the axis); a row of NaN for a straight move
        (:mod:`~hexapod_workspace.core.motions.interpolation`). None: every move is straight.
    beziers : array_like, shape (N − 1, 6), optional
        Moves that are cubic Bézier curves (CAM's NURBS spans): per move, the inner control
        points b₁, b₂ (m, base frame; the ends are the waypoints); a row of NaN for another
        move (:mod:`~hexapod_workspace.core.motions.interpolation`). None: none is.

    Returns
    -------
    PathCheck
        Unreachable poses and moves are results, not exceptions.

    Raises
    ------
    InputError
        Wrong shapes, fewer than 2 waypoints, NaN/infinite or absurd values, zero quaternions,
        non-rotation matrices, unknown interpolation.
    """
    started = time.perf_counter()
    positions = _validate_positions(positions)
    matrices = _orientations(positions.shape[0], angles, quaternions, rotations)
    interpolation = _validate_interpolation(interpolation)
    tolerance = _validate_tolerance(tolerance)
    if not (math.isfinite(max_sample_angle) and max_sample_angle >= tolerance):
        msg = f"max_sample_angle: expected a finite value >= tolerance, got {max_sample_angle!r}"
        raise ResolutionError(msg)
    circles = _validate_curves(arcs, beziers, positions)
    certifier = _Certifier(manipulator)
    waypoints, found = _waypoint_checks(certifier, positions, matrices)
    moves = _Moves(
        positions[:-1],
        positions[1:],
        matrices[:-1],
        matrices[1:],
        interpolation,
        certifier.rho,
        arcs=circles,
    )
    raw = _check_moves(
        certifier,
        moves,
        found.margins[:, :-1],
        found.margins[:, 1:],
        tolerance,
        max_sample_angle,
        (found.limiting_legs[:, :-1], found.limiting_pairs[:-1]),
        (found.limiting_legs[:, 1:], found.limiting_pairs[1:]),
    )
    segments = _segment_checks(certifier, moves, raw)
    return PathCheck(
        waypoints=waypoints,
        segments=segments,
        interpolation=interpolation,
        tolerance=tolerance,
        elapsed=time.perf_counter() - started,
        arcs=_some_rows(arcs),
        beziers=_some_rows(beziers),
    )


def _some_rows(rows: ArrayLike | None) -> NDArray[np.float64] | None:
    """Validated curve rows as given, or None when none is a curve (all NaN, or not given)."""
    if rows is None:
        return None
    array = np.array(rows, dtype=np.float64)
    return array if bool(np.isfinite(array[:, 0]).any()) else None


def _segment_checks(certifier: _Certifier, moves: _Moves, raw: _MoveCheck) -> SegmentChecks:
    """Per-move results from the raw check: violation pose, limiting constraint and leg."""
    count = raw.ok.shape[0]
    samples = raw.samples
    # The pose that names the limiting constraint: first violation, else the smallest margin.
    rows = np.where(raw.ok, raw.min_index, raw.bad_index)
    margins = samples["margins"][:, rows]
    relative = relative_margins(certifier.manipulator, margins)
    limiting = np.argmin(np.where(np.isnan(relative), -np.inf, relative), axis=0)
    legs = np.where(limiting == COLLISION, 0, samples["legs"][limiting, rows] + 1)
    enabled = certifier.manipulator.leg_diameter > 0.0
    pairs = samples["pairs"][rows] + 1 if enabled else np.zeros((count, 2), dtype=np.int64)
    s_bad = np.where(raw.ok, 0.0, raw.first_bad)
    rotations, positions = moves.poses(np.arange(count), s_bad)
    angles = matrix_to_tt(rotations)
    nan_rows = raw.ok
    angles[nan_rows] = np.nan
    positions[nan_rows] = np.nan
    violation_margins = np.where(nan_rows[None, :], np.nan, margins)
    return SegmentChecks(
        ok=raw.ok,
        first_violation_s=raw.first_bad,
        violation_angles=angles,
        violation_positions=positions,
        violation_margins=violation_margins,
        limiting_constraint=limiting,
        limiting_leg=legs,
        limiting_pair=pairs,
        min_relative_margin=raw.min_value,
        min_at_s=raw.min_s,
        min_relative_margin_bound=raw.bound,
        angular_rate=moves.omega,
        translation=moves.translation,
        evaluations=raw.evaluations,
        collision_pair=_pair_names(certifier.manipulator, samples["legs"][COLLISION, rows]),
    )


def report_singularity(
    manipulator: Manipulator, result: PathCheck | TorsionPlan
) -> PathCheck | TorsionPlan:
    """The same result with the singularity margin of every waypoint evaluated, as
    :func:`~hexapod_workspace.core.evaluation.check.check` reports it with ``singularity=True``.

    With ``limits.singularity_min`` > 0 the margin is enforced and already evaluated: the result
    is returned as it is. At 0 it is a report only: it never limits, so the verdicts, relative
    margins and limiting constraints stay; the moves are not searched for its minimum.

    Parameters
    ----------
    manipulator : Manipulator
        The model the result was computed with.
    result : PathCheck or TorsionPlan
        A path check, or a torsion plan (its path and its ψ = 0 baseline).

    Returns
    -------
    PathCheck or TorsionPlan
    """
    if manipulator.singularity_min > 0.0:
        return result
    if isinstance(result, TorsionPlan):
        path = None if result.path is None else _with_singularity(manipulator, result.path)
        return replace(result, path=path, baseline=_with_singularity(manipulator, result.baseline))
    return _with_singularity(manipulator, result)


def _with_singularity(manipulator: Manipulator, path: PathCheck) -> PathCheck:
    waypoints = path.waypoints
    if len(waypoints) == 0:
        return path
    found = pose_margins(
        manipulator,
        tt_to_matrix(waypoints.angles),
        waypoints.positions,
        interference=False,
        singularity=True,
    )
    margins = dict(waypoints.margins)
    margins[CONSTRAINT_NAMES[SINGULARITY]] = found.margins[SINGULARITY]
    return replace(path, waypoints=replace(waypoints, margins=margins))
