"""The single mapping from core results to ROS message fields, ROS-free.

Every function returns plain nested dicts keyed by the ROS field names of the message named in
its docstring (nested messages are dicts, message arrays lists of dicts, ``uint8[]`` is
``bytes``, numeric arrays numpy arrays). The node fills rclpy messages from them; the CLI's
``--record`` builds rosbags messages from them (:func:`hexapod_workspace.logs.fields.serialize`);
replay reads recorded messages back with the inverse helpers at the end of this module.

Units are SI (m, rad) as everywhere in the package. Stamps are ns since the epoch.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from ..core.base.resolution import WorkspaceKind
from ..core.base.rotations import approach_vector
from ..core.workspaces.orientation import OrientationWorkspace
from ..core.workspaces.projected import ProjectedWorkspace
from .interfaces import TOPICS, TYPES

if TYPE_CHECKING:
    from numpy.typing import ArrayLike, NDArray

    from hexapod_workspace.core.evaluation.check import CheckResult

__all__ = [
    "POINT_FIELD_NAMES",
    "TOPICS",
    "TYPES",
    "boundary_points",
    "check_poses_request_fields",
    "check_poses_response_fields",
    "commanded_pose_fields",
    "compute_workspace_request_fields",
    "compute_workspace_response_fields",
    "header_fields",
    "no_cell_frames_fields",
    "point_fields",
    "pointcloud_fields",
    "pointcloud_to_array",
    "pose_check_fields",
    "pose_checks_fields",
    "reachability_result_fields",
    "stamp_fields",
    "stamp_to_ns",
    "summary_fields",
    "summary_line",
    "tilt_torsion_fields",
    "workspace_kind",
    "workspace_request_fields",
]

#: PointCloud2 fields of a boundary cloud, all float32, in this order (point_step 24 bytes).
POINT_FIELD_NAMES = ("x", "y", "z", "phi", "theta", "psi")
_FLOAT32 = 7  # sensor_msgs/PointField.FLOAT32
_FLOAT64 = 8  # sensor_msgs/PointField.FLOAT64

# --------------------------------------------------------------------------- small pieces


def stamp_fields(stamp_ns: int) -> dict[str, int]:
    """builtin_interfaces/msg/Time from ns since the epoch."""
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    return {"sec": sec, "nanosec": nanosec}


def stamp_to_ns(stamp: Any) -> int:
    """ns since the epoch from a Time dict or message (``sec``, ``nanosec``)."""
    sec, nanosec = _get(stamp, "sec"), _get(stamp, "nanosec")
    return int(sec) * 1_000_000_000 + int(nanosec)


def header_fields(stamp_ns: int, frame_id: str) -> dict[str, Any]:
    """std_msgs/msg/Header."""
    return {"stamp": stamp_fields(stamp_ns), "frame_id": str(frame_id)}


def point_fields(position: ArrayLike) -> dict[str, float]:
    """geometry_msgs/msg/Point from a (3,) position, m."""
    x, y, z = (float(v) for v in np.asarray(position, dtype=float).reshape(3))
    return {"x": x, "y": y, "z": z}


def tilt_torsion_fields(angles: ArrayLike) -> dict[str, float]:
    """hexapod_workspace_msgs/msg/TiltTorsion from (φ, θ, ψ), rad."""
    phi, theta, psi = (float(v) for v in np.asarray(angles, dtype=float).reshape(3))
    return {"phi": phi, "theta": theta, "psi": psi}


def identity_pose_fields() -> dict[str, Any]:
    """geometry_msgs/msg/Pose at the origin with the identity orientation (w = 1)."""
    return {
        "position": {"x": 0.0, "y": 0.0, "z": 0.0},
        "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
    }


def unchecked_motion_fields() -> dict[str, Any]:
    """hexapod_workspace_msgs/msg/PathSegmentCheck of a move that was not checked (NaN)."""
    nan = math.nan
    return {
        "ok": False,
        "first_violation_s": nan,
        "position_at_violation": {"x": nan, "y": nan, "z": nan},
        "pose_at_violation": {"phi": nan, "theta": nan, "psi": nan},
        "violated": [],
        "limiting_leg": 0,
        "limiting_pair": [],
        "min_relative_margin": nan,
        "min_at_s": nan,
        "min_relative_margin_bound": nan,
        "collision_pair": "",
    }


# --------------------------------------------------------------------------- pose checks


def pose_check_fields(result: CheckResult, index: int) -> dict[str, Any]:
    """hexapod_workspace_msgs/msg/PoseCheck of pose ``index`` of a check result."""
    margins = result.margins
    return {
        "reachable": bool(result.reachable[index]),
        "violated": list(result.violated[index]),
        "constraint_names": list(margins),
        "margins": [float(values[index]) for values in margins.values()],
        "limiting_leg": int(result.limiting_leg[index]),
        "collision_pair": result.collision_pair[index],
    }


class PoseChecks(Protocol):
    """What the PoseCheck fields are read from: a :class:`CheckResult` (one position), or the
    ``WaypointChecks`` of a path (one position per pose). Arrays have shape (N,)."""

    @property
    def reachable(self) -> NDArray[np.bool_]: ...

    @property
    def margins(self) -> Mapping[str, NDArray[np.float64]]: ...

    @property
    def limiting_leg(self) -> NDArray[np.int64]: ...

    @property
    def violated(self) -> list[list[str]]: ...

    @property
    def collision_pair(self) -> Sequence[str]: ...

    def __len__(self) -> int: ...


def pose_checks_fields(result: PoseChecks) -> list[dict[str, Any]]:
    """PoseCheck dicts of every pose of a check result, in order."""
    violated = result.violated
    names = list(result.margins)
    margins = np.stack([result.margins[name] for name in names], axis=1).tolist()
    reachable = result.reachable.tolist()
    limiting = np.asarray(result.limiting_leg).tolist()
    pairs = list(result.collision_pair) or [""] * len(reachable)  # empty: no scene
    return [
        {
            "reachable": bool(reachable[i]),
            "violated": list(violated[i]),
            "constraint_names": names,
            "margins": margins[i],
            "limiting_leg": int(limiting[i]),
            "collision_pair": pairs[i],
        }
        for i in range(len(reachable))
    ]


def _failed_pose_check(names: Sequence[str]) -> dict[str, Any]:
    """A PoseCheck that was not made: the constraint ``names`` of the model (its rows, not the
    whole table), every margin NaN."""
    return {
        "reachable": False,
        "violated": [],
        "constraint_names": list(names),
        "margins": [math.nan] * len(names),
        "limiting_leg": 0,
        "collision_pair": "",
    }


def check_poses_request_fields(
    position: ArrayLike, angles: ArrayLike, frame_id: str = ""
) -> dict[str, Any]:
    """hexapod_workspace_msgs/srv/CheckPoses_Request from a position (3,) m and angles (N, 3)
    in the frame ``frame_id`` (``""``: the base frame)."""
    angles = np.asarray(angles, dtype=float).reshape(-1, 3)
    return {
        "position": point_fields(position),
        "orientations": [{"phi": p, "theta": t, "psi": s} for p, t, s in angles.tolist()],
        "poses": [],
        "header": header_fields(0, frame_id),
    }


def no_cell_frames_fields(request_frame_id: str = "") -> dict[str, Any]:
    """hexapod_workspace_msgs/msg/CellFrames of a result computed without a machining cell: the
    tool at the platform frame, no work frame (the cell's own: logs/cell.py)."""
    zero = {"x": 0.0, "y": 0.0, "z": 0.0}
    angles = {"phi": 0.0, "theta": 0.0, "psi": 0.0}
    return {
        "tool_offset": dict(zero),
        "tool_orientation": dict(angles),
        "work_origin": dict(zero),
        "work_orientation": dict(angles),
        "tool_number": 0,
        "work_frame_id": "",
        "request_frame_id": str(request_frame_id),
    }


def check_poses_response_fields(
    result: PoseChecks | None, *, success: bool = True, message: str | None = None
) -> dict[str, Any]:
    """hexapod_workspace_msgs/srv/CheckPoses_Response.

    ``result=None`` (or ``success=False``) gives a failure response with an empty result list;
    the default message is ``"N/M reachable"``.
    """
    if result is None or not success:
        return {"success": False, "message": message or "request failed", "results": []}
    reachable = int(np.count_nonzero(result.reachable))
    return {
        "success": True,
        "message": message if message is not None else f"{reachable}/{len(result)} reachable",
        "results": pose_checks_fields(result),
        "frames": no_cell_frames_fields(),
    }


def commanded_pose_fields(
    angles: ArrayLike,
    position: ArrayLike,
    *,
    request_id: str = "",
    stamp_ns: int = 0,
    frame_id: str = "",
) -> dict[str, Any]:
    """hexapod_workspace_msgs/msg/CommandedPose."""
    return {
        "header": header_fields(stamp_ns, frame_id),
        "request_id": str(request_id),
        "position": point_fields(position),
        "orientation": tilt_torsion_fields(angles),
        "use_pose": False,
        "pose": identity_pose_fields(),
    }


def reachability_result_fields(
    result: CheckResult | None,
    *,
    position: ArrayLike,
    angles: ArrayLike,
    stamp_ns: int,
    frame_id: str,
    request_id: str = "",
    index: int = 0,
    message: str | None = None,
    names: Sequence[str] = (),
    check: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """hexapod_workspace_msgs/msg/ReachabilityResult answering one CommandedPose.

    ``result=None`` means the command was not checked (invalid, overloaded, or no model):
    ``success`` false, ``message`` the reason, ``check.constraint_names`` the model's rows
    ``names`` (empty where no model is loaded) with NaN margins. ``check``: the pose's PoseCheck
    fields when the caller has them (``pose_checks_fields(result)[index]``): a caller that answers
    the poses of one large result one by one computes them once for all, since
    :func:`pose_check_fields` reads properties of the result that are computed for every pose at
    each call.
    """
    if result is None:
        check = _failed_pose_check(names)
        verdict = message or "invalid command"
    else:
        check = pose_check_fields(result, index) if check is None else check
        verdict = message or (
            "reachable" if check["reachable"] else "unreachable: " + ", ".join(check["violated"])
        )
    return {
        "header": header_fields(stamp_ns, frame_id),
        "request_id": str(request_id),
        "success": result is not None,
        "message": verdict,
        "position": point_fields(position),
        "orientation": tilt_torsion_fields(angles),
        "check": check,
        "motion_checked": False,
        "motion_ok": False,
        "current_pose": identity_pose_fields(),
        "motion": unchecked_motion_fields(),
        "frames": no_cell_frames_fields(),
    }


# --------------------------------------------------------------------------- workspaces


def workspace_kind(workspace: ProjectedWorkspace | OrientationWorkspace) -> int:
    """The WorkspaceKind of a result (orientation, projected torsion_zero or exact)."""
    if isinstance(workspace, OrientationWorkspace):
        return WorkspaceKind.ORIENTATION
    return WorkspaceKind.projected(workspace.method)


def workspace_request_fields(
    kind: int,
    position: ArrayLike,
    *,
    request_id: str = "",
    n_rays: int = 0,
    psi_step: float = 0.0,
    tolerance: float = 0.0,
    stamp_ns: int = 0,
    frame_id: str = "",
) -> dict[str, Any]:
    """hexapod_workspace_msgs/msg/WorkspaceRequest (0 resolution fields = node parameter)."""
    return {
        "header": header_fields(stamp_ns, frame_id),
        "request_id": str(request_id),
        "kind": int(kind),
        "position": point_fields(position),
        "n_rays": int(n_rays),
        "psi_step": float(psi_step),
        "tolerance": float(tolerance),
    }


def _request_for(
    workspace: ProjectedWorkspace | OrientationWorkspace,
    *,
    request_id: str,
    stamp_ns: int,
    frame_id: str,
) -> dict[str, Any]:
    kind = workspace_kind(workspace)
    if isinstance(workspace, OrientationWorkspace):
        n_rays, psi_step = int(workspace.n_rays), float(workspace.psi_step)
    else:
        n_rays, psi_step = int(np.asarray(workspace.phi).shape[0]), 0.0
    return workspace_request_fields(
        kind,
        workspace.position,
        request_id=request_id,
        n_rays=n_rays,
        psi_step=psi_step,
        tolerance=float(workspace.tolerance),
        stamp_ns=stamp_ns,
        frame_id=frame_id,
    )


def compute_workspace_request_fields(
    workspace: ProjectedWorkspace | OrientationWorkspace,
    *,
    request_id: str = "",
    stamp_ns: int = 0,
    frame_id: str = "",
) -> dict[str, Any]:
    """hexapod_workspace_msgs/srv/ComputeWorkspace_Request that asks for what ``workspace``
    answers (kind, position, resolution used): what the CLI records as its request."""
    return {
        "request": _request_for(
            workspace, request_id=request_id, stamp_ns=stamp_ns, frame_id=frame_id
        )
    }


def boundary_points(workspace: ProjectedWorkspace | OrientationWorkspace) -> NDArray[np.float64]:
    """Boundary points of a result, columns x, y, z, φ, θ, ψ (see ComputeWorkspace.srv).

    Returns
    -------
    ndarray, shape (M, 6)
        Orientation workspace: x, y, z = θ cos φ, θ sin φ, ψ (the cylindrical picture).
        Projected workspace: x, y, z = the unit approach vector of each boundary direction.
    """
    if isinstance(workspace, OrientationWorkspace):
        return np.asarray(workspace.boundary_points(), dtype=float).reshape(-1, 6)
    phi = np.asarray(workspace.phi, dtype=float)
    theta = np.asarray(workspace.theta, dtype=float)
    psi = np.broadcast_to(np.asarray(workspace.psi, dtype=float), phi.shape)
    return np.column_stack((approach_vector(phi, theta), phi, theta, psi))


def summary_fields(
    workspace: ProjectedWorkspace | OrientationWorkspace | None,
    *,
    stamp_ns: int,
    frame_id: str,
    request_id: str = "",
    kind: int | None = None,
    position: ArrayLike | None = None,
    n_points: int | None = None,
    success: bool = True,
    reference_reachable: bool = True,
    message: str | None = None,
    n_rays: int = 0,
    tolerance: float = math.nan,
) -> dict[str, Any]:
    """hexapod_workspace_msgs/msg/WorkspaceSummary.

    Parameters
    ----------
    workspace : ProjectedWorkspace, OrientationWorkspace or None
        ``None`` for a failed computation (then give ``kind``, ``position``, ``message``, and
        ``reference_reachable=False`` when the reference orientation was unreachable).
    stamp_ns, frame_id : int, str
        Header; use the same stamp for the summary and its boundary cloud.
    n_points : int, optional
        Points of the published cloud; default the number of boundary points.

    Fields that do not apply to the kind are NaN.
    """
    nan = math.nan
    fields: dict[str, Any] = {
        "header": header_fields(stamp_ns, frame_id),
        "request_id": str(request_id),
        "tilt_min": nan,
        "tilt_max": nan,
        "solid_angle": nan,
        "psi_min": nan,
        "psi_max": nan,
        "volume": nan,
    }
    if workspace is None or not success:
        fields.update(
            kind=int(kind if kind is not None else WorkspaceKind.ORIENTATION),
            success=False,
            message=message or "workspace computation failed",
            position=point_fields(position if position is not None else np.zeros(3)),
            reference_reachable=bool(reference_reachable) and workspace is not None,
            n_rays=int(n_rays),
            tolerance=float(tolerance),
            n_points=int(n_points or 0),
            elapsed=0.0 if workspace is None else float(workspace.elapsed),
            frames=no_cell_frames_fields(),
        )
        return fields
    kind = workspace_kind(workspace) if kind is None else int(kind)
    if isinstance(workspace, OrientationWorkspace):
        fields.update(
            psi_min=float(workspace.psi_min),
            psi_max=float(workspace.psi_max),
            volume=float(workspace.volume),
            n_rays=int(workspace.n_rays),
        )
    else:
        fields.update(
            tilt_min=float(workspace.tilt_min),
            tilt_max=float(workspace.tilt_max),
            solid_angle=float(workspace.solid_angle),
            n_rays=int(np.asarray(workspace.phi).shape[0]),
        )
    fields.update(
        kind=kind,
        success=True,
        position=point_fields(workspace.position),
        reference_reachable=True,
        tolerance=float(workspace.tolerance),
        n_points=int(n_points if n_points is not None else boundary_points(workspace).shape[0]),
        elapsed=float(workspace.elapsed),
    )
    fields["message"] = message if message is not None else summary_line(fields)
    fields["frames"] = no_cell_frames_fields()
    return fields


def pointcloud_fields(points: ArrayLike, *, frame_id: str, stamp_ns: int) -> dict[str, Any]:
    """sensor_msgs/msg/PointCloud2 of boundary points: float32 x, y, z, phi, theta, psi.

    Parameters
    ----------
    points : array_like, shape (M, 6)
        Columns :data:`POINT_FIELD_NAMES` (:func:`boundary_points`).

    Returns
    -------
    dict
        Unorganised cloud (height 1), little-endian, point_step 24, ``data`` as ``bytes``
        (an rclpy message wants ``array.array("B", data)``: assigning bytes-likes directly to
        ``PointCloud2.data`` is slow for large clouds).
    """
    array = np.ascontiguousarray(np.asarray(points).reshape(-1, 6), dtype="<f4")
    count = array.shape[0]
    return {
        "header": header_fields(stamp_ns, frame_id),
        "height": 1,
        "width": count,
        "fields": [
            {"name": name, "offset": 4 * i, "datatype": _FLOAT32, "count": 1}
            for i, name in enumerate(POINT_FIELD_NAMES)
        ],
        "is_bigendian": False,
        "point_step": 24,
        "row_step": 24 * count,
        "data": array.tobytes(),
        "is_dense": bool(np.isfinite(array).all()),
    }


def compute_workspace_response_fields(
    workspace: ProjectedWorkspace | OrientationWorkspace | None,
    *,
    stamp_ns: int,
    frame_id: str,
    request_id: str = "",
    summary: Mapping[str, Any] | Any = None,
    boundary: Mapping[str, Any] | Any = None,
) -> dict[str, Any]:
    """hexapod_workspace_msgs/srv/ComputeWorkspace_Response (summary + boundary cloud).

    Pass ``summary``/``boundary`` already built for publishing (field dicts, or messages, which
    are kept as they are) to avoid building them twice; for a failure pass ``workspace=None``
    and a failed ``summary``.
    """
    if summary is None:
        summary = summary_fields(
            workspace, stamp_ns=stamp_ns, frame_id=frame_id, request_id=request_id
        )
    if boundary is None:
        points = boundary_points(workspace) if workspace is not None else np.zeros((0, 6))
        boundary = pointcloud_fields(points, frame_id=frame_id, stamp_ns=stamp_ns)
    return {
        "success": bool(_get(summary, "success")),
        "message": str(_get(summary, "message")),
        # dicts are copied; message objects (the node's, already published) pass through
        "summary": dict(summary) if isinstance(summary, Mapping) else summary,
        "boundary": dict(boundary) if isinstance(boundary, Mapping) else boundary,
    }


# --------------------------------------------------------------------------- inverse (replay)


def _get(obj: Any, name: str) -> Any:
    return obj[name] if isinstance(obj, Mapping) else getattr(obj, name)


def pointcloud_to_array(cloud: Any) -> NDArray[np.float64]:
    """Boundary points back from a PointCloud2 (dict, rosbags or rclpy message).

    Returns
    -------
    ndarray, shape (M, 6), float64
        Columns x, y, z, φ, θ, ψ; a column whose field the cloud lacks is NaN.

    Raises
    ------
    ValueError
        When ``data`` is shorter than ``width * height * point_step`` or a field is not
        FLOAT32/FLOAT64.
    """
    count = int(_get(cloud, "width")) * int(_get(cloud, "height"))
    step = int(_get(cloud, "point_step"))
    order = ">" if bool(_get(cloud, "is_bigendian")) else "<"
    data = _get(cloud, "data")
    buffer: NDArray[np.uint8]
    if isinstance(data, np.ndarray):
        buffer = np.ascontiguousarray(data).view(np.uint8).reshape(-1)
    else:  # bytes, bytearray, memoryview, array.array("B") of an rclpy message
        buffer = np.frombuffer(data, dtype=np.uint8)
    if buffer.size < count * step:
        msg = f"PointCloud2 data has {buffer.size} bytes, expected {count * step}"
        raise ValueError(msg)
    out = np.full((count, 6), np.nan)
    if count == 0:
        return out
    rows = buffer[: count * step].reshape(count, step)
    for point_field in _get(cloud, "fields"):
        name = str(_get(point_field, "name"))
        if name not in POINT_FIELD_NAMES:
            continue
        datatype, offset = int(_get(point_field, "datatype")), int(_get(point_field, "offset"))
        if datatype not in (_FLOAT32, _FLOAT64):
            msg = f"PointCloud2 field {name} has datatype {datatype}, expected FLOAT32/FLOAT64"
            raise ValueError(msg)
        width = 4 if datatype == _FLOAT32 else 8
        column = np.ascontiguousarray(rows[:, offset : offset + width]).view(f"{order}f{width}")
        out[:, POINT_FIELD_NAMES.index(name)] = column[:, 0]
    return out


def summary_line(summary: Any) -> str:
    """One-line human summary of a WorkspaceSummary (dict or message), degrees."""
    kind = int(_get(summary, "kind"))
    known = WorkspaceKind.of(kind)
    name = known.label if known is not None else f"kind {kind}"
    if not bool(_get(summary, "success")):
        return f"{name}: failed: {_get(summary, 'message')}"
    if kind == WorkspaceKind.ORIENTATION:
        return (
            f"{name}: psi {math.degrees(_get(summary, 'psi_min')):.3f}..."
            f"{math.degrees(_get(summary, 'psi_max')):.3f} deg, "
            f"volume {float(_get(summary, 'volume')):.6g} rad^3, "
            f"{int(_get(summary, 'n_points'))} boundary points"
        )
    return (
        f"{name}: tilt {math.degrees(_get(summary, 'tilt_min')):.3f}..."
        f"{math.degrees(_get(summary, 'tilt_max')):.3f} deg, "
        f"solid angle {float(_get(summary, 'solid_angle')):.6g} sr, "
        f"{int(_get(summary, 'n_points'))} boundary points"
    )
