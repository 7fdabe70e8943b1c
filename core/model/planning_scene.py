"""MoveIt's moveit_msgs/PlanningScene, read by core/config/planning_scene_yaml.py, resolved into a moveplan Scene.

Resolved as MoveIt's PlanningScene::setPlanningSceneMsg resolves it, with these choices:

- Allowed-collision entries naming an object id apply to every part (`id/0`, `id/1`, ...).
- Frames: an empty `header.frame_id` is the planning frame (for attached objects: their
  link); objects are placed with the robot in the scene's own robot state, as MoveIt
  does. `fixed_frame_transforms` are read as MoveIt's Transforms::copyTransforms writes them:
  `child_frame_id` is the planning frame and `header.frame_id` the fixed frame, whose pose in
  the planning frame is the transform. The planning frame is the URDF root link, or the frame
  the SRDF's virtual joint hangs from (MoveIt's model frame), or any frame the file gives
  relative to itself (MoveIt writes its planning frame so); frames that name it must be the
  identity. A transform to another child frame is read as tf reads it: the child frame's pose
  in the header frame. Subframes become frames named `id/subframe`.
- Attached objects (robot_state.attached_collision_objects, after the world's objects, and a
  MotionPlanRequest's start state through `attach_request_objects`) are attached as
  processAttachedCollisionObjectMsg attaches them: one given by id alone takes the world object
  of that id, where it is, and any world object of that id leaves the world; an object attached
  again replaces the first. (MoveIt applies a whole scene's robot state before its world, so
  there an object attached by id must already be in the world.)
- The allowed collision matrix's allowed pairs come on top of the SRDF's disabled pairs, so a
  `false` entry does not re-enable a pair the SRDF disables. Unknown names are ignored, as in MoveIt.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..config import (
    AttachedMessage,
    FixedTransform,
    MotionPlanRequest,
    ObjectMessage,
    PackagePath,
    attached_collision_object,
    check_shape_count,
    first_repeated,
    is_identity,
    parse_planning_scene,
)
from ..errors import ConfigError, UnknownName
from ..types import CollisionObject, Frame
from .robot import Robot
from .scene import Scene, empty_scene, planning_frame_names, resolve_frames

__all__ = ["attach_request_objects", "known_joints", "read_planning_scene"]

logger = logging.getLogger(__name__)


@dataclass
class _Objects:
    """The objects of a scene being built, by message id, in the order they came (world, then attached)."""

    world: dict[str, tuple[list[CollisionObject], list[Frame]]] = field(default_factory=dict)
    attached: dict[str, tuple[list[CollisionObject], list[Frame]]] = field(default_factory=dict)

    def scene(self, base: Scene, frames: list[Frame], robot: Robot) -> Scene:
        """Return `base` with these objects, `frames` and the objects' subframes, frames resolved."""
        groups = [*self.world.items(), *self.attached.items()]
        objects = [obj for _, (parts, _) in groups for obj in parts]
        check_shape_count(len(objects), base.source)
        if (twice := first_repeated(o.name for o in objects)) is not None:
            raise ConfigError(f"{base.source}: collision object '{twice}' is defined twice")
        frames = [*frames, *(frame for _, (_, subframes) in groups for frame in subframes)]
        if (twice := first_repeated(f.name for f in frames)) is not None:
            raise ConfigError(f"{base.source}: frame '{twice}' is defined twice")
        return replace(base, frames=tuple(frames), objects=tuple(objects),
                       anchors=resolve_frames(frames, robot, base.source),
                       parts={i: tuple(o.name for o in parts) for i, (parts, _) in groups},
                       subframes={i: tuple(f.name for f in subs) for i, (_, subs) in groups})


