"""rclpy messages from the ROS-free field dicts of :mod:`hexapod_workspace.logs.messages`, and back.

:mod:`hexapod_workspace.logs.messages` is the single mapping from core results to message fields
(nested dicts keyed by ROS field names). This module only moves those dicts into generated rclpy
message classes (:func:`to_message`) and reads request messages into numpy arrays. No per-point
Python loop touches a point cloud: ``PointCloud2.data`` is assigned as one
``array.array("B", bytes)`` (assigning a numpy array or memoryview there takes seconds for 10^6
points in rclpy).

Units and frames are those of the messages: SI (m, rad), positions in the base frame.
"""

from __future__ import annotations

import array
import functools
import importlib
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray
from rosidl_parser.definition import AbstractSequence, Array, BasicType, NamespacedType

__all__ = [
    "angles_from_orientations",
    "margins_by_name",
    "message_class",
    "position_from_point",
    "to_message",
    "type_name",
]


@functools.cache
def _message_class(namespaced: tuple[str, ...]) -> type:
    """The generated class of a namespaced type, e.g. ``("geometry_msgs", "msg", "Point")``."""
    *namespaces, name = namespaced
    return getattr(importlib.import_module(".".join(namespaces)), name)


@functools.cache
def _slots(message_class: type) -> dict[str, Any]:
    """Field name -> rosidl type of a generated message class."""
    generated: Any = message_class  # rosidl's generated classes carry no type information
    names = generated.get_fields_and_field_types().keys()
    return dict(zip(names, generated.SLOT_TYPES, strict=True))


def _namespaced_class(definition: NamespacedType) -> type:
    return _message_class((*definition.namespaces, definition.name))


def message_class(msgtype: str) -> type:
    """The generated rclpy class of ``pkg/msg/Type``, ``pkg/srv/Name`` or ``pkg/srv/Name_Request``.

    Raises ImportError or AttributeError when the type is not available in this ROS environment.
    """
    package, kind, name = msgtype.split("/")
    if kind == "srv" and name.endswith(("_Request", "_Response")):
        service, _, part = name.rpartition("_")
        return getattr(_message_class((package, kind, service)), part)
    return _message_class((package, kind, name))


def type_name(message_class: type) -> str:
    """``pkg/msg/Type`` of a generated message class (inverse of :func:`message_class`)."""
    package, kind = message_class.__module__.split(".")[:2]
    return f"{package}/{kind}/{message_class.__name__}"


def _plain(value: Any) -> Any:
    return value.item() if isinstance(value, np.generic) else value


def _octets(value: Any) -> Any:
    # the fast path for PointCloud2.data (bytes in the dict form)
    return array.array("B", bytes(value))


def _numbers(value: Any) -> Any:
    return value.tolist() if isinstance(value, np.ndarray) else list(value)


def _converter(definition: Any) -> Any:
    """The function that turns a dict-form value of a field of type ``definition`` into what
    the rclpy message accepts."""
    if isinstance(definition, NamespacedType):
        nested = _namespaced_class(definition)
        return functools.partial(to_message, nested)
    if isinstance(definition, (AbstractSequence, Array)):
        element = definition.value_type
        if isinstance(element, NamespacedType):
            element_class = _namespaced_class(element)
            return lambda value: [to_message(element_class, item) for item in value]
        if isinstance(element, BasicType) and element.typename in ("uint8", "octet"):
            return _octets
        return _numbers
    return _plain


@functools.cache
def _converters(message_class: type) -> dict[str, Any]:
    """Field name -> converter of a generated message class (built once per class)."""
    return {name: _converter(definition) for name, definition in _slots(message_class).items()}


def to_message(message_class: type, fields: Mapping[str, Any] | Any) -> Any:
    """Build an rclpy message of ``message_class`` from a field dict.

    Parameters
    ----------
    message_class : type
        A generated message (or service request/response) class, e.g.
        ``hexapod_workspace_msgs.msg.PoseCheck``.
    fields : Mapping or message
        Nested dict keyed by field names, as returned by :mod:`hexapod_workspace.logs.messages`
        (nested messages as dicts, message sequences as lists of dicts, ``uint8[]`` as
        ``bytes``). Missing fields keep their defaults. A message instance of the right class is
        returned unchanged.

    Returns
    -------
    message_class instance

    Raises
    ------
    KeyError
        A field the message does not have.
    """
    if isinstance(fields, message_class):
        return fields
    converters = _converters(message_class)
    message = message_class()
    for name, value in fields.items():
        setattr(message, name, converters[name](value))
    return message


def angles_from_orientations(orientations: Sequence[Any]) -> NDArray[np.float64]:
    """Tilt-and-Torsion angles of ``TiltTorsion`` messages as an array.

    Parameters
    ----------
    orientations : sequence of hexapod_workspace_msgs/msg/TiltTorsion
        Each with ``phi``, ``theta``, ``psi`` in rad.

    Returns
    -------
    ndarray, shape (N, 3)
        Columns φ, θ, ψ, rad (not validated: NaN stays NaN, the core refuses it).
    """
    flat = [value for o in orientations for value in (o.phi, o.theta, o.psi)]
    return np.array(flat, dtype=np.float64).reshape(-1, 3)


def position_from_point(point: Any) -> NDArray[np.float64]:
    """A ``geometry_msgs/msg/Point`` as an array of shape (3,), m, base frame."""
    return np.array((point.x, point.y, point.z), dtype=np.float64)


def margins_by_name(pose_check: Any) -> dict[str, float]:
    """The margins of a ``hexapod_workspace_msgs/msg/PoseCheck`` (message or field dict) by
    constraint name: ``{"leg_length": m, "base_joint": rad, ...}``, in message order.

    Raises
    ------
    ValueError
        ``constraint_names`` and ``margins`` differ in length (a malformed message).
    """
    if isinstance(pose_check, Mapping):
        names, values = pose_check["constraint_names"], pose_check["margins"]
    else:
        names, values = pose_check.constraint_names, pose_check.margins
    names, values = list(names), [float(value) for value in values]
    if len(names) != len(values):
        msg = (
            f"PoseCheck: expected as many margins as constraint_names, got {len(values)} "
            f"margins for {len(names)} names"
        )
        raise ValueError(msg)
    return dict(zip(names, values, strict=True))
