"""Reach along a direction of the pose space, and the ± limits along the six axes of a frame.

From a pose (p, R) the pose moves along a direction (d, r) of the six-dimensional pose space as

    p(t) = p + t·d,      R(t) = Rot(t·r)·R,

(d in m per unit t, r a rotation vector in rad per unit t, base frame; the rotation is about an
axis through the tool centre point, since p does not move with it). For t·|r| < π this is
exactly the slerp move from (p, R) to (p(T), R(T)) (the rotation R(T)·Rᵀ = Rot(T·r) is the
shortest one, about the fixed axis r, at a constant rate), so the reach is certified by the
move certificate of :func:`hexapod_workspace.check_path`:

1. check the move from t = 0 to the search bound T; if it is ok the reach is T (the bound was
   reached, nothing limits it);
2. otherwise the check returns a violated pose at t₁ = s₁·T, and every interval before it is
   certified or narrower than its step ``h`` (in t: ``tol / (|r| + |d|/ρ)``, ρ = max|b_i|): the
   candidate reach is t₁ − h, and the move from 0 to it is checked again (its own violation, if
   any, gives a smaller candidate), until a check is ok.

The step ``h`` is the accuracy of the reach in t. It is chosen from tolerances in the units of
the motion, not from an angle of the platform: ``h = min(tol_translation / |d|,
tol_rotation / |r|)`` (m and rad), and the move certificate's tolerance is set to
``h·(|r| + |d|/ρ)`` so that its step is exactly ``h``. So a translation limit is within
``tol_translation`` (default 0.01 mm) of the boundary and a rotation limit within
``tol_rotation`` (default 0.001°) whatever the distance ρ from the tool centre point to the
platform joints (an angle tolerance of the platform would give ρ times it in a translation:
0.47 mm for 0.01° at 2.7 m).

So the move from the pose to the reported reach holds (certified to the tolerance), and the pose
t₁ just beyond it (within ``h`` plus the tolerance) violates the constraints named in
``limited_by``. A start pose that is itself unreachable has reach 0, limited by its violated
constraints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError
from ..base.rotations import matrix_to_tt
from ..evaluation.check import check
from ..model.manipulator import Manipulator
from ..motions import check_path
from .frames import WorkFrame

__all__ = [
    "AXES",
    "DEFAULT_TOL_ROTATION",
    "DEFAULT_TOL_TRANSLATION",
    "DEFAULT_T_MAX",
    "DEFAULT_T_MAX_ROTATION",
    "Reach",
    "axis_limits",
    "reach",
    "rotation_vector_matrix",
]

#: Default search bound of :func:`reach` (units of t: m for a unit translation, rad for a unit
#: rotation).
DEFAULT_T_MAX = 1.0
#: Default search bound of the rotation axes in :func:`axis_limits`, rad (90°).
DEFAULT_T_MAX_ROTATION = math.pi / 2.0
#: The six axes of a frame, in order: translations along x, y, z, rotations about x, y, z.
AXES = ("x", "y", "z", "rx", "ry", "rz")
#: Re-checks after the first violation (each moves the candidate below a found violation).
MAX_RETRIES = 30
#: Default accuracy of a translation limit, m (0.01 mm).
DEFAULT_TOL_TRANSLATION = 1e-5
#: Default accuracy of a rotation limit, rad (0.001°).
DEFAULT_TOL_ROTATION = math.radians(0.001)
#: The move certificate's tolerance range, rad (:func:`hexapod_workspace.check_path`).
_PATH_TOLERANCE_RANGE = (1e-9, 0.1)


@dataclass(frozen=True)
class Reach:
    """The largest steps along ±(d, r) before a constraint is violated.

    Attributes
    ----------
    plus, minus : float
        Largest t ≥ 0 in each sense (units of t), certified to the tolerance.
    limited_by_plus, limited_by_minus : list of str
        Constraints violated just beyond it (empty: the search bound ``t_max`` was reached).
    t_max : float
        The search bound.
    start_reachable : bool
        The pose itself is reachable (if not, both reaches are 0).
    tolerance : float
        rad of platform rotation, the move certificate's (:func:`hexapod_workspace.check_path`).
    accuracy : float
        The step h in units of t: the boundary lies within ``plus + accuracy`` (likewise minus).
    """

    plus: float
    minus: float
    limited_by_plus: list[str]
    limited_by_minus: list[str]
    t_max: float
    start_reachable: bool
    tolerance: float
    accuracy: float = math.nan


def rotation_vector_matrix(vector: ArrayLike) -> NDArray[np.float64]:
    """Rot(r): the rotation by |r| rad about r/|r| (Rodrigues' formula), shape (3, 3)."""
    r = np.asarray(vector, dtype=np.float64)
    angle = float(np.linalg.norm(r))
    if angle == 0.0:
        return np.eye(3)
    x, y, z = r / angle
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    matrix: NDArray[np.float64] = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
    return matrix


def _vector(name: str, value: ArrayLike) -> NDArray[np.float64]:
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        msg = f"{name}: expected 3 finite numbers, got {np.asarray(value).tolist()}"
        raise InputError(msg)
    return array


def _one_sense(
    manipulator: Manipulator,
    rotation: NDArray[np.float64],
    position: NDArray[np.float64],
    translation: NDArray[np.float64],
    turn: NDArray[np.float64],
    t_max: float,
    tolerance: float,
    step: float,
) -> tuple[float, list[str]]:
    t_end = t_max
    limited: list[str] = []
    for _ in range(MAX_RETRIES):
        if t_end <= 0.0:
            return 0.0, limited
        end_rotation = rotation_vector_matrix(t_end * turn) @ rotation
        result = check_path(
            manipulator,
            [position, position + t_end * translation],
            rotations=[rotation, end_rotation],
            tolerance=tolerance,
        )
        if bool(result.segments.ok[0]):
            return t_end, limited
        first = float(result.segments.first_violation_s[0])
        limited = result.segments.violated[0] or limited
        t_end = t_end * first - step
    return 0.0, limited


def reach(
    manipulator: Manipulator,
    rotation: ArrayLike,
    position: ArrayLike,
    translation: ArrayLike,
    turn: ArrayLike,
    *,
    t_max: float = DEFAULT_T_MAX,
    tolerance: float | None = None,
    tol_translation: float = DEFAULT_TOL_TRANSLATION,
    tol_rotation: float = DEFAULT_TOL_ROTATION,
) -> Reach:
    """Largest steps from a pose along ±(d, r) (see the module documentation).

    Parameters
    ----------
    manipulator : Manipulator
        In the frame of the poses (a tool model for tool-frame poses).
    rotation : array_like, shape (3, 3)
        R, base frame.
    position : array_like, shape (3,)
        p, base frame, m.
    translation : array_like, shape (3,)
        d, base frame, m per unit t.
    turn : array_like, shape (3,)
        r, rotation vector, base frame, rad per unit t (about an axis through p).
    t_max : float
        Search bound, > 0, with t_max·|r| < π.
    tolerance : float, optional
        An upper bound of the move certificate's tolerance, rad (default: the one the
        accuracies below need).
    tol_translation : float
        Accuracy of the reach in the translation, m (> 0): the boundary lies within
        ``tol_translation / |d|`` in t of the reach.
    tol_rotation : float
        Accuracy of the reach in the rotation, rad (> 0): within ``tol_rotation / |r|`` in t.

    Returns
    -------
    Reach

    Raises
    ------
    InputError
        Non-finite values, a zero direction, a bad search bound or accuracy.
    """
    rotation = np.asarray(rotation, dtype=np.float64)
    if rotation.shape != (3, 3) or not np.all(np.isfinite(rotation)):
        msg = f"rotation: expected a finite 3x3 matrix, got shape {rotation.shape}"
        raise InputError(msg)
    position = _vector("position", position)
    translation = _vector("direction (translation)", translation)
    turn = _vector("direction (rotation)", turn)
    if not (np.any(translation) or np.any(turn)):
        msg = "direction: expected a non-zero direction (DX, DY, DZ, RX, RY, RZ), got all zeros"
        raise InputError(msg)
    if not (math.isfinite(t_max) and t_max > 0.0):
        msg = f"t_max: expected a finite value > 0, got {t_max!r}"
        raise InputError(msg)
    if t_max * float(np.linalg.norm(turn)) >= math.pi:
        msg = (
            f"t_max: expected t_max·|r| < pi (a rotation below 180 deg), got "
            f"{t_max:g}·{float(np.linalg.norm(turn)):g}"
        )
        raise InputError(msg)
    for name, value in (("tol_translation", tol_translation), ("tol_rotation", tol_rotation)):
        if not (math.isfinite(value) and value > 0.0):
            msg = f"{name}: expected a finite value > 0, got {value!r}"
            raise InputError(msg)
    speed, spin = float(np.linalg.norm(translation)), float(np.linalg.norm(turn))
    step = min(
        tol_translation / speed if speed else math.inf, tol_rotation / spin if spin else math.inf
    )
    rho = float(np.max(np.linalg.norm(manipulator.platform_joints, axis=1))) or 1.0
    low, high = _PATH_TOLERANCE_RANGE
    path_tolerance = min(step * (spin + speed / rho), high if tolerance is None else tolerance)
    path_tolerance = max(path_tolerance, low)
    step = min(step, path_tolerance / (spin + speed / rho))  # the certificate's own step
    start = check(manipulator, matrix_to_tt(rotation), position)
    if not bool(start.reachable[0]):
        violated = start.violated[0]
        return Reach(0.0, 0.0, violated, list(violated), t_max, False, path_tolerance, step)
    plus = _one_sense(
        manipulator, rotation, position, translation, turn, t_max, path_tolerance, step
    )
    minus = _one_sense(
        manipulator, rotation, position, -translation, -turn, t_max, path_tolerance, step
    )
    return Reach(plus[0], minus[0], plus[1], minus[1], t_max, True, path_tolerance, step)


def axis_limits(
    manipulator: Manipulator,
    rotation: ArrayLike,
    position: ArrayLike,
    *,
    frame: str = "base",
    work: WorkFrame | None = None,
    t_max: float = DEFAULT_T_MAX,
    t_max_rotation: float = DEFAULT_T_MAX_ROTATION,
    tolerance: float | None = None,
    tol_translation: float = DEFAULT_TOL_TRANSLATION,
    tol_rotation: float = DEFAULT_TOL_ROTATION,
) -> dict[str, Reach]:
    """The ± reach along the six axes of a frame at a pose.

    Parameters
    ----------
    manipulator : Manipulator
    rotation : array_like, shape (3, 3)
        R of the tool frame, base frame.
    position : array_like, shape (3,)
        Tool centre point, base frame, m.
    frame : {"base", "work", "tool"}
        Whose axes: the base frame's, the work frame's (``work`` required) or the tool frame's
        at this pose (the columns of R).
    t_max : float
        Search bound of the translations, m.
    t_max_rotation : float
        Search bound of the rotations, rad (< π).
    tolerance : float, optional
        rad, as for :func:`reach`.
    tol_translation : float
        Accuracy of the translation limits, m (default 0.01 mm).
    tol_rotation : float
        Accuracy of the rotation limits, rad (default 0.001°).

    Returns
    -------
    dict of str to Reach
        Keys :data:`AXES`; translations in m, rotations (about axes through the tool centre
        point) in rad.
    """
    rotation = np.asarray(rotation, dtype=np.float64)
    if frame == "base":
        axes = np.eye(3)
    elif frame == "work":
        if work is None:
            msg = "frame 'work': expected a work frame"
            raise InputError(msg)
        axes = work.rotation
    elif frame == "tool":
        axes = rotation
    else:
        msg = f"frame: expected base, work or tool, got {frame!r}"
        raise InputError(msg)
    zero = np.zeros(3)
    limits = {}
    for k, name in enumerate(AXES):
        unit = axes[:, k % 3]
        if k < 3:
            limits[name] = reach(
                manipulator,
                rotation,
                position,
                unit,
                zero,
                t_max=t_max,
                tolerance=tolerance,
                tol_translation=tol_translation,
                tol_rotation=tol_rotation,
            )
        else:
            limits[name] = reach(
                manipulator,
                rotation,
                position,
                zero,
                unit,
                t_max=t_max_rotation,
                tolerance=tolerance,
                tol_translation=tol_translation,
                tol_rotation=tol_rotation,
            )
    return limits
