"""``hexapod-workspace atlas``: orientation capability over a box of positions, on Dask.

::

    hexapod-workspace atlas --box X0 X1 Y0 Y1 Z0 Z1 --step S --out STORE.zarr
        [--tilt-required-deg T ...] [--scheduler ADDR] [--workers N] [--resume] [--plot DIR]
        [--json]

Lengths in m, angles in degrees. Exit 0 when the store is complete, 2 on bad input (one line on
stderr): an empty box, a step <= 0, more than :data:`MAX_POSITIONS` positions without
``--force``, an existing store without ``--resume``, an unreachable scheduler, a missing
``atlas`` extra.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..core.model.manipulator import Manipulator
from ..core.workspaces.atlas import (
    AtlasGrid,
    AtlasOptions,
    dexterous_mask,
    positions_capability,
)
from ..errors import InputError
from .inputs import CliError, configured_manipulator, finite, tolerance_flag
from .progress import ProgressBar

__all__ = [
    "ATLAS_DESCRIPTION",
    "ATLAS_HELP",
    "ESTIMATE_SAMPLES",
    "MAX_POSITIONS",
    "atlas_arguments",
    "atlas_summary",
    "cmd_atlas",
]

#: Positions above which the command asks for ``--force`` (with an estimate of the cost).
MAX_POSITIONS = 20_000
#: Default boundary tolerance of the atlas, rad: coarser than a single workspace's
#: (resolution.DEFAULT_TOLERANCE) because an atlas computes thousands of them.
ATLAS_TOLERANCE = 1e-4
#: Positions of the grid timed for the estimate of the ``--force`` message (after one untimed
#: position that loads the compiled kernels).
ESTIMATE_SAMPLES = 8


ATLAS_HELP = "orientation capability over a box of positions (Dask, Zarr store)"
ATLAS_DESCRIPTION = (
    "Over the grid x0 + k*step (and y, z) inside the box: whether the reference "
    "orientation is reachable, the tilt capability (largest cone of tool directions all "
    "attainable), its torsion-zero value, the largest tilt, the solid angle and the torsion "
    "range at zero tilt. Runs on a local Dask cluster (or --scheduler) and writes a Zarr "
    "store chunk by chunk; --resume completes an interrupted run. Needs the 'atlas' extra."
)


def atlas_arguments(sub: argparse.ArgumentParser) -> None:
    """The ``atlas`` command's own options."""
    sub.add_argument(
        "--box",
        nargs=6,
        type=float,
        required=True,
        metavar=("X0", "X1", "Y0", "Y1", "Z0", "Z1"),
        help="box of tool-tip positions, base frame, m",
    )
    sub.add_argument("--step", type=float, required=True, metavar="S", help="grid step, m")
    sub.add_argument("--out", required=True, metavar="STORE.zarr", help="Zarr store to write")
    sub.add_argument(
        "--tilt-required-deg",
        type=float,
        nargs="+",
        action="extend",
        default=[],
        metavar="T",
        help="required tilt for the dexterous workspace, degrees (repeatable)",
    )
    sub.add_argument(
        "--torsion-required-deg",
        type=float,
        nargs=2,
        metavar=("LO", "HI"),
        help="also require the torsion range at zero tilt to cover [LO, HI] degrees",
    )
    sub.add_argument(
        "--scheduler",
        metavar="ADDR",
        help="existing Dask scheduler (tcp://host:port; default: $DASK_SCHEDULER_ADDRESS when "
        "set, else a local cluster)",
    )
    sub.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="local cluster workers (default: the cores; 0 = in this process, no Dask)",
    )
    sub.add_argument("--resume", action="store_true", help="complete an interrupted --out store")
    sub.add_argument("--plot", metavar="DIR", help="write heat maps and a 3-D view into DIR")
    sub.add_argument(
        "--n-phi",
        type=int,
        default=72,
        metavar="N",
        help="azimuths per position (default %(default)s)",
    )
    sub.add_argument(
        "--tol-deg",
        type=float,
        metavar="T",
        help=f"boundary tolerance, degrees (default {math.degrees(ATLAS_TOLERANCE):.3g}, "
        f"i.e. {ATLAS_TOLERANCE:g} rad)",
    )
    sub.add_argument(
        "--chunk",
        type=int,
        nargs=3,
        metavar=("CX", "CY", "CZ"),
        help="positions per task and Zarr chunk along x, y, z "
        "(default: 4 4 4, smaller for small grids)",
    )
    sub.add_argument(
        "--volume", action="store_true", help="also the 3-D orientation workspace volume (slow)"
    )
    sub.add_argument(
        "--force", action="store_true", help=f"allow more than {MAX_POSITIONS} positions"
    )


