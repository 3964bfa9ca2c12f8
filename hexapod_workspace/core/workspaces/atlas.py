"""Orientation capability of a manipulator at many positions (the workspace atlas, per position).

What the atlas stores at each position p of a grid, computed with the public workspace
functions only (so an atlas value is, by construction, what a single-position call returns):

``reference_reachable``
    The reference orientation (φ, θ, ψ) = (0, 0, 0) is reachable at p (:func:`check`).
``tilt_capability``
    min over φ of the ``exact`` projected boundary θ_b(φ) (:func:`projected_workspace`): the
    half-angle of the largest cone of tool directions about the base z-axis that are all
    attainable with some torsion.
``tilt_capability_torsion_zero``
    The same with ψ = 0 (the paper's θmin). Taken from the same ``exact`` call: its ``gap`` is
    exact − torsion_zero per azimuth, and the torsion-zero rays are its ψ = 0 grid column, so no
    second search is needed (the test suite checks it against a ``torsion_zero`` call).
``tilt_max``
    max over φ of the ``exact`` boundary.
``solid_angle``
    Solid angle of the attainable tool directions (``exact``), sr.
``psi_min``, ``psi_max``
    The torsion interval at θ = 0 that contains ψ = 0 (:func:`torsion_range`).
``orientation_volume`` (optional, off by default)
    Volume of the 3-D orientation workspace in the cylindrical picture
    (:func:`orientation_workspace`), rad³.

Where the reference is unreachable every value but ``reference_reachable`` is NaN: the
workspace is empty there, which is a result and never a silent zero.

The dexterous workspace for a required tilt θ_req is the set of positions with
``tilt_capability ≥ θ_req`` (and, optionally, a torsion interval covering a required one); its
volume on a box grid counts one grid cell (step³) per position.

This module is numpy-only; the Dask engine and the Zarr store are in
:mod:`hexapod_workspace.atlas` (the optional ``atlas`` extra).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InputError
from ..base.resolution import validate_rays, validate_tolerance
from ..evaluation.check import check
from ..model.manipulator import Manipulator
from .orientation import orientation_workspace, torsion_range
from .projected import projected_workspace

__all__ = [
    "ATLAS_VARIABLES",
    "AtlasGrid",
    "AtlasOptions",
    "AtlasVariable",
    "dexterous_mask",
    "position_capability",
    "positions_capability",
]


@dataclass(frozen=True)
class AtlasVariable:
    """Name, unit and description of one per-position atlas value (store attributes)."""

    name: str
    units: str
    long_name: str


#: The per-position values, in store order. ``orientation_volume`` only with ``volume=True``.
ATLAS_VARIABLES: tuple[AtlasVariable, ...] = (
    AtlasVariable(
        "reference_reachable", "1", "reference orientation (phi, theta, psi) = (0, 0, 0) reachable"
    ),
    AtlasVariable(
        "tilt_capability",
        "rad",
        "tilt capability: min over azimuth of the exact projected boundary tilt "
        "(largest cone of tool directions all attainable with some torsion)",
    ),
    AtlasVariable(
        "tilt_capability_torsion_zero",
        "rad",
        "tilt capability at zero torsion: min over azimuth of the torsion_zero boundary tilt",
    ),
    AtlasVariable("tilt_max", "rad", "max over azimuth of the exact projected boundary tilt"),
    AtlasVariable("solid_angle", "sr", "solid angle of the attainable tool directions (exact)"),
    AtlasVariable("psi_min", "rad", "lowest torsion at zero tilt (interval containing psi = 0)"),
    AtlasVariable("psi_max", "rad", "highest torsion at zero tilt (interval containing psi = 0)"),
    AtlasVariable(
        "orientation_volume",
        "rad^3",
        "volume of the 3-D orientation workspace in the cylindrical picture",
    ),
)
_OPTIONAL = {"orientation_volume"}
#: Grid points per axis closer than this fraction of a step to the box end count as inside it.
_END_SLACK = 1e-9


@dataclass(frozen=True, eq=False)
class AtlasGrid:
    """The positions of an atlas: a box sampled with one step, or explicit positions.

    Build it with :meth:`box` or :meth:`from_positions`.

    Attributes
    ----------
    x, y, z : ndarray, shape (nx,), (ny,), (nz,)
        Box grids only: the coordinates of the grid planes, base frame, m (``x0 + k·step``).
    positions : ndarray, shape (n, 3) or None
        Explicit positions, base frame, m (``None`` for a box).
    step : float or None
        Box step, m.
    """

    x: NDArray[np.float64] | None = None
    y: NDArray[np.float64] | None = None
    z: NDArray[np.float64] | None = None
    positions: NDArray[np.float64] | None = None
    step: float | None = None

    @classmethod
    def box(cls, bounds: ArrayLike, step: float) -> AtlasGrid:
        """Grid ``x0 + k·step`` (and likewise y, z) inside the box [x0, x1]×[y0, y1]×[z0, z1].

        Parameters
        ----------
        bounds : array_like, shape (6,)
            x0, x1, y0, y1, z0, z1, base frame, m; ``x0 <= x1`` and so on (equal ends give a
            single plane).
        step : float
            Grid spacing, m, > 0.

        Raises
        ------
        InputError
            Non-finite values, an empty box (an upper end below its lower end), step <= 0.
        """
        values = np.asarray(bounds, dtype=np.float64)
        if values.shape != (6,) or not np.all(np.isfinite(values)):
            msg = f"box: expected 6 finite numbers x0 x1 y0 y1 z0 z1 in m, got {values.tolist()}"
            raise InputError(msg)
        step = float(step)
        if not (math.isfinite(step) and step > 0.0):
            msg = f"step: expected a positive length in m, got {step!r}"
            raise InputError(msg)
        axes = []
        for name, (low, high) in zip("xyz", values.reshape(3, 2), strict=True):
            if high < low:
                msg = f"box: empty, {name}1 = {high:g} m is below {name}0 = {low:g} m"
                raise InputError(msg)
            count = math.floor((high - low) / step + _END_SLACK) + 1
            axes.append(low + step * np.arange(count))
        return cls(x=axes[0], y=axes[1], z=axes[2], step=step)

    @classmethod
    def from_positions(cls, positions: ArrayLike) -> AtlasGrid:
        """Explicit positions, shape (n, 3), base frame, m (n >= 1, finite)."""
        array = np.asarray(positions, dtype=np.float64)
        if array.ndim != 2 or array.shape[1] != 3 or array.shape[0] == 0:
            msg = f"positions: expected shape (n, 3) with n >= 1, got {array.shape}"
            raise InputError(msg)
        if not np.all(np.isfinite(array)):
            msg = "positions: expected finite x, y, z in m"
            raise InputError(msg)
        return cls(positions=array.copy())

    @property
    def is_box(self) -> bool:
        """Whether this is a box grid (dims x, y, z) rather than a list (dim position)."""
        return self.positions is None

    @property
    def box_axes(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """The grid planes (x, y, z) of a box grid, m, shapes (nx,), (ny,), (nz,).

        Raises
        ------
        InputError
            The grid is a list of explicit positions.
        """
        if self.x is None or self.y is None or self.z is None:
            msg = "grid: explicit positions have no x, y, z grid planes"
            raise InputError(msg)
        return self.x, self.y, self.z

    @property
    def dims(self) -> tuple[str, ...]:
        """Dimension names of the stored arrays."""
        return ("x", "y", "z") if self.is_box else ("position",)

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of the stored arrays: (nx, ny, nz) or (n,)."""
        if self.positions is not None:
            return (self.positions.shape[0],)
        assert self.x is not None and self.y is not None and self.z is not None
        return (self.x.size, self.y.size, self.z.size)

    @property
    def size(self) -> int:
        """Number of positions."""
        return int(np.prod(self.shape))

    @property
    def cell_volume(self) -> float | None:
        """Volume one box grid position stands for (step³, m³); ``None`` for explicit ones."""
        return None if self.step is None else self.step**3

    def points(self, region: tuple[slice, ...]) -> NDArray[np.float64]:
        """Positions of a region of the grid (slices along ``dims``), C order; shape (n, 3)."""
        if self.positions is not None:
            return self.positions[region[0]]
        assert self.x is not None and self.y is not None and self.z is not None
        xs, ys, zs = np.meshgrid(
            self.x[region[0]], self.y[region[1]], self.z[region[2]], indexing="ij"
        )
        return np.column_stack([xs.ravel(), ys.ravel(), zs.ravel()])

    def to_attrs(self) -> dict[str, object]:
        """JSON-able description (store attributes; a resumed run must match it)."""
        if self.positions is not None:
            return {"kind": "positions", "count": int(self.positions.shape[0])}
        assert self.x is not None and self.y is not None and self.z is not None
        bounds = [float(v) for axis in (self.x, self.y, self.z) for v in (axis[0], axis[-1])]
        return {"kind": "box", "first_last": bounds, "step": self.step, "shape": list(self.shape)}


