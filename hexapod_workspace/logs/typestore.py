"""The type store of the logs: rosbags' Jazzy store plus hexapod_workspace_msgs and std_srvs.

Schema text (``ros2msg``, full concatenated definitions), RIHS01 type hashes, the rosbag2 QoS
profile text of each channel, and how a service call is recorded.

How service calls are recorded
------------------------------
A call of service ``S`` is two messages: its request on ``S/request`` and its response on
``S/response`` (:func:`service_topics`), in the order they happened. Their channel types are
*message* types (``pkg/msg/...``) with exactly the fields, and so the very CDR bytes, of the
service's ``_Request`` and ``_Response`` (:func:`recorded_type`):

(``pkg`` = ``hexapod_workspace_msgs``)

=================================  ==================================
service part                       recorded as
=================================  ==================================
``pkg/srv/CheckPoses_Request``     ``pkg/msg/CheckPosesRequest``
``pkg/srv/CheckPoses_Response``    ``pkg/msg/CheckPosesResponse``
``pkg/srv/CheckPosesFlat_...``     ``pkg/msg/CheckPosesFlat...`` (same suffix)
``pkg/srv/ComputeWorkspace_...``   ``pkg/msg/ComputeWorkspace...`` (same suffix)
``std_srvs/srv/Trigger_Request``   ``std_msgs/msg/Empty``
``std_srvs/srv/Trigger_Response``  ``pkg/msg/TriggerResponse``
=================================  ==================================

Why message types: rosbags files a type ``pkg/srv/X_Request`` under ``pkg/srv/msg/X_Request``,
so its documented ``reader.deserialize(raw, connection.msgtype)`` cannot find any ``srv``-named
channel (rosbag2's own service events, ``pkg/srv/X_Event``, included). Foxglove refuses an empty
``ros2msg`` schema unless it is ``std_msgs/Empty``, which is what ``Trigger_Request`` (an empty
structure) is on the wire. With message types every tool decodes every channel: rosbags with its
documented API, mcap_ros2, Foxglove (``@mcap/core``, ``@foxglove/rosmsg2-serialization``), and
``ros2 bag play`` can republish them, because the types exist in the interface package.
Logs written before this choice (``srv``-named channels) are still read here.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any

import numpy as np
from rosbags.interfaces import (
    Nodetype,
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2.metadata import dump_qos_v9
from rosbags.typesys import Stores, get_types_from_msg
from rosbags.typesys import get_typestore as _rosbags_typestore
from rosbags.typesys.msg import normalize_msgtype

from hexapod_workspace._resources import data_dir

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore


INTERFACE_PACKAGE = "hexapod_workspace_msgs"
SCHEMA_ENCODING = "ros2msg"
MESSAGE_ENCODING = "cdr"
PROFILE = "ros2"
ROS_DISTRO = "jazzy"

# std_srvs ships no .msg/.srv files in the pip wheels and rosbags' stores hold no services.
_EXTRA_SERVICES = {"std_srvs/srv/Trigger": "---\nbool success\nstring message\n"}
_EMPTY_FIELD = "structure_needs_at_least_one_member"
#: The only types whose ros2msg schema may be empty (what Foxglove accepts as empty).
_EMPTY_SCHEMA_NAMES = ("std_msgs/msg/Empty", "std_msgs/Empty")
_DTYPES = {
    "bool": np.bool_,
    "byte": np.uint8,
    "char": np.uint8,
    "int8": np.int8,
    "uint8": np.uint8,
    "int16": np.int16,
    "uint16": np.uint16,
    "int32": np.int32,
    "uint32": np.uint32,
    "int64": np.int64,
    "uint64": np.uint64,
    "float32": np.float32,
    "float64": np.float64,
}


# --------------------------------------------------------------------------- type store


#: The message type each service part is recorded as (see the module docstring).
RECORDED_TYPES = {
    f"{INTERFACE_PACKAGE}/srv/CheckPoses_Request": f"{INTERFACE_PACKAGE}/msg/CheckPosesRequest",
    f"{INTERFACE_PACKAGE}/srv/CheckPoses_Response": f"{INTERFACE_PACKAGE}/msg/CheckPosesResponse",
    f"{INTERFACE_PACKAGE}/srv/CheckPosesFlat_Request": (
        f"{INTERFACE_PACKAGE}/msg/CheckPosesFlatRequest"
    ),
    f"{INTERFACE_PACKAGE}/srv/CheckPosesFlat_Response": (
        f"{INTERFACE_PACKAGE}/msg/CheckPosesFlatResponse"
    ),
    f"{INTERFACE_PACKAGE}/srv/ComputeWorkspace_Request": (
        f"{INTERFACE_PACKAGE}/msg/ComputeWorkspaceRequest"
    ),
    f"{INTERFACE_PACKAGE}/srv/ComputeWorkspace_Response": (
        f"{INTERFACE_PACKAGE}/msg/ComputeWorkspaceResponse"
    ),
    f"{INTERFACE_PACKAGE}/srv/CheckPath_Request": f"{INTERFACE_PACKAGE}/msg/CheckPathRequest",
    f"{INTERFACE_PACKAGE}/srv/CheckPath_Response": f"{INTERFACE_PACKAGE}/msg/CheckPathResponse",
    f"{INTERFACE_PACKAGE}/srv/SchedulePath_Request": (
        f"{INTERFACE_PACKAGE}/msg/SchedulePathRequest"
    ),
    f"{INTERFACE_PACKAGE}/srv/SchedulePath_Response": (
        f"{INTERFACE_PACKAGE}/msg/SchedulePathResponse"
    ),
    f"{INTERFACE_PACKAGE}/srv/Loads_Request": f"{INTERFACE_PACKAGE}/msg/LoadsRequest",
    f"{INTERFACE_PACKAGE}/srv/Loads_Response": f"{INTERFACE_PACKAGE}/msg/LoadsResponse",
    "std_srvs/srv/Trigger_Request": "std_msgs/msg/Empty",
    "std_srvs/srv/Trigger_Response": f"{INTERFACE_PACKAGE}/msg/TriggerResponse",
}


def recorded_type(msgtype: str) -> str:
    """Return the type a log records ``msgtype`` as: a service part's message twin, else itself.

    Parameters
    ----------
    msgtype : str
        A ROS type name, e.g. ``"std_srvs/srv/Trigger_Response"`` or
        ``"sensor_msgs/msg/PointCloud2"``.

    Returns
    -------
    str
        ``"hexapod_workspace_msgs/msg/TriggerResponse"``, or ``msgtype`` unchanged.
    """
    return RECORDED_TYPES.get(msgtype, msgtype)


def service_part(msgtype: str) -> str:
    """Return the service part (``pkg/srv/X_Request``) a recorded type stands for, else itself."""
    for part, recorded in RECORDED_TYPES.items():
        if recorded == msgtype and not recorded.startswith("std_msgs/"):
            return part
    return msgtype


def service_topics(service_name: str) -> tuple[str, str]:
    """Return the topics a service's requests and responses are recorded on.

    Parameters
    ----------
    service_name : str
        Fully qualified, e.g. ``"/hexapod_workspace/check_poses"``.

    Returns
    -------
    (str, str)
        ``("<service>/request", "<service>/response")``; their types are
        ``recorded_type("<pkg>/srv/<Name>_Request")`` and ``..._Response``.
    """
    return f"{service_name}/request", f"{service_name}/response"


def _service_types(service_type: str, text: str) -> dict[str, Any]:
    """Parse a ``.srv`` text into its ``_Request`` and ``_Response`` type definitions.

    Keys are rosbags' normalised names (``pkg/srv/msg/Name_Request``), which its schema
    generator turns back into ROS names (``pkg/srv/Name_Request``).
    """
    lines = text.splitlines()
    split = next((i for i, line in enumerate(lines) if line.strip() == "---"), len(lines))
    parts = {
        "Request": "\n".join(lines[:split]),
        "Response": "\n".join(lines[split + 1 :]),
    }
    types: dict[str, Any] = {}
    for suffix, part in parts.items():
        for name, definition in get_types_from_msg(part, f"{service_type}_{suffix}").items():
            consts, fields = definition[0], definition[1]
            if not fields:  # rosidl gives an empty structure one uint8 member on the wire
                fields = [(_EMPTY_FIELD, (Nodetype.BASE, ("uint8", 0)))]
            own = {store_name(f"{service_type}_{x}") for x in parts}
            relative = [(fname, _package_relative(desc, own)) for fname, desc in fields]
            types[name] = (consts, relative, *definition[2:])
    return types


def _package_relative(desc: tuple[int, Any], own: set[str]) -> tuple[int, Any]:
    """Resolve a relative type of a .srv (``TiltTorsion``) in ``pkg/msg`` as rosidl does; rosbags
    resolves it next to the service (``pkg/srv/msg/TiltTorsion``)."""
    nodetype, detail = desc
    if nodetype == Nodetype.NAME:
        if "/srv/msg/" in detail and detail not in own:
            return (nodetype, detail.replace("/srv/msg/", "/msg/"))
        return desc
    if nodetype in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        subdesc, length = detail
        return (nodetype, (_package_relative(subdesc, own), length))
    return desc


def store_name(msgtype: str) -> str:
    """Return the type store's key for a ROS type name (``pkg/srv/X`` -> ``pkg/srv/msg/X``)."""
    return normalize_msgtype(msgtype)


