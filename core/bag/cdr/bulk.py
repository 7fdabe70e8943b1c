"""CDR twins of the big, numerous messages: trajectories, /tf, controller states.

Each `*_cdr` function writes exactly the bytes the schema-driven encoder (core.bag.cdr.generic)
makes of its dict builder's message in core.bag.cdr.messages, but with bulk float packing and
templates patched per message: the generic encoder spends a Python call per float
(tests/bag/test_recording.py and tests/bag/test_execution_file.py check every shipped distro). The
field layout is the same in every distro except control_msgs/JointTrajectoryControllerState,
whose encoder reads it from the distro's schema.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ...types import CollisionObject, ControllerStates, JointTrajectory, PointSeries
from ._primitives import CdrWriter, patched_copies, time_array
from .definitions import POINT_SOURCES, controller_state_fields
from .messages import marker_array, seconds_to_ns

__all__ = [
    "controller_states_cdr", "display_trajectory_cdr", "joint_trajectory_cdr", "marker_array_cdr", "tf_messages_cdr",
]


def joint_trajectory_cdr(trajectory: JointTrajectory, frame_id: str) -> bytes:
    """Return `messages.joint_trajectory(trajectory, frame_id)` encoded as CDR."""
    writer = CdrWriter()
    _write_joint_trajectory(writer, trajectory, frame_id)
    return writer.data()


def display_trajectory_cdr(
    robot_name: str, trajectories: Sequence[JointTrajectory], frame_id: str
) -> bytes:
    """Return `messages.display_trajectory(robot_name, trajectories, frame_id)` encoded as CDR."""
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


def marker_array_cdr(objects: Sequence[CollisionObject], planning_frame: str) -> bytes:
    """Return `messages.marker_array(objects, planning_frame)` encoded as CDR (Marker's layout is every distro's)."""
    writer = CdrWriter()
    markers = marker_array(objects, planning_frame)["markers"]
    writer.uint32(len(markers))
    for marker in markers:
        stamp, pose = marker["header"]["stamp"], marker["pose"]
        writer.scalars("i", 4, [stamp["sec"]])
        writer.scalars("I", 4, [stamp["nanosec"]])
        writer.string(marker["header"]["frame_id"])
        writer.string(marker["ns"])
        writer.scalars("i", 4, [marker["id"], marker["type"], marker["action"]])
        writer.scalars("d", 8, [*pose["position"].values(), *pose["orientation"].values(), *marker["scale"].values()])
        writer.scalars("f", 4, list(marker["color"].values()))
        writer.scalars("i", 4, [0, 0])  # lifetime: forever
        writer.boolean(marker["frame_locked"])
        writer.uint32(len(marker["points"]))
        writer.scalars("d", 8, [value for point in marker["points"] for value in point.values()])
        writer.uint32(0)  # colors[]
        writer.string("")  # texture_resource
        writer.scalars("i", 4, [0, 0])  # texture: a sensor_msgs/CompressedImage, empty: header stamp,
        writer.string("")  # its frame_id,
        writer.string("")  # format
        writer.uint32(0)  # and data[]
        writer.uint32(0)  # uv_coordinates[]
        writer.string(marker["text"])
        writer.string(marker["mesh_resource"])
        writer.string("")  # mesh_file: filename,
        writer.uint32(0)  # data[]
        writer.boolean(False)  # mesh_use_embedded_materials
    return writer.data()


def tf_messages_cdr(
    parents: Sequence[str],
    children: Sequence[str],
    poses: NDArray[np.float64],
    stamps_ns: Sequence[int],
) -> list[bytes]:
    """Return one CDR `messages.tf_message` per stamp; `poses` (stamps, children, 7) are xyz then quaternion xyzw."""
    # The messages differ only in stamps and poses: one template written field by field,
    # then copies of it patched in bulk (a plan has ~180 messages of ~7 transforms).
    poses = np.asarray(poses).astype("<f8", copy=False)
    stamps = time_array(stamps_ns)
    if not len(stamps):
        return []
    # The template is the first message: a plan's /tf_static is one message, and is then written.
    template = CdrWriter()
    template.uint32(len(children))
    stamp_at, pose_at = [], []
    for child, (parent, name) in enumerate(zip(parents, children, strict=True)):
        # geometry_msgs/TransformStamped: header, child_frame_id, then a Transform of
        # translation xyz and rotation xyzw, seven float64 in a row.
        stamp_at.append(template.time(int(stamps_ns[0])))
        template.string(parent)
        template.string(name)
        pose_at.append(template.float64_array(poses[0, child]))
    if len(stamps) == 1:
        return [template.data()]
    patches: list[tuple[int, NDArray[np.generic]]] = [(start, stamps) for start in stamp_at]
    patches += [(start, poses[:, child]) for child, start in enumerate(pose_at)]
    messages = patched_copies(template.data(), len(stamps), patches)
    return [message.tobytes() for message in messages]


def controller_states_cdr(states: ControllerStates, distro: str) -> list[bytes]:
    """Return every cycle of `states` as CDR `messages.controller_state`, laid out for `distro`."""
    # Every message of a series has the same names and array lengths, so the same layout
    # and padding: one template, patched per cycle.
    template = CdrWriter()
    count = len(states.stamps_ns)
    times = time_array(states.times_from_start_ns)
    zeros = np.zeros(len(states.joint_names))
    patches: list[tuple[int, NDArray[np.generic]]] = []
    for kind, name in controller_state_fields(distro):
        if kind == "header":
            patches.append((template.time(0), time_array(states.stamps_ns)))
            template.string("")
        elif kind == "names":
            template.strings(states.joint_names if name == "joint_names" else ())
        elif kind == "point":
            series: PointSeries = getattr(states, POINT_SOURCES[name])
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


def _write_joint_trajectory(writer: CdrWriter, trajectory: JointTrajectory, frame_id: str) -> None:
    """Write the fields of `joint_trajectory(trajectory, frame_id)` to `writer`; return None."""
    writer.time(0)
    writer.string(frame_id)
    writer.strings(trajectory.joint_names)
    times_ns = [seconds_to_ns(t) for t in trajectory.times_s.tolist()]
    # A field the points do not carry is written empty, as the message came (JTC's degree follows it).
    none = np.empty((len(trajectory.times_s), 0))
    motion = (trajectory.positions, trajectory.velocities if trajectory.has_velocities else none,
              trajectory.accelerations if trajectory.has_accelerations else none)
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
