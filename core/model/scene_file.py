"""Reading a scene file: moveplan's own format or a MoveIt PlanningScene written as YAML."""

from __future__ import annotations

from pathlib import Path

from ..config import PLANNING_SCENE_KEYS, load_yaml, mapping
from .planning_scene import read_planning_scene
from .robot import Robot
from .scene import Scene, moveplan_scene

__all__ = ["load_scene"]


def load_scene(path: Path, robot: Robot) -> Scene:
    """Return the scene in a moveplan scene file or a PlanningScene YAML, resolved against `robot`'s links."""
    top = mapping(load_yaml(path), str(path))
    if PLANNING_SCENE_KEYS & set(top):
        return read_planning_scene(top, path, robot)
    return moveplan_scene(top, path, robot)
