"""The planning scene's objects and the robot's state as moveit_msgs, and collision object messages read back.

An object of several shapes (a CollisionObject with two primitives) is held as one scene object
per shape, named `id/0`, `id/1`... as a PlanningScene YAML's are; its message puts them back
together, each shape at its pose relative to the first.
"""

from __future__ import annotations

import logging
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.config import allowed_collisions
from ..core.errors import UsageError
from ..core.types import CollisionObject, Shape
from ._objects import apply_object, attach_existing, detach
from ._world import World
from .conversions import matrix_to_pose, matrix_to_transform
from .msgs import (
    AllowedCollisionEntry,
    AllowedCollisionMatrix,
    AttachedCollisionObject,
    Header,
    JointState,
    Mesh,
    MeshTriangle,
    MultiDOFJointState,
    PlanningScene,
    PlanningSceneComponents,
    Point,
    RobotState,
    SolidPrimitive,
    TransformStamped,
    plain,
)
from .msgs import CollisionObject as CollisionObjectMsg

__all__ = ["apply_scene", "attached_messages", "object_message", "scene_message", "state_message"]

logger = logging.getLogger(__name__)

_PRIMITIVES = {"box": SolidPrimitive.BOX, "sphere": SolidPrimitive.SPHERE, "cylinder": SolidPrimitive.CYLINDER}


def state_message(world: World, q: NDArray[np.float64] | None = None) -> RobotState:
    """Return the RobotState at `q` (default: now): every movable joint, attached objects, in the planning frame."""
    frame = world.robot(None).root_link
    names = world.joint_names()
    joints = JointState(Header(frame_id=frame), names, [world.joint_value(j, q) for j in names])
    return RobotState(joints, MultiDOFJointState(Header(frame_id=frame)), attached_messages(world, ()))


def object_message(world: World, oid: str) -> CollisionObjectMsg:
    """Return the world object `oid` (all its shapes) as a CollisionObject in the planning frame."""
    message = CollisionObjectMsg(Header(frame_id=world.robot(None).root_link), id=oid)
    parts = [world.objects[n] for n in world.parts(oid) if n in world.objects]
    if parts:
        root_T_object = world.object_pose(oid)
        message.pose = matrix_to_pose(root_T_object)
        _add_shapes(message, parts, np.asarray(np.linalg.inv(root_T_object), dtype=float))
    return message


def attached_messages(world: World, names: Any) -> list[AttachedCollisionObject]:
    """Return the attached objects among `names` (all for none), each in its link's frame."""
    wanted = set(names)
    messages = []
    for oid in world.object_ids(attached=True):
        if wanted and oid not in wanted:
            continue
        parts = [world.objects[n] for n in world.parts(oid)]
        link_T_object = world.object_pose(oid)
        message = CollisionObjectMsg(Header(frame_id=parts[0].link), id=oid, pose=matrix_to_pose(link_T_object))
        _add_shapes(message, parts, np.asarray(np.linalg.inv(link_T_object), dtype=float))
        messages.append(AttachedCollisionObject(parts[0].link, message, list(parts[0].touch_links)))
    return messages


def apply_scene(world: World, scene: Any) -> None:
    """Apply a PlanningScene message: its objects, attached objects, frames, joints and allowed collisions.

    A diff (`is_diff`) changes what it names; a whole scene replaces the objects. Collision
    objects apply first, then attached ones (which may attach what was just added).
    """
    if not all(hasattr(scene, key) for key in ("world", "robot_state", "allowed_collision_matrix", "is_diff")):
        raise UsageError(f"apply_planning_scene: expected a moveit_msgs PlanningScene, got {type(scene).__name__}")
    if not scene.is_diff:
        world.change(objects={}, parts={})
    for k, item in enumerate(scene.world.collision_objects):
        apply_object(world, item, f"apply_planning_scene: world.collision_objects[{k}]")
    for k, attached in enumerate(scene.robot_state.attached_collision_objects):
        where = f"apply_planning_scene: robot_state.attached_collision_objects[{k}]"
        item = attached.object
        if item.operation == CollisionObjectMsg.REMOVE:
            detach(world, item.id or attached.link_name, attached.link_name or None)
            continue
        if item.primitives or item.meshes:
            header = item.header.frame_id or attached.link_name
            apply_object(world, replace(item, header=replace(item.header, frame_id=header),
                                        operation=CollisionObjectMsg.ADD), where)
        attach_existing(world, item.id, attached.link_name, attached.touch_links or None, where)
    if scene.robot_state.joint_state.name:
        world.set_joints(scene.robot_state.joint_state, "apply_planning_scene: robot_state.joint_state")
    acm = scene.allowed_collision_matrix
    if acm.entry_names or acm.default_entry_names:
        world.change(acm=allowed_collisions(plain(acm), "apply_planning_scene: allowed_collision_matrix"))


