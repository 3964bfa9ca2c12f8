"""The node as a managed (lifecycle) node: what each transition does to the workspace node.

``hexapod_workspace`` is an :class:`rclpy.lifecycle.LifecycleNode` (REP 2002 / the ROS 2
managed-node design): a launch system or an operator drives it with the standard
``lifecycle_msgs`` services ``~/change_state``, ``~/get_state``, ``~/get_available_states``,
``~/get_available_transitions`` (and ``~/transition_event``), the way drivers and other
hardware-facing nodes are brought up in order. Its interfaces (services, topics, actions) exist
from the start, so that a command never meets silence; what the state changes is how they
answer:

unconfigured
    Every command is answered ``success`` false, "inactive: ...". Parameters may be set freely
    (they are validated as a whole by *configure*). No log is open, no worker runs.
configure
    Validates the parameters as a whole and builds the manipulator model
    (:func:`~hexapod_workspace.ros.parameters.state_from`). A bad set leaves the node
    unconfigured, with the reason in the transition's log line and on ``/diagnostics`` (level
    ERROR); otherwise opens the MCAP log (``recording.enabled``), starts the worker process and
    loads the core's kernels. State *inactive*.
activate
    Starts serving: pose checks, commands, workspace and path requests. State *active*.
deactivate
    Stops taking work: the queued and running workspace jobs are canceled (their goals end
    CANCELED), and every command that still arrives is answered ``success`` false, "inactive:
    ..." (a ReachabilityResult per CommandedPose, a refusal per service call or goal), and
    recorded. State *inactive*.
cleanup, shutdown (and error processing)
    Cancel the jobs, end the worker process and finish the log (a playable file). Cleanup
    returns to *unconfigured*; shutdown to *finalized*: ``workspace_node`` then exits with
    status 0 :data:`FINALIZED_GRACE` s later (time for the ChangeState answer and the
    transition event to reach their readers; a command arriving meanwhile is answered
    "inactive"), as a finalized managed node has nothing left to do. A node built in another
    program (``exit_when_finalized`` False) stays, answering "inactive", until destroyed.

*Autostart* (default; ``workspace_node --autostart=false`` or the launch argument
``autostart:=false`` turn it off) runs configure and activate as the node starts, so today's
one-line start serves at once, and a bad parameters file still stops the process with exit
status 1 and the reason. Without autostart the node waits unconfigured for a ``configure``.
"""

from __future__ import annotations

from typing import Any

import rclpy
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.lifecycle import LifecycleState, TransitionCallbackReturn

from hexapod_workspace.core.base import jit
from hexapod_workspace.errors import ConfigError, InputError

from .parameters import state_from

#: What rclpy's lifecycle state machine raises for a transition the state does not allow.
RCLError = _rclpy.RCLError

__all__ = [
    "AUTOSTART_OPTION",
    "FINALIZED_GRACE",
    "INACTIVE",
    "ManagedTransitions",
    "autostart_from_argv",
]

#: The prefix of every answer given while the node is not active.
INACTIVE = "inactive"
#: Seconds between the shutdown transition and the end of ``workspace_node``'s process.
FINALIZED_GRACE = 0.5
#: Command-line option of ``workspace_node`` (before ``--ros-args``): ``--autostart=false``
#: leaves the node unconfigured at start (default ``true``).
AUTOSTART_OPTION = "--autostart"


def autostart_from_argv(argv: list[str]) -> tuple[bool, list[str]]:
    """Whether to autostart, and ``argv`` without the :data:`AUTOSTART_OPTION` (for
    ``rclpy.init``). Only arguments before ``--ros-args`` are looked at (the rest are ROS's).

    Raises
    ------
    ConfigError
        The option's value is not ``true`` or ``false``.
    """
    end = argv.index("--ros-args") if "--ros-args" in argv else len(argv)
    autostart, kept = True, []
    for index, argument in enumerate(argv):
        if index < end and argument.startswith(f"{AUTOSTART_OPTION}="):
            value = argument.split("=", 1)[1].strip().lower()
            if value not in ("true", "false"):
                msg = f"{AUTOSTART_OPTION}: expected true or false, got {value!r}"
                raise ConfigError(msg)
            autostart = value == "true"
        else:
            kept.append(argument)
    return autostart, kept


