"""ROS's sensor_msgs package: its messages in `sensor_msgs.msg`."""

from . import msg

__all__ = ["msg"]
