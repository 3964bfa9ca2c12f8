#!/usr/bin/env python3
"""Workspace atlas: positions per second in one process and on a local Dask cluster, warm
start against cold, and the paper estimate for a 100 × 100 × 50 grid.

Measured in one run on the packaged example, CLI defaults per position (72 azimuths,
tolerance 1e-4 rad):

* **scaling**: the same box computed in this process (``workers=0``, no Dask) and on a local
  cluster with one single-threaded worker process per core (bound to 127.0.0.1, no dashboard);
  the cluster's start-up is timed apart. Ratio = cluster rate / one-process rate. Other jobs on
  a shared machine cap that ratio, so the CPU seconds per position are measured too (this
  process, and every worker through ``Client.run``): their ratio gives the scaling on idle
  cores.
* **warm start**: along a line of neighbouring positions, the ``exact`` tilt capability
  computed cold (the ψ grid of :func:`projected_workspace`) against a warm start that searches
  ψ only around the neighbour's best torsion per azimuth. Reports the speed ratio and how far
  the warm answer strays from the cold one.
* **paper estimate**: hours for 100 × 100 × 50 = 500,000 positions on 1, 8 and 64 idle
  machines with as many cores as this one, from the measured CPU seconds per position and the
  workers' measured CPU efficiency.

Usage: python benchmarks/atlas.py [--step S] [--workers N]
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time
from pathlib import Path

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(variable, "1")

import numpy as np  # noqa: E402

from hexapod_workspace import (  # noqa: E402
    AtlasGrid,
    AtlasOptions,
    Manipulator,
    projected_workspace,
    workspace_atlas,
)
from hexapod_workspace._resources import example_config_path  # noqa: E402
from hexapod_workspace.core.evaluation.loading import load_manipulator  # noqa: E402
from hexapod_workspace.core.workspaces.projected import (  # noqa: E402
    COARSE_TOLERANCE,
    EXACT_GOLDEN_STEPS,
    EXACT_PSI_SAMPLES,
    reference_torsion_interval,
)
from hexapod_workspace.core.workspaces.search import RaySearch  # noqa: E402

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def warm_exact(
    manipulator: Manipulator,
    position: np.ndarray,
    n_phi: int,
    tolerance: float,
    psi_seed: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """``exact`` boundary per azimuth with ψ searched only within one cold grid spacing of the
    neighbour's best ψ (golden section, same step count), plus the ψ = 0 ray; (θ, ψ)."""
    search = RaySearch(manipulator, position)
    low_limit, high_limit = reference_torsion_interval(search, tolerance)
    phi = 2.0 * math.pi * np.arange(n_phi) / n_phi
    coarse = max(tolerance, COARSE_TOLERANCE)

    tilt = np.array([0.0, 1.0, 0.0])  # rays in θ at fixed (φ, ψ)

    def boundary(psi: np.ndarray, tol: float) -> np.ndarray:
        origins = np.column_stack([phi, np.zeros(n_phi), psi])
        return search.rays("tt", origins, tilt, math.pi, tol).feasible

    theta = boundary(np.zeros(n_phi), tolerance)
    best_psi = np.zeros(n_phi)
    spacing = (high_limit - low_limit) / (EXACT_PSI_SAMPLES - 1)
    low = np.clip(psi_seed - spacing, low_limit, high_limit)
    high = np.clip(psi_seed + spacing, low_limit, high_limit)
    left, right = high - GOLDEN * (high - low), low + GOLDEN * (high - low)
    theta_left, theta_right = boundary(left, coarse), boundary(right, coarse)
    best_coarse = np.full(n_phi, -np.inf)
    for _ in range(EXACT_GOLDEN_STEPS):
        for candidate, value in ((left, theta_left), (right, theta_right)):
            better = value > best_coarse
            best_coarse = np.where(better, value, best_coarse)
            best_psi = np.where(better, candidate, best_psi)
        go_right = theta_left < theta_right
        low = np.where(go_right, left, low)
        high = np.where(go_right, high, right)
        new_left = np.where(go_right, right, high - GOLDEN * (high - low))
        new_right = np.where(go_right, low + GOLDEN * (high - low), left)
        kept = np.where(go_right, theta_right, theta_left)
        fresh = boundary(np.where(go_right, new_right, new_left), coarse)
        theta_left = np.where(go_right, kept, fresh)
        theta_right = np.where(go_right, fresh, kept)
        left, right = new_left, new_right
    refined = boundary(best_psi, tolerance)
    better = refined > theta
    return np.where(better, refined, theta), np.where(better, best_psi, 0.0)


def _worker_cpu() -> float:
    """CPU seconds (user + system) of this process (run on each worker)."""
    import psutil

    times = psutil.Process().cpu_times()
    return times.user + times.system


def scaling(manipulator: Manipulator, grid: AtlasGrid, options: AtlasOptions, workers: int):
    """Both runs, the cluster start-up, whether the stores are equal, and CPU seconds per
    position in one process and on the workers (load-independent: what the ratio would be on
    an idle machine follows from it)."""
    from distributed import Client, LocalCluster

    with tempfile.TemporaryDirectory() as folder:
        cpu = time.process_time()
        single = workspace_atlas(
            manipulator, grid, store=Path(folder) / "one.zarr", options=options, workers=0
        )
        cpu_one = (time.process_time() - cpu) / grid.size
        started = time.perf_counter()
        with LocalCluster(
            host="127.0.0.1",
            processes=True,
            n_workers=workers,
            threads_per_worker=1,
            dashboard_address=None,
        ) as cluster:
            startup = time.perf_counter() - started
            with Client(cluster) as observer:
                before = observer.run(_worker_cpu)
                spread = workspace_atlas(
                    manipulator,
                    grid,
                    store=Path(folder) / "cluster.zarr",
                    options=options,
                    scheduler=cluster.scheduler_address,
                )
                after = observer.run(_worker_cpu)
        cpu_workers = sum(after[k] - before[k] for k in after) / grid.size
        same = single.dataset.drop_vars("chunk_done").equals(spread.dataset.drop_vars("chunk_done"))
    return single, spread, startup, same, cpu_one, cpu_workers


