"""The ROS 2 side of plan files: shipped message definitions, QoS profiles, messages.

Messages are plain dicts for a schema-driven CDR encoder. Field names follow the .msg
definitions in core/bag/msgs; a field left out is written with its default (zero, empty or
the definition's constant) by the encoder.

The big, numerous messages (trajectories, /tf, joint states, controller states) also have
`*_cdr` twins that write CDR bytes directly with bulk float packing: a generic encoder
spends a Python call per float. Each twin writes exactly the bytes the generic encoder
makes of its dict builder's message (tests/test_recording.py and tests/test_execution_file.py
check every shipped distro). The field layout is the same in every distro except
control_msgs/JointTrajectoryControllerState, whose builders read it from the distro's schema.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import fields
from functools import cache
from importlib.resources import files
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..errors import UsageError, known
from ..types import CollisionObject, ControllerStates, JointTrajectory, PointSeries
from .cdr import CdrWriter, patched_copies, time_array

__all__ = [
    "ControllerStates",
    "PointSeries",
    "controller_state",
    "controller_states_cdr",
    "display_trajectory",
    "display_trajectory_cdr",
    "durability",
    "joint_state",
    "joint_trajectory",
    "joint_trajectory_cdr",
    "marker_array",
    "offered_qos_profiles",
    "schema_text",
    "seconds_to_ns",
    "stamps_ns",
    "string",
    "tf_message",
    "tf_messages_cdr",
    "time_msg",
    "trajectory_from_message",
]

Message = dict[str, Any]

_MARKER_TYPES = {"box": 1, "sphere": 2, "cylinder": 3, "mesh": 10}  # CUBE, SPHERE, CYLINDER, ...
_TRIANGLE_LIST = 11
# MoveIt's RViz defaults: scene objects green, attached objects purple.
_SCENE_COLOR = {"r": 0.2, "g": 0.9, "b": 0.2, "a": 0.9}
_ATTACHED_COLOR = {"r": 0.6, "g": 0.2, "b": 0.6, "a": 0.9}
_CONTROLLER_STATE = "control_msgs/msg/JointTrajectoryControllerState"
# Humble's deprecated points repeat the new ones: ros2_controllers#1985 fills `desired`
# from the reference and `actual` from the feedback.
_POINT_SOURCES = {
    "reference": "reference",
    "feedback": "feedback",
    "error": "error",
    "output": "output",
    "desired": "reference",
    "actual": "feedback",
}


@cache
def schema_text(msgtype: str, distro: str) -> bytes:
    """Return the shipped ros2msg definition of `msgtype` ("pkg/msg/Type") for `distro`.

    The text is exactly what rosbag2 stores as an MCAP schema (see core/bag/msgs/README.md).
    """
    folder = files("moveplan.core.bag.msgs")
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


def stamps_ns(times_s: npt.ArrayLike) -> NDArray[np.int64]:
    """Return times in [s] as the nearest int64 [ns], each rounded as `seconds_to_ns` rounds it."""
    # np.rint and round() both round the same float product half to even.
    return np.rint(np.asarray(times_s, dtype=np.float64) * 1e9).astype(np.int64)


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
    for kind, name in _controller_state_fields(distro):
        if kind == "header":
            message[name] = {"stamp": time_msg(int(states.stamps_ns[index])), "frame_id": ""}
        elif kind == "names":
            message[name] = list(states.joint_names) if name == "joint_names" else []
        elif kind == "point":
            series: PointSeries = getattr(states, _POINT_SOURCES[name])
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


def joint_trajectory_cdr(trajectory: JointTrajectory, frame_id: str) -> bytes:
    """Return `joint_trajectory(trajectory, frame_id)` encoded as CDR."""
    writer = CdrWriter()
    _write_joint_trajectory(writer, trajectory, frame_id)
    return writer.data()


def display_trajectory_cdr(
    robot_name: str, trajectories: Sequence[JointTrajectory], frame_id: str
) -> bytes:
    """Return `display_trajectory(robot_name, trajectories, frame_id)` encoded as CDR."""
    writer = CdrWriter()
    writer.string(robot_name)  # model_id
    writer.uint32(len(trajectories))
    for trajectory in trajectories:  # moveit_msgs/RobotTrajectory
        _write_joint_trajectory(writer, trajectory, frame_id)
        # An empty trajectory_msgs/MultiDOFJointTrajectory: header, joint_names[], points[].
        writer.time(0)
        writer.string("")
        writer.uint32(0)
        writer.uint32(0)
    first = trajectories[0]
    # trajectory_start, a moveit_msgs/RobotState; first its sensor_msgs/JointState.
    writer.time(0)
    writer.string(frame_id)
    writer.strings(first.joint_names)
    writer.float64_sequence(first.positions[0])
    writer.float64_sequence(first.velocities[0])
    writer.uint32(0)  # effort[]
    # An empty sensor_msgs/MultiDOFJointState: header, then joint_names[], transforms[],
    # twist[], wrench[].
    writer.time(0)
    writer.string("")
    for _ in range(4):
        writer.uint32(0)
    writer.uint32(0)  # attached_collision_objects[]
    writer.boolean(False)  # is_diff
    return writer.data()


def tf_messages_cdr(
    parents: Sequence[str],
    children: Sequence[str],
    transforms: NDArray[np.float64],
    stamps_ns: Sequence[int],
) -> list[bytes]:
    """Return one CDR `tf_message` per stamp; `transforms` has shape (stamps, children, 4, 4)."""
    # The messages differ only in stamps and poses: one template written field by field,
    # then copies of it patched in bulk (a plan has ~180 messages of ~7 transforms).
    template = CdrWriter()
    template.uint32(len(children))
    stamp_at, pose_at = [], []
    for parent, child in zip(parents, children, strict=True):
        # geometry_msgs/TransformStamped: header, child_frame_id, then a Transform of
        # translation xyz and rotation xyzw, seven float64 in a row.
        stamp_at.append(template.time(0))
        template.string(parent)
        template.string(child)
        pose_at.append(template.float64_array(np.zeros(7)))
    poses = np.concatenate([transforms[..., :3, 3], _quaternions(transforms)], axis=-1)
    poses = poses.astype("<f8", copy=False)
    stamps = time_array(stamps_ns)
    patches: list[tuple[int, NDArray[np.generic]]] = [(start, stamps) for start in stamp_at]
    patches += [(start, poses[:, child]) for child, start in enumerate(pose_at)]
    messages = patched_copies(template.data(), len(stamps), patches)
    return [message.tobytes() for message in messages]


def controller_states_cdr(states: ControllerStates, distro: str) -> list[bytes]:
    """Return every cycle of `states` as CDR `controller_state`, laid out for `distro`."""
    # Every message of a series has the same names and array lengths, so the same layout
    # and padding: one template, patched per cycle.
    template = CdrWriter()
    count = len(states.stamps_ns)
    times = time_array(states.times_from_start_ns)
    zeros = np.zeros(len(states.joint_names))
    patches: list[tuple[int, NDArray[np.generic]]] = []
    for kind, name in _controller_state_fields(distro):
        if kind == "header":
            patches.append((template.time(0), time_array(states.stamps_ns)))
            template.string("")
        elif kind == "names":
            template.strings(states.joint_names if name == "joint_names" else ())
        elif kind == "point":
            series: PointSeries = getattr(states, _POINT_SOURCES[name])
            for values in series.filled():
                if values is None:
                    template.uint32(0)
                else:
                    patches.append((template.float64_sequence(zeros), _column(values)))
            patches.append((template.time(0), times))
        elif kind == "multi_dof_point":
            for _ in range(3):  # transforms[], velocities[], accelerations[]
                template.uint32(0)
            template.time(0)
        else:
            template.float64_array(np.ones(1))  # speed_scaling_factor
    return _copies(template.data(), count, patches)


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
        "pose": {"position": _xyz(obj.transform), "orientation": _quaternion(obj.transform)},
        "scale": dict(zip("xyz", map(float, scale), strict=True)),
        "color": _ATTACHED_COLOR if obj.link else _SCENE_COLOR,
        # An attached object must follow its link as TF moves it.
        "frame_locked": bool(obj.link),
        # Only TEXT markers show `text`; it names the object for anyone reading the message.
        "text": obj.name,
        "mesh_resource": mesh_path,
        "points": points,
    }


def _write_joint_trajectory(writer: CdrWriter, trajectory: JointTrajectory, frame_id: str) -> None:
    """Write the fields of `joint_trajectory(trajectory, frame_id)` to `writer`; return None."""
    writer.time(0)
    writer.string(frame_id)
    writer.strings(trajectory.joint_names)
    times_ns = [seconds_to_ns(t) for t in trajectory.times_s.tolist()]
    motion = (trajectory.positions, trajectory.velocities, trajectory.accelerations)
    arrays = [values.astype("<f8", copy=False) for values in motion]

    def write_point(i: int) -> list[int]:
        """Write point `i`; return where its positions, velocities, accelerations, time start."""
        indexes = [writer.float64_sequence(values[i]) for values in arrays]
        writer.uint32(0)  # effort[]
        return [*indexes, writer.time(times_ns[i])]

    writer.uint32(len(times_ns))
    write_point(0)
    if len(times_ns) == 1:
        return
    # A point's padding depends on where it starts, mod 8, and the first may start
    # anywhere. Every point ends at the same offset mod 8, though, so from the second on
    # all points share one layout: the second is written field by field and the rest are
    # copies of it with their own values (its size, a multiple of 8, keeps them aligned).
    start = len(writer)
    indexes = write_point(1)
    template = writer.data()[start:]
    assert len(template) % 8 == 0, len(template)
    columns: list[NDArray[np.generic]] = [*arrays, time_array(times_ns)]
    patches = [(index - start, column[2:]) for index, column in zip(indexes, columns, strict=True)]
    writer.raw(patched_copies(template, len(times_ns) - 2, patches).tobytes())


@cache
def _controller_state_fields(distro: str) -> tuple[tuple[str, str], ...]:
    """Return (kind, name) of each JointTrajectoryControllerState field of `distro`, in order.

    Read from the shipped schema, as the layouts differ (Humble keeps the deprecated
    desired/actual points, Jazzy adds speed_scaling_factor). Kinds: header, names, point,
    multi_dof_point, scale.

    Raises:
        UsageError: `distro` has no shipped message definitions.
        ValueError: The schema has a field these encoders do not know.

    """
    kinds = {
        "std_msgs/Header": "header",
        "string[]": "names",
        "trajectory_msgs/JointTrajectoryPoint": "point",
        "trajectory_msgs/MultiDOFJointTrajectoryPoint": "multi_dof_point",
        "float64": "scale",
    }
    root = schema_text(_CONTROLLER_STATE, distro).decode().split("\n" + "=" * 80)[0]
    result = []
    for line in root.splitlines():
        words = line.split("#", 1)[0].split()
        if not words or "=" in line.split("#", 1)[0]:
            continue  # blank, comment or constant
        msgtype, name = words[0], words[1]
        kind = kinds.get(msgtype)
        known_point = kind != "point" or name in _POINT_SOURCES
        if kind is None or not known_point or (kind == "scale" and name != "speed_scaling_factor"):
            raise ValueError(f"{_CONTROLLER_STATE} ({distro}): unexpected field '{msgtype} {name}'")
        result.append((kind, name))
    return tuple(result)


def _column(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return (rows, n) values as little-endian float64 rows, for `patched_copies`."""
    return np.asarray(values).astype("<f8", copy=False)