def _grid(options: argparse.Namespace) -> AtlasGrid:
    """The box grid of the options."""
    return AtlasGrid.box(
        finite(options.box, "--box", "m"), finite([options.step], "--step", "m")[0]
    )


def measured_seconds_per_position(
    manipulator: Manipulator,
    grid: AtlasGrid,
    options: AtlasOptions,
    samples: int = ESTIMATE_SAMPLES,
) -> tuple[float, int]:
    """Time the atlas at a few positions of ``grid``, spread evenly over it (C order).

    The cost of a position depends on the machine, the options (``n_phi``, tolerance,
    ``volume``) and where it is (an unreachable reference costs one check), so the estimate of
    a run is measured on the run's own grid, not taken from a constant.

    Returns
    -------
    seconds : float
        Mean wall time per position, one core (this process), s.
    count : int
        Positions timed.
    """
    count = min(samples, grid.size)
    flat = np.unique(np.linspace(0, grid.size - 1, count + 1).round().astype(np.int64))
    positions = np.vstack(
        [
            grid.points(tuple(slice(int(i), int(i) + 1) for i in where))
            for where in zip(*np.unravel_index(flat, grid.shape), strict=True)
        ]
    )
    positions_capability(manipulator, positions[:1], options)  # loads the kernels, untimed
    started = time.perf_counter()
    positions_capability(manipulator, positions[1:], options)
    return (time.perf_counter() - started) / max(len(positions) - 1, 1), len(positions) - 1


def _check_cap(
    grid: AtlasGrid, manipulator: Manipulator, options: AtlasOptions, force: bool
) -> None:
    """Refuse more than :data:`MAX_POSITIONS` positions without ``--force``, with the cost
    estimated from a measurement."""
    if grid.size <= MAX_POSITIONS or force:
        return
    seconds, timed = measured_seconds_per_position(manipulator, grid, options)
    hours = grid.size * seconds / 3600.0
    msg = (
        f"--box/--step give {grid.size} positions, more than the cap of {MAX_POSITIONS} "
        f"(about {hours:.3g} core-hours: {1e3 * seconds:.3g} ms per position, measured here at "
        f"{timed} positions of this grid): add --force to run it"
    )
    raise CliError(msg)


def atlas_summary(
    dataset: Any, grid: AtlasGrid, tilts_deg: list[float], torsion_deg: list[float] | None
) -> dict[str, Any]:
    """Counts, tilt capability statistics (degrees) and dexterous volumes (m³) of an atlas."""
    capability = np.degrees(dataset["tilt_capability"].values)
    reachable = dataset["reference_reachable"].values.astype(bool)
    known = capability[np.isfinite(capability)]
    stats = (
        {"min": float(known.min()), "max": float(known.max()), "mean": float(known.mean())}
        if known.size
        else {"min": None, "max": None, "mean": None}
    )
    torsion = None if torsion_deg is None else tuple(math.radians(v) for v in torsion_deg)
    volumes = {}
    for tilt in tilts_deg:
        mask = dexterous_mask(
            dataset["tilt_capability"].values,
            math.radians(tilt),
            psi_min=dataset["psi_min"].values,
            psi_max=dataset["psi_max"].values,
            torsion_required=torsion,
        )
        cell = grid.cell_volume
        volumes[f"{tilt:g}"] = None if cell is None else float(mask.sum()) * cell
    return {
        "positions": int(grid.size),
        "reachable_positions": int(reachable.sum()),
        "tilt_capability_deg": stats,
        "dexterous_volume_m3": volumes,
    }


