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
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from ..core.manipulator import Manipulator
from ..core.orientation import orientation_workspace
from ..core.projected import projected_workspace
from ..errors import UnreachableReferenceError

__all__ = ["DEMO_CASES", "run_demo"]

#: The two cases of the demo: name and position (m, base frame).
DEMO_CASES: tuple[tuple[str, tuple[float, float, float]], ...] = (
    ("on_axis", (0.0, 0.0, -1.3)),
    ("off_axis", (0.2, 0.2, -0.95)),
)


def _progress(label: str):
    from .progress import ProgressBar

    return ProgressBar(label)


def run_demo(manipulator: Manipulator, out_dir: Path, *, out: TextIO, as_json: bool = False) -> int:
    """Run the demo and write its files into ``out_dir``.

    Parameters
    ----------
    manipulator : Manipulator
        Normally the packaged example.
    out_dir : pathlib.Path
        Output folder (created).
    out : file-like
        Where the results table (or JSON with ``as_json``) goes.

    Returns
    -------
    int
        0, or 1 when a case's reference orientation is unreachable (reported in the table).
    """
    from ..logs.record import record_results
    from .plotting import plot_orientation, plot_projected

    out_dir.mkdir(parents=True, exist_ok=True)
    rows: list[dict[str, Any]] = []
    recorded: list[Any] = []
    status = 0
    for name, position in DEMO_CASES:
        try:
            torsion_zero = projected_workspace(
                manipulator, position, progress=_progress(f"{name}: projected torsion_zero")
            )
            exact = projected_workspace(
                manipulator, position, method="exact", progress=_progress(f"{name}: exact")
            )
            solid = orientation_workspace(
                manipulator, position, progress=_progress(f"{name}: orientation")
            )
        except UnreachableReferenceError as error:
            rows.append({"case": name, "position": list(position), "error": str(error)})
            status = 1
            continue
        projected_png = plot_projected([torsion_zero, exact], out_dir / f"projected_{name}.png")
        orientation_png = plot_orientation(solid, out_dir / f"orientation_{name}.png")
        recorded += [torsion_zero, exact, solid]
        rows.append(
            {
                "case": name,
                "position": list(position),
                "tilt_min_deg": math.degrees(torsion_zero.tilt_min),
                "tilt_max_deg": math.degrees(torsion_zero.tilt_max),
                "exact_tilt_min_deg": math.degrees(exact.tilt_min),
                "exact_tilt_max_deg": math.degrees(exact.tilt_max),
                "torsion_zero_gap_max_deg": math.degrees(float(np.max(exact.gap))),
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
    log = record_results(out_dir / "demo.mcap", recorded, frame_id=manipulator.frame_id)
    (out_dir / "results.json").write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")
    table = _table(rows, log.name)
    (out_dir / "results.md").write_text(table, encoding="utf-8")
    if as_json:
        out.write(json.dumps({"out": str(out_dir), "cases": rows, "log": log.name}) + "\n")
    else:
        out.write(table)
        out.write(f"\nwrote {out_dir}/: results.md, results.json, {log.name}, ")
        out.write(", ".join(name for row in rows for name in row.get("plots", [])) + "\n")
    return status


def _table(rows: list[dict[str, Any]], log_name: str) -> str:
    lines = [
        "| case | position [m] | tilt θ (ψ = 0) [deg] | tilt θ (exact) [deg] "
        "| max gap [deg] | ψ range [deg] | volume [rad³] | time tz / exact / 3-D [s] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        position = "({:g}, {:g}, {:g})".format(*row["position"])
        if "error" in row:
            lines.append(f"| {row['case']} | {position} | {row['error']} | | | | | |")
            continue
        elapsed = row["elapsed_s"]
        lines.append(
            f"| {row['case']} | {position} "
            f"| {row['tilt_min_deg']:.2f} – {row['tilt_max_deg']:.2f} "
            f"| {row['exact_tilt_min_deg']:.2f} – {row['exact_tilt_max_deg']:.2f} "
            f"| {row['torsion_zero_gap_max_deg']:.2f} "
            f"| {row['psi_min_deg']:.2f} – {row['psi_max_deg']:.2f} "
            f"| {row['volume_rad3']:.4f} "
            f"| {elapsed['torsion_zero']:.3f} / {elapsed['exact']:.3f} / "
            f"{elapsed['orientation']:.2f} |"
        )
    lines.append("")
    lines.append(f"Log of every result: `{log_name}` (`hexapod-workspace replay {log_name}`).")
    return "\n".join(lines) + "\n"