@dataclass(frozen=True)
class AtlasOptions:
    """Resolution of the per-position computation.

    Attributes
    ----------
    n_phi : int
        Azimuths of the projected workspaces (3 to 7200). ``tilt_capability`` is the minimum
        over these azimuths.
    tolerance : float
        Boundary tolerance of every search, rad.
    volume : bool
        Also compute ``orientation_volume`` (the 3-D orientation workspace; about an order of
        magnitude more work per position).
    n_rays : int
        Rays per ψ slice for ``orientation_volume``.
    psi_step : float
        ψ slice step for ``orientation_volume``, rad.
    """

    n_phi: int = 72
    tolerance: float = 1e-4
    volume: bool = False
    n_rays: int = 72
    psi_step: float = math.radians(2.0)

    def __post_init__(self) -> None:
        validate_rays(self.n_phi, "n_phi")
        validate_tolerance(self.tolerance)
        validate_rays(self.n_rays, "n_rays")
        if not (math.isfinite(self.psi_step) and 0.0 < self.psi_step <= math.pi / 4):
            msg = f"psi_step: expected 0 < psi_step <= pi/4 rad, got {self.psi_step!r}"
            raise InputError(msg)

    def variables(self) -> tuple[AtlasVariable, ...]:
        """The variables these options compute."""
        return tuple(v for v in ATLAS_VARIABLES if self.volume or v.name not in _OPTIONAL)

    def to_attrs(self) -> dict[str, float | int | bool]:
        """JSON-able form (store attributes)."""
        return {
            "n_phi": self.n_phi,
            "tolerance": self.tolerance,
            "volume": self.volume,
            "n_rays": self.n_rays,
            "psi_step": self.psi_step,
        }


