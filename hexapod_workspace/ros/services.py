"""A node service whose calls are recorded: the request, then the response, in the node's log.

:class:`RecordedService` is the wiring ``~/schedule_path`` and ``~/loads`` share: the service
under its node-relative name from :mod:`hexapod_workspace.logs.interfaces`, a reentrant
callback group, the services QoS, and both halves of every call written to the recorder as the
message twins the logs use (:func:`hexapod_workspace.logs.recorded_type`). The answer is a
function of the node's state and the request returning the response's fields; a
:class:`~hexapod_workspace.errors.HexapodWorkspaceError` (an inactive node) or any other error
becomes ``success: false`` with the reason, and the node keeps serving.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rclpy.callback_groups import ReentrantCallbackGroup

from ..errors import HexapodWorkspaceError
from ..logs import SERVICE_QOS, recorded_type, service_topics
from ..logs.interfaces import interface, relative_name
from .conversions import to_message
from .parameters import State
from .qos import SERVICE_QOS_PROFILE

__all__ = ["RecordedService"]


class RecordedService:
    """One recorded service on a node.

    Parameters
    ----------
    node : rclpy.node.Node
    service_type : type
        The generated service class (``hexapod_workspace_msgs.srv.Loads``).
    key : str
        Its row in :data:`~hexapod_workspace.logs.interfaces.INTERFACES` (``"loads"``).
    answer : callable
        ``answer(state, request)`` -> the response's fields (a dict).
    get_state : callable
        Returns the node's configured state (``InputError`` while inactive).
    recorder : object, optional
        The node's MCAP recorder (``add_channel``, ``write``).
    """

    def __init__(
        self,
        node: Any,
        service_type: Any,
        key: str,
        answer: Callable[[State, Any], dict[str, Any]],
        get_state: Callable[[], State],
        recorder: Any | None = None,
    ) -> None:
        self._node = node
        self._type = service_type
        self._key = key
        self._answer = answer
        self._get_state = get_state
        self._recorder = recorder
        name = relative_name(key)
        self.service = node.create_service(
            service_type,
            name,
            self._on_request,
            qos_profile=SERVICE_QOS_PROFILE,
            callback_group=ReentrantCallbackGroup(),
        )
        self._topics = service_topics(node.resolve_service_name(name))
        if recorder is not None:
            for topic, part in zip(self._topics, ("Request", "Response"), strict=True):
                recorded = recorded_type(f"{interface(key).type}_{part}")
                recorder.add_channel(topic, recorded, SERVICE_QOS)

    def _on_request(self, request: Any, response: Any) -> Any:
        self._record(self._topics[0], request)
        try:
            fields = self._answer(self._get_state(), request)
        except HexapodWorkspaceError as error:  # inactive: the reason goes back
            fields = {"success": False, "message": str(error)}
        except Exception as error:  # keep serving; the reason goes back to the caller
            self._node.get_logger().error(f"{self._key}: internal error: {error!r}")
            fields = {"success": False, "message": f"internal error: {error}"}
        response = to_message(self._type.Response, fields)
        self._record(self._topics[1], response)
        return response

    def _record(self, topic: str, message: Any) -> None:
        if self._recorder is not None:
            self._recorder.write(topic, message)
