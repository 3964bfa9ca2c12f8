"""The evaluation layer: poses checked against every constraint, above the kernels.

:mod:`~hexapod_workspace.core.evaluation.check` (``check``, ``check_pose``: the compiled margins for
arrays of poses) and
:mod:`~hexapod_workspace.core.evaluation.loading`, the one place where a model file or mapping
becomes a
:class:`~hexapod_workspace.core.model.manipulator.Manipulator`, refused in one line or checked
at its home pose (which is why it sits above the evaluator).
"""
