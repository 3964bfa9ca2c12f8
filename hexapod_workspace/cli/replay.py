"""``hexapod-workspace replay LOG``: list what a log holds, redraw its workspaces, republish it.

The log is read by :mod:`hexapod_workspace.logs.summary`; ``--publish`` hands it to
:mod:`hexapod_workspace.ros.republish` (rclpy, imported only then).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import IO, Any

import numpy as np

from hexapod_workspace.core.base.resolution import WorkspaceKind
from hexapod_workspace.errors import LogReadError
from hexapod_workspace.logs.summary import LogSummary, WorkspaceRecord, summarize_log

from . import log_report
from .commands import PROG

# --------------------------------------------------------------------------- plots


def _rebuild(record: WorkspaceRecord) -> Any:
    """Rebuild the core result dataclass from a recorded summary and boundary cloud."""
    summary, points = record.summary, record.points
    if points is None:
        msg = "no boundary points recorded"
        raise ValueError(msg)
    position = np.array([summary["position"][k] for k in "xyz"])
    kind = int(summary["kind"])
    if kind == WorkspaceKind.ORIENTATION:
        from hexapod_workspace.core.workspaces.orientation import (
            OrientationSlice,
            OrientationWorkspace,
        )

        psi = points[:, 5].astype(np.float32)
        levels = np.unique(psi)
        slices = []
        for level in levels:
            rows = points[psi == level]
            # The ray origin is not recorded; the centroid of the slice's boundary stands in.
            slices.append(
                OrientationSlice(
                    psi=float(rows[0, 5]),
                    center=rows[:, :2].mean(axis=0),
                    phi=rows[:, 3],
                    theta=rows[:, 4],
                )
            )
        step = float(np.median(np.diff(levels))) if levels.size > 1 else 0.0
        return OrientationWorkspace(
            position=position,
            slices=slices,
            psi_min=summary["psi_min"],
            psi_max=summary["psi_max"],
            volume=summary["volume"],
            n_rays=int(summary["n_rays"]),
            psi_step=step,
            tolerance=summary["tolerance"],
            elapsed=summary["elapsed"],
        )
    from hexapod_workspace.core.workspaces.projected import ProjectedWorkspace

    return ProjectedWorkspace(
        method=WorkspaceKind(kind).label,
        position=position,
        phi=points[:, 3],
        theta=points[:, 4],
        psi=points[:, 5],
        tilt_min=summary["tilt_min"],
        tilt_max=summary["tilt_max"],
        solid_angle=summary["solid_angle"],
        tolerance=summary["tolerance"],
        elapsed=summary["elapsed"],
        limiting=[""] * len(points),
    )


def _plot(summary: LogSummary, plot_dir: Path, out: IO[str], err: IO[str]) -> list[Path]:
    """Redraw the recorded workspaces; one that cannot be redrawn is a note, not a failure."""
    from hexapod_workspace.cli import plotting

    plot_dir.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    projected: dict[tuple[float, ...], list[tuple[int, Any]]] = {}

    def draw(index: int, function: Any, workspace: Any, path: Path) -> None:
        try:
            written.append(Path(function(workspace, path)))
        except (ValueError, IndexError, TypeError, ArithmeticError) as error:
            err.write(f"note: workspace {index} could not be redrawn ({error})\n")

    for index, record in enumerate(summary.workspaces, start=1):
        if not record.summary["success"] or record.points is None or not len(record.points):
            continue
        try:
            workspace = _rebuild(record)
        except (ValueError, IndexError, TypeError, KeyError) as error:
            err.write(f"note: workspace {index} could not be rebuilt from the log ({error})\n")
            continue
        if int(record.summary["kind"]) == WorkspaceKind.ORIENTATION:
            path = plot_dir / f"workspace_{index:03d}_orientation.png"
            draw(index, plotting.plot_orientation, workspace, path)
        else:  # methods computed at one position are overlaid, like the live command
            key = tuple(np.round(workspace.position, 9))
            projected.setdefault(key, []).append((index, workspace))
    for group in projected.values():
        path = plot_dir / f"workspace_{group[0][0]:03d}_projected.png"
        draw(group[0][0], plotting.plot_projected, [ws for _, ws in group], path)
    for path in written:
        out.write(f"plot: {path}\n")
    return written


def run_replay(
    log: str | Path,
    *,
    as_json: bool = False,
    plot_dir: str | Path | None = None,
    publish: bool = False,
    rate: float = 1.0,
    stdout: IO[str] | None = None,
    stderr: IO[str] | None = None,
    allow_network: bool = False,
    wait_for_subscribers: float = 0.0,
) -> int:
    """Report what a log holds; optionally redraw its workspaces and republish it.

    Parameters
    ----------
    log : str or Path
        Bare ``.mcap`` file or rosbag2 bag directory (``metadata.yaml`` + ``.mcap``).
    as_json : bool
        One JSON document on stdout instead of text.
    plot_dir : str or Path, optional
        Redraw every recorded workspace with the live commands' plots into this folder.
    publish : bool
        Republish the recorded messages on their topics (needs rclpy). Sets
        ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` when unset and refuses other values unless
        ``allow_network``.
    rate : float
        Playback speed factor for ``publish`` (1 = recorded pace, 2 = twice as fast,
        0 = as fast as possible).
    stdout, stderr : text streams, optional
        Default ``sys.stdout``/``sys.stderr``.
    allow_network : bool
        Let ``publish`` run with a discovery range other than LOCALHOST.
    wait_for_subscribers : float
        ``publish``: wait up to this many seconds for every topic to have a subscriber.

    Returns
    -------
    int
        0 when the log was read whole, 1 when it is damaged (truncated, a corrupt chunk,
        undecodable messages: everything intact is reported, the notes go to stderr), 2 when
        it cannot be read or nothing in it could be decoded (one line on stderr).
    """
    out = stdout if stdout is not None else sys.stdout
    err = stderr if stderr is not None else sys.stderr
    if not (rate >= 0 and math.isfinite(rate)):
        err.write(f"{PROG}: error: --rate: expected a finite number >= 0, got {rate:g}\n")
        return 2
    try:
        summary, kept = summarize_log(log, keep_messages=publish)
    except LogReadError as error:
        err.write(f"{PROG}: error: {error}\n")
        return 2
    except OSError as error:
        err.write(f"{PROG}: error: {log}: {error.strerror or error}\n")
        return 2
    contents = summary.contents
    for problem in contents.problems:
        err.write(f"note: {problem}\n")
    if summary.decoded == 0 and (contents.problems or not contents.finished):
        err.write(f"{PROG}: error: nothing usable in {log}\n")
        return 2
    report = log_report.log_report(summary)
    if as_json:
        json.dump(log_report.jsonable(report), out, indent=1, allow_nan=False)
        out.write("\n")
    else:
        log_report.log_report_text(report, out)
    if plot_dir is not None:
        try:
            _plot(summary, Path(plot_dir), err if as_json else out, err)
        except OSError as error:
            err.write(
                f"{PROG}: error: cannot write plots to {plot_dir}: {error.strerror or error}\n"
            )
            return 2
    if publish:
        try:
            from hexapod_workspace.ros.republish import publish_log
        except ImportError as error:
            err.write(
                f"{PROG}: error: replay --publish needs rclpy (a ROS 2 environment): {error}\n"
            )
            return 2
        published = publish_log(
            summary,
            kept,
            rate,
            err,
            allow_network=allow_network,
            wait_for_subscribers=wait_for_subscribers,
        )
        if published:
            return published
    if contents.damaged:
        err.write(f"{PROG}: {log} is damaged; everything intact was read (see the notes above)\n")
        return 1
    return 0
