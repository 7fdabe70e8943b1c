"""Executed files: what a replay or check did, per control cycle, written as one ROS 2 bag.

The file is written while the execution runs (`execution_writer`): blocks of cycles and /tf
samples go in as they are produced, so memory does not grow with the execution's length.
"""

from __future__ import annotations

import json
import math
from bisect import bisect_left
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from operator import itemgetter
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..types import ControllerStates, TfSamples
from .cdr import (
    CONTROLLER_STATE,
    JOINT_STATE_TYPE,
    controller_states_cdr,
    encode_joint_states,
    encoder,
    schema_text,
    stamps_ns,
    string_message,
    tf_messages_cdr,
)
from .container import BagStream, open_bag
from .plan_file import ROBOT_DESCRIPTION, STRING

__all__ = ["EXECUTION_RESULT_TOPIC", "ExecutedStep", "ExecutionWriter", "execution_writer", "write_execution"]

EXECUTION_RESULT_TOPIC = "/moveplan/execution_result"
"""Topic of an executed file's result: a std_msgs/String holding the result JSON."""

_TF = "tf2_msgs/msg/TFMessage"

# At one log time the messages go in this order (then in the order they were added): the
# robot description, the cycles (joint state, then controller state), /tf, the result.
_DESCRIPTION, _CYCLES, _TF_SAMPLES, _RESULT = range(4)
_Pending = tuple[int, int, str, bytes]
_ORDER = itemgetter(0, 1)
_TIME = itemgetter(0)


@dataclass(frozen=True)
class ExecutedStep:
    """Executed cycles as written: per control cycle the measured joint state and the controller's state.

    A whole step, or a block of its cycles.

    Attributes:
        joint_names: Column order of `positions` and `velocities` (n).
        positions: Measured positions in [rad], shape (K, n).
        velocities: Measured velocities in [rad]/[s], shape (K, n).
        states: The controller's state per cycle, stamped on the execution's timeline.
    """

    joint_names: tuple[str, ...]
    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    states: ControllerStates


class ExecutionWriter:
    """An executed file being written (`execution_writer`): cycles and /tf as they come, then the result.

    Each message is written as soon as nothing still to come can precede it: the cycles and
    the /tf samples are each added in log-time order, so only messages at or after the last
    time of either wait. The file is the one that sorting every message by log time would
    give (at equal times: robot description, cycles, /tf, result, each in the order added).
    """

    def __init__(self, bag: BagStream, state_topic: str, distro: str, tf: bool) -> None:
        self._bag = bag
        self._state_topic = state_topic
        self._distro = distro
        self._string = encoder(STRING, schema_text(STRING, distro))
        self._pending: list[_Pending] = []
        # Per stream, the log time [ns] no message still to come precedes (None: no such stream).
        self._next: dict[int, int | None] = {_CYCLES: 0, _TF_SAMPLES: 0 if tf else None}
        self._written_until = 0
        self.finished = False

    def add_description(self, urdf: str) -> None:
        """Add /robot_description at log time 0; return None."""
        self._pending.append((0, _DESCRIPTION, ROBOT_DESCRIPTION, self._string(string_message(urdf))))

    def add_cycles(self, cycles: ExecutedStep) -> None:
        """Add cycles: per cycle its /joint_states, then its controller state; return None.

        Blocks come in log-time order; add a step's /tf before its cycles, so that the cycles
        are written as they come.

        Raises:
            ValueError: The block's log times go back.

        """
        stamps_ns = cycles.states.stamps_ns
        if not len(stamps_ns):
            return
        self._advance(_CYCLES, stamps_ns)
        joint_states = encode_joint_states(cycles.joint_names, stamps_ns, cycles.positions, cycles.velocities)
        states = controller_states_cdr(cycles.states, self._distro)
        topic = self._state_topic
        for stamp, joint_state, state in zip(stamps_ns.tolist(), joint_states, states, strict=True):
            self._pending += [(stamp, _CYCLES, "/joint_states", joint_state), (stamp, _CYCLES, topic, state)]
        self._flush()

    def add_tf(self, tf: TfSamples) -> None:
        """Add /tf samples (times on the execution's timeline), in log-time order; return None.

        Raises:
            ValueError: The writer was opened without /tf, or the samples' log times go back.

        """
        if self._next[_TF_SAMPLES] is None:
            raise ValueError("this executed file was opened without /tf")
        times_ns = stamps_ns(tf.times_s)
        if not len(times_ns):
            return
        self._advance(_TF_SAMPLES, times_ns)
        stamps = times_ns.tolist()
        encoded = tf_messages_cdr(tf.parents, tf.children, tf.poses, stamps)
        self._pending += [(stamp, _TF_SAMPLES, "/tf", data) for stamp, data in zip(stamps, encoded, strict=True)]
        self._flush()

    def finish(self, document: dict[str, Any], end_ns: int) -> None:
        """Add the result `document` at `end_ns` [ns] and as metadata, and write what waits; return None.

        Raises:
            ValueError: A message already written lies after `end_ns`.

        """
        if end_ns < self._written_until:
            raise ValueError(f"the result at {end_ns} ns would precede messages written up to {self._written_until} ns")
        result = self._string(string_message(json.dumps(document)))
        self._pending.append((end_ns, _RESULT, EXECUTION_RESULT_TOPIC, result))
        self._flush(final=True)
        self._bag.add_metadata("rosbag2", {"ROS_DISTRO": self._distro})
        self._bag.add_metadata("moveplan_execution", {key: json.dumps(value) for key, value in document.items()})
        self.finished = True

    def _advance(self, stream: int, stamps_ns: NDArray[np.int64]) -> None:
        """Record that `stream` continues at `stamps_ns`; raise ValueError if they go back."""
        floor = self._next[stream]
        assert floor is not None
        if stamps_ns[0] < floor or np.any(np.diff(stamps_ns) < 0):
            raise ValueError(f"executed file: log times go back (at {int(stamps_ns[0])} ns, after {floor} ns); "
                             "add steps in order")
        self._next[stream] = int(stamps_ns[-1])

    def _flush(self, final: bool = False) -> None:
        """Write, in order, the waiting messages that nothing still to come can precede."""
        # Stable, and the waiting messages are sorted runs: a merge, not a full sort.
        self._pending.sort(key=_ORDER)
        floor = math.inf if final else min(t for t in self._next.values() if t is not None)
        ready = len(self._pending) if final else bisect_left(self._pending, floor, key=_TIME)
        add = self._bag.add
        for stamp, _, topic, data in self._pending[:ready]:
            add(topic, stamp, data)
        if ready:
            self._written_until = self._pending[ready - 1][0]
        del self._pending[:ready]


