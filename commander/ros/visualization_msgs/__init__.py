"""ROS's visualization_msgs package: its messages in `visualization_msgs.msg`."""

from . import msg

__all__ = ["msg"]
