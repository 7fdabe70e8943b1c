"""ROS's moveit_msgs package: its messages in `moveit_msgs.msg`."""

from . import msg

__all__ = ["msg"]
