"""moveit_msgs/msg: the message types MoveIt scripts use (moveplan.commander.msgs defines them)."""

from ...msgs import (
    AllowedCollisionEntry,
    AllowedCollisionMatrix,
    AttachedCollisionObject,
    BoundingVolume,
    CollisionObject,
    Constraints,
    DisplayTrajectory,
    JointConstraint,
    MoveItErrorCodes,
    ObjectColor,
    OrientationConstraint,
    PlanningScene,
    PlanningSceneComponents,
    PlanningSceneWorld,
    PositionConstraint,
    RobotState,
    RobotTrajectory,
)

__all__ = [
    "AllowedCollisionEntry", "AllowedCollisionMatrix", "AttachedCollisionObject", "BoundingVolume",
    "CollisionObject", "Constraints", "DisplayTrajectory", "JointConstraint", "MoveItErrorCodes", "ObjectColor",
    "OrientationConstraint", "PlanningScene", "PlanningSceneComponents", "PlanningSceneWorld",
    "PositionConstraint", "RobotState", "RobotTrajectory",
]
