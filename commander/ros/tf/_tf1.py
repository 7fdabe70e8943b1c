"""ROS 1's tf (tf1) listener and broadcaster, as MoveIt 1 scripts use them, over moveplan's tf2_ros."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ...conversions import transform_to_list
from ...msgs import Header, PoseStamped, Time, TransformStamped
from .. import tf2_ros

__all__ = ["ConnectivityException", "Exception", "ExtrapolationException", "LookupException", "TransformBroadcaster",
           "TransformListener"]

Exception = tf2_ros.TransformException  # noqa: A001 (tf's name)
LookupException = ConnectivityException = ExtrapolationException = tf2_ros.LookupException


class TransformListener:
    """tf.TransformListener: transforms between the robot's links (where it is now) and the scene's frames."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._buffer = tf2_ros.Buffer()

    def lookupTransform(self, target_frame: str, source_frame: str, time: Any = None,  # noqa: N802 (tf's name)
                        ) -> tuple[list[float], list[float]]:
        """Return ([x, y, z], [qx, qy, qz, qw]): the pose of `source_frame` in `target_frame`, now."""
        values = transform_to_list(self._buffer.lookup_transform(target_frame, source_frame).transform)
        return values[:3], values[3:]

    def waitForTransform(self, target_frame: str, source_frame: str, time: Any = None,  # noqa: N802
                         timeout: Any = None, polling_sleep_duration: Any = None) -> None:
        """Return at once if both frames are known (nothing arrives later), else raise LookupException."""
        self._buffer.lookup_transform(target_frame, source_frame)

    def canTransform(self, target_frame: str, source_frame: str, time: Any = None) -> bool:  # noqa: N802
        """Return True if both frames are known."""
        return self._buffer.can_transform(target_frame, source_frame)

    def frameExists(self, frame_id: str) -> bool:  # noqa: N802
        """Return True if the frame is a robot link or a scene frame."""
        return self._buffer.can_transform(frame_id, frame_id)

    def getLatestCommonTime(self, source_frame: str, target_frame: str) -> Time:  # noqa: N802
        """Return time zero: every transform is the latest."""
        return Time()

    def transformPose(self, target_frame: str, ps: PoseStamped) -> PoseStamped:  # noqa: N802
        """Return a PoseStamped expressed in `target_frame`."""
        return self._buffer.transform(ps, target_frame)


class TransformBroadcaster:
    """tf.TransformBroadcaster: a transform sent is a frame of the planning scene, as a static one."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._broadcaster = tf2_ros.StaticTransformBroadcaster()

    def sendTransform(self, translation: Sequence[float], rotation: Sequence[float], time: Any,  # noqa: N802
                      child: str, parent: str) -> None:
        """Add (or move) frame `child` at `translation`, `rotation` [x, y, z, w] in `parent`; return None."""
        message = TransformStamped(Header(frame_id=parent), child)
        t, q = message.transform.translation, message.transform.rotation
        t.x, t.y, t.z = (float(v) for v in translation)
        q.x, q.y, q.z, q.w = (float(v) for v in rotation)
        self._broadcaster.sendTransform(message)
