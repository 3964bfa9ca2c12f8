"""Workspace requests of the node: the ``~/compute_workspace`` action, the Trigger services and
the request topic, all through one first-in first-out
:class:`~hexapod_workspace.ros.jobs.JobQueue`.

A request is checked here (a refusal names the field and the value) and becomes a
:class:`~hexapod_workspace.ros.worker.WorkspaceJob` with the node's resolution parameters filled
in. The job queue's thread runs it in the worker process, which publishes the full boundary
cloud itself (:mod:`~hexapod_workspace.ros.clouds`; the node records its bytes), then publishes
(and records) the summary and completes the request with a cloud of at most
:data:`~hexapod_workspace.ros.clouds.RESULT_MAX_POINTS` points: the action's execute coroutine
and the Trigger services await it without holding the executor. Goals are always accepted and
queue with the other requests; an invalid goal is aborted with the reason in ``result.message``;
a canceled goal, queued or running, ends CANCELED with the message "canceled". The action is
recorded in the form of ComputeWorkspace.srv (same fields as the Goal and the Result; rosbag2 in
Jazzy records no actions) on ``<action>/request`` and ``<action>/response``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from hexapod_workspace_msgs.action import ComputeWorkspace
from hexapod_workspace_msgs.msg import WorkspaceRequest, WorkspaceSummary
from hexapod_workspace_msgs.srv import ComputeWorkspace as ComputeWorkspaceRecord
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from sensor_msgs.msg import PointCloud2
from std_srvs.srv import Trigger

from hexapod_workspace.core.base.resolution import WorkspaceKind
from hexapod_workspace.errors import InputError, UnreachableReferenceError
from hexapod_workspace.logs import messages, qos_profile_text
from hexapod_workspace.logs.cell import cell_frames_fields

from .clouds import RESULT_MAX_POINTS, CloudTopics
from .conversions import position_from_point, to_message, type_name
from .jobs import JobQueue, Ticket, completion
from .load_rows import require_geometric
from .parameters import RAYS_RANGE
from .qos import FEEDBACK_QOS_PROFILE
from .worker import CanceledError, WorkspaceJob

__all__ = ["WorkspaceServer"]


@dataclass(frozen=True)
class _Failed:
    """A workspace request refused before it reaches the worker."""

    reason: str
    n_rays: int = 0


class WorkspaceServer:
    """The node's workspace interfaces; ``name(key)`` gives the node-relative names."""

    def __init__(self, node: Any, name: Callable[[str], str]) -> None:
        self._node = node
        # the clouds: published by the worker process (ros/clouds.py), recorded here
        topics = {
            int(kind): node.resolve_topic_name(name(topic))
            for kind, topic in (
                (WorkspaceKind.ORIENTATION, "orientation_workspace"),
                (WorkspaceKind.PROJECTED_TORSION_ZERO, "projected_workspace"),
                (WorkspaceKind.PROJECTED_EXACT, "projected_workspace"),
            )
        }
        cloud_qos = qos_profile_text(durability="transient_local", depth=1)
        for topic in set(topics.values()):
            node.recorder.add_channel(topic, type_name(PointCloud2), cloud_qos)
        node.worker.cloud_topics = CloudTopics(
            node.get_name(), node.get_namespace(), topics, node.context.get_domain_id()
        )
        self.jobs = JobQueue(
            node.worker,
            self._finish_job,
            self._fail_job,
            lambda cloud: node.recorder.write_serialized(
                cloud.topic, cloud.data, cloud.log_time_ns
            ),
        )
        self._summary_publisher = node.recorded_publisher(
            WorkspaceSummary, name("workspace_summary")
        )
        node.recorded_service(
            Trigger, name("compute_orientation_workspace"), self._on_compute_orientation
        )
        node.recorded_service(
            Trigger, name("compute_projected_workspace"), self._on_compute_projected
        )
        self._requests = node.recorded_subscription(
            WorkspaceRequest, name("workspace_request"), self._on_workspace_request
        )
        self._action_topics = node.record_service_channels(
            ComputeWorkspaceRecord, name("compute_workspace")
        )
        self._goal_tickets: dict[bytes, Ticket] = {}
        self._action = ActionServer(
            node,
            ComputeWorkspace,
            name("compute_workspace"),
            execute_callback=self._execute_goal,
            goal_callback=lambda goal: GoalResponse.ACCEPT,
            cancel_callback=self._cancel_goal,
            callback_group=node.job_group,
            feedback_pub_qos_profile=FEEDBACK_QOS_PROFILE,
        )

    def stop(self) -> None:
        """Cancel the queued and running jobs and end the queue's thread."""
        self.jobs.stop()

    def job(self, request: WorkspaceRequest) -> WorkspaceJob | _Failed:
        """The job of a request with the node's parameters filled in, or why it is refused."""
        inactive = self._node.inactive_reason()
        if inactive is not None:  # not active (lifecycle): refused, never silence
            return _Failed(inactive)
        try:
            require_geometric(self._node.state, "a workspace")
        except InputError as error:
            return _Failed(str(error))
        settings = self._node.state.settings
        base = self._node.state.manipulator.frame_id
        if request.header.frame_id not in ("", base):
            # Boundaries are T&T angles about the base frame's axes at a base-frame position:
            # a request in another frame (the work frame included) would be answered for
            # another point and other axes than the ones meant.
            return _Failed(
                f"header.frame_id: workspaces are computed in the base frame {base!r} (or ''), "
                f"got {request.header.frame_id!r}"
            )
        kind, position = int(request.kind), position_from_point(request.position)
        if WorkspaceKind.of(kind) is None:
            return _Failed(
                f"kind: expected 0 (orientation), 1 (torsion_zero) or 2 (exact), got {kind}"
            )
        if not np.all(np.isfinite(position)):
            return _Failed(f"position: expected finite values, got {position.tolist()}")
        for name in ("psi_step", "tolerance"):
            value = float(getattr(request, name))
            if not np.isfinite(value) or value < 0.0:
                return _Failed(
                    f"{name}: expected a finite value >= 0 (0 = node parameter), got {value}"
                )
        default_rays = settings.n_rays if kind == WorkspaceKind.ORIENTATION else settings.n_phi
        rays = int(request.n_rays) or default_rays
        if not RAYS_RANGE[0] <= rays <= RAYS_RANGE[1]:
            return _Failed(f"n_rays: expected {RAYS_RANGE[0]}..{RAYS_RANGE[1]}, got {rays}", rays)
        return WorkspaceJob(
            manipulator=self._node.state.manipulator,
            kind=kind,
            position=position,
            n_rays=rays,
            psi_step=float(request.psi_step) or settings.psi_step,
            tolerance=float(request.tolerance) or settings.tolerance,
            stamp_ns=self._node._now_ns(),
            frame_id=self._node.state.manipulator.frame_id,
            request_id=request.request_id,
            result_points=RESULT_MAX_POINTS,
            frames=cell_frames_fields(self._node.state.cell),
            record=settings.recording_enabled,
            record_points=settings.recording_cloud_points,
        )

    def _submit(self, request: WorkspaceRequest, **callbacks: Any) -> Ticket | None:
        """Queue the job of ``request``; a refused request publishes its failure (None)."""
        job = self.job(request)
        if isinstance(job, _Failed):
            self._publish_failure(job.reason, request, n_rays=job.n_rays)
            return None
        return self.jobs.submit(Ticket(job, **callbacks))

    def _finish_job(self, job: WorkspaceJob, fields: Any) -> tuple[Any, Any]:
        """Job thread: the worker's fields -> published (and recorded) summary, and the
        action's bounded cloud (the worker published the full one)."""
        summary_fields, cloud_fields = fields
        if job.frames is not None:
            summary_fields = {**summary_fields, "frames": job.frames}
        cloud = to_message(PointCloud2, cloud_fields)
        summary = to_message(WorkspaceSummary, summary_fields)
        self._node.publish(self._summary_publisher, summary)
        self._node.get_logger().info(summary.message)
        return summary, cloud

    def _fail_job(self, job: WorkspaceJob, error: BaseException) -> tuple[Any, Any]:
        """Job thread: a failed or canceled job -> published failure summary (and cloud)."""
        if isinstance(error, CanceledError):
            reason = "canceled"
        elif isinstance(error, (InputError, UnreachableReferenceError)):
            reason = str(error)
        else:
            reason = self._node.internal_error(error)
        return self._publish_failure(
            reason,
            job,
            n_rays=job.n_rays,
            tolerance=job.tolerance,
            reference_reachable=not isinstance(error, UnreachableReferenceError),
        )

    def _publish_failure(
        self,
        reason: str,
        origin: WorkspaceRequest | WorkspaceJob,
        *,
        n_rays: int = 0,
        tolerance: float = float("nan"),
        reference_reachable: bool = True,
    ) -> tuple[Any, Any]:
        """Publish (and return) the summary of a failed computation; return an empty cloud.

        Only the summary is published: the transient-local cloud topics keep the last boundary
        that was computed, for a late subscriber (RViz, a dashboard); the failure's summary, with
        its request's ``kind`` as given and ``reference_reachable`` false for an empty
        workspace, says what happened. The empty cloud goes to the action's result only.
        """
        if isinstance(origin, WorkspaceJob):
            position, stamp_ns, kind = origin.position, origin.stamp_ns, origin.kind
        else:
            position, stamp_ns = position_from_point(origin.position), self._node._now_ns()
            kind = int(origin.kind)  # as requested, even when unknown (7 is not orientation)
        state = self._node.state
        frame_id = state.manipulator.frame_id if state is not None else ""
        fields = messages.summary_fields(
            None,
            message=reason,
            reference_reachable=reference_reachable,
            n_rays=n_rays,
            tolerance=tolerance,
            stamp_ns=stamp_ns,
            frame_id=frame_id,
            request_id=origin.request_id,
            kind=kind,
            position=position,  # as requested: NaN stays NaN (replay shows it)
        )
        if isinstance(origin, WorkspaceJob) and origin.frames is not None:
            fields["frames"] = origin.frames
        elif state is not None:
            fields["frames"] = cell_frames_fields(state.cell)
        summary = to_message(WorkspaceSummary, fields)
        empty = messages.pointcloud_fields(np.zeros((0, 6)), frame_id=frame_id, stamp_ns=stamp_ns)
        cloud = to_message(PointCloud2, empty)
        self._node.publish(self._summary_publisher, summary)
        self._node.get_logger().warning(f"workspace request failed: {reason}")
        return summary, cloud

    def _on_workspace_request(self, request: WorkspaceRequest) -> None:
        self._node.recorder.write(self._requests.topic_name, request)
        self._submit(request)

    async def _trigger(self, kind: WorkspaceKind) -> Trigger.Response:
        request = WorkspaceRequest(kind=int(kind))
        position = self._node.state.manipulator.position
        request.position.x, request.position.y, request.position.z = map(float, position)
        summary, _ = await self._workspace(request)
        return Trigger.Response(success=summary.success, message=summary.message)

    async def _on_compute_orientation(self, request: Any, response: Any) -> Trigger.Response:
        return await self._trigger(WorkspaceKind.ORIENTATION)

    async def _on_compute_projected(self, request: Any, response: Any) -> Trigger.Response:
        return await self._trigger(
            WorkspaceKind.projected(self._node.state.settings.projected_method)
        )

    async def _workspace(
        self,
        request: WorkspaceRequest,
        register: Callable[[Ticket], object] | None = None,
        **callbacks: Any,
    ) -> tuple[Any, Any]:
        """Queue ``request``, await its (summary, cloud) without holding the executor; a
        refused request answers at once. ``register(ticket)`` runs before the first wait."""
        job = self.job(request)
        if isinstance(job, _Failed):
            return self._publish_failure(job.reason, request, n_rays=job.n_rays)
        future, complete = completion(self._node)
        ticket = self.jobs.submit(
            Ticket(job, on_done=lambda done: complete(done.outcome), **callbacks)
        )
        if register is not None:
            register(ticket)
        return await future

    # ------------------------------------------------------------------ action
    def _cancel_goal(self, goal_handle: Any) -> CancelResponse:
        ticket = self._goal_tickets.get(bytes(goal_handle.goal_id.uuid))
        if ticket is not None:
            self.jobs.cancel(ticket)
        return CancelResponse.ACCEPT

    async def _execute_goal(self, goal_handle: Any) -> ComputeWorkspace.Result:
        request = goal_handle.request.request
        request_topic, response_topic = self._action_topics
        self._node.recorder.write(request_topic, ComputeWorkspaceRecord.Request(request=request))
        key = bytes(goal_handle.goal_id.uuid)

        def feedback(progress: float, stage: str) -> None:
            goal_handle.publish_feedback(ComputeWorkspace.Feedback(progress=progress, stage=stage))

        if goal_handle.is_cancel_requested:
            summary, cloud = self._publish_failure("canceled", request)
        else:
            feedback(0.0, "queued")
            summary, cloud = await self._workspace(
                request,
                lambda ticket: self._goal_tickets.__setitem__(key, ticket),
                on_progress=feedback,
            )
        self._goal_tickets.pop(key, None)
        fields = messages.compute_workspace_response_fields(
            None,
            stamp_ns=0,
            frame_id="",
            summary=summary,
            boundary=cloud,
        )
        result = to_message(ComputeWorkspace.Result, fields)
        self._node.recorder.write(
            response_topic, to_message(ComputeWorkspaceRecord.Response, fields)
        )
        if summary.success:
            goal_handle.succeed()
        elif goal_handle.is_cancel_requested:
            goal_handle.canceled()
        else:
            goal_handle.abort()
        return result
