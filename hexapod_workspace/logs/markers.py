"""A scene (:class:`~hexapod_workspace.core.cell.scene_view.SceneView`) as
``visualization_msgs/MarkerArray`` fields: what the node publishes on ``~/markers`` and
records. ROS-free (field dicts; the node turns them into rclpy messages, the logs into CDR).

One marker per body, in namespaces RViz and Foxglove list as toggles:

==================== ============================================================================
namespace            markers
==================== ============================================================================
(first)              ``DELETEALL``: a body that is gone (an obstacle removed) does not linger
``legs``             ids 1–6: ``CYLINDER`` of ``limits.leg_diameter`` along A_iB_i; one
                     ``LINE_LIST`` (id 0) when the diameter is 0
``platform``         ``CYLINDER`` (collision scene) or the ``LINE_STRIP`` through the joints
``tool``             ``CYLINDER`` + two ``SPHERE`` (the capsule), or a ``LINE_LIST`` (the axis)
``obstacles``        ``CUBE``, ``CYLINDER``, ``SPHERE``, capsules as ``CYLINDER`` + ``SPHERE``
``labels``           ``TEXT_VIEW_FACING``: each obstacle's name
``closest_pair``     ``LINE_LIST`` between the closest points, ``TEXT_VIEW_FACING`` with the
                     pair and its margin in mm
``tool_directions``  ``TRIANGLE_LIST``: the cone of attainable tool directions at the tool
                     centre point (apex, rim k, rim k + 1 per triangle)
==================== ============================================================================

Colours (RGBA): legs grey, platform and tool blue, obstacles brown, the two bodies of the
closest pair red when violated and orange otherwise, the cone translucent green. Positions in
m in ``frame_id`` (the node's base frame).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.base.rotations import matrix_to_quaternion
from ..core.cell.scene_view import Body, SceneView

__all__ = ["MARKER_ARRAY_TYPE", "NAMESPACES", "marker_array_fields"]

MARKER_ARRAY_TYPE = "visualization_msgs/msg/MarkerArray"
#: visualization_msgs/Marker type and action constants.
ARROW, CUBE, SPHERE, CYLINDER, LINE_STRIP, LINE_LIST = 0, 1, 2, 3, 4, 5
TEXT_VIEW_FACING, TRIANGLE_LIST = 9, 11
ADD, DELETEALL = 0, 3
NAMESPACES = (
    "legs",
    "platform",
    "tool",
    "obstacles",
    "labels",
    "closest_pair",
    "tool_directions",
)
LEG = (0.55, 0.55, 0.58, 1.0)
MACHINE = (0.12, 0.47, 0.71, 0.8)
PLATFORM = (0.12, 0.47, 0.71, 0.45)
OBSTACLE = (0.55, 0.34, 0.29, 0.6)
VIOLATED = (0.84, 0.15, 0.16, 1.0)
CLOSEST = (1.0, 0.5, 0.05, 1.0)
CONE = (0.17, 0.63, 0.17, 0.35)
TEXT = (0.1, 0.1, 0.1, 1.0)
#: Width of lines (legs of diameter 0, the tool axis, the closest-pair segment), m.
LINE_WIDTH = 0.005
#: Height of the text labels, m.
TEXT_HEIGHT = 0.04


def _point(p: NDArray[np.float64]) -> dict[str, float]:
    return {"x": float(p[0]), "y": float(p[1]), "z": float(p[2])}


_IDENTITY = {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}


def _colour(rgba: tuple[float, float, float, float]) -> dict[str, float]:
    return dict(zip("rgba", rgba, strict=True))


class _Builder:
    def __init__(self, frame_id: str, stamp: dict[str, int]) -> None:
        self.header = {"stamp": stamp, "frame_id": frame_id}
        origin = {"position": _point(np.zeros(3)), "orientation": dict(_IDENTITY)}
        self.markers: list[dict[str, Any]] = [
            {"header": self.header, "action": DELETEALL, "pose": origin}
        ]
        self._ids: dict[str, int] = {}
        # markers whose orientation is a rotation: converted to quaternions in one call
        self._rotated: list[tuple[dict[str, Any], NDArray[np.float64]]] = []

    def add(
        self,
        namespace: str,
        kind: int,
        colour: tuple[float, float, float, float],
        *,
        centre: NDArray[np.float64] | None = None,
        rotation: NDArray[np.float64] | None = None,
        scale: tuple[float, float, float] = (1.0, 1.0, 1.0),
        points: NDArray[np.float64] | None = None,
        text: str = "",
        marker_id: int | None = None,
    ) -> None:
        if marker_id is None:
            marker_id = self._ids.get(namespace, 0)
        self._ids[namespace] = marker_id + 1
        pose = {
            "position": _point(np.zeros(3) if centre is None else centre),
            "orientation": dict(_IDENTITY),
        }
        if rotation is not None:
            self._rotated.append((pose, rotation))
        self.markers.append(
            {
                "header": self.header,
                "ns": namespace,
                "id": marker_id,
                "type": kind,
                "action": ADD,
                "pose": pose,
                "scale": dict(zip("xyz", (float(s) for s in scale), strict=True)),
                "color": _colour(colour),
                "points": [] if points is None else [_point(p) for p in points],
                "text": text,
            }
        )

    def finish(self) -> list[dict[str, Any]]:
        """The markers, with the orientations of the rotated ones filled in."""
        if self._rotated:
            quaternions = matrix_to_quaternion(np.array([r for _, r in self._rotated]))
            for (pose, _), q in zip(self._rotated, quaternions.tolist(), strict=True):
                pose["orientation"] = dict(zip("xyzw", q, strict=True))
        return self.markers


def _solid(builder: _Builder, namespace: str, body: Body, colour: Any) -> None:
    """A body as RViz primitives (a capsule is a cylinder and two spheres)."""
    if body.kind == "segment":
        if body.radius > 0.0:
            d = 2.0 * body.radius
            builder.add(
                namespace,
                CYLINDER,
                colour,
                centre=body.centre,
                rotation=body.rotation,
                scale=(d, d, body.length),
            )
            if body.name.startswith("leg"):
                return  # a leg is drawn as its cylinder (its capsule ends sit in the joints)
            for end in body.points:
                builder.add(namespace, SPHERE, colour, centre=end, scale=(d, d, d))
        else:
            builder.add(
                namespace, LINE_LIST, colour, scale=(LINE_WIDTH, 0.0, 0.0), points=body.points
            )
    elif body.kind == "cylinder":
        d = 2.0 * body.radius
        builder.add(
            namespace,
            CYLINDER,
            colour,
            centre=body.centre,
            rotation=body.rotation,
            scale=(d, d, body.length),
        )
    elif body.kind == "box":
        builder.add(
            namespace,
            CUBE,
            colour,
            centre=body.centre,
            rotation=body.rotation,
            scale=(float(body.size[0]), float(body.size[1]), float(body.size[2])),
        )
    elif body.kind == "sphere":
        d = 2.0 * body.radius
        builder.add(namespace, SPHERE, colour, centre=body.centre, scale=(d, d, d))
    elif body.kind == "polygon":
        closed = np.vstack([body.points, body.points[:1]])
        builder.add(namespace, LINE_STRIP, colour, scale=(LINE_WIDTH, 0.0, 0.0), points=closed)


def marker_array_fields(
    view: SceneView, *, frame_id: str, stamp: dict[str, int] | None = None
) -> dict[str, Any]:
    """``visualization_msgs/MarkerArray`` fields of a scene (see the module documentation).

    Parameters
    ----------
    view : SceneView
    frame_id : str
        The frame of every marker (the node's base frame).
    stamp : dict, optional
        ``{"sec": ..., "nanosec": ...}`` of every header (default 0: "latest" in RViz).

    Returns
    -------
    dict
        ``{"markers": [...]}``, field dicts of ``visualization_msgs/Marker``.
    """
    builder = _Builder(frame_id, stamp or {"sec": 0, "nanosec": 0})
    pair = view.closest
    highlight: dict[str, tuple[float, float, float, float]] = {}
    if pair is not None:
        highlight = dict.fromkeys((pair.first, pair.second), VIOLATED if pair.violated else CLOSEST)
    legs = [body for body in view.bodies if body.name.startswith("leg ")]
    if legs and legs[0].radius == 0.0:
        # one line list of the six legs, coloured per vertex is not needed: pair legs apart
        plain = [b for b in legs if b.name not in highlight]
        if plain:
            builder.add(
                "legs",
                LINE_LIST,
                LEG,
                scale=(LINE_WIDTH, 0.0, 0.0),
                points=np.vstack([b.points for b in plain]),
                marker_id=0,
            )
        for body in legs:
            if body.name in highlight:
                builder.add(
                    "legs",
                    LINE_LIST,
                    highlight[body.name],
                    scale=(2 * LINE_WIDTH, 0, 0),
                    points=body.points,
                    marker_id=int(body.name.split()[1]),
                )
    else:
        for body in legs:
            builder._ids["legs"] = int(body.name.split()[1])
            _solid(builder, "legs", body, highlight.get(body.name, LEG))
    for body in view.bodies:
        if body.name.startswith("leg "):
            continue
        if body.moving:
            namespace = body.name  # "platform" or "tool"
            colour = PLATFORM if body.name == "platform" else MACHINE
        else:
            namespace, colour = "obstacles", OBSTACLE
            top = body.centre + np.array(
                [0.0, 0.0, max(body.size[2], body.length, 2 * body.radius)]
            )
            builder.add(
                "labels",
                TEXT_VIEW_FACING,
                TEXT,
                centre=top,
                scale=(0.0, 0.0, TEXT_HEIGHT),
                text=body.name,
            )
        _solid(builder, namespace, body, highlight.get(body.name, colour))
    if pair is not None:
        colour = VIOLATED if pair.violated else CLOSEST
        builder.add(
            "closest_pair", LINE_LIST, colour, scale=(LINE_WIDTH, 0.0, 0.0), points=pair.points
        )
        state = "VIOLATED " if pair.violated else ""
        builder.add(
            "closest_pair",
            TEXT_VIEW_FACING,
            colour,
            centre=pair.points.mean(axis=0) + np.array([0.0, 0.0, TEXT_HEIGHT]),
            scale=(0.0, 0.0, TEXT_HEIGHT),
            text=f"{state}{pair.name}: {1000.0 * pair.margin:.1f} mm",
        )
    if view.cone is not None:
        builder.add(
            "tool_directions", TRIANGLE_LIST, CONE, points=view.cone.triangles().reshape(-1, 3)
        )
    return {"markers": builder.finish()}