def _copies(
    template: bytes, count: int, patches: list[tuple[int, NDArray[np.generic]]]
) -> list[bytes]:
    """Return `count` copies of `template` patched row by row, as separate messages."""
    if count == 0:
        return []
    return [row.tobytes() for row in patched_copies(template, count, patches)]


def _xyz(transform: NDArray[np.float64]) -> Message:
    x, y, z = transform[:3, 3].tolist()
    return {"x": x, "y": y, "z": z}


def _quaternion(transform: NDArray[np.float64]) -> Message:
    """Return the rotation of a 4x4 transform as a unit quaternion with w >= 0."""
    x, y, z, w = _quaternions(transform).tolist()
    return {"x": x, "y": y, "z": z, "w": w}


def _quaternions(transforms: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the rotations of 4x4 transforms (..., 4, 4) as unit quaternions xyzw with w >= 0."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = np.moveaxis(
        transforms[..., :3, :3], (-2, -1), (0, 1)
    )
    trace = m00 + m11 + m22
    # Shepperd's method: divide by the largest of the four candidates, for accuracy. All
    # four are computed and one kept, so the others may divide by zero or take sqrt(< 0).
    with np.errstate(divide="ignore", invalid="ignore"):
        s = 2.0 * np.sqrt(1.0 + trace)
        q0 = [(m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, s / 4]
        s = 2.0 * np.sqrt(1.0 + m00 - m11 - m22)
        q1 = [s / 4, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s]
        s = 2.0 * np.sqrt(1.0 + m11 - m00 - m22)
        q2 = [(m01 + m10) / s, s / 4, (m12 + m21) / s, (m02 - m20) / s]
        s = 2.0 * np.sqrt(1.0 + m22 - m00 - m11)
        q3 = [(m02 + m20) / s, (m12 + m21) / s, s / 4, (m10 - m01) / s]
    # np.select takes the first true condition, like an if/elif chain.
    conditions = [trace > 0.0, (m00 > m11) & (m00 > m22), m11 > m22]
    candidates = [np.stack(q, axis=-1) for q in (q0, q1, q2, q3)]
    xyzw = np.select([c[..., None] for c in conditions], candidates[:3], candidates[3])
    # The norm as a plain sum over the last axis, not BLAS: the same bits for one transform
    # or many, whatever the machine.
    xyzw /= np.linalg.norm(xyzw, axis=-1, keepdims=True)
    result: NDArray[np.float64] = np.where(xyzw[..., 3:] < 0.0, -xyzw, xyzw)
    return result


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
