"""Workspace jobs of the node: one FIFO queue, one thread that runs them in the worker process.

Every workspace request (the ``~/compute_workspace`` action, the Trigger services, the request
topic) becomes a :class:`Ticket` in one first-in first-out queue. The queue's thread sends one
job at a time to :class:`~hexapod_workspace.ros.worker.WorkspaceWorker`, forwards its progress,
and hands the outcome to the ``finish`` function of the node (which builds, publishes and
records the summary and the action's bounded cloud in this thread, so the executor never waits
for a computation; the full cloud is published by the worker process and only recorded here,
through ``on_published``). A ticket can be canceled while queued (it never runs) or while
running (the worker stops within :data:`~hexapod_workspace.ros.worker.CANCEL_GRACE` s).
"""

from __future__ import annotations

import collections
import threading
from collections.abc import Callable
from typing import Any

from rclpy.task import Future

from .worker import CanceledError, WorkspaceJob, WorkspaceWorker

__all__ = ["JobQueue", "Ticket", "completion", "in_thread"]

#: The stages a ticket goes through (the action's feedback ``stage``).
QUEUED, COMPUTING, PUBLISHING, DONE = "queued", "computing", "publishing", "done"


class Ticket:
    """One queued workspace job and its outcome.

    ``on_progress(fraction, stage)`` is called from the queue's thread (fraction 0..1,
    non-decreasing); ``on_done(ticket)`` once, from the queue's thread (or from the thread that
    canceled a queued ticket), after ``outcome`` or ``error`` is set.
    """

    def __init__(
        self,
        job: WorkspaceJob,
        on_progress: Callable[[float, str], None] | None = None,
        on_done: Callable[[Ticket], None] | None = None,
    ) -> None:
        self.job = job
        self.on_progress = on_progress
        self.on_done = on_done
        self.canceled = threading.Event()
        self.stage = QUEUED
        self.progress = 0.0
        self.outcome: Any = None
        self.error: BaseException | None = None
        self.done = threading.Event()

    def report(self, fraction: float, stage: str | None = None) -> None:
        self.progress = max(self.progress, min(1.0, float(fraction)))
        if stage is not None:
            self.stage = stage
        if self.on_progress is not None:
            self.on_progress(self.progress, self.stage)

    def _finish(self, outcome: Any = None, error: BaseException | None = None) -> None:
        self.outcome, self.error, self.stage = outcome, error, DONE
        self.done.set()
        if self.on_done is not None:
            self.on_done(self)


