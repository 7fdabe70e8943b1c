"""visualization_msgs/msg: the message types MoveIt scripts use (moveplan.commander.msgs defines them)."""

from ...msgs import Marker, MarkerArray

__all__ = [
    "Marker", "MarkerArray",
]