class ManagedTransitions:
    """The transition callbacks of the workspace node (mixed into
    :class:`~hexapod_workspace.ros.node.WorkspaceNode`, before ``LifecycleNode``).

    Uses the node's ``state``, ``worker``, ``jobs``, ``recorder``, ``_parameter_values``,
    and ``warm_up``.
    """

    #: True while the node serves (state *active*)
    active: bool = False
    #: why the last configure failed ("" when it did not)
    configure_error: str = ""
    #: end the node's context :data:`FINALIZED_GRACE` s after the shutdown transition, which
    #: ends ``workspace_node``'s spin (set by its ``main``; a node in another program stays)
    exit_when_finalized: bool = False

    # ------------------------------------------------------------------ queries
    @property
    def lifecycle_state(self) -> str:
        """The current state's label: unconfigured, inactive, active, finalized, or a
        transition's (configuring, ...)."""
        return str(self._state_machine.current_state[1])  # type: ignore[attr-defined]

    @property
    def configured(self) -> bool:
        """True in *inactive* and *active* (the parameters were validated and applied)."""
        return self.lifecycle_state in ("inactive", "active", "deactivating", "activating")

    def inactive_reason(self) -> str | None:
        """None while active; else the refusal every command gets, starting with "inactive"."""
        if self.active:
            return None
        state = self.lifecycle_state
        hint = "configure and activate it" if state == "unconfigured" else "activate it"
        if state in ("finalized", "shuttingdown"):
            hint = "it is shutting down"
        return f"{INACTIVE}: the node is {state} (lifecycle); {hint} to get verdicts"

    def guard_change_state(self) -> None:
        """Answer an impossible transition (``activate`` while unconfigured, an unknown id)
        ``success`` false with a warning: rclpy (Jazzy 7.1.6) raises RCLError from its
        ``~/change_state`` callback there, which ends the executor, and so the node."""
        service: Any = self._service_change_state  # type: ignore[attr-defined]
        handle = service.callback
        node: Any = self

        def change_state(request: Any, response: Any) -> Any:
            try:
                return handle(request, response)
            except RCLError as error:
                transition = request.transition.label or request.transition.id
                node.get_logger().warning(
                    f"transition {transition} refused in state {self.lifecycle_state}: {error}"
                )
                response.success = False
                return response

        service.callback = change_state

    # ------------------------------------------------------------------ autostart
    def autostart(self) -> None:
        """Configure and activate now (the node's one-line start).

        Raises
        ------
        ConfigError
            Configure failed: the parameters are invalid (the message names them).
        """
        if self.trigger_configure() != TransitionCallbackReturn.SUCCESS:  # type: ignore[attr-defined]
            raise ConfigError(self.configure_error or "configure failed")
        if self.trigger_activate() != TransitionCallbackReturn.SUCCESS:  # type: ignore[attr-defined]
            msg = "activate failed"
            raise ConfigError(msg)

    # ------------------------------------------------------------------ transitions
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        node: Any = self
        try:
            node.state = state_from(node._parameter_values())
        except (ConfigError, InputError) as error:
            self.configure_error = str(error)
            node.get_logger().error(f"configure failed, the node stays unconfigured: {error}")
            return TransitionCallbackReturn.FAILURE
        self.configure_error = ""
        settings = node.state.settings
        if settings.recording_enabled:
            node.recorder.open(settings.recording_directory, settings.recording_rotation)
        node.worker.start()  # it warms its own kernels up meanwhile
        seconds = node.warm_up()
        node.get_logger().info(
            f"configured: pose-check kernels ready in {seconds:.1f} s "
            f"(compiled-code cache: {jit.CACHE_DIRECTORY or 'none, nothing is writable'})"
        )
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        node: Any = self
        self.active = True
        node.get_logger().info(f"active; ready: {node.interfaces_line()}")
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        node: Any = self
        self.active = False
        canceled = node.jobs.cancel_all()
        node.get_logger().info(
            f"inactive: commands are answered '{INACTIVE}' ({canceled} workspace jobs canceled)"
        )
        return TransitionCallbackReturn.SUCCESS

    def _release(self, what: str) -> TransitionCallbackReturn:
        """Cancel the jobs, end the worker, finish the log."""
        node: Any = self
        self.active = False
        node.jobs.cancel_all()
        node.worker.close()
        node.recorder.close()
        node.get_logger().info(f"{what}: worker ended, log finished")
        return TransitionCallbackReturn.SUCCESS

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        return self._release("cleaned up (unconfigured)")

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        outcome = self._release("shut down (finalized)")
        if self.exit_when_finalized:
            node: Any = self
            node.get_logger().info(f"finalized: the process exits in {FINALIZED_GRACE:g} s")
            node.create_timer(FINALIZED_GRACE, lambda: rclpy.try_shutdown(context=node.context))
        return outcome

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        return self._release("error processed (unconfigured)")
