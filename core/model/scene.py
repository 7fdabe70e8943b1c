"""Scene: named static frames and collision objects around a robot.

Frames may chain and may hang off robot links. Everything is resolved to the
planning frame (the URDF root) with the robot at its neutral configuration,
so world objects must sit in frames that do not move with the arm.

This module resolves moveplan's own format (frames, objects, attached; read by
core/config/scene_yaml.py); core/model/planning_scene.py resolves a moveit_msgs/PlanningScene
(it places objects with the robot in the scene's own robot state, as MoveIt does), and
core/model/scene_file.py tells the two apart.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..config import SceneFile, parse_scene
from ..errors import ConfigError, FrameNotFound
from ..types import CollisionObject, Frame
from .robot import Robot

__all__ = [
    "MAX_SCENE_FRAMES", "Scene", "empty_scene", "moveplan_scene", "planning_frame_names", "resolve_frames",
    "resolved_scene",
]

MAX_SCENE_FRAMES = 10_000
"""Frames a scene may define, subframes of PlanningScene objects included."""


@dataclass(frozen=True)
class Scene:
    """Frames and objects of a scene, with every frame resolved to a robot link.

    Attributes:
        source: The scene file, for messages ("(no scene)" when none was given).
        frames: Scene frames as written (`parent_T_frame`).
        objects: World objects placed in the planning frame, then attached objects.
        anchors: Frame name -> (robot link, `link_T_frame`).
        allowed: Pairs of link or object names allowed to touch (a PlanningScene's allowed
            collision matrix; the SRDF's disabled pairs come on top).
        robot_state: Joint name -> position in [rad] or [m], the robot state a PlanningScene
            carries (empty for moveplan scenes).
        parts: PlanningScene (or `.scene`) object id -> the names of the objects it became (one per shape).
        subframes: PlanningScene object id -> the names of the frames its subframes became.
        name: The scene's name, where its file gives one (a PlanningScene's `name`, a `.scene` file's first line).
    """

    source: str
    frames: tuple[Frame, ...]
    objects: tuple[CollisionObject, ...]
    anchors: dict[str, tuple[str, NDArray[np.float64]]]
    allowed: frozenset[frozenset[str]] = frozenset()
    robot_state: dict[str, float] = field(default_factory=dict)
    parts: dict[str, tuple[str, ...]] = field(default_factory=dict)
    subframes: dict[str, tuple[str, ...]] = field(default_factory=dict)
    name: str = ""

    def anchor(self, frame: str, robot: Robot) -> tuple[str, NDArray[np.float64]]:
        """Return (robot link, `link_T_frame`) for a scene frame, a robot link or a name of the planning frame."""
        if frame in self.anchors:
            return self.anchors[frame]
        if frame in robot.link_names:
            return frame, np.eye(4)
        planning = planning_frame_names(robot)
        if frame in planning:
            return robot.root_link, np.eye(4)
        raise FrameNotFound(frame, self.source, [*self.anchors, *robot.link_names, *planning])

    def object_groups(self, attached: bool = False) -> dict[str, tuple[CollisionObject, ...]]:
        """Return the world objects (attached ones with `attached`) by object id, each id's parts in scene order."""
        id_of = {name: object_id for object_id, names in self.parts.items() for name in names}
        groups: dict[str, list[CollisionObject]] = {}
        for obj in self.objects:
            if bool(obj.link) == attached:  # a moveplan scene's objects are their own ids
                groups.setdefault(id_of.get(obj.name, obj.name), []).append(obj)
        return {object_id: tuple(parts) for object_id, parts in groups.items()}


def planning_frame_names(robot: Robot) -> frozenset[str]:
    """Return the names of the planning frame: the URDF root link, and the frame its SRDF virtual joint hangs from.

    MoveIt's planning frame is that parent frame (`world`) for a floating or planar virtual
    joint; moveplan plans with the robot at the identity of its virtual joint, so both name it.
    """
    names = {robot.root_link}
    for joint in robot.config.srdf.virtual_joints.values():
        parent = joint.parent_frame.lstrip("/")
        if joint.child_link == robot.root_link and parent and parent not in robot.link_names:
            names.add(parent)
    return frozenset(names)


def empty_scene() -> Scene:
    """Return a scene with no frames or objects."""
    return Scene("(no scene)", (), (), {})


def moveplan_scene(top: dict[str, Any], path: Path, robot: Robot) -> Scene:
    """Return the scene of a moveplan scene file's parsed `top` mapping, resolved against `robot`'s links."""
    return resolved_scene(parse_scene(top, path), robot)


def resolved_scene(file: SceneFile, robot: Robot) -> Scene:
    """Return the scene of a read scene file (moveplan's, or MoveIt's text `.scene`), resolved against `robot`."""
    anchors = resolve_frames(list(file.frames), robot, file.source)
    root_q = robot.neutral()
    objects: list[CollisionObject] = []
    for entry in file.objects:
        frame = robot.root_link if entry.frame is None else entry.frame
        link, link_T_frame = Scene(file.source, (), (), anchors).anchor(frame, robot)
        if robot.model.frames[robot.model.getFrameId(link)].parentJoint != 0:
            raise ConfigError(f"{entry.where}: frame '{frame}' moves with link '{link}'; "
                              "put objects carried by the robot under 'attached'")
        root_T_object = robot.frame_pose(root_q, link) @ link_T_frame @ entry.transform
        objects.append(CollisionObject(entry.name, entry.shape, root_T_object))
    for entry in file.attached:
        if entry.link not in robot.link_names:
            raise FrameNotFound(entry.link, entry.where, robot.link_names)
        objects.append(CollisionObject(entry.name, entry.shape, entry.transform, entry.link, entry.touch_links))
    return Scene(file.source, file.frames, tuple(objects), anchors, parts=dict(file.parts), name=file.name)


def resolve_frames(
    frames: list[Frame], robot: Robot, source: str
) -> dict[str, tuple[str, NDArray[np.float64]]]:
    """Return each frame's robot link and `link_T_frame`, following parent chains."""
    if len(frames) > MAX_SCENE_FRAMES:
        raise ConfigError(f"{source}: {len(frames)} frames; moveplan reads at most {MAX_SCENE_FRAMES} per scene")
    by_name = {f.name: f for f in frames}
    for frame in frames:
        if frame.name in robot.link_names:
            raise ConfigError(f"{source}: frame '{frame.name}' has the name of a robot link")
    anchors: dict[str, tuple[str, NDArray[np.float64]]] = {}
    for frame in frames:
        # Up the parents to a resolved frame or a link, then down again: no recursion, chains of any length.
        chain: list[str] = []
        on_chain: set[str] = set()
        name = frame.name
        while name not in anchors and name not in robot.link_names:
            if name not in by_name:
                raise FrameNotFound(name, source, [*by_name, *robot.link_names])
            if name in on_chain:
                raise ConfigError(f"{source}: frames form a loop: {' -> '.join((*chain, name))}")
            chain.append(name)
            on_chain.add(name)
            name = by_name[name].parent
        link, link_T = anchors[name] if name in anchors else (name, np.eye(4))
        for child in reversed(chain):
            link_T = link_T @ by_name[child].transform
            anchors[child] = (link, link_T)
    return anchors
