"""The workspace layer: certified searches over orientations, above
:mod:`~hexapod_workspace.core.evaluation`.

:mod:`~hexapod_workspace.core.workspaces.search` (the certified ray searches),
:mod:`~hexapod_workspace.core.workspaces.projected` (the projected orientation workspace of Bonev &
Ryu), :mod:`~hexapod_workspace.core.workspaces.orientation` (the 3-D workspace and torsion ranges)
and :mod:`~hexapod_workspace.core.workspaces.atlas` (workspaces over a box of positions).
"""
