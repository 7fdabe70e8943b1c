"""ROS message types with ROS's field names, mutable as rospy's messages are; no ROS installation needed.

`pose.position.z += 0.1` works, `copy.deepcopy(pose)` copies, `==` compares field by field,
and constants are class attributes (`SolidPrimitive.BOX`). Fields default as ROS 1's do, except
`Quaternion.w`, which defaults to 1.0 (ROS 2's default: the identity, not an invalid rotation).
Times are ROS 1's: `secs` and `nsecs`, with `to_sec()`; `Time(1.5)` takes seconds as rospy's does.
`serialize(buff)` and `deserialize(data)` round-trip a message through bytes (JSON text, not
ROS's wire format: nothing but these classes reads it). The ROS packages' modules
(moveplan.commander.ros.moveit_msgs.msg, ...) hold these classes under their packages' names.
"""

from __future__ import annotations

import json
import math
import time
import typing
from dataclasses import dataclass, field, fields, is_dataclass
from typing import Any, ClassVar, Self

from ..core.errors import UsageError

__all__ = [
    "AllowedCollisionEntry", "AllowedCollisionMatrix", "AttachedCollisionObject", "BoundingVolume", "CollisionObject",
    "ColorRGBA", "Constraints", "DeserializationError", "DisplayTrajectory", "Duration", "FollowJointTrajectoryGoal",
    "Header", "JointConstraint", "JointState", "JointTolerance", "JointTrajectory", "JointTrajectoryPoint", "Marker",
    "MarkerArray", "Mesh", "MeshTriangle", "Message", "MoveItErrorCodes", "MultiDOFJointState",
    "MultiDOFJointTrajectory", "ObjectColor", "OrientationConstraint", "Plane", "PlanningScene",
    "PlanningSceneComponents", "PlanningSceneWorld", "Point", "PointStamped", "Pose", "PoseArray", "PoseStamped",
    "PositionConstraint", "Quaternion", "RobotState", "RobotTrajectory", "SolidPrimitive", "String", "Time",
    "Transform", "TransformStamped", "Twist", "Vector3", "plain",
]


class DeserializationError(UsageError):
    """genpy's: bytes that are not a serialized message of the type asked for."""


class Message:
    """What every message can do besides holding fields: serialize and deserialize itself (genpy.Message's)."""

    def __str__(self) -> str:
        """Return the message as YAML lines, field by field, as genpy prints one."""
        return "\n".join(_lines(self, 0))

    def serialize(self, buff: Any) -> None:
        """Write the message to `buff` (a file-like object such as io.BytesIO); return None."""
        buff.write(json.dumps(plain(self)).encode("utf-8"))

    def deserialize(self, data: bytes | str) -> Self:
        """Fill the message from bytes `serialize` wrote; return it.

        Raises:
            DeserializationError: The bytes are no serialized message of this type.
        """
        try:
            values = json.loads(data)
        except (TypeError, ValueError):
            raise DeserializationError(f"{type(self).__name__}.deserialize: not a serialized message") from None
        filled = _build(type(self), values, type(self).__name__)
        for item in fields(self):  # type: ignore[arg-type]
            setattr(self, item.name, getattr(filled, item.name))
        return self


def plain(value: Any) -> Any:
    """Return a message (or a field of one) as nested dicts and lists of plain values, as a YAML file holds it."""
    if is_dataclass(value) and not isinstance(value, type):
        return {f.name: plain(getattr(value, f.name)) for f in fields(value)}
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    if hasattr(value, "tolist"):  # a numpy array or scalar a script put in a field
        return value.tolist()
    return value


def _lines(message: Any, depth: int) -> list[str]:
    """Return a message's fields as YAML lines indented `depth` levels: nested messages below their field."""
    pad, out = "  " * depth, []
    for item in fields(message):
        value = getattr(message, item.name)
        if is_dataclass(value):
            out += [f"{pad}{item.name}:", *_lines(value, depth + 1)]
        elif isinstance(value, list) and value and is_dataclass(value[0]):
            out.append(f"{pad}{item.name}:")
            for element in value:
                out += [f"{pad}  -", *_lines(element, depth + 2)]
        else:
            out.append(f"{pad}{item.name}: {_scalar(value)}")
    return out


