"""Value types shared across core: trajectories, scene geometry, plans and recorded joint states.

Arrays are copied, shape-checked and made read-only on construction, so a value
cannot change after it has been checked.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from .rotations import quaternion_from_matrix, rpy_from_matrix

__all__ = [
    "ControllerStates",
    "PointSeries",
    "CollisionObject",
    "Frame",
    "GoalTolerances",
    "JointStateSeries",
    "JointTolerance",
    "JointTrajectory",
    "LinkPose",
    "Plan",
    "RobotState",
    "Shape",
    "SkippedData",
    "StepResult",
    "TfSamples",
    "TimeSource",
    "frozen_array",
]


def frozen_array(value: npt.ArrayLike, shape: tuple[int | None, ...], name: str) -> NDArray[np.float64]:
    """Return a read-only float64 copy of `value`, checked against `shape` (None = any size)."""
    array = np.array(value, dtype=np.float64)
    if array.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(array.shape, shape, strict=True)
    ):
        raise ValueError(f"{name}: expected shape {shape}, got {array.shape}")
    array.setflags(write=False)
    return array


@dataclass(frozen=True)
class JointTrajectory:
    """Timed joint trajectory, one row per point, like trajectory_msgs/JointTrajectory.

    Attributes:
        joint_names: Joint order of the columns.
        times_s: Time from start of each point in [s], strictly increasing, first 0.
        positions: Joint positions in [rad] or [m], shape (N, n).
        velocities: In [rad]/[s], shape (N, n); zeros where `has_velocities` is False.
        accelerations: In [rad]/[s]^2, shape (N, n); zeros where `has_accelerations` is False.
        has_velocities: False for a message whose points carry no velocities (JTC then
            interpolates linearly).
        has_accelerations: False for points without accelerations (JTC: cubic with velocities).
    """

    joint_names: tuple[str, ...]
    times_s: NDArray[np.float64]
    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    accelerations: NDArray[np.float64]
    has_velocities: bool = field(default=True, kw_only=True)
    has_accelerations: bool = field(default=True, kw_only=True)

    def __post_init__(self) -> None:
        n = len(self.joint_names)
        times = frozen_array(self.times_s, (None,), "times_s")
        count = len(times)
        object.__setattr__(self, "joint_names", tuple(self.joint_names))
        object.__setattr__(self, "times_s", times)
        for name in ("positions", "velocities", "accelerations"):
            object.__setattr__(self, name, frozen_array(getattr(self, name), (count, n), name))
        if count == 0:
            raise ValueError("a trajectory needs at least one point")
        if np.any(np.diff(times) <= 0.0):
            raise ValueError("trajectory times must be strictly increasing")

    @property
    def duration_s(self) -> float:
        """Return the time of the last point in [s]."""
        return float(self.times_s[-1])


TimeSource = Literal["header", "log"]


@dataclass(frozen=True)
class JointStateSeries:
    """Joint positions (and velocities) recorded on one topic, in a chosen joint order.

    Arrays are read-only. Read-only float64 arrays given to the constructor are kept as
    they are (an hour at 1 kHz is 170 MB per array); any other input is copied.

    Attributes:
        names: Joint order of the columns.
        times_s: Sample times in [s] from the first sample, non-decreasing, shape (N,).
        positions: In [rad] or [m], shape (N, n).
        velocities: In [rad]/[s] or [m]/[s], shape (N, n); None when the messages carry none.
        start_ns: Time of the first sample in [ns] (header stamp or log time), so
            `start_ns + times_s * 1e9` are the recorded times.
        time_source: "header" (the messages' header.stamp) or "log" (MCAP log time).
        source: The file or folder read, for messages.

    """

    names: tuple[str, ...]
    times_s: NDArray[np.float64]
    positions: NDArray[np.float64]
    velocities: NDArray[np.float64] | None
    start_ns: int
    time_source: TimeSource = "header"
    source: str = ""

    def __post_init__(self) -> None:
        """Check shapes and order, and freeze the arrays."""
        object.__setattr__(self, "names", tuple(self.names))
        times = _kept_frozen(self.times_s, (None,), "times_s")
        object.__setattr__(self, "times_s", times)
        shape = (len(times), len(self.names))
        object.__setattr__(self, "positions", _kept_frozen(self.positions, shape, "positions"))
        if self.velocities is not None:
            velocities = _kept_frozen(self.velocities, shape, "velocities")
            object.__setattr__(self, "velocities", velocities)
        if np.any(np.diff(times) < 0.0):
            raise ValueError("times_s must be non-decreasing")


def _kept_frozen(
    value: npt.ArrayLike, shape: tuple[int | None, ...], name: str
) -> NDArray[np.float64]:
    """Return `value` itself if it is a read-only float64 array of `shape`, else frozen_array's."""
    if (
        isinstance(value, np.ndarray) and value.dtype == np.float64 and not value.flags.writeable
        and value.ndim == len(shape)
        and all(want in (None, got) for got, want in zip(value.shape, shape, strict=True))
    ):
        return value
    return frozen_array(value, shape, name)


@dataclass(frozen=True)
class Frame:
    """A static transform `parent_T_frame`, like one static_transform_publisher."""

    name: str
    parent: str
    transform: NDArray[np.float64]

    def __post_init__(self) -> None:
        object.__setattr__(self, "transform", frozen_array(self.transform, (4, 4), "transform"))


@dataclass(frozen=True)
class Shape:
    """Collision shape in its own frame, sizes in [m].

    box: dims = (x, y, z) full sizes; cylinder: dims = (radius, length) along local z;
    sphere: dims = (radius,); mesh: `mesh_path` with `scale` (sx, sy, sz), or, for a mesh
    given inline (a shape_msgs/Mesh), `vertices` (N, 3) in [m] and `triangles` (M, 3),
    indices into `vertices`, with `mesh_path` empty. Both arrays are read-only.
    """

    kind: Literal["box", "cylinder", "sphere", "mesh"]
    dims: tuple[float, ...] = ()
    mesh_path: str = ""
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    vertices: NDArray[np.float64] | None = None
    triangles: NDArray[np.int64] | None = None

    def __post_init__(self) -> None:
        """Check and freeze an inline mesh's arrays."""
        if self.vertices is None and self.triangles is None:
            return
        if self.kind != "mesh" or self.mesh_path or self.vertices is None or self.triangles is None:
            raise ValueError("an inline mesh is kind 'mesh' with vertices and triangles and no mesh_path")
        vertices = frozen_array(self.vertices, (None, 3), "vertices")
        triangles = np.array(self.triangles, dtype=np.int64)
        if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) == 0:
            raise ValueError(f"triangles: expected shape (M, 3) with M > 0, got {triangles.shape}")
        if triangles.min() < 0 or triangles.max() >= len(vertices):
            raise ValueError(f"triangles: indices must lie in [0, {len(vertices) - 1}]")
        triangles.setflags(write=False)
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "triangles", triangles)


