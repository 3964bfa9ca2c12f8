#!/usr/bin/env python3
"""Cold-start figures: what the first answer after install costs, in CPU seconds.

Every figure runs in a fresh process with an empty numba cache of its own (``NUMBA_CACHE_DIR``
pointing to a new temporary directory), on this machine, and is read from the child's
resource usage (user + system CPU time, ``os.wait4``): CPU time does not depend on what else
the machine runs as much as wall time does. Wall time is printed beside it. The figures of the
landed ``main`` before the rebuild (dfebf16, measured the same way on this kind of machine and
quoted in its issue) stand beside each one, with the goal.

Then, in one process with a cold cache, the compile time of every entry point of every variant
of the model (``kernels.ALL_SWITCHES``), from numba's own per-signature timers: where the time
goes.

Usage: python benchmarks/compile.py [--skip-variants] [--skip-every]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: The console script of this interpreter's environment.
CLI = [str(Path(sys.executable).parent / "hexapod-workspace")]

#: (figure, goal in CPU s, dfebf16's CPU s or None). dfebf16: the issue's measurements.
GOALS = {
    "first check of one pose": (10.0, 297.0),
    "first projected --method exact": (15.0, None),
    "first check-path on a small CSV": (20.0, None),
    "warm_up of the packaged 6-UPS example": (60.0, None),
    "warm_up of every kernel, every variant": (60.0, 819.0),
    "warm check of one pose (import included)": (0.5, 1.8),
}


def run(command: list[str], environment: dict[str, str]) -> tuple[float, float, int, str]:
    """(CPU s, wall s, return code, stderr) of one child process."""
    started = time.perf_counter()
    process = subprocess.Popen(
        command,
        env=environment,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    assert process.stderr is not None
    stderr = process.stderr.read()
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - started
    return usage.ru_utime + usage.ru_stime, wall, process.returncode, stderr


def calibration() -> float:
    """CPU seconds of a fixed pure-Python loop (10⁷ additions), the best of three: this kind of
    machine is a virtual one whose speed varies by up to 2x from hour to hour, so every figure
    is printed beside it, to compare runs by."""
    best = float("inf")
    for _ in range(3):
        started = time.process_time()
        total = 0
        for value in range(10_000_000):
            total += value
        best = min(best, time.process_time() - started)
    return best


def python(code: str) -> list[str]:
    return [sys.executable, "-c", textwrap.dedent(code)]


def cold_figures(scratch: Path, every: bool = True) -> list[tuple[str, float, float, int, str]]:
    # As a user's install runs: Python's bytecode cached (pip compiles it at install time; a
    # development shell's PYTHONDONTWRITEBYTECODE=1 would add ~0.16 s of source compilation of
    # this package's modules to every warm figure).
    base = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}
    csv = scratch / "small.csv"
    csv.write_text(
        "x_m,y_m,z_m,phi_deg,theta_deg,psi_deg\n"
        "0,0,-1.3,0,0,0\n0.05,0,-1.25,0,10,0\n0.05,0.05,-1.25,45,20,5\n",
        encoding="utf-8",
    )
    cases = {
        "first check of one pose": [*CLI, "check", "--pose", "0", "30", "0"],
        "first projected --method exact": [*CLI, "projected", "--method", "exact"],
        "first check-path on a small CSV": [*CLI, "check-path", str(csv)],
        "warm_up of the packaged 6-UPS example": python(
            """
            from hexapod_workspace import example_manipulator
            from hexapod_workspace.core import kernels
            kernels.warm_up(kernels.model_vector(example_manipulator()))
            """
        ),
        "warm_up of every kernel, every variant": python(
            """
            from hexapod_workspace.core import kernels
            from hexapod_workspace.core.kernels import planner as planner_kernels
            kernels.warm_up()
            planner_kernels.warm_up()
            """
        ),
    }
    if not every:
        del cases["warm_up of every kernel, every variant"]
    rows = []
    for index, (name, command) in enumerate(cases.items()):
        cache = scratch / f"cache{index}"
        cpu, wall, code, stderr = run(command, {**base, "NUMBA_CACHE_DIR": str(cache)})
        notice = next((line for line in stderr.splitlines() if "compiling" in line), "")
        rows.append((name, cpu, wall, code, notice))
        if name == "first check of one pose":
            # The same command again: the cache is warm now.
            warm = []
            for _ in range(5):
                warm.append(run(command, {**base, "NUMBA_CACHE_DIR": str(cache)}))
            best = min(warm, key=lambda row: row[0])
            rows.append(
                ("warm check of one pose (import included)", best[0], best[1], best[2], best[3])
            )
        print(f"  {name}: {cpu:.1f} s CPU", file=sys.stderr, flush=True)
    return rows


VARIANT_CODE = """
import json, time
from hexapod_workspace.core import kernels
rows = []
for key in kernels.ALL_SWITCHES:
    started = time.process_time()
    kernels._run_variant(kernels._variant(key))
    total = time.process_time() - started
    entry = {}
    variant = kernels._variant(key)
    for name in kernels.ENTRY_POINTS:
        dispatcher = getattr(variant, name)
        signatures = dispatcher.signatures
        timers = dispatcher.get_metadata(signatures[0]).get("timers", {}) if signatures else {}
        entry[name] = [timers.get("compiler_lock", 0.0), timers.get("llvm_lock", 0.0),
                       len(signatures)]
    rows.append(("".join("1" if f is not None else "0" for f in key), total, entry))
