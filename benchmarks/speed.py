#!/usr/bin/env python3
"""Every speed figure of the compiled kernels against its goal, with same-run ratios.

The baseline is the numpy implementation of commit 0b9ef59 (before the compiled kernels),
extracted with ``git archive`` into a temporary directory and imported under another name, so
both run here, on the same machine, in the same minute. The literal procedure is the paper's
projected-workspace walk of ``test/reference.py`` (per-pose checks, 0.1° steps, m = 5).

One-core figures pin this process to one CPU (threads cannot help there); "both cores" lets
:func:`hexapod_workspace.check` split the batch over the CPUs it may use. Times are the best of
several runs (the machine is shared: the best run is the one least disturbed); the load
average is printed with the results.

Usage: python benchmarks/speed.py [--poses N] [--skip-cold]
"""

from __future__ import annotations

import argparse
import importlib
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
import timeit
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BASELINE_COMMIT = "0b9ef59"
# The literal reference is a test oracle (test/reference.py), not part of the package.
sys.path.insert(0, str(ROOT / "test"))

from reference import paper_projected_workspace  # noqa: E402

import hexapod_workspace as new  # noqa: E402
from hexapod_workspace._resources import example_config_path  # noqa: E402
from hexapod_workspace.core import kernels  # noqa: E402
from hexapod_workspace.core.evaluation.check import check_pose  # noqa: E402

POSITION = np.array([0.0, 0.0, -1.3])


def load_baseline(directory: Path, commit: str = BASELINE_COMMIT):
    """The package as of ``commit``, imported as ``hexapod_workspace_baseline`` (or None).

    A ``directory`` that already holds it (kept from an earlier run, with its compiled cache)
    is imported as it is."""
    if (directory / "hexapod_workspace_baseline").is_dir():
        sys.path.insert(0, str(directory))
        return importlib.import_module("hexapod_workspace_baseline")
    try:
        archive = subprocess.run(
            ["git", "-C", str(ROOT), "archive", commit, "hexapod_workspace"],
            capture_output=True,
            check=True,
        ).stdout
        subprocess.run(["tar", "-x", "-C", str(directory)], input=archive, check=True)
    except (OSError, subprocess.CalledProcessError):
        return None
    (directory / "hexapod_workspace").rename(directory / "hexapod_workspace_baseline")
    sys.path.insert(0, str(directory))
    return importlib.import_module("hexapod_workspace_baseline")


def machine_from(package, parameters: dict | None = None, path: Path | None = None):
    """A manipulator built by ``package``, this one or a baseline that predates
    ``core.loading`` (where the loaders were ``Manipulator.from_mapping`` and
    ``Manipulator.from_params_file``): from ``parameters``, or else from the file ``path``."""
    if hasattr(package, "manipulator_from_mapping"):
        if parameters is not None:
            return package.manipulator_from_mapping(parameters)
        return package.load_manipulator(path)
    if parameters is not None:
        return package.Manipulator.from_mapping(parameters)
    return package.Manipulator.from_params_file(path)


def best_of(
    repeats: int,
    function: Callable[[], object],
    budget: float = 20.0,
    clock: Callable[[], float] = time.perf_counter,
) -> float:
    """Best time of up to ``repeats`` runs (stops early after ``budget`` seconds of wall time),
    by ``clock`` (wall time; ``time.process_time`` for this process's CPU time, which leaves
    out the time other jobs of a shared machine hold the core)."""
    best = math.inf
    started = time.perf_counter()
    for _ in range(repeats):
        begin = clock()
        function()
        best = min(best, clock() - begin)
        if time.perf_counter() - started > budget:
            break
    return best


def cpu_seconds(function: Callable[[], object], repeats: int = 3) -> tuple[float, float]:
    """Wall and process CPU seconds of one run (the smallest CPU time of ``repeats`` runs)."""
    best = (math.inf, math.inf)
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        function()
        run = (time.perf_counter() - wall, time.process_time() - cpu)
        best = min(best, run, key=lambda pair: pair[1])
    return best


def per_call(
    statement: Callable[[], object],
    number: int = 2000,
    clock: Callable[[], float] = time.perf_counter,
) -> float:
    """Best time per call over 5 batches of ``number`` calls, s, by ``clock`` (as
    :func:`best_of`)."""
    return min(timeit.repeat(statement, number=number, repeat=5, timer=clock)) / number