def cmd_atlas(options: argparse.Namespace, out: IO[str], err: IO[str]) -> int:
    """``atlas``: compute (or complete, ``--resume``) an atlas store; print its summary."""
    tilts = [
        float(t) for t in finite(options.tilt_required_deg or [], "--tilt-required-deg", "degrees")
    ]
    if any(not 0.0 <= t <= 180.0 for t in tilts):
        msg = f"--tilt-required-deg: expected 0 to 180 degrees, got {tilts}"
        raise CliError(msg)
    torsion = None
    if options.torsion_required_deg is not None:
        torsion = [
            float(v)
            for v in finite(options.torsion_required_deg, "--torsion-required-deg", "degrees")
        ]
        if not torsion[0] <= 0.0 <= torsion[1]:
            msg = f"--torsion-required-deg: expected LO <= 0 <= HI, got {torsion}"
            raise CliError(msg)
    if options.workers is not None and options.workers < 0:
        msg = f"--workers: expected 0 or more, got {options.workers}"
        raise CliError(msg)
    if options.workers is not None and options.scheduler:
        msg = "--workers sizes the local cluster: not with --scheduler"
        raise CliError(msg)
    grid = _grid(options)
    tolerance = ATLAS_TOLERANCE if options.tol_deg is None else tolerance_flag(options.tol_deg)
    try:
        atlas_options = AtlasOptions(
            n_phi=options.n_phi, tolerance=tolerance, volume=options.volume
        )
    except InputError as error:
        raise CliError(str(error)) from error
    manipulator = configured_manipulator(options.config, None, err)
    _check_cap(grid, manipulator, atlas_options, options.force)
    from ..atlas import workspace_atlas

    bar = ProgressBar("atlas")
    run = workspace_atlas(
        manipulator,
        grid,
        store=Path(options.out),
        options=atlas_options,
        scheduler=options.scheduler,
        workers=options.workers,
        resume=options.resume,
        chunk=None if options.chunk is None else tuple(options.chunk),
        progress=lambda done, total: bar(done / total),
    )
    document = atlas_summary(run.dataset, grid, tilts, torsion)
    document.update(
        {
            "store": str(run.store),
            "elapsed_s": run.elapsed,
            "workers": run.workers,
            "chunks_computed": run.chunks_computed,
            "chunks_total": run.chunks_total,
        }
    )
    plots = []
    if options.plot:
        from .atlas_plots import plot_atlas

        plots = [str(p) for p in plot_atlas(run.dataset, grid, tilts, Path(options.plot))]
        document["plots"] = plots
    if options.json:
        out.write(json.dumps(document) + "\n")
    else:
        _summary_text(document, out)
    return 0


def _summary_text(document: dict[str, Any], out: IO[str]) -> None:
    stats = document["tilt_capability_deg"]
    out.write(
        f"atlas: {document['positions']} positions, {document['reachable_positions']} with the "
        f"reference orientation reachable\n"
        f"  store: {document['store']} ({document['chunks_computed']} of "
        f"{document['chunks_total']} chunks computed now, {document['workers']} workers, "
        f"{document['elapsed_s']:.1f} s)\n"
    )
    if stats["min"] is not None:
        out.write(
            f"  tilt capability: {stats['min']:.2f} .. {stats['max']:.2f} deg "
            f"(mean {stats['mean']:.2f})\n"
        )
    for tilt, volume in document["dexterous_volume_m3"].items():
        out.write(f"  dexterous volume, tilt >= {tilt} deg: {volume:.6g} m^3\n")
    for path in document.get("plots", []):
        out.write(f"  plot: {path}\n")
