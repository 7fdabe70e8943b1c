"""The ROS 2 side of plan files: shipped message definitions, QoS profiles, messages as dicts.

Messages are plain dicts for a schema-driven CDR encoder. Field names follow the .msg
definitions in core/msgs; a field left out is written with its default (zero, empty or
the definition's constant) by the encoder.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from functools import cache
from importlib.resources import files
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from moveplan.core.errors import UsageError, known
from moveplan.core.types import CollisionObject, JointTrajectory

__all__ = [
    "display_trajectory",
    "durability",
    "joint_trajectory",
    "marker_array",
    "offered_qos_profiles",
    "schema_text",
    "seconds_to_ns",
    "string",
    "tf_message",
    "time_msg",
    "trajectory_from_message",
]

Message = dict[str, Any]

_MARKER_TYPES = {"box": 1, "sphere": 2, "cylinder": 3, "mesh": 10}  # CUBE, SPHERE, CYLINDER, ...
# MoveIt's RViz defaults: scene objects green, attached objects purple.
_SCENE_COLOR = {"r": 0.2, "g": 0.9, "b": 0.2, "a": 0.9}
_ATTACHED_COLOR = {"r": 0.6, "g": 0.2, "b": 0.6, "a": 0.9}


@cache
def schema_text(msgtype: str, distro: str) -> bytes:
    """Return the shipped ros2msg definition of `msgtype` ("pkg/msg/Type") for `distro`.

    The text is exactly what rosbag2 stores as an MCAP schema (see core/msgs/README.md).
    """
    folder = files("moveplan.core.msgs")
    distros = [entry.name for entry in folder.iterdir() if entry.is_dir() and entry.name.isalpha()]
    if distro not in distros:
        raise UsageError(f"unknown ROS distro '{distro}'; known: {known(distros)}")
    return folder.joinpath(distro, msgtype.replace("/", "__") + ".msg").read_bytes()


def offered_qos_profiles(latched: bool) -> str:
    """Return the offered_qos_profiles YAML rosbag2 stores per topic, with integer enums.

    Humble's player reads the enums as integers only; Jazzy's reads both. history 1 =
    keep_last, reliability 1 = reliable, durability 1 = transient_local (latched) or
    2 = volatile, liveliness 1 = automatic; durations are rmw's "infinite".
    """
    infinite = "    sec: 9223372036\n    nsec: 854775807\n"
    return (
        "- history: 1\n"
        f"  depth: {1 if latched else 10}\n"
        "  reliability: 1\n"
        f"  durability: {1 if latched else 2}\n"
        f"  deadline:\n{infinite}"
        f"  lifespan:\n{infinite}"
        "  liveliness: 1\n"
        f"  liveliness_lease_duration:\n{infinite}"
        "  avoid_ros_namespace_conventions: false"
    )


def durability(offered_qos_profiles: str) -> str:
    """Return "transient_local" if all offered profiles are, else "volatile"; "" if none given."""
    # Humble writes integer enums, Jazzy writes names. No yaml here: it enters through config only.
    values = re.findall(r"^[\s-]*durability:\s*['\"]?(\w+)", offered_qos_profiles, re.MULTILINE)
    enums = {"1": "transient_local", "2": "volatile"}
    names = [enums.get(value, value.lower()) for value in values]
    if not names:
        return ""
    return "transient_local" if all(name == "transient_local" for name in names) else "volatile"


def seconds_to_ns(seconds: float) -> int:
    """Return `seconds` in [s] as the nearest integer number of nanoseconds."""
    return round(seconds * 1e9)


def time_msg(stamp_ns: int) -> Message:
    """Return a builtin_interfaces Time or Duration {sec, nanosec} for `stamp_ns` in [ns] >= 0."""
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    return {"sec": sec, "nanosec": nanosec}


def string(text: str) -> Message:
    """Return a std_msgs/String holding `text`."""
    return {"data": text}


def joint_trajectory(trajectory: JointTrajectory, frame_id: str) -> Message:
    """Return a trajectory_msgs/JointTrajectory with header.stamp 0 ("start now" for JTC)."""
    points = [
        {
            "positions": trajectory.positions[i].tolist(),
            "velocities": trajectory.velocities[i].tolist(),
            "accelerations": trajectory.accelerations[i].tolist(),
            "effort": [],
            "time_from_start": time_msg(seconds_to_ns(float(t))),
        }
        for i, t in enumerate(trajectory.times_s)
    ]
    return {
        "header": {"stamp": time_msg(0), "frame_id": frame_id},
        "joint_names": list(trajectory.joint_names),
        "points": points,
    }


def display_trajectory(
    robot_name: str, trajectories: Sequence[JointTrajectory], frame_id: str
) -> Message:
    """Return a moveit_msgs/DisplayTrajectory: one RobotTrajectory per step, starting at step 0."""
    first = trajectories[0]
    start_state = {
        "header": {"stamp": time_msg(0), "frame_id": frame_id},
        "name": list(first.joint_names),
        "position": first.positions[0].tolist(),
        "velocity": first.velocities[0].tolist(),
        "effort": [],
    }
    return {
        "model_id": robot_name,
        "trajectory": [
            {"joint_trajectory": joint_trajectory(trajectory, frame_id)}
            for trajectory in trajectories
        ],
        "trajectory_start": {"joint_state": start_state, "is_diff": False},
    }


def tf_message(
    parents: Sequence[str],
    children: Sequence[str],
    transforms: Sequence[NDArray[np.float64]],
    stamp_ns: int,
) -> Message:
    """Return a tf2_msgs/TFMessage with one `parent_T_child` transform per child."""
    return {
        "transforms": [
            {
                "header": {"stamp": time_msg(stamp_ns), "frame_id": parent},
                "child_frame_id": child,
                "transform": {
                    "translation": _xyz(transform),
                    "rotation": _quaternion(transform),
                },
            }
            for parent, child, transform in zip(parents, children, transforms, strict=True)
        ]
    }


def marker_array(objects: Sequence[CollisionObject], planning_frame: str) -> Message:
    """Return a visualization_msgs/MarkerArray with one marker per collision object."""
    return {"markers": [_marker(obj, index, planning_frame) for index, obj in enumerate(objects)]}


def _marker(obj: CollisionObject, marker_id: int, planning_frame: str) -> Message:
    shape = obj.shape
    if shape.kind == "box":
        scale = shape.dims
    elif shape.kind == "cylinder":
        scale = (2 * shape.dims[0], 2 * shape.dims[0], shape.dims[1])
    elif shape.kind == "sphere":
        scale = (2 * shape.dims[0],) * 3
    else:
        scale = shape.scale
    mesh_path = shape.mesh_path
    if mesh_path and "://" not in mesh_path:
        mesh_path = Path(mesh_path).absolute().as_uri()
    return {
        "header": {"stamp": time_msg(0), "frame_id": obj.link or planning_frame},
        "ns": "moveplan",
        "id": marker_id,
        "type": _MARKER_TYPES[shape.kind],
        "action": 0,  # ADD
        "pose": {"position": _xyz(obj.transform), "orientation": _quaternion(obj.transform)},
        "scale": dict(zip("xyz", map(float, scale), strict=True)),
        "color": _ATTACHED_COLOR if obj.link else _SCENE_COLOR,
        # An attached object must follow its link as TF moves it.
        "frame_locked": bool(obj.link),
        # Only TEXT markers show `text`; it names the object for anyone reading the message.
        "text": obj.name,
        "mesh_resource": mesh_path,
    }


def _xyz(transform: NDArray[np.float64]) -> Message:
    x, y, z = transform[:3, 3].tolist()
    return {"x": x, "y": y, "z": z}


def _quaternion(transform: NDArray[np.float64]) -> Message:
    """Return the rotation of a 4x4 transform as a unit quaternion with w >= 0."""
    m = transform[:3, :3]
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    # Shepperd's method: divide by the largest of the four candidates, for accuracy.
    if trace > 0.0:
        s = 2.0 * np.sqrt(1.0 + trace)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4, (m[1, 0] - m[0, 1]) / s]
    xyzw = np.array(q, dtype=np.float64)
    xyzw /= np.linalg.norm(xyzw)
    if xyzw[3] < 0.0:
        xyzw = -xyzw
    x, y, z, w = xyzw.tolist()
    return {"x": x, "y": y, "z": z, "w": w}


def trajectory_from_message(message: Any) -> JointTrajectory:
    """Return a decoded trajectory_msgs/JointTrajectory (any object with its fields) as a value.

    Raises ValueError if the points do not make a valid JointTrajectory.
    """
    points = message.points
    times_ns = [p.time_from_start.sec * 1_000_000_000 + p.time_from_start.nanosec for p in points]
    return JointTrajectory(
        joint_names=tuple(message.joint_names),
        times_s=np.array(times_ns, dtype=np.float64) / 1e9,
        positions=np.array([list(p.positions) for p in points], dtype=np.float64),
        velocities=np.array([list(p.velocities) for p in points], dtype=np.float64),
        accelerations=np.array([list(p.accelerations) for p in points], dtype=np.float64),
    )
