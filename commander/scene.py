"""PlanningSceneInterface: moveit_commander's collision objects, added to the planning scene moveplan plans in.

As in MoveIt, an object is placed where its PoseStamped says with the robot where it is now,
and stays there (in the planning frame) when the robot moves; an attached object moves with
its link, and its `touch_links` (default: the link) may touch it. Adding an object under a
name in use replaces it. Calls apply at once (MoveIt's `synchronous=True`).
"""

from __future__ import annotations

import logging
import reprlib
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.config import MAX_MAGNITUDE, mesh_file
from ..core.errors import UnknownName, UsageError
from ..core.types import CollisionObject, Shape
from ._targets import frame_name
from ._world import World, current_world
from .conversions import matrix_to_pose, pose_to_matrix
from .msgs import AttachedCollisionObject, Header, Pose, PoseStamped
from .msgs import CollisionObject as CollisionObjectMsg

__all__ = ["PlanningSceneInterface", "attach_existing", "detach"]

logger = logging.getLogger(__name__)


class PlanningSceneInterface:
    """The planning scene's collision objects: add, attach, detach, remove, list.

    Args:
        robot: The RobotCommander whose scene this is; None (or MoveIt's `ns` string): the one created last.
        synchronous, service_timeout: MoveIt's; accepted and unused (every call applies at once).
    """

    def __init__(self, robot: Any = None, synchronous: bool = True, service_timeout: float = 5.0) -> None:
        self._world = current_world(robot, "PlanningSceneInterface")

    def add_box(self, name: str, pose: PoseStamped | Pose, size: Sequence[float] = (1, 1, 1)) -> None:
        """Add a box of full edge lengths `size` [m], centred at `pose`; return None."""
        where = f"add_box('{name}')"
        self._add(name, Shape("box", _lengths(size, 3, f"{where}: size")), pose, where)

    def add_sphere(self, name: str, pose: PoseStamped | Pose, radius: float = 1) -> None:
        """Add a sphere of `radius` [m] centred at `pose`; return None."""
        where = f"add_sphere('{name}')"
        self._add(name, Shape("sphere", _lengths([radius], 1, f"{where}: radius")), pose, where)

    def add_cylinder(self, name: str, pose: PoseStamped | Pose, height: float, radius: float) -> None:
        """Add a cylinder of `height` and `radius` [m] along the z axis of `pose`, centred there; return None."""
        where = f"add_cylinder('{name}')"
        height, radius = _lengths([height, radius], 2, f"{where}: height, radius")
        self._add(name, Shape("cylinder", (radius, height)), pose, where)

    def add_mesh(self, name: str, pose: PoseStamped | Pose, filename: str | Path,
                 size: Sequence[float] = (1, 1, 1)) -> None:
        """Add the mesh in `filename` (STL, OBJ, DAE...) scaled by `size`, at `pose`; return None."""
        where = f"add_mesh('{name}')"
        self._add(name, _mesh(filename, size, where), pose, where)

    def attach_object(self, object: Any, link: str | None = None, touch_links: Sequence[str] | None = None) -> None:
        """Attach the scene object `object` (a name, or a message with an `id`) to `link`; return None."""
        name = object if isinstance(object, str) else str(getattr(object, "id", ""))
        if not link:
            raise UsageError(f"attach_object('{name}'): give the link to attach it to")
        attach_existing(self._world, name, link, touch_links, f"attach_object('{name}')")

    def attach_box(self, link: str, name: str, pose: PoseStamped | Pose | None = None,
                   size: Sequence[float] = (1, 1, 1), touch_links: Sequence[str] | None = None) -> None:
        """Attach a new box (or, without `pose`, the scene object `name`) to `link`; return None."""
        where = f"attach_box('{link}', '{name}')"
        self._attach(link, name, pose, lambda: Shape("box", _lengths(size, 3, f"{where}: size")), touch_links, where)

    def attach_sphere(self, link: str, name: str, pose: PoseStamped | Pose | None = None, radius: float = 1,
                      touch_links: Sequence[str] | None = None) -> None:
        """Attach a new sphere (or, without `pose`, the scene object `name`) to `link`; return None."""
        where = f"attach_sphere('{link}', '{name}')"
        self._attach(link, name, pose, lambda: Shape("sphere", _lengths([radius], 1, f"{where}: radius")),
                     touch_links, where)

    def attach_cylinder(self, link: str, name: str, pose: PoseStamped | Pose | None = None, height: float = 1,
                        radius: float = 1, touch_links: Sequence[str] | None = None) -> None:
        """Attach a new cylinder (or, without `pose`, the scene object `name`) to `link`; return None."""
        where = f"attach_cylinder('{link}', '{name}')"

        def shape() -> Shape:
            length, r = _lengths([height, radius], 2, f"{where}: height, radius")
            return Shape("cylinder", (r, length))

        self._attach(link, name, pose, shape, touch_links, where)

    def attach_mesh(self, link: str, name: str, pose: PoseStamped | Pose | None = None, filename: str | Path = "",
                    size: Sequence[float] = (1, 1, 1), touch_links: Sequence[str] | None = None) -> None:
        """Attach a new mesh (or, without `pose` and `filename`, the scene object `name`) to `link`; return None."""
        where = f"attach_mesh('{link}', '{name}')"
        self._attach(link, name, pose if filename else None, lambda: _mesh(filename, size, where), touch_links,
                     where)

    def remove_world_object(self, name: str | None = None) -> None:
        """Remove the world object `name`, or every world object for None (attached ones stay); return None."""
        objects = self._world.objects
        doomed = [n for n, o in objects.items() if not o.link] if name is None else [
            n for n in self._world.parts(name) if n in objects and not objects[n].link]
        if name is not None and not doomed:
            logger.info("remove_world_object: no world object '%s'", name)
        self._world.change(objects={n: o for n, o in objects.items() if n not in doomed})

    def remove_attached_object(self, link: str | None = None, name: str | None = None) -> None:
        """Detach `name` (or every object of `link`, or every attached object): it stays in the world; return None."""
        detach(self._world, name or link or "", link)

    def clear(self) -> None:
        """Remove every object, world and attached, from the scene; return None."""
        self._world.change(objects={})

    def get_known_object_names(self, with_type: bool = False) -> list[str]:
        """Return the names of the world objects (attached objects are the robot's)."""
        return [n for n, o in self._world.objects.items() if not o.link]

    def get_object_poses(self, object_ids: Iterable[str]) -> dict[str, Pose]:
        """Return name -> pose in the planning frame of the world objects among `object_ids`."""
        objects = self._world.objects
        wanted = _names(object_ids, "get_object_poses")
        return {n: matrix_to_pose(objects[n].transform) for n in wanted if n in objects and not objects[n].link}

    def get_objects(self, object_ids: Iterable[str] = ()) -> dict[str, CollisionObjectMsg]:
        """Return name -> CollisionObject (pose in the planning frame) of the world objects asked (all for none)."""
        frame = self._world.robot(None).root_link
        wanted = set(_names(object_ids, "get_objects"))
        return {n: CollisionObjectMsg(Header(frame_id=frame), n, matrix_to_pose(o.transform))
                for n, o in self._world.objects.items() if not o.link and (not wanted or n in wanted)}

    def get_attached_objects(self, object_ids: Iterable[str] = ()) -> dict[str, AttachedCollisionObject]:
        """Return name -> AttachedCollisionObject (pose in its link's frame) of the objects asked (all for none)."""
        wanted = set(_names(object_ids, "get_attached_objects"))
        return {n: AttachedCollisionObject(o.link, CollisionObjectMsg(Header(frame_id=o.link), n,
                                                                      matrix_to_pose(o.transform)), list(o.touch_links))
                for n, o in self._world.objects.items() if o.link and (not wanted or n in wanted)}

    def _add(self, name: str, shape: Shape, pose: PoseStamped | Pose, where: str) -> None:
        """Add or replace the world object `name` at `pose`."""
        objects = self._world.objects
        objects[_name(name, where)] = CollisionObject(name, shape, _placed(self._world, pose, where))
        self._world.change(objects=objects)

    def _attach(self, link: str, name: str, pose: PoseStamped | Pose | None, shape: Any,
                touch_links: Sequence[str] | None, where: str) -> None:
        """Attach a new object of `shape()` at `pose` to `link`, or (no pose) the scene object `name`."""
        if pose is None:
            attach_existing(self._world, name, link, touch_links, where)
            return
        objects = self._world.objects
        placed = CollisionObject(_name(name, where), shape(), _placed(self._world, pose, where))
        objects[name] = _on_link(self._world, placed, link, touch_links, where)
        self._world.change(objects=objects)


