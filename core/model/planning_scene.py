"""MoveIt's moveit_msgs/PlanningScene, written as YAML, read into a moveplan Scene.

Read as MoveIt's PlanningScene::setPlanningSceneMsg reads it, with these choices:

- A collision object's shapes (primitives, then meshes) become one moveplan object each,
  named `id/0`, `id/1`, ... (just `id` for a lone shape); allowed-collision entries naming
  the id apply to every part. Object and shape poses compose as in MoveIt, including its
  rule that a lone shape's pose is the object's pose when the object has none.
- Primitive types are names in any case or SolidPrimitive numbers (1 box, 2 sphere,
  3 cylinder, 4 cone). A cone is checked as the cylinder enclosing it (conservative);
  prisms and planes are errors. Only the ADD operation describes an object in a scene.
- Frames: an empty `header.frame_id` is the planning frame (for attached objects: their
  link); objects are placed with the robot in the scene's own robot state, as MoveIt
  does. `fixed_frame_transforms` become scene frames; one for the planning frame itself
  must be the identity and is skipped. Subframes become frames named `id/subframe`.
- The allowed collision matrix is read as MoveIt reads it (upper triangle, then default
  entries for pairs it does not list); its allowed pairs come on top of the SRDF's disabled
  pairs, so a `false` entry does not re-enable a pair the SRDF disables. Unknown names are
  ignored, as in MoveIt.
- Ignored, with a warning where they would change the result: link_padding, link_scale,
  object_colors, a robot_model_name of another robot. `is_diff` scenes are read whole: there
  is no running scene to apply them to. Errors: an octomap with data (moveplan checks
  objects only), a virtual joint away from the identity (moveplan plans in the URDF root frame).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..config.fields import check_keys, mapping, number
from ..errors import ConfigError, UnknownName
from ..types import CollisionObject, Frame, Shape
from .moveit_messages import (
    header_frame,
    is_empty_pose,
    known_joints,
    point,
    pose,
    robot_state,
    string_list,
    transform,
    yaml_list,
)
from .robot import Robot
from .scene import PLANNING_SCENE_KEYS, Scene, check_shape_count, first_repeated, resolve_frames

__all__ = ["planning_scene"]

logger = logging.getLogger(__name__)

_WORLD_KEYS = {"collision_objects", "octomap"}
_OBJECT_KEYS = {
    "header", "pose", "id", "type", "primitives", "primitive_poses", "meshes", "mesh_poses", "planes",
    "plane_poses", "subframe_names", "subframe_poses", "operation",
}
_ATTACHED_KEYS = {"link_name", "object", "touch_links", "detach_posture", "weight"}
_ACM_KEYS = {"entry_names", "entry_values", "default_entry_names", "default_entry_values"}
_PRIMITIVES = {1: "box", 2: "sphere", 3: "cylinder", 4: "cone"}  # SolidPrimitive type constants
_DIMENSIONS = {"box": "x, y, z (full sizes)", "sphere": "radius", "cylinder": "height, radius",
               "cone": "height, radius"}
_ADD = (0, "add", "ADD", "\x00", b"\x00")  # CollisionObject.ADD as numbers, names or a byte


@dataclass(frozen=True)
class _Object:
    """A CollisionObject message, parsed: shapes placed in the object frame, the object in its header frame."""

    id: str
    frame: str
    header_T_object: NDArray[np.float64]
    parts: tuple[tuple[str, Shape, NDArray[np.float64]], ...]  # (name, shape, object_T_shape)
    subframes: dict[str, NDArray[np.float64]]  # name -> object_T_subframe


def planning_scene(top: dict[str, Any], path: Path, robot: Robot) -> Scene:
    """Return the scene a PlanningScene message (already parsed from YAML at `path`) describes."""
    source = str(path)
    check_keys(top, PLANNING_SCENE_KEYS, source)
    _warn_ignored(top, source, robot)
    joints, attached = robot_state(top.get("robot_state"), f"{source}: robot_state")
    state = known_joints(joints, robot, f"{source}: robot_state.joint_state.name")
    q = robot.neutral()
    for joint, value in state.items():
        q = robot.set_joint(q, joint, value)

    frames = _fixed_frames(top.get("fixed_frame_transforms"), source, robot)
    anchors = resolve_frames(frames, robot, source)
    world = mapping(top.get("world"), f"{source}: world")
    check_keys(world, _WORLD_KEYS, f"{source}: world")
    _check_octomap(world.get("octomap"), f"{source}: world.octomap")
    check_shape_count(_shape_count(world.get("collision_objects"), attached), source)
    placed = [
        _place(value, f"{source}: world.collision_objects[{k}]", "", robot, anchors, q)
        for k, value in enumerate(yaml_list(world.get("collision_objects"), f"{source}: world.collision_objects"))
    ]
    for k, value in enumerate(attached):
        where = f"{source}: robot_state.attached_collision_objects[{k}]"
        entry = mapping(value, where)
        check_keys(entry, _ATTACHED_KEYS, where)
        link = entry.get("link_name")
        if not isinstance(link, str) or link not in robot.link_names:
            raise UnknownName("link", str(link), f"{where}.link_name", robot.link_names)
        touch = tuple(string_list(entry.get("touch_links"), f"{where}.touch_links"))
        placed.append(_place(entry.get("object"), f"{where}.object", link, robot, anchors, q, touch))

    objects = [obj for group in placed for obj in group[1]]
    if (twice := first_repeated(o.name for o in objects)) is not None:
        raise ConfigError(f"{source}: collision object '{twice}' is defined twice")
    frames.extend(frame for group in placed for frame in group[2])
    if (twice := first_repeated(f.name for f in frames)) is not None:
        raise ConfigError(f"{source}: frame '{twice}' is defined twice")
    parts_of = {object_id: [o.name for o in parts] for object_id, parts, _ in placed}
    pairs = _allowed_pairs(top.get("allowed_collision_matrix"), f"{source}: allowed_collision_matrix",
                           [*robot.link_names, *parts_of])
    # Entries naming an object apply to each of its parts.
    allowed: set[frozenset[str]] = set()
    for first, second in map(tuple, pairs):
        for a in parts_of.get(first, [first]):
            allowed.update(frozenset((a, b)) for b in parts_of.get(second, [second]) if a != b)
    return Scene(source, tuple(frames), tuple(objects), resolve_frames(frames, robot, source), frozenset(allowed),
                 state)


def _place(
    value: Any,
    where: str,
    link: str,
    robot: Robot,
    anchors: dict[str, tuple[str, NDArray[np.float64]]],
    q: NDArray[np.float64],
    touch_links: tuple[str, ...] = (),
) -> tuple[str, list[CollisionObject], list[Frame]]:
    """Return a CollisionObject message's id, parts and subframes, placed with the robot at `q`.

    `link` is "" for a world object (placed in the planning frame), else the link it is attached to.
    """
    parsed = _collision_object(value, where, link or robot.root_link)
    frame_link, link_T_frame = _anchor(parsed.frame, anchors, robot, f"{where}.header.frame_id")
    root_T_header = robot.frame_pose(q, frame_link) @ link_T_frame
    # MoveIt fixes an attached object to its link where the scene's robot state puts it.
    parent_T_header = np.linalg.inv(robot.frame_pose(q, link)) @ root_T_header if link else root_T_header
    parent_T_object = parent_T_header @ parsed.header_T_object
    parts = [CollisionObject(name, shape, parent_T_object @ object_T_shape, link, touch_links)
             for name, shape, object_T_shape in parsed.parts]
    subframes = [Frame(f"{parsed.id}/{sub}", link or robot.root_link, parent_T_object @ object_T_sub)
                 for sub, object_T_sub in parsed.subframes.items()]
    return parsed.id, parts, subframes


def _shape_count(collision_objects: Any, attached: list[Any]) -> int:
    """Return the primitives and meshes of the scene's objects, counted before any is read (malformed entries: 0)."""
    entries = [*(collision_objects if isinstance(collision_objects, list) else []),
               *(a.get("object") for a in attached if isinstance(a, dict))]
    return sum(len(e.get(key) or ()) if isinstance(e, dict) and isinstance(e.get(key), list) else 0
               for e in entries for key in ("primitives", "meshes"))


