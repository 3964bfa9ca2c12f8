"""The atlas engine: chunks of positions as Dask tasks, results written chunk by chunk.

Where the work runs:

* by default a local ``dask.distributed`` cluster on this machine's cores (worker processes,
  one thread each, bound to 127.0.0.1, no dashboard), started and stopped here;
* ``scheduler=ADDRESS`` (or the ``DASK_SCHEDULER_ADDRESS`` environment variable): an existing
  cluster; the same tasks, nothing else changes;
* ``workers=0``: in this process, without Dask (the reference for tests and benchmarks).

Tasks return their values to this process, which alone writes the store (so workers need no
shared file system): each finished chunk's data first, then its completion marker. A worker
that dies has its tasks rerun elsewhere by the scheduler; an interrupted run keeps every chunk
with a marker and ``resume=True`` computes only the others.
"""

from __future__ import annotations

import logging
import os
import shutil
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import xarray as xr

from ..core import kernels
from ..core.model.manipulator import Manipulator
from ..core.workspaces.atlas import (
    AtlasGrid,
    AtlasOptions,
    dexterous_mask,
    positions_capability,
)
from ..errors import AtlasError, InputError
from .store import (
    ChunkLayout,
    check_resumable,
    create_store,
    done_chunks,
    mark_done,
    open_atlas,
    set_complete,
    settle_store_io,
    store_attrs,
    write_chunk,
)

__all__ = ["AtlasRun", "dexterous_volume", "run_atlas"]

#: progress(positions_done, positions_total)
AtlasProgress = Callable[[int, int], None]
#: Seconds to wait for an existing scheduler to answer, and for a first worker.
CONNECT_TIMEOUT = 5.0


@dataclass(frozen=True)
class AtlasRun:
    """Outcome of an atlas run.

    Attributes
    ----------
    store : pathlib.Path
        The Zarr store.
    dataset : xarray.Dataset
        Its content, loaded into memory.
    grid : AtlasGrid
    elapsed : float
        Wall time of this run, s.
    workers : int
        Dask workers at the start (0: computed in this process).
    chunks_total, chunks_computed : int
        Chunks of the grid, and those this run computed (the others were done before: resume).
    positions_computed : int
        Positions this run computed.
    """

    store: Path
    dataset: xr.Dataset
    grid: AtlasGrid
    elapsed: float
    workers: int
    chunks_total: int
    chunks_computed: int
    positions_computed: int

    def dexterous_volume(
        self, tilt_required: float, torsion_required: tuple[float, float] | None = None
    ) -> float | None:
        """Volume of the dexterous workspace, m³ (see :func:`dexterous_volume`)."""
        return dexterous_volume(self.dataset, self.grid, tilt_required, torsion_required)


def dexterous_volume(
    dataset: xr.Dataset,
    grid: AtlasGrid,
    tilt_required: float,
    torsion_required: tuple[float, float] | None = None,
) -> float | None:
    """Volume (m³) of the positions with ``tilt_capability >= tilt_required`` (rad).

    Each box grid position stands for one cell of step³; ``None`` for explicit positions
    (they sample no volume). With ``torsion_required = (ψ_lo, ψ_hi)`` (rad) the torsion interval
    at θ = 0 must cover it too.
    """
    mask = dexterous_mask(
        dataset["tilt_capability"].values,
        tilt_required,
        psi_min=dataset["psi_min"].values,
        psi_max=dataset["psi_max"].values,
        torsion_required=torsion_required,
    )
    cell = grid.cell_volume
    return None if cell is None else float(mask.sum()) * cell


class _InProcess:
    """Computes chunks in this process, in order (``workers=0``)."""

    def __init__(self, manipulator: Manipulator, options: AtlasOptions) -> None:
        self.manipulator = manipulator
        self.options = options

    def run(self, jobs, finished) -> None:
        for chunk_id, points in jobs:
            finished(chunk_id, positions_capability(self.manipulator, points, self.options))


