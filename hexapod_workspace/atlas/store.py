"""The atlas Zarr store, written through xarray one chunk of positions at a time.

Layout of ``STORE.zarr``:

* a Zarr group holding an xarray Dataset: dims ``x, y, z`` (box grids, coordinates in m) or
  ``position`` (explicit positions, with coordinates ``x, y, z`` along it); one variable per
  atlas value (:data:`~hexapod_workspace.core.workspaces.atlas.ATLAS_VARIABLES`) with ``units`` and
  ``long_name``; store attributes: the manipulator parameters, the grid, the options, the
  software version, the chunk shape and ``complete``;
* ``chunk_done`` (dims ``chunk_x, chunk_y, chunk_z`` or ``chunk``, one Zarr chunk per element):
  the completion marker of each atlas chunk, set to 1 only after that chunk's data is in the
  store. A resumed run computes exactly the chunks whose marker is 0, so an interruption loses
  at most the chunks in flight.

Zarr chunks and atlas chunks coincide, so every chunk write touches its own Zarr chunks only.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import dask.array as da
import numpy as np
import xarray as xr
from numpy.typing import NDArray

from ..core.model.manipulator import Manipulator
from ..core.workspaces.atlas import ATLAS_VARIABLES, AtlasGrid, AtlasOptions
from ..errors import AtlasError

__all__ = [
    "MARKER",
    "ChunkLayout",
    "check_resumable",
    "create_store",
    "done_chunks",
    "mark_done",
    "open_atlas",
    "set_complete",
    "settle_store_io",
    "store_attrs",
    "write_chunk",
]

MARKER = "chunk_done"
#: Default chunk shapes shrink until the grid has at least this many chunks.
MIN_CHUNKS = 32
_COORD_ATTRS = {
    "x": {"units": "m", "long_name": "tool-tip position x, base frame"},
    "y": {"units": "m", "long_name": "tool-tip position y, base frame"},
    "z": {"units": "m", "long_name": "tool-tip position z, base frame"},
}


@dataclass(frozen=True)
class ChunkLayout:
    """How a grid is cut into chunks (tasks and Zarr chunks alike).

    Attributes
    ----------
    shape : tuple of int
        Grid shape (along the grid's dims).
    chunk : tuple of int
        Chunk shape (same rank), each entry >= 1.
    """

    shape: tuple[int, ...]
    chunk: tuple[int, ...]

    @classmethod
    def for_grid(cls, grid: AtlasGrid, chunk: tuple[int, ...] | None = None) -> ChunkLayout:
        """The given chunk shape, or a default: the largest of 4×4×4, 3×3×3, 2×2×2 (64 to 8
        explicit positions) that still cuts the grid into :data:`MIN_CHUNKS` chunks (so that
        the workers stay busy to the end), else one position per chunk."""
        shape = grid.shape
        if chunk is None:
            chunk = (1,) * len(shape)
            for edge in (4, 3, 2):
                trial = (edge,) * 3 if grid.is_box else (edge**3,)
                if np.prod([math.ceil(s / c) for s, c in zip(shape, trial, strict=True)]) >= (
                    MIN_CHUNKS
                ):
                    chunk = trial
                    break
        chunk = tuple(int(c) for c in chunk)
        if len(chunk) != len(shape) or any(c < 1 for c in chunk):
            msg = f"chunk: expected {len(shape)} positive integers, got {list(chunk)}"
            raise AtlasError(msg)
        return cls(shape, tuple(min(c, s) for c, s in zip(chunk, shape, strict=True)))

    @property
    def counts(self) -> tuple[int, ...]:
        """Chunks per dim."""
        return tuple(math.ceil(s / c) for s, c in zip(self.shape, self.chunk, strict=True))

    @property
    def marker_dims(self) -> tuple[str, ...]:
        """Dims of the completion markers."""
        return ("chunk_x", "chunk_y", "chunk_z") if len(self.shape) == 3 else ("chunk",)

    @property
    def total(self) -> int:
        """Number of chunks."""
        return int(np.prod(self.counts))

    def region(self, chunk_id: int) -> tuple[slice, ...]:
        """Slices of chunk ``chunk_id`` (C-order flat index over :attr:`counts`)."""
        index = np.unravel_index(chunk_id, self.counts)
        return tuple(
            slice(int(i) * c, min((int(i) + 1) * c, s))
            for i, c, s in zip(index, self.chunk, self.shape, strict=True)
        )

    def regions(self) -> list[tuple[int, tuple[slice, ...]]]:
        """Every (chunk id, region), in chunk id order."""
        return [(k, self.region(k)) for k in range(self.total)]


def store_attrs(
    manipulator: Manipulator, grid: AtlasGrid, options: AtlasOptions, layout: ChunkLayout
) -> dict[str, Any]:
    """The store attributes that define a run (a resumed run must match them)."""
    from .. import __version__

    return {
        "title": "hexapod_workspace atlas: orientation capability over the working volume",
        "software": "hexapod_workspace",
        "software_version": __version__,
        "manipulator_parameters": json.dumps(manipulator.to_parameters(), sort_keys=True),
        "grid": json.dumps(grid.to_attrs(), sort_keys=True),
        "atlas_options": json.dumps(options.to_attrs(), sort_keys=True),
        "chunk_shape": list(layout.chunk),
        "frame_id": manipulator.frame_id,
    }


def create_store(
    path: Path,
    grid: AtlasGrid,
    options: AtlasOptions,
    layout: ChunkLayout,
    attrs: dict[str, Any],
) -> None:
    """Write the store's metadata and coordinates (no chunk data, no markers)."""
    dims = grid.dims
    if grid.is_box:
        coords = {name: (name, getattr(grid, name), _COORD_ATTRS[name]) for name in "xyz"}
    else:
        assert grid.positions is not None
        coords = {
            name: ("position", grid.positions[:, k], _COORD_ATTRS[name])
            for k, name in enumerate("xyz")
        }
    variables = {}
    for variable in options.variables():
        boolean = variable.name == "reference_reachable"
        fill = (
            da.zeros(grid.shape, dtype=bool, chunks=layout.chunk)
            if boolean
            else da.full(grid.shape, np.nan, dtype=np.float64, chunks=layout.chunk)
        )
        variables[variable.name] = (
            dims,
            fill,
            {"units": variable.units, "long_name": variable.long_name},
        )
    variables[MARKER] = (
        layout.marker_dims,
        da.zeros(layout.counts, dtype=np.uint8, chunks=1),
        {
            "units": "1",
            "long_name": "completion marker of each atlas chunk (1: its data is in the store)",
        },
    )
    dataset = xr.Dataset(variables, coords=coords, attrs={**attrs, "complete": False})
    try:
        dataset.to_zarr(path, mode="w-", compute=False, consolidated=False)
    except FileExistsError as error:  # raced with another writer
        msg = f"store {path} already exists"
        raise AtlasError(msg) from error


def write_chunk(
    path: Path,
    grid: AtlasGrid,
    region: tuple[slice, ...],
    values: dict[str, NDArray[np.float64]],
) -> None:
    """Write one chunk's values (arrays of shape (n,), C order over the region) to the store."""
    shape = tuple(s.stop - s.start for s in region)
    data = {}
    for name, column in values.items():
        array = np.asarray(column).reshape(shape)
        if name == "reference_reachable":
            array = array > 0.5
        data[name] = (grid.dims, array)
    xr.Dataset(data).to_zarr(
        path, region=dict(zip(grid.dims, region, strict=True)), mode="r+", consolidated=False
    )


def mark_done(path: Path, layout: ChunkLayout, chunk_id: int) -> None:
    """Set the completion marker of a chunk (call it after :func:`write_chunk`)."""
    index = np.unravel_index(chunk_id, layout.counts)
    region = {
        dim: slice(int(i), int(i) + 1) for dim, i in zip(layout.marker_dims, index, strict=True)
    }
    marker = np.ones((1,) * len(index), dtype=np.uint8)
    xr.Dataset({MARKER: (layout.marker_dims, marker)}).to_zarr(
        path, region=region, mode="r+", consolidated=False
    )


def done_chunks(path: Path) -> set[int]:
    """Ids (C-order flat indices) of the chunks whose completion marker is set."""
    markers = xr.open_zarr(path, consolidated=False)[MARKER].values
    return {int(k) for k in np.flatnonzero(markers.ravel() == 1)}


def set_complete(path: Path, complete: bool) -> None:
    """Record in the store attributes whether every chunk is done."""
    import zarr

    group = zarr.open_group(str(path), mode="r+")
    group.attrs["complete"] = bool(complete)


def check_resumable(path: Path, attrs: dict[str, Any]) -> None:
    """Refuse to resume a store made for another manipulator, grid, options or version."""
    try:
        stored = dict(xr.open_zarr(path, consolidated=False).attrs)
    except (OSError, ValueError, KeyError) as error:
        msg = f"cannot resume {path}: not an atlas store ({error})"
        raise AtlasError(msg) from error
    for key, value in attrs.items():
        old: Any
        if key == "chunk_shape":
            value, old = list(value), list(stored.get(key, []))
        else:
            old = stored.get(key)
        if old != value:
            msg = (
                f"cannot resume {path}: it was made with another {key.replace('_', ' ')} "
                "(remove it or choose another --out)"
            )
            raise AtlasError(msg)


def open_atlas(path: str | Path) -> xr.Dataset:
    """Open an atlas store (lazily, Dask-backed) as an xarray Dataset, variables in the order
    of :data:`~hexapod_workspace.core.workspaces.atlas.ATLAS_VARIABLES`, markers last."""
    dataset = xr.open_zarr(Path(path), consolidated=False)
    order = [v.name for v in ATLAS_VARIABLES if v.name in dataset.data_vars]
    rest = [name for name in dataset.data_vars if name not in order]
    return dataset[order + rest]


def settle_store_io(timeout: float = 10.0) -> None:
    """Wait (at most ``timeout`` s) until zarr's I/O thread has nothing left running.

    An interrupt (SIGINT: KeyboardInterrupt in the main thread) can land while the main thread
    waits for zarr to write a chunk; the write goes on in zarr's I/O thread. zarr's exit
    handler stops that thread and waits only 0.2 s for it, then writes "Thread did not finish
    cleanly; forcefully closing the event loop" to stderr (a loaded machine is slower than
    that). Called on the way out of an interrupted run, this lets the write finish first, so
    the handler finds the thread idle. Reads zarr's module state (``zarr.core.sync.loop``);
    does nothing when it is not there (another zarr version) or not running.
    """
    import asyncio
    import contextlib

    with contextlib.suppress(Exception):
        from zarr.core import sync

        loop = sync.loop[0]
        if loop is None or not loop.is_running():
            return

        async def drained() -> None:
            current = asyncio.current_task()
            pending = [task for task in asyncio.all_tasks() if task is not current]
            if pending:
                await asyncio.wait(pending, timeout=timeout)

        asyncio.run_coroutine_threadsafe(drained(), loop).result(timeout + 1.0)
