"""The workspace worker process (ROS-free): results, progress, cancel, a replaced process."""

from __future__ import annotations

import itertools
import threading
import time

import numpy as np
import pytest

from hexapod_workspace import Manipulator
from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.orientation import orientation_workspace
from hexapod_workspace.core.resolution import WorkspaceKind
from hexapod_workspace.ros.worker import (
    CanceledError,
    WorkspaceJob,
    WorkspaceWorker,
)

#: What the node promises for a cancel (issue 10): the computation stops within this, s.
CANCEL_BOUND = 0.5


@pytest.fixture(scope="module")
def worker():
    worker = WorkspaceWorker()
    worker.start()
    try:
        yield worker
    finally:
        worker.close()


def job(**changes) -> WorkspaceJob:
    fields = {
        "manipulator": Manipulator.from_params_file(example_config_path()),
        "kind": WorkspaceKind.ORIENTATION,
        "position": np.array([0.0, 0.0, -1.3]),
        "n_rays": 24,
        "psi_step": 0.05,
        "tolerance": 1e-4,
        "stamp_ns": 1,
        "frame_id": "base",
        **changes,
    }
    return WorkspaceJob(**fields)


def test_result_and_progress_match_the_core(worker):
    progress: list[float] = []
    summary, cloud = worker.compute(job(), progress=progress.append)
    expected = orientation_workspace(
        job().manipulator, (0.0, 0.0, -1.3), n_rays=24, psi_step=0.05, tolerance=1e-4
    )
    assert summary["volume"] == pytest.approx(expected.volume, rel=1e-12)
    assert len(progress) >= 3 and progress[-1] == 1.0
    assert all(b >= a for a, b in itertools.pairwise(progress))


@pytest.mark.parametrize("grace", ["cooperative", "terminate"])
def test_cancel_stops_the_computation_within_the_bound(worker, grace):
    """Cooperative: the job stops at its next progress report. Terminate: a job that does not
    stop within the grace (here 0 s) is ended with its process, which is then replaced."""
    if grace == "terminate":
        worker = WorkspaceWorker(cancel_grace=0.0)
    long_job = job(n_rays=720, psi_step=0.001, tolerance=1e-9)
    canceled = threading.Event()
    outcome: list = []
    started = threading.Event()

    def run() -> None:
        try:
            worker.compute(long_job, progress=lambda _: started.set(), canceled=canceled)
            outcome.append("finished")
        except CanceledError:
            outcome.append(time.monotonic())

    thread = threading.Thread(target=run)
    thread.start()
    assert started.wait(60), "the job never reported progress"
    time.sleep(0.2)
    canceled_at = time.monotonic()
    canceled.set()
    thread.join(30)
    assert outcome and outcome[0] != "finished", "the job ended before the cancel"
    elapsed = outcome[0] - canceled_at
    grace_s = worker.cancel_grace
    print(f"{grace}: stopped {elapsed * 1e3:.0f} ms after the cancel (grace {grace_s} s)")
    try:
        assert elapsed <= CANCEL_BOUND
        # and the worker serves the next job (a terminated process is replaced)
        assert worker.compute(job(n_rays=12))[0]["success"]
    finally:
        if grace == "terminate":
            worker.close()
