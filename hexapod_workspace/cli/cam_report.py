"""How ``check-path`` on a CL file reports its speed verdicts: the text lines after the verdict
and the ``--plot`` figure (per move, the certified peak actuator speed against the limit and
the programmed feed against the largest certified one). The report itself is built in
:mod:`hexapod_workspace.cli.cam`.
"""

from __future__ import annotations

from pathlib import Path
from typing import IO, Any

import numpy as np

__all__ = ["plot_speeds", "speed_text"]


def speed_text(report: dict[str, Any], out: IO[str]) -> None:
    """The text lines of a ``check-path`` report on a CL file after its verdict: the CL units,
    frames and splines, what was passed over, the frame, and the moves that must slow down
    (at most 10; ``--json`` lists every move)."""
    speed = report["speed"]
    if "cl_units" in report:
        units = report["cl_units"]
        out.write(f"  CL units: {units['unit']} ({units['source']})\n")
        for frame in report["cl_frames"]:
            origin = ", ".join(f"{v:.6g}" for v in frame["origin"])
            out.write(
                f"  CL frame from line {frame['line']}: origin ({origin}) m in the work frame\n"
            )
    splines = report.get("cl_splines") or []
    if splines:
        lines = ", ".join(str(spline["line"]) for spline in splines[:8])
        lines += ", ..." if len(splines) > 8 else ""
        moves = sum(spline["moves"] for spline in splines)
        out.write(
            f"  NURBS: {len(splines)} spline(s) (line {lines}) as {moves} cubic Bézier moves, "
            "checked along the curve\n"
        )
    if report["passed_over"]:
        names = ", ".join(f"{n} x{c}" for n, c in report["passed_over"].items())
        out.write(f"  passed over (cannot change motion, frame, tool or units): {names}\n")
    out.write(f"  frame: {report['frame']}; speeds: {speed['covers']}\n")
    if not speed["limited"]:
        out.write("  no actuator speed limit (limits.actuator_speed_max is 0)\n")
    if speed["moves_without_feed"]:
        out.write(f"  {speed['moves_without_feed']} move(s) without a feed: no speed verdict\n")
    for move in speed["moves_to_slow_down"][:10]:
        limit = (
            f"{move['feed_max_mm_min']:.0f} mm/min"
            if move["feed_max_mm_min"] is not None
            else f"{move['feed_max_deg_min']:.0f} deg/min"
        )
        peak = move["actuator_speed_peak"]
        up_to = "unbounded" if peak is None else f"up to {peak:.4g} {speed['actuator_unit']}/s"
        out.write(
            f"  part {move['part']} move {move['segment']}: actuator speed {up_to} (limit "
            f"{max(speed['actuator_speed_max']):g}), slow down to {limit}\n"
        )


def plot_speeds(documents: list[dict[str, Any]], speed: dict[str, Any], path: Path) -> Path:
    """Per move: the certified peak actuator speed against the limit, and the programmed feed
    against ``feed_max``; tool changes as vertical lines.

    Parameters
    ----------
    documents : list of dict
        The parts' documents (with the speed keys of
        :func:`hexapod_workspace.cli.cam.cmd_check_cell_path`).
    speed : dict
        The ``speed`` summary.
    path : Path
        Image file (.png, .pdf, .svg).
    """
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    figure = Figure(figsize=(11.0, 6.0))
    top, bottom = figure.subplots(2, 1, sharex=True)
    offset = 0
    unit = speed["actuator_unit"]
    used: set[str] = set()

    def once(label: str) -> str | None:
        """Each legend entry once, from whichever part first has it."""
        if label in used:
            return None
        used.add(label)
        return label

    for document in documents:
        segments = document["segments"]
        index = offset + np.arange(len(segments))
        peak = np.array(
            [
                np.nan if s["actuator_speed_peak"] is None else s["actuator_speed_peak"]
                for s in segments
            ]
        )
        rapid = np.array([s["rapid"] for s in segments])
        rotary = np.array(["feed_deg_min" in s for s in segments])
        top.bar(index, peak, color=np.where(rapid, "tab:orange", "tab:blue"))
        feed = np.array(
            [np.nan if s.get("feed_mm_min") is None else s["feed_mm_min"] for s in segments]
        )
        feed_max = np.array(
            [np.nan if s["feed_max_mm_min"] is None else s["feed_max_mm_min"] for s in segments]
        )
        bottom.plot(
            index,
            feed,
            "o",
            color="tab:blue",
            ms=4,
            label=once("programmed feed"),
        )
        bottom.plot(
            index,
            feed_max,
            "v",
            color="tab:red",
            ms=5,
            label=once("feed_max (certified)"),
        )
        if rotary.any():
            rotary_feed = np.array([s.get("feed_deg_min") or np.nan for s in segments])
            rotary_max = np.array([s.get("feed_max_deg_min") or np.nan for s in segments])
            bottom.plot(
                index,
                rotary_feed,
                "s",
                color="tab:green",
                ms=4,
                label=once("rotary feed [deg/min]"),
            )
            bottom.plot(
                index,
                rotary_max,
                "^",
                color="tab:green",
                ms=5,
                mfc="none",
                label=once("rotary feed_max [deg/min]"),
            )
        tool = document["tool"]["number"]
        for axes in (top, bottom):
            axes.axvline(offset - 0.5, color="gray", lw=0.8, ls=":")
        top.text(
            offset - 0.4,
            0.98,
            f"T{tool}" if tool else "tool.*",
            transform=top.get_xaxis_transform(),
            va="top",
            fontsize=8,
        )
        offset += len(segments)
    limits = [v for v in speed["actuator_speed_max"] if v > 0]
    if limits:
        top.axhline(
            min(limits), color="tab:red", lw=1.2, ls="--", label=f"limit {min(limits):g} {unit}/s"
        )
    handles, _ = top.get_legend_handles_labels()
    handles += [
        Patch(color="tab:blue", label="certified peak actuator speed"),
        Patch(color="tab:orange", label="RAPID move"),
    ]
    top.set_ylabel(f"actuator speed [{unit}/s]")
    top.set_title("Certified peak actuator speed per move (bars) against the limit", fontsize=10)
    top.legend(handles=handles, fontsize=7, loc="center left")
    top.grid(alpha=0.3)
    bottom.set_yscale("log")
    bottom.set_ylabel("feed [mm/min or deg/min]")
    bottom.set_xlabel("move (parts in order; dotted lines: tool changes)")
    bottom.set_title(
        "Programmed feed and the largest feed within every actuator limit", fontsize=10
    )
    bottom.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=4)
    bottom.grid(alpha=0.3, which="both")
    figure.tight_layout()
    figure.savefig(path, dpi=120, bbox_inches="tight")
    return path
