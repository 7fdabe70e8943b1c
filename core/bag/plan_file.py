"""Plan files: their layout (topics, types, metadata keys; docs/formats.md), and plans read back.

A plan file is a ROS 2 bag: /robot_description, /tf_static, /planning_scene_markers and
/display_planned_path once and latched, one /planned_trajectory message per step at the
step's start, /tf along the plan; a "moveplan" metadata record (robot, group, frame, step
names, limits, distro) and the robot's config files as attachments.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from mcap.records import Channel, Schema
from mcap_ros2._vendor.rosidl_adapter.parser import InvalidSpecification, InvalidValue
from mcap_ros2.decoder import DecoderFactory

from ..errors import InputError
from ..types import GoalTolerances, JointTolerance, JointTrajectory
from .cdr import trajectory_from_message
from .container import DAMAGE, Contents, Kept, Skips, open_mcap, scan, verify_mcap

__all__ = [
    "END_STATES_KEY",
    "PLAN_TOPICS",
    "ROBOT_DESCRIPTION",
    "STRING",
    "TRAJECTORY",
    "PlanFile",
    "PlanStepRecord",
    "plan_urdf",
    "read_plan",
]

STRING = "std_msgs/msg/String"
TRAJECTORY = "/planned_trajectory"
ROBOT_DESCRIPTION = "/robot_description"
# topic -> (message type, latched). Latched topics are offered transient_local, so a late
# subscriber (RViz, robot_state_publisher) still gets them from `ros2 bag play`. The
# trajectory stays volatile: a controller that joins late must not receive a stale step.
PLAN_TOPICS: dict[str, tuple[str, bool]] = {
    ROBOT_DESCRIPTION: (STRING, True),
    "/tf_static": ("tf2_msgs/msg/TFMessage", True),
    "/planning_scene_markers": ("visualization_msgs/msg/MarkerArray", True),
    "/display_planned_path": ("moveit_msgs/msg/DisplayTrajectory", True),
    TRAJECTORY: ("trajectory_msgs/msg/JointTrajectory", False),
    "/tf": ("tf2_msgs/msg/TFMessage", False),
}
"""Every topic a plan file may hold, in channel order: topic -> (message type, latched)."""

PLAN_KEYS = ("robot_name", "group", "planning_frame", "step_names", "limits", "distro")
"""The keys moveplan itself writes into a plan's "moveplan" metadata record."""

END_STATES_KEY = "end_states"
"""The "moveplan" metadata key under which a plan records where each step ends: a JSON list, one
{"joints", "pose"} per step (RobotState.as_dict), read by `inspect` without loading the robot."""

_UNREADABLE = (*DAMAGE, TypeError, IndexError, AttributeError, KeyError, RecursionError)
# What parsing a ros2msg schema raises on text that is no valid definition (mcap_ros2's vendored
# rosidl parser), besides _UNREADABLE's (McapError, ValueError: UnicodeDecodeError among them).
_BAD_SCHEMA = (*_UNREADABLE, InvalidSpecification, InvalidValue)


@dataclass(frozen=True)
class PlanStepRecord:
    """One step read back from a plan file: name, start on the plan's timeline in [s], motion, goal tolerances."""

    name: str
    start_s: float
    trajectory: JointTrajectory
    tolerances: GoalTolerances | None = None
    scaling: tuple[float, float] | None = None  # the velocity and acceleration scaling its timing used


@dataclass(frozen=True)
class PlanFile:
    """A plan read back from an MCAP file: its steps plus what execute and checks need.

    `urdf` is the text of the file's /robot_description, "" if it has none.
    """

    robot_name: str
    group: str
    planning_frame: str
    distro: str
    steps: tuple[PlanStepRecord, ...]
    attachments: dict[str, bytes]
    metadata: dict[str, str]
    limits: dict[str, dict[str, float]]
    urdf: str = ""


