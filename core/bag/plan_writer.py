"""Plans written as plan files: every message of a plan encoded, then written as one ROS 2 bag."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..rotations import tf_poses
from ..types import Plan
from .cdr import (
    Message,
    display_trajectory_cdr,
    encoder,
    joint_trajectory_cdr,
    marker_array_cdr,
    schema_text,
    seconds_to_ns,
    string_message,
    tf_messages_cdr,
)
from .container import write_bag
from .plan_file import PLAN_TOPICS, ROBOT_DESCRIPTION, TRAJECTORY

__all__ = ["write_plan"]


def write_plan(path: Path, plan: Plan, distro: str = "jazzy") -> None:
    """Write `plan` to `path` as a ROS 2 bag for `distro`, atomically; return None.

    Raises:
        UsageError: `distro` has no shipped message definitions, or `path` cannot be an
            output file (a directory, a symbolic link, a device: bag_writer.output_problem).
        InputError: `path` cannot be written (missing or read-only folder, full disk).

    """
    schemas = {msgtype: schema_text(msgtype, distro) for msgtype, _ in PLAN_TOPICS.values()}
    messages = _plan_messages(plan, schemas)
    metadata = {
        **plan.metadata,
        "robot_name": plan.robot_name,
        "group": plan.group,
        "planning_frame": plan.planning_frame,
        "step_names": json.dumps([step.name for step in plan.steps]),
        # The tolerances each step's goal carries (control_msgs/FollowJointTrajectory's fields), null: none.
        **({"step_tolerances": json.dumps([s.tolerances.as_dict() if s.tolerances else None for s in plan.steps])}
           if any(step.tolerances for step in plan.steps) else {}),
        # The scaling factors each step was timed with, [velocity, acceleration], null: not timed by moveplan.
        **({"step_scaling": json.dumps([list(s.scaling) if s.scaling else None for s in plan.steps])}
           if any(step.scaling for step in plan.steps) else {}),
        "limits": json.dumps(plan.limits, sort_keys=True),
        "distro": distro,
    }
    topics = {topic: PLAN_TOPICS[topic] for topic in dict.fromkeys(t for t, _, _ in messages)}
    write_bag(
        path,
        topics,
        schemas,
        messages,
        {"rosbag2": {"ROS_DISTRO": distro}, "moveplan": metadata},
        plan.attachments,
    )


def _plan_messages(plan: Plan, schemas: dict[str, bytes]) -> list[tuple[str, int, bytes]]:
    """Return (topic, log time [ns], CDR message) for every message of `plan`, in log-time order.

    Trajectories, transforms and markers take the fast `*_cdr` encoders; the URDF's string
    takes the generic encoder built from `schemas` (message type -> schema text).
    """
    if not plan.steps:
        raise ValueError("a plan needs at least one step")

    def generic(topic: str, message: Message) -> bytes:
        msgtype = PLAN_TOPICS[topic][0]
        return encoder(msgtype, schemas[msgtype])(message)

    frame = plan.planning_frame
    trajectories = [step.trajectory for step in plan.steps]
    statics = plan.static_frames
    # reshape, not np.array alone: no static frames must still give shape (1, 0, 4, 4).
    static_transforms = np.reshape([f.transform for f in statics], (1, len(statics), 4, 4))
    [tf_static] = tf_messages_cdr([f.parent for f in statics], [f.name for f in statics], tf_poses(static_transforms),
                                  [0])
    messages = [
        (ROBOT_DESCRIPTION, 0, generic(ROBOT_DESCRIPTION, string_message(plan.urdf))),
        ("/tf_static", 0, tf_static),
        ("/planning_scene_markers", 0, marker_array_cdr(plan.objects, frame)),
        ("/display_planned_path", 0, display_trajectory_cdr(plan.robot_name, trajectories, frame)),
    ]
    # Starts add up integer durations, so a step starts exactly where the previous one's
    # last time_from_start ends.
    start_ns = 0
    for trajectory in trajectories:
        messages.append((TRAJECTORY, start_ns, joint_trajectory_cdr(trajectory, frame)))
        start_ns += seconds_to_ns(trajectory.duration_s)
    if plan.tf is not None:
        tf = plan.tf
        stamps_ns = [seconds_to_ns(float(time_s)) for time_s in tf.times_s]
        encoded = tf_messages_cdr(tf.parents, tf.children, tf.poses, stamps_ns)
        messages += [("/tf", stamp, data) for stamp, data in zip(stamps_ns, encoded, strict=True)]
    # A stable sort: messages logged at the same time keep the order above.
    return sorted(messages, key=lambda item: item[1])
