"""std_msgs/msg: the message types MoveIt scripts use (moveplan.commander.msgs defines them)."""

from ...msgs import ColorRGBA, Header, String

__all__ = [
    "ColorRGBA", "Header", "String",
]
