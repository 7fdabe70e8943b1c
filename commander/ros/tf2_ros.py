"""tf2_ros for a robot in memory: look transforms up between links and scene frames, publish static frames.

Frames are the robot's links (where the robot is now), the scene's static frames and the
planning frame. `StaticTransformBroadcaster.sendTransform` adds frames to the planning scene,
as `static_transform_publisher` does for MoveIt; pose targets may then name them. There is
no time: transforms are the latest (ROS's `rospy.Time(0)`), and a lookup never waits.
tf2's exceptions are moveplan's FrameNotFound, so `except tf2_ros.LookupException` catches it.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from ...core.errors import FrameNotFound, MoveplanError, UsageError
from ...core.types import Frame
from .._targets import frame_name
from .._world import current_world
from ..conversions import matrix_to_pose, matrix_to_transform, pose_to_matrix, transform_to_matrix
from ..msgs import Header, PoseStamped, TransformStamped

__all__ = [
    "Buffer", "ConnectivityException", "ExtrapolationException", "LookupException", "StaticTransformBroadcaster",
    "TransformException", "TransformListener",
]

TransformException = MoveplanError
"""tf2's base exception: every moveplan error is one."""
LookupException = ConnectivityException = ExtrapolationException = FrameNotFound
"""tf2's lookup failures: a frame neither the robot nor the scene has."""


class Buffer:
    """The transforms between the robot's links (at its current state) and the planning scene's frames.

    Args:
        robot: The RobotCommander; None (or tf2's cache_time): the one created last.
    """

    def __init__(self, robot: Any = None, cache_time: Any = None, debug: bool = True) -> None:
        self.world = current_world(robot, "Buffer")

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any = None,
                         timeout: Any = None) -> TransformStamped:
        """Return the pose of `source_frame` in `target_frame` now (`target_T_source`), as a TransformStamped.

        Raises:
            FrameNotFound: A frame neither the robot nor the scene has; the message lists the known ones.
        """
        target = frame_name(target_frame, "lookup_transform: target_frame")
        source = frame_name(source_frame, "lookup_transform: source_frame")
        target_T_source = np.linalg.inv(self.world.pose(target)) @ self.world.pose(source)
        return TransformStamped(Header(frame_id=target_frame), source_frame, matrix_to_transform(target_T_source))

    def can_transform(self, target_frame: str, source_frame: str, time: Any = None, timeout: Any = None) -> bool:
        """Return True if both frames are known."""
        try:
            self.lookup_transform(target_frame, source_frame)
        except FrameNotFound:
            return False
        return True

    def transform(self, object_stamped: PoseStamped, target_frame: str, timeout: Any = None) -> PoseStamped:
        """Return a PoseStamped expressed in `target_frame` (tf2_geometry_msgs' do_transform_pose)."""
        if not isinstance(object_stamped, PoseStamped):
            raise UsageError(f"Buffer.transform: expected a PoseStamped, got {type(object_stamped).__name__}")
        source = frame_name(object_stamped.header.frame_id, "Buffer.transform: header.frame_id") \
            or self.world.robot(None).root_link
        target_T_source = transform_to_matrix(self.lookup_transform(target_frame, source).transform)
        pose = matrix_to_pose(target_T_source @ pose_to_matrix(object_stamped.pose, "Buffer.transform: pose"))
        return PoseStamped(Header(object_stamped.header.seq, object_stamped.header.stamp, target_frame), pose)

    def all_frames_as_string(self) -> str:
        """Return one line per frame: the robot's links, then the scene's frames with their parents."""
        lines = [f"Frame {link} exists" for link in self.world.robot(None).link_names]
        lines += [f"Frame {f.name} exists with parent {f.parent}." for f in self.world.frames.values()]
        return "\n".join(lines) + "\n"


class TransformListener:
    """tf2_ros.TransformListener: nothing to listen to, the Buffer holds everything already."""

    def __init__(self, buffer: Buffer, *args: Any, **kwargs: Any) -> None:
        self.buffer = buffer


class StaticTransformBroadcaster:
    """Adds static frames to the planning scene, as static_transform_publisher does.

    Args:
        target: A Buffer or RobotCommander; None: the robot created last.
    """

    def __init__(self, target: Any = None) -> None:
        self._world = current_world(target, "StaticTransformBroadcaster")

    def sendTransform(self, transform: TransformStamped | Iterable[TransformStamped]) -> None:  # noqa: N802
        """Add (or move) the frame `child_frame_id` at `transform` in `header.frame_id`; a list adds each; return None.

        Raises:
            UsageError: A transform without a child frame name, or an invalid rotation.
            ConfigError: A frame named as a robot link, or frames that form a loop.
            FrameNotFound: A parent frame that does not exist.
        """
        if not isinstance(transform, TransformStamped) and (isinstance(transform, str)
                                                             or not hasattr(transform, "__iter__")):
            raise UsageError(f"sendTransform: expected a TransformStamped or a list of them, got {transform!r}")
        transforms = [transform] if isinstance(transform, TransformStamped) else list(transform)
        frames = self._world.frames
        for item in transforms:
            if not isinstance(item, TransformStamped):
                raise UsageError(f"sendTransform: expected TransformStamped messages, got {type(item).__name__}")
            child = frame_name(item.child_frame_id, "sendTransform: child_frame_id")
            if not child:
                raise UsageError("sendTransform: a transform needs a child_frame_id")
            parent = frame_name(item.header.frame_id, f"sendTransform('{child}'): header.frame_id") \
                or self._world.robot(None).root_link
            matrix = transform_to_matrix(item.transform, f"sendTransform('{child}'): transform")
            frames.pop(child, None)  # a frame sent again moves: it goes last, after any parent sent with it
            frames[child] = Frame(child, parent, matrix)
        self._world.change(frames=frames)