@dataclass(frozen=True)
class CollisionObject:
    """A world collision object, placed in the planning frame (`planning_T_object`).

    `link` is set for objects attached to a robot link; then `transform` is
    `link_T_object` and `touch_links` may touch it.
    """

    name: str
    shape: Shape
    transform: NDArray[np.float64]
    link: str = ""
    touch_links: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "transform", frozen_array(self.transform, (4, 4), "transform"))


@dataclass(frozen=True)
class TfSamples:
    """Poses of moving links along a plan, for /tf playback.

    Attributes:
        times_s: Sample times on the plan's timeline in [s], shape (M,).
        parents: Parent frame of each transform, length L.
        children: Child frame of each transform, length L.
        poses: `parent_T_child` per sample as /tf carries it, shape (M, L, 7): translation xyz in
            [m], then the rotation's unit quaternion xyzw (w >= 0).
    """

    times_s: NDArray[np.float64]
    parents: tuple[str, ...]
    children: tuple[str, ...]
    poses: NDArray[np.float64]

    def __post_init__(self) -> None:
        times = frozen_array(self.times_s, (None,), "times_s")
        object.__setattr__(self, "times_s", times)
        object.__setattr__(self, "poses", frozen_array(self.poses, (len(times), len(self.children), 7), "poses"))


@dataclass(frozen=True)
class JointTolerance:
    """A control_msgs/JointTolerance: 0 = the controller's own, -1 = erased (not checked), > 0 = this one.

    In [rad] (or [m]), [rad]/[s] and [rad]/[s]^2.
    """

    name: str
    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass(frozen=True)