def random_poses(count: int, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.column_stack(
        [
            rng.uniform(-np.pi, np.pi, count),
            rng.uniform(0.0, np.radians(45.0), count),
            rng.uniform(-np.radians(60.0), np.radians(60.0), count),
        ]
    )


class Table:
    """Rows of: figure, goal, new, baseline, ratio, met."""

    def __init__(self) -> None:
        self.rows: list[tuple[str, ...]] = []

    def add(
        self, figure: str, goal: str, new_text: str, old_text: str, ratio: str, met: bool | None
    ) -> None:
        status = "" if met is None else ("met" if met else "NOT met")
        self.rows.append((figure, goal, new_text, old_text, ratio, status))
        print(f"  {figure:<44} {goal:<16} {new_text:>12} {old_text:>12} {ratio:>9}  {status}")


def ms(seconds: float) -> str:
    return f"{seconds * 1e3:.2f} ms" if seconds < 0.1 else f"{seconds * 1e3:.0f} ms"


def run_cli(environment: dict, *arguments: str) -> tuple[float, subprocess.CompletedProcess]:
    """Wall time of one CLI process (the console script of this environment)."""
    cli = shutil.which("hexapod-workspace", path=str(Path(sys.executable).parent))
    command = [cli] if cli else [sys.executable, "-m", "hexapod_workspace"]
    started = time.perf_counter()
    done = subprocess.run(
        [*command, *arguments], env=environment, capture_output=True, text=True, timeout=600
    )
    return time.perf_counter() - started, done


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=1_000_000)
    parser.add_argument("--skip-cold", action="store_true", help="skip the first-run compile")
    options = parser.parse_args()
    cpus = sorted(os.sched_getaffinity(0))
    kernels.warm_up()
    manipulator = new.load_manipulator(example_config_path())
    table = Table()
    with tempfile.TemporaryDirectory() as scratch:
        baseline = load_baseline(Path(scratch))
        old = machine_from(baseline, path=example_config_path()) if baseline else None
        print(
            f"speed, packaged example at ({', '.join(f'{v:g}' for v in POSITION)}) m, all four "
            f"constraints; baseline: {'commit ' + BASELINE_COMMIT if baseline else 'unavailable'}"
            f"; {len(cpus)} CPUs, load average {os.getloadavg()[0]:.1f} at start"
        )
        print(f"  {'figure':<44} {'goal':<16} {'new':>12} {'baseline':>12} {'ratio':>9}  status")

        # -- check throughput, one core, then both.
        poses = random_poses(options.poses)
        os.sched_setaffinity(0, {cpus[0]})
        t_one = best_of(5, lambda: new.check(manipulator, poses))
        t_old = best_of(2, lambda: baseline.check(old, poses)) if baseline else math.nan
        cpu_one = cpu_seconds(lambda: new.check(manipulator, poses))
        os.sched_setaffinity(0, set(cpus))
        t_both = best_of(5, lambda: new.check(manipulator, poses))
        cpu_both = cpu_seconds(lambda: new.check(manipulator, poses))
        rate, rate_old, rate_both = (options.poses / t for t in (t_one, t_old, t_both))
        table.add(
            "check, one core, all four constraints",
            ">= 6 M poses/s",
            f"{rate / 1e6:.2f} M/s",
            f"{rate_old / 1e6:.2f} M/s",
            f"{rate / rate_old:.1f}x",
            rate >= 6e6,
        )
        table.add(
            f"check, both cores ({len(cpus)} CPUs)",
            ">= 1.8x one core",
            f"{rate_both / 1e6:.2f} M/s",
            "",
            f"{rate_both / rate:.2f}x",
            rate_both >= 1.8 * rate,
        )
        # What the CPUs did: with both cores free the process uses ~2 CPU-seconds per second;
        # poses per CPU-second show whether threads cost efficiency (they should not).
        table.add(
            "  both cores: CPU-s per s; M poses per CPU-s",
            "",
            f"{cpu_both[1] / cpu_both[0]:.2f}",
            "",
            f"{options.poses / cpu_both[1] / 1e6:.1f} vs {options.poses / cpu_one[1] / 1e6:.1f}",
            None,
        )

        # -- one pose in-process.
        os.sched_setaffinity(0, {cpus[0]})
        t_pose = per_call(lambda: check_pose(manipulator, 0.3, 0.2, 0.1), 20_000)
        t_check1 = per_call(lambda: new.check(manipulator, (0.3, 0.2, 0.1)), 5000)
        t_check1_old = (
            per_call(lambda: baseline.check(old, (0.3, 0.2, 0.1)), 2000) if baseline else math.nan
        )
        table.add(
            "one pose, in-process (check_pose)",
            "<= 5 us",
            f"{t_pose * 1e6:.2f} us",
            f"{t_check1_old * 1e6:.1f} us",
            f"{t_check1_old / t_pose:.0f}x",
            t_pose <= 5e-6,
        )
        table.add(
            "one pose through check() (arrays out)",
            "",
            f"{t_check1 * 1e6:.2f} us",
            f"{t_check1_old * 1e6:.1f} us",
            f"{t_check1_old / t_check1:.0f}x",
            None,
        )

        # -- workspaces (one core).
        def projected(module, model, **kw):
            return module.projected_workspace(model, POSITION, tolerance=1e-6, **kw)

        for n_phi in (360, 90):
            t_zero = best_of(30, lambda n=n_phi: projected(new, manipulator, n_phi=n))
            t_zero_old = (
                best_of(5, lambda n=n_phi: projected(baseline, old, n_phi=n))
                if baseline
                else math.nan
            )
            t_paper = best_of(
                1, lambda n=n_phi: paper_projected_workspace(manipulator, POSITION, n)
            )
            ratio = t_paper / t_zero
            table.add(
                f"torsion_zero, {n_phi} rays, tol 1e-6 rad",
                "<= 1 ms" if n_phi == 360 else "",
                ms(t_zero),
                ms(t_zero_old),
                f"{t_zero_old / t_zero:.0f}x",
                t_zero <= 1e-3 if n_phi == 360 else None,
            )
            table.add(
                f"  literal procedure / torsion_zero, {n_phi} rays",
                ">= 300x",
                f"{ratio:.0f}x",
                f"{t_paper / t_zero_old:.0f}x",
                f"({ms(t_paper)})",
                ratio >= 300,
            )
        t_exact = best_of(10, lambda: projected(new, manipulator, method="exact", n_phi=360))
        t_exact_old = (
            best_of(2, lambda: projected(baseline, old, method="exact", n_phi=360))
            if baseline
            else math.nan
        )
        table.add(
            "exact, 360 rays, tol 1e-6 rad",
            "<= 30 ms",
            ms(t_exact),
            ms(t_exact_old),
            f"{t_exact_old / t_exact:.0f}x",
            t_exact <= 0.030,
        )

        def solid(module, model):
            return module.orientation_workspace(
                model, POSITION, n_rays=180, psi_step=math.radians(1.0), tolerance=1e-5
            )

        t_solid = best_of(10, lambda: solid(new, manipulator))
        t_solid_old = best_of(2, lambda: solid(baseline, old)) if baseline else math.nan
        table.add(
            "3-D, 180 rays x 1 deg, tol 1e-5 rad",
            "<= 100 ms",
            ms(t_solid),
            ms(t_solid_old),
            f"{t_solid_old / t_solid:.0f}x",
            t_solid <= 0.100,
        )

        def torsion(module, model):
            return module.torsion_range(model, 0.5, math.radians(20.0), POSITION)

        t_torsion = best_of(200, lambda: torsion(new, manipulator), budget=5.0)
        t_torsion_old = best_of(5, lambda: torsion(baseline, old)) if baseline else math.nan
        table.add(
            "torsion range, one direction, tol 1e-6",
            "<= 0.5 ms",
            ms(t_torsion),
            ms(t_torsion_old),
            f"{t_torsion_old / t_torsion:.0f}x",
            t_torsion <= 0.5e-3,
        )
        os.sched_setaffinity(0, set(cpus))

        # -- processes: CLI with a warm cache, first run after install, node warm-up.
        environment = dict(os.environ)
        run_cli(environment, "check", "--pose", "0", "10", "0")  # make sure the cache is warm
        walls = [run_cli(environment, "check", "--pose", "0", "10", "0")[0] for _ in range(5)]
        table.add(
            "CLI check of one pose, warm cache (wall)",
            "<= 0.5 s",
            f"{min(walls):.2f} s",
            "",
            f"med {np.median(walls):.2f}",
            min(walls) <= 0.5,
        )
        if not options.skip_cold:
            cold = {**environment, "NUMBA_CACHE_DIR": str(Path(scratch) / "cold")}
            wall, done = run_cli(cold, "check", "--pose", "0", "10", "0")
            notice = [line for line in done.stderr.splitlines() if "compiling" in line]
            table.add(
                "CLI first run after install (compiles)",
                "<= 20 s, 1 line",
                f"{wall:.1f} s",
                "",
                f"{len(notice)} line",
                wall <= 20.0 and len(notice) == 1 and done.returncode == 0,
            )
            code = "from hexapod_workspace.core import kernels; print(kernels.warm_up())"
            cold_all = {**environment, "NUMBA_CACHE_DIR": str(Path(scratch) / "cold_all")}
            seconds = []
            for env in (cold_all, cold_all):
                done = subprocess.run(
                    [sys.executable, "-c", code], env=env, capture_output=True, text=True
                )
                seconds.append(float(done.stdout.split()[-1]))
            table.add(
                "node warm_up(): every kernel, cold cache",
                "",
                f"{seconds[0]:.1f} s",
                "",
                "",
                None,
            )
            table.add("node warm_up(): warm cache", "", f"{seconds[1]:.2f} s", "", "", None)
    print(f"load average at the end: {os.getloadavg()[0]:.1f}")
    print(
        f"goals met: {sum(r[5] == 'met' for r in table.rows)} of "
        f"{sum(r[5] != '' for r in table.rows)}"
    )


if __name__ == "__main__":
    main()
