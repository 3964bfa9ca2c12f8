"""``schedule --plot``: the feed along the path against the programmed feed, and each actuator's
speed and acceleration against its limits, over time."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..core.cell.frames import CellFrames
from ..core.model.manipulator import Manipulator
from ..core.motions.schedule import PathSchedule
from ..core.motions.schedule_report import schedule_profiles
from .cam import MM_MIN

__all__ = ["ScheduledPart", "plot_schedule"]


@dataclass(frozen=True)
class ScheduledPart:
    """One part as it was scheduled: its tool model, waypoints (base frame), curved moves,
    programmed feeds per move (m/s, or rad/s for a rotation without translation; NaN: none)
    and schedule."""

    model: Manipulator
    positions: NDArray[np.float64]
    rotations: NDArray[np.float64]
    arcs: NDArray[np.float64] | None
    beziers: NDArray[np.float64] | None
    programmed: NDArray[np.float64]
    schedule: PathSchedule


def plot_schedule(parts: list[ScheduledPart], cell: CellFrames, unit: str, path: Path) -> Path:
    """Draw the schedules of ``parts`` (one after the other in time) into ``path``: the feed at
    the grid nodes against the programmed feed, |q̇_i| and q̈_i against the limits."""
    from matplotlib import rcParams
    from matplotlib.figure import Figure

    figure = Figure(figsize=(10.5, 8.5))
    top, middle, bottom = figure.subplots(3, 1, sharex=True)
    colours = rcParams["axes.prop_cycle"].by_key()["color"]
    offset = 0.0
    for index, part in enumerate(parts):
        schedule = part.schedule
        profile = schedule_profiles(
            part.model,
            part.positions,
            part.rotations,
            schedule,
            arcs=part.arcs,
            beziers=part.beziers,
        )
        t = profile.time + offset
        first = index == 0
        top.plot(t, profile.feed / MM_MIN, color="tab:blue", lw=1.2, label="scheduled" * first)
        # rotations without translation are programmed in deg/min: no tool feed to draw
        rotary = schedule.rotary[schedule.node_move]
        programmed = np.where(rotary, np.nan, part.programmed[schedule.node_move] / MM_MIN)
        top.plot(t, programmed, color="0.35", ls="--", lw=1.0, label="programmed" * first)
        for i in range(6):
            colour = colours[i % len(colours)]
            middle.plot(
                t, np.abs(profile.speed[:, i]), color=colour, lw=1.0, label=f"{i + 1}" * first
            )
            bottom.plot(t, profile.accel[:, i], color=colour, lw=1.0)
        if index:
            for axis in (top, middle, bottom):
                axis.axvline(offset, color="0.6", lw=0.8)
        offset = float(t[-1]) if t.size else offset
    for axis, limits, name, both in (
        (middle, cell.actuator_speed_max, "limit", False),
        (bottom, cell.actuator_accel_max, "limits", True),
    ):
        for j, value in enumerate(sorted({float(v) for v in limits if v > 0.0})):
            axis.axhline(value, color="tab:red", ls=":", lw=1.4, label=name if j == 0 else None)
            if both:
                axis.axhline(-value, color="tab:red", ls=":", lw=1.4)
    top.set_ylabel("tool feed, mm/min")
    middle.set_ylabel(f"|actuator speed|, {unit}/s")
    bottom.set_ylabel(f"actuator accel., {unit}/s²")
    bottom.set_xlabel("time, s")
    outside = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "fontsize": 8}
    top.legend(**outside)
    middle.legend(**outside, title="actuator", title_fontsize=8)
    bottom.legend(**outside)
    for axis in (top, middle, bottom):
        axis.grid(True, alpha=0.3)
    total = sum(p.schedule.duration for p in parts)
    top.set_title(f"Fastest certified schedule: {total:.2f} s (limits hold between grid points)")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    return path
