"""``~/check_poses_flat``: the batch pose check in flat arrays (``CheckPosesFlat.srv``).

The nested ``~/check_poses`` builds and (de)serialises one ``PoseCheck`` message per pose: about
10 µs a pose in rclpy, a hundred times the compiled check itself. This form carries the same
verdicts in a handful of arrays: the request's angles as one ``float64[]`` (N × 3, row-major),
the answer's margins as one ``float64[]`` (N × K, row-major) with the K constraint names once
(``constraint_names``: the rows of :data:`hexapod_workspace.core.evaluation.check.CONSTRAINT_NAMES`
that apply to the model, never counted here), ``reachable`` and ``limiting_leg`` one value per
pose. The arrays go in and out of the messages as numpy buffers (``array.array`` for rclpy),
with no Python loop per pose.
Requests and answers are recorded like the other services' (``<service>/request`` and
``/response``, as the message twins ``CheckPosesFlatRequest``/``CheckPosesFlatResponse``).
The position and angles are in the frame ``header.frame_id`` names (base or work,
:mod:`~hexapod_workspace.ros.cell`); the answer's ``frames`` says which tool and work frame.
"""

from __future__ import annotations

import array
from collections.abc import Sequence
from typing import Any

import numpy as np
from hexapod_workspace_msgs.srv import CheckPosesFlat
from numpy.typing import NDArray

from hexapod_workspace.core.constraints.table import constraint_names
from hexapod_workspace.core.evaluation.check import CONSTRAINT_NAMES, CheckResult, check
from hexapod_workspace.core.evaluation.loads import LoadRows
from hexapod_workspace.errors import InputError

from .cell import angles_to_base, frames_message
from .conversions import position_from_point
from .load_rows import load_rows_of

__all__ = ["angles_from_flat", "attach", "flat_margins", "flat_response"]


def angles_from_flat(values: Any, max_poses: int) -> NDArray[np.float64]:
    """The poses of a flat request: T&T angles, shape (N, 3), rad.

    Parameters
    ----------
    values : array.array('d') or array_like, shape (3 N,)
        ``phi_1, theta_1, psi_1, phi_2, ...`` (a view is taken, not a copy, of an ``array``).
    max_poses : int
        Most poses accepted (``check.max_poses``).

    Raises
    ------
    InputError
        No pose, a length that is not a multiple of 3, or more than ``max_poses`` poses (the
        core refuses NaN/inf values itself).
    """
    if isinstance(values, array.array):
        flat = np.frombuffer(values, dtype=np.float64) if len(values) else np.zeros(0)
    else:
        flat = np.asarray(values, dtype=np.float64).reshape(-1)
    if flat.size == 0:
        msg = "angles: expected at least one pose (phi, theta, psi), got none"
        raise InputError(msg)
    if flat.size % 3:
        msg = f"angles: expected 3 values per pose (phi, theta, psi), got {flat.size} values"
        raise InputError(msg)
    count = flat.size // 3
    if count > max_poses:
        msg = f"angles: at most {max_poses} poses per request (check.max_poses), got {count}"
        raise InputError(msg)
    return flat.reshape(count, 3)


def flat_margins(result: CheckResult) -> NDArray[np.float64]:
    """Margins of ``result``, shape (N, K): column k is constraint ``list(result.margins)[k]``
    (the constraints of the model's leg architecture, in table order)."""
    return np.column_stack([np.asarray(values) for values in result.margins.values()])


def _doubles(values: NDArray[Any]) -> array.array:
    out = array.array("d")
    out.frombytes(np.ascontiguousarray(values, dtype=np.float64).tobytes())
    return out


def _int32s(values: NDArray[Any]) -> array.array:
    out = array.array("i")
    out.frombytes(np.ascontiguousarray(values, dtype=np.int32).tobytes())
    return out


def flat_response(
    result: CheckResult | None,
    *,
    message: str | None = None,
    names: Sequence[str] = CONSTRAINT_NAMES,
    loads: LoadRows | None = None,
) -> CheckPosesFlat.Response:
    """The answer to a flat request: the verdicts of ``result``, or a refusal (``result`` None,
    ``message`` the reason; every array empty, ``constraint_names`` still given: ``names``, the
    model's). ``loads``: the loads rows of the same poses, appended as columns after the
    geometric rows (:mod:`~hexapod_workspace.ros.load_rows`); a pose is reachable only where
    they hold too."""
    names = list(result.margins) if result is not None else list(names)
    if result is not None and loads is not None:
        names += list(loads.margins)
    response = CheckPosesFlat.Response(constraint_names=names)
    if result is None:
        response.success = False
        response.message = message or "request failed"
        return response
    reachable = np.asarray(result.reachable, dtype=bool)
    margins = flat_margins(result)
    suffix = ""
    if loads is not None:
        reachable = reachable & loads.holds
        margins = np.column_stack([margins, *loads.margins.values()])
        suffix = " (loads' limits included)"
    response.success = True
    response.message = f"{int(np.count_nonzero(reachable))}/{reachable.size} reachable{suffix}"
    response.margins = _doubles(margins.reshape(-1))
    response.reachable = reachable.tolist()
    response.limiting_leg = _int32s(np.asarray(result.limiting_leg))
    if "collision" in result.margins:  # a scene: one pair per pose (none: empty, no cost)
        response.collision_pair = result.collision_pair
    return response


def attach(node: Any, name: str) -> Any:
    """Serve (and record) the flat check as ``name`` (``~/check_poses_flat``) on ``node``, in
    its check callback group."""

    def on_check(
        request: CheckPosesFlat.Request, response: CheckPosesFlat.Response
    ) -> CheckPosesFlat.Response:
        node.stats.check_calls += 1
        state = node.state
        names = constraint_names(state.manipulator)
        try:
            angles, position = angles_to_base(
                state,
                request.header.frame_id,
                angles_from_flat(request.angles, state.settings.max_poses),
                position_from_point(request.position),
            )
            answer = flat_response(
                check(
                    state.manipulator,
                    angles,
                    position,
                    singularity=state.settings.report_singularity,
                ),
                loads=load_rows_of(state, position, angles=angles),
            )
        except InputError as error:
            answer = flat_response(None, message=str(error), names=names)
        except Exception as error:  # a bug: answered, never silence
            answer = flat_response(None, message=node.internal_error(error), names=names)
        if not answer.success:
            node.stats.check_refused += 1
        if state is not None:
            answer.frames = frames_message(state, request.header.frame_id)
        return answer

    return node.recorded_service(CheckPosesFlat, name, on_check, node.check_group)
