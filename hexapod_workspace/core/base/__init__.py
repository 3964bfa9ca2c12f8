"""The base layer: what every other layer of the core stands on, and imports nothing of it.

:mod:`~hexapod_workspace.core.base.jit` (numba's set-up, the kernel cache and the compile-time
switches), :mod:`~hexapod_workspace.core.base.params` (parameters files and flat names),
:mod:`~hexapod_workspace.core.base.resolution` (shared methods, kinds, bounds and defaults),
:mod:`~hexapod_workspace.core.base.rotations` (Tilt-and-Torsion and the controllers' angle
conventions),
:mod:`~hexapod_workspace.core.base.validation` (array rules: machine size, units, joint layouts) and
:mod:`~hexapod_workspace.core.base.values` (readers of parameter values). numpy, numba and the
standard library only.
"""
