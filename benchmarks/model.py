#!/usr/bin/env python3
"""The open model (constraint table, singularity margin) against the code before it, ratios
measured in the same run.

The baseline is the package as of commit 3c6da1e (four constraints wired by hand, one leg
architecture; ``--baseline REV`` for another revision), extracted with ``git archive`` and
imported as ``hexapod_workspace_baseline`` (:func:`speed.load_baseline`), so both run here, on
the same machine, in the same minute. Both are measured in ``--rounds`` rounds, in alternating
order (new first in even rounds, the baseline first in odd ones), on one core, by this
process's CPU time (``--clock wall`` for wall time): on a shared machine, wall time also counts
the time other jobs hold the core, which differs from one run to the next. Printed: per-pose
time of a batch check, one-pose check, the exact projected workspace, the orientation workspace
and a toolpath check, for the packaged 6-UPS example, the best of each version; the ratio is
baseline time / new time (≥ 1: not slower; the goal is ≥ 0.9), of the bests and, per round,
its range and median. Then the leg architectures: the same figures for the packaged 6-PUS and
6-RUS examples against the 6-UPS one (new code, same run; ratio pus or rus time / ups time).
Then the cost of an enforced singularity margin (new code, limit 0.3 against 0): enforced time
/ free time.

Usage: python benchmarks/model.py [--poses N] [--rounds R] [--baseline REV] [--clock cpu|wall]
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from speed import best_of, load_baseline, machine_from, per_call, random_poses

import hexapod_workspace as new
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core import kernels
from hexapod_workspace.core.evaluation.check import check_pose

MODEL_BASELINE = "3c6da1e"
POSITION = np.array([0.0, 0.0, -1.3])


#: The goal of every ratio baseline time / new time of the 6-UPS figures.
GOAL = 0.95


def figures(
    package, check_one, poses: np.ndarray, clock: Callable[[], float] = time.perf_counter
) -> dict[str, float]:
    """Seconds of each figure for one version of the package, by ``clock``."""
    # The packaged example, given as parameters the baseline knows (it predates
    # limits.singularity_min, 0 here).
    parameters = new.load_manipulator(example_config_path()).to_parameters()
    parameters.pop("limits.singularity_min")
    # The leg-architecture keys are newer; the model moved to core.model with the layers.
    layout = getattr(package.core, "model", None)
    known = (layout.manipulator if layout else package.core.manipulator).PARAMETER_DEFAULTS
    parameters = {name: value for name, value in parameters.items() if name in known}
    machine = machine_from(package, parameters)
    rng = np.random.default_rng(3)
    waypoints = POSITION + rng.normal(scale=0.05, size=(200, 3))
    angles = random_poses(200, seed=4) * np.array([1.0, 0.5, 0.5])
    best = functools.partial(best_of, clock=clock)
    return {
        "check, per pose": best(7, lambda: package.check(machine, poses, POSITION))
        / poses.shape[0],
        "check_pose, per call": per_call(
            lambda: check_one(machine, 0.3, 0.2, 0.1, POSITION), clock=clock
        ),
        "projected exact (360 rays)": best(
            5, lambda: package.projected_workspace(machine, POSITION, method="exact")
        ),
        "orientation (180 rays, 1 deg)": best(
            3, lambda: package.orientation_workspace(machine, POSITION)
        ),
        "check_path (199 moves)": best(
            5, lambda: package.check_path(machine, waypoints, angles=angles)
        ),
    }


def singularity_figures(
    poses: np.ndarray, clock: Callable[[], float] = time.perf_counter
) -> list[tuple[str, float, float]]:
    """(figure, seconds without, seconds with the singularity margin enforced), new code."""
    free = new.load_manipulator(example_config_path())
    enforced = new.manipulator_from_mapping(
        {**free.to_parameters(), "limits.singularity_min": 0.3}, warn=False
    )
    rows = []
    for name, run in (
        ("check, per pose", lambda m: new.check(m, poses, POSITION)),
        (
            "projected exact (360 rays)",
            lambda m: new.projected_workspace(m, POSITION, method="exact"),
        ),
    ):
        without = min(best_of(5, functools.partial(run, free), clock=clock) for _ in range(2))
        with_it = min(best_of(5, functools.partial(run, enforced), clock=clock) for _ in range(2))
        scale = poses.shape[0] if name.endswith("per pose") else 1
        rows.append((name, without / scale, with_it / scale))
    one = [
        per_call(lambda m=m: check_pose(m, 0.3, 0.2, 0.1, POSITION), clock=clock)
        for m in (free, enforced)
    ]
    rows.insert(1, ("check_pose, per call", *one))
    return rows


def architecture_figures(
    poses: np.ndarray, clock: Callable[[], float] = time.perf_counter
) -> list[tuple[str, float, float, float]]:
    """(figure, ups, pus, rus seconds), new code, each packaged example at its home position
    (the same random orientations; a different share of them is reachable on each machine)."""
    config = example_config_path().parent
    machines = [
        new.load_manipulator(config / name)
        for name in ("example_gpm.yaml", "example_pus.yaml", "example_rus.yaml")
    ]
    rows = []
    for name, run, scale in (
        ("check, per pose", lambda m: new.check(m, poses, m.position), poses.shape[0]),
        (
            "check_pose, per call",
            lambda m: check_pose(m, 0.3, 0.2, 0.1, m.position),
            1,
        ),
        (
            "projected exact (360 rays)",
            lambda m: new.projected_workspace(m, m.position, method="exact"),
            1,
        ),
    ):
        if name.startswith("check_pose"):
            times = [per_call(functools.partial(run, m), clock=clock) for m in machines]
        else:
            times = [
                min(best_of(5, functools.partial(run, m), clock=clock) for _ in range(2)) / scale
                for m in machines
            ]
        rows.append((name, *times))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=200_000)
    parser.add_argument("--rounds", type=int, default=6, help="alternated rounds (default 6)")
    parser.add_argument(
        "--baseline",
        default=MODEL_BASELINE,
        metavar="REV",
        help=f"the revision compared with (default {MODEL_BASELINE}, before the open model)",
    )
    parser.add_argument(
        "--clock",
        choices=("cpu", "wall"),
        default="cpu",
        help="this process's CPU time (default) or wall time",
    )
    parser.add_argument(
        "--keep",
        metavar="DIR",
        help="extract the baseline into DIR/REV and keep it there with its compiled kernels, so "
        "a later run with the same DIR does not compile it again (default: a temporary directory)",
    )
    options = parser.parse_args()
    if options.rounds < 1 or options.poses < 1:
        parser.error(f"--rounds and --poses: expected ≥ 1, got {options.rounds}, {options.poses}")
    clock = time.process_time if options.clock == "cpu" else time.perf_counter
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})  # one core
    loads = [os.getloadavg()[0]]
    with contextlib.ExitStack() as stack:
        if options.keep:
            directory = Path(options.keep) / options.baseline
            directory.mkdir(parents=True, exist_ok=True)
        else:
            directory = Path(stack.enter_context(tempfile.TemporaryDirectory()))
        old = load_baseline(directory, options.baseline)
        if old is None:
            sys.exit(f"cannot extract the baseline {options.baseline} (git archive)")
        from hexapod_workspace_baseline.core import kernels as old_kernels
        from hexapod_workspace_baseline.core.constraints import check_pose as old_check_pose

        kernels.warm_up()
        old_kernels.warm_up()
        poses = random_poses(options.poses)
        # Alternated: new then baseline in even rounds, baseline then new in odd ones (neither
        # always runs right after the other's caches and the machine's other jobs).
        versions = {"new": (new, check_pose), "baseline": (old, old_check_pose)}
        runs: dict[str, list[dict[str, float]]] = {"new": [], "baseline": []}
        for k in range(options.rounds):
            for name in ("new", "baseline") if k % 2 == 0 else ("baseline", "new"):
                package, check_one = versions[name]
                runs[name].append(figures(package, check_one, poses, clock))
            loads.append(os.getloadavg()[0])
    print(
        f"6-UPS example against {options.baseline}: load average {min(loads):.2f}-"
        f"{max(loads):.2f}, one core, {options.clock} time, {options.rounds} alternated "
        f"rounds, {options.poses} poses per batch"
    )
    print(
        f"  {'figure':<32} {'new':>12} {'baseline':>12} {'ratio':>7}  {'rounds':>11} "
        f"{'median':>6}  goal ≥ {GOAL}"
    )
    for name in runs["new"][0]:
        now = min(run[name] for run in runs["new"])
        before = min(run[name] for run in runs["baseline"])
        per_round = [b[name] / n[name] for n, b in zip(runs["new"], runs["baseline"], strict=True)]
        unit, scale = ("µs", 1e6) if now < 1e-3 else ("ms", 1e3)
        print(
            f"  {name:<32} {now * scale:>9.3f} {unit} {before * scale:>9.3f} {unit}"
            f" {before / now:>7.3f}  {min(per_round):.3f}-{max(per_round):.3f}"
            f" {float(np.median(per_round)):>6.3f}  {'met' if before / now >= GOAL else 'MISSED'}"
        )
    print("leg architectures, new code, each example at its home position (ratio to ups):")
    print(f"  {'figure':<32} {'ups':>12} {'pus':>12} {'rus':>12} {'pus/ups':>8} {'rus/ups':>8}")
    for name, ups, pus, rus in architecture_figures(poses, clock):
        unit, scale = ("µs", 1e6) if ups < 1e-3 else ("ms", 1e3)
        print(
            f"  {name:<32} {ups * scale:>9.3f} {unit} {pus * scale:>9.3f} {unit}"
            f" {rus * scale:>9.3f} {unit} {pus / ups:>8.2f} {rus / ups:>8.2f}"
        )
    print("singularity margin enforced (limit 0.3) against free (limit 0), new code:")
    print(f"  {'figure':<32} {'free':>12} {'enforced':>12} {'ratio':>7}")
    for name, without, with_it in singularity_figures(poses, clock):
        unit, scale = ("µs", 1e6) if without < 1e-3 else ("ms", 1e3)
        print(
            f"  {name:<32} {without * scale:>9.3f} {unit} {with_it * scale:>9.3f} {unit}"
            f" {with_it / without:>7.2f}"
        )


if __name__ == "__main__":
    main()
