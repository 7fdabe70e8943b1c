"""ROS's geometry_msgs package: its messages in `geometry_msgs.msg`."""

from . import msg

__all__ = ["msg"]
