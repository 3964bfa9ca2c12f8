"""The model layer: the manipulator as data, above :mod:`~hexapod_workspace.core.base`.

:mod:`~hexapod_workspace.core.model.manipulator` (the frozen model and its parameter tables),
:mod:`~hexapod_workspace.core.model.architectures` (the leg architectures 6-UPS, 6-PUS, 6-RUS: numpy
kinematics), :mod:`~hexapod_workspace.core.model.legs` (where each leg runs),
:mod:`~hexapod_workspace.core.model.collision` (bodies, exact distances and the scene) and
:mod:`~hexapod_workspace.core.model.genhexkins` (LinuxCNC's hexapod geometry). Nothing here
evaluates a constraint; building a model from parameters, which checks its home pose, is
:mod:`hexapod_workspace.core.evaluation.loading`.
"""