print(json.dumps(rows))
"""


def variant_table(scratch: Path) -> None:
    import json

    environment = {**os.environ, "NUMBA_CACHE_DIR": str(scratch / "variants")}
    done = subprocess.run(
        python(VARIANT_CODE), env=environment, capture_output=True, text=True, cwd=ROOT
    )
    if done.returncode != 0:
        print(done.stderr[-2000:], file=sys.stderr)
        return
    rows = json.loads(done.stdout.splitlines()[-1])
    names = tuple(rows[0][2])  # the entry points, in the child's kernels.ENTRY_POINTS order
    print()
    print("Compile time of each entry point, per variant (one process, cold cache, CPU s;")
    print("numba's timers: the whole compilation, LLVM's part in brackets; a kernel's callees")
    print("compiled for an earlier entry point of the variant are not counted again)")
    print()
    print("| variant (moving, cranks, scene, singularity) | " + " | ".join(names) + " | all |")
    print("|---" * (len(names) + 2) + "|")
    labels = {"00": "6-UPS", "10": "6-PUS", "11": "6-RUS"}
    for key, total, entry in rows:
        label = f"{labels[key[:2]]}{', scene' if key[2] == '1' else ''}"
        label += ", singularity" if key[3] == "1" else ""
        cells = [f"{entry[n][0]:.1f} ({entry[n][1]:.1f})" for n in names]
        print(f"| {label} | " + " | ".join(cells) + f" | {total:.1f} |")
        if any(entry[n][2] != 1 for n in names):
            print(f"  (!) a kernel of {label} has {[entry[n][2] for n in names]} signatures")
    print(f"\nevery variant: {sum(row[1] for row in rows):.1f} s CPU")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-variants", action="store_true", help="no per-kernel table")
    parser.add_argument(
        "--skip-every",
        action="store_true",
        help="not the figure of every variant's warm-up (minutes)",
    )
    options = parser.parse_args()
    print(f"cold start, {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}")
    print(f"this machine's speed now: a 10^7-step Python loop in {calibration():.2f} s CPU")
    with tempfile.TemporaryDirectory(prefix="hexapod-compile-") as scratch:
        rows = cold_figures(Path(scratch), every=not options.skip_every)
        print()
        print("| figure | CPU s | wall s | goal (CPU s) | dfebf16 (CPU s) | met |")
        print("|---|---|---|---|---|---|")
        for name, cpu, wall, code, _ in rows:
            goal, before = GOALS[name]
            met = "yes" if cpu <= goal and code in (0, 1) else "NO"
            shown = f"{before:g}" if before is not None else "not measured"
            print(f"| {name} | {cpu:.2f} | {wall:.2f} | <= {goal:g} | {shown} | {met} |")
        notices = [row[4] for row in rows if row[4]]
        if notices:
            print(f"\nthe CLI's notice: {notices[0]}")
        if not options.skip_variants:
            variant_table(Path(scratch))
    print(
        f"\nload average at the end: {os.getloadavg()[0]:.1f}; "
        f"the 10^7-step loop: {calibration():.2f} s"
    )


if __name__ == "__main__":
    main()
