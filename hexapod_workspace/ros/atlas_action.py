"""The ``~/compute_atlas`` action: the workspace atlas from ROS, published as a PointCloud2.

One function, :func:`attach_atlas_action`, adds to a node:

* the action server ``~/compute_atlas`` (``hexapod_workspace_msgs/action/ComputeAtlas``):
  a goal is a box and a step (m) with the resolution; feedback is positions done out of the
  total after every chunk; a cancel stops the run after the chunk in flight;
* the publisher ``~/atlas`` (sensor_msgs/PointCloud2, transient local, depth 1): the finished
  atlas, fields x, y, z (the position, m, base frame, float32) then one float32 per atlas value
  (:data:`CLOUD_FIELDS`), NaN where the reference orientation is unreachable. A late subscriber
  gets the last atlas. The cloud goes to the node's recorder too, when it has one.

The atlas runs on the engine of :mod:`hexapod_workspace.atlas` (the ``atlas`` extra) in a
temporary Zarr store: in the node's process by default, or on the Dask scheduler named in the
goal. Without the extra every goal is refused with the install hint; the node keeps serving.
"""

from __future__ import annotations

import array
import math
import shutil
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import PointCloud2, PointField

from ..core.workspaces.atlas import ATLAS_VARIABLES, AtlasGrid, AtlasOptions, dexterous_mask
from ..errors import HexapodWorkspaceError
from ..logs import qos_profile_text
from ..logs.interfaces import relative_name
from ..logs.messages import header_fields
from .conversions import to_message
from .jobs import in_thread

__all__ = ["ACTION_NAME", "CLOUD_FIELDS", "CLOUD_TOPIC", "atlas_cloud", "attach_atlas_action"]

ACTION_NAME = relative_name("compute_atlas")
CLOUD_TOPIC = relative_name("atlas")
#: Atlas values carried by the cloud after x, y, z (float32 each, this order).
CLOUD_FIELDS = tuple(v.name for v in ATLAS_VARIABLES if v.name != "orientation_volume")
#: The largest grid a goal may ask for (as the CLI's cap without --force).
MAX_POSITIONS = 20_000


class _CancelledError(Exception):
    """The client cancelled the goal (raised from the progress callback)."""


def atlas_cloud(dataset: Any, grid: AtlasGrid, *, frame_id: str, stamp_ns: int) -> PointCloud2:
    """The atlas as an unorganised PointCloud2 (see the module documentation).

    Parameters
    ----------
    dataset : xarray.Dataset
        An atlas (box grid, dims x, y, z).
    grid : AtlasGrid
    frame_id : str
    stamp_ns : int

    Returns
    -------
    sensor_msgs.msg.PointCloud2
        Little-endian, point_step 4 × (3 + len(CLOUD_FIELDS)) bytes, C order over (x, y, z).
    """
    names = ("x", "y", "z", *CLOUD_FIELDS)
    points = grid.points((slice(None),) * len(grid.dims))
    columns = [points[:, 0], points[:, 1], points[:, 2]]
    columns += [np.asarray(dataset[name].values, dtype=np.float64).ravel() for name in CLOUD_FIELDS]
    table = np.column_stack(columns).astype("<f4")
    step = 4 * len(names)
    return to_message(
        PointCloud2,
        {
            "header": header_fields(stamp_ns, frame_id),
            "height": 1,
            "width": points.shape[0],
            "fields": [
                {"name": name, "offset": 4 * k, "datatype": PointField.FLOAT32, "count": 1}
                for k, name in enumerate(names)
            ],
            "is_bigendian": False,
            "point_step": step,
            "row_step": step * points.shape[0],
            "data": array.array("B", table.tobytes()),
            "is_dense": False,
        },
    )