def _scalar(value: Any) -> str:
    """Return a field's value as YAML writes it: strings quoted, lists in brackets."""
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_scalar(v) for v in value) + "]"
    return str(value.tolist() if hasattr(value, "tolist") else value)


def _build(kind: Any, value: Any, where: str) -> Any:
    """Return `value` (from _plain) as an instance of the annotated type `kind`."""
    origin = typing.get_origin(kind)
    if origin is list:
        if not isinstance(value, list):
            raise DeserializationError(f"{where}: expected a list")
        (item,) = typing.get_args(kind)
        return [_build(item, v, f"{where}[{k}]") for k, v in enumerate(value)]
    if isinstance(kind, type) and is_dataclass(kind):
        if not isinstance(value, dict):
            raise DeserializationError(f"{where}: expected a {kind.__name__}")
        hints = typing.get_type_hints(kind)
        return kind(**{f.name: _build(hints[f.name], value[f.name], f"{where}.{f.name}")
                       for f in fields(kind) if f.init and f.name in value})
    return value


@dataclass
class Time(Message):
    """A point in time, as rospy.Time: whole seconds and nanoseconds (`Time(1.5)` takes seconds)."""

    secs: int = 0
    nsecs: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.secs, int):  # rospy.Time(1.5): seconds as a float
            if self.nsecs:
                raise UsageError(f"{type(self).__name__}({self.secs!r}, {self.nsecs!r}): seconds as a float take "
                                 "no nanoseconds")
            self.secs, self.nsecs = _split(_seconds(self.secs, type(self).__name__))

    @classmethod
    def from_sec(cls, seconds: float) -> Self:
        """Return the time `seconds` [s] after zero."""
        secs, nsecs = _split(_seconds(seconds, f"{cls.__name__}.from_sec"))
        return cls(secs, nsecs)

    @classmethod
    def now(cls) -> Self:
        """Return the script's clock now (rospy's: see moveplan.commander.ros.rospy.get_time)."""
        return cls.from_sec(clock())

    def to_sec(self) -> float:
        """Return the time in [s]."""
        return self.secs + self.nsecs * 1e-9

    def to_nsec(self) -> int:
        """Return the time in [ns]."""
        return self.secs * 1_000_000_000 + self.nsecs

    def is_zero(self) -> bool:
        """Return True for time zero."""
        return self.secs == 0 and self.nsecs == 0

    # genpy's arithmetic: time - time is a duration, time +- duration a time, durations add and scale.
    def __add__(self, other: Any) -> Any:
        if not isinstance(other, Duration):
            return NotImplemented
        return type(self)(*_split_ns(self.to_nsec() + other.to_nsec()))

    def __sub__(self, other: Any) -> Any:
        if not isinstance(other, Time):
            return NotImplemented
        kind = Duration if type(other) is Time or isinstance(self, Duration) else type(self)
        return kind(*_split_ns(self.to_nsec() - other.to_nsec()))

    def __lt__(self, other: Any) -> bool:
        return self.to_nsec() < _nsec(other)

    def __le__(self, other: Any) -> bool:
        return self.to_nsec() <= _nsec(other)

    def __gt__(self, other: Any) -> bool:
        return self.to_nsec() > _nsec(other)

    def __ge__(self, other: Any) -> bool:
        return self.to_nsec() >= _nsec(other)


@dataclass
class Duration(Time):
    """A length of time, as rospy.Duration: whole seconds and nanoseconds (`Duration(0.5)` takes seconds)."""

    def __mul__(self, factor: float) -> Duration:
        return Duration(*_split_ns(int(round(self.to_nsec() * float(factor)))))

    __rmul__ = __mul__

    def __neg__(self) -> Duration:
        return Duration(*_split_ns(-self.to_nsec()))


