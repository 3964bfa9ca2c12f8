"""Locate data files shipped with the package (example configuration, interface definitions).

An installed package carries them in ``hexapod_workspace/_data`` (copied there by ``setup.py``);
a source checkout or an editable install finds them at the top of the repository.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["data_dir", "data_path", "example_config_path"]

_PACKAGE_DIR = Path(__file__).resolve().parent
_REPO_DIRS = {"config": "config", "msg": "msg_defs/msg", "srv": "msg_defs/srv"}


def data_path(kind: str, name: str) -> Path:
    """Return the path of a shipped data file.

    Parameters
    ----------
    kind : {"config", "msg", "srv"}
        Which data folder.
    name : str
        File name inside it, e.g. ``"example_gpm.yaml"`` or ``"TiltTorsion.msg"``.

    Returns
    -------
    pathlib.Path
        An existing file.

    Raises
    ------
    FileNotFoundError
        When neither the installed copy nor the source checkout has the file.
    """
    candidates = [
        _PACKAGE_DIR / "_data" / kind / name,
        _PACKAGE_DIR.parent / _REPO_DIRS[kind] / name,
    ]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    msg = f"data file {kind}/{name} not found (looked in {', '.join(map(str, candidates))})"
    raise FileNotFoundError(msg)


def data_dir(kind: str) -> Path:
    """Return the folder holding the shipped files of one kind (``"msg"`` or ``"srv"``)."""
    for candidate in (_PACKAGE_DIR / "_data" / kind, _PACKAGE_DIR.parent / _REPO_DIRS[kind]):
        if candidate.is_dir():
            return candidate
    msg = f"data folder {kind} not found"
    raise FileNotFoundError(msg)


def example_config_path() -> Path:
    """Return the packaged example parameters file (an axisymmetric GPM, paper's Fig. 1 style)."""
    return data_path("config", "example_gpm.yaml")
