"""The workspace worker process (ROS-free): results, progress, cancel, a replaced process."""

from __future__ import annotations

import itertools
import threading
import time

import numpy as np
import pytest

from hexapod_workspace._resources import example_config_path
from hexapod_workspace.core.base.resolution import WorkspaceKind
from hexapod_workspace.core.evaluation.loading import load_manipulator
from hexapod_workspace.core.workspaces.orientation import orientation_workspace
from hexapod_workspace.ros.worker import (
    CanceledError,
    WorkspaceJob,
    WorkspaceWorker,
)


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
        "manipulator": load_manipulator(example_config_path()),
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
def test_cancel_stops_the_computation(grace):
    """Cooperative: the job stops at its next progress report and its process lives on (the
    grace is long enough that only the job itself can have stopped). Terminate: a job that does
    not stop within the grace (here 0 s) is ended with its process, which is then replaced.
    How soon a cancel takes effect is measured by benchmarks/cancel.py, not asserted here."""
    worker = WorkspaceWorker(cancel_grace=0.0 if grace == "terminate" else 300.0)
    worker.start()
    process = worker._process  # the process before the cancel (private: no public handle)
    long_job = job(n_rays=720, psi_step=0.001, tolerance=1e-9)
    canceled = threading.Event()
    outcome: list = []
    started = threading.Event()

    def run() -> None:
        try:
            worker.compute(long_job, progress=lambda _: started.set(), canceled=canceled)
            outcome.append("finished")
        except CanceledError:
            outcome.append("canceled")

    thread = threading.Thread(target=run)
    thread.start()
    try:
        assert started.wait(60), "the job never reported progress"
        time.sleep(0.2)
        canceled.set()
        thread.join(120)  # a hang detector only: the job alone takes far longer
        assert outcome == ["canceled"], outcome
        if grace == "cooperative":
            assert worker._process is process and process.is_alive()
        else:
            assert worker._process is None and not process.is_alive()
        # and the worker serves the next job (a terminated process is replaced)
        assert worker.compute(job(n_rays=12))[0]["success"]
        assert worker.alive
    finally:
        worker.close()
