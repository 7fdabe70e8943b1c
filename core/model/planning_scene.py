"""MoveIt's moveit_msgs/PlanningScene, written as YAML, read into a moveplan Scene.

Read as MoveIt's PlanningScene::setPlanningSceneMsg reads it, with these choices:

- A collision object's shapes (primitives, then meshes) become one moveplan object each,
  named `id/0`, `id/1`, ... (just `id` for a lone shape); allowed-collision entries naming
  the id apply to every part. Object and shape poses compose as in MoveIt, including its
  rule that a lone shape's pose is the object's pose when the object has none. Meshes are
  inline (triangles, vertices) or, as robowflex and MotionBenchMaker write them, a
  `resource` file (a path relative to the scene file, or a package:// URI) scaled by `dimensions`.
- Primitive types are names in any case or SolidPrimitive numbers (1 box, 2 sphere,
  3 cylinder, 4 cone). A cone is checked as the cylinder enclosing it (conservative);
  prisms and planes are errors. Only the ADD operation describes an object in a scene.
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
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..config import PackagePath, check_keys, mapping, number
from ..errors import ConfigError, UnknownName
from ..types import CollisionObject, Frame
from .moveit_messages import (
    ObjectMessage,
    attached_object,
    collision_object,
    header_frame,
    known_joints,
    robot_state,
    string_list,
    transform,
    yaml_list,
)
from .moveit_request import MotionPlanRequest
from .robot import Robot
from .scene import (
    PLANNING_SCENE_KEYS,
    Scene,
    check_shape_count,
    empty_scene,
    first_repeated,
    planning_frame_names,
    resolve_frames,
)

__all__ = ["attach_request_objects", "read_planning_scene"]

logger = logging.getLogger(__name__)

_WORLD_KEYS = {"collision_objects", "octomap"}
_ACM_KEYS = {"entry_names", "entry_values", "default_entry_names", "default_entry_values"}


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
    source = str(path)
    check_keys(top, PLANNING_SCENE_KEYS, source)
    _warn_ignored(top, source, robot)
    joints, attached = robot_state(top.get("robot_state"), f"{source}: robot_state")
    state = known_joints(joints, robot, f"{source}: robot_state.joint_state.name")
    q = robot.neutral()
    for joint, value in state.items():
        q = robot.set_joint(q, joint, value)

    frames = _fixed_frames(top.get("fixed_frame_transforms"), source, robot)
    fixed = Scene(source, tuple(frames), (), resolve_frames(frames, robot, source), robot_state=state)
    world = mapping(top.get("world"), f"{source}: world")
    check_keys(world, _WORLD_KEYS, f"{source}: world")
    _check_octomap(world.get("octomap"), f"{source}: world.octomap")
    check_shape_count(_shape_count(world.get("collision_objects"), attached), source)
    packages = PackagePath(tuple(robot.config.package_paths))
    objects = _Objects()
    for k, value in enumerate(yaml_list(world.get("collision_objects"), f"{source}: world.collision_objects")):
        where = f"{source}: world.collision_objects[{k}]"
        message = collision_object(value, where, path.parent, packages)
        if not message.parts:
            raise ConfigError(f"{where}: object '{message.id}' has no primitives or meshes")
        if message.id in objects.world:
            raise ConfigError(f"{source}: collision object '{message.id}' is defined twice")
        objects.world[message.id] = _place(message, where, "", robot, fixed, q)
    _attach(objects, attached, f"{source}: robot_state.attached_collision_objects", robot, fixed, q,
            path.parent, packages)
    scene = objects.scene(fixed, frames, robot)
    pairs = _allowed_pairs(top.get("allowed_collision_matrix"), f"{source}: allowed_collision_matrix",
                           [*robot.link_names, *scene.parts])
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
    _attach(objects, list(request.attached), f"{request.source}: start_state.attached_collision_objects", robot,
            scene, q, request.source.parent, packages)
    subframes = {name for names in scene.subframes.values() for name in names}
    source = str(request.source) if scene.source == empty_scene().source else scene.source
    return objects.scene(replace(scene, source=source), [f for f in scene.frames if f.name not in subframes], robot)


def _attach(
    objects: _Objects, entries: list[Any], where: str, robot: Robot, fixed: Scene, q: NDArray[np.float64],
    folder: Path, packages: PackagePath,
) -> None:
    """Attach moveit_msgs/AttachedCollisionObject entries to `objects`, as MoveIt attaches them."""
    for k, value in enumerate(entries):
        at = f"{where}[{k}]"
        link, written, touch = attached_object(value, at)
        if link not in robot.link_names:
            raise UnknownName("link", link, f"{at}.link_name", robot.link_names)
        unknown = [t for t in touch if t not in robot.link_names and t not in {*objects.world, *objects.attached}]
        if unknown:
            # MoveIt takes any name; one that is no link or object allows nothing, likely a typo.
            logger.warning("%s.touch_links: %s name no robot link or object; they allow no contact",
                           at, ", ".join(unknown[:10]))
        message = collision_object(written, f"{at}.object", folder, packages)
        world = objects.world.pop(message.id, None)
        objects.attached.pop(message.id, None)
        if message.parts:
            objects.attached[message.id] = _place(message, f"{at}.object", link, robot, fixed, q, touch)
        elif world is not None:
            objects.attached[message.id] = _carried(world, link, robot, q, touch)
        else:
            raise ConfigError(f"{at}.object: object '{message.id}' has no primitives or meshes, and no world "
                              f"object has that id to attach (world objects: {', '.join(objects.world) or 'none'})")


def _place(
    message: ObjectMessage, where: str, link: str, robot: Robot, fixed: Scene, q: NDArray[np.float64],
    touch_links: tuple[str, ...] = (),
) -> tuple[list[CollisionObject], list[Frame]]:
    """Return a CollisionObject message's parts and subframes, placed with the robot at `q`.

    `link` is "" for a world object (placed in the planning frame), else the link it is attached to.
    """
    frame = message.frame or link or robot.root_link
    frame_link, link_T_frame = Scene(f"{where}.header.frame_id", (), (), fixed.anchors).anchor(frame, robot)
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


def _shape_count(collision_objects: Any, attached: list[Any]) -> int:
    """Return the primitives and meshes of the scene's objects, counted before any is read (malformed entries: 0)."""
    entries = [*(collision_objects if isinstance(collision_objects, list) else []),
               *(a.get("object") for a in attached if isinstance(a, dict))]
    return sum(len(e.get(key) or ()) if isinstance(e, dict) and isinstance(e.get(key), list) else 0
               for e in entries for key in ("primitives", "meshes"))


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
    """Return scene frames from `fixed_frame_transforms` (geometry_msgs/TransformStamped entries).

    MoveIt writes each fixed frame F as {header.frame_id: F, child_frame_id: planning frame,
    transform: planning_T_F}, its planning frame P as {header.frame_id: P, child_frame_id: P}.
    Names of the planning frame that are no robot link (`world`) are kept as identity frames.
    """
    entries = []
    for k, item in enumerate(yaml_list(value, f"{source}: fixed_frame_transforms")):
        where = f"{source}: fixed_frame_transforms[{k}]"
        entry = mapping(item, where)
        check_keys(entry, {"header", "child_frame_id", "transform"}, where)
        child = entry.get("child_frame_id")
        if not isinstance(child, str) or not child.strip("/"):
            raise ConfigError(f"{where}.child_frame_id: expected a frame name, got {child!r}")
        entries.append((header_frame(entry, where, ""), child.lstrip("/"),
                        transform(entry.get("transform"), f"{where}.transform"), where))
    # A frame given relative to itself is MoveIt's planning frame; robowflex leaves that header out.
    planning = set(planning_frame_names(robot)) | {
        child for header, child, parent_T_child, _ in entries
        if header in ("", child) and np.allclose(parent_T_child, np.eye(4), atol=1e-9)}
    aliases: dict[str, Frame] = {}
    frames = []
    for header, child, parent_T_child, where in entries:
        if child in planning and header in planning | {""}:
            if not np.allclose(parent_T_child, np.eye(4), atol=1e-9):
                raise ConfigError(f"{where}: '{header or child}' and '{child}' both name the planning frame; "
                                  "the transform between them can only be the identity")
            for name in {header, child} - {"", *robot.link_names}:
                aliases.setdefault(name, Frame(name, robot.root_link, np.eye(4)))
        elif child in planning:
            frames.append(Frame(header, robot.root_link, parent_T_child))
        elif header == child:
            raise ConfigError(f"{where}: frame '{child}' relative to itself can only be the identity")
        else:
            frames.append(Frame(child, header or robot.root_link, parent_T_child))
    return [*aliases.values(), *frames]


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