def _anchor(
    frame: str, anchors: dict[str, tuple[str, NDArray[np.float64]]], robot: Robot, where: str
) -> tuple[str, NDArray[np.float64]]:
    """Return (robot link, `link_T_frame`) of a scene frame or robot link; FrameNotFound names `where`."""
    return Scene(where, (), (), anchors).anchor(frame, robot)


def _warn_ignored(top: dict[str, Any], source: str, robot: Robot) -> None:
    """Log a warning for each PlanningScene field that would change the result but is ignored."""
    model = top.get("robot_model_name")
    if model is not None and not isinstance(model, str):
        raise ConfigError(f"{source}: robot_model_name: expected a robot name, got a {type(model).__name__}")
    if model not in (None, "", robot.config.name, robot.config.srdf.name):
        model = model if len(model) <= 80 else model[:77] + "..."
        logger.warning("%s: robot_model_name '%s' is not the loaded robot '%s'", source, model, robot.config.name)
    for key, field_name, neutral in (("link_padding", "padding", 0.0), ("link_scale", "scale", 1.0)):
        for k, value in enumerate(yaml_list(top.get(key), f"{source}: {key}")):
            where = f"{source}: {key}[{k}]"
            entry = mapping(value, where)
            check_keys(entry, {"link_name", field_name}, where)
            if number(entry.get(field_name, neutral), f"{where}.{field_name}") != neutral:
                logger.warning("%s: ignored; moveplan checks links as the URDF gives them", where)
    yaml_list(top.get("object_colors"), f"{source}: object_colors")


