"""Scene: named static frames and collision objects around a robot.

Frames may chain and may hang off robot links. Everything is resolved to the
planning frame (the URDF root) with the robot at its neutral configuration,
so world objects must sit in frames that do not move with the arm.

This module reads moveplan's own format (frames, objects, attached);
core/model/planning_scene.py reads a moveit_msgs/PlanningScene written as YAML (it places
objects with the robot in the scene's own robot state, as MoveIt does), and
core/model/scene_file.py tells the two apart.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..config import MAX_MAGNITUDE, check_keys, mapping, number, pose_angles
from ..errors import ConfigError, FrameNotFound
from ..types import CollisionObject, Frame, Shape
from .poses import pose_matrix, vector
from .robot import Robot

__all__ = [
    "MAX_SCENE_FRAMES", "MAX_SCENE_SHAPES", "PLANNING_SCENE_KEYS", "Scene", "check_shape_count", "empty_scene",
    "first_repeated", "mesh_file", "moveplan_scene", "planning_frame_names", "resolve_frames",
]

MAX_SCENE_SHAPES = 10_000
"""Collision shapes a scene may hold: MotionBenchMaker's scenes hold tens, a detailed cell a few thousand;
each shape costs collision checks at every state of every motion (docs/formats.md, Limits)."""
MAX_SCENE_FRAMES = 10_000
"""Frames a scene may define, subframes of PlanningScene objects included."""

_STL_HEADER = 84  # 80 bytes of text, then the triangle count
_STL_TRIANGLE = 50  # normal and three vertices as float32, then a 2-byte attribute
_STL_NUMBER = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)")
_FRAME_KEYS = {"name", "parent", "xyz", "rpy", "quat"}
_SHAPE_KEYS = {"box", "cylinder", "sphere", "mesh", "scale"}
_OBJECT_KEYS = {"name", "frame", "xyz", "rpy", "quat"} | _SHAPE_KEYS
_ATTACHED_KEYS = {"name", "link", "xyz", "rpy", "quat", "touch_links"} | _SHAPE_KEYS
# The fields of moveit_msgs/PlanningScene: a scene file with any of them is one.
PLANNING_SCENE_KEYS = {
    "name", "robot_state", "robot_model_name", "fixed_frame_transforms", "allowed_collision_matrix",
    "link_padding", "link_scale", "object_colors", "world", "is_diff",
}


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
        parts: PlanningScene object id -> the names of the objects it became (one per shape).
        subframes: PlanningScene object id -> the names of the frames its subframes became.
    """

    source: str
    frames: tuple[Frame, ...]
    objects: tuple[CollisionObject, ...]
    anchors: dict[str, tuple[str, NDArray[np.float64]]]
    allowed: frozenset[frozenset[str]] = frozenset()
    robot_state: dict[str, float] = field(default_factory=dict)
    parts: dict[str, tuple[str, ...]] = field(default_factory=dict)
    subframes: dict[str, tuple[str, ...]] = field(default_factory=dict)

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


def _shape(entry: dict[str, Any], where: str, folder: Path) -> Shape:
    kinds = [k for k in ("box", "cylinder", "sphere", "mesh") if k in entry]
    if len(kinds) != 1:
        raise ConfigError(f"{where}: give exactly one shape of box, cylinder, sphere, mesh")
    kind = kinds[0]
    value = entry[kind]
    if kind == "box":
        dims = tuple(float(v) for v in vector(value, 3, f"{where}.box"))
    elif kind == "cylinder":
        cyl = mapping(value, f"{where}.cylinder")
        check_keys(cyl, {"radius", "length"}, f"{where}.cylinder")
        dims = (number(cyl.get("radius"), f"{where}.cylinder.radius", positive=True),
                number(cyl.get("length"), f"{where}.cylinder.length", positive=True))
    elif kind == "sphere":
        dims = (number(value, f"{where}.sphere", positive=True),)
    else:
        if not isinstance(value, str):
            raise ConfigError(f"{where}.mesh: expected a file name, got {value!r}")
        scale = tuple(float(v) for v in vector(entry.get("scale", [1, 1, 1]), 3, f"{where}.scale"))
        if any(not 0 < s <= MAX_MAGNITUDE for s in scale):
            raise ConfigError(f"{where}.scale: expected positive sizes up to {MAX_MAGNITUDE:g}, got {list(scale)}")
        path = mesh_file(folder / value, f"{where}.mesh")
        return Shape("mesh", (), str(path), (scale[0], scale[1], scale[2]))
    if any(d <= 0 for d in dims):
        raise ConfigError(f"{where}.{kind}: sizes must be positive, got {list(dims)}")
    return Shape(kind, dims)


def mesh_file(path: Path, where: str) -> Path:
    """Return a mesh file's absolute path, after checking it is a file and, for an STL, that it is whole and finite.

    The mesh loader (assimp) reads a cut binary STL, or one whose vertices are NaN, into
    geometry whose checks answer anything; other formats are left to it.

    Raises:
        ConfigError: Not a file, or an STL that is empty, cut, or has a vertex that is not finite.
    """
    try:
        if not path.is_file():
            raise ConfigError(f"{where}: mesh file not found: {path}")
        resolved = path.resolve()
        size = resolved.stat().st_size
    except OSError as exc:
        raise ConfigError(f"{where}: cannot use {str(path)[:120]} as a mesh file: {exc.strerror or exc}") from None
    if path.suffix.lower() == ".stl":
        problem = _stl_problem(resolved, size)
        if problem:
            raise ConfigError(f"{where}: {path}: {problem}")
    return resolved