def position_capability(
    manipulator: Manipulator, position: ArrayLike, options: AtlasOptions | None = None
) -> dict[str, float]:
    """The atlas values at one position (see the module documentation).

    Parameters
    ----------
    manipulator : Manipulator
    position : array_like, shape (3,)
        Tool-tip position OC, base frame, m.
    options : AtlasOptions, optional

    Returns
    -------
    dict of str to float
        One value per variable of ``options.variables()``; ``reference_reachable`` is 1.0 or
        0.0, every other value NaN when it is 0.0. Angles in rad, solid angle in sr.
    """
    options = AtlasOptions() if options is None else options
    names = [variable.name for variable in options.variables()]
    values = dict.fromkeys(names, math.nan)
    position = np.asarray(position, dtype=np.float64)
    reachable = bool(check(manipulator, np.zeros((1, 3)), position).reachable[0])
    values["reference_reachable"] = 1.0 if reachable else 0.0
    if not reachable:
        return values
    exact = projected_workspace(
        manipulator, position, method="exact", n_phi=options.n_phi, tolerance=options.tolerance
    )
    # The exact method always reports the gap to the torsion-zero boundary.
    gap = exact.gap if exact.gap is not None else np.zeros_like(exact.theta)
    values["tilt_capability"] = exact.tilt_min
    values["tilt_capability_torsion_zero"] = float(np.min(exact.theta - gap))
    values["tilt_max"] = exact.tilt_max
    values["solid_angle"] = exact.solid_angle
    intervals = torsion_range(
        manipulator, 0.0, 0.0, position, tolerance=options.tolerance
    ).intervals
    # The reference is reachable, so one interval holds ψ = 0 (to the tolerance of its ends).
    holding = intervals[(intervals[:, 0] <= 0.0) & (intervals[:, 1] >= 0.0)]
    if holding.shape[0]:
        values["psi_min"], values["psi_max"] = float(holding[0, 0]), float(holding[0, 1])
    if options.volume:
        values["orientation_volume"] = orientation_workspace(
            manipulator,
            position,
            n_rays=options.n_rays,
            psi_step=options.psi_step,
            tolerance=max(options.tolerance, 1e-5),
        ).volume
    return values


