"""The robot and its world: kinematics, frames, scenes and MoveIt messages, resolved against the model."""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from .kinematics import IkSolution, solve_ik
    from .planning_scene import attach_request_objects, known_joints, read_planning_scene
    from .robot import Robot
    from .scene import Scene, empty_scene, moveplan_scene, resolve_frames
    from .scene_file import load_scene

__all__ = [
    "IkSolution",
    "Robot",
    "Scene",
    "attach_request_objects",
    "empty_scene",
    "known_joints",
    "load_scene",
    "moveplan_scene",
    "read_planning_scene",
    "resolve_frames",
    "solve_ik",
]

__getattr__ = lazy_exports(__name__, {
    "IkSolution": "kinematics",
    "Robot": "robot",
    "Scene": "scene",
    "attach_request_objects": "planning_scene",
    "empty_scene": "scene",
    "known_joints": "planning_scene",
    "load_scene": "scene_file",
    "moveplan_scene": "scene",
    "read_planning_scene": "planning_scene",
    "resolve_frames": "scene",
    "solve_ik": "kinematics",
})