def read_planning_scene(top: dict[str, Any], path: Path, robot: Robot) -> Scene:
    """Return the scene a PlanningScene message (already parsed from YAML at `path`) describes."""
    file = parse_planning_scene(top, path, robot.config)
    source = file.source
    state = known_joints(file.joints, robot, f"{source}: robot_state.joint_state.name")
    q = robot.neutral()
    for joint, value in state.items():
        q = robot.set_joint(q, joint, value)

    frames = _fixed_frames(file.fixed_transforms, robot)
    fixed = Scene(source, tuple(frames), (), resolve_frames(frames, robot, source), robot_state=state, name=file.name)
    objects = _Objects()
    for message in file.objects:
        objects.world[message.id] = _place(message, "", robot, fixed, q)
    _attach(objects, file.attached, robot, fixed, q)
    scene = objects.scene(fixed, frames, robot)
    pairs = file.allowed.pairs([*robot.link_names, *scene.parts])
    # Entries naming an object apply to each of its parts.
    allowed: set[frozenset[str]] = set()
    for first, second in map(tuple, pairs):
        for a in scene.parts.get(first, (first,)):
            allowed.update(frozenset((a, b)) for b in scene.parts.get(second, (second,)) if a != b)
    return replace(scene, allowed=frozenset(allowed))


def attach_request_objects(
    scene: Scene, request: MotionPlanRequest, robot: Robot, q: NDArray[np.float64]
) -> Scene:
    """Return `scene` with a request's start_state.attached_collision_objects attached, the robot at `q`.

    As MoveIt applies a request's start state to the planning scene: an object given by id
    alone takes the world object of that id, where it is; a world object of an attached id
    leaves the world; an object attached again replaces the first.
    """
    if not request.attached:
        return scene
    objects = _Objects()
    id_of = {name: object_id for object_id, names in scene.parts.items() for name in names}
    frames = {f.name: f for f in scene.frames}
    for obj in scene.objects:
        object_id = id_of.get(obj.name, obj.name)  # a moveplan scene's objects are their own ids
        side = objects.attached if obj.link else objects.world
        side.setdefault(object_id, ([], [frames[name] for name in scene.subframes.get(object_id, ())]))[0].append(obj)
    packages = PackagePath(tuple(robot.config.package_paths))
    where = f"{request.source}: start_state.attached_collision_objects"
    entries = [attached_collision_object(value, f"{where}[{k}]", request.source.parent, packages)
               for k, value in enumerate(request.attached)]
    _attach(objects, entries, robot, scene, q)
    subframes = {name for names in scene.subframes.values() for name in names}
    source = str(request.source) if scene.source == empty_scene().source else scene.source
    return objects.scene(replace(scene, source=source), [f for f in scene.frames if f.name not in subframes], robot)


def _attach(
    objects: _Objects, entries: Iterable[AttachedMessage], robot: Robot, fixed: Scene, q: NDArray[np.float64]
) -> None:
    """Attach moveit_msgs/AttachedCollisionObject entries to `objects`, as MoveIt attaches them."""
    for entry in entries:
        at, link, touch, message = entry.where, entry.link, entry.touch_links, entry.object
        if link not in robot.link_names:
            raise UnknownName("link", link, f"{at}.link_name", robot.link_names)
        unknown = [t for t in touch if t not in robot.link_names and t not in {*objects.world, *objects.attached}]
        if unknown:
            # MoveIt takes any name; one that is no link or object allows nothing, likely a typo.
            logger.warning("%s.touch_links: %s name no robot link or object; they allow no contact",
                           at, ", ".join(unknown[:10]))
        world = objects.world.pop(message.id, None)
        objects.attached.pop(message.id, None)
        if message.parts:
            objects.attached[message.id] = _place(message, link, robot, fixed, q, touch)
        elif world is not None:
            objects.attached[message.id] = _carried(world, link, robot, q, touch)
        else:
            raise ConfigError(f"{at}.object: object '{message.id}' has no primitives or meshes, and no world "
                              f"object has that id to attach (world objects: {', '.join(objects.world) or 'none'})")


