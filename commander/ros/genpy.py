"""genpy, the ROS 1 message runtime, as far as scripts touch it: its base class, times and errors."""

from ...core.errors import UsageError
from ..msgs import DeserializationError, Duration, Message, Time

__all__ = ["DeserializationError", "Duration", "Message", "SerializationError", "Time"]


class SerializationError(UsageError):
    """genpy's: a message that cannot be serialized."""