class GoalTolerances:
    """The tolerances a FollowJointTrajectory goal carries, replacing the controller's for that goal.

    Attributes:
        path: path_tolerance, per joint.
        goal: goal_tolerance, per joint.
        goal_time_s: goal_time_tolerance in [s]: 0 = the controller's, -1 = erased.
    """

    path: tuple[JointTolerance, ...] = ()
    goal: tuple[JointTolerance, ...] = ()
    goal_time_s: float = 0.0

    def as_dict(self) -> dict[str, Any]:
        """Return the tolerances as a FollowJointTrajectory goal's fields (a task file's `tolerances`)."""
        def joints(items: tuple[JointTolerance, ...]) -> list[dict[str, Any]]:
            return [{"name": t.name, "position": t.position, "velocity": t.velocity, "acceleration": t.acceleration}
                    for t in items]
        return {"path_tolerance": joints(self.path), "goal_tolerance": joints(self.goal),
                "goal_time_tolerance": self.goal_time_s}


@dataclass(frozen=True)
class StepResult:
    """One planned motion: its goal as requested, how it was planned, and its trajectory."""

    name: str
    goal: dict[str, Any]
    planner: str
    planning_time_s: float
    trajectory: JointTrajectory
    fraction: float = 1.0
    residual: dict[str, float] | None = None
    stats: dict[str, float] = field(default_factory=dict)
    tolerances: GoalTolerances | None = None  # sent with the goal, replacing the controller's
    # The fractions of the velocity and acceleration limits its timing used; None: not timed by moveplan.
    scaling: tuple[float, float] | None = None


@dataclass(frozen=True)
class Plan:
    """A whole plan: steps in order plus everything needed to replay or check it.

    Attributes:
        robot_name: The robot's name (URDF / moveplan.yaml).
        group: Planning group.
        planning_frame: Root frame the scene and /tf are expressed in.
        steps: Planned steps; each step's trajectory starts at time 0.
        urdf: URDF text, written once to /robot_description.
        static_frames: Static transforms for /tf_static (scene frames, fixed robot joints).
        objects: Scene collision objects, for /planning_scene_markers.
        tf: Moving-link poses along the whole plan, for /tf.
        limits: Per joint, unscaled limits {"max_velocity": .., "max_acceleration": ..}.
        attachments: Config files to embed, file name -> bytes (SRDF, joint limits, controllers ...).
        metadata: Flat string map stored as MCAP metadata "moveplan" (seed, planner, version ...).
    """

    robot_name: str
    group: str
    planning_frame: str
    steps: tuple[StepResult, ...]
    urdf: str
    static_frames: tuple[Frame, ...] = ()
    objects: tuple[CollisionObject, ...] = ()
    tf: TfSamples | None = None
    limits: dict[str, dict[str, float]] = field(default_factory=dict)
    attachments: dict[str, bytes] = field(default_factory=dict)
    metadata: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class PointSeries:
    """A trajectory_msgs/JointTrajectoryPoint per cycle: each field (K, n), or None = left empty.

    As in JTC's state message, a field holds a value for every joint or is empty.
    """

    positions: NDArray[np.float64] | None = None
    velocities: NDArray[np.float64] | None = None
    accelerations: NDArray[np.float64] | None = None
    effort: NDArray[np.float64] | None = None

    def filled(self) -> list[NDArray[np.float64] | None]:
        """Return positions, velocities, accelerations, effort in message field order."""
        return [self.positions, self.velocities, self.accelerations, self.effort]


