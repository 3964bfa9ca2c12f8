"""Leg architectures: where each leg's base-side end is, and what its actuator does.

One interface per architecture (a module each, in numpy; the compiled margins of
:mod:`hexapod_workspace.core.kernels.margins` follow the same formulas):

* ``inverse_kinematics(manipulator, platform)``: the actuated coordinate q_i of every leg for
  platform joints ``B_i`` (..., 6, 3) and the ``ik`` margin (m, negative exactly where the leg
  has no solution; q is NaN there);
* ``base_ends(manipulator, q)``: the base-side end A_i(q_i) of every leg (the leg segment runs
  from there to B_i);
* ``base_end_derivatives(manipulator, q)``: dA_i/dq and d²A_i/dq² (the schedule's second-order
  bounds, :mod:`hexapod_workspace.core.motions.schedule`);
* ``transmission(manipulator, directions, q)``: τ_i, the factor by which the actuator's motion
  reaches the leg line (``n_i·dB_i = τ_i·(speed of the base-side end)``), whose inverse bounds
  the actuator's rate;
* ``base_axes(manipulator, q)``: the base joint axes at q (they turn with a crank);
* ``actuator_lever(manipulator)``: r_i (6,), m, in ``dq_i = n_i·dB_i / (r_i·τ_i)`` (1 for a leg
  or a slide, the crank length for a crank): the Jacobian row's divisor is ``r_i·τ_i``;
* ``ACTUATOR_UNIT`` (``"m"`` or ``"rad"``), ``FORCE_UNIT`` (``"N"`` or ``"N·m"``),
  ``MOVING_BASE`` (the base-side ends move with the actuators) and ``TURNING_BASE`` (they turn
  about an axis with it: a crank), which select the rate gains of the searches' and the moves'
  bounds.

:class:`Architecture` declares the interface (mypy checks every module against it) and
:data:`ARCHITECTURES`, :data:`CODES` and the module table below are the registry; the compiled
leg stage is selected by the code in :mod:`hexapod_workspace.core.kernels.pose`.

The Jacobian row of leg i is the same for every architecture with fixed-length or
variable-length legs: the unit leg line in Plücker coordinates ``(n_i, (R·b_i) × n_i)``
(:mod:`~hexapod_workspace.core.constraints.table`, singularity). ``ups`` is the Gough-Stewart
platform of the paper (fixed base joints, the leg length is actuated); ``pus`` slides the base
joints on rails (legs of fixed length, the paper's 6-PRRS, Hexaglide-like); ``rus`` turns
cranks (rods of fixed length from the crank ends, motion platforms).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from . import pus, rus, ups

if TYPE_CHECKING:
    from ..manipulator import Manipulator

__all__ = ["ARCHITECTURES", "CODES", "Architecture", "module"]


class Architecture(Protocol):
    """The interface of a leg architecture's module (module documentation; shapes (..., 6)
    for q and (..., 6, 3) for points, directions and axes, base frame, m and rad)."""

    ACTUATOR_UNIT: str
    FORCE_UNIT: str
    MOVING_BASE: bool
    TURNING_BASE: bool

    def inverse_kinematics(
        self, manipulator: Manipulator, platform: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """q and the ``ik`` margin for platform joints B_i."""
        ...

    def base_ends(self, manipulator: Manipulator, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """The base-side ends A_i(q_i)."""
        ...

    def base_end_derivatives(
        self, manipulator: Manipulator, q: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """dA_i/dq and d²A_i/dq²."""
        ...

    def transmission(
        self, manipulator: Manipulator, directions: NDArray[np.float64], q: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """τ_i for unit leg directions."""
        ...

    def base_axes(self, manipulator: Manipulator, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """The base joint axes at q."""
        ...

    def actuator_lever(self, manipulator: Manipulator) -> NDArray[np.float64]:
        """r_i, shape (6,), m."""
        ...


#: The accepted values of ``geometry.architecture``.
ARCHITECTURES = ("ups", "pus", "rus")
#: The code of each architecture in the packed model of the kernels.
CODES = {"ups": 0, "pus": 1, "rus": 2}

_MODULES: dict[str, Architecture] = {"ups": ups, "pus": pus, "rus": rus}


def module(architecture: str) -> Architecture:
    """The module implementing an architecture (``ups``, ``pus`` or ``rus``)."""
    return _MODULES[architecture]