def _split_ns(total: int) -> tuple[int, int]:
    """Return whole seconds and nanoseconds (0 <= nsecs < 1e9) of `total` [ns]."""
    return total // 1_000_000_000, total % 1_000_000_000


def _nsec(value: Any) -> int:
    """Return a Time or Duration in [ns] for comparisons; a number of seconds too."""
    return value.to_nsec() if isinstance(value, Time) else int(round(float(value) * 1e9))


def _seconds(value: Any, where: str) -> float:
    """Return `value` as finite seconds, else raise UsageError naming `where`."""
    try:
        seconds = float(value)
    except (TypeError, ValueError):
        raise UsageError(f"{where}: expected seconds, got {value!r}") from None
    if not math.isfinite(seconds):
        raise UsageError(f"{where}: expected a finite number of seconds, got {value!r}")
    return seconds


def _split(seconds: float) -> tuple[int, int]:
    """Return whole seconds and nanoseconds of `seconds`, nanoseconds rounded."""
    return _split_ns(int(round(seconds * 1e9)))


_CLOCK = [time.time()]  # the script's clock [s]: wall time at start, then advanced by rospy.sleep


def clock() -> float:
    """Return the script's clock in [s]: where it started plus every sleep (nothing waits for real)."""
    return _CLOCK[0]


def advance_clock(seconds: float) -> None:
    """Move the script's clock `seconds` [s] on; return None."""
    _CLOCK[0] += max(0.0, seconds)


# std_msgs ---------------------------------------------------------------------------------------


@dataclass
class Header(Message):
    """std_msgs/Header: a sequence number, a time stamp and a frame."""

    seq: int = 0
    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
class String(Message):
    """std_msgs/String."""

    data: str = ""


@dataclass
class ColorRGBA(Message):
    """std_msgs/ColorRGBA, each in [0, 1]."""

    r: float = 0.0
    g: float = 0.0
    b: float = 0.0
    a: float = 0.0


# geometry_msgs ----------------------------------------------------------------------------------


@dataclass
class Point(Message):
    """geometry_msgs/Point, in [m]."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


@dataclass
class Vector3(Message):
    """geometry_msgs/Vector3."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


