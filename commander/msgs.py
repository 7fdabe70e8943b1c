"""ROS message types with ROS's field names, mutable as rospy's messages are; no ROS installation needed.

`pose.position.z += 0.1` works, and `copy.deepcopy(pose)` copies. Fields default as ROS 1's do,
except `Quaternion.w`, which defaults to 1.0 (ROS 2's default: the identity, not an invalid
rotation). Times are ROS 1's: `secs` and `nsecs`, with `to_sec()`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, Self

__all__ = [
    "AttachedCollisionObject", "CollisionObject", "Duration", "Header", "JointState", "JointTrajectory",
    "JointTrajectoryPoint", "MoveItErrorCodes", "Point", "Pose", "PoseStamped", "Quaternion", "RobotState",
    "RobotTrajectory", "Time", "Transform", "TransformStamped", "Vector3",
]


@dataclass
class Time:
    """A point in time, as rospy.Time: whole seconds and nanoseconds."""

    secs: int = 0
    nsecs: int = 0

    @classmethod
    def from_sec(cls, seconds: float) -> Self:
        """Return the time `seconds` [s] after zero."""
        secs, nsecs = _split(seconds)
        return cls(secs, nsecs)

    def to_sec(self) -> float:
        """Return the time in [s]."""
        return self.secs + self.nsecs * 1e-9

    def to_nsec(self) -> int:
        """Return the time in [ns]."""
        return self.secs * 1_000_000_000 + self.nsecs


@dataclass
class Duration(Time):
    """A length of time, as rospy.Duration: whole seconds and nanoseconds."""


def _split(seconds: float) -> tuple[int, int]:
    """Return whole seconds and nanoseconds of `seconds`, nanoseconds rounded."""
    total = int(round(seconds * 1e9))
    return total // 1_000_000_000, total % 1_000_000_000


@dataclass
class Header:
    """std_msgs/Header: a sequence number, a time stamp and a frame."""

    seq: int = 0
    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
class Point:
    """geometry_msgs/Point, in [m]."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


@dataclass
class Vector3:
    """geometry_msgs/Vector3, in [m]."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


@dataclass
class Quaternion:
    """geometry_msgs/Quaternion (x, y, z, w); the default is the identity."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    w: float = 1.0


@dataclass
class Pose:
    """geometry_msgs/Pose: a position and an orientation."""

    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class PoseStamped:
    """geometry_msgs/PoseStamped: a pose in the frame `header.frame_id`."""

    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)


@dataclass
class Transform:
    """geometry_msgs/Transform: a translation and a rotation."""

    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@dataclass
class TransformStamped:
    """geometry_msgs/TransformStamped: the pose of `child_frame_id` in `header.frame_id`."""

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    transform: Transform = field(default_factory=Transform)


@dataclass
class JointState:
    """sensor_msgs/JointState: per joint name a position, and optionally a velocity and an effort."""

    header: Header = field(default_factory=Header)
    name: list[str] = field(default_factory=list)
    position: list[float] = field(default_factory=list)
    velocity: list[float] = field(default_factory=list)
    effort: list[float] = field(default_factory=list)


@dataclass
class RobotState:
    """moveit_msgs/RobotState: the joint state (this robot has no multi-DOF joint state)."""

    joint_state: JointState = field(default_factory=JointState)
    is_diff: bool = False


@dataclass
class JointTrajectoryPoint:
    """trajectory_msgs/JointTrajectoryPoint: one point, in the trajectory's joint order."""

    positions: list[float] = field(default_factory=list)
    velocities: list[float] = field(default_factory=list)
    accelerations: list[float] = field(default_factory=list)
    effort: list[float] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


@dataclass
class JointTrajectory:
    """trajectory_msgs/JointTrajectory: joint names and timed points."""

    header: Header = field(default_factory=Header)
    joint_names: list[str] = field(default_factory=list)
    points: list[JointTrajectoryPoint] = field(default_factory=list)


@dataclass
class RobotTrajectory:
    """moveit_msgs/RobotTrajectory: what plan() returns and execute() takes."""

    joint_trajectory: JointTrajectory = field(default_factory=JointTrajectory)


@dataclass
class CollisionObject:
    """moveit_msgs/CollisionObject, as the planning scene reports one: its id and its pose in `header.frame_id`."""

    ADD: ClassVar[int] = 0
    REMOVE: ClassVar[int] = 1

    header: Header = field(default_factory=Header)
    id: str = ""
    pose: Pose = field(default_factory=Pose)
    operation: int = 0


@dataclass
class AttachedCollisionObject:
    """moveit_msgs/AttachedCollisionObject: an object carried by `link_name`; `touch_links` may touch it."""

    link_name: str = ""
    object: CollisionObject = field(default_factory=CollisionObject)
    touch_links: list[str] = field(default_factory=list)


@dataclass
class MoveItErrorCodes:
    """moveit_msgs/MoveItErrorCodes: `val` is one of the constants; `message` says why."""

    SUCCESS: ClassVar[int] = 1
    UNDEFINED: ClassVar[int] = 0
    FAILURE: ClassVar[int] = 99999
    PLANNING_FAILED: ClassVar[int] = -1
    INVALID_MOTION_PLAN: ClassVar[int] = -2
    CONTROL_FAILED: ClassVar[int] = -4
    TIMED_OUT: ClassVar[int] = -6
    START_STATE_IN_COLLISION: ClassVar[int] = -10
    GOAL_IN_COLLISION: ClassVar[int] = -12
    GOAL_CONSTRAINTS_VIOLATED: ClassVar[int] = -14
    INVALID_GROUP_NAME: ClassVar[int] = -15
    FRAME_TRANSFORM_FAILURE: ClassVar[int] = -21
    START_STATE_INVALID: ClassVar[int] = -26
    GOAL_STATE_INVALID: ClassVar[int] = -27
    NO_IK_SOLUTION: ClassVar[int] = -31

    val: int = 0
    message: str = ""
    source: str = ""
