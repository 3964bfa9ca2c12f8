"""The ``demo`` command: the example manipulator end to end, in the manner of the paper.

Bonev & Ryu analyse their GPM at two positions: on the axis of symmetry and off it. The demo
does the same for the packaged example: at each position it computes the projected workspace
with both methods and the 3-D orientation workspace, then writes

* ``results.md``: a table of the figures (tilt range, torsion range, volume, timings),
* ``results.json``: the same figures, machine-readable,
* ``projected_<case>.png`` and ``orientation_<case>.png``: the plots,
* ``demo.mcap``: every result as an MCAP log in the node's format (``replay`` reads it).
"""

from __future__ import annotations

import json
import math
import shlex
import time
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..core import kernels
from ..core.model.manipulator import Manipulator
from ..core.workspaces.orientation import orientation_workspace
from ..core.workspaces.projected import projected_workspace
from ..errors import UnreachableReferenceError
from . import reports
from .inputs import CliError, output_file

__all__ = ["DEMO_CASES", "run_demo"]

#: The two cases of the demo: name and position (m, base frame).
DEMO_CASES: tuple[tuple[str, tuple[float, float, float]], ...] = (
    ("on_axis", (0.0, 0.0, -1.3)),
    ("off_axis", (0.2, 0.2, -0.95)),
)


#: The files the demo writes into its folder (besides ``projected_<case>.png`` and
#: ``orientation_<case>.png``), with the start of each when it is the demo's own.
_OWN_TEXT = {"results.md": "| case |", "results.json": "["}


def _targets(out_dir: Path, force: bool) -> None:
    """Refuse to replace, without ``force``, a file in ``out_dir`` that is not the demo's."""
    names = [
        f"{kind}_{case}.png" for case, _ in DEMO_CASES for kind in ("projected", "orientation")
    ]
    for name in [*names, "demo.mcap"]:
        output_file(out_dir / name, "--out", force=force, suffixes=(Path(name).suffix,))
    for name, start in _OWN_TEXT.items():
        path = out_dir / name
        if path.is_file() and not force:
            with path.open("rb") as handle:
                head = handle.read(len(start)).decode("utf-8", "replace")
            if head != start:
                msg = f"--out: {path} exists and is not the demo's; not replaced (use --force)"
                raise CliError(msg)


def run_demo(
    manipulator: Manipulator,
    out_dir: Path,
    *,
    out: IO[str],
    err: IO[str],
    as_json: bool = False,
    force: bool = False,
) -> int:
    """Run the demo and write its files into ``out_dir``.

    Parameters
    ----------
    manipulator : Manipulator
        Normally the packaged example (its ``pose.position`` is not used: the demo has its own
        two positions, :data:`DEMO_CASES`).
    out_dir : pathlib.Path
        Output folder, created with its parents.
    out, err : text streams
        Where the results table (or JSON with ``as_json``) and the progress go.
    force : bool
        Replace files in ``out_dir`` with the demo's names even when they are not the demo's.

    Returns
    -------
    int
        0, or 1 when a case's reference orientation is unreachable (reported in the table).
    """
    from ..logs.record import record_results
    from .plotting import plot_orientation, plot_projected
    from .progress import ProgressBar

    # Compiled (first run after install) before anything is timed.
    kernels.warm_up(kernels.model_vector(manipulator))

    if out_dir.exists() and not out_dir.is_dir():
        msg = f"--out: {out_dir} exists and is not a folder"
        raise CliError(msg)
    out_dir.mkdir(parents=True, exist_ok=True)
    _targets(out_dir, force)
    rows: list[dict[str, Any]] = []
    recorded: list[Any] = []
    stamps: list[int] = []
    status = 0
    for name, position in DEMO_CASES:
        try:
            started = [time.time_ns()]
            torsion_zero = projected_workspace(
                manipulator, position, progress=ProgressBar(f"{name}: torsion_zero", stream=err)
            )
            started.append(time.time_ns())
            exact = projected_workspace(
                manipulator,
                position,
                method="exact",
                progress=ProgressBar(f"{name}: exact", stream=err),
            )
            started.append(time.time_ns())
            solid = orientation_workspace(
                manipulator, position, progress=ProgressBar(f"{name}: orientation", stream=err)
            )
        except UnreachableReferenceError as error:
            rows.append({"case": name, "position": list(position), "error": str(error)})
            status = 1
            continue
        projected_png = plot_projected([torsion_zero, exact], out_dir / f"projected_{name}.png")
        orientation_png = plot_orientation(solid, out_dir / f"orientation_{name}.png")
        recorded += [torsion_zero, exact, solid]
        stamps += started
        rows.append(
            {
                "case": name,
                "position": list(position),
                "tilt_min_deg": math.degrees(torsion_zero.tilt_min),
                "tilt_max_deg": math.degrees(torsion_zero.tilt_max),
                "exact_tilt_min_deg": math.degrees(exact.tilt_min),
                "exact_tilt_max_deg": math.degrees(exact.tilt_max),
                # The exact method always reports its gap to the torsion-zero boundary.
                "torsion_zero_gap_max_deg": math.degrees(float(np.max(exact.gap)))
                if exact.gap is not None
                else math.nan,
                "solid_angle_sr": torsion_zero.solid_angle,
                "exact_solid_angle_sr": exact.solid_angle,
                "psi_min_deg": math.degrees(solid.psi_min),
                "psi_max_deg": math.degrees(solid.psi_max),
                "volume_rad3": solid.volume,
                "slices": len(solid.slices),
                "elapsed_s": {
                    "torsion_zero": torsion_zero.elapsed,
                    "exact": exact.elapsed,
                    "orientation": solid.elapsed,
                },
                "plots": [projected_png.name, orientation_png.name],
            }
        )
    log = record_results(
        out_dir / "demo.mcap", recorded, frame_id=manipulator.frame_id, stamps_ns=stamps
    )
    (out_dir / "results.json").write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")
    # The log as the user can name it from where the demo ran (--out as given: demo_out/demo.mcap).
    table = reports.demo_table(rows, shlex.quote(str(out_dir / log.name)))
    (out_dir / "results.md").write_text(table, encoding="utf-8")
    if as_json:
        out.write(json.dumps({"out": str(out_dir), "cases": rows, "log": log.name}) + "\n")
    else:
        out.write(table)
        out.write(f"\nwrote {out_dir}/: results.md, results.json, {log.name}, ")
        out.write(", ".join(name for row in rows for name in row.get("plots", [])) + "\n")
    return status