def _place(
    message: ObjectMessage, link: str, robot: Robot, fixed: Scene, q: NDArray[np.float64],
    touch_links: tuple[str, ...] = (),
) -> tuple[list[CollisionObject], list[Frame]]:
    """Return a CollisionObject message's parts and subframes, placed with the robot at `q`.

    `link` is "" for a world object (placed in the planning frame), else the link it is attached to.
    """
    frame = message.frame or link or robot.root_link
    frame_link, link_T_frame = Scene(f"{message.where}.header.frame_id", (), (), fixed.anchors).anchor(frame, robot)
    root_T_header = robot.frame_pose(q, frame_link) @ link_T_frame
    # MoveIt fixes an attached object to its link where the scene's robot state puts it.
    parent_T_header = np.linalg.inv(robot.frame_pose(q, link)) @ root_T_header if link else root_T_header
    parent_T_object = parent_T_header @ message.header_T_object
    parts = [CollisionObject(name, shape, parent_T_object @ object_T_shape, link, touch_links)
             for name, shape, object_T_shape in message.parts]
    subframes = [Frame(f"{message.id}/{sub}", link or robot.root_link, parent_T_object @ object_T_sub)
                 for sub, object_T_sub in message.subframes.items()]
    return parts, subframes


def _carried(
    world: tuple[list[CollisionObject], list[Frame]], link: str, robot: Robot, q: NDArray[np.float64],
    touch_links: tuple[str, ...],
) -> tuple[list[CollisionObject], list[Frame]]:
    """Return a world object's parts and subframes fixed to `link` where they are, the robot at `q`."""
    link_T_root = np.linalg.inv(robot.frame_pose(q, link))
    parts, subframes = world
    return ([replace(o, transform=link_T_root @ o.transform, link=link, touch_links=touch_links) for o in parts],
            [Frame(f.name, link, link_T_root @ f.transform) for f in subframes])


def _fixed_frames(entries: tuple[FixedTransform, ...], robot: Robot) -> list[Frame]:
    """Return scene frames from `fixed_frame_transforms` (geometry_msgs/TransformStamped entries).

    MoveIt writes each fixed frame F as {header.frame_id: F, child_frame_id: planning frame,
    transform: planning_T_F}, its planning frame P as {header.frame_id: P, child_frame_id: P}.
    Names of the planning frame that are no robot link (`world`) are kept as identity frames.
    """
    # A frame given relative to itself is MoveIt's planning frame; robowflex leaves that header out.
    planning = set(planning_frame_names(robot)) | {
        e.child for e in entries if e.header in ("", e.child) and is_identity(e.header_T_child)}
    aliases: dict[str, Frame] = {}
    frames = []
    for entry in entries:
        header, child, header_T_child = entry.header, entry.child, entry.header_T_child
        if child in planning and header in planning | {""}:
            if not is_identity(header_T_child):
                raise ConfigError(f"{entry.where}: '{header or child}' and '{child}' both name the planning frame; "
                                  "the transform between them can only be the identity")
            for name in {header, child} - {"", *robot.link_names}:
                aliases.setdefault(name, Frame(name, robot.root_link, np.eye(4)))
        elif child in planning:
            frames.append(Frame(header, robot.root_link, header_T_child))
        elif header == child:
            raise ConfigError(f"{entry.where}: frame '{child}' relative to itself can only be the identity")
        else:
            frames.append(Frame(child, header or robot.root_link, header_T_child))
    return [*aliases.values(), *frames]


def known_joints(joints: dict[str, float], robot: Robot, where: str) -> dict[str, float]:
    """Return the joints that have a position in `robot`, after checking every name is a URDF joint.

    Fixed joints (a Panda's fingers in some URDFs) are known but have no position: left out.
    """
    for joint in joints:
        if joint not in robot.config.urdf_joints:
            raise UnknownName("joint", joint, where, robot.config.limits)
    return {j: v for j, v in joints.items() if robot.model.existJointName(j)}