def attach_existing(world: World, name: str, link: str, touch_links: Sequence[str] | None, where: str) -> None:
    """Attach the scene object `name` to `link` where it is now; `touch_links` default to [link]; return None.

    `where` names the call in errors.
    """
    objects = world.objects
    if name not in objects:
        raise UnknownName("object", name, "the planning scene", objects)
    objects[name] = _on_link(world, _in_world(world, objects[name]), link, touch_links, where)
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


def _on_link(
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


def _placed(world: World, pose: PoseStamped | Pose, where: str) -> NDArray[np.float64]:
    """Return `root_T_pose` of a PoseStamped (in its frame, the robot where it is now) or a Pose (planning frame)."""
    if isinstance(pose, PoseStamped):
        frame = frame_name(pose.header.frame_id, f"{where}: header.frame_id") or world.robot(None).root_link
        return world.pose(frame) @ pose_to_matrix(pose.pose, f"{where}: pose")
    if isinstance(pose, Pose):
        return pose_to_matrix(pose, f"{where}: pose")
    raise UsageError(f"{where}: expected a PoseStamped (or a Pose in the planning frame), got {type(pose).__name__}")


def _name(name: Any, where: str) -> str:
    """Return `name` if it is a nonempty string, else raise UsageError naming `where`."""
    if not isinstance(name, str) or not name:
        raise UsageError(f"{where}: an object needs a nonempty name, got {name!r}")
    return name


def _names(object_ids: Any, where: str) -> list[str]:
    """Return the object names of a list, else raise UsageError naming `where` (a string would be its letters)."""
    if isinstance(object_ids, str) or not hasattr(object_ids, "__iter__"):
        raise UsageError(f"{where}: expected a list of object names, got {reprlib.repr(object_ids)}")
    return list(object_ids)


def _lengths(values: Any, count: int, where: str) -> tuple[float, ...]:
    """Return `count` positive finite lengths [m], else raise UsageError naming `where`."""
    try:
        numbers = tuple(float(v) for v in values)
    except (TypeError, ValueError, OverflowError):
        numbers = ()
    # A scene file's sizes have the same bound: the collision library misses contacts with a box of 1e18 m.
    if len(numbers) != count or not all(0.0 < v <= MAX_MAGNITUDE for v in numbers):
        raise UsageError(f"{where}: expected {count} positive lengths in [m] up to {MAX_MAGNITUDE:,.0f}, "
                         f"got {reprlib.repr(values)}")
    return numbers


def _mesh(filename: str | Path, size: Sequence[float], where: str) -> Shape:
    """Return the mesh shape of a file (checked as a scene file's mesh is), scaled by `size`."""
    scale = _lengths(size, 3, f"{where}: size")
    if not isinstance(filename, str | Path) or not str(filename):
        raise UsageError(f"{where}: filename: expected a mesh file's path, got {filename!r}")
    path = mesh_file(Path(filename), f"{where}: filename")
    return Shape("mesh", (), str(path), (scale[0], scale[1], scale[2]))
