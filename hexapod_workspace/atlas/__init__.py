"""The workspace atlas on Dask, stored as Zarr through xarray (the optional ``atlas`` extra).

``import hexapod_workspace`` never imports Dask, xarray or Zarr: :func:`workspace_atlas` loads
the engine (:mod:`hexapod_workspace.atlas.engine`) on first call and, when the extra is missing,
raises :class:`~hexapod_workspace.errors.MissingExtraError` saying how to install it. The
per-position computation is numpy-only and lives in :mod:`hexapod_workspace.core.workspaces.atlas`.
"""

from __future__ import annotations

import shlex
import sys
from typing import TYPE_CHECKING, Any

from ..errors import MissingExtraError

if TYPE_CHECKING:
    from ..core.model.manipulator import Manipulator
    from ..core.workspaces.atlas import AtlasGrid
    from .engine import AtlasRun

__all__ = ["EXTRA_REQUIREMENTS", "install_hint", "require_extra", "workspace_atlas"]

#: The ``atlas`` extra of setup.py, requirement by requirement (a test keeps the two equal).
EXTRA_REQUIREMENTS = ("dask[distributed]>=2024.12", "xarray>=2025.1", "zarr>=3.0")
_MODULES = ("dask", "distributed", "xarray", "zarr")


def install_hint() -> str:
    """A command that installs the extra into the running interpreter, wherever the package came
    from (the package is not on the package index, so ``pip install hexapod_workspace[atlas]``
    cannot work): ``/path/to/python -m pip install 'dask[distributed]>=2024.12' ...``."""
    command = [sys.executable or "python3", "-m", "pip", "install", *EXTRA_REQUIREMENTS]
    return (
        " ".join(shlex.quote(word) for word in command)
        + " (in a clone of the repository also: pip install '.[atlas]')"
    )


def require_extra() -> None:
    """Raise :class:`MissingExtraError` unless Dask (distributed), xarray and Zarr import."""
    missing = []
    for name in _MODULES:
        try:
            __import__(name)
        except ImportError:
            missing.append(name)
    if missing:
        msg = (
            f"the workspace atlas needs the 'atlas' extra ({', '.join(missing)} missing): "
            f"{install_hint()}"
        )
        raise MissingExtraError(msg)


def workspace_atlas(manipulator: Manipulator, grid: AtlasGrid, **options: Any) -> AtlasRun:
    """Compute the workspace atlas over a grid of positions (see :func:`.engine.run_atlas`).

    Parameters
    ----------
    manipulator : Manipulator
    grid : AtlasGrid
        A box with a step (:meth:`AtlasGrid.box`) or explicit positions
        (:meth:`AtlasGrid.from_positions`), base frame, m.
    **options
        Keyword options of :func:`hexapod_workspace.atlas.engine.run_atlas` (``store``,
        ``options``, ``scheduler``, ``workers``, ``resume``, ``chunk``, ``progress``, ...).

    Returns
    -------
    AtlasRun

    Raises
    ------
    MissingExtraError
        Dask, xarray or Zarr is not installed.
    """
    require_extra()
    from .engine import run_atlas

    return run_atlas(manipulator, grid, **options)
