"""ROS's shape_msgs package: its messages in `shape_msgs.msg`."""

from . import msg

__all__ = ["msg"]
