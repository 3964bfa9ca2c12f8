"""hexapod_workspace: orientation workspace of 6-DOF parallel manipulators (hexapods, GPMs).

The core (model, kinematics, constraints, workspace algorithms) depends on numpy, numba (its
compiled kernels) and the standard library, with PyYAML only to read a parameters file; ROS 2
lives in :mod:`hexapod_workspace.ros`.

Units are SI (m, rad). Orientations are Tilt-and-Torsion angles (φ, θ, ψ) with
``R = Rz(φ) Ry(θ) Rz(−φ) Rz(ψ)``; see :mod:`hexapod_workspace.core.base.rotations`.
"""

from ._version import __version__ as __version__
from .atlas import workspace_atlas
from .core.cell.cldata import CLProgram, parse_cldata, read_cldata
from .core.cell.frames import CellFrames, Tool, WorkFrame, cell_from_mapping, tool_model
from .core.cell.reach import Reach, axis_limits, reach
from .core.evaluation.check import CONSTRAINT_NAMES, CheckResult, check
from .core.evaluation.loading import (
    HomePoseWarning,
    example_manipulator,
    load_manipulator,
    manipulator_from_mapping,
)
from .core.model.manipulator import Manipulator
from .core.motions import (
    PathCheck,
    TorsionPlan,
    check_path,
    check_waypoints,
    plan_torsion,
)
from .core.motions.speeds import actuator_rates, feed_limits
from .core.workspaces.atlas import AtlasGrid, AtlasOptions
from .core.workspaces.orientation import (
    OrientationSlice,
    OrientationWorkspace,
    TorsionRange,
    orientation_workspace,
    torsion_range,
)
from .core.workspaces.projected import ProjectedWorkspace, projected_workspace
from .errors import (
    AtlasError,
    ConfigError,
    GeometryError,
    HexapodWorkspaceError,
    InputError,
    LogReadError,
    MissingExtraError,
    RecordingError,
    ResolutionError,
    UnreachableReferenceError,
)

__all__ = [
    "CONSTRAINT_NAMES",
    "AtlasError",
    "AtlasGrid",
    "AtlasOptions",
    "CLProgram",
    "CellFrames",
    "CheckResult",
    "ConfigError",
    "GeometryError",
    "HexapodWorkspaceError",
    "HomePoseWarning",
    "InputError",
    "LogReadError",
    "Manipulator",
    "MissingExtraError",
    "OrientationSlice",
    "OrientationWorkspace",
    "PathCheck",
    "ProjectedWorkspace",
    "Reach",
    "RecordingError",
    "ResolutionError",
    "Tool",
    "TorsionPlan",
    "TorsionRange",
    "UnreachableReferenceError",
    "WorkFrame",
    "actuator_rates",
    "axis_limits",
    "cell_from_mapping",
    "check",
    "check_path",
    "check_waypoints",
    "example_manipulator",
    "feed_limits",
    "load_manipulator",
    "manipulator_from_mapping",
    "orientation_workspace",
    "parse_cldata",
    "plan_torsion",
    "projected_workspace",
    "reach",
    "read_cldata",
    "tool_model",
    "torsion_range",
    "workspace_atlas",
]