class _OnDask:
    """Submits chunks to a dask.distributed cluster and hands results back as they finish."""

    def __init__(
        self,
        manipulator: Manipulator,
        options: AtlasOptions,
        scheduler: str | None,
        workers: int | None,
        connect_timeout: float,
    ) -> None:
        from distributed import Client, LocalCluster

        self.manipulator = manipulator
        self.options = options
        self.cluster = None
        if scheduler:
            try:
                self.client = Client(scheduler, timeout=connect_timeout)
            except (OSError, TimeoutError, ValueError) as error:
                reason = " ".join(str(error).split()) or type(error).__name__
                msg = (
                    f"cannot reach the Dask scheduler at {scheduler} within "
                    f"{connect_timeout:g} s: {reason}"
                )
                raise AtlasError(msg) from error
        else:
            count = workers if workers is not None else len(os.sched_getaffinity(0))
            self.cluster = LocalCluster(
                n_workers=count,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=None,
                silence_logs=logging.ERROR,  # no worker chatter on the CLI's stderr
            )
            self.client = Client(self.cluster)
        try:
            self.client.wait_for_workers(1, timeout=connect_timeout)
        except TimeoutError as error:
            self.close()
            msg = f"the Dask scheduler has no workers (waited {connect_timeout:g} s)"
            raise AtlasError(msg) from error
        self.workers = len(self.client.scheduler_info().get("workers", {}))
        # Each worker process loads (or, on a fresh cache, compiles) the kernels once, all at
        # the same time, instead of inside its first chunk.
        self.client.run(kernels.warm_up, kernels.model_vector(self.manipulator))

    def run(self, jobs, finished) -> None:
        from distributed import as_completed

        model = self.client.scatter(self.manipulator, broadcast=True)
        futures = {}
        for chunk_id, points in jobs:
            future = self.client.submit(
                positions_capability, model, points, self.options, pure=False
            )
            futures[future] = chunk_id
        try:
            for future in as_completed(futures):
                try:
                    values = future.result()
                except Exception as error:  # a task that failed for good on the cluster
                    reason = " ".join(str(error).split()) or type(error).__name__
                    msg = (
                        f"chunk {futures[future]} failed on the Dask cluster "
                        f"({type(error).__name__}: {reason}); the finished chunks are kept, "
                        "--resume completes the store"
                    )
                    raise AtlasError(msg) from error
                finished(futures[future], values)
        finally:
            self.client.cancel(list(futures))

    def close(self) -> None:
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def run_atlas(
    manipulator: Manipulator,
    grid: AtlasGrid,
    *,
    store: str | Path,
    options: AtlasOptions | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    resume: bool = False,
    chunk: tuple[int, ...] | None = None,
    progress: AtlasProgress | None = None,
    connect_timeout: float = CONNECT_TIMEOUT,
) -> AtlasRun:
    """Compute the atlas values over a grid and write them to a Zarr store.

    Parameters
    ----------
    manipulator : Manipulator
    grid : AtlasGrid
        Positions, base frame, m.
    store : str or pathlib.Path
        The Zarr store to create (``STORE.zarr``); it must not exist unless ``resume``.
    options : AtlasOptions, optional
        Resolution per position (default :class:`AtlasOptions`).
    scheduler : str, optional
        Address of an existing dask.distributed scheduler (``tcp://host:8786``); default the
        ``DASK_SCHEDULER_ADDRESS`` environment variable, else a local cluster.
    workers : int, optional
        Local cluster size (default: the cores this process may use); 0 computes in this
        process without Dask. Not allowed together with a scheduler.
    resume : bool
        Complete an existing store of the same run (manipulator, grid, options, chunks,
        software version): only chunks without a completion marker are computed.
    chunk : tuple of int, optional
        Positions per chunk along each dim (default: see :meth:`ChunkLayout.for_grid`).
    progress : callable, optional
        ``progress(positions_done, positions_total)`` after each chunk (and once at the start).
    connect_timeout : float
        Seconds to wait for the scheduler and for a first worker.

    Returns
    -------
    AtlasRun

    Raises
    ------
    AtlasError
        The store exists (without ``resume``) or belongs to another run, the scheduler cannot
        be reached, or it has no workers.
    InputError
        ``workers`` negative, or given with a scheduler.
    """
    started = time.perf_counter()
    options = AtlasOptions() if options is None else options
    path = Path(store)
    scheduler = scheduler or os.environ.get("DASK_SCHEDULER_ADDRESS") or None
    if workers is not None and (workers < 0 or (scheduler and workers)):
        msg = f"workers: expected >= 0 and no scheduler address, got {workers}"
        raise InputError(msg)
    if workers != 0 and _reimported_by_a_worker():
        raise AtlasError(_GUARD_HINT)  # before the store is touched
    layout = ChunkLayout.for_grid(grid, chunk)
    attrs = store_attrs(manipulator, grid, options, layout)
    created = False
    if path.exists():
        if not resume:
            raise AtlasError(_existing_store(path, layout))
        check_resumable(path, attrs)
    else:
        create_store(path, grid, options, layout, attrs)
        created = True
    done = done_chunks(path)
    pending = [(k, region) for k, region in layout.regions() if k not in done]
    total = grid.size
    done_positions = total - sum(_region_size(region) for _, region in pending)
    if progress:
        progress(done_positions, total)
    regions = dict(pending)
    computed = {"chunks": 0, "positions": 0}

    def finished(chunk_id: int, values) -> None:
        region = regions[chunk_id]
        write_chunk(path, grid, region, values)
        mark_done(path, layout, chunk_id)
        computed["chunks"] += 1
        computed["positions"] += _region_size(region)
        if progress:
            progress(done_positions + computed["positions"], total)

    jobs = [(k, grid.points(region)) for k, region in pending]
    try:
        engine = (
            _InProcess(manipulator, options)
            if workers == 0
            else _OnDask(manipulator, options, scheduler, workers, connect_timeout)
        )
    except AtlasError:
        if created:  # nothing was computed: leave no empty store behind
            shutil.rmtree(path, ignore_errors=True)
        raise
    except Exception as error:  # the local cluster did not start (e.g. "Nanny failed to start")
        if created:
            shutil.rmtree(path, ignore_errors=True)
        reason = " ".join(str(error).split()) or type(error).__name__
        msg = f"the local Dask cluster did not start ({type(error).__name__}: {reason})"
        if _main_is_a_script():
            msg += f"; {_GUARD_HINT}"
        raise AtlasError(msg) from error
    worker_count = getattr(engine, "workers", 0)
    try:
        if jobs:
            engine.run(jobs, finished)
    except BaseException:  # an interrupt too: the cluster closes, the chunk being written ends
        if isinstance(engine, _OnDask):
            engine.close()
        settle_store_io()
        raise
    if isinstance(engine, _OnDask):
        engine.close()
    set_complete(path, True)
    dataset = open_atlas(path).load()
    return AtlasRun(
        store=path,
        dataset=dataset,
        grid=grid,
        elapsed=time.perf_counter() - started,
        workers=worker_count,
        chunks_total=layout.total,
        chunks_computed=computed["chunks"],
        positions_computed=computed["positions"],
    )


