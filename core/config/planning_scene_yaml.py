"""MoveIt's moveit_msgs/PlanningScene, written as YAML, read into checked values; names stay unresolved.

Read as MoveIt's PlanningScene::setPlanningSceneMsg reads it, with these choices (core/model
resolves the values against the robot and places the objects):

- A collision object's shapes (primitives, then meshes) become one moveplan object each,
  named `id/0`, `id/1`, ... (just `id` for a lone shape). Object and shape poses compose as in
  MoveIt, including its rule that a lone shape's pose is the object's pose when the object has
  none. Meshes are inline (triangles, vertices) or, as robowflex and MotionBenchMaker write them,
  a `resource` file (a path relative to the scene file, or a package:// URI) scaled by `dimensions`.
- Primitive types are names in any case or SolidPrimitive numbers (1 box, 2 sphere,
  3 cylinder, 4 cone). A cone is checked as the cylinder enclosing it (conservative);
  prisms and planes are errors. Only the ADD operation describes an object in a scene.
- The allowed collision matrix is read as MoveIt reads it (upper triangle, then default
  entries for pairs it does not list).
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

from ..errors import ConfigError
from ..types import frozen_array
from .collision_objects import AttachedMessage, ObjectMessage, attached_collision_object, collision_object
from .fields import check_keys, mapping, number
from .robot_config import RobotConfig
from .ros_messages import header_frame, robot_state, string_list, transform, yaml_list
from .scene_yaml import check_shape_count
from .xacro import PackagePath

__all__ = [
    "PLANNING_SCENE_KEYS", "AllowedCollisions", "FixedTransform", "PlanningSceneFile", "allowed_collisions",
    "parse_planning_scene",
]

logger = logging.getLogger(__name__)

# The fields of moveit_msgs/PlanningScene: a scene file with any of them is one.
PLANNING_SCENE_KEYS = {
    "name", "robot_state", "robot_model_name", "fixed_frame_transforms", "allowed_collision_matrix",
    "link_padding", "link_scale", "object_colors", "world", "is_diff",
}
_WORLD_KEYS = {"collision_objects", "octomap"}
_ACM_KEYS = {"entry_names", "entry_values", "default_entry_names", "default_entry_values"}


@dataclass(frozen=True)
class FixedTransform:
    """One geometry_msgs/TransformStamped of `fixed_frame_transforms`, as written.

    Attributes:
        header: header.frame_id without a leading slash ("" when empty).
        child: child_frame_id without a leading slash.
        header_T_child: The transform.
        where: The entry's place in its file, for messages.
    """

    header: str
    child: str
    header_T_child: NDArray[np.float64]
    where: str

    def __post_init__(self) -> None:
        object.__setattr__(self, "header_T_child", frozen_array(self.header_T_child, (4, 4), "header_T_child"))


@dataclass(frozen=True)
class AllowedCollisions:
    """A moveit_msgs/AllowedCollisionMatrix as MoveIt reads it.

    Attributes:
        explicit: Pair -> allowed, from the upper triangle of entry_values.
        defaults: Name -> allowed with any name the matrix does not pair it with.
    """

    explicit: dict[frozenset[str], bool]
    defaults: dict[str, bool]

    def pairs(self, names: list[str]) -> set[frozenset[str]]:
        """Return the pairs allowed to touch; `names` are the links and objects a default entry may pair with."""
        allowed = {pair for pair, value in self.explicit.items() if value and len(pair) == 2}
        for name, value in self.defaults.items():
            if not value:
                continue
            for other in names:
                pair = frozenset((name, other))
                # An explicit entry wins over defaults; a default `false` on either side forbids.
                if other != name and pair not in self.explicit and self.defaults.get(other, True):
                    allowed.add(pair)
        return allowed


@dataclass(frozen=True)
class PlanningSceneFile:
    """A PlanningScene YAML file, read and checked; joint, link and frame names are resolved by core/model.

    Attributes:
        source: The file, for messages.
        joints: robot_state.joint_state as joint -> position in [rad] or [m].
        fixed_transforms: fixed_frame_transforms, in file order.
        objects: world.collision_objects, each with parts and a unique id.
        attached: robot_state.attached_collision_objects, in file order.
        allowed: The allowed collision matrix.
        name: The scene's `name` ("" when it has none).
    """

    source: str
    joints: dict[str, float]
    fixed_transforms: tuple[FixedTransform, ...]
    objects: tuple[ObjectMessage, ...]
    attached: tuple[AttachedMessage, ...]
    allowed: AllowedCollisions
    name: str = ""


def parse_planning_scene(top: dict[str, Any], path: Path, config: RobotConfig) -> PlanningSceneFile:
    """Return the PlanningScene at `path` (already parsed from YAML to `top`), for `config`'s robot, checked.

    Mesh files resolve through `config`'s package paths; a robot_model_name of another robot
    is logged.
    """
    source = str(path)
    check_keys(top, PLANNING_SCENE_KEYS, source)
    _warn_ignored(top, source, config)
    joints, attached = robot_state(top.get("robot_state"), f"{source}: robot_state")
    fixed = _fixed_transforms(top.get("fixed_frame_transforms"), source)
    world = mapping(top.get("world"), f"{source}: world")
    check_keys(world, _WORLD_KEYS, f"{source}: world")
    _check_octomap(world.get("octomap"), f"{source}: world.octomap")
    check_shape_count(_shape_count(world.get("collision_objects"), attached), source)
    packages = PackagePath(tuple(config.package_paths))
    objects: dict[str, ObjectMessage] = {}
    for k, value in enumerate(yaml_list(world.get("collision_objects"), f"{source}: world.collision_objects")):
        where = f"{source}: world.collision_objects[{k}]"
        message = collision_object(value, where, path.parent, packages)
        if not message.parts:
            raise ConfigError(f"{where}: object '{message.id}' has no primitives or meshes")
        if message.id in objects:
            raise ConfigError(f"{source}: collision object '{message.id}' is defined twice")
        objects[message.id] = message
    where = f"{source}: robot_state.attached_collision_objects"
    attached_messages = tuple(attached_collision_object(value, f"{where}[{k}]", path.parent, packages)
                              for k, value in enumerate(attached))
    allowed = allowed_collisions(top.get("allowed_collision_matrix"), f"{source}: allowed_collision_matrix")
    name = top.get("name")
    if name is not None and not isinstance(name, str):
        raise ConfigError(f"{source}: name: expected a string, got {name!r}")
    return PlanningSceneFile(source, joints, fixed, tuple(objects.values()), attached_messages, allowed, name or "")


def _shape_count(collision_objects: Any, attached: list[Any]) -> int:
    """Return the primitives and meshes of the scene's objects, counted before any is read (malformed entries: 0)."""
    entries = [*(collision_objects if isinstance(collision_objects, list) else []),
               *(a.get("object") for a in attached if isinstance(a, dict))]
    return sum(len(e.get(key) or ()) if isinstance(e, dict) and isinstance(e.get(key), list) else 0
               for e in entries for key in ("primitives", "meshes"))