@functools.cache
def get_typestore() -> Typestore:
    """Return the type store used for every log: Jazzy + hexapod_workspace_msgs + std_srvs.

    Returns
    -------
    rosbags.typesys.store.Typestore
        Shared, built once per process. Holds ``hexapod_workspace_msgs/msg/*``, the services'
        ``/srv/<Name>_Request`` and ``_Response`` types, and
        ``std_srvs/srv/Trigger_*``.
    """
    store = _rosbags_typestore(Stores.ROS2_JAZZY)
    types: dict[str, Any] = {}
    for path in sorted(data_dir("msg").glob("*.msg")):
        types.update(
            get_types_from_msg(
                path.read_text(encoding="utf-8"), f"{INTERFACE_PACKAGE}/msg/{path.stem}"
            )
        )
    store.register(types)
    services: dict[str, Any] = {}
    for path in sorted(data_dir("srv").glob("*.srv")):
        text = path.read_text(encoding="utf-8")
        services.update(_service_types(f"{INTERFACE_PACKAGE}/srv/{path.stem}", text))
    for service_type, text in _EXTRA_SERVICES.items():
        services.update(_service_types(service_type, text))
    store.register(services)
    return store


@functools.cache
def message_definition(msgtype: str) -> str:
    """Return the full ``ros2msg`` schema text of a type, dependencies concatenated.

    Raises
    ------
    KeyError
        When the type is not in :func:`get_typestore`.
    """
    store = get_typestore()
    if store_name(msgtype) not in store.fielddefs:
        msg = f"unknown ROS type {msgtype!r}"
        raise KeyError(msg)
    text = store.generate_msgdef(store_name(msgtype), ros_version=2)[0]
    if not text and msgtype not in _EMPTY_SCHEMA_NAMES:
        # An empty structure is one uint8 on the wire (rosidl's filler); say so, as Foxglove
        # refuses an empty schema for any type but std_msgs/Empty.
        text = f"uint8 {_EMPTY_FIELD}\n"
    return text