def read_plan(path: Path) -> PlanFile:
    """Return the plan stored in the moveplan MCAP file at `path`.

    Raises:
        InputError: The file is missing, not MCAP, truncated, corrupt (a chunk, attachment or
            section failing its CRC or size checks) or not a moveplan plan.

    """
    with open_mcap(path) as stream:
        # Checked whole first: the mcap package would unpack a chunk to whatever size its frame claims.
        verify_mcap(path, stream, stream.seek(0, 2), Skips())
        contents = scan(path, stream, keep_topics=(TRAJECTORY, ROBOT_DESCRIPTION))
    info = next((m.metadata for m in contents.metadata if m.name == "moveplan"), {})
    if any(key not in info for key in PLAN_KEYS):
        raise InputError(f"{path}: not a moveplan plan file (no complete 'moveplan' metadata)")
    try:
        step_names = [str(name) for name in json.loads(info["step_names"])]
        limits = _limits(json.loads(info["limits"]))
        tolerances = _tolerances(info.get("step_tolerances"), len(step_names))
        scalings = _scalings(info.get("step_scaling"), len(step_names))
    except (ValueError, TypeError, AttributeError, KeyError, IndexError) as exc:
        raise InputError(f"{path}: 'moveplan' metadata is malformed: {exc}") from exc
    factory = DecoderFactory()
    descriptions = [item for item in contents.kept if item[0].topic == ROBOT_DESCRIPTION]
    return PlanFile(
        robot_name=info["robot_name"],
        group=info["group"],
        planning_frame=info["planning_frame"],
        distro=info["distro"],
        steps=tuple(replace(step, tolerances=tolerance, scaling=scaling) for step, tolerance, scaling
                    in zip(_steps(path, factory, contents, step_names), tolerances, scalings, strict=True)),
        attachments={attachment.name: attachment.data for attachment in contents.attachments},
        metadata={key: value for key, value in info.items() if key not in PLAN_KEYS},
        limits=limits,
        urdf=_robot_description(path, factory, descriptions),
    )


def _limits(parsed: object) -> dict[str, dict[str, float]]:
    """Return the "limits" metadata value `parsed` (JSON) as floats, checked as plan_writer writes them.

    Raises:
        ValueError: It is no object of joints, each an object of numbers; or a joint's lower
            limit is above its upper one, or its max_velocity or max_acceleration is missing or
            not a positive finite number.

    """
    if not isinstance(parsed, dict):
        raise ValueError(f"limits: expected an object of joints, got {type(parsed).__name__}")
    limits = {}
    for joint, given in parsed.items():
        if not isinstance(given, dict):
            raise ValueError(f"limits of joint {joint}: expected an object, got {type(given).__name__}")
        values = {}
        for key, value in given.items():
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(f"limits of joint {joint}: {key} is {str(value)[:40]!r}, not a number")
            values[str(key)] = float(value)
        lower, upper = values.get("lower", -math.inf), values.get("upper", math.inf)
        if not lower <= upper:  # NaN fails too
            raise ValueError(f"limits of joint {joint}: lower {lower} is not at most upper {upper}")
        for key in ("max_velocity", "max_acceleration"):  # what a plan's limits are for (core.types.Plan)
            if key not in values:
                raise ValueError(f"limits of joint {joint}: no {key}")
            if not 0.0 < values[key] < math.inf:
                raise ValueError(f"limits of joint {joint}: {key} {values[key]} is not a positive finite number")
        limits[str(joint)] = values
    return limits


def plan_urdf(plan: PlanFile) -> str:
    """Return the plan's URDF: its /robot_description, else its one .urdf attachment, else ""."""
    if plan.urdf:
        return plan.urdf
    urdfs = [data for name, data in plan.attachments.items() if name.lower().endswith(".urdf")]
    return urdfs[0].decode() if len(urdfs) == 1 else ""


