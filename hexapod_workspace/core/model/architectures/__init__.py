"""Leg architectures: where each leg's base-side end is, and what its actuator does.

One interface per architecture (a module each, in numpy; the compiled margins of
:mod:`hexapod_workspace.core.kernels.margins` follow the same formulas):

* ``inverse_kinematics(manipulator, platform)``: the actuated coordinate q_i of every leg for
  platform joints ``B_i`` (..., 6, 3) and the ``ik`` margin (m, negative exactly where the leg
  has no solution; q is NaN there);
* ``base_ends(manipulator, q)``: the base-side end A_i(q_i) of every leg (the leg segment runs
  from there to B_i);
* ``transmission(manipulator, directions, q)``: τ_i, the factor by which the actuator's motion
  reaches the leg line (``n_i·dB_i = τ_i·(speed of the base-side end)``), whose inverse bounds
  the actuator's rate;
* ``base_axes(manipulator, q)``: the base joint axes at q (they turn with a crank).

The Jacobian row of leg i is the same for every architecture with fixed-length or
variable-length legs: the unit leg line in Plücker coordinates ``(n_i, (R·b_i) × n_i)``
(:mod:`~hexapod_workspace.core.constraints.table`, singularity). ``ups`` is the Gough-Stewart
platform of the paper (fixed base joints, the leg length is actuated); ``pus`` slides the base
joints on rails (legs of fixed length, the paper's 6-PRRS, Hexaglide-like); ``rus`` turns
cranks (rods of fixed length from the crank ends, motion platforms).
"""

from __future__ import annotations

from types import ModuleType

from . import pus, rus, ups

__all__ = ["ARCHITECTURES", "CODES", "module"]

#: The accepted values of ``geometry.architecture``.
ARCHITECTURES = ("ups", "pus", "rus")
#: The code of each architecture in the packed model of the kernels.
CODES = {"ups": 0, "pus": 1, "rus": 2}

_MODULES: dict[str, ModuleType] = {"ups": ups, "pus": pus, "rus": rus}


def module(architecture: str) -> ModuleType:
    """The module implementing an architecture (``ups``, ``pus`` or ``rus``)."""
    return _MODULES[architecture]
