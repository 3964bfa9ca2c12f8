"""The loads' limits in the node's verdicts: the rows a pose check carries, and the refusal of
every answer that cannot carry them yet.

With ``limits.actuator_force_max``, ``limits.deflection_max`` or ``limits.accuracy_max`` set
(the node's loads parameters, :mod:`hexapod_workspace.ros.loads`), the pose verdicts
(``~/check_poses`` in both forms, ``~/check_poses_flat``, the commanded poses) carry the rows
those limits set (:func:`~hexapod_workspace.core.evaluation.loads.load_rows`: exact at each
pose), appended after the geometric rows, and a pose is reachable only where they hold too.
The answers that certify more than poses (moves, schedules, workspaces, the atlas, the axis
limits, the cone of tool directions) need the rows' rate bounds, which are not derived yet:
they refuse, naming the limit (:func:`require_geometric`), rather than pass over it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.base.rotations import quaternion_to_matrix, tt_to_matrix
from ..core.evaluation.loads import LoadCase, LoadRows, load_rows
from ..core.model.manipulator import Manipulator
from ..errors import InputError
from .parameters import State

__all__ = [
    "check_poses_with_loads",
    "load_rows_of",
    "require_geometric",
    "tool_case",
    "with_load_rows",
]


def tool_case(state: State) -> LoadCase:
    """The node's loads with the centre of mass in the active tool's frame (the frame of
    ``state.manipulator``'s mobile side), as :func:`loads_at` takes them."""
    if state.cell is None:
        return state.loads
    return state.loads.in_tool_frame(state.cell.tool.offset, state.cell.tool.rotation)


def require_geometric(state: State, what: str) -> Manipulator:
    """``state.manipulator`` for an answer that carries no loads rows, or InputError when the
    node's parameters set a loads limit: ``what`` (a workspace, a move) is not certified with
    the loads' limits yet, and a verdict that passed over them would be for another machine.
    """
    rows = state.loads.limited_rows
    if rows:
        names = ", ".join(_LIMIT_OF[row] for row in rows)
        msg = (
            f"{names}: {what} is not certified with the loads' limits yet (their rate bounds "
            "are not derived); the pose verdicts (~/check_poses, ~/check_poses_flat, commanded "
            "poses) and ~/loads take them (unset the limit for this answer)"
        )
        raise InputError(msg)
    return state.manipulator


#: The parameter of each loads row.
_LIMIT_OF = {
    "actuator_force": "limits.actuator_force_max",
    "deflection": "limits.deflection_max",
    "accuracy": "limits.accuracy_max",
}


def load_rows_of(
    state: State,
    positions: NDArray[np.float64],
    *,
    angles: NDArray[np.float64] | None = None,
    quaternions: NDArray[np.float64] | None = None,
) -> LoadRows | None:
    """The loads rows the node's parameters set at N tool poses, or None when no loads limit
    is set (then nothing is computed: the pose verdicts' path pays nothing without loads).

    Parameters
    ----------
    state : State
    positions : ndarray, shape (N, 3) or (3,)
        Tool centre points, base frame, m.
    angles, quaternions : ndarray, shape (N, 3) or (N, 4)
        The tool frames' orientations, base frame: T&T angles (rad) or quaternions
        ``(x, y, z, w)``; one of the two.
    """
    if not state.loads.limited_rows:
        return None
    if quaternions is not None:
        rotations = quaternion_to_matrix(quaternions)
    else:
        assert angles is not None, "give angles or quaternions"
        rotations = tt_to_matrix(angles)
    return load_rows(state.manipulator, tool_case(state), rotations, positions)


def with_load_rows(checks: list[dict[str, Any]], rows: LoadRows | None) -> list[dict[str, Any]]:
    """PoseCheck fields (one per pose) with the loads rows appended: their names to
    ``constraint_names``, their margins to ``margins``, the violated ones to ``violated``, and
    ``reachable`` only where they hold too. ``rows`` None: ``checks`` unchanged."""
    if rows is None:
        return checks
    names = list(rows.margins)
    values = np.column_stack([rows.margins[name] for name in names]).tolist()
    violated, holds = rows.violated, rows.holds.tolist()
    merged = []
    for k, check in enumerate(checks):
        merged.append(
            {
                **check,
                "constraint_names": [*check["constraint_names"], *names],
                "margins": [*check["margins"], *values[k]],
                "violated": [*check["violated"], *violated[k]],
                "reachable": bool(check["reachable"] and holds[k]),
            }
        )
    return merged


def check_poses_with_loads(fields: dict[str, Any], rows: LoadRows | None) -> dict[str, Any]:
    """``CheckPoses_Response`` fields with the loads rows in every result
    (:func:`with_load_rows`) and the summary recounted; a refusal or ``rows`` None unchanged."""
    if rows is None or not fields.get("success"):
        return fields
    results = with_load_rows(fields["results"], rows)
    held = sum(bool(r["reachable"]) for r in results)
    return {
        **fields,
        "results": results,
        "message": f"{held}/{len(results)} reachable (loads' limits included)",
    }