def _steps(
    path: Path, factory: DecoderFactory, contents: Contents, step_names: list[str]
) -> tuple[PlanStepRecord, ...]:
    """Return the steps: one /planned_trajectory message per name, in log-time order.

    Raises:
        InputError: The counts differ, or a message is not a readable JointTrajectory.

    """
    kept = [item for item in contents.kept if item[0].topic == TRAJECTORY]
    if len(kept) != len(step_names):
        raise InputError(
            f"{path}: {len(kept)} messages on {TRAJECTORY} "
            f"but {len(step_names)} step names in its metadata"
        )
    steps = []
    for name, (channel, schema, message) in zip(step_names, kept, strict=True):
        decode = _decoder(path, factory, channel, schema, TRAJECTORY)
        try:
            trajectory = trajectory_from_message(decode(message.data))
        except _UNREADABLE as exc:
            raise InputError(f"{path}: step '{name}' on {TRAJECTORY} is unreadable: {exc}") from exc
        steps.append(PlanStepRecord(name, message.log_time / 1e9, trajectory))
    return tuple(steps)


def _tolerances(text: str | None, count: int) -> list[GoalTolerances | None]:
    """Return each step's goal tolerances from the metadata's step_tolerances (JSON; absent: none)."""
    if text is None:
        return [None] * count
    entries = json.loads(text)
    if not isinstance(entries, list) or len(entries) != count:
        raise ValueError(f"step_tolerances: expected {count} entries, one per step")
    return [None if entry is None else _goal_tolerances(entry) for entry in entries]


def _scalings(text: str | None, count: int) -> list[tuple[float, float] | None]:
    """Return each step's (velocity, acceleration) scaling from the metadata's step_scaling (JSON; absent: none)."""
    if text is None:
        return [None] * count
    entries = json.loads(text)
    if not isinstance(entries, list) or len(entries) != count:
        raise ValueError(f"step_scaling: expected {count} entries, one per step")
    scalings: list[tuple[float, float] | None] = []
    for entry in entries:
        pair = None if entry is None else (float(entry[0]), float(entry[1]))
        if pair is not None and not all(0.0 < value <= 1.0 for value in pair):
            raise ValueError(f"step_scaling: {entry!r} is no pair of fractions in (0, 1]")
        scalings.append(pair)
    return scalings


def _goal_tolerances(entry: dict[str, Any]) -> GoalTolerances:
    def joints(items: list[dict[str, Any]]) -> tuple[JointTolerance, ...]:
        return tuple(JointTolerance(str(t["name"]), *(float(t[key]) for key in ("position", "velocity",
                                                                                 "acceleration"))) for t in items)
    return GoalTolerances(joints(entry["path_tolerance"]), joints(entry["goal_tolerance"]),
                          float(entry["goal_time_tolerance"]))


def _robot_description(path: Path, factory: DecoderFactory, kept: list[Kept]) -> str:
    """Return the URDF text of the first /robot_description message, "" if there is none.

    Raises:
        InputError: The message is not a readable std_msgs/msg/String.

    """
    if not kept:
        return ""
    channel, schema, message = kept[0]
    decode = _decoder(path, factory, channel, schema, ROBOT_DESCRIPTION)
    try:
        return str(decode(message.data).data)
    except _UNREADABLE as exc:
        raise InputError(f"{path}: {ROBOT_DESCRIPTION} is unreadable: {exc}") from exc


def _decoder(
    path: Path, factory: DecoderFactory, channel: Channel, schema: Schema | None, topic: str
) -> Callable[[bytes], Any]:
    """Return the decoder of `topic`'s messages: CDR with a ros2msg schema of the type a plan file gives it.

    The schema's name is checked before its text is parsed: a plan's own topics need no other type.

    Raises:
        InputError: The channel is not CDR, the schema missing, of another type or encoding, or
            its text no valid ros2msg definition.

    """
    kind = PLAN_TOPICS[topic][0]
    problem = f"{path}: {topic} must hold CDR {kind} messages with a ros2msg schema"
    if schema is None or schema.name != kind:
        raise InputError(problem)
    try:
        # The vendored rosidl parser prints the line it fails on to stderr: the error says it once.
        with contextlib.redirect_stderr(io.StringIO()):
            decode = factory.decoder_for(channel.message_encoding, schema)
    except _BAD_SCHEMA as exc:
        raise InputError(f"{path}: the schema of {topic} ({kind}) is no valid ros2msg definition: "
                         f"{type(exc).__name__}: {exc}") from None
    if decode is None:
        raise InputError(problem)
    return decode
