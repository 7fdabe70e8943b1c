"""trajectory_msgs/msg: the message types MoveIt scripts use (moveplan.commander.msgs defines them)."""

from ...msgs import JointTrajectory, JointTrajectoryPoint, MultiDOFJointTrajectory

__all__ = [
    "JointTrajectory", "JointTrajectoryPoint", "MultiDOFJointTrajectory",
]
