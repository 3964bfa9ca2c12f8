"""The numerical core: model and parameters file, rotations, constraints, search, workspaces.

Imports numpy, numba (the compiled kernels of :mod:`hexapod_workspace.core.kernels`) and the
standard library only (PyYAML lazily, to read a parameters file). Nothing
here imports from :mod:`hexapod_workspace.logs`, :mod:`hexapod_workspace.cli` or
:mod:`hexapod_workspace.ros`; ``test/test_layers.py`` parses every module to keep it so.
"""