@dataclass
class Quaternion(Message):
    """geometry_msgs/Quaternion (x, y, z, w); the default is the identity."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    w: float = 1.0


@dataclass
class Pose(Message):
    """geometry_msgs/Pose: a position and an orientation."""

    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class PoseStamped(Message):
    """geometry_msgs/PoseStamped: a pose in the frame `header.frame_id`."""

    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)


@dataclass
class PoseArray(Message):
    """geometry_msgs/PoseArray: poses in the frame `header.frame_id`."""

    header: Header = field(default_factory=Header)
    poses: list[Pose] = field(default_factory=list)


@dataclass
class PointStamped(Message):
    """geometry_msgs/PointStamped: a point in the frame `header.frame_id`."""

    header: Header = field(default_factory=Header)
    point: Point = field(default_factory=Point)


@dataclass
class Transform(Message):
    """geometry_msgs/Transform: a translation and a rotation."""

    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@dataclass
class TransformStamped(Message):
    """geometry_msgs/TransformStamped: the pose of `child_frame_id` in `header.frame_id`."""

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    transform: Transform = field(default_factory=Transform)


@dataclass
class Twist(Message):
    """geometry_msgs/Twist: linear and angular velocity."""

    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


# sensor_msgs, trajectory_msgs ---------------------------------------------------------------------


@dataclass
class JointState(Message):
    """sensor_msgs/JointState: per joint name a position, and optionally a velocity and an effort."""

    header: Header = field(default_factory=Header)
    name: list[str] = field(default_factory=list)
    position: list[float] = field(default_factory=list)
    velocity: list[float] = field(default_factory=list)
    effort: list[float] = field(default_factory=list)


@dataclass
class MultiDOFJointState(Message):
    """sensor_msgs/MultiDOFJointState: planar and floating joints (moveplan's robots have none moving)."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    transforms: list[Transform] = field(default_factory=list)
    twist: list[Twist] = field(default_factory=list)
    wrench: list[Any] = field(default_factory=list)


@dataclass
class JointTrajectoryPoint(Message):
    """trajectory_msgs/JointTrajectoryPoint: one point, in the trajectory's joint order."""

    positions: list[float] = field(default_factory=list)
    velocities: list[float] = field(default_factory=list)
    accelerations: list[float] = field(default_factory=list)
    effort: list[float] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


@dataclass
class JointTrajectory(Message):
    """trajectory_msgs/JointTrajectory: joint names and timed points."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    points: list[JointTrajectoryPoint] = field(default_factory=list)


@dataclass
class MultiDOFJointTrajectory(Message):
    """trajectory_msgs/MultiDOFJointTrajectory (empty in every moveplan plan: no planar or floating joint moves)."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    points: list[Any] = field(default_factory=list)


# shape_msgs -----------------------------------------------------------------------------------------


@dataclass
class SolidPrimitive(Message):
    """shape_msgs/SolidPrimitive: `type` one of the constants, `dimensions` indexed by the *_X... constants, in [m]."""

    BOX: ClassVar[int] = 1
    SPHERE: ClassVar[int] = 2
    CYLINDER: ClassVar[int] = 3
    CONE: ClassVar[int] = 4
    BOX_X: ClassVar[int] = 0
    BOX_Y: ClassVar[int] = 1
    BOX_Z: ClassVar[int] = 2
    SPHERE_RADIUS: ClassVar[int] = 0
    CYLINDER_HEIGHT: ClassVar[int] = 0
    CYLINDER_RADIUS: ClassVar[int] = 1
    CONE_HEIGHT: ClassVar[int] = 0
    CONE_RADIUS: ClassVar[int] = 1

    type: int = 0
    dimensions: list[float] = field(default_factory=list)


@dataclass
class MeshTriangle(Message):
    """shape_msgs/MeshTriangle: three indices into the mesh's vertices."""

    vertex_indices: list[int] = field(default_factory=lambda: [0, 0, 0])


@dataclass
class Mesh(Message):
    """shape_msgs/Mesh: triangles over vertices, in [m]."""

    triangles: list[MeshTriangle] = field(default_factory=list)
    vertices: list[Point] = field(default_factory=list)


@dataclass
class Plane(Message):
    """shape_msgs/Plane: ax + by + cz + d = 0, `coef` [a, b, c, d]."""

    coef: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0, 0.0])


# moveit_msgs -------------------------------------------------------------------------------------------


@dataclass
class CollisionObject(Message):
    """moveit_msgs/CollisionObject: shapes at poses relative to `pose`, in `header.frame_id`; `operation` what to do."""

    ADD: ClassVar[int] = 0
    REMOVE: ClassVar[int] = 1
    APPEND: ClassVar[int] = 2
    MOVE: ClassVar[int] = 3

    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)
    id: str = ""
    type: Any = None
    primitives: list[SolidPrimitive] = field(default_factory=list)
    primitive_poses: list[Pose] = field(default_factory=list)
    meshes: list[Mesh] = field(default_factory=list)
    mesh_poses: list[Pose] = field(default_factory=list)
    planes: list[Plane] = field(default_factory=list)
    plane_poses: list[Pose] = field(default_factory=list)
    subframe_names: list[str] = field(default_factory=list)
    subframe_poses: list[Pose] = field(default_factory=list)
    operation: int = 0


@dataclass
class AttachedCollisionObject(Message):
    """moveit_msgs/AttachedCollisionObject: an object carried by `link_name`; `touch_links` may touch it."""

    link_name: str = ""
    object: CollisionObject = field(default_factory=CollisionObject)
    touch_links: list[str] = field(default_factory=list)
    detach_posture: JointTrajectory = field(default_factory=JointTrajectory)
    weight: float = 0.0


