"""The CommandedPose stream: every command gets exactly one ReachabilityResult.

The subscription is reliable KEEP_ALL (:data:`~hexapod_workspace.ros.qos.COMMAND_QOS`): DDS
never drops a command on the node's side. When the executor hands over one command, the callback
also takes the commands that arrived since (up to :data:`BATCH`) from the same subscription, as
the executor would, one after the other, and answers them together: one pass of the executor per
batch instead of per command, and one vectorised ``check`` per distinct position. The results
are published in the order the commands arrived.

A command whose header stamp is older than ``check.max_command_age`` when its turn comes is
answered ``success`` false, "overloaded: ..." (counted), not checked: a verdict that late is of
no use to a controller, and skipping the check lets the node catch up. Commands with a zero
stamp are always checked.

A command's ``header.frame_id`` names the frame of its pose: the base frame (or ``""``) or the
work frame, converted here (:func:`hexapod_workspace.ros.cell.angles_to_base`); any other is
refused with the reason. The result echoes the pose in the base frame and says with ``frames``
which tool and work frame it was computed with.
"""

from __future__ import annotations

import contextlib
from typing import Any

import numpy as np
from hexapod_workspace_msgs.msg import CommandedPose, ReachabilityResult
from numpy.typing import NDArray
from rclpy.exceptions import InvalidHandle
from rclpy.serialization import deserialize_message

from hexapod_workspace.core.constraints.table import constraint_names
from hexapod_workspace.core.evaluation.check import check
from hexapod_workspace.errors import InputError
from hexapod_workspace.logs import messages

from .cell import angles_to_base, frames_message
from .conversions import to_message
from .load_rows import load_rows_of, with_load_rows
from .paths import commanded_target

__all__ = ["BATCH", "CommandStream"]

#: Most commands answered in one callback.
BATCH = 256
#: Batches up to this size are grouped by position without numpy.unique.
_SMALL_BATCH = 16


