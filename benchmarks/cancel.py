#!/usr/bin/env python3
"""How soon a cancelled workspace job stops: cooperatively, and by ending the worker process.

The node's worker (:class:`hexapod_workspace.ros.worker.WorkspaceWorker`) stops a cancelled job
at its next progress report; a job that does not stop within ``cancel_grace`` seconds is ended
with its process, which is then replaced. ``test/ros/test_worker.py`` asserts both behaviours;
this script measures the delay from the cancel to the job's end (``CanceledError`` raised), a
few runs each, with the load average (the machine is shared).

Usage: python benchmarks/cancel.py [--runs N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import threading
import time

import numpy as np

from hexapod_workspace.core.base.resolution import WorkspaceKind
from hexapod_workspace.core.evaluation.loading import example_manipulator
from hexapod_workspace.ros.worker import CANCEL_GRACE, CanceledError, WorkspaceJob, WorkspaceWorker

#: A 3-D workspace job that runs far longer than any cancel takes (it reports progress often).
LONG_JOB = {
    "kind": WorkspaceKind.ORIENTATION,
    "position": np.array([0.0, 0.0, -1.3]),
    "n_rays": 720,
    "psi_step": 0.001,
    "tolerance": 1e-9,
    "stamp_ns": 1,
    "frame_id": "base",
}


def cancel_delay(worker: WorkspaceWorker, job: WorkspaceJob) -> float:
    """Start ``job``, cancel it 0.2 s after its first progress report; seconds to its end."""
    canceled, started = threading.Event(), threading.Event()
    ended: list[float] = []

    def run() -> None:
        try:
            worker.compute(job, progress=lambda _: started.set(), canceled=canceled)
        except CanceledError:
            ended.append(time.monotonic())

    thread = threading.Thread(target=run)
    thread.start()
    if not started.wait(120):
        raise SystemExit("the job never reported progress")
    time.sleep(0.2)
    at = time.monotonic()
    canceled.set()
    thread.join(120)
    if not ended:
        raise SystemExit("the job was not cancelled")
    return ended[0] - at


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="cancels per mode (default 5)")
    runs = parser.parse_args().runs
    job = WorkspaceJob(manipulator=example_manipulator(), **LONG_JOB)
    print(f"cancel of a running 3-D workspace job; load average {os.getloadavg()[0]:.2f}")
    for mode, grace in (("cooperative", 300.0), ("terminate", 0.0)):
        worker = WorkspaceWorker(cancel_grace=grace)
        worker.start()
        try:
            delays = [cancel_delay(worker, job) for _ in range(runs)]
        finally:
            worker.close()
        print(
            f"  {mode:11} (grace {grace:g} s): median {statistics.median(delays) * 1e3:6.1f} ms, "
            f"max {max(delays) * 1e3:6.1f} ms over {runs} cancels"
        )
    print(f"the node's grace before it ends the worker process: {CANCEL_GRACE} s")


if __name__ == "__main__":
    main()
