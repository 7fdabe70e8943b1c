"""The planning scene's objects changed as MoveIt changes them: added from messages, attached, detached.

An object of several shapes (a CollisionObject with two primitives) is held as one scene object
per shape, named `id/0`, `id/1`... as a PlanningScene YAML's are; World.object_parts maps the
id to them and World.shape_offsets keeps each shape's pose in the object's frame.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.config import ObjectMessage, PackagePath, collision_object
from ..core.errors import UnknownName, UsageError
from ..core.types import CollisionObject
from ._targets import frame_name
from ._world import World
from .conversions import pose_to_matrix
from .msgs import CollisionObject as CollisionObjectMsg
from .msgs import plain

__all__ = ["apply_object", "attach_existing", "detach", "on_link"]

logger = logging.getLogger(__name__)


def apply_object(world: World, message: Any, where: str) -> None:
    """Apply a CollisionObject message to the world: ADD (replacing), APPEND, MOVE or REMOVE; return None.

    Raises:
        UsageError: Not a CollisionObject, an unknown operation, or an ADD without shapes.
        UnknownName: MOVE or REMOVE of an object the scene does not have.
        ConfigError: Shapes MoveIt refuses (dimensions, triangles, planes).
    """
    if not all(hasattr(message, key) for key in ("id", "header", "primitives", "operation")):
        raise UsageError(f"{where}: expected a moveit_msgs CollisionObject, got {type(message).__name__}")
    oid, operation = str(message.id), message.operation
    where = f"{where}('{oid}')"
    objects = world.objects
    if operation == CollisionObjectMsg.REMOVE:
        doomed = world.object_ids(attached=False) if not oid else [oid]
        removed = {n for d in doomed for n in world.parts(d) if n in objects and not objects[n].link}
        if oid and not removed:
            logger.warning("%s: REMOVE: no world object '%s'", where, oid)
        world.change(objects={n: o for n, o in objects.items() if n not in removed})
        return
    if operation not in (CollisionObjectMsg.ADD, CollisionObjectMsg.APPEND, CollisionObjectMsg.MOVE):
        raise UsageError(f"{where}: operation {operation!r}: expected ADD (0), REMOVE (1), APPEND (2) or MOVE (3)")
    known = [n for n in world.parts(oid) if n in objects and not objects[n].link]
    if operation == CollisionObjectMsg.MOVE:
        if not known:
            raise UnknownName("object", oid, f"{where} MOVE (the world objects)", world.object_ids(attached=False))
        root_T_object = _frame(world, message, where) @ pose_to_matrix(message.pose, f"{where}: pose")
        for name in known:
            offset = world.shape_offsets.get(name, np.eye(4))
            objects[name] = replace(objects[name], transform=root_T_object @ offset)
        world.change(objects=objects)
        return
    parsed = read_object(message, where, Path.cwd())
    if not parsed.parts:
        raise UsageError(f"{where}: {'APPEND' if operation else 'ADD'}: the object has no shapes (primitives or "
                         "meshes)")
    root_T_object = _frame(world, message, where) @ parsed.header_T_object
    if operation == CollisionObjectMsg.ADD or not known:  # APPEND to nothing adds, as MoveIt does
        for name in known:
            del objects[name]
        known = []
    names = [*known, *(f"{oid}/{k}" for k in range(len(known), len(known) + len(parsed.parts)))]
    if len(names) == 1:
        names = [oid]
    elif known == [oid]:  # a one-shape object gets a second shape: its first becomes oid/0
        objects[f"{oid}/0"] = replace(objects.pop(oid), name=f"{oid}/0")
        if oid in world.shape_offsets:
            world.shape_offsets[f"{oid}/0"] = world.shape_offsets.pop(oid)
        names[0] = f"{oid}/0"
    for name, (_, shape, object_T_shape) in zip(names[len(known):], parsed.parts, strict=True):
        objects[name] = CollisionObject(name, shape, root_T_object @ object_T_shape)
        world.shape_offsets[name] = np.array(object_T_shape)
    parts = world.object_parts
    parts[oid] = tuple(names)
    world.change(objects=objects, parts=parts)


def read_object(message: Any, where: str, folder: Path) -> ObjectMessage:
    """Return a CollisionObject message (or one with its fields) parsed as a PlanningScene YAML's object is.

    Raises:
        UsageError: Not a CollisionObject; ConfigError: shapes MoveIt refuses (a primitive's
            dimensions, a mesh's triangles), named as fields of `where`.
    """
    if not all(hasattr(message, key) for key in ("id", "header", "primitives")):
        raise UsageError(f"{where}: expected a moveit_msgs CollisionObject, got {type(message).__name__}")
    written = {f.name: plain(getattr(message, f.name)) for f in fields(CollisionObjectMsg)}
    written.pop("type", None)  # object_recognition_msgs/ObjectType: a database key, nothing to plan with
    written["operation"] = CollisionObjectMsg.ADD
    return collision_object(written, where, folder, PackagePath(()))


def _frame(world: World, message: Any, where: str) -> NDArray[np.float64]:
    """Return `root_T_header` of a message's header frame (the planning frame when empty), the robot where it is."""
    frame = frame_name(message.header.frame_id, f"{where}: header.frame_id") or world.robot(None).root_link
    return world.pose(frame)


def attach_existing(world: World, name: str, link: str, touch_links: Sequence[str] | None, where: str) -> None:
    """Attach the scene object `name` to `link` where it is now; `touch_links` default to [link]; return None.

    `where` names the call in errors.
    """
    objects = world.objects
    if name not in objects:
        raise UnknownName("object", name, "the planning scene", objects)
    objects[name] = on_link(world, _in_world(world, objects[name]), link, touch_links, where)
    world.change(objects=objects)


def detach(world: World, name: str, link: str | None = None) -> bool:
    """Return True if objects were detached: `name` (an object, else a link's objects; "" all), left where they are."""
    objects = world.objects
    attached = [n for n, o in objects.items() if o.link and (link is None or o.link == link)]
    if name in objects:
        chosen = [name] if name in attached else []
    else:
        chosen = [n for n in attached if not name or objects[n].link == name]
    for n in chosen:
        objects[n] = _in_world(world, objects[n])
    world.change(objects=objects)
    return bool(chosen)


def on_link(
    world: World, placed: CollisionObject, link: str, touch_links: Sequence[str] | None, where: str
) -> CollisionObject:
    """Return a world object attached to `link`, kept where it is now."""
    robot = world.robot(None)
    if not isinstance(link, str) or link not in robot.link_names:
        raise UnknownName("link", str(link), f"{where} (the robot's links)", robot.link_names)
    if touch_links is not None and (isinstance(touch_links, str) or not hasattr(touch_links, "__iter__")):
        raise UsageError(f"{where}: touch_links: expected a list of link names, got {touch_links!r}")
    touch = tuple(touch_links) if touch_links is not None else (link,)
    for other in touch:
        if other not in robot.link_names:
            raise UnknownName("link", other, f"touch_links of '{placed.name}'", robot.link_names)
    link_T_object = np.linalg.inv(world.pose(link)) @ placed.transform
    return CollisionObject(placed.name, placed.shape, link_T_object, link, touch)


def _in_world(world: World, item: CollisionObject) -> CollisionObject:
    """Return an object as a world object where it is now (an attached one where its link holds it)."""
    if not item.link:
        return item
    return CollisionObject(item.name, item.shape, world.pose(item.link) @ item.transform)
