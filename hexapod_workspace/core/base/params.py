"""Read ROS 2 parameters files (the configuration format shared by the node and the CLI).

A parameters file maps a node name (``hexapod_workspace``, ``/hexapod_workspace`` or the
wildcard ``/**``) to ``{"ros__parameters": {...}}``. This module returns that mapping flattened
to the node's dotted parameter names (``geometry.base_joints``, ...);
:func:`hexapod_workspace.core.evaluation.loading.manipulator_from_mapping` interprets it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from ...errors import ConfigError

__all__ = [
    "CELL_PARAMETERS",
    "COLLISION_PARAMETERS",
    "NODE_NAME",
    "NODE_PARAMETERS",
    "ROS_PARAMETERS",
    "flatten",
    "load_params_file",
    "unknown_parameter",
]

#: The node name, and the root key the CLI looks for in a parameters file.
NODE_NAME = "hexapod_workspace"
_ROOT_KEYS = (NODE_NAME, f"/{NODE_NAME}", "/**")

#: Parameters the node declares besides the manipulator model (``Manipulator.PARAMETER_DEFAULTS``).
#: A parameters file may carry them; the CLI ignores them, but refuses any name it does not know
#: so that a misspelt section (``limitz:``) is named instead of reported as a missing parameter.
#: ``test/ros`` checks that the node declares exactly these.
NODE_PARAMETERS = (
    "resolution.n_phi",
    "resolution.n_rays",
    "resolution.psi_step",
    "resolution.tolerance",
    "resolution.projected_method",
    "check.max_poses",
    "check.max_command_age",
    "check.report_singularity",
    "recording.enabled",
    "recording.directory",
    "recording.max_file_mb",
    "recording.max_file_duration",
    "recording.max_total_mb",
    "recording.cloud_points",
    "motion.current_pose_topic",
    "axis_limits.frame",
    "axis_limits.rate",
)
#: Parameters of the machining cell (tool and work frames, tool table, actuator speeds), read by
#: :func:`hexapod_workspace.core.cell.frames.cell_from_mapping`; ``tools.`` holds ``tools.T<n>.*``.
CELL_PARAMETERS = (
    "tool.offset",
    "tool.orientation",
    "tool.number",
    "work.origin",
    "work.orientation",
    "work.frame_id",
    "tools.",
    "limits.actuator_speed_max",
    "limits.actuator_accel_max",
)
#: Parameters of the collision scene (``collision.clearance``, ``collision.platform.*``,
#: ``collision.tool.*``, ``collision.obstacles.*``), read by
#: :func:`hexapod_workspace.core.model.collision.params.collision_scene`, which knows every name.
COLLISION_PARAMETERS = ("collision.",)
#: Parameters every ROS 2 node has (prefixes end with a dot).
ROS_PARAMETERS = ("use_sim_time", "start_type_description_service", "qos_overrides.")


def load_params_file(path: str | Path) -> dict[str, Any]:
    """Load the ``ros__parameters`` mapping of this node from a ROS 2 parameters file.

    Parameters
    ----------
    path : str or pathlib.Path
        YAML parameters file.

    Returns
    -------
    dict
        Dotted parameter names to values (``{"geometry.base_joints": [...], ...}``). When the
        file has both a wildcard ``/**`` section and a ``hexapod_workspace`` section, the latter's
        values override the former's, as ROS does.

    Raises
    ------
    ConfigError
        When the file is missing, is not YAML, or has no section for this node.
    """
    import yaml  # PyYAML: only the configuration loader needs it

    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        msg = f"cannot read parameters file {path}: {error.strerror or error}"
        raise ConfigError(msg) from error
    try:
        document = yaml.safe_load(text)
    except yaml.YAMLError as error:
        where = getattr(error, "problem_mark", None)
        line = f" (line {where.line + 1})" if where is not None else ""
        msg = f"parameters file {path} is not valid YAML{line}"
        raise ConfigError(msg) from error
    if not isinstance(document, Mapping):
        msg = f"parameters file {path}: expected a mapping at the top level"
        raise ConfigError(msg)
    merged: dict[str, Any] = {}
    found = False
    for key in ("/**", f"/{NODE_NAME}", NODE_NAME):
        section = document.get(key)
        if section is None:
            continue
        if not isinstance(section, Mapping) or not isinstance(
            section.get("ros__parameters"), Mapping
        ):
            msg = f"parameters file {path}: section {key!r} has no 'ros__parameters' mapping"
            raise ConfigError(msg)
        extra = sorted(str(name) for name in section if name != "ros__parameters")
        if extra:
            msg = (
                f"parameters file {path}: unknown key {extra[0]!r} in section {key!r} "
                "(expected only 'ros__parameters')"
            )
            raise ConfigError(msg)
        found = True
        merged.update(flatten(section["ros__parameters"]))
    if not found:
        msg = (
            f"parameters file {path}: no section for this node "
            f"(expected one of {', '.join(repr(k) for k in _ROOT_KEYS)})"
        )
        raise ConfigError(msg)
    return merged


def flatten(parameters: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Flatten nested parameter mappings into ROS-style dotted names.

    Parameters
    ----------
    parameters : Mapping
        Nested (``{"limits": {"leg_diameter": 0.05}}``), dotted (``{"limits.leg_diameter":
        0.05}``) or mixed.
    prefix : str
        Prefix for the names (used by the recursion).

    Returns
    -------
    dict
        ``{"limits.leg_diameter": 0.05, ...}``.
    """
    flat: dict[str, Any] = {}
    for key, value in parameters.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            flat.update(flatten(value, prefix=f"{name}."))
        else:
            flat[name] = value
    return flat


def unknown_parameter(names: Iterable[str], known: Iterable[str]) -> str | None:
    """Describe the first name of ``names`` that is not a known parameter, at its own level.

    Parameters
    ----------
    names : iterable of str
        Dotted parameter names, as :func:`flatten` gives them.
    known : iterable of str
        Every accepted dotted name; a name ending with ``.`` accepts everything under it.

    Returns
    -------
    str or None
        ``"limitz: unknown section (expected one of ...)"`` when the first level is unknown,
        ``"limits.leg_lenght_min: unknown parameter (expected one of limits.leg_length_min,
        ...)"`` when a deeper one is; None when every name is known.
    """
    known = tuple(known)
    exact = {name for name in known if not name.endswith(".")}
    prefixes = tuple(name for name in known if name.endswith("."))
    for name in sorted(names):
        if name in exact or name.startswith(prefixes):
            continue
        parts = name.split(".")
        for depth in range(1, len(parts) + 1):
            stem = ".".join(parts[:depth])
            if stem in exact:
                return f"{stem}: expected a value, got a section (holding {name})"
            below = [k for k in known if k == stem or k.startswith(stem + ".")]
            if below:
                continue
            level = ".".join(parts[: depth - 1])
            siblings = sorted(
                {
                    ".".join(k.rstrip(".").split(".")[:depth])
                    for k in known
                    if not level or k.startswith(level + ".")
                }
            )
            what = "section" if depth < len(parts) else "parameter"
            return f"{stem}: unknown {what} (expected one of {', '.join(siblings)})"
    return None
