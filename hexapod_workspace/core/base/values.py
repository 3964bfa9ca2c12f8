"""Parameter values as the model and the cell read them: numbers, vectors, joint arrays, axes.

Every reader refuses, in one line naming the parameter, what it expected and what it got
(:class:`~hexapod_workspace.errors.ConfigError` for values that are not numbers,
:class:`~hexapod_workspace.errors.GeometryError` for numbers of the wrong count or range).
Lengths are in m, angles in rad; arrays come back C-contiguous float64.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...errors import ConfigError, GeometryError
from .resolution import MAX_POSITION_NORM
from .rotations import tt_to_matrix

__all__ = [
    "active_tool_group",
    "angles3",
    "bounded_lengths",
    "cell_transform",
    "describe",
    "frozen",
    "joint_array",
    "numbers",
    "per_leg",
    "tool_number",
    "unit_axes",
    "unknown_tool",
    "vector3",
]


def describe(value: Any) -> str:
    """``repr(value)``, cut to 60 characters, for a message."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def numbers(name: str, value: Any) -> NDArray[np.float64]:
    """A flat float array from a parameter value, refusing non-numbers and non-finite values."""
    if isinstance(value, (str, bytes)) or value is None:
        msg = f"{name}: expected numbers, got {describe(value)}"
        raise ConfigError(msg)
    items = list(np.ravel(np.asarray(value, dtype=object))) if np.ndim(value) else [value]
    for item in items:
        if isinstance(item, (bool, np.bool_)) or not isinstance(item, (int, float, np.number)):
            msg = f"{name}: expected numbers, got {describe(value)}"
            raise ConfigError(msg)
    array = np.asarray(items, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        msg = f"{name}: expected finite numbers, got {describe(value)}"
        raise ConfigError(msg)
    return array


def bounded_lengths(name: str, array: NDArray[np.float64]) -> NDArray[np.float64]:
    """Refuse lengths (m) beyond MAX_POSITION_NORM, where margins would stop being finite."""
    if array.size and float(np.max(np.abs(array))) > MAX_POSITION_NORM:
        shown = describe(array.tolist())
        msg = f"{name}: expected values within ±{MAX_POSITION_NORM:g} m, got {shown}"
        raise GeometryError(msg)
    return array


def joint_array(name: str, value: Any) -> NDArray[np.float64]:
    """Six joint centres, shape (6, 3), m, from 18 numbers (x, y, z of joint 1 first)."""
    array = bounded_lengths(name, numbers(name, value))
    if array.size != 18:
        msg = f"{name}: expected 18 numbers (6 joints × x, y, z), got {array.size}"
        raise GeometryError(msg)
    return array.reshape(6, 3)


def vector3(name: str, value: Any) -> NDArray[np.float64]:
    """A position, shape (3,), m, within ±MAX_POSITION_NORM."""
    array = bounded_lengths(name, numbers(name, value))
    if array.size != 3:
        msg = f"{name}: expected 3 numbers (x, y, z), got {array.size}"
        raise GeometryError(msg)
    return array


def per_leg(name: str, value: Any) -> NDArray[np.float64]:
    """One value per leg, shape (6,), from 1 (shared by all) or 6 numbers."""
    array = numbers(name, value)
    if array.size not in (1, 6):
        msg = f"{name}: expected 1 or 6 numbers, got {array.size}"
        raise GeometryError(msg)
    return np.broadcast_to(array, (6,)).copy()


def unit_axes(name: str, value: Any) -> NDArray[np.float64] | None:
    """Six unit axes, shape (6, 3), from 18 numbers (normalised), or None for an empty list."""
    array = numbers(name, value)
    if array.size == 0:
        return None
    if array.size != 18:
        msg = f"{name}: expected 18 numbers (6 axes × x, y, z) or an empty list, got {array.size}"
        raise GeometryError(msg)
    axes = array.reshape(6, 3)
    norms = np.linalg.norm(axes, axis=1)
    zero = np.flatnonzero(norms < 1e-12)
    if zero.size:
        msg = f"{name}: expected non-zero axes, axis of joint {zero[0] + 1} is zero"
        raise GeometryError(msg)
    unit: NDArray[np.float64] = axes / norms[:, None]
    return unit


def angles3(name: str, value: Any) -> NDArray[np.float64]:
    """Three angles (φ, θ, ψ) in rad, within ±1e6 (the cell's frame orientations)."""
    array = numbers(name, value)
    if array.size != 3:
        msg = f"{name}: expected 3 numbers (phi, theta, psi) in rad, got {array.size}"
        raise ConfigError(msg)
    if float(np.max(np.abs(array))) > 1e6:
        msg = f"{name}: expected angles within ±1e6 rad, got {describe(array.tolist())}"
        raise ConfigError(msg)
    return array


def cell_transform(flat: Mapping[str, Any], group: str, offset: str) -> NDArray[np.float64]:
    """The 4×4 transform of the cell's ``tool`` (P <- C: ``offset``, ``orientation``) or
    ``work`` (O <- W: ``origin``, ``orientation``) frame, from its parameters (default zero),
    as :mod:`hexapod_workspace.core.cell.frames` reads them."""
    transform = np.eye(4)
    transform[:3, 3] = vector3(f"{group}.{offset}", flat.get(f"{group}.{offset}", [0.0] * 3))
    angles = angles3(f"{group}.orientation", flat.get(f"{group}.orientation", [0.0] * 3))
    transform[:3, :3] = tt_to_matrix(angles)
    return transform


def frozen(array: NDArray[np.float64]) -> NDArray[np.float64]:
    """The array as C-contiguous float64, made read-only (converted first when it is not one)."""
    array = np.ascontiguousarray(array, dtype=np.float64)
    array.setflags(write=False)
    return array


def tool_number(value: Any) -> int:
    """``tool.number`` as an int >= 0 (0: ``tool.*``, n: ``tools.T<n>.*``), else ConfigError."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        msg = f"tool.number: expected an integer >= 0 (0 = tool.offset), got {describe(value)}"
        raise ConfigError(msg)
    return int(value)


def unknown_tool(number: int, defined: Iterable[int]) -> ConfigError:
    """The refusal of a ``tool.number`` that names no entry of the tool table."""
    have = ", ".join(f"T{n}" for n in sorted(defined)) or "none"
    return ConfigError(
        f"tool.number: tool {number} is not in the tool table (tools.T<n>; defined: {have})"
    )


def active_tool_group(flat: Mapping[str, Any]) -> tuple[str, str]:
    """The parameter group and offset name of the tool ``tool.number`` selects: ``("tool",
    "offset")`` for 0, ``("tools.T<n>", "offset")`` for n (ConfigError naming ``tool.number``
    otherwise, worded as the cell's loader words it)."""
    number = tool_number(flat.get("tool.number", 0))
    if number == 0:
        return "tool", "offset"
    group = f"tools.T{number}"
    if f"{group}.offset" not in flat:
        tags = {name.split(".")[1][1:] for name in flat if name.startswith("tools.T")}
        raise unknown_tool(number, (int(tag) for tag in tags if tag.isdigit()))
    return group, "offset"