@functools.cache
def _hash_store() -> Typestore:
    """A store whose service types carry their ROS names (``pkg/srv/X_Request``): the RIHS01
    hash includes the type name, and :func:`get_typestore` keys them ``pkg/srv/msg/X_Request``."""
    store = _rosbags_typestore(Stores.ROS2_JAZZY)
    fielddefs = get_typestore().fielddefs
    store.register(
        {k: v for k, v in fielddefs.items() if k.startswith(f"{INTERFACE_PACKAGE}/msg/")}
    )
    store.register(
        {k.replace("/srv/msg/", "/srv/"): v for k, v in fielddefs.items() if "/srv/msg/" in k}
    )
    return store


@functools.cache
def type_hash(msgtype: str) -> str:
    """Return the type's RIHS01 hash (``RIHS01_<64 hex>``), as rosbag2 Jazzy stores it (the
    same value rclpy reports as ``topic_type_hash``)."""
    message_definition(msgtype)  # same KeyError for unknown types
    return _hash_store().hash_rihs01(msgtype)


def qos_profile_text(
    *,
    reliability: str = "reliable",
    durability: str = "volatile",
    history: str = "keep_last",
    depth: int = 10,
) -> str:
    """Return the ``offered_qos_profiles`` channel metadata text for one publisher.

    Parameters
    ----------
    reliability : {"reliable", "best_effort"}
    durability : {"volatile", "transient_local"}
    history : {"keep_last", "keep_all"}
    depth : int
        History depth.

    Returns
    -------
    str
        YAML list with one profile in the rosbag2 v9 layout (as ``ros2 bag record`` stores it).
    """
    import yaml

    infinite = QosTime(0x7FFFFFFF, 0xFFFFFFFF)  # rmw's "infinite" duration in rosbag2 metadata
    profile = Qos(
        QosHistory[history.upper()],
        depth,
        QosReliability[reliability.upper()],
        QosDurability[durability.upper()],
        infinite,
        infinite,
        QosLiveliness.AUTOMATIC,
        infinite,
        False,
    )
    return yaml.safe_dump(dump_qos_v9([profile]), sort_keys=False).strip()


#: Request topics (commands coming in): reliable, volatile, depth 10.
REQUEST_QOS = qos_profile_text()
#: Result topics (summaries, boundaries, reachability): reliable, transient local, depth 1.
RESULT_QOS = qos_profile_text(durability="transient_local", depth=1)
#: Service request/response topics (rmw's services default: reliable, volatile, depth 10).
SERVICE_QOS = qos_profile_text()
