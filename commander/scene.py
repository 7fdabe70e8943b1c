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
from ..core.errors import UsageError
from ..core.types import CollisionObject, Shape
from ._messages import apply_scene, attached_messages, object_message, scene_message
from ._objects import apply_object, attach_existing, detach, on_link
from ._targets import frame_name
from ._world import World, current_world
from .conversions import list_to_pose, matrix_to_pose, pose_to_matrix
from .msgs import AttachedCollisionObject, PlanningScene, Pose, PoseStamped
from .msgs import CollisionObject as CollisionObjectMsg

__all__ = ["PlanningSceneInterface", "attach_existing", "detach"]

logger = logging.getLogger(__name__)


class PlanningSceneInterface:
    """The planning scene's collision objects: add, attach, detach, remove, list.

    Args:
        ns: MoveIt's namespace, a string: the robot created last (one is made from `$MOVEPLAN_ROBOT`
            if there is none); or the RobotCommander whose scene this is.
        synchronous, service_timeout: MoveIt's; accepted and unused (every call applies at once).
    """

    def __init__(self, ns: Any = "", synchronous: bool = True, service_timeout: float = 5.0) -> None:
        self._world = current_world(ns, "PlanningSceneInterface")

    def add_object(self, collision_object: CollisionObjectMsg) -> None:
        """Apply a moveit_msgs CollisionObject: ADD (or replace), APPEND shapes, MOVE or REMOVE it; return None.

        Its shapes are placed as MoveIt places them: each primitive and mesh at its pose in the
        object's frame, the object at `pose` in `header.frame_id` (the planning frame when empty),
        the robot where it is now. Planes are refused: use a thin box.
        """
        apply_object(self._world, collision_object, "add_object")

    def add_cone(self, name: str, pose: PoseStamped | Pose, height: float, radius: float) -> None:
        """Add a cone of `height` and `radius` [m], checked as the cylinder that encloses it; return None."""
        where = f"add_cone('{name}')"
        height, radius = _lengths([height, radius], 2, f"{where}: height, radius")
        logger.warning("%s: a cone is checked as the cylinder that encloses it", where)
        self._add(name, Shape("cylinder", (radius, height)), pose, where)

    def add_plane(self, name: str, pose: PoseStamped | Pose, normal: Sequence[float] = (0, 0, 1),
                  offset: float = 0) -> None:
        """Raise UsageError: an infinite plane is not supported; a thin box is."""
        raise UsageError(f"add_plane('{name}'): planes are not supported; add a thin box instead "
                         "(add_box(name, pose, (10, 10, 0.001)))")

    def get_planning_scene(self, components: int) -> PlanningScene:
        """Return the planning scene's parts that `components` (PlanningSceneComponents bits) ask for."""
        if isinstance(components, bool) or not isinstance(components, int):
            raise UsageError(f"get_planning_scene: expected PlanningSceneComponents bits, got {components!r}")
        return scene_message(self._world, components)

    def apply_planning_scene(self, planning_scene_message: PlanningScene) -> bool:
        """Apply a PlanningScene (a diff, or the whole scene), as move_group's apply_planning_scene; return True."""
        apply_scene(self._world, planning_scene_message)
        return True

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
        """Attach an object to `link`: a scene object's name, a CollisionObject, or an AttachedCollisionObject.

        A CollisionObject with shapes is added where it says, then attached; one without (or a
        name) is the scene object of that id. `touch_links` default to the link (MoveIt's); return None.
        """
        if isinstance(object, AttachedCollisionObject):
            link = link or object.link_name
            touch_links = touch_links if touch_links is not None else (object.touch_links or None)
            object = object.object
        name = object if isinstance(object, str) else str(getattr(object, "id", ""))
        if not link:
            raise UsageError(f"attach_object('{name}'): give the link to attach it to")
        if isinstance(object, CollisionObjectMsg) and (object.primitives or object.meshes):
            apply_object(self._world, object, f"attach_object('{name}')")
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
        return self._world.object_ids(attached=False)

    def get_known_object_names_in_roi(self, minx: float, miny: float, minz: float, maxx: float, maxy: float,
                                       maxz: float, with_type: bool = False) -> list[str]:
        """Return the world objects whose every shape's origin lies in the box [min, max] of the planning frame."""
        low, high = np.array([minx, miny, minz], dtype=float), np.array([maxx, maxy, maxz], dtype=float)
        objects = self._world.objects
        return [oid for oid in self.get_known_object_names()
                if all(bool(np.all((low <= objects[n].transform[:3, 3]) & (objects[n].transform[:3, 3] <= high)))
                       for n in self._world.parts(oid))]

    def get_object_poses(self, object_ids: Iterable[str]) -> dict[str, Pose]:
        """Return name -> pose in the planning frame of the world objects among `object_ids`."""
        known = self.get_known_object_names()
        wanted = _names(object_ids, "get_object_poses")
        return {n: matrix_to_pose(self._world.object_pose(n)) for n in wanted if n in known}

    def get_objects(self, object_ids: Iterable[str] = ()) -> dict[str, CollisionObjectMsg]:
        """Return name -> CollisionObject (shapes, poses in the planning frame) of world objects asked (all: none)."""
        wanted = set(_names(object_ids, "get_objects"))
        known = self.get_known_object_names()
        return {n: object_message(self._world, n) for n in known if not wanted or n in wanted}

    def get_attached_objects(self, object_ids: Iterable[str] = ()) -> dict[str, AttachedCollisionObject]:
        """Return name -> AttachedCollisionObject (in its link's frame) of the objects asked (all for none)."""
        return {m.object.id: m for m in attached_messages(self._world, _names(object_ids, "get_attached_objects"))}

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
        objects[name] = on_link(self._world, placed, link, touch_links, where)
        self._world.change(objects=objects)


def _placed(world: World, pose: PoseStamped | Pose, where: str) -> NDArray[np.float64]:
    """Return `root_T_pose` of a PoseStamped (in its frame, the robot where it is now) or a Pose (planning frame)."""
    if isinstance(pose, PoseStamped):
        frame = frame_name(pose.header.frame_id, f"{where}: header.frame_id") or world.robot(None).root_link
        return world.pose(frame) @ pose_to_matrix(pose.pose, f"{where}: pose")
    if isinstance(pose, Pose):
        return pose_to_matrix(pose, f"{where}: pose")
    if isinstance(pose, list | tuple) and len(pose) in (3, 6, 7):  # a position, or MoveIt's pose lists
        values = list(pose) + [0.0, 0.0, 0.0] * (len(pose) == 3)
        try:
            return pose_to_matrix(list_to_pose(values), f"{where}: pose")
        except UsageError as exc:
            raise UsageError(f"{where}: pose: {exc}") from None
    raise UsageError(f"{where}: expected a PoseStamped, a Pose or a list [x, y, z(, orientation)] in the planning "
                     f"frame, got {type(pose).__name__}")


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
