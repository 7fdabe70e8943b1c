"""Reading a scene file: moveplan's own format, a MoveIt PlanningScene written as YAML, or MoveIt's text `.scene`."""

from __future__ import annotations

from pathlib import Path

from ..config import PLANNING_SCENE_KEYS, load_yaml, mapping, parse_scene_text, read_input_text
from .planning_scene import read_planning_scene
from .robot import Robot
from .scene import Scene, moveplan_scene, resolved_scene

__all__ = ["load_scene"]


def load_scene(path: Path, robot: Robot) -> Scene:
    """Return the scene in a moveplan scene file, a PlanningScene YAML or a `.scene` file, resolved against `robot`."""
    if path.suffix == ".scene":  # what RViz's Motion Planning panel exports
        return resolved_scene(parse_scene_text(read_input_text(path), path), robot)
    top = mapping(load_yaml(path), str(path))
    if PLANNING_SCENE_KEYS & set(top):
        return read_planning_scene(top, path, robot)
    return moveplan_scene(top, path, robot)
