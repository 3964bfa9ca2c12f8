"""Workspace computations in a worker process of the node (numpy and the core; rclpy only to
publish the clouds).

A 3-D orientation workspace takes seconds of mostly-Python work. Run in a thread of the node, it
would share the interpreter lock with the pose checks and delay them; run here, in a spawned
process, it leaves the node's interpreter to the checks. The node sends one
:class:`WorkspaceJob` at a time and gets back the ROS-free field dicts of the summary and of the
boundary cloud (:mod:`hexapod_workspace.logs.messages`), ready to become rclpy messages.

Given :class:`~hexapod_workspace.ros.clouds.CloudTopics`, the worker also publishes each full
boundary cloud itself (:class:`~hexapod_workspace.ros.clouds.CloudPublisher`: building,
serialising and publishing a large cloud stays out of the node's interpreter), hands its CDR
bytes back for the node's log (``published``), and returns a cloud of at most
``WorkspaceJob.result_points`` points for the action's result.
"""

from __future__ import annotations

import multiprocessing
import signal
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from multiprocessing.connection import Connection
from typing import Any

import numpy as np

from hexapod_workspace.core.base.resolution import WorkspaceKind
from hexapod_workspace.core.model.manipulator import Manipulator
from hexapod_workspace.core.workspaces.orientation import (
    OrientationWorkspace,
    orientation_workspace,
)
from hexapod_workspace.core.workspaces.projected import ProjectedWorkspace, projected_workspace
from hexapod_workspace.errors import HexapodWorkspaceError
from hexapod_workspace.logs import messages

from .clouds import CloudTopics, PublishedCloud, decimated_cloud_fields
from .scheduling import background, time_sharing, worker_policy

__all__ = [
    "CANCEL_GRACE",
    "CanceledError",
    "WorkerError",
    "WorkspaceJob",
    "WorkspaceWorker",
    "compute_fields",
]

#: Seconds a canceled computation has to stop by itself (at its next progress report) before
#: the worker process is terminated (and replaced on next use).
CANCEL_GRACE = 0.3
#: Smallest progress step reported to the node (fewer messages through the pipe).
_PROGRESS_STEP = 0.01


class WorkerError(RuntimeError):
    """The worker process died or could not be reached (the node restarts it on next use)."""


class CanceledError(HexapodWorkspaceError):
    """The computation was canceled before it finished."""


@dataclass(frozen=True)
class WorkspaceJob:
    """One workspace computation.

    Attributes
    ----------
    manipulator : Manipulator
    kind : int
        :data:`WorkspaceKind.ORIENTATION`, :data:`WorkspaceKind.PROJECTED_TORSION_ZERO` or
        :data:`WorkspaceKind.PROJECTED_EXACT`.
    position : ndarray, shape (3,)
        Tool-tip position OC, base frame, m.
    n_rays : int
        Rays per ψ slice (orientation) or number of φ samples (projected).
    psi_step, tolerance : float
        Slice step and boundary tolerance, rad.
    stamp_ns : int
        Stamp of the summary and of the cloud, ns since the epoch.
    frame_id, request_id : str
        Header frame and the request's id, copied into the results.
    result_points : int
        Most points of the returned cloud when the worker publishes the full one (0 = all).
    frames : dict, optional
        CellFrames fields of the node's tool and work frames when the job was made (copied
        into the summary).
    record : bool
        Hand the published cloud's CDR bytes back for the node's log (False: the node does
        not record, nothing crosses the pipe).
    record_points : int
        Most points of the cloud handed back for the log (0 = the full cloud as published).
    """

    manipulator: Manipulator
    kind: int
    position: np.ndarray
    n_rays: int
    psi_step: float
    tolerance: float
    stamp_ns: int
    frame_id: str
    request_id: str = ""
    result_points: int = 0
    frames: dict[str, Any] | None = None
    record: bool = True
    record_points: int = 0


