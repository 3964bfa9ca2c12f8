#!/usr/bin/env python3
"""``pip install .`` at both ends of what setup.py declares, each in a fresh venv.

* ``newest``: ``pip install .`` as a new user runs it: pip resolves the newest releases the
  declared ranges allow.
* ``lowest``: the same with numpy and numba pinned to their declared lower bounds (the
  ``>=`` versions of ``install_requires``, read from setup.py; the versions a ROS 2 Jazzy user
  on Ubuntu 24.04 gets with apt).

In each venv, outside the source tree and with a cache of its own: import the package, print
the versions it runs with, answer ``hexapod-workspace check --json`` for three poses of the
packaged example (the verdicts and margins must be those of the pinned environment that runs
this script, margins to 1e-9 m or rad) and run ``projected --method exact``. Exit 0 when both
ends pass; the reason in one line otherwise.

Usage: python tools/check_install.py [newest|lowest ...] [--keep DIR]
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import re
import subprocess
import sys
import tempfile
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
POSES = ["--pose", "0", "0", "0", "--pose", "30", "20", "10", "--pose", "0", "60", "0"]


def declared_lower_bounds() -> dict[str, str]:
    """The ``>=`` bound of each install requirement of setup.py, by name."""
    tree = ast.parse((ROOT / "setup.py").read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.keyword) and node.arg == "install_requires":
            requirements = ast.literal_eval(node.value)
            break
    else:
        raise SystemExit("setup.py: no install_requires")
    bounds = {}
    for requirement in requirements:
        match = re.match(r"^([A-Za-z0-9_.-]+)>=([0-9.]+)", requirement)
        if match:
            bounds[match[1].lower()] = match[2]
    return bounds


def run(command: list[str], **options: object) -> subprocess.CompletedProcess[str]:
    done: subprocess.CompletedProcess[str] = subprocess.run(
        command, capture_output=True, text=True, check=False, **options
    )
    return done


def verdicts(hexapod: list[str], environment: dict[str, str], cwd: Path) -> list[dict]:
    done = run([*hexapod, "--json", "check", *POSES], env=environment, cwd=cwd)
    if done.returncode not in (0, 1):
        raise SystemExit(f"check failed (exit {done.returncode}): {done.stderr.strip()[-400:]}")
    poses = json.loads(done.stdout)["poses"]
    return [{"reachable": pose["reachable"], "margins": pose["margins"]} for pose in poses]


def same(expected: list[dict], got: list[dict]) -> str:
    """'' when the answers agree, else what differs."""
    for index, (a, b) in enumerate(zip(expected, got, strict=True)):
        if a["reachable"] != b["reachable"]:
            return (
                f"pose {index}: reachable {b['reachable']}, the pinned venv says {a['reachable']}"
            )
        for name, value in a["margins"].items():
            other = b["margins"].get(name)
            if (value is None) != (other is None) or (
                value is not None and abs(value - other) > 1e-9
            ):
                return f"pose {index}: {name} {other}, the pinned venv says {value}"
    return ""


def check_end(end: str, folder: Path, expected: list[dict]) -> None:
    bounds = declared_lower_bounds()
    environment = {
        key: value
        for key, value in os.environ.items()
        if not key.startswith(("NUMBA_", "PYTHON", "VIRTUAL_ENV"))
    }
    environment["NUMBA_CACHE_DIR"] = str(folder / "numba-cache")
    target = folder / "venv"
    venv.create(target, with_pip=True)
    python = str(target / "bin" / "python")
    pins = []
    if end == "lowest":  # exactly the declared bounds (numpy>=1.26 means 1.26.0)
        pins = [f"{name}=={bounds[name]}" for name in ("numpy", "numba")]
    install = run(
        [python, "-m", "pip", "install", "--disable-pip-version-check", "-q", str(ROOT), *pins],
        env=environment,
        cwd=folder,
    )
    if install.returncode != 0:
        tail = " ".join(install.stderr.strip().splitlines()[-3:])
        raise SystemExit(f"{end}: pip install . {' '.join(pins)} failed: {tail}")
    versions = run(
        [
            python,
            "-c",
            "import numpy, numba, hexapod_workspace; "
            "print(numpy.__version__, numba.__version__, hexapod_workspace.__version__)",
        ],
        env=environment,
        cwd=folder,
    )
    if versions.returncode != 0:
        tail = versions.stderr.strip().splitlines()[-1:]
        raise SystemExit(f"{end}: import hexapod_workspace failed: {' '.join(tail)}")
    numpy_version, numba_version, package = versions.stdout.split()
    hexapod = [str(target / "bin" / "hexapod-workspace")]
    difference = same(expected, verdicts(hexapod, environment, folder))
    if difference:
        raise SystemExit(f"{end} (numpy {numpy_version}, numba {numba_version}): {difference}")
    projected = run(
        [*hexapod, "--json", "projected", "--method", "exact"], env=environment, cwd=folder
    )
    if projected.returncode != 0:
        tail = projected.stderr.strip().splitlines()[-1:]
        raise SystemExit(f"{end}: projected --method exact failed: {' '.join(tail)}")
    answer = json.loads(projected.stdout)
    print(
        f"{end}: numpy {numpy_version}, numba {numba_version}, hexapod_workspace {package}: "
        "check agrees with the pinned venv; projected --method exact: tilt "
        f"{answer['tilt_min_deg']:.3f}-{answer['tilt_max_deg']:.3f} deg"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ends", nargs="*", help="newest, lowest (default: both)")
    parser.add_argument(
        "--keep", type=Path, help="build the venvs here (kept) instead of a temporary folder"
    )
    options = parser.parse_args()
    ends = options.ends or ["newest", "lowest"]
    unknown = sorted(set(ends) - {"newest", "lowest"})
    if unknown:
        parser.error(f"ends: expected newest or lowest, got {', '.join(unknown)}")
    here = Path(sys.executable).parent / "hexapod-workspace"
    with tempfile.TemporaryDirectory(prefix="hexapod-install-") as scratch:
        base = options.keep or Path(scratch)
        expected = verdicts([str(here)], dict(os.environ), Path(scratch))
        for end in ends:
            folder = base / end
            folder.mkdir(parents=True, exist_ok=True)
            check_end(end, folder, expected)


if __name__ == "__main__":
    main()
