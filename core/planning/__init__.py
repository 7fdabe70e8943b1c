"""Motion planning: goals to joint targets, OMPL searches in joint space, and straight lines of the tip."""

from .cartesian import LinearPath, straight_line
from .goals import check_limits, joint_target, pose_error, tip_target
from .search import PathResult, Validity, plan_path, repair_path, seed_planner

__all__ = [
    "LinearPath", "PathResult", "Validity", "check_limits", "joint_target", "plan_path", "pose_error", "repair_path",
    "seed_planner", "straight_line", "tip_target",
]
