"""Motion planning: goals to joint targets, OMPL searches in joint space, and straight lines of the tip."""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from .cartesian import LinearPath, straight_line
    from .constraints import PathCheck
    from .goals import check_limits, joint_target, orientation_tolerance, pose_error, tip_target
    from .search import PathResult, Validity, plan_path, repair_path, seed_planner

__all__ = [
    "LinearPath",
    "PathCheck",
    "PathResult",
    "Validity",
    "check_limits",
    "joint_target",
    "orientation_tolerance",
    "plan_path",
    "pose_error",
    "repair_path",
    "seed_planner",
    "straight_line",
    "tip_target",
]

__getattr__ = lazy_exports(__name__, {
    "LinearPath": "cartesian",
    "PathCheck": "constraints",
    "PathResult": "search",
    "Validity": "search",
    "check_limits": "goals",
    "joint_target": "goals",
    "orientation_tolerance": "goals",
    "plan_path": "search",
    "pose_error": "goals",
    "repair_path": "search",
    "seed_planner": "search",
    "straight_line": "cartesian",
    "tip_target": "goals",
})