@dataclass
class RobotState(Message):
    """moveit_msgs/RobotState: joint positions, multi-DOF joints (none move here) and attached objects."""

    joint_state: JointState = field(default_factory=JointState)
    multi_dof_joint_state: MultiDOFJointState = field(default_factory=MultiDOFJointState)
    attached_collision_objects: list[AttachedCollisionObject] = field(default_factory=list)
    is_diff: bool = False


@dataclass
class RobotTrajectory(Message):
    """moveit_msgs/RobotTrajectory: what plan() returns and execute() takes."""

    joint_trajectory: JointTrajectory = field(default_factory=JointTrajectory)
    multi_dof_joint_trajectory: MultiDOFJointTrajectory = field(default_factory=MultiDOFJointTrajectory)


@dataclass
class JointTolerance(Message):
    """control_msgs/JointTolerance: > 0 replaces the controller's tolerance, 0 keeps it, -1 erases it."""

    name: str = ""
    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass
class FollowJointTrajectoryGoal(Message):
    """control_msgs/FollowJointTrajectoryGoal: a trajectory and the tolerances the controller applies to it."""

    trajectory: JointTrajectory = field(default_factory=JointTrajectory)
    path_tolerance: list[JointTolerance] = field(default_factory=list)
    goal_tolerance: list[JointTolerance] = field(default_factory=list)
    goal_time_tolerance: Duration = field(default_factory=Duration)


@dataclass
class DisplayTrajectory(Message):
    """moveit_msgs/DisplayTrajectory: trajectories for RViz to show, from `trajectory_start`."""

    model_id: str = ""
    trajectory: list[RobotTrajectory] = field(default_factory=list)
    trajectory_start: RobotState = field(default_factory=RobotState)


@dataclass
class BoundingVolume(Message):
    """moveit_msgs/BoundingVolume: a region, the union of its shapes at their poses."""

    primitives: list[SolidPrimitive] = field(default_factory=list)
    primitive_poses: list[Pose] = field(default_factory=list)
    meshes: list[Mesh] = field(default_factory=list)
    mesh_poses: list[Pose] = field(default_factory=list)


@dataclass
class JointConstraint(Message):
    """moveit_msgs/JointConstraint: `joint_name` within [position - tolerance_below, position + tolerance_above]."""

    joint_name: str = ""
    position: float = 0.0
    tolerance_above: float = 0.0
    tolerance_below: float = 0.0
    weight: float = 0.0


@dataclass
class PositionConstraint(Message):
    """moveit_msgs/PositionConstraint: a point of `link_name` (`target_point_offset`) within `constraint_region`."""

    header: Header = field(default_factory=Header)
    link_name: str = ""
    target_point_offset: Vector3 = field(default_factory=Vector3)
    constraint_region: BoundingVolume = field(default_factory=BoundingVolume)
    weight: float = 0.0


@dataclass
class OrientationConstraint(Message):
    """moveit_msgs/OrientationConstraint: `link_name` oriented as `orientation` within the axis tolerances [rad]."""

    XYZ_EULER_ANGLES: ClassVar[int] = 0
    ROTATION_VECTOR: ClassVar[int] = 1

    header: Header = field(default_factory=Header)
    orientation: Quaternion = field(default_factory=Quaternion)
    link_name: str = ""
    absolute_x_axis_tolerance: float = 0.0
    absolute_y_axis_tolerance: float = 0.0
    absolute_z_axis_tolerance: float = 0.0
    parameterization: int = 0
    weight: float = 0.0


@dataclass
class Constraints(Message):
    """moveit_msgs/Constraints: what every state of a path (or the goal) must satisfy, all of it."""

    name: str = ""
    joint_constraints: list[JointConstraint] = field(default_factory=list)
    position_constraints: list[PositionConstraint] = field(default_factory=list)
    orientation_constraints: list[OrientationConstraint] = field(default_factory=list)
    visibility_constraints: list[Any] = field(default_factory=list)


@dataclass
class AllowedCollisionEntry(Message):
    """moveit_msgs/AllowedCollisionEntry: per entry name of the matrix, whether a collision is allowed."""

    enabled: list[bool] = field(default_factory=list)


