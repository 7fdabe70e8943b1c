"""The robot and its world: kinematics, frames, scenes and MoveIt messages, resolved against the model."""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from .kinematics import IkSolution, solve_ik
    from .moveit_messages import known_joints
    from .moveit_request import MotionPlanRequest, PositionGoal, load_motion_plan_request
    from .planning_scene import attach_request_objects, read_planning_scene
    from .poses import pose_matrix
    from .robot import Robot
    from .scene import (
        PLANNING_SCENE_KEYS,
        Scene,
        check_shape_count,
        empty_scene,
        first_repeated,
        mesh_file,
        moveplan_scene,
        resolve_frames,
    )
    from .scene_file import load_scene

__all__ = [
    "IkSolution",
    "MotionPlanRequest",
    "PLANNING_SCENE_KEYS",
    "PositionGoal",
    "Robot",
    "Scene",
    "attach_request_objects",
    "check_shape_count",
    "empty_scene",
    "first_repeated",
    "known_joints",
    "load_motion_plan_request",
    "load_scene",
    "mesh_file",
    "moveplan_scene",
    "pose_matrix",
    "read_planning_scene",
    "resolve_frames",
    "solve_ik",
]

__getattr__ = lazy_exports(__name__, {
    "IkSolution": "kinematics",
    "MotionPlanRequest": "moveit_request",
    "PLANNING_SCENE_KEYS": "scene",
    "PositionGoal": "moveit_request",
    "Robot": "robot",
    "Scene": "scene",
    "attach_request_objects": "planning_scene",
    "check_shape_count": "scene",
    "empty_scene": "scene",
    "first_repeated": "scene",
    "known_joints": "moveit_messages",
    "load_motion_plan_request": "moveit_request",
    "load_scene": "scene_file",
    "mesh_file": "scene",
    "moveplan_scene": "scene",
    "pose_matrix": "poses",
    "read_planning_scene": "planning_scene",
    "resolve_frames": "scene",
    "solve_ik": "kinematics",
})