def warm_against_cold(manipulator: Manipulator, options: AtlasOptions, count: int):
    """Along x at y = 0.1, z = -1.2 m: cold exact vs warm from the previous position."""
    positions = np.column_stack(
        [np.linspace(-0.3, 0.3, count), np.full(count, 0.1), np.full(count, -1.2)]
    )
    cold_time = warm_time = 0.0
    cold_caps, warm_caps = [], []
    seed = None
    for position in positions:
        started = time.perf_counter()
        cold = projected_workspace(
            manipulator, position, method="exact", n_phi=options.n_phi, tolerance=options.tolerance
        )
        cold_time += time.perf_counter() - started
        cold_caps.append(cold.tilt_min)
        if seed is None:  # the first position has no neighbour: both are cold
            warm_caps.append(cold.tilt_min)
            seed = cold.psi
            warm_time += cold.elapsed
            continue
        started = time.perf_counter()
        theta, seed = warm_exact(manipulator, position, options.n_phi, options.tolerance, seed)
        warm_time += time.perf_counter() - started
        warm_caps.append(float(theta.min()))
    return cold_time, warm_time, np.array(cold_caps), np.array(warm_caps)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--step",
        type=float,
        default=0.05,
        help="grid step, m (fine enough that start-up costs do not hide the scaling)",
    )
    parser.add_argument("--workers", type=int, default=len(os.sched_getaffinity(0)))
    parser.add_argument("--line", type=int, default=13, help="positions of the warm-start line")
    options_cli = parser.parse_args()
    manipulator = load_manipulator(example_config_path())
    options = AtlasOptions()
    grid = AtlasGrid.box([-0.2, 0.2, -0.2, 0.2, -1.3, -1.1], options_cli.step)
    print(
        f"atlas benchmark, packaged example, {grid.size} positions "
        f"({' x '.join(map(str, grid.shape))}, step {options_cli.step:g} m, "
        f"x, y in [-0.2, 0.2], z in [-1.3, -1.1] m), n_phi {options.n_phi}, "
        f"tolerance {options.tolerance:g} rad"
    )
    load = os.getloadavg()[0]
    print(
        f"  load average at start: {load:.2f} on {os.cpu_count()} cores "
        "(other work on the machine caps the scaling ratio)"
    )
    single, spread, startup, same, cpu_one, cpu_workers = scaling(
        manipulator, grid, options, options_cli.workers
    )
    rate_one = grid.size / single.elapsed
    rate_cluster = grid.size / spread.elapsed
    print(f"  one process (no Dask):      {rate_one:7.2f} positions/s ({single.elapsed:.1f} s)")
    print(
        f"  local cluster, {spread.workers} workers:   {rate_cluster:7.2f} positions/s "
        f"({spread.elapsed:.1f} s; cluster start-up {startup:.1f} s apart)"
    )
    print(
        f"  scaling ratio cluster / one process: {rate_cluster / rate_one:.2f} "
        f"(ideal {spread.workers}); stores equal: {same}"
    )
    print(
        f"  CPU per position: one process {cpu_one * 1e3:.0f} ms, on the workers "
        f"{cpu_workers * 1e3:.0f} ms: on idle cores the ratio would be about "
        f"{spread.workers * cpu_one / cpu_workers:.2f}"
    )

    cold_time, warm_time, cold, warm = warm_against_cold(manipulator, options, options_cli.line)
    stray = np.degrees(np.abs(warm - cold))
    print(
        f"  warm start ({options_cli.line} neighbours along x): cold {cold_time:.2f} s, "
        f"warm {warm_time:.2f} s, ratio cold / warm {cold_time / warm_time:.2f}; "
        f"tilt capability differs by up to {stray.max():.4f} deg "
        f"(warm lower at {int((warm < cold - 1e-9).sum())} of {cold.size} positions)"
    )

    wall = 1.0 / rate_one  # s per position on one (shared) core
    saved = (cold_time - warm_time) / cold.size  # s per position saved by the warm start
    print(
        f"  warm start per whole position (exact + torsion range + check, {wall:.3f} s cold): "
        f"{wall / max(wall - saved, 1e-9):.2f}x"
    )
    # On paper: CPU seconds per position (independent of other load on this machine) and the
    # CPU efficiency of the workers (scheduling and transfer overhead), on idle cores.
    cost = cpu_one
    efficiency = cpu_one / cpu_workers
    cores = options_cli.workers
    positions = 100 * 100 * 50
    print(
        f"  paper estimate, 100 x 100 x 50 = {positions} positions at {cost:.3f} CPU-s each "
        f"(every position costed as reachable: an upper bound), idle machines of {cores} cores, "
        f"worker CPU efficiency {efficiency:.2f}:"
    )
    for machines in (1, 8, 64):
        hours = positions * cost / (machines * cores * efficiency) / 3600.0
        print(f"    {machines:3d} machine(s): {hours:8.2f} h")


if __name__ == "__main__":
    main()
