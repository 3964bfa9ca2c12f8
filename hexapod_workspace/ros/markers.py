"""``~/markers`` (visualization_msgs/MarkerArray): the scene where people look, RViz and Foxglove.

The machine (legs, platform, tool), the obstacles of the collision scene, the closest pair
(red when violated, orange otherwise) and the cone of attainable tool directions at the tool
centre point (:mod:`hexapod_workspace.logs.markers` says which marker is what). Reliable,
transient local, depth 1: a display that starts later gets the last scene at once. Recorded in
the node's MCAP log like every publication.

When it is published
    At activation and after every accepted parameter change (the model's pose
    ``pose.position``, identity orientation), and, when ``motion.current_pose_topic`` is set,
    with the last current pose received there, at most :data:`MARKER_RATE` times a second.
Off the command path
    A thread of its own polls the node's state and current pose every 1/:data:`MARKER_RATE` s
    and builds the scene only when one of them changed; the executor's callbacks only store
    the pose (:mod:`~hexapod_workspace.ros.paths`). The cone is recomputed only when the
    position or the model changed.
The cone
    The projected workspace at the current position with the node's
    ``resolution.projected_method`` (``torsion_zero`` by default: the tool directions reachable
    at ψ = 0; ``exact``: with some torsion) and ``resolution.tolerance``, on
    :data:`CONE_AZIMUTHS` azimuths (a picture: every boundary point is certified, the rim
    between them is drawn straight). No cone when the reference orientation is unreachable at
    the position, nor while a loads limit is set (:mod:`~hexapod_workspace.ros.load_rows`:
    the cone would pass over it).
The collision scene
    :func:`node_scene`: the scene of the node's model (``collision.*``, read from the
    parameters file and changed at run time like every model parameter); without one the
    machine is drawn alone, with the closest leg pair when ``limits.leg_diameter`` > 0.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np
from visualization_msgs.msg import MarkerArray

from ..core.base.rotations import quaternion_to_matrix
from ..core.cell.scene_view import Cone, cone_of, scene_view
from ..core.model.collision import CollisionScene
from ..core.workspaces.projected import projected_workspace
from ..errors import HexapodWorkspaceError
from ..logs.interfaces import relative_name
from ..logs.markers import marker_array_fields
from .conversions import to_message
from .load_rows import require_geometric

__all__ = ["CONE_AZIMUTHS", "MARKER_RATE", "MarkerPublisher", "attach", "node_scene"]

#: Largest number of scenes published per second while the current pose moves.
MARKER_RATE = 5.0
#: Azimuths of the cone of tool directions (every 5°).
CONE_AZIMUTHS = 72


def node_scene(state: Any) -> CollisionScene | None:
    """The collision scene of the node's configured state, or None.

    The one place the markers learn the scene: the model's own scene
    (:attr:`~hexapod_workspace.core.model.manipulator.Manipulator.collision`, read from
    ``collision.*``); None without one (the machine is then drawn without obstacles).
    """
    scene = getattr(getattr(state, "manipulator", None), "collision", None)
    return scene if isinstance(scene, CollisionScene) else None


class MarkerPublisher:
    """The ``~/markers`` publisher and its thread (see the module documentation).

    Parameters
    ----------
    node : WorkspaceNode
        Gives ``state``, ``paths.current_pose``, ``recorded_publisher``, ``publish``.
    """

    def __init__(self, node: Any) -> None:
        self._node = node
        self.publisher = node.recorded_publisher(MarkerArray, relative_name("markers"), depth=1)
        self._stop = threading.Event()
        # what the last scene and the last cone were built from: the state object itself
        # (held, so that its id is never reused) and the pose
        self._published: tuple[Any, bytes, bytes] | None = None
        self._cone_for: tuple[Any, bytes] | None = None
        self._cone: Cone | None = None
        #: scenes published (for the tests and the diagnostics)
        self.count = 0
        self._thread = threading.Thread(target=self._run, name="markers", daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop the thread (waits for a scene being built)."""
        self._stop.set()
        if self._thread is not threading.current_thread():
            self._thread.join(timeout=5.0)

    def _pose(self, state: Any) -> tuple[np.ndarray, np.ndarray]:
        paths = getattr(self._node, "paths", None)
        current = paths.current_pose if paths is not None else None
        if current is None:
            return np.asarray(state.manipulator.position, dtype=float), np.eye(3)
        position, quaternion = current
        return np.asarray(position, dtype=float), quaternion_to_matrix(quaternion)

    def _run(self) -> None:
        while not self._stop.wait(1.0 / MARKER_RATE):
            try:
                self.publish_once()
            except Exception as error:  # keep the node serving; say what went wrong once
                if self._stop.is_set() or not _context_ok(self._node):
                    return
                self._node.get_logger().error(f"markers: {type(error).__name__}: {error}")
                self._stop.wait(1.0)

    def publish_once(self) -> bool:
        """Publish the scene if the state or the pose changed since the last one; True if it
        published."""
        node = self._node
        state = node.state
        if state is None or not getattr(node, "active", True):
            self._published = None  # publish again on the next activation
            return False
        position, rotation = self._pose(state)
        pose = (position.tobytes(), rotation.tobytes())
        last = self._published
        if last is not None and last[0] is state and last[1:] == pose:
            return False
        scene = node_scene(state)
        manipulator = state.manipulator
        cone_for = self._cone_for
        if cone_for is None or cone_for[0] is not state or cone_for[1] != pose[0]:
            try:
                require_geometric(state, "the cone of tool directions")  # none with loads
                workspace = projected_workspace(
                    manipulator,
                    position,
                    method=state.settings.projected_method,
                    n_phi=CONE_AZIMUTHS,
                    tolerance=state.settings.tolerance,
                )
                self._cone = cone_of(workspace, manipulator, scene)
            except HexapodWorkspaceError:  # unreachable reference, position out of bounds
                self._cone = None
            self._cone_for = (state, pose[0])
        view = scene_view(manipulator, rotation, position, scene, cone=self._cone)
        now = node.get_clock().now().to_msg()
        fields = marker_array_fields(
            view,
            frame_id=manipulator.frame_id,
            stamp={"sec": int(now.sec), "nanosec": int(now.nanosec)},
        )
        node.publish(self.publisher, to_message(MarkerArray, fields))
        self._published = (state, *pose)
        self.count += 1
        return True


def _context_ok(node: Any) -> bool:
    import rclpy

    return bool(rclpy.ok(context=node.context))


def attach(node: Any) -> MarkerPublisher:
    """Create ``~/markers`` on ``node`` and start its thread; stored as ``node.markers``."""
    markers = MarkerPublisher(node)
    node.markers = markers
    return markers
