"""ROS's std_msgs package: its messages in `std_msgs.msg`."""

from . import msg

__all__ = ["msg"]
