"""control_msgs/msg: a FollowJointTrajectory goal and its tolerances (moveplan.commander.msgs defines them).

MoveGroupCommander.execute(plan, tolerances=goal) takes such a goal's tolerances.
"""

from ...msgs import FollowJointTrajectoryGoal, JointTolerance

__all__ = ["FollowJointTrajectoryGoal", "JointTolerance"]