def scene_message(world: World, components: int) -> PlanningScene:
    """Return the parts of the planning scene that `components` (PlanningSceneComponents bits) ask for."""
    bits = PlanningSceneComponents
    message = PlanningScene()
    if components & bits.SCENE_SETTINGS:
        message.name, message.robot_model_name = world.source, world.config.name
    if components & bits.ROBOT_STATE:
        message.robot_state = state_message(world)
        message.robot_state.attached_collision_objects = []
    if components & bits.ROBOT_STATE_ATTACHED_OBJECTS:
        message.robot_state.attached_collision_objects = attached_messages(world, ())
    if components & (bits.WORLD_OBJECT_NAMES | bits.WORLD_OBJECT_GEOMETRY):
        full = bool(components & bits.WORLD_OBJECT_GEOMETRY)
        root = world.robot(None).root_link
        message.world.collision_objects = [object_message(world, oid) if full else
                                           CollisionObjectMsg(Header(frame_id=root), id=oid)
                                           for oid in world.object_ids(attached=False)]
    if components & bits.TRANSFORMS:
        message.fixed_frame_transforms = [
            TransformStamped(Header(frame_id=f.parent), f.name, matrix_to_transform(f.transform))
            for f in world.frames.values()]
    if components & bits.ALLOWED_COLLISION_MATRIX:
        message.allowed_collision_matrix = _matrix(world)
    return message


def _matrix(world: World) -> AllowedCollisionMatrix:
    """Return the allowed collision matrix now: every pair allowed to touch, and apply_planning_scene's defaults."""
    pairs = sorted(tuple(sorted(p)) for p in world.allowed if len(p) == 2)
    names = sorted({n for p in pairs for n in p} | {n for pair in world.acm.explicit for n in pair})
    index = {n: i for i, n in enumerate(names)}
    entries = [AllowedCollisionEntry([False] * len(names)) for _ in names]
    for a, b in pairs:
        entries[index[a]].enabled[index[b]] = entries[index[b]].enabled[index[a]] = True
    for pair, allowed in world.acm.explicit.items():
        a, b = (*pair, *pair)[:2]
        entries[index[a]].enabled[index[b]] = entries[index[b]].enabled[index[a]] = allowed
    defaults = world.acm.defaults
    return AllowedCollisionMatrix(names, entries, list(defaults), list(defaults.values()))


def _add_shapes(message: CollisionObjectMsg, parts: list[CollisionObject], object_T_root: NDArray[np.float64]) -> None:
    """Append each part's shape and its pose relative to the object to the message."""
    for part in parts:
        pose = matrix_to_pose(object_T_root @ part.transform)
        shape = part.shape
        if shape.kind in _PRIMITIVES:
            message.primitives.append(SolidPrimitive(_PRIMITIVES[shape.kind], _dimensions(shape)))
            message.primitive_poses.append(pose)
        elif shape.vertices is not None and shape.triangles is not None:
            vertices = [Point(*map(float, v)) for v in shape.vertices]
            message.meshes.append(Mesh([MeshTriangle([int(i) for i in t]) for t in shape.triangles], vertices))
            message.mesh_poses.append(pose)
        # A mesh file's triangles stay in the file: the message has no shape for it, as ROS has no file field.


def _dimensions(shape: Shape) -> list[float]:
    """Return a primitive's SolidPrimitive dimensions: box x, y, z; sphere radius; cylinder height, radius."""
    size = [float(v) for v in shape.dims]
    return [size[1], size[0]] if shape.kind == "cylinder" else size


