"""Every ROS interface of the node, one row each: the one table of names, types and QoS.

The node creates its topics, services and actions under these names (node-relative,
:func:`relative_name`), the CLI records under them (:data:`TOPICS`), replay and the tests look
them up here, and the documentation's interface reference is generated from :data:`INTERFACES`.
ROS-free (the QoS is text; the node builds its profiles, and ``test/ros/test_ros_install.py``
checks the running node's endpoints against this table).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.base.params import NODE_NAME

__all__ = [
    "INTERFACES",
    "NODE_NAME",
    "TOPICS",
    "TYPES",
    "Interface",
    "absolute_name",
    "interface",
    "relative_name",
]

#: QoS of every service and action (rclpy's default services profile).
SERVICE_QOS_TEXT = "reliable, volatile, keep last 10 (the services default)"


@dataclass(frozen=True)
class Interface:
    """One topic, service or action of the node.

    Attributes
    ----------
    key : str
        Name relative to the node (``check_poses`` is ``~/check_poses``); a name starting with
        ``/`` is absolute (``/diagnostics``).
    kind : str
        ``"subscription"``, ``"publisher"``, ``"service"`` or ``"action"``.
    type : str
        ROS type, e.g. ``hexapod_workspace_msgs/srv/CheckPoses``.
    reliability, durability : str
        QoS policies (``"reliable"``, ``"volatile"``, ``"transient_local"``) of a topic; for a
        service or an action the services default.
    depth : int
        History depth of a topic; 0 = KEEP_ALL. Services and actions: 10 (keep last).
    summary : str
        What it carries, one line.
    extension : str
        The module that adds it to the node (``""``: the node itself).
    condition : str
        When the node offers it (``""``: always), e.g. only with a parameter set.
    """

    key: str
    kind: str
    type: str
    summary: str
    reliability: str = "reliable"
    durability: str = "volatile"
    depth: int = 10
    extension: str = ""
    condition: str = ""

    @property
    def name(self) -> str:
        """The resolved name under the default node name, e.g. ``/hexapod_workspace/atlas``."""
        return absolute_name(self.key)

    @property
    def qos_text(self) -> str:
        """The QoS in words (topics), or the services default."""
        if self.kind in ("service", "action"):
            return SERVICE_QOS_TEXT
        history = "keep all" if self.depth == 0 else f"keep last {self.depth}"
        return f"{self.reliability}, {self.durability.replace('_', ' ')}, {history}"


_MSGS = "hexapod_workspace_msgs"

#: Every interface of the node, in the order of the reference.
INTERFACES: tuple[Interface, ...] = (
    Interface(
        "commanded_pose",
        "subscription",
        f"{_MSGS}/msg/CommandedPose",
        "a pose to validate; each is answered by exactly one ReachabilityResult",
        depth=0,
    ),
    Interface(
        "workspace_request",
        "subscription",
        f"{_MSGS}/msg/WorkspaceRequest",
        "a workspace to compute (queued with the goals)",
        depth=0,
    ),
    Interface(
        "reachability",
        "publisher",
        f"{_MSGS}/msg/ReachabilityResult",
        "the verdict of each commanded pose, in arrival order",
        durability="transient_local",
        depth=1000,
    ),
    Interface(
        "workspace_summary",
        "publisher",
        f"{_MSGS}/msg/WorkspaceSummary",
        "the summary of every computation (failed ones too)",
        durability="transient_local",
        depth=1,
    ),
    Interface(
        "orientation_workspace",
        "publisher",
        "sensor_msgs/msg/PointCloud2",
        "boundary of the last 3-D orientation workspace",
        durability="transient_local",
        depth=1,
    ),
    Interface(
        "projected_workspace",
        "publisher",
        "sensor_msgs/msg/PointCloud2",
        "boundary of the last projected workspace",
        durability="transient_local",
        depth=1,
    ),
    Interface(
        "check_poses",
        "service",
        f"{_MSGS}/srv/CheckPoses",
        "a batch of (phi, theta, psi) at one position: verdicts, margins, limiting legs",
    ),
    Interface(
        "check_poses_flat",
        "service",
        f"{_MSGS}/srv/CheckPosesFlat",
        "the same check in flat arrays (angles N x 3, margins N x K with the constraint names "
        "once), for large batches",
    ),
    Interface(
        "compute_workspace",
        "action",
        # Recorded in the form of the service of the same name (rosbag2 records no actions).
        f"{_MSGS}/srv/ComputeWorkspace",
        "a workspace at any position, with progress and cancel (logs record it in the form "
        "of the service of the same name)",
    ),
    Interface(
        "compute_orientation_workspace",
        "service",
        "std_srvs/srv/Trigger",
        "the 3-D orientation workspace at pose.position with the node's parameters",
    ),
    Interface(
        "compute_projected_workspace",
        "service",
        "std_srvs/srv/Trigger",
        "the projected workspace at pose.position with the node's parameters",
    ),
    Interface(
        "check_path",
        "service",
        f"{_MSGS}/srv/CheckPath",
        "a motion through waypoints: certified moves, or a torsion plan; with feeds or "
        "durations, the certified peak actuator speed and the largest feed of each move",
        extension="hexapod_workspace.ros.paths",
    ),
    Interface(
        "schedule_path",
        "service",
        f"{_MSGS}/srv/SchedulePath",
        "the fastest schedule along a path that is certified to keep every actuator within "
        "its speed and acceleration limits and the tool within each move's feed",
        extension="hexapod_workspace.ros.schedule",
    ),
    Interface(
        "loads",
        "service",
        f"{_MSGS}/srv/Loads",
        "the loads at a pose: actuator forces under the payload and the process wrench, "
        "stiffness, deflection and accuracy at the tool",
        extension="hexapod_workspace.ros.loads",
    ),
    Interface(
        "axis_limits",
        "publisher",
        f"{_MSGS}/msg/AxisLimits",
        "the +/- reach along the six axes of axis_limits.frame at the current pose (soft "
        "limits), at most axis_limits.rate Hz",
        extension="hexapod_workspace.ros.cell",
        durability="transient_local",
        depth=1,
        condition="motion.current_pose_topic set",
    ),
    Interface(
        "compute_atlas",
        "action",
        f"{_MSGS}/action/ComputeAtlas",
        "the workspace atlas over a box of positions, with progress and cancel",
        extension="hexapod_workspace.ros.atlas_action",
    ),
    Interface(
        "atlas",
        "publisher",
        "sensor_msgs/msg/PointCloud2",
        "the last atlas, one point per position",
        extension="hexapod_workspace.ros.atlas_action",
        durability="transient_local",
        depth=1,
    ),
    Interface(
        "markers",
        "publisher",
        "visualization_msgs/msg/MarkerArray",
        "the scene at the current pose: legs, platform, tool, obstacles, the closest pair "
        "coloured, the cone of attainable tool directions (RViz, Foxglove)",
        extension="hexapod_workspace.ros.markers",
        durability="transient_local",
        depth=1,
    ),
    Interface(
        "/diagnostics",
        "publisher",
        "diagnostic_msgs/msg/DiagnosticArray",
        "the node's health, 1 Hz",
    ),
)


def absolute_name(key: str) -> str:
    """``/hexapod_workspace/<key>`` for a node-relative key; an absolute key as it is."""
    return key if key.startswith("/") else f"/{NODE_NAME}/{key}"


def relative_name(key: str) -> str:
    """The node-relative name (``~/<key>``) the node creates an interface under, so that a
    remapped node name or namespace moves every topic, service and action with the node."""
    if key.startswith("/") or key not in _BY_KEY:
        msg = f"{key!r}: not a node-relative interface of {NODE_NAME}"
        raise KeyError(msg)
    return f"~/{key}"


_BY_KEY = {row.key: row for row in INTERFACES}


def interface(key: str) -> Interface:
    """The row of :data:`INTERFACES` named ``key`` (``KeyError`` naming it when there is none)."""
    if key not in _BY_KEY:
        msg = f"{key!r}: no such interface of {NODE_NAME}"
        raise KeyError(msg)
    return _BY_KEY[key]


_CORE = [i for i in INTERFACES if not i.extension and not i.key.startswith("/")]

#: Topic and service names the node itself uses and the CLI records under (the node is named
#: ``hexapod_workspace``; ``~/workspace_summary`` resolves to
#: ``/hexapod_workspace/workspace_summary``). The extensions' names: :data:`INTERFACES`.
TOPICS: dict[str, str] = {i.key: i.name for i in _CORE}
#: ROS type of each entry of :data:`TOPICS` (services: the service type; the action
#: ``compute_workspace``: the service it is recorded as).
TYPES: dict[str, str] = {i.key: i.type for i in _CORE}