def attach_atlas_action(
    node: Any,
    manipulator: Callable[[], Any],
    *,
    recorder: Any | None = None,
) -> ActionServer:
    """Add the ``~/compute_atlas`` action server and the ``~/atlas`` publisher to a node.

    Parameters
    ----------
    node : rclpy.node.Node
        Spun by a multi-threaded executor (the action runs in its own callback group).
    manipulator : callable
        Returns the node's current :class:`~hexapod_workspace.core.model.manipulator.Manipulator`
        (read when a goal starts, so a parameter change applies to the next goal).
    recorder : object, optional
        With ``add_channel(topic, msgtype, qos_text)`` and ``write(topic, message)`` (the node's
        MCAP recorder): the published atlas is recorded.

    Returns
    -------
    rclpy.action.ActionServer
    """
    from hexapod_workspace_msgs.action import ComputeAtlas

    qos = QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    publisher = node.create_publisher(PointCloud2, CLOUD_TOPIC, qos)
    if recorder is not None:
        recorder.add_channel(
            publisher.topic_name,
            "sensor_msgs/msg/PointCloud2",
            qos_profile_text(durability="transient_local", depth=1),
        )
    one_at_a_time = threading.Lock()

    def refuse(reason: str) -> Any:
        result = ComputeAtlas.Result()
        result.success = False
        result.reason = reason
        result.tilt_capability_min = math.nan
        result.tilt_capability_max = math.nan
        result.tilt_capability_mean = math.nan
        return result

    def on_goal(goal: Any) -> GoalResponse:
        return GoalResponse.ACCEPT  # validated in execute, so a refusal carries its reason

    def on_cancel(goal_handle: Any) -> CancelResponse:
        return CancelResponse.ACCEPT

    def execute(goal_handle: Any) -> Any:
        goal = goal_handle.request
        if not one_at_a_time.acquire(blocking=False):
            goal_handle.abort()
            return refuse("another atlas is being computed; try again when it is done")
        folder = Path(tempfile.mkdtemp(prefix="hexapod_atlas_"))
        try:
            return run(goal_handle, goal, folder)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
            one_at_a_time.release()

    def run(goal_handle: Any, goal: Any, folder: Path) -> Any:
        started = time.perf_counter()
        try:
            grid = AtlasGrid.box(list(goal.box), goal.step)
            if grid.size > MAX_POSITIONS:
                goal_handle.abort()
                return refuse(
                    f"{grid.size} positions: more than the {MAX_POSITIONS} a goal may ask for"
                )
            options = AtlasOptions(
                n_phi=int(goal.n_phi) or AtlasOptions.n_phi,
                tolerance=float(goal.tolerance) or AtlasOptions.tolerance,
            )
            tilts = [float(t) for t in goal.tilt_required]
            for tilt in tilts:
                dexterous_mask(np.zeros(1), tilt)  # validates the tilt (InputError)
            from ..atlas import workspace_atlas

            def progress(done: int, total: int) -> None:
                if goal_handle.is_cancel_requested:
                    raise _CancelledError
                feedback = ComputeAtlas.Feedback()
                feedback.positions_done = done
                feedback.positions_total = total
                goal_handle.publish_feedback(feedback)

            atlas = workspace_atlas(
                manipulator(),
                grid,
                store=folder / "atlas.zarr",
                options=options,
                scheduler=goal.scheduler or None,
                workers=None if goal.scheduler else 0,
                progress=progress,
            )
        except _CancelledError:
            goal_handle.canceled()
            return refuse("cancelled")
        except HexapodWorkspaceError as error:
            goal_handle.abort()
            return refuse(" ".join(str(error).split()))
        dataset = atlas.dataset
        cloud = atlas_cloud(
            dataset,
            grid,
            frame_id=manipulator().frame_id,
            stamp_ns=node.get_clock().now().nanoseconds,
        )
        publisher.publish(cloud)
        if recorder is not None:
            recorder.write(publisher.topic_name, cloud)
        capability = dataset["tilt_capability"].values
        known = capability[np.isfinite(capability)]
        result = ComputeAtlas.Result()
        result.success = True
        result.positions = grid.size
        result.reachable_positions = int(dataset["reference_reachable"].values.sum())
        result.tilt_capability_min = float(known.min()) if known.size else math.nan
        result.tilt_capability_max = float(known.max()) if known.size else math.nan
        result.tilt_capability_mean = float(known.mean()) if known.size else math.nan
        result.dexterous_volume = [atlas.dexterous_volume(tilt) or 0.0 for tilt in tilts]
        result.elapsed = time.perf_counter() - started
        goal_handle.succeed()
        return result

    return ActionServer(
        node,
        ComputeAtlas,
        ACTION_NAME,
        # the run blocks for minutes: in a thread of its own, so that a single-threaded
        # executor (the workspace node's) keeps serving meanwhile
        execute_callback=in_thread(node, execute),
        goal_callback=on_goal,
        cancel_callback=on_cancel,
        callback_group=ReentrantCallbackGroup(),
    )
