"""The constraint layer: every constraint once, as data, above :mod:`~hexapod_workspace.core.model`.

:mod:`~hexapod_workspace.core.constraints.table` holds the rows (name, unit, scale, rate
coefficients, report text) that the kernels evaluate and every report, message and document reads.
"""
