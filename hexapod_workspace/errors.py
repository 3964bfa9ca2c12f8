"""The package's small error hierarchy.

Every exception raised for malformed input derives from :class:`HexapodWorkspaceError`.
An unreachable *pose* is a result, never an exception.
"""

from __future__ import annotations

__all__ = [
    "AtlasError",
    "ConfigError",
    "GeometryError",
    "HexapodWorkspaceError",
    "InputError",
    "LogReadError",
    "MissingExtraError",
    "RecordingError",
    "ResolutionError",
    "UnreachableReferenceError",
]


class HexapodWorkspaceError(Exception):
    """Base class of every error this package raises on purpose."""


class ConfigError(HexapodWorkspaceError, ValueError):
    """A parameter of the configuration is missing, malformed or out of range."""


class GeometryError(ConfigError):
    """The manipulator geometry or its limits are invalid."""


class InputError(HexapodWorkspaceError, ValueError):
    """A request (poses, position, direction) is malformed: wrong shape, NaN or infinite."""


class ResolutionError(InputError):
    """A requested resolution (rays, slices, tolerance) is outside the supported bounds."""


class UnreachableReferenceError(HexapodWorkspaceError):
    """The reference orientation is itself unreachable, so the workspace is empty."""


class RecordingError(HexapodWorkspaceError):
    """An MCAP log could not be written."""


class LogReadError(HexapodWorkspaceError):
    """An MCAP log could not be read (missing, truncated beyond use, or not a log)."""


class MissingExtraError(HexapodWorkspaceError, ImportError):
    """An optional extra (e.g. ``atlas``: Dask, xarray, Zarr) is not installed."""


class AtlasError(HexapodWorkspaceError):
    """An atlas run cannot start or go on: store conflict, unreachable scheduler, no workers."""