def _check_octomap(value: Any, where: str) -> None:
    """Raise ConfigError if the world holds an octomap with data (moveplan cannot check against one)."""
    octomap = mapping(mapping(value, where).get("octomap"), f"{where}.octomap")
    if yaml_list(octomap.get("data"), f"{where}.octomap.data"):
        raise ConfigError(f"{where}: octomaps are not supported; give the obstacles as collision objects")


def _fixed_frames(value: Any, source: str, robot: Robot) -> list[Frame]:
    """Return scene frames from `fixed_frame_transforms` (geometry_msgs/TransformStamped entries)."""
    frames = []
    for k, item in enumerate(yaml_list(value, f"{source}: fixed_frame_transforms")):
        where = f"{source}: fixed_frame_transforms[{k}]"
        entry = mapping(item, where)
        check_keys(entry, {"header", "child_frame_id", "transform"}, where)
        child = entry.get("child_frame_id")
        if not isinstance(child, str) or not child.strip("/"):
            raise ConfigError(f"{where}.child_frame_id: expected a frame name, got {child!r}")
        child = child.lstrip("/")
        parent = header_frame(entry, where, robot.root_link)
        parent_T_child = transform(entry.get("transform"), f"{where}.transform")
        if child == robot.root_link:
            # MoveIt writes its planning frame among these; it adds nothing if it is the identity.
            if parent != robot.root_link or not np.allclose(parent_T_child, np.eye(4), atol=1e-9):
                raise ConfigError(f"{where}: frame '{child}' is the planning frame; "
                                  "it can only be the identity relative to itself")
            continue
        frames.append(Frame(child, parent, parent_T_child))
    return frames


