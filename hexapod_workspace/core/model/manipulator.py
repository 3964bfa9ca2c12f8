"""The manipulator model: joint positions, joint axes and limits of a hexapod (6-UPS, 6-PUS or
6-RUS legs: ``geometry.architecture``, see :mod:`hexapod_workspace.core.model.architectures`).

A :class:`Manipulator` is data: built and validated from its parameters by
:mod:`hexapod_workspace.core.evaluation.loading`
(:func:`~hexapod_workspace.core.evaluation.loading.load_manipulator` for a file,
:func:`~hexapod_workspace.core.evaluation.loading.manipulator_from_mapping` for what a node holds),
which sits above the evaluator; this module imports neither.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..base.validation import shared_joint_pairs
from ..base.values import frozen, vector3

if TYPE_CHECKING:
    from .collision.params import CollisionScene

__all__ = [
    "ARCHITECTURE_PARAMETERS",
    "MODEL_GROUPS",
    "PARAMETER_DEFAULTS",
    "REQUIRED_PARAMETERS",
    "SPECIFIC_PARAMETERS",
    "Manipulator",
    "required_parameters",
]

#: Parameters of the model with their defaults; ``None`` means required.
PARAMETER_DEFAULTS: dict[str, Any] = {
    "frame_id": "base",
    "geometry.base_joints": None,
    "geometry.platform_joints": None,
    "geometry.home_position": None,
    "geometry.base_joint_axes": [],
    "geometry.platform_joint_axes": [],
    "limits.leg_length_min": None,
    "limits.leg_length_max": None,
    "limits.base_joint_max_angle": None,
    "limits.platform_joint_max_angle": None,
    "limits.leg_diameter": 0.0,
    "geometry.paired_joint_length": 0.0,
    "limits.singularity_min": 0.0,
    "pose.position": None,
    "geometry.architecture": "ups",
    "geometry.rail_directions": [],
    "geometry.crank_axes": [],
    "geometry.crank_zero_directions": [],
    "geometry.crank_lengths": [],
    "geometry.leg_lengths": [],
    "geometry.branch": [],
    "limits.actuator_min": [],
    "limits.actuator_max": [],
    "limits.transmission_min": 0.1,
}
#: The parameters only one architecture has (the others refuse them when given), and the
#: required ones (``None`` in :data:`PARAMETER_DEFAULTS` or listed here) of each.
ARCHITECTURE_PARAMETERS: dict[str, tuple[str, ...]] = {
    "ups": ("limits.leg_length_min", "limits.leg_length_max", "geometry.paired_joint_length"),
    "pus": (
        "geometry.rail_directions",
        "geometry.leg_lengths",
        "geometry.branch",
        "limits.actuator_min",
        "limits.actuator_max",
        "limits.transmission_min",
    ),
    "rus": (
        "geometry.crank_axes",
        "geometry.crank_zero_directions",
        "geometry.crank_lengths",
        "geometry.leg_lengths",
        "geometry.branch",
        "limits.actuator_min",
        "limits.actuator_max",
        "limits.transmission_min",
    ),
}
REQUIRED_PARAMETERS: dict[str, tuple[str, ...]] = {
    "ups": ("limits.leg_length_min", "limits.leg_length_max"),
    "pus": (
        "geometry.rail_directions",
        "geometry.leg_lengths",
        "limits.actuator_min",
        "limits.actuator_max",
    ),
    "rus": (
        "geometry.crank_axes",
        "geometry.crank_zero_directions",
        "geometry.crank_lengths",
        "geometry.leg_lengths",
        "limits.actuator_min",
        "limits.actuator_max",
    ),
}
MODEL_GROUPS = ("geometry.", "limits.", "pose.")


#: Every parameter that belongs to one architecture only.
SPECIFIC_PARAMETERS = frozenset(
    name for names in ARCHITECTURE_PARAMETERS.values() for name in names
)


def required_parameters(architecture: str) -> tuple[str, ...]:
    """The model parameters a model of this architecture must be given (``pose.position``
    excluded: it defaults to the home position), in :data:`PARAMETER_DEFAULTS` order."""
    needed = set(REQUIRED_PARAMETERS.get(architecture, ()))
    return tuple(
        name
        for name, default in PARAMETER_DEFAULTS.items()
        if name != "pose.position"
        and name.startswith(MODEL_GROUPS)
        and (name in needed or (default is None and name not in SPECIFIC_PARAMETERS))
    )


@dataclass(frozen=True, eq=False)
class Manipulator:
    """A hexapod (6-UPS, 6-PUS or 6-RUS): geometry, joint axes and limits, as the loader
    validated them.

    Attributes
    ----------
    base_joints : ndarray, shape (6, 3)
        a_i = OA_i, centres of the base (universal) joints, base frame, m.
    platform_joints : ndarray, shape (6, 3)
        b_i = CB'_i, centres of the platform (spherical) joints, mobile frame (origin at the
        tool tip C), m.
    base_joint_axes : ndarray, shape (6, 3)
        jA_i, unit axes of symmetry of the base joints, base frame, pointing into the legs.
    platform_joint_axes : ndarray, shape (6, 3)
        jB_i, unit axes of symmetry of the platform joints, mobile frame, pointing into the legs.
    leg_length_min, leg_length_max : ndarray, shape (6,)
        Leg length limits, m.
    base_joint_max_angle, platform_joint_max_angle : ndarray, shape (6,)
        Maximum angle between a joint axis and its leg, rad, in (0, π).
    leg_diameter : float
        D, m; legs must stay at least D apart (segment distance); 0 disables the check.
    paired_joint_length : float
        c, m (ups): along each leg, from a joint centre it shares with another leg, the length
        the joint occupies; the interference of two legs that share a joint is measured on the
        rest of them (their free lengths). 0 when no legs share a joint or D = 0.
    home_position : ndarray, shape (3,)
        Home position OC, base frame, m; the default joint axes are the leg directions there.
    position : ndarray, shape (3,)
        Default tool-tip position OC (``pose.position``), base frame, m.
    frame_id : str
        Name of the base frame in published results.
    axes_from_home : tuple of bool
        Whether the (base, platform) joint axes were derived from the home pose (not given).
    singularity_min : float
        σ_lim ≥ 0: the smallest singular value of the homogenised Plücker matrix of the legs
        allowed (constraint ``singularity``, see :mod:`~hexapod_workspace.core.constraints.table`);
        0 disables the constraint (dimensionless).
    architecture : str
        ``"ups"`` (legs of variable length between fixed joints, the default), ``"pus"``
        (slides on rails, legs of fixed length) or ``"rus"`` (cranks, rods of fixed length):
        :mod:`hexapod_workspace.core.model.architectures`. For pus and rus, ``base_joints`` are the
        rail origins or crank pivots A0_i, ``leg_length_min`` and ``leg_length_max`` both hold
        the fixed leg lengths, and the base joint axes of rus are given at crank angle 0.
    leg_lengths, branch : ndarray, shape (6,), or None
        pus/rus: fixed leg (rod) lengths L_i, m; assembly branch ±1 of each leg.
    rail_directions : ndarray, shape (6, 3), or None
        pus: unit rail directions u_i, base frame.
    crank_axes, crank_zero_directions : ndarray, shape (6, 3), or None
        rus: unit crank axes w_i and zero directions e_i ⟂ w_i, base frame.
    crank_lengths : ndarray, shape (6,), or None
        rus: crank lengths r_i, m.
    actuator_min, actuator_max : ndarray, shape (6,), or None
        pus: slide stroke along the rail, m; rus: crank range, rad (max − min < 2π).
    transmission_min : float
        pus/rus: smallest |τ_i| allowed (constraint ``transmission``), in (0, 1).
    collision : CollisionScene or None
        The collision scene (``collision.*``: platform and tool bodies, obstacles), with its
        moving bodies in this model's mobile frame; None when no scene is declared (then the
        ``collision`` constraint does not exist: +inf, left out of the interfaces).
    """

    base_joints: NDArray[np.float64]
    platform_joints: NDArray[np.float64]
    base_joint_axes: NDArray[np.float64]
    platform_joint_axes: NDArray[np.float64]
    leg_length_min: NDArray[np.float64]
    leg_length_max: NDArray[np.float64]
    base_joint_max_angle: NDArray[np.float64]
    platform_joint_max_angle: NDArray[np.float64]
    leg_diameter: float
    home_position: NDArray[np.float64]
    position: NDArray[np.float64]
    frame_id: str = "base"
    axes_from_home: tuple[bool, bool] = field(default=(True, True))
    singularity_min: float = 0.0
    architecture: str = "ups"
    leg_lengths: NDArray[np.float64] | None = None
    branch: NDArray[np.float64] | None = None
    rail_directions: NDArray[np.float64] | None = None
    crank_axes: NDArray[np.float64] | None = None
    crank_zero_directions: NDArray[np.float64] | None = None
    crank_lengths: NDArray[np.float64] | None = None
    actuator_min: NDArray[np.float64] | None = None
    actuator_max: NDArray[np.float64] | None = None
    transmission_min: float = 0.1
    collision: CollisionScene | None = None
    paired_joint_length: float = 0.0

    # ------------------------------------------------------------------ views
    def to_parameters(self) -> dict[str, Any]:
        """The model as ROS parameters (dotted names, plain Python values).

        ``manipulator_from_mapping(m.to_parameters())`` rebuilds an equal manipulator; joint axes
        that were derived from the home pose are given back as empty lists so that they keep
        following ``geometry.home_position``.

        Returns
        -------
        dict
            ``{"frame_id": str, "geometry.base_joints": [18 floats], ...}``.
        """

        def floats(array: NDArray[np.float64]) -> list[float]:
            return [float(v) for v in np.ravel(array)]

        def optional(array: NDArray[np.float64] | None) -> list[float]:
            return [] if array is None else floats(array)

        ups = self.architecture == "ups"

        scene = dict(self.collision.parameters) if self.collision is not None else {}
        return {
            **scene,
            "frame_id": self.frame_id,
            "geometry.base_joints": floats(self.base_joints),
            "geometry.platform_joints": floats(self.platform_joints),
            "geometry.home_position": floats(self.home_position),
            "geometry.base_joint_axes": []
            if self.axes_from_home[0]
            else floats(self.base_joint_axes),
            "geometry.platform_joint_axes": []
            if self.axes_from_home[1]
            else floats(self.platform_joint_axes),
            "limits.leg_length_min": floats(self.leg_length_min) if ups else [],
            "limits.leg_length_max": floats(self.leg_length_max) if ups else [],
            "limits.base_joint_max_angle": floats(self.base_joint_max_angle),
            "limits.platform_joint_max_angle": floats(self.platform_joint_max_angle),
            "limits.leg_diameter": float(self.leg_diameter),
            "geometry.paired_joint_length": float(self.paired_joint_length),
            "limits.singularity_min": float(self.singularity_min),
            "pose.position": floats(self.position),
            "geometry.architecture": self.architecture,
            "geometry.rail_directions": optional(self.rail_directions),
            "geometry.crank_axes": optional(self.crank_axes),
            "geometry.crank_zero_directions": optional(self.crank_zero_directions),
            "geometry.crank_lengths": optional(self.crank_lengths),
            "geometry.leg_lengths": optional(self.leg_lengths),
            "geometry.branch": optional(self.branch),
            "limits.actuator_min": optional(self.actuator_min),
            "limits.actuator_max": optional(self.actuator_max),
            "limits.transmission_min": float(self.transmission_min),
        }

    def with_position(self, position: Any) -> Manipulator:
        """A copy whose default position (``pose.position``) is ``position`` (m, base frame)."""
        return replace(self, position=frozen(vector3("position", position)))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Manipulator):
            return NotImplemented
        arrays_equal = all(
            np.array_equal(getattr(self, name), getattr(other, name))
            for name in (
                "base_joints",
                "platform_joints",
                "base_joint_axes",
                "platform_joint_axes",
                "leg_length_min",
                "leg_length_max",
                "base_joint_max_angle",
                "platform_joint_max_angle",
                "home_position",
                "position",
            )
        )
        optional_equal = all(
            (getattr(self, name) is None and getattr(other, name) is None)
            or (
                getattr(self, name) is not None
                and getattr(other, name) is not None
                and np.array_equal(getattr(self, name), getattr(other, name))
            )
            for name in (
                "leg_lengths",
                "branch",
                "rail_directions",
                "crank_axes",
                "crank_zero_directions",
                "crank_lengths",
                "actuator_min",
                "actuator_max",
            )
        )
        return (
            arrays_equal
            and optional_equal
            and self.architecture == other.architecture
            and self.transmission_min == other.transmission_min
            and self.leg_diameter == other.leg_diameter
            and self.paired_joint_length == other.paired_joint_length
            and self.singularity_min == other.singularity_min
            and self.frame_id == other.frame_id
            and self.axes_from_home == other.axes_from_home
            and self.collision == other.collision
        )

    __hash__ = None  # type: ignore[assignment]

    @property
    def shared_base_pairs(self) -> NDArray[np.bool_]:
        """Leg pairs i < j (``numpy.triu_indices(6, 1)`` order, shape (15,)) that share a base
        joint."""
        return shared_joint_pairs(self.base_joints)

    @property
    def shared_platform_pairs(self) -> NDArray[np.bool_]:
        """Leg pairs i < j (shape (15,)) that share a platform joint."""
        return shared_joint_pairs(self.platform_joints)
