"""Readers for moveit_msgs/CollisionObject and AttachedCollisionObject as MoveIt's YAML files write them.

An object's shapes (primitives, then meshes) are placed in the object frame and the object in its
header frame; mesh files are checked where they are named.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ConfigError
from ..types import Shape, frozen_array
from .fields import MAX_MAGNITUDE, check_keys, mapping, number
from .meshes import mesh_file
from .ros_messages import header_frame, is_empty_pose, point, pose, string_list, yaml_list
from .xacro import PackagePath

__all__ = ["AttachedMessage", "ObjectMessage", "attached_collision_object", "attached_object", "collision_object"]

logger = logging.getLogger(__name__)

_ATTACHED_KEYS = {"link_name", "object", "touch_links", "detach_posture", "weight"}
_OBJECT_KEYS = {
    "header", "pose", "id", "type", "primitives", "primitive_poses", "meshes", "mesh_poses", "planes",
    "plane_poses", "subframe_names", "subframe_poses", "operation",
}
_PRIMITIVES = {1: "box", 2: "sphere", 3: "cylinder", 4: "cone"}  # SolidPrimitive type constants
_DIMENSIONS = {"box": "x, y, z (full sizes)", "sphere": "radius", "cylinder": "height, radius",
               "cone": "height, radius"}
_ADD = (0, "add", "ADD", "\x00", b"\x00")  # CollisionObject.ADD as numbers, names or a byte


@dataclass(frozen=True)
class ObjectMessage:
    """A moveit_msgs/CollisionObject, parsed: shapes placed in the object frame, the object in its header frame.

    Attributes:
        id: The object's name.
        frame: Its header.frame_id, "" when empty (the planning frame, or an attached object's link).
        header_T_object: The object's pose in `frame`.
        parts: (name, shape, `object_T_shape`) per shape; empty for an object given by id alone
            (attaching the world object of that id).
        subframes: Subframe name -> `object_T_subframe`.
        where: The object's place in its file, for messages ("scene.yaml: world.collision_objects[0]").
    """

    id: str
    frame: str
    header_T_object: NDArray[np.float64]
    parts: tuple[tuple[str, Shape, NDArray[np.float64]], ...]
    subframes: dict[str, NDArray[np.float64]]
    where: str

    def __post_init__(self) -> None:
        object.__setattr__(self, "header_T_object", frozen_array(self.header_T_object, (4, 4), "header_T_object"))
        object.__setattr__(self, "parts", tuple((name, shape, frozen_array(shape_T, (4, 4), "object_T_shape"))
                                                for name, shape, shape_T in self.parts))
        object.__setattr__(self, "subframes", {name: frozen_array(sub_T, (4, 4), "object_T_subframe")
                                               for name, sub_T in self.subframes.items()})


@dataclass(frozen=True)
class AttachedMessage:
    """A moveit_msgs/AttachedCollisionObject, parsed.

    Attributes:
        link: The robot link (by name, not yet checked against a robot) the object is attached to.
        object: The object; with no parts when given by id alone (the world object of that id).
        touch_links: Links (or objects) the object may touch.
        where: The entry's place in its file, for messages.
    """

    link: str
    object: ObjectMessage
    touch_links: tuple[str, ...]
    where: str


def attached_object(value: Any, where: str) -> tuple[str, dict[str, Any], tuple[str, ...]]:
    """Return a moveit_msgs/AttachedCollisionObject's link name, its object (as written) and its touch links."""
    entry = mapping(value, where)
    check_keys(entry, _ATTACHED_KEYS, where)
    link = entry.get("link_name")
    if not isinstance(link, str) or not link:
        raise ConfigError(f"{where}.link_name: expected a link name, got {link!r}")
    written = mapping(entry.get("object"), f"{where}.object")
    if not isinstance(written.get("id"), str) or not written["id"]:
        raise ConfigError(f"{where}.object.id: expected an object name, got {written.get('id')!r}")
    number(entry.get("weight", 0.0), f"{where}.weight", bound=MAX_MAGNITUDE)
    return link, written, tuple(string_list(entry.get("touch_links"), f"{where}.touch_links"))


def attached_collision_object(value: Any, where: str, folder: Path, packages: PackagePath) -> AttachedMessage:
    """Return a moveit_msgs/AttachedCollisionObject with its object read as `collision_object` reads one."""
    link, written, touch = attached_object(value, where)
    return AttachedMessage(link, collision_object(written, f"{where}.object", folder, packages), touch, where)


def collision_object(value: Any, where: str, folder: Path, packages: PackagePath) -> ObjectMessage:
    """Return a moveit_msgs/CollisionObject's shapes, poses and subframes.

    Mesh files (`meshes[].resource`) resolve through `packages` (package://) or against `folder`.
    An object with no shapes is returned with no parts: only an attached object may be one.
    """
    entry = mapping(value, where)
    check_keys(entry, _OBJECT_KEYS, where)
    name = entry.get("id")
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{where}.id: expected an object name, got {name!r}")
    operation = entry.get("operation", 0)
    if isinstance(operation, bool) or operation not in _ADD:
        raise ConfigError(f"{where}.operation: only ADD (0) describes an object in a scene, got {operation!r} "
                          "(APPEND 1, REMOVE 2 and MOVE 3 edit a running scene)")
    if yaml_list(entry.get("planes"), f"{where}.planes"):
        raise ConfigError(f"{where}.planes: planes are not supported; use a thin box")
    shapes: list[Shape] = []
    shape_poses: list[NDArray[np.float64]] = []
    readers = (("primitives", "primitive_poses", _primitive),
               ("meshes", "mesh_poses", lambda item, at: _mesh(item, at, folder, packages)))
    for key, poses_key, read in readers:
        items = yaml_list(entry.get(key), f"{where}.{key}")
        poses = yaml_list(entry.get(poses_key), f"{where}.{poses_key}")
        if len(poses) != len(items):
            # MoveIt refuses such an object ("Number of primitive shapes does not match number of poses").
            raise ConfigError(f"{where}.{poses_key}: object '{name}' has {len(items)} {key} and {len(poses)} "
                              f"{poses_key}; give one pose per shape")
        shapes.extend(read(item, f"{where}.{key}[{i}]") for i, item in enumerate(items))
        shape_poses.extend(pose(p, f"{where}.{poses_key}[{i}]") for i, p in enumerate(poses))
    header_T_object = pose(entry.get("pose"), f"{where}.pose")
    if len(shapes) == 1 and is_empty_pose(entry.get("pose"), f"{where}.pose"):
        # MoveIt: an object with one shape and no pose takes the shape's pose as its own.
        header_T_object, shape_poses[0] = shape_poses[0], header_T_object
    parts = tuple((name if len(shapes) == 1 else f"{name}/{i}", shape, shape_T)
                  for i, (shape, shape_T) in enumerate(zip(shapes, shape_poses, strict=True)))
    sub_names = string_list(entry.get("subframe_names"), f"{where}.subframe_names")
    sub_poses = yaml_list(entry.get("subframe_poses"), f"{where}.subframe_poses")
    if len(sub_names) != len(sub_poses):
        raise ConfigError(f"{where}.subframe_poses: {len(sub_poses)} poses for {len(sub_names)} subframe_names")
    subframes = {sub: pose(p, f"{where}.subframe_poses[{i}]")
                 for i, (sub, p) in enumerate(zip(sub_names, sub_poses, strict=True))}
    return ObjectMessage(name, header_frame(entry, where, ""), header_T_object, parts, subframes, where)


def _primitive(value: Any, where: str) -> Shape:
    """Return the shape of a shape_msgs/SolidPrimitive."""
    entry = mapping(value, where)
    check_keys(entry, {"type", "dimensions", "polygon"}, where)
    kind_value = entry.get("type")
    kind = _PRIMITIVES.get(kind_value) if isinstance(kind_value, int) and not isinstance(kind_value, bool) else (
        kind_value.lower() if isinstance(kind_value, str) else None)
    if kind not in _DIMENSIONS:
        raise ConfigError(f"{where}.type: unknown primitive type {kind_value!r}; expected box (1), sphere (2), "
                          "cylinder (3) or cone (4)")
    dims = entry.get("dimensions")
    size = len(_DIMENSIONS[kind].split(","))
    if not isinstance(dims, list) or len(dims) != size:
        raise ConfigError(f"{where}.dimensions: a {kind} takes {size} number{'s' * (size > 1)} "
                          f"[{_DIMENSIONS[kind]}], got {dims!r}")
    values = [number(v, f"{where}.dimensions[{i}]", positive=True, bound=MAX_MAGNITUDE) for i, v in enumerate(dims)]
    if kind == "box":
        return Shape("box", tuple(values))
    if kind == "sphere":
        return Shape("sphere", (values[0],))
    height, radius = values
    if kind == "cone":
        logger.warning("%s: a cone is checked as the cylinder that encloses it", where)
    return Shape("cylinder", (radius, height))


def _mesh(value: Any, where: str, folder: Path, packages: PackagePath) -> Shape:
    """Return the mesh of a shape_msgs/Mesh: inline, or a file named by `resource` (robowflex's extension)."""
    entry = mapping(value, where)
    check_keys(entry, {"triangles", "vertices", "resource", "dimensions"}, where)
    if "resource" in entry or "dimensions" in entry:
        return _mesh_file(entry, where, folder, packages)
    vertices = [point(v, f"{where}.vertices[{i}]")
                for i, v in enumerate(yaml_list(entry.get("vertices"), f"{where}.vertices"))]
    triangles = []
    for i, item in enumerate(yaml_list(entry.get("triangles"), f"{where}.triangles")):
        at = f"{where}.triangles[{i}]"
        if isinstance(item, dict):
            triangle = mapping(item, at)
            check_keys(triangle, {"vertex_indices"}, at)
            item, at = triangle.get("vertex_indices"), f"{at}.vertex_indices"
        if not (isinstance(item, list) and len(item) == 3
                and all(isinstance(n, int) and not isinstance(n, bool) and 0 <= n < len(vertices) for n in item)):
            raise ConfigError(f"{at}: expected 3 indices into vertices (0 to {len(vertices) - 1}), got {item!r}")
        triangles.append(item)
    if not triangles:
        raise ConfigError(f"{where}: a mesh needs vertices and triangles, or a resource (a mesh file)")
    return Shape("mesh", vertices=np.array(vertices), triangles=np.array(triangles))


def _mesh_file(entry: dict[str, Any], where: str, folder: Path, packages: PackagePath) -> Shape:
    """Return a mesh given by file: `resource` (a path or a package:// URI), scaled by `dimensions`."""
    if "triangles" in entry or "vertices" in entry:
        raise ConfigError(f"{where}: give a resource (a mesh file) or triangles and vertices, not both")
    uri = entry.get("resource")
    if not isinstance(uri, str) or not uri.strip():
        raise ConfigError(f"{where}.resource: expected a mesh file path or package:// URI, got {uri!r}")
    scale = entry.get("dimensions", [1.0, 1.0, 1.0])
    if not isinstance(scale, list) or len(scale) != 3:
        raise ConfigError(f"{where}.dimensions: expected the scale [x, y, z] of the mesh, got {scale!r}")
    sx, sy, sz = (number(v, f"{where}.dimensions[{i}]", positive=True, bound=MAX_MAGNITUDE)
                  for i, v in enumerate(scale))
    if len(uri) > 4096 or "\0" in uri:
        raise ConfigError(f"{where}.resource: {uri[:60]!r}... is not a file name or package:// URI")
    path, package = packages.resolve_uri(uri.strip(), folder, f"{where}.resource")
    inside = f" (package '{package}' is {packages.find(package, where)})" if package else ""
    try:
        found = path.is_file()
    except OSError:
        found = False
    if not found:
        raise ConfigError(f"{where}.resource: mesh file not found: {str(path)[:200]}{inside}")
    return Shape("mesh", (), str(mesh_file(path, f"{where}.resource")), (sx, sy, sz))