@dataclass
class AllowedCollisionMatrix(Message):
    """moveit_msgs/AllowedCollisionMatrix, with moveit_commander's `set_default` and `set_allowed`."""

    entry_names: list[str] = field(default_factory=list)
    entry_values: list[AllowedCollisionEntry] = field(default_factory=list)
    default_entry_names: list[str] = field(default_factory=list)
    default_entry_values: list[bool] = field(default_factory=list)

    def set_default(self, obj: str, allow: bool) -> None:
        """Allow (or not) collisions of `obj` with anything; return None (moveit_commander's acm_set_default)."""
        if obj in self.default_entry_names:
            self.default_entry_values[self.default_entry_names.index(obj)] = allow
        else:
            self.default_entry_names.append(obj)
            self.default_entry_values.append(allow)

    def set_allowed(self, obj: str, other: str | None = None, allow: bool = True) -> None:
        """Allow (or not) collisions between `obj` and `other` (None: anything); return None (acm_set_allowed)."""
        if other is None:
            self.set_default(obj, allow)
            return
        for name in (other, obj):
            if name not in self.entry_names:
                default = dict(zip(self.default_entry_names, self.default_entry_values, strict=True))
                value = default.get(name)
                enabled = [value if value is not None else default.get(n, False) for n in self.entry_names]
                self.entry_names.append(name)
                self.entry_values.append(AllowedCollisionEntry(enabled))
                for entry, allowed in zip(self.entry_values, [*enabled, False], strict=True):
                    entry.enabled.append(allowed)
        i, j = self.entry_names.index(obj), self.entry_names.index(other)
        self.entry_values[i].enabled[j] = self.entry_values[j].enabled[i] = allow


@dataclass
class ObjectColor(Message):
    """moveit_msgs/ObjectColor: the color RViz draws object `id` in."""

    id: str = ""
    color: ColorRGBA = field(default_factory=ColorRGBA)


@dataclass
class PlanningSceneWorld(Message):
    """moveit_msgs/PlanningSceneWorld: the world's collision objects (no octomap here)."""

    collision_objects: list[CollisionObject] = field(default_factory=list)
    octomap: Any = None


@dataclass
class PlanningScene(Message):
    """moveit_msgs/PlanningScene: the whole scene, or with `is_diff` a change to it."""

    name: str = ""
    robot_state: RobotState = field(default_factory=RobotState)
    robot_model_name: str = ""
    fixed_frame_transforms: list[TransformStamped] = field(default_factory=list)
    allowed_collision_matrix: AllowedCollisionMatrix = field(default_factory=AllowedCollisionMatrix)
    link_padding: list[Any] = field(default_factory=list)
    link_scale: list[Any] = field(default_factory=list)
    object_colors: list[ObjectColor] = field(default_factory=list)
    world: PlanningSceneWorld = field(default_factory=PlanningSceneWorld)
    is_diff: bool = False


@dataclass
class PlanningSceneComponents(Message):
    """moveit_msgs/PlanningSceneComponents: which parts of the scene get_planning_scene fills (a bit mask)."""

    SCENE_SETTINGS: ClassVar[int] = 1
    ROBOT_STATE: ClassVar[int] = 2
    ROBOT_STATE_ATTACHED_OBJECTS: ClassVar[int] = 4
    WORLD_OBJECT_NAMES: ClassVar[int] = 8
    WORLD_OBJECT_GEOMETRY: ClassVar[int] = 16
    OCTOMAP: ClassVar[int] = 32
    TRANSFORMS: ClassVar[int] = 64
    ALLOWED_COLLISION_MATRIX: ClassVar[int] = 128
    LINK_PADDING_AND_SCALING: ClassVar[int] = 256
    OBJECT_COLORS: ClassVar[int] = 512

    components: int = 0


