"""ROS 2 messages as plain dicts, for the schema-driven CDR encoder, and their time stamps.

Field names follow the .msg definitions in core/bag/cdr/msgs; a field left out is written with
its default (zero, empty or the definition's constant) by the encoder (core.bag.cdr.generic).
The big, numerous messages also have `*_cdr` twins in core.bag.cdr.bulk that write the
same bytes directly.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import fields
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ...rotations import quaternions_xyzw
from ...types import CollisionObject, ControllerStates, JointTrajectory, PointSeries
from .definitions import POINT_SOURCES, controller_state_fields

__all__ = [
    "Message",
    "controller_state",
    "display_trajectory",
    "joint_state",
    "joint_trajectory",
    "marker_array",
    "seconds_to_ns",
    "stamps_ns",
    "string_message",
    "tf_message",
    "time_msg",
    "trajectory_from_message",
]

Message = dict[str, Any]

_MARKER_TYPES = {"box": 1, "sphere": 2, "cylinder": 3, "mesh": 10}  # CUBE, SPHERE, CYLINDER, ...
_TRIANGLE_LIST = 11
# MoveIt's RViz defaults: scene objects green, attached objects purple.
_SCENE_COLOR = {"r": 0.2, "g": 0.9, "b": 0.2, "a": 0.9}
_ATTACHED_COLOR = {"r": 0.6, "g": 0.2, "b": 0.6, "a": 0.9}


def seconds_to_ns(seconds: float) -> int:
    """Return `seconds` in [s] as the nearest integer number of nanoseconds."""
    return round(seconds * 1e9)


def stamps_ns(times_s: npt.ArrayLike) -> NDArray[np.int64]:
    """Return times in [s] as the nearest int64 [ns], each rounded as `seconds_to_ns` rounds it."""
    # np.rint and round() both round the same float product half to even.
    return np.rint(np.asarray(times_s, dtype=np.float64) * 1e9).astype(np.int64)


def time_msg(stamp_ns: int) -> Message:
    """Return a builtin_interfaces Time or Duration {sec, nanosec} for `stamp_ns` in [ns] >= 0."""
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    return {"sec": sec, "nanosec": nanosec}


def string_message(text: str) -> Message:
    """Return a std_msgs/String holding `text`."""
    return {"data": text}


def joint_trajectory(trajectory: JointTrajectory, frame_id: str) -> Message:
    """Return a trajectory_msgs/JointTrajectory with header.stamp 0 ("start now" for JTC)."""
    points = [
        {
            "positions": trajectory.positions[i].tolist(),
            "velocities": trajectory.velocities[i].tolist() if trajectory.has_velocities else [],
            "accelerations": trajectory.accelerations[i].tolist() if trajectory.has_accelerations else [],
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
    poses: Sequence[NDArray[np.float64]],
    stamp_ns: int,
) -> Message:
    """Return a tf2_msgs/TFMessage with one `parent_T_child` pose (xyz, then quaternion xyzw) per child."""
    return {
        "transforms": [
            {
                "header": {"stamp": time_msg(stamp_ns), "frame_id": parent},
                "child_frame_id": child,
                "transform": {
                    "translation": dict(zip("xyz", np.asarray(pose)[:3].tolist(), strict=True)),
                    "rotation": dict(zip("xyzw", np.asarray(pose)[3:].tolist(), strict=True)),
                },
            }
            for parent, child, pose in zip(parents, children, poses, strict=True)
        ]
    }


def joint_state(
    names: Sequence[str],
    stamp_ns: int,
    positions: NDArray[np.float64],
    velocities: NDArray[np.float64],
    frame_id: str = "",
) -> Message:
    """Return a sensor_msgs/JointState of measured positions and velocities, no effort."""
    return {
        "header": {"stamp": time_msg(stamp_ns), "frame_id": frame_id},
        "name": list(names),
        "position": np.asarray(positions, dtype=np.float64).tolist(),
        "velocity": np.asarray(velocities, dtype=np.float64).tolist(),
        "effort": [],
    }


def controller_state(states: ControllerStates, index: int, distro: str) -> Message:
    """Return cycle `index` of `states` as a JointTrajectoryControllerState laid out for `distro`.

    Multi-DOF fields stay empty and speed_scaling_factor (Jazzy) is 1.0; header.frame_id is
    empty, as JTC leaves it.
    """
    tfs = time_msg(int(states.times_from_start_ns[index]))
    message: Message = {}
    for kind, name in controller_state_fields(distro):
        if kind == "header":
            message[name] = {"stamp": time_msg(int(states.stamps_ns[index])), "frame_id": ""}
        elif kind == "names":
            message[name] = list(states.joint_names) if name == "joint_names" else []
        elif kind == "point":
            series: PointSeries = getattr(states, POINT_SOURCES[name])
            point = {
                field.name: [] if value is None else value[index].tolist()
                for field, value in zip(fields(series), series.filled(), strict=True)
            }
            message[name] = {**point, "time_from_start": tfs}
        elif kind == "multi_dof_point":
            empty: Message = {"transforms": [], "velocities": [], "accelerations": []}
            message[name] = {**empty, "time_from_start": time_msg(0)}
        else:
            message[name] = 1.0  # speed_scaling_factor: JTC without scaling runs at 1
    return message


def marker_array(objects: Sequence[CollisionObject], planning_frame: str) -> Message:
    """Return a visualization_msgs/MarkerArray with one marker per collision object."""
    # The orientations in one call: a scene holds tens of objects, and each call is tens of numpy operations.
    orientations = quaternions_xyzw(np.reshape([obj.transform for obj in objects], (len(objects), 4, 4))).tolist()
    return {"markers": [_marker(obj, index, planning_frame, dict(zip("xyzw", orientations[index], strict=True)))
                        for index, obj in enumerate(objects)]}


def _marker(obj: CollisionObject, marker_id: int, planning_frame: str, orientation: Message) -> Message:
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
    marker_type, points = _MARKER_TYPES[shape.kind], []
    if shape.vertices is not None and shape.triangles is not None:
        # An inline mesh has no file for mesh_resource: draw its triangles, three points each.
        marker_type = _TRIANGLE_LIST
        corners = shape.vertices[shape.triangles.ravel()]
        points = [{"x": float(x), "y": float(y), "z": float(z)} for x, y, z in corners]
    return {
        "header": {"stamp": time_msg(0), "frame_id": obj.link or planning_frame},
        "ns": "moveplan",
        "id": marker_id,
        "type": marker_type,
        "action": 0,  # ADD
        "pose": {"position": _xyz(obj.transform), "orientation": orientation},
        "scale": dict(zip("xyz", map(float, scale), strict=True)),
        "color": _ATTACHED_COLOR if obj.link else _SCENE_COLOR,
        # An attached object must follow its link as TF moves it.
        "frame_locked": bool(obj.link),
        # Only TEXT markers show `text`; it names the object for anyone reading the message.
        "text": obj.name,
        "mesh_resource": mesh_path,
        "points": points,
    }


def _xyz(transform: NDArray[np.float64]) -> Message:
    x, y, z = transform[:3, 3].tolist()
    return {"x": x, "y": y, "z": z}


def trajectory_from_message(message: Any) -> JointTrajectory:
    """Return a decoded trajectory_msgs/JointTrajectory (any object with its fields) as a value.

    Raises ValueError if the points do not make a valid JointTrajectory, or a joint name is empty,
    given twice or holds a control character (what no planner writes, and a damaged message
    decodes to). NaN and infinite values are left to the plan's checks, which name joint and point.
    """
    points = message.points
    times_ns = [p.time_from_start.sec * 1_000_000_000 + p.time_from_start.nanosec for p in points]
    names = tuple(message.joint_names)
    # JTC takes velocities and accelerations empty or full at each point; empty at every point,
    # it interpolates with a lower degree (linear with positions only, cubic without accelerations).
    has_velocities = any(len(p.velocities) for p in points)
    has_accelerations = any(len(p.accelerations) for p in points)
    for name in names:
        if not name or any(ord(c) < 0x20 or ord(c) == 0x7F for c in name):
            raise ValueError(f"joint name {name[:40]!r} is empty or holds a control character")
    if len(set(names)) < len(names):
        raise ValueError(f"joint {next(n for i, n in enumerate(names) if n in names[:i])!r} is named twice")
    return JointTrajectory(
        joint_names=names,
        times_s=np.array(times_ns, dtype=np.float64) / 1e9,
        positions=np.array([list(p.positions) for p in points], dtype=np.float64),
        velocities=_field([list(p.velocities) for p in points], has_velocities, len(names)),
        accelerations=_field([list(p.accelerations) for p in points], has_accelerations, len(names)),
        has_velocities=has_velocities,
        has_accelerations=has_accelerations,
    )


def _field(rows: list[list[float]], present: bool, joints: int) -> NDArray[np.float64]:
    """Return a point field's values, zeros where no point has it (a mix is left to the shape check)."""
    return np.array(rows, dtype=np.float64) if present else np.zeros((len(rows), joints))
