"""Node services answered by a function of the node's state and the request.

:func:`fields_service` is the wiring ``~/schedule_path`` and ``~/loads`` share, on the node's
own :meth:`~hexapod_workspace.ros.node.WorkspaceNode.recorded_service` (both halves of every
call recorded, the "inactive: ..." refusal while the node is not active): the answer is
``fields_of(state, request)``, the response's fields; an unexpected error becomes
``success: false`` with the reason
(:meth:`~hexapod_workspace.ros.node.WorkspaceNode.internal_error`), and the node keeps serving.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..logs.interfaces import relative_name
from .conversions import to_message
from .parameters import State

__all__ = ["fields_service"]


def fields_service(
    node: Any,
    service_class: Any,
    key: str,
    fields_of: Callable[[State, Any], dict[str, Any]],
) -> Any:
    """Create the recorded service ``~/<key>`` (its row in
    :data:`~hexapod_workspace.logs.interfaces.INTERFACES`) of ``service_class`` on ``node``,
    answered by ``fields_of(node.configured_state, request)``, in the node's check callback
    group (reentrant)."""

    def answer(request: Any, response: Any) -> Any:
        try:
            fields = fields_of(node.configured_state, request)
        except Exception as error:  # a bug: answered, never silence
            fields = {"success": False, "message": node.internal_error(error)}
        return to_message(service_class.Response, fields)

    return node.recorded_service(service_class, relative_name(key), answer, node.check_group)
