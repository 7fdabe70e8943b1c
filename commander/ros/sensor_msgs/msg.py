"""sensor_msgs/msg: the message types MoveIt scripts use (moveplan.commander.msgs defines them)."""

from ...msgs import JointState, MultiDOFJointState

__all__ = [
    "JointState", "MultiDOFJointState",
]
