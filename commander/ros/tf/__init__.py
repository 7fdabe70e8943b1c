"""ROS 1's tf package, without a ROS graph: `tf.transformations`, TransformListener, TransformBroadcaster."""

from . import transformations
from ._tf1 import (
    ConnectivityException,
    Exception,
    ExtrapolationException,
    LookupException,
    TransformBroadcaster,
    TransformListener,
)

__all__ = [
    "ConnectivityException", "Exception", "ExtrapolationException", "LookupException", "TransformBroadcaster",
    "TransformListener", "transformations",
]
