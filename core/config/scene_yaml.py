"""moveplan's own scene format (frames, objects, attached), read into checked values; names stay unresolved.

core/config/planning_scene_yaml.py reads a MoveIt PlanningScene written as YAML; core/model
resolves either against a robot into a Scene.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ConfigError
from ..types import Frame, Shape, frozen_array
from .fields import MAX_MAGNITUDE, check_keys, mapping, number, pose_angles
from .meshes import mesh_file
from .poses import pose_matrix, vector

__all__ = ["MAX_SCENE_SHAPES", "SceneEntry", "SceneFile", "check_shape_count", "first_repeated", "parse_scene"]

MAX_SCENE_SHAPES = 10_000
"""Collision shapes a scene may hold: MotionBenchMaker's scenes hold tens, a detailed cell a few thousand;
each shape costs collision checks at every state of every motion (docs/formats.md, Limits)."""

_FRAME_KEYS = {"name", "parent", "xyz", "rpy", "quat"}
_SHAPE_KEYS = {"box", "cylinder", "sphere", "mesh", "scale"}
_OBJECT_KEYS = {"name", "frame", "xyz", "rpy", "quat"} | _SHAPE_KEYS
_ATTACHED_KEYS = {"name", "link", "xyz", "rpy", "quat", "touch_links"} | _SHAPE_KEYS


@dataclass(frozen=True)
class SceneEntry:
    """An object of a moveplan scene file as written: a shape at a pose in a frame, or on a link.

    Attributes:
        where: The entry's place in its file, for messages ("scene.yaml: objects[0]").
        name: The object's name.
        shape: Its shape; a mesh file is checked and absolute.
        transform: `frame_T_object` for a world object, `link_T_object` for an attached one.
        frame: A world object's frame as written; None for the planning frame (and attached objects).
        link: The link carrying an attached object; "" for a world object.
        touch_links: Links an attached object may touch.
    """

    where: str
    name: str
    shape: Shape
    transform: NDArray[np.float64]
    frame: str | None = None
    link: str = ""
    touch_links: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "transform", frozen_array(self.transform, (4, 4), "transform"))


@dataclass(frozen=True)
class SceneFile:
    """A moveplan scene file, read and checked; frame, link and parent names are resolved by core/model.

    Attributes:
        source: The file, for messages.
        frames: Scene frames as written (`parent_T_frame`).
        objects: World objects.
        attached: Objects carried by robot links.
        name: The scene's name, where the file gives one (a `.scene` file's first line).
        parts: Object id -> the names of the objects its shapes became (`id/0`, `id/1`, ...), where the
            file groups shapes under an id (a `.scene` file); empty when each object is its own id.
    """

    source: str
    frames: tuple[Frame, ...]
    objects: tuple[SceneEntry, ...]
    attached: tuple[SceneEntry, ...]
    name: str = ""
    parts: dict[str, tuple[str, ...]] = field(default_factory=dict)


def parse_scene(top: dict[str, Any], path: Path) -> SceneFile:
    """Return the moveplan scene file at `path` (already parsed from YAML to `top`), checked."""
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
        frames.append(Frame(entry["name"], entry["parent"], _pose(entry, where)))

    check_shape_count(len(_entries(top, "objects", source)) + len(_entries(top, "attached", source)), source)
    objects: list[SceneEntry] = []
    for k, entry in enumerate(_entries(top, "objects", source)):
        where = f"{source}: objects[{k}]"
        entry = mapping(entry, where)
        check_keys(entry, _OBJECT_KEYS, where)
        name = entry.get("name")
        if not isinstance(name, str):
            raise ConfigError(f"{where}: 'name' must be a string")
        frame = str(entry["frame"]) if "frame" in entry else None
        objects.append(SceneEntry(where, name, _shape(entry, where, path.parent), _pose(entry, where), frame))
    attached: list[SceneEntry] = []
    for k, entry in enumerate(_entries(top, "attached", source)):
        where = f"{source}: attached[{k}]"
        entry = mapping(entry, where)
        check_keys(entry, _ATTACHED_KEYS, where)
        name, carrier = entry.get("name"), entry.get("link")
        if not isinstance(name, str) or not isinstance(carrier, str):
            raise ConfigError(f"{where}: 'name' and 'link' must be strings")
        touch = tuple(str(t) for t in entry.get("touch_links") or [])
        attached.append(SceneEntry(where, name, _shape(entry, where, path.parent), _pose(entry, where),
                                   link=carrier, touch_links=touch))
    if (twice := first_repeated(o.name for o in (*objects, *attached))) is not None:
        raise ConfigError(f"{source}: object name '{twice}' is used twice")
    return SceneFile(source, tuple(frames), tuple(objects), tuple(attached))


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


def _pose(entry: dict[str, Any], where: str) -> NDArray[np.float64]:
    """Return the transform of a scene entry's xyz and rpy or quat; rpy angles are read as task files read them."""
    rpy = entry.get("rpy")
    return pose_matrix(entry.get("xyz"), None if rpy is None else list(pose_angles(rpy, f"{where}.rpy")),
                       entry.get("quat"), where)


def _entries(top: dict[str, Any], key: str, source: str) -> list[Any]:
    """Return the list under `key` (absent or null: empty), else raise ConfigError."""
    value = top.get(key)
    if value is None:
        return []
    if not isinstance(value, list):
        raise ConfigError(f"{source}: {key}: expected a list, got {type(value).__name__}")
    return value
