"""Executed files: what a replay or check did, per control cycle, written as one ROS 2 bag."""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..types import ControllerStates, TfSamples
from . import messages as msgs
from .bag_writer import write_bag
from .definitions import CONTROLLER_STATE, schema_text
from .generic_cdr import encoder
from .jointstate_cdr import JOINT_STATE_TYPE, encode_joint_states
from .message_cdr import controller_states_cdr, tf_messages_cdr
from .plan_file import ROBOT_DESCRIPTION, STRING

__all__ = ["EXECUTION_RESULT_TOPIC", "ExecutedStep", "write_execution"]

EXECUTION_RESULT_TOPIC = "/moveplan/execution_result"
"""Topic of an executed file's result: a std_msgs/String holding the result JSON."""

_TF = "tf2_msgs/msg/TFMessage"


@dataclass(frozen=True)
class ExecutedStep:
    """One executed step as written: per control cycle the measured joint state and the controller's state.

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

    """
    state_topic = f"/{controller}/controller_state"
    # Channels exist even without messages (an execution refused before its first cycle),
    # so every executed file has the same topics and schemas.
    topics = {ROBOT_DESCRIPTION: (STRING, True)} if urdf else {}
    topics |= {"/joint_states": (JOINT_STATE_TYPE, False), state_topic: (CONTROLLER_STATE, False)}
    if tf is not None:
        topics["/tf"] = (_TF, False)
    # Latched: a late subscriber (a dashboard, `ros2 topic echo`) still gets the verdict.
    topics[EXECUTION_RESULT_TOPIC] = (STRING, True)
    schemas = {msgtype: schema_text(msgtype, distro) for msgtype, _ in topics.values()}
    string = encoder(STRING, schemas[STRING])

    messages: list[tuple[str, int, bytes]] = []
    if urdf:
        messages.append((ROBOT_DESCRIPTION, 0, string(msgs.string(urdf))))
    messages += _cycle_messages(steps, state_topic, distro)
    if tf is not None:
        tf_stamps = msgs.stamps_ns(tf.times_s).tolist()
        encoded = tf_messages_cdr(tf.parents, tf.children, tf.transforms, tf_stamps)
        messages += [("/tf", stamp, data) for stamp, data in zip(tf_stamps, encoded, strict=True)]
    messages.append((EXECUTION_RESULT_TOPIC, end_ns, string(msgs.string(json.dumps(document)))))
    # A stable sort: within a cycle the joint state comes before the controller state.
    messages.sort(key=lambda item: item[1])
    metadata = {key: json.dumps(value) for key, value in document.items()}
    write_bag(path, topics, schemas, messages, {"rosbag2": {"ROS_DISTRO": distro}, "moveplan_execution": metadata}, {})


def _cycle_messages(steps: Sequence[ExecutedStep], state_topic: str, distro: str) -> list[tuple[str, int, bytes]]:
    """Return (topic, log time [ns], CDR) of every cycle: its joint state, then its controller state."""
    messages: list[tuple[str, int, bytes]] = []
    for step in steps:
        stamps_ns = step.states.stamps_ns
        joint_states = encode_joint_states(step.joint_names, stamps_ns, step.positions, step.velocities)
        controller_states = controller_states_cdr(step.states, distro)
        for stamp, joint_state, state in zip(stamps_ns.tolist(), joint_states, controller_states, strict=True):
            messages += [("/joint_states", stamp, joint_state), (state_topic, stamp, state)]
    return messages
