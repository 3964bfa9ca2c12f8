"""What the machine looks like at one pose: bodies, the closest pair, the cone of tool directions.

One description of the scene for everyone who draws it: the node's ``~/markers``
(:mod:`hexapod_workspace.logs.markers` turns it into a ``visualization_msgs/MarkerArray``) and the
CLI's scene plots (:mod:`hexapod_workspace.cli.scene_plot`). numpy only; base frame, m.

Bodies
    Always the machine: the six legs (segments from
    :func:`~hexapod_workspace.core.model.legs.leg_endpoints`, so a leg architecture whose base
    joints move is drawn where it is; capsules of
    ``limits.leg_diameter``, lines when it is 0), the platform and the tool. With a collision
    scene (:class:`~hexapod_workspace.core.model.collision.CollisionScene`) the platform is its
    cylinder and the tool its capsule, and the obstacles are drawn; without one the platform is
    the polygon of its joints and the tool the line from the tool centre point C along the tool
    axis z' to the plane of the platform joints.
Closest pair
    The pair with the smallest margin among the collision scene's pairs (signed distance minus
    ``collision.clearance``, :func:`~hexapod_workspace.core.model.collision.scene_distances`) and
    the leg pairs of ``leg_interference`` (segment distance minus the leg diameter): the pair in
    violation when there is one, else the closest. Its margin is the certified one of those
    functions. The two points drawn between the bodies are found by alternating projections
    onto the two convex bodies (Cheney and Goldstein: they converge to a closest pair of points
    of disjoint convex sets, and to a common point of overlapping ones); they are for the
    picture only, never for a verdict.
Cone
    The attainable tool directions at the tool centre point: the boundary directions of a
    projected workspace (:func:`~hexapod_workspace.core.workspaces.projected.projected_workspace`)
    drawn as a cone from C along the approach vectors, the side of the tool.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError
from ..model.collision.distance import _C, _INFLATION, _P, _R, BOX, CYLINDER, POINT, SEGMENT
from ..model.collision.scene import scene_distances
from ..model.legs import leg_endpoints

if TYPE_CHECKING:
    from ..model.collision.params import CollisionScene
    from ..model.manipulator import Manipulator
    from ..workspaces.projected import ProjectedWorkspace

__all__ = ["Body", "ClosestPair", "Cone", "SceneView", "cone_of", "scene_view"]

#: Alternating projections made to place the closest points of the drawn pair.
PROJECTION_STEPS = 400


@dataclass(frozen=True)
class Body:
    """One body as drawn, base frame, m.

    Attributes
    ----------
    name : str
        ``"leg 1"`` … ``"leg 6"``, ``"platform"``, ``"tool"`` or the obstacle's name.
    kind : str
        ``"segment"`` (a capsule of ``radius`` around ``points[0]``–``points[1]``; a line when
        the radius is 0), ``"cylinder"``, ``"box"``, ``"sphere"`` or ``"polygon"`` (a flat
        closed polygon through ``points``).
    centre : ndarray, shape (3,)
    rotation : ndarray, shape (3, 3)
        Local -> base frame; a cylinder's axis is the local z.
    radius : float
        Capsule, cylinder or sphere radius (0 for a box, a line or a polygon).
    length : float
        Cylinder length along its axis, capsule core length.
    size : ndarray, shape (3,)
        Box full edge lengths (zeros for other kinds).
    points : ndarray, shape (k, 3)
        Segment ends (k = 2) or polygon vertices; empty for the solids.
    moving : bool
        Attached to the machine (legs, platform, tool) rather than standing still.
    """

    name: str
    kind: str
    centre: NDArray[np.float64]
    rotation: NDArray[np.float64]
    radius: float = 0.0
    length: float = 0.0
    size: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    points: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 3)))
    moving: bool = True


@dataclass(frozen=True)
class ClosestPair:
    """The pair in violation, or the closest pair, at the pose.

    Attributes
    ----------
    name : str
        ``"tool vs leg 4"``, ``"leg 2 vs vise"``, ``"leg 1 vs leg 2"``: moving body first.
    first, second : str
        The two body names (:attr:`Body.name`).
    constraint : str
        ``"collision"`` or ``"leg_interference"``.
    margin : float
        m: signed distance minus the clearance (collision) or minus the leg diameter (legs);
        negative when violated.
    points : ndarray, shape (2, 3)
        A closest point on each body (for the picture), base frame, m.
    """

    name: str
    first: str
    second: str
    constraint: str
    margin: float
    points: NDArray[np.float64]

    @property
    def violated(self) -> bool:
        """The margin is negative."""
        return self.margin < 0.0


@dataclass(frozen=True)
class Cone:
    """The attainable tool directions at the tool centre point, as a cone.

    Attributes
    ----------
    apex : ndarray, shape (3,)
        Tool centre point C, base frame, m.
    directions : ndarray, shape (n, 3)
        Unit approach vectors of the boundary, in azimuth order, base frame.
    length : float
        Length of the drawn generatrices, m.
    method : str
        ``"torsion_zero"`` or ``"exact"`` (the projected workspace's).
    tilt_min, tilt_max : float
        Smallest and largest boundary tilt, rad.
    """

    apex: NDArray[np.float64]
    directions: NDArray[np.float64]
    length: float
    method: str
    tilt_min: float
    tilt_max: float

    def triangles(self) -> NDArray[np.float64]:
        """The cone's side as a triangle list (apex, rim k, rim k + 1), shape (n, 3, 3), m."""
        rim = self.apex + self.length * self.directions
        following = np.roll(rim, -1, axis=0)
        apex = np.broadcast_to(self.apex, rim.shape)
        return np.stack([apex, rim, following], axis=1)


@dataclass(frozen=True)
class SceneView:
    """Everything drawn at one pose.

    Attributes
    ----------
    position : ndarray, shape (3,)
        Tool centre point C, base frame, m.
    rotation : ndarray, shape (3, 3)
        Platform orientation (mobile -> base frame).
    bodies : tuple of Body
        Legs 1–6, platform, tool, then the obstacles in the scene's order.
    closest : ClosestPair or None
        None when no pair is checked (no obstacle, no tool body and a leg diameter of 0).
    cone : Cone or None
    has_scene : bool
        A collision scene was given (the platform and tool are its bodies).
    """

    position: NDArray[np.float64]
    rotation: NDArray[np.float64]
    bodies: tuple[Body, ...]
    closest: ClosestPair | None
    cone: Cone | None
    has_scene: bool

    def body(self, name: str) -> Body:
        """The body called ``name`` (KeyError naming it when there is none)."""
        for body in self.bodies:
            if body.name == name:
                return body
        raise KeyError(name)


def _segment(name: str, a: NDArray[np.float64], b: NDArray[np.float64], radius: float) -> Body:
    axis = b - a
    length = float(np.linalg.norm(axis))
    return Body(
        name=name,
        kind="segment",
        centre=0.5 * (a + b),
        rotation=_frame_of(axis),
        radius=radius,
        length=length,
        points=np.array([a, b]),
    )


def _frame_of(axis: NDArray[np.float64]) -> NDArray[np.float64]:
    """A rotation whose local z is ``axis`` (the identity for a zero axis)."""
    norm = float(np.linalg.norm(axis))
    if norm == 0.0:
        return np.eye(3)
    z = axis / norm
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _obstacle_body(name: str, record: NDArray[np.float64]) -> Body:
    """An obstacle from its record in the base frame (:mod:`.collision.distance`)."""
    kind = int(record[0])
    centre = record[_C : _C + 3].copy()
    rotation = record[_R : _R + 9].reshape(3, 3).copy()
    inflation = float(record[_INFLATION])
    if kind == POINT:
        return Body(name, "sphere", centre, rotation, radius=inflation, moving=False)
    if kind == SEGMENT:
        half = float(record[_P])
        axis = rotation[:, 2]
        ends = np.array([centre - half * axis, centre + half * axis])
        return Body(
            name,
            "segment",
            centre,
            rotation,
            radius=inflation,
            length=2.0 * half,
            points=ends,
            moving=False,
        )
    if kind == BOX:
        size = 2.0 * record[_P : _P + 3]
        return Body(name, "box", centre, rotation, size=size, moving=False)
    if kind == CYLINDER:
        radius, half = float(record[_P]), float(record[_P + 1])
        return Body(
            name, "cylinder", centre, rotation, radius=radius, length=2 * half, moving=False
        )
    msg = f"obstacle {name}: unknown body kind {kind}"
    raise InputError(msg)


def _machine_bodies(
    manipulator: Manipulator,
    rotation: NDArray[np.float64],
    position: NDArray[np.float64],
    scene: CollisionScene | None,
) -> list[Body]:
    base_ends, platform_ends = leg_endpoints(manipulator, rotation, position)
    leg_radius = 0.5 * manipulator.leg_diameter
    bodies = [
        _segment(f"leg {k + 1}", base_ends[0, k], platform_ends[0, k], leg_radius) for k in range(6)
    ]
    if scene is not None and scene.platform is not None:
        platform = scene.platform
        middle = np.array([0.0, 0.0, 0.5 * (platform.z_min + platform.z_max)])
        bodies.append(
            Body(
                "platform",
                "cylinder",
                position + rotation @ middle,
                rotation.copy(),
                radius=platform.radius,
                length=platform.z_max - platform.z_min,
            )
        )
    else:
        joints = platform_ends[0]
        bodies.append(
            Body("platform", "polygon", joints.mean(axis=0), rotation.copy(), points=joints)
        )
    if scene is not None and scene.tool is not None:
        transform = scene.tool_transform
        start = transform[:3, 3]
        end = start + transform[:3, :3] @ np.array([0.0, 0.0, scene.tool.length])
        bodies.append(
            _segment(
                "tool", position + rotation @ start, position + rotation @ end, scene.tool.radius
            )
        )
    else:
        height = float(np.mean(manipulator.platform_joints[:, 2]))
        end = position + rotation @ np.array([0.0, 0.0, height])
        bodies.append(_segment("tool", position.copy(), end, 0.0))
    return bodies


# ------------------------------------------------------------------ closest points
def _project(body: Body, x: NDArray[np.float64]) -> NDArray[np.float64]:
    """The point of the (convex) body nearest to x; x itself when inside."""
    if body.kind in ("segment", "sphere"):
        if body.kind == "segment":
            a, b = body.points
            ab = b - a
            denominator = float(ab @ ab)
            t = 0.0 if denominator == 0.0 else min(max(float((x - a) @ ab) / denominator, 0.0), 1.0)
            core = a + t * ab
        else:
            core = body.centre
        offset = x - core
        distance = float(np.linalg.norm(offset))
        if distance <= body.radius:
            return x
        projected: NDArray[np.float64] = core + body.radius * offset / distance
        return projected
    if body.kind == "polygon":  # a flat polygon: its projection is not needed (never paired)
        return body.centre.copy()
    local = body.rotation.T @ (x - body.centre)
    if body.kind == "box":
        local = np.clip(local, -0.5 * body.size, 0.5 * body.size)
    else:  # cylinder
        half = 0.5 * body.length
        local[2] = min(max(local[2], -half), half)
        radial = math.hypot(local[0], local[1])
        if radial > body.radius:
            local[:2] *= body.radius / radial
    return body.centre + body.rotation @ local


def closest_points(first: Body, second: Body) -> NDArray[np.float64]:
    """A pair of closest points of two convex bodies by alternating projections, shape (2, 3).

    For the picture only (see the module documentation); overlapping bodies give a common point
    twice.
    """
    b = second.centre.copy()
    a = _project(first, b)
    for _ in range(PROJECTION_STEPS):
        b_next = _project(second, a)
        a_next = _project(first, b_next)
        if np.allclose(a_next, a, rtol=0.0, atol=1e-12) and np.allclose(
            b_next, b, rtol=0.0, atol=1e-12
        ):
            a, b = a_next, b_next
            break
        a, b = a_next, b_next
    return np.array([a, b])


def _leg_pairs(
    bodies: list[Body], manipulator: Manipulator
) -> tuple[float, int, int, NDArray[np.float64]] | None:
    """Smallest leg-pair margin (segment distance − D), the two leg indices and the closest
    points; legs that share a joint are compared along their free lengths, as the
    ``leg_interference`` margin compares them (:func:`_free_lengths`)."""
    if manipulator.leg_diameter <= 0.0:
        return None
    best: tuple[float, int, int, NDArray[np.float64]] | None = None
    base, platform = manipulator.shared_base_pairs, manipulator.shared_platform_pairs
    pair = 0
    for i in range(6):
        for j in range(i + 1, 6):
            ends = (base[pair], platform[pair], manipulator.paired_joint_length)
            points = _segment_closest(
                _free_lengths(bodies[i].points, *ends), _free_lengths(bodies[j].points, *ends)
            )
            margin = float(np.linalg.norm(points[1] - points[0])) - manipulator.leg_diameter
            if best is None or margin < best[0]:
                best = (margin, i, j, points)
            pair += 1
    return best


def _free_lengths(
    leg: NDArray[np.float64], base: bool, platform: bool, length: float
) -> NDArray[np.float64]:
    """The segment A_iB_i (2, 3) without ``length`` (m) at a shared base or platform end (not
    past the other end): what ``leg_interference`` measures for legs that share a joint."""
    vector = leg[1] - leg[0]
    size = float(np.linalg.norm(vector))
    if not (base or platform) or size == 0.0:
        return leg
    start = min(length / size, 1.0) if base else 0.0
    end = max(1.0 - length / size, start) if platform else 1.0
    return np.array([leg[0] + start * vector, leg[0] + end * vector])


def _segment_closest(p: NDArray[np.float64], q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Closest points of segments p0p1 and q0q1 (Ericson, Real-Time Collision Detection §5.1.9)."""
    d1, d2, r = p[1] - p[0], q[1] - q[0], p[0] - q[0]
    a, e, f = float(d1 @ d1), float(d2 @ d2), float(d2 @ r)
    if a <= 1e-300 and e <= 1e-300:
        return np.array([p[0], q[0]])
    if a <= 1e-300:
        s, t = 0.0, min(max(f / e, 0.0), 1.0)
    else:
        c = float(d1 @ r)
        if e <= 1e-300:
            s, t = min(max(-c / a, 0.0), 1.0), 0.0
        else:
            b = float(d1 @ d2)
            denominator = a * e - b * b
            s = min(max((b * f - c * e) / denominator, 0.0), 1.0) if denominator > 0 else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                s, t = min(max(-c / a, 0.0), 1.0), 0.0
            elif t > 1.0:
                s, t = min(max((b - c) / a, 0.0), 1.0), 1.0
    return np.array([p[0] + s * d1, q[0] + t * d2])


def _closest_pair(
    manipulator: Manipulator,
    bodies: list[Body],
    scene: CollisionScene | None,
    rotation: NDArray[np.float64],
    position: NDArray[np.float64],
) -> ClosestPair | None:
    by_name = {body.name: body for body in bodies}
    candidates: list[ClosestPair] = []
    if scene is not None:
        result = scene_distances(manipulator, scene, rotation, position)
        name = result.pair_name(0)
        if name:
            first, second = name.split(" vs ", 1)
            points = closest_points(by_name[first], by_name[second])
            margin = float(result.margin[0])
            candidates.append(ClosestPair(name, first, second, "collision", margin, points))
    legs = _leg_pairs(bodies, manipulator)
    if legs is not None:
        margin, i, j, points = legs
        first, second = bodies[i].name, bodies[j].name
        candidates.append(
            ClosestPair(f"{first} vs {second}", first, second, "leg_interference", margin, points)
        )
    if not candidates:
        return None
    return min(candidates, key=lambda pair: pair.margin)


def scene_view(
    manipulator: Manipulator,
    rotation: ArrayLike,
    position: ArrayLike,
    scene: CollisionScene | None = None,
    *,
    cone: Cone | None = None,
) -> SceneView:
    """Describe the scene at one pose.

    Parameters
    ----------
    manipulator : Manipulator
    rotation : array_like, shape (3, 3)
        Platform orientation R (mobile -> base frame).
    position : array_like, shape (3,)
        Tool centre point C, base frame, m.
    scene : CollisionScene, optional
        The collision scene (platform, tool, obstacles); None draws the machine alone.
    cone : Cone, optional
        The attainable tool directions (:func:`cone_of`).

    Returns
    -------
    SceneView

    Raises
    ------
    InputError
        Wrong shapes, non-finite values.
    """
    r = np.asarray(rotation, dtype=np.float64)
    p = np.asarray(position, dtype=np.float64)
    if r.shape != (3, 3) or p.shape != (3,):
        msg = f"expected a (3, 3) rotation and a (3,) position, got {r.shape} and {p.shape}"
        raise InputError(msg)
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(p))):
        msg = f"pose: expected finite values, got position {p.tolist()}"
        raise InputError(msg)
    bodies = _machine_bodies(manipulator, r, p, scene)
    if scene is not None:
        bodies += [_obstacle_body(o.name, o.record) for o in scene.obstacles]
    closest = _closest_pair(manipulator, bodies, scene, r, p)
    return SceneView(p.copy(), r.copy(), tuple(bodies), closest, cone, scene is not None)


def cone_of(
    workspace: ProjectedWorkspace,
    manipulator: Manipulator,
    scene: CollisionScene | None = None,
) -> Cone:
    """The cone of a projected workspace, drawn from its position (the tool centre point).

    The generatrices are as long as the tool (with a scene that has one), else as the largest
    distance of a platform joint from C, so the cone reaches the platform.
    """
    length = float(np.max(np.linalg.norm(manipulator.platform_joints, axis=1)))
    if scene is not None and scene.tool is not None:
        length = max(length, scene.tool.length)
    return Cone(
        apex=np.asarray(workspace.position, dtype=np.float64).copy(),
        directions=workspace.approach_vectors(),
        length=length,
        method=workspace.method,
        tilt_min=workspace.tilt_min,
        tilt_max=workspace.tilt_max,
    )
