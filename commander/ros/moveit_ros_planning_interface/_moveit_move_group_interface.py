"""MoveGroupInterface, the C++ binding moveit_commander's MoveGroupCommander wraps, as scripts call it directly.

It speaks serialized messages where MoveGroupCommander speaks message objects: plan() returns
(serialized MoveItErrorCodes, serialized RobotTrajectory, planning time), and execute() takes
the serialized trajectory; `MoveItErrorCodes().deserialize(...)` reads them back. Every other
method is MoveGroupCommander's.
"""

from __future__ import annotations

import io
from typing import Any

from ...move_group import MoveGroupCommander
from ...msgs import Message, RobotTrajectory

__all__ = ["MoveGroupInterface"]


class MoveGroupInterface:
    """One planning group, as moveit_ros_planning_interface's Python binding offers it."""

    def __init__(self, group_name: str, robot_description: Any = "robot_description", ns: str = "",
                 wait_for_servers: float = 5.0) -> None:
        self._group = MoveGroupCommander(group_name, robot_description, ns, wait_for_servers)

    def plan(self) -> tuple[bytes, bytes, float]:
        """Return (serialized MoveItErrorCodes, serialized RobotTrajectory, planning time [s]) to the target."""
        _, trajectory, seconds, error = self._group.plan()
        return _bytes(error), _bytes(trajectory), seconds

    def execute(self, plan: bytes | RobotTrajectory) -> bool:
        """Return True if executing a (serialized) trajectory succeeded."""
        message = plan if isinstance(plan, RobotTrajectory) else RobotTrajectory().deserialize(plan)
        return self._group.execute(message)

    def __getattr__(self, name: str) -> Any:
        """Return MoveGroupCommander's method of that name."""
        return getattr(self._group, name)


def _bytes(message: Message) -> bytes:
    """Return a message serialized."""
    buffer = io.BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()