#: Why a script that starts a local cluster fails without the main guard, and what to do.
_GUARD_HINT = (
    "Dask's worker processes re-import the script that starts a local cluster, so a script "
    'must call workspace_atlas under `if __name__ == "__main__":` (or pass workers=0)'
)


def _reimported_by_a_worker() -> bool:
    """True in a worker process that is importing the user's script as ``__mp_main__`` (what
    multiprocessing's spawn does): starting a cluster there would fail, so refuse at once."""
    # In the process that ran the script, sys.modules["__mp_main__"] is "__main__" itself.
    main = sys.modules.get("__mp_main__")  # spawn runs the script under this name
    return getattr(main, "__name__", "") == "__mp_main__"


def _main_is_a_script() -> bool:
    """True when ``__main__`` is a file the worker processes re-import (not a REPL, not -c)."""
    return bool(getattr(sys.modules.get("__main__"), "__file__", None))


def _existing_store(path: Path, layout: ChunkLayout) -> str:
    """The refusal for an existing store without ``resume``: what it holds and what to do."""
    try:
        done = len(done_chunks(path))
    except Exception:  # not a store of ours, or its metadata is damaged
        return (
            f"store {path} already exists and is not a readable atlas store: remove it "
            "(or choose another store)"
        )
    if done >= layout.total:
        return (
            f"store {path} already exists and is complete ({done} of {layout.total} chunks): "
            "open it with hexapod_workspace.atlas.store.open_atlas (resume=True, --resume "
            "returns it without computing), or remove it to compute it again"
        )
    return (
        f"store {path} already exists and is incomplete ({done} of {layout.total} chunks "
        "done, an interrupted run): resume=True (CLI --resume) computes only the missing "
        "chunks; or remove it to start again"
    )


def _region_size(region: tuple[slice, ...]) -> int:
    size = 1
    for piece in region:
        size *= piece.stop - piece.start
    return size
