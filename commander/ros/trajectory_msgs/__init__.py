"""ROS's trajectory_msgs package: its messages in `trajectory_msgs.msg`."""

from . import msg

__all__ = ["msg"]
