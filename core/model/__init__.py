"""The robot and its world: kinematics, frames, scenes and MoveIt messages, resolved against the model."""

from .kinematics import IkSolution, solve_ik
from .moveit_request import MotionPlanRequest, load_motion_plan_request
from .robot import Robot
from .scene import Scene, empty_scene
from .scene_file import load_scene

__all__ = [
    "IkSolution", "MotionPlanRequest", "Robot", "Scene", "empty_scene", "load_motion_plan_request", "load_scene",
    "solve_ik",
]