@dataclass(frozen=True)
class ControllerStates:
    """A JointTrajectoryController's state over K cycles, one JointTrajectoryControllerState each.

    Attributes:
        joint_names: The controller's joints, the column order of every array (n).
        stamps_ns: header.stamp of each cycle in [ns], shape (K,).
        times_from_start_ns: time_from_start of each cycle's points in [ns], shape (K,).
        reference, feedback, error, output: The message's points, fields (K, n) or None.

    """

    joint_names: tuple[str, ...]
    stamps_ns: NDArray[np.int64]
    times_from_start_ns: NDArray[np.int64]
    reference: PointSeries
    feedback: PointSeries
    error: PointSeries
    output: PointSeries

    def __post_init__(self) -> None:
        object.__setattr__(self, "joint_names", tuple(self.joint_names))
        stamps = np.array(self.stamps_ns, dtype=np.int64).reshape(-1)
        times = np.array(self.times_from_start_ns, dtype=np.int64).reshape(-1)
        if times.shape != stamps.shape:
            raise ValueError(
                f"times_from_start_ns: expected shape {stamps.shape}, got {times.shape}"
            )
        object.__setattr__(self, "stamps_ns", stamps)
        object.__setattr__(self, "times_from_start_ns", times)
        shape = (len(stamps), len(self.joint_names))
        for name in ("reference", "feedback", "error", "output"):
            series: PointSeries = getattr(self, name)
            checked = {
                field.name: frozen_array(value, shape, f"{name}.{field.name}")
                for field, value in zip(fields(series), series.filled(), strict=True)
                if value is not None
            }
            object.__setattr__(self, name, PointSeries(**checked))


@dataclass(frozen=True)
class LinkPose:
    """The pose of a link in a frame, as tf2's lookup_transform(frame, link) gives it.

    Attributes:
        link: The link (or scene frame) whose pose this is.
        frame: The frame it is expressed in.
        position: x, y, z in [m].
        quaternion: x, y, z, w (w >= 0), as geometry_msgs/Quaternion.
        rpy: Roll, pitch, yaw in [rad], fixed axes X-Y-Z as in URDF and tf's euler_from_quaternion.
    """

    link: str
    frame: str
    position: tuple[float, float, float]
    quaternion: tuple[float, float, float, float]
    rpy: tuple[float, float, float]

    @classmethod
    def of(cls, link: str, frame: str, frame_T_link: NDArray[np.float64]) -> LinkPose:
        """Return the pose a 4x4 transform `frame_T_link` holds."""
        rotation = frame_T_link[:3, :3]
        px, py, pz = (float(c) for c in frame_T_link[:3, 3])
        return cls(link, frame, (px, py, pz), quaternion_from_matrix(rotation), rpy_from_matrix(rotation))

    def as_dict(self) -> dict[str, object]:
        """Return the pose as the JSON documents give it: link, frame, position, quaternion, rpy."""
        return {"link": self.link, "frame": self.frame, "position": list(self.position),
                "quaternion": list(self.quaternion), "rpy": list(self.rpy)}


@dataclass(frozen=True)
class RobotState:
    """The planning group's joint values and one link's pose.

    Attributes:
        joints: Group joint -> value in [rad] (revolute, continuous) or [m] (prismatic), in group order.
        pose: The link's pose.
        prismatic: The group's joints whose values are in [m].
    """

    joints: dict[str, float]
    pose: LinkPose
    prismatic: tuple[str, ...] = ()

    def as_dict(self) -> dict[str, object]:
        """Return the state as the JSON documents give it: {"joints": {...}, "pose": {...}}."""
        return {"joints": dict(self.joints), "pose": self.pose.as_dict()}

    @classmethod
    def from_dict(cls, document: dict[str, Any], prismatic: tuple[str, ...] = ()) -> RobotState:
        """Return the state `as_dict` gave (KeyError, TypeError or ValueError if it is not one)."""
        pose = document["pose"]
        position, quaternion, rpy = (tuple(float(v) for v in pose[key]) for key in ("position", "quaternion", "rpy"))
        if len(position) != 3 or len(quaternion) != 4 or len(rpy) != 3:
            raise ValueError("a pose has 3 position, 4 quaternion and 3 rpy values")
        link_pose = LinkPose(str(pose["link"]), str(pose["frame"]), position, quaternion, rpy)
        return cls({str(j): float(v) for j, v in document["joints"].items()}, link_pose, prismatic)


@dataclass(frozen=True)
class SkippedData:
    """A damaged part of a recording that a read skipped, as asked (--skip-damaged).

    Attributes:
        file: The file it lies in.
        offset: Where it starts, in bytes from the start of the file.
        part: What it is: "chunk", "data section", "summary section", "attachment 'NAME'".
        reason: What is wrong with it: which check failed, with the numbers compared.
    """

    file: str
    offset: int
    part: str
    reason: str

    def as_dict(self) -> dict[str, object]:
        """Return it as the JSON documents give it: {"file", "offset", "part", "reason"}."""
        return {"file": self.file, "offset": self.offset, "part": self.part, "reason": self.reason}
