"""ROS 1's tf package, the part scripts use without a ROS graph: `tf.transformations`."""

from . import transformations

__all__ = ["transformations"]