def _same_position(
    positions: NDArray[np.float64], todo: NDArray[np.int_]
) -> list[tuple[NDArray[np.float64], NDArray[np.int_]]]:
    """The commands ``todo`` (indices into ``positions``, (N, 3) m) grouped by position: one
    check per group. At 1 kHz a batch is mostly one command, and ``numpy.unique`` over rows
    costs about 25 µs of the node's few hundred per command: small batches are grouped in a
    dict (insertion order; the order of the groups does not change any verdict)."""
    if todo.size <= _SMALL_BATCH:
        groups: dict[tuple[float, ...], list[int]] = {}
        for k in todo.tolist():
            groups.setdefault(tuple(positions[k].tolist()), []).append(k)
        return [(np.array(key), np.array(members, dtype=int)) for key, members in groups.items()]
    keys, inverse = np.unique(positions[todo], axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    return [(keys[g], todo[inverse == g]) for g in range(keys.shape[0])]


class CommandStream:
    """Answers the commands of ``subscription`` on ``publisher`` for ``node``."""

    def __init__(self, node: Any, subscription: Any, publisher: Any) -> None:
        self._node = node
        self._subscription = subscription
        self._publisher = publisher

    def on_command(self, data: bytes) -> None:
        """Subscription callback (raw: the CDR bytes of a command): answer it and the commands
        queued behind it. Each is taken as bytes, recorded as such and deserialised once (a
        taken message would be serialised again for the log)."""
        raw = [data]
        handle = self._subscription.handle
        with contextlib.suppress(InvalidHandle), handle:
            while len(raw) < BATCH:
                taken = handle.take_message(CommandedPose, True)
                if taken is None:
                    break
                raw.append(taken[0])
        self.answer([deserialize_message(item, CommandedPose) for item in raw], raw)

    def answer(self, batch: list[CommandedPose], raw: list[bytes] | None = None) -> None:
        """Record and answer ``batch`` (``raw``: the same commands' CDR bytes, recorded as they
        are; without them the commands are serialised for the log)."""
        node, stats = self._node, self._node.stats
        stats.commands_received += len(batch)
        topic = self._subscription.topic_name
        if raw is not None:
            for data in raw:
                node.recorder.write_serialized(topic, data)
        else:
            for command in batch:
                node.recorder.write(topic, command)
        state = node.state
        now_ns = node.get_clock().now().nanoseconds
        inactive = node.inactive_reason()
        if inactive is not None:  # not active (lifecycle): every command gets the refusal
            self._refuse_all(batch, inactive, now_ns, state)
            return
        limit_ns = state.settings.max_command_age * 1e9
        positions = np.full((len(batch), 3), np.nan)
        angles = np.full((len(batch), 3), np.nan)
        verdicts: dict[int, tuple[Any, int, str | None]] = {}
        for k, command in enumerate(batch):
            try:  # T&T, or a geometry_msgs/Pose converted (hexapod_workspace.ros.paths)
                position, target = commanded_target(command)
                target, position = angles_to_base(state, command.header.frame_id, target, position)
            except InputError as error:
                stats.commands_refused += 1
                verdicts[k] = (None, 0, str(error))
                continue
            positions[k], angles[k] = position, target[0]
        sent_ns = np.array(
            [c.header.stamp.sec * 1_000_000_000 + c.header.stamp.nanosec for c in batch]
        )
        late = (sent_ns > 0) & (limit_ns > 0) & (now_ns - sent_ns > limit_ns)
        late[list(verdicts)] = False  # refused already
        limit = state.settings.max_command_age
        for k in np.flatnonzero(late):
            age = (now_ns - sent_ns[k]) * 1e-9
            stale = f"overloaded: command {age:.3f} s old when its turn came (limit {limit:g} s)"
            verdicts[int(k)] = (None, 0, stale)
        stats.commands_overloaded += int(late.sum())
        todo = np.array([k for k in np.flatnonzero(~late) if k not in verdicts], dtype=int)
        for position, members in _same_position(positions, todo):
            self._check_group(state, position, angles, members, verdicts)
        names = constraint_names(state.manipulator)
        # the PoseCheck fields of each check, computed once for all its poses: one pose's
        # fields read properties computed for the whole result, so a batch answered pose by
        # pose would cost its size squared, and the further behind the node, the slower it
        # would answer
        checks: dict[int, list[dict[str, Any]]] = {}
        for k, command in enumerate(batch):
            result, index, reason = verdicts[k]
            if result is not None and id(result) not in checks:  # with the loads rows set
                rows = load_rows_of(state, result.position, angles=result.angles)
                checks[id(result)] = with_load_rows(messages.pose_checks_fields(result), rows)
            fields = messages.reachability_result_fields(
                result,
                index=index,
                message=reason,
                check=None if result is None else checks[id(result)][index],
                position=positions[k],
                angles=angles[k],
                stamp_ns=now_ns,
                frame_id=state.manipulator.frame_id,
                request_id=command.request_id,
                names=names,
            )
            if result is not None and node.paths is not None:  # the move from the current pose
                fields = node.paths.with_motion(
                    fields, state.manipulator, positions[k], angles[k][None, :]
                )
            fields["frames"] = frames_message(state, command.header.frame_id)
            node.publish(self._publisher, to_message(ReachabilityResult, fields))
        stats.commands_answered += len(batch)

    def _refuse_all(self, batch: list[CommandedPose], reason: str, now_ns: int, state: Any) -> None:
        """Answer every command of ``batch`` ``success`` false with ``reason``."""
        frame_id = state.manipulator.frame_id if state is not None else ""
        names = constraint_names(state.manipulator) if state is not None else ()
        for command in batch:
            try:
                position, target = commanded_target(command)
                angles = target[0]
            except InputError:
                position, angles = np.full(3, np.nan), np.full(3, np.nan)
            fields = messages.reachability_result_fields(
                None,
                index=0,
                message=reason,
                position=position,
                angles=angles,
                stamp_ns=now_ns,
                frame_id=frame_id,
                request_id=command.request_id,
                names=names,
            )
            self._node.publish(self._publisher, to_message(ReachabilityResult, fields))
        self._node.stats.commands_refused += len(batch)
        self._node.stats.commands_answered += len(batch)

    def _check_group(
        self, state: Any, position: Any, angles: Any, members: Any, verdicts: dict
    ) -> None:
        """One check for the commands ``members`` at ``position``; one by one if it fails."""
        try:
            result = check(
                state.manipulator,
                angles[members],
                position,
                singularity=state.settings.report_singularity,
            )
        except InputError as error:
            if members.size > 1:  # find the invalid one(s)
                for k in members:
                    self._check_group(state, position, angles, np.array([k]), verdicts)
                return
            self._node.stats.commands_refused += 1
            verdicts[int(members[0])] = (None, 0, str(error))
            return
        except Exception as error:  # a bug: every command still gets its answer
            for k in members:
                self._node.stats.commands_refused += 1
                verdicts[int(k)] = (None, 0, self._node.internal_error(error))
            return
        for index, k in enumerate(members):
            verdicts[int(k)] = (result, index, None)