@contextmanager
def execution_writer(
    path: Path, *, controller: str, urdf: str = "", distro: str = "jazzy", tf: bool = False
) -> Iterator[ExecutionWriter]:
    """Yield an executed file for `distro` being written to `path`; it is renamed into place when the block ends.

    Channels: /robot_description (with `urdf`, which is added at once), /joint_states and
    /<controller>/controller_state (JointTrajectoryControllerState in the layout of
    `distro`) per control cycle, /tf if `tf`, and the result. The block must end with
    `finish`; on any error the file is not written (bag_writer.atomic_file).

    Raises:
        UsageError: `distro` has no shipped message definitions, or `path` cannot be an
            output file (a directory, a symbolic link, a device: bag_writer.output_problem).
        InputError: `path` cannot be written (missing or read-only folder, full disk).
        RuntimeError: The block ended without `finish`.

    """
    state_topic = f"/{controller}/controller_state"
    # Channels exist even without messages (an execution refused before its first cycle),
    # so every executed file has the same topics and schemas.
    topics = {ROBOT_DESCRIPTION: (STRING, True)} if urdf else {}
    topics |= {"/joint_states": (JOINT_STATE_TYPE, False), state_topic: (CONTROLLER_STATE, False)}
    if tf:
        topics["/tf"] = (_TF, False)
    # Latched: a late subscriber (a dashboard, `ros2 topic echo`) still gets the verdict.
    topics[EXECUTION_RESULT_TOPIC] = (STRING, True)
    schemas = {msgtype: schema_text(msgtype, distro) for msgtype, _ in topics.values()}
    with open_bag(path, topics, schemas) as bag:
        writer = ExecutionWriter(bag, state_topic, distro, tf)
        if urdf:
            writer.add_description(urdf)
        yield writer
        if not writer.finished:
            raise RuntimeError("executed file left without its result: call finish()")


def write_execution(
    path: Path,
    steps: Sequence[ExecutedStep],
    document: dict[str, Any],
    end_ns: int,
    *,
    controller: str,
    urdf: str = "",
    distro: str = "jazzy",
    tf: TfSamples | None = None,
) -> None:
    """Write an execution to `path` as a ROS 2 bag for `distro`, atomically; return None.

    Per control cycle: /joint_states (measured state) and /<controller>/controller_state
    (JointTrajectoryControllerState in the layout of `distro`). Once: /robot_description
    (`urdf`, if given) and the result `document` as JSON, on EXECUTION_RESULT_TOPIC at
    `end_ns` and in the metadata record "moveplan_execution" (one JSON value per key). /tf
    only if `tf` is given (times on the execution's timeline). No steps write no cycles.

    Raises:
        UsageError: `distro` has no shipped message definitions, or `path` cannot be an
            output file (a directory, a symbolic link, a device: bag_writer.output_problem).
        InputError: `path` cannot be written (missing or read-only folder, full disk).
        ValueError: The steps' log times go back (steps out of order).

    """
    with execution_writer(path, controller=controller, urdf=urdf, distro=distro, tf=tf is not None) as writer:
        if tf is not None:
            writer.add_tf(tf)
        for step in steps:
            writer.add_cycles(step)
        writer.finish(document, end_ns)
