"""geometry_msgs/msg: the message types MoveIt scripts use (moveplan.commander.msgs defines them)."""

from ...msgs import (
    Point,
    PointStamped,
    Pose,
    PoseArray,
    PoseStamped,
    Quaternion,
    Transform,
    TransformStamped,
    Twist,
    Vector3,
)

__all__ = [
    "Point", "PointStamped", "Pose", "PoseArray", "PoseStamped", "Quaternion", "Transform", "TransformStamped",
    "Twist", "Vector3",
]
