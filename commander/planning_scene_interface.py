"""moveit_commander.planning_scene_interface, under its MoveIt name: the PlanningSceneInterface (scene.py)."""

from .scene import PlanningSceneInterface

__all__ = ["PlanningSceneInterface"]
