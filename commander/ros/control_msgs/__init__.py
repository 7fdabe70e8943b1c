"""ROS's control_msgs package: its messages in `control_msgs.msg`."""

from . import msg

__all__ = ["msg"]
