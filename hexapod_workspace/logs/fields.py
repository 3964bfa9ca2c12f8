"""Plain field dicts <-> messages of the type store, and CDR (de)serialisation.

The logs layer builds every message from a mapping of field values (numpy arrays allowed), so
nothing here needs rclpy; :func:`message_to_fields` turns a decoded message back into dicts.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from rosbags.interfaces import (
    Nodetype,
)

from .typestore import _DTYPES, _EMPTY_FIELD, get_typestore, store_name

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore


# --------------------------------------------------------------------------- dicts <-> messages


def _default(desc: tuple[int, Any], store: Typestore) -> Any:
    nodetype, detail = desc
    if nodetype == Nodetype.BASE:
        typename = detail[0]
        return "" if typename == "string" else _DTYPES[typename](0).item()
    if nodetype == Nodetype.NAME:
        return build_message(detail, {}, store=store)
    (subtype, subdetail), length = detail
    if nodetype == Nodetype.ARRAY:
        if subtype == Nodetype.BASE and subdetail[0] != "string":
            return np.zeros(length, dtype=_DTYPES[subdetail[0]])
        return [_default((subtype, subdetail), store) for _ in range(length)]
    if subtype == Nodetype.BASE and subdetail[0] != "string":
        return np.zeros(0, dtype=_DTYPES[subdetail[0]])
    return []


def _convert(desc: tuple[int, Any], value: Any, store: Typestore) -> Any:
    nodetype, detail = desc
    if nodetype == Nodetype.BASE:
        return value
    if nodetype == Nodetype.NAME:
        return (
            value if not isinstance(value, Mapping) else build_message(detail, value, store=store)
        )
    (subtype, subdetail), _ = detail
    if subtype == Nodetype.BASE and subdetail[0] != "string":
        if isinstance(value, bytes | bytearray | memoryview):
            return np.frombuffer(value, dtype=_DTYPES[subdetail[0]])
        return np.asarray(value, dtype=_DTYPES[subdetail[0]])
    return [_convert((subtype, subdetail), item, store) for item in value]


def build_message(
    msgtype: str, fields: Mapping[str, Any], *, store: Typestore | None = None
) -> Any:
    """Build a rosbags message object from a nested dict keyed by ROS field names.

    Missing fields take ROS defaults (0, "", empty arrays, default sub-messages). Nested
    messages are dicts, message arrays are lists of dicts, numeric arrays anything
    :func:`numpy.asarray` takes (``bytes`` for ``uint8[]``).

    Parameters
    ----------
    msgtype : str
        E.g. ``"hexapod_workspace_msgs/msg/WorkspaceSummary"``.
    fields : mapping
        Field values by name.
    store : Typestore, optional
        Defaults to :func:`get_typestore`.

    Raises
    ------
    KeyError
        Unknown type or a field the type does not have.
    """
    store = store if store is not None else get_typestore()
    msgtype = store_name(msgtype)
    if msgtype not in store.fielddefs:
        msg = f"unknown ROS type {msgtype!r}"
        raise KeyError(msg)
    field_descs = store.fielddefs[msgtype][1]
    known = {name for name, _ in field_descs}
    unknown = set(fields) - known
    if unknown:
        msg = f"{msgtype} has no field(s) {sorted(unknown)}; fields are {sorted(known)}"
        raise KeyError(msg)
    values = {
        name: _convert(desc, fields[name], store) if name in fields else _default(desc, store)
        for name, desc in field_descs
    }
    return store.types[msgtype](**values)


def serialize(msgtype: str, fields: Mapping[str, Any] | Any) -> memoryview:
    """Serialise a message (a field dict or a rosbags message object) to little-endian CDR.

    Returns a read-only bytes-like view (no copy of large payloads); ``bytes(...)`` it to keep.
    """
    store = get_typestore()
    message = build_message(msgtype, fields, store=store) if isinstance(fields, Mapping) else fields
    return store.serialize_cdr(message, store_name(msgtype)).toreadonly()


def deserialize(msgtype: str, data: bytes | memoryview) -> Any:
    """Decode CDR bytes into a rosbags message object (dataclass with numpy arrays)."""
    return get_typestore().deserialize_cdr(data, store_name(msgtype))


def message_to_fields(message: Any) -> Any:
    """Turn a decoded message (rosbags dataclass, or anything with ``get_fields_and_field_types``)
    into nested dicts and lists; numeric arrays stay numpy arrays."""
    if dataclasses.is_dataclass(message) and not isinstance(message, type):
        return {
            f.name: message_to_fields(getattr(message, f.name))
            for f in dataclasses.fields(message)
            # constants are upper case; rosbags adds __msgtype__
            if f.name != _EMPTY_FIELD and not f.name.startswith("__") and not f.name.isupper()
        }
    if hasattr(message, "get_fields_and_field_types"):  # an rclpy message
        return {
            name: message_to_fields(getattr(message, name))
            for name in message.get_fields_and_field_types()
        }
    if isinstance(message, list | tuple):
        return [message_to_fields(item) for item in message]
    return message