class JobQueue:
    """Runs :class:`Ticket` jobs one at a time, in order, in a thread of its own.

    Parameters
    ----------
    worker : WorkspaceWorker
    finish : callable
        ``finish(job, fields)`` turns the worker's field dicts into the node's published
        messages and returns what the ticket's ``outcome`` becomes; called in the queue's
        thread.
    on_error : callable
        ``on_error(job, error)`` for a failed (or canceled) job: returns the ``outcome`` too.
    on_published : callable, optional
        ``on_published(cloud)`` for each cloud the worker published
        (:class:`~hexapod_workspace.ros.clouds.PublishedCloud`), in the queue's thread.
    """

    def __init__(
        self,
        worker: WorkspaceWorker,
        finish: Callable[[WorkspaceJob, Any], Any],
        on_error: Callable[[WorkspaceJob, BaseException], Any],
        on_published: Callable[[Any], None] | None = None,
    ) -> None:
        self._worker = worker
        self._finish_job = finish
        self._on_error = on_error
        self._on_published = on_published
        self._condition = threading.Condition()
        self._pending: collections.deque[Ticket] = collections.deque()
        self._running: Ticket | None = None
        self._stopped = False
        self.completed = 0
        self.canceled = 0
        self._thread = threading.Thread(
            target=self._run, name="hexapod_workspace_jobs", daemon=True
        )
        self._thread.start()

    @property
    def depth(self) -> int:
        """Jobs waiting or running."""
        return len(self._pending) + (self._running is not None)

    def submit(self, ticket: Ticket) -> Ticket:
        """Queue ``ticket`` (it runs after those before it)."""
        with self._condition:
            if self._stopped:
                ticket._finish(error=CanceledError("the node is shutting down"))
                return ticket
            self._pending.append(ticket)
            self._condition.notify()
        return ticket

    def cancel(self, ticket: Ticket) -> None:
        """Cancel a queued ticket at once, or a running one (the worker stops it)."""
        ticket.canceled.set()
        with self._condition:
            if ticket not in self._pending:
                return  # running (the worker sees the event) or done
            self._pending.remove(ticket)
        self.canceled += 1
        error = CanceledError("canceled")
        ticket._finish(self._failure(ticket.job, error), error)

    def cancel_all(self) -> int:
        """Cancel the queued tickets and the running one (the node is deactivated); returns
        how many were canceled. The queue keeps serving later submissions."""
        with self._condition:
            tickets = [*([self._running] if self._running is not None else []), *self._pending]
        for ticket in tickets:
            self.cancel(ticket)
        return len(tickets)

    def stop(self, timeout: float = 10.0) -> None:
        """Cancel everything and end the thread."""
        with self._condition:
            self._stopped = True
            pending = list(self._pending)
            running = self._running
            self._condition.notify()
        for ticket in pending:
            self.cancel(ticket)
        if running is not None:
            running.canceled.set()
        self._thread.join(timeout)

    def _failure(self, job: WorkspaceJob, error: BaseException) -> Any:
        """The outcome of a failed job (``on_error``), or None when even that fails (the node
        is shutting down: its publishers are gone)."""
        try:
            return self._on_error(job, error)
        except Exception:
            return None

    def _run(self) -> None:
        while True:
            with self._condition:
                while not self._pending and not self._stopped:
                    self._condition.wait()
                if self._stopped:
                    return
                ticket = self._running = self._pending.popleft()
            try:
                self._execute(ticket)
            finally:
                with self._condition:
                    self._running = None

    def _execute(self, ticket: Ticket) -> None:
        job = ticket.job
        try:
            ticket.report(0.0, COMPUTING)
            fields = self._worker.compute(
                job,
                progress=lambda fraction: ticket.report(0.95 * fraction),
                canceled=ticket.canceled,
                published=self._on_published,
            )
            ticket.report(0.95, PUBLISHING)
            outcome = self._finish_job(job, fields)
        except Exception as error:  # a bad request, a cancel, a dead worker, a bug: answered
            if isinstance(error, CanceledError):
                self.canceled += 1
            ticket._finish(self._failure(job, error), error)
            return
        self.completed += 1
        ticket.report(1.0)
        ticket._finish(outcome)


def completion(node: Any) -> tuple[Future, Callable[..., None]]:
    """A future a coroutine callback of ``node`` can await, and the function another thread
    calls to complete it: ``complete(value)`` or ``complete(error=exception)``. Completing wakes
    the node's executor, which then resumes the coroutine."""
    executor = node.executor
    future: Future = Future(executor=executor)

    def complete(value: Any = None, error: BaseException | None = None) -> None:
        if error is None:
            future.set_result(value)
        else:
            future.set_exception(error)
        if executor is not None:
            executor.wake()

    return future, complete


def in_thread(node: Any, callback: Callable[..., Any]) -> Callable[..., Any]:
    """A coroutine version of a blocking callback of ``node`` (an action's execute callback, a
    slow service): each call runs ``callback`` in a thread of its own while the node's
    single-threaded executor keeps serving, and resumes when it returns. For extensions whose
    callbacks block, e.g. ``execute_callback=in_thread(node, execute)``."""

    async def run(*args: Any, **kwargs: Any) -> Any:
        future, complete = completion(node)

        def target() -> None:
            try:
                value = callback(*args, **kwargs)
            except BaseException as error:  # handed to the awaiting coroutine
                complete(error=error)
            else:
                complete(value)

        name = f"hexapod_workspace_{getattr(callback, '__name__', 'callback')}"
        threading.Thread(target=target, name=name, daemon=True).start()
        return await future

    return run