def positions_capability(
    manipulator: Manipulator, positions: ArrayLike, options: AtlasOptions | None = None
) -> dict[str, NDArray[np.float64]]:
    """The atlas values at several positions (one Dask task of the atlas runs this).

    Each position is an independent boundary search (vectorised over its rays); the loop here
    is over positions, whose per-position work is thousands of pose evaluations.

    Parameters
    ----------
    manipulator : Manipulator
    positions : array_like, shape (n, 3)
        Tool-tip positions, base frame, m.
    options : AtlasOptions, optional

    Returns
    -------
    dict of str to ndarray, shape (n,)
        As :func:`position_capability`, one array per variable.
    """
    options = AtlasOptions() if options is None else options
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    if not np.all(np.isfinite(positions)):
        msg = "positions: expected finite x, y, z in m"
        raise InputError(msg)
    names = [variable.name for variable in options.variables()]
    columns: dict[str, NDArray[np.float64]] = {
        name: np.full(positions.shape[0], np.nan) for name in names
    }
    for row, position in enumerate(positions):
        for name, value in position_capability(manipulator, position, options).items():
            columns[name][row] = value
    return columns


def dexterous_mask(
    tilt_capability: ArrayLike,
    tilt_required: float,
    *,
    psi_min: ArrayLike | None = None,
    psi_max: ArrayLike | None = None,
    torsion_required: Sequence[float] | None = None,
) -> NDArray[np.bool_]:
    """Positions of the dexterous workspace for a required tilt (and torsion range).

    Parameters
    ----------
    tilt_capability : array_like, shape (...)
        rad; NaN (reference unreachable) is never dexterous.
    tilt_required : float
        θ_req, rad, in [0, π].
    psi_min, psi_max : array_like, shape (...), optional
        Torsion interval at θ = 0, rad (needed with ``torsion_required``).
    torsion_required : (float, float), optional
        (ψ_lo, ψ_hi), rad: the interval must cover it as well.

    Returns
    -------
    ndarray of bool, shape (...)
    """
    if not (math.isfinite(tilt_required) and 0.0 <= tilt_required <= math.pi):
        msg = f"tilt_required: expected 0 to pi rad, got {tilt_required!r}"
        raise InputError(msg)
    capability = np.asarray(tilt_capability, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        mask = capability >= tilt_required
        if torsion_required is not None:
            low, high = (float(v) for v in torsion_required)
            if psi_min is None or psi_max is None or not low <= 0.0 <= high:
                msg = (
                    "torsion_required: expected (psi_lo <= 0 <= psi_hi) rad with psi_min and "
                    f"psi_max, got {torsion_required!r}"
                )
                raise InputError(msg)
            mask &= (np.asarray(psi_min) <= low) & (np.asarray(psi_max) >= high)
    return mask
