"""The machining-cell layer: tool and work frames, CL files and reach, above
:mod:`~hexapod_workspace.core.motions`.

:mod:`~hexapod_workspace.core.cell.frames` (tool and work frames, the tool table),
:mod:`~hexapod_workspace.core.cell.cldata` (APT/CLDATA cutter location files),
:mod:`~hexapod_workspace.core.cell.reach` (reach along a direction, axis limits) and
:mod:`~hexapod_workspace.core.cell.scene_view` (the collision scene as drawn).
"""