def compute_fields(
    job: WorkspaceJob, progress: Callable[[float], None] | None = None
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Compute a workspace and return its WorkspaceSummary and PointCloud2 field dicts.

    ``progress`` receives the fraction done (0..1, non-decreasing); it may raise to stop.

    Raises
    ------
    HexapodWorkspaceError
        ``InputError``/``ResolutionError`` for a bad request, ``UnreachableReferenceError``
        when the reference orientation is unreachable at the position.
    """
    workspace: OrientationWorkspace | ProjectedWorkspace
    if job.kind == WorkspaceKind.ORIENTATION:
        workspace = orientation_workspace(
            job.manipulator,
            job.position,
            n_rays=job.n_rays,
            psi_step=job.psi_step,
            tolerance=job.tolerance,
            progress=progress,
        )
    else:
        workspace = projected_workspace(
            job.manipulator,
            job.position,
            method=WorkspaceKind(job.kind).label,
            n_phi=job.n_rays,
            tolerance=job.tolerance,
            progress=progress,
        )
    points = messages.boundary_points(workspace)
    summary = messages.summary_fields(
        workspace,
        stamp_ns=job.stamp_ns,
        frame_id=job.frame_id,
        request_id=job.request_id,
        kind=job.kind,
        n_points=points.shape[0],
    )
    cloud = messages.pointcloud_fields(points, frame_id=job.frame_id, stamp_ns=job.stamp_ns)
    return summary, cloud


def _reporter(connection: Connection, cancel: Any) -> Callable[[float], None]:
    """The progress callback of one job in the worker: sends steps, raises when canceled."""
    last = [-1.0]

    def progress(fraction: float) -> None:
        if cancel.is_set():
            raise CanceledError("canceled")
        if fraction >= last[0] + _PROGRESS_STEP or fraction >= 1.0:
            last[0] = fraction
            connection.send(("progress", float(fraction)))

    return progress


def _published(
    publisher: Any, job: WorkspaceJob, fields: tuple[dict[str, Any], dict[str, Any]]
) -> tuple[tuple[dict[str, Any], dict[str, Any]], PublishedCloud | None]:
    """Publish the full cloud of ``fields``; return the fields with the cloud bounded to
    ``job.result_points`` and what the node records (None when ``job.record`` is False)."""
    summary, cloud = fields
    published = publisher.publish(job.kind, cloud, job.record_points if job.record else None)
    return (summary, decimated_cloud_fields(cloud, job.result_points)), published


def _cloud_publisher(topics: CloudTopics | None) -> tuple[Any, str]:
    """The worker's cloud publisher (None without topics) and why it could not start ("")."""
    if topics is None:
        return None, ""
    try:
        from .clouds import CloudPublisher

        return CloudPublisher(topics), ""
    except Exception as error:  # reported with every job (the worker keeps computing)
        return None, f"the worker cannot publish clouds: {type(error).__name__}: {error}"


def _serve(
    connection: Connection,
    cancel: Any,
    topics: CloudTopics | None = None,
    policy: str = "normal",
) -> None:
    """Worker process main loop: one job in; ``("progress", fraction)`` and ``("published",
    PublishedCloud)`` messages, then ``("ok", result)``, ``("error", exc)`` or
    ``("canceled", None)`` out. ``cancel`` (an event the node sets) stops the job at its next
    progress report. The computing thread runs under ``policy``
    (:data:`~hexapod_workspace.ros.scheduling.WORKER_POLICIES`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the node decides when the worker stops
    # The publisher's DDS threads start first, at normal priority (Linux: a thread's policy and
    # niceness are its own and new threads inherit their creator's): discovery and delivery of
    # the clouds do not wait behind the computation on a busy machine.
    # a node under a real-time policy (ros/scheduling.py) passed it on: back to time-sharing
    # before the publisher's threads start, as they inherit it
    time_sharing()
    publisher, broken = _cloud_publisher(topics)
    background(policy)  # throughput work: the node's checks are scheduled first
    # The kernels of the node's model: the node's warm-up fills the cache while this process
    # starts, and the first job loads them (a job for another model compiles its own variant).
    while True:
        try:
            job = connection.recv()
        except (EOFError, OSError):
            if publisher is not None:
                publisher.close()
            return
        try:
            if broken:
                raise WorkerError(broken)
            fields = compute_fields(job, _reporter(connection, cancel))
            if publisher is not None:
                fields, published = _published(publisher, job, fields)
                if published is not None:
                    connection.send(("published", published))
            reply: tuple[str, Any] = ("ok", fields)
        except CanceledError:
            reply = ("canceled", None)
        except HexapodWorkspaceError as error:  # an empty workspace too: results only are
            reply = ("error", error)  # published, the latched clouds keep the last boundary
        except Exception as error:  # a bug: report it, keep serving
            reply = ("error", WorkerError(f"{type(error).__name__}: {error}"))
        connection.send(reply)


class WorkspaceWorker:
    """A spawned worker process that computes one :class:`WorkspaceJob` at a time.

    Thread-safe (calls are serialised). The process is started on first use (or by
    :meth:`start`) and replaced when it dies; :meth:`close` terminates it for good.
    """

    def __init__(
        self, cancel_grace: float = CANCEL_GRACE, cloud_topics: CloudTopics | None = None
    ) -> None:
        self.cancel_grace = float(cancel_grace)
        #: where the worker publishes the clouds (None: it does not); read at each (re)start
        self.cloud_topics = cloud_topics
        self._context = multiprocessing.get_context("spawn")
        self._lock = threading.Lock()
        self._process: Any = None
        self._connection: Connection | None = None
        self._cancel = self._context.Event()
        self._closed = False

    def start(self) -> None:
        """Start the worker process now (it then imports the core while the node starts);
        after :meth:`close`, start again (the node is configured again)."""
        with self._lock:
            self._closed = False
            self._ensure_started()

    def _ensure_started(self) -> Connection:
        if self._closed:
            msg = "the workspace worker is closed (the node is shutting down)"
            raise WorkerError(msg)
        if self._process is None or not self._process.is_alive() or self._connection is None:
            self._stop_locked()
            parent, child = self._context.Pipe()
            process = self._context.Process(
                target=_serve,
                args=(child, self._cancel, self.cloud_topics, worker_policy()),
                name="hexapod_workspace_worker",
                daemon=True,
            )
            process.start()
            child.close()
            self._process, self._connection = process, parent
        return self._connection

    @property
    def alive(self) -> bool:
        """True while the worker process runs (False before the first start or after a death)."""
        process = self._process
        return process is not None and process.is_alive()

    def compute(
        self,
        job: WorkspaceJob,
        progress: Callable[[float], None] | None = None,
        canceled: threading.Event | None = None,
        published: Callable[[PublishedCloud], None] | None = None,
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """Run ``job`` in the worker; block until done.

        Parameters
        ----------
        job : WorkspaceJob
        progress : callable, optional
            Called (in this thread) with the fraction done, 0..1, non-decreasing.
        canceled : threading.Event, optional
            Set by another thread to cancel: the job stops at its next progress report, or the
            worker process is terminated after ``cancel_grace`` s (:data:`CANCEL_GRACE`).
        published : callable, optional
            Called (in this thread) with each cloud the worker published (with
            :attr:`cloud_topics`), before the job's result or error.

        Returns
        -------
        (dict, dict)
            WorkspaceSummary and PointCloud2 field dicts (the cloud bounded to
            ``job.result_points`` when the worker published the full one).

        Raises
        ------
        CanceledError
            ``canceled`` was set before the job finished.
        HexapodWorkspaceError
            As :func:`compute_fields`.
        WorkerError
            The worker died twice on this job (a dead worker is replaced and the job run once
            more), the worker was closed, or the job failed unexpectedly.
        """
        with self._lock:
            for attempt in range(2):  # a job is a pure function: run it again in a new worker
                connection = self._ensure_started()
                self._cancel.clear()
                try:
                    connection.send(job)
                    status, payload = self._wait(connection, progress, canceled, published)
                    break
                except (EOFError, OSError) as error:
                    self._stop_locked()
                    if canceled is not None and canceled.is_set():
                        raise CanceledError("canceled") from None
                    if attempt == 1 or self._closed:
                        msg = "the workspace worker process died during the computation"
                        raise WorkerError(msg) from error
        if status == "canceled":
            raise CanceledError("canceled")
        if status == "error":
            raise payload
        return payload

    def _wait(
        self,
        connection: Connection,
        progress: Callable[[float], None] | None,
        canceled: threading.Event | None,
        published: Callable[[PublishedCloud], None] | None = None,
    ) -> tuple[str, Any]:
        """Receive until the job's reply; forward progress and published clouds; enforce a
        cancel (under the lock)."""
        cancel_time = None
        while True:
            if canceled is not None and canceled.is_set() and cancel_time is None:
                cancel_time = time.monotonic()
                self._cancel.set()
            if cancel_time is not None and time.monotonic() - cancel_time >= self.cancel_grace:
                self._stop_locked()  # the job did not stop by itself: end the process
                return "canceled", None
            if not connection.poll(0.02):
                continue
            status, payload = connection.recv()
            if status == "published":
                if published is not None:
                    published(payload)
            elif status != "progress":
                return status, payload
            elif progress is not None:
                progress(payload)

    def _stop_locked(self) -> None:
        process, connection = self._process, self._connection
        self._process, self._connection = None, None
        if connection is not None:
            connection.close()
        if process is not None:
            if process.is_alive():
                process.terminate()
            process.join(timeout=5.0)
            if process.is_alive():
                process.kill()
                process.join(timeout=5.0)

    def close(self) -> None:
        """Terminate the worker process (idempotent). A running computation is abandoned."""
        self._closed = True
        # not under the lock: a computation in progress holds it; terminate wakes its recv()
        process = self._process
        if process is not None and process.is_alive():
            process.terminate()
        with self._lock:
            self._stop_locked()