def _collision_object(value: Any, where: str, default_frame: str) -> _Object:
    """Return a moveit_msgs/CollisionObject's shapes, poses and subframes."""
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
    for key, poses_key, read in (("primitives", "primitive_poses", _primitive), ("meshes", "mesh_poses", _mesh)):
        items = yaml_list(entry.get(key), f"{where}.{key}")
        poses = yaml_list(entry.get(poses_key), f"{where}.{poses_key}")
        if len(poses) != len(items):
            # MoveIt refuses such an object ("Number of primitive shapes does not match number of poses").
            raise ConfigError(f"{where}.{poses_key}: object '{name}' has {len(items)} {key} and {len(poses)} "
                              f"{poses_key}; give one pose per shape")
        shapes.extend(read(item, f"{where}.{key}[{i}]") for i, item in enumerate(items))
        shape_poses.extend(pose(p, f"{where}.{poses_key}[{i}]") for i, p in enumerate(poses))
    if not shapes:
        raise ConfigError(f"{where}: object '{name}' has no primitives or meshes")
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
    return _Object(name, header_frame(entry, where, default_frame), header_T_object, parts, subframes)


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
    values = [number(v, f"{where}.dimensions[{i}]", positive=True) for i, v in enumerate(dims)]
    if kind == "box":
        return Shape("box", tuple(values))
    if kind == "sphere":
        return Shape("sphere", (values[0],))
    height, radius = values
    if kind == "cone":
        logger.warning("%s: a cone is checked as the cylinder that encloses it", where)
    return Shape("cylinder", (radius, height))


def _mesh(value: Any, where: str) -> Shape:
    """Return the inline mesh of a shape_msgs/Mesh."""
    entry = mapping(value, where)
    check_keys(entry, {"triangles", "vertices"}, where)
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
        raise ConfigError(f"{where}: a mesh needs vertices and triangles")
    return Shape("mesh", vertices=np.array(vertices), triangles=np.array(triangles))


def _allowed_pairs(value: Any, where: str, names: list[str]) -> set[frozenset[str]]:
    """Return the pairs a moveit_msgs/AllowedCollisionMatrix allows, read as MoveIt reads it.

    `names` are the links and objects a default entry may pair with.
    """
    acm = mapping(value, where)
    check_keys(acm, _ACM_KEYS, where)
    entries = string_list(acm.get("entry_names"), f"{where}.entry_names")
    rows = yaml_list(acm.get("entry_values"), f"{where}.entry_values")
    if len(rows) != len(entries):
        raise ConfigError(f"{where}.entry_values: {len(rows)} rows for {len(entries)} entry_names")
    explicit: dict[frozenset[str], bool] = {}
    for i, row in enumerate(rows):
        at = f"{where}.entry_values[{i}]"
        if isinstance(row, dict):  # AllowedCollisionEntry as a message: {enabled: [...]}
            entry = mapping(row, at)
            check_keys(entry, {"enabled"}, at)
            row, at = entry.get("enabled"), f"{at}.enabled"
        values = _bools(row, at, len(entries))
        # MoveIt reads the upper triangle only.
        explicit.update({frozenset((entries[i], entries[j])): values[j] for j in range(i + 1, len(entries))})
    default_names = string_list(acm.get("default_entry_names"), f"{where}.default_entry_names")
    defaults = dict(zip(default_names, _bools(acm.get("default_entry_values") or [],
                                              f"{where}.default_entry_values", len(default_names)), strict=True))
    allowed = {pair for pair, value in explicit.items() if value and len(pair) == 2}
    for name, value in defaults.items():
        if not value:
            continue
        for other in names:
            pair = frozenset((name, other))
            # An explicit entry wins over defaults; a default `false` on either side forbids.
            if other != name and pair not in explicit and defaults.get(other, True):
                allowed.add(pair)
    return allowed


def _bools(value: Any, where: str, size: int) -> list[bool]:
    if not isinstance(value, list) or len(value) != size or not all(isinstance(v, bool) for v in value):
        raise ConfigError(f"{where}: expected a list of {size} true/false values, got {value!r}")
    return list(value)
