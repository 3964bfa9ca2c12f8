"""Parameters of the collision scene: ``collision.*``, validated as a whole.

ROS parameters cannot hold a list of maps, so obstacles are a list of names plus one group per
name (the pattern ros2_control uses)::

    collision:
      clearance: 0.005                 # m, subtracted from every pair's distance
      platform: {radius: 0.33, z_min: 0.08, z_max: 0.14}   # m, platform frame, about z
      tool: {radius: 0.04, length: 0.25}                   # m, from C along +z of the tool
      obstacles:
        names: [vise, column]
        vise:
          shape: box                   # box | cylinder | sphere | capsule
          frame: work                  # base | work
          position: [0.0, 0.0, -1.75]  # m, centre, in that frame
          orientation: [0.0, 0.0, 0.0] # roll, pitch, yaw (rad, R = Rz Ry Rx) or x, y, z, w
          size: [0.3, 0.2, 0.1]        # box: full edge lengths along its local x, y, z, m
        column:
          shape: cylinder
          position: [0.9, 0.0, -1.0]
          radius: 0.1                  # cylinder, capsule, sphere, m
          length: 1.5                  # cylinder, capsule: along the local z axis, centred, m

The platform body exists when ``collision.platform.radius`` > 0, the tool body when
``collision.tool.length`` > 0 (a zero radius makes it a line); half a body (a z range without
a radius, a tool radius without a length) is refused; ``frame`` defaults to ``base`` and
``orientation`` to the identity. Every error is one line naming the parameter, what was
expected and what was given, raised before anything is built.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ....errors import ConfigError
from ...base.params import flatten, unknown_parameter
from ...base.resolution import MAX_POSITION_NORM
from .distance import BOX, CYLINDER, POINT, SEGMENT, record

__all__ = [
    "OBSTACLE_FRAMES",
    "OBSTACLE_SHAPES",
    "CollisionScene",
    "Obstacle",
    "PlatformBody",
    "ToolBody",
    "collision_scene",
]

#: Shapes an obstacle may have, and the size parameters each needs.
OBSTACLE_SHAPES: dict[str, tuple[str, ...]] = {
    "box": ("size",),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "capsule": ("radius", "length"),
}
#: Frames an obstacle may be given in.
OBSTACLE_FRAMES = ("base", "work")
_OBSTACLE_KEYS = ("shape", "frame", "position", "orientation", "size", "radius", "length")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class PlatformBody:
    """The platform cylinder, platform frame, about z: radius and z range, m."""

    radius: float
    z_min: float
    z_max: float


@dataclass(frozen=True)
class ToolBody:
    """The tool/spindle capsule: radius and length from C along +z of the tool frame, m."""

    radius: float
    length: float


@dataclass(frozen=True)
class Obstacle:
    """An obstacle as given and as placed in the base frame.

    Attributes
    ----------
    name : str
    shape : str
        ``box``, ``cylinder``, ``sphere`` or ``capsule``.
    frame : str
        ``base`` or ``work`` (the frame ``position`` and ``orientation`` are given in).
    position : ndarray, shape (3,)
        Centre in ``frame``, m.
    rotation : ndarray, shape (3, 3)
        Local -> ``frame``.
    dimensions : tuple of float
        ``size`` (3 full edge lengths), or (radius, length), or (radius,), m.
    record : ndarray, shape (RECORD_SIZE,)
        The body in the base frame (:mod:`.distance`).
    """

    name: str
    shape: str
    frame: str
    position: NDArray[np.float64]
    rotation: NDArray[np.float64]
    dimensions: tuple[float, ...]
    record: NDArray[np.float64] = field(repr=False)


@dataclass(frozen=True, eq=False)
class CollisionScene:
    """Everything the ``collision`` margin needs besides the manipulator.

    Attributes
    ----------
    clearance : float
        m, subtracted from every pair's distance.
    platform : PlatformBody or None
    tool : ToolBody or None
    obstacles : tuple of Obstacle
    tool_transform : ndarray, shape (4, 4)
        Mobile frame <- tool frame; the identity unless the cell's tool frame is set.
    platform_transform : ndarray, shape (4, 4)
        Mobile frame <- platform frame P (where the platform cylinder is given); the identity
        for a model in P, ``T_CP`` for a model that answers for tool-frame poses
        (:meth:`in_tool_frame`).
    parameters : dict
        The ``collision.*`` parameters the scene was built from (dotted names), so that a model
        gives them back (``Manipulator.to_parameters``).
    """

    clearance: float = 0.0
    platform: PlatformBody | None = None
    tool: ToolBody | None = None
    obstacles: tuple[Obstacle, ...] = ()
    tool_transform: NDArray[np.float64] = field(default_factory=lambda: np.eye(4), repr=False)
    platform_transform: NDArray[np.float64] = field(default_factory=lambda: np.eye(4), repr=False)
    parameters: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    @property
    def empty(self) -> bool:
        """No pair to check apart from legs (no tool and no obstacle)."""
        return self.tool is None and not self.obstacles

    @property
    def pair_count(self) -> int:
        """Number of pairs the scene checks (0: the ``collision`` constraint does not exist)."""
        tool = 6 if self.tool is not None else 0
        moving = 6 + (self.tool is not None) + (self.platform is not None)
        return tool + moving * len(self.obstacles)

    def in_tool_frame(self, tool_transform: NDArray[np.float64]) -> CollisionScene:
        """The scene of a model whose mobile frame is the tool frame C.

        Parameters
        ----------
        tool_transform : ndarray, shape (4, 4)
            P <- C of the selected tool. The tool body follows that tool (it starts at C), the
            platform stays where it is on P: its transform becomes ``T_CP = T_PC⁻¹``.
        """
        inverse = np.eye(4)
        inverse[:3, :3] = tool_transform[:3, :3].T
        inverse[:3, 3] = -tool_transform[:3, :3].T @ tool_transform[:3, 3]
        from dataclasses import replace

        return replace(
            self, tool_transform=np.eye(4), platform_transform=inverse @ self.platform_transform
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, CollisionScene):
            return NotImplemented
        return (
            self.clearance == other.clearance
            and self.platform == other.platform
            and self.tool == other.tool
            and len(self.obstacles) == len(other.obstacles)
            and all(
                a.name == b.name and np.array_equal(a.record, b.record)
                for a, b in zip(self.obstacles, other.obstacles, strict=True)
            )
            and np.array_equal(self.tool_transform, other.tool_transform)
            and np.array_equal(self.platform_transform, other.platform_transform)
        )

    __hash__ = None  # type: ignore[assignment]


def _describe(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _number(
    name: str, value: Any, *, minimum: float | None = None, positive: bool = False
) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
        msg = f"{name}: expected a number, got {_describe(value)}"
        raise ConfigError(msg)
    number = float(value)
    if not math.isfinite(number):
        msg = f"{name}: expected a finite number, got {_describe(value)}"
        raise ConfigError(msg)
    if abs(number) > MAX_POSITION_NORM:
        msg = f"{name}: expected a value within ±{MAX_POSITION_NORM:g} m, got {number!r}"
        raise ConfigError(msg)
    if positive and not number > 0.0:
        msg = f"{name}: expected a positive length (m), got {number!r}"
        raise ConfigError(msg)
    if minimum is not None and number < minimum:
        msg = f"{name}: expected a value ≥ {minimum:g} m, got {number!r}"
        raise ConfigError(msg)
    return number


def _numbers(name: str, value: Any, counts: tuple[int, ...], what: str) -> NDArray[np.float64]:
    if isinstance(value, (str, bytes, Mapping)) or value is None or np.ndim(value) != 1:
        msg = f"{name}: expected {what}, got {_describe(value)}"
        raise ConfigError(msg)
    items = list(value)
    if len(items) not in counts:
        msg = f"{name}: expected {what}, got {len(items)} values {_describe(value)}"
        raise ConfigError(msg)
    return np.array([_number(name, item) for item in items])


def _rotation(name: str, value: Any) -> NDArray[np.float64]:
    """Rotation from roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll), as URDF) or x, y, z, w."""
    numbers = _numbers(
        name, value, (3, 4), "3 angles (roll, pitch, yaw, rad) or a quaternion (x, y, z, w)"
    )
    if numbers.size == 3:
        roll, pitch, yaw = numbers
        cr, sr = math.cos(roll), math.sin(roll)
        cp, sp = math.cos(pitch), math.sin(pitch)
        cy, sy = math.cos(yaw), math.sin(yaw)
        return np.array(
            [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ]
        )
    norm = float(np.linalg.norm(numbers))
    if not abs(norm - 1.0) <= 1e-6:
        msg = f"{name}: expected a unit quaternion (x, y, z, w), got norm {norm:.6g}"
        raise ConfigError(msg)
    x, y, z, w = numbers / norm
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _transform(name: str, value: Any) -> NDArray[np.float64]:
    transform = np.asarray(value, dtype=np.float64)
    rotation = transform[:3, :3] if transform.shape == (4, 4) else None
    if (
        rotation is None
        or not np.all(np.isfinite(transform))
        or not np.allclose(transform[3], [0.0, 0.0, 0.0, 1.0])
        or not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-9)
        or not np.linalg.det(rotation) > 0.0
    ):
        msg = f"{name}: expected a 4×4 rigid transform (rotation, translation in m)"
        raise ConfigError(msg)
    return transform


def _obstacle(name: str, group: Mapping[str, Any], work: NDArray[np.float64]) -> Obstacle:
    prefix = f"collision.obstacles.{name}"
    unknown = sorted(set(group) - set(_OBSTACLE_KEYS))
    if unknown:
        msg = (
            f"{prefix}.{unknown[0]}: unknown parameter "
            f"(expected one of {', '.join(_OBSTACLE_KEYS)})"
        )
        raise ConfigError(msg)
    shape = group.get("shape")
    if shape not in OBSTACLE_SHAPES:
        msg = (
            f"{prefix}.shape: expected one of {', '.join(OBSTACLE_SHAPES)}, got {_describe(shape)}"
        )
        raise ConfigError(msg)
    frame = group.get("frame", "base")
    if frame not in OBSTACLE_FRAMES:
        msg = (
            f"{prefix}.frame: expected one of {', '.join(OBSTACLE_FRAMES)}, got {_describe(frame)}"
        )
        raise ConfigError(msg)
    if "position" not in group:
        msg = f"{prefix}.position: missing (expected the centre x, y, z in m, {frame} frame)"
        raise ConfigError(msg)
    position = _numbers(f"{prefix}.position", group["position"], (3,), "3 numbers (x, y, z, m)")
    rotation = (
        _rotation(f"{prefix}.orientation", group["orientation"])
        if "orientation" in group
        else np.eye(3)
    )
    needed = OBSTACLE_SHAPES[shape]
    for key in ("size", "radius", "length"):
        if key in group and key not in needed:
            msg = (
                f"{prefix}.{key}: not a parameter of a {shape} "
                f"(a {shape} has {' and '.join(needed)})"
            )
            raise ConfigError(msg)
        if key not in group and key in needed:
            msg = f"{prefix}.{key}: missing (a {shape} needs {' and '.join(needed)}, in m)"
            raise ConfigError(msg)
    if shape == "box":
        size = _numbers(f"{prefix}.size", group["size"], (3,), "3 full edge lengths (x, y, z, m)")
        for value in size:
            _number(f"{prefix}.size", float(value), positive=True)
        dimensions: tuple[float, ...] = tuple(float(v) for v in size)
    else:
        dimensions = (_number(f"{prefix}.radius", group["radius"], positive=True),)
        if "length" in needed:
            dimensions += (_number(f"{prefix}.length", group["length"], positive=True),)
    if frame == "work":
        rotation_base = work[:3, :3] @ rotation
        centre = work[:3, :3] @ position + work[:3, 3]
    else:
        rotation_base, centre = rotation, position
    if shape == "box":
        half = (0.5 * dimensions[0], 0.5 * dimensions[1], 0.5 * dimensions[2])
        body = record(BOX, centre, rotation_base, half)
    elif shape == "cylinder":
        body = record(CYLINDER, centre, rotation_base, (dimensions[0], 0.5 * dimensions[1], 0.0))
    elif shape == "capsule":
        body = record(
            SEGMENT, centre, rotation_base, (0.5 * dimensions[1], 0.0, 0.0), dimensions[0]
        )
    else:
        body = record(POINT, centre, rotation_base, (0.0, 0.0, 0.0), dimensions[0])
    body.setflags(write=False)
    return Obstacle(name, shape, frame, position, rotation, dimensions, body)


def collision_scene(
    parameters: Mapping[str, Any],
    *,
    work_transform: Any = None,
    tool_transform: Any = None,
) -> CollisionScene:
    """Build and validate the collision scene from parameters.

    Parameters
    ----------
    parameters : Mapping
        Nested or dotted parameters (the shape :func:`hexapod_workspace.core.base.params.flatten`
        takes); only the ``collision.`` names are read, every one of them must be known.
    work_transform : array_like, shape (4, 4), optional
        Base frame <- work frame (rotation, translation in m), for obstacles with
        ``frame: work``; default the identity (work frame = base frame).
    tool_transform : array_like, shape (4, 4), optional
        Platform (mobile) frame <- tool frame; default the identity.

    Returns
    -------
    CollisionScene

    Raises
    ------
    ConfigError
        One line naming the parameter, what was expected and what was given: unknown shape or
        frame, missing or non-positive size, NaN, a misspelt name (the home pose is checked
        against the model by
        :func:`~hexapod_workspace.core.model.collision.scene.require_free_home`).
    """
    flat = {k: v for k, v in flatten(parameters).items() if k.startswith("collision.")}
    work = np.eye(4) if work_transform is None else _transform("work_transform", work_transform)
    tool_frame = (
        np.eye(4) if tool_transform is None else _transform("tool_transform", tool_transform)
    )
    names_value = flat.get("collision.obstacles.names", [])
    if isinstance(names_value, (str, bytes)) or np.ndim(names_value) != 1:
        msg = f"collision.obstacles.names: expected a list of names, got {_describe(names_value)}"
        raise ConfigError(msg)
    names = list(names_value)
    for name in names:
        if not isinstance(name, str) or not _NAME.match(name) or name == "names":
            msg = (
                "collision.obstacles.names: expected names of letters, digits and _ "
                f"(not 'names'), got {_describe(name)}"
            )
            raise ConfigError(msg)
    if len(set(names)) != len(names):
        repeated = next(name for name in names if names.count(name) > 1)
        msg = f"collision.obstacles.names: {repeated!r} is listed twice"
        raise ConfigError(msg)
    known = [
        "collision.clearance",
        "collision.platform.radius",
        "collision.platform.z_min",
        "collision.platform.z_max",
        "collision.tool.radius",
        "collision.tool.length",
        "collision.obstacles.names",
        *(f"collision.obstacles.{name}." for name in names),
    ]
    problem = unknown_parameter(flat, known)
    if problem is not None:
        raise ConfigError(problem)
    clearance = _number("collision.clearance", flat.get("collision.clearance", 0.0), minimum=0.0)

    platform = None
    radius = _number(
        "collision.platform.radius", flat.get("collision.platform.radius", 0.0), minimum=0.0
    )
    if radius > 0.0:
        z_range = []
        for key in ("z_min", "z_max"):
            name = f"collision.platform.{key}"
            if name not in flat:
                msg = f"{name}: missing (needed when collision.platform.radius > 0), in m"
                raise ConfigError(msg)
            z_range.append(_number(name, flat[name]))
        if not z_range[0] < z_range[1]:
            msg = (
                f"collision.platform.z_max: expected more than z_min = {z_range[0]!r} m, "
                f"got {z_range[1]!r}"
            )
            raise ConfigError(msg)
        platform = PlatformBody(radius, z_range[0], z_range[1])
    else:
        given = [k for k in ("z_min", "z_max") if f"collision.platform.{k}" in flat]
        if given:
            msg = (
                f"collision.platform.radius: expected a positive radius (m) with "
                f"collision.platform.{given[0]} given, got {radius!r}"
            )
            raise ConfigError(msg)

    tool = None
    length = _number("collision.tool.length", flat.get("collision.tool.length", 0.0), minimum=0.0)
    tool_radius = _number(
        "collision.tool.radius", flat.get("collision.tool.radius", 0.0), minimum=0.0
    )
    if length > 0.0:
        tool = ToolBody(tool_radius, length)
    elif tool_radius > 0.0:
        msg = (
            "collision.tool.length: expected a positive length (m) with collision.tool.radius "
            f"{tool_radius!r}, got {length!r}"
        )
        raise ConfigError(msg)

    obstacles = []
    for name in names:
        prefix = f"collision.obstacles.{name}."
        group = {k[len(prefix) :]: v for k, v in flat.items() if k.startswith(prefix)}
        if not group:
            msg = f"collision.obstacles.{name}: listed in collision.obstacles.names but not given"
            raise ConfigError(msg)
        obstacles.append(_obstacle(name, group, work))
    scene = CollisionScene(
        clearance, platform, tool, tuple(obstacles), tool_frame, parameters=dict(flat)
    )
    return scene