@dataclass
class MoveItErrorCodes(Message):
    """moveit_msgs/MoveItErrorCodes: `val` is one of the constants; `message` says why."""

    SUCCESS: ClassVar[int] = 1
    UNDEFINED: ClassVar[int] = 0
    FAILURE: ClassVar[int] = 99999
    PLANNING_FAILED: ClassVar[int] = -1
    INVALID_MOTION_PLAN: ClassVar[int] = -2
    MOTION_PLAN_INVALIDATED_BY_ENVIRONMENT_CHANGE: ClassVar[int] = -3
    CONTROL_FAILED: ClassVar[int] = -4
    UNABLE_TO_AQUIRE_SENSOR_DATA: ClassVar[int] = -5
    TIMED_OUT: ClassVar[int] = -6
    PREEMPTED: ClassVar[int] = -7
    START_STATE_IN_COLLISION: ClassVar[int] = -10
    START_STATE_VIOLATES_PATH_CONSTRAINTS: ClassVar[int] = -11
    GOAL_IN_COLLISION: ClassVar[int] = -12
    GOAL_VIOLATES_PATH_CONSTRAINTS: ClassVar[int] = -13
    GOAL_CONSTRAINTS_VIOLATED: ClassVar[int] = -14
    INVALID_GROUP_NAME: ClassVar[int] = -15
    INVALID_GOAL_CONSTRAINTS: ClassVar[int] = -16
    INVALID_ROBOT_STATE: ClassVar[int] = -17
    INVALID_LINK_NAME: ClassVar[int] = -18
    INVALID_OBJECT_NAME: ClassVar[int] = -19
    FRAME_TRANSFORM_FAILURE: ClassVar[int] = -21
    COLLISION_CHECKING_UNAVAILABLE: ClassVar[int] = -22
    ROBOT_STATE_STALE: ClassVar[int] = -23
    SENSOR_INFO_STALE: ClassVar[int] = -24
    COMMUNICATION_FAILURE: ClassVar[int] = -25
    START_STATE_INVALID: ClassVar[int] = -26
    GOAL_STATE_INVALID: ClassVar[int] = -27
    UNRECOGNIZED_GOAL_TYPE: ClassVar[int] = -28
    CRASH: ClassVar[int] = -29
    ABORT: ClassVar[int] = -30
    NO_IK_SOLUTION: ClassVar[int] = -31

    val: int = 0
    message: str = ""
    source: str = ""


# visualization_msgs -------------------------------------------------------------------------------------


@dataclass
class Marker(Message):
    """visualization_msgs/Marker: a shape for RViz to draw (kept, drawn nowhere)."""

    ARROW: ClassVar[int] = 0
    CUBE: ClassVar[int] = 1
    SPHERE: ClassVar[int] = 2
    CYLINDER: ClassVar[int] = 3
    LINE_STRIP: ClassVar[int] = 4
    LINE_LIST: ClassVar[int] = 5
    CUBE_LIST: ClassVar[int] = 6
    SPHERE_LIST: ClassVar[int] = 7
    POINTS: ClassVar[int] = 8
    TEXT_VIEW_FACING: ClassVar[int] = 9
    MESH_RESOURCE: ClassVar[int] = 10
    TRIANGLE_LIST: ClassVar[int] = 11
    ADD: ClassVar[int] = 0
    MODIFY: ClassVar[int] = 0
    DELETE: ClassVar[int] = 2
    DELETEALL: ClassVar[int] = 3

    header: Header = field(default_factory=Header)
    ns: str = ""
    id: int = 0
    type: int = 0
    action: int = 0
    pose: Pose = field(default_factory=Pose)
    scale: Vector3 = field(default_factory=Vector3)
    color: ColorRGBA = field(default_factory=ColorRGBA)
    lifetime: Duration = field(default_factory=Duration)
    frame_locked: bool = False
    points: list[Point] = field(default_factory=list)
    colors: list[ColorRGBA] = field(default_factory=list)
    text: str = ""
    mesh_resource: str = ""
    mesh_use_embedded_materials: bool = False


@dataclass
class MarkerArray(Message):
    """visualization_msgs/MarkerArray."""

    markers: list[Marker] = field(default_factory=list)