def _warn_ignored(top: dict[str, Any], source: str, config: RobotConfig) -> None:
    """Log a warning for each PlanningScene field that would change the result but is ignored."""
    model = top.get("robot_model_name")
    if model is not None and not isinstance(model, str):
        raise ConfigError(f"{source}: robot_model_name: expected a robot name, got a {type(model).__name__}")
    if model not in (None, "", config.name, config.srdf.name):
        model = model if len(model) <= 80 else model[:77] + "..."
        logger.warning("%s: robot_model_name '%s' is not the loaded robot '%s'", source, model, config.name)
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


def _fixed_transforms(value: Any, source: str) -> tuple[FixedTransform, ...]:
    """Return the geometry_msgs/TransformStamped entries of `fixed_frame_transforms`."""
    entries = []
    for k, item in enumerate(yaml_list(value, f"{source}: fixed_frame_transforms")):
        where = f"{source}: fixed_frame_transforms[{k}]"
        entry = mapping(item, where)
        check_keys(entry, {"header", "child_frame_id", "transform"}, where)
        child = entry.get("child_frame_id")
        if not isinstance(child, str) or not child.strip("/"):
            raise ConfigError(f"{where}.child_frame_id: expected a frame name, got {child!r}")
        entries.append(FixedTransform(header_frame(entry, where, ""), child.lstrip("/"),
                                      transform(entry.get("transform"), f"{where}.transform"), where))
    return tuple(entries)


def allowed_collisions(value: Any, where: str) -> AllowedCollisions:
    """Return a moveit_msgs/AllowedCollisionMatrix's entries, read as MoveIt reads them."""
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
    return AllowedCollisions(explicit, defaults)


def _bools(value: Any, where: str, size: int) -> list[bool]:
    if not isinstance(value, list) or len(value) != size or not all(isinstance(v, bool) for v in value):
        raise ConfigError(f"{where}: expected a list of {size} true/false values, got {value!r}")
    return list(value)