def _stl_problem(path: Path, size: int) -> str:
    """Return what is wrong with an STL file ("" if nothing): binary when its size says so, else ASCII."""
    if size == 0:
        return "empty file, not an STL mesh"
    with path.open("rb") as stream:
        head = stream.read(_STL_HEADER)
    count = int.from_bytes(head[80:84], "little") if len(head) == _STL_HEADER else -1
    if count >= 0 and size == _STL_HEADER + _STL_TRIANGLE * count:
        if count == 0:
            return "binary STL with no triangles"
        triangles = np.memmap(path, dtype=np.dtype([("normal", "<f4", 3), ("vertices", "<f4", 9),
                                                    ("attribute", "<u2")]), mode="r", offset=_STL_HEADER)
        bad = np.flatnonzero(~np.isfinite(triangles["vertices"]).all(axis=1))
        return f"binary STL: triangle {bad[0]} has a vertex that is not finite" if len(bad) else ""
    if not head.lstrip().startswith(b"solid"):
        return (f"not an STL mesh: {size} bytes, but a binary STL of {count} triangles has "
                f"{_STL_HEADER + _STL_TRIANGLE * max(count, 0)} (cut, or not a mesh)")
    vertices = _STL_NUMBER.findall(path.read_bytes())
    if not vertices:
        return "ASCII STL with no vertices (cut, or not a mesh)"
    try:
        values = np.array(vertices, dtype=np.float64)
    except ValueError:
        return "ASCII STL: a vertex coordinate is not a number"
    bad = np.flatnonzero(~np.isfinite(values).all(axis=1))
    return f"ASCII STL: vertex {bad[0]} is not finite" if len(bad) else ""


def moveplan_scene(top: dict[str, Any], path: Path, robot: Robot) -> Scene:
    """Return the scene of a moveplan scene file's parsed `top` mapping, resolved against `robot`'s links."""
    source = str(path)
    check_keys(top, {"frames", "objects", "attached"}, source)
    frames: list[Frame] = []
    for k, entry in enumerate(_entries(top, "frames", source)):
        where = f"{source}: frames[{k}]"
        entry = mapping(entry, where)
        check_keys(entry, _FRAME_KEYS, where)
        for key in ("name", "parent"):
            if not isinstance(entry.get(key), str):
                raise ConfigError(f"{where}: '{key}' must be a frame name")
        transform = _pose(entry, where)
        frames.append(Frame(entry["name"], entry["parent"], transform))
    anchors = resolve_frames(frames, robot, source)

    check_shape_count(len(_entries(top, "objects", source)) + len(_entries(top, "attached", source)), source)
    root_q = robot.neutral()
    objects: list[CollisionObject] = []
    for k, entry in enumerate(_entries(top, "objects", source)):
        where = f"{source}: objects[{k}]"
        entry = mapping(entry, where)
        check_keys(entry, _OBJECT_KEYS, where)
        name, frame = entry.get("name"), entry.get("frame", robot.root_link)
        if not isinstance(name, str):
            raise ConfigError(f"{where}: 'name' must be a string")
        link, link_T_frame = Scene(source, (), (), anchors).anchor(str(frame), robot)
        if robot.model.frames[robot.model.getFrameId(link)].parentJoint != 0:
            raise ConfigError(f"{where}: frame '{frame}' moves with link '{link}'; "
                              "put objects carried by the robot under 'attached'")
        root_T_object = robot.frame_pose(root_q, link) @ link_T_frame @ _pose(entry, where)
        objects.append(CollisionObject(name, _shape(entry, where, path.parent), root_T_object))
    for k, entry in enumerate(_entries(top, "attached", source)):
        where = f"{source}: attached[{k}]"
        entry = mapping(entry, where)
        check_keys(entry, _ATTACHED_KEYS, where)
        name, carrier = entry.get("name"), entry.get("link")
        if not isinstance(name, str) or not isinstance(carrier, str):
            raise ConfigError(f"{where}: 'name' and 'link' must be strings")
        if carrier not in robot.link_names:
            raise FrameNotFound(carrier, where, robot.link_names)
        touch = tuple(str(t) for t in entry.get("touch_links") or [])
        transform = _pose(entry, where)
        objects.append(CollisionObject(name, _shape(entry, where, path.parent), transform, carrier, touch))
    if (twice := first_repeated(o.name for o in objects)) is not None:
        raise ConfigError(f"{source}: object name '{twice}' is used twice")
    return Scene(source, tuple(frames), tuple(objects), anchors)


def _pose(entry: dict[str, Any], where: str) -> NDArray[np.float64]:
    """Return the transform of a scene entry's xyz and rpy or quat; rpy angles are read as task files read them."""
    rpy = entry.get("rpy")
    return pose_matrix(entry.get("xyz"), None if rpy is None else list(pose_angles(rpy, f"{where}.rpy")),
                       entry.get("quat"), where)


def check_shape_count(count: int, source: str) -> None:
    """Raise ConfigError if a scene has more than MAX_SCENE_SHAPES collision shapes."""
    if count > MAX_SCENE_SHAPES:
        raise ConfigError(f"{source}: {count} collision shapes; moveplan checks at most {MAX_SCENE_SHAPES} "
                          "per scene (merge small ones into boxes or meshes)")


def first_repeated(names: Iterable[str]) -> str | None:
    """Return the first name that comes a second time, None if all differ."""
    seen: set[str] = set()
    for name in names:
        if name in seen:
            return name
        seen.add(name)
    return None


def _entries(top: dict[str, Any], key: str, source: str) -> list[Any]:
    """Return the list under `key` (absent or null: empty), else raise ConfigError."""
    value = top.get(key)
    if value is None:
        return []
    if not isinstance(value, list):
        raise ConfigError(f"{source}: {key}: expected a list, got {type(value).__name__}")
    return value


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
