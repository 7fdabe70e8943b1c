"""MoveIt's text scene format (`.scene`, what RViz exports), read as PlanningScene::loadGeometryFromStream reads it.

    scene name
    * object id
    x y z                      (the object's pose: MoveIt's newer format only; the older one has
    qx qy qz qw                 no such lines, and its shape poses are in the planning frame)
    shape count
    box                        (or sphere r | cylinder r l | cone r l | mesh v t, its vertices and
    dx dy dz                    triangles | plane a b c d)
    x y z                      (the shape's pose, in the object's frame)
    qx qy qz qw
    r g b a                    (its colour, not used)
    subframe count             (newer format: name, then a pose, each)
    .

Boxes are full sizes, cylinders and cones radius then length. Objects are world objects in the
planning frame; one of several shapes becomes `id/0`, `id/1`... as a PlanningScene YAML's does, and
the scene keeps them grouped under their id (`SceneFile.parts`).
A cone is checked as the cylinder that encloses it; planes are refused; subframes are not read.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import ConfigError
from ..rotations import MIN_QUATERNION_NORM, matrix_from_quaternion
from ..types import Shape
from .fields import MAX_MAGNITUDE
from .scene_yaml import SceneEntry, SceneFile, check_shape_count

__all__ = ["parse_scene_text"]

logger = logging.getLogger(__name__)


class _Tokens:
    """The file's whitespace-separated words, with the line each came from."""

    def __init__(self, lines: list[str], path: Path) -> None:
        # A line starting with '*' is one word: the marker, the rest of the line the object's id.
        self.words: list[tuple[str, int, str]] = []
        for n, text in enumerate(lines, start=2):  # the file's first line is the scene's name
            stripped = text.strip()
            if stripped.startswith("*"):
                self.words.append(("*", n, stripped[1:].strip()))
            else:
                self.words.extend((word, n, "") for word in stripped.split())
        self.at, self.path = 0, path

    def word(self, what: str) -> str:
        """Return the next word, else raise ConfigError saying `what` was expected."""
        if self.at >= len(self.words):
            raise ConfigError(f"{self.path}: the file ends where {what} was expected (a .scene file ends with '.')")
        self.at += 1
        return self.words[self.at - 1][0]

    def line(self) -> int:
        """Return the line of the next word (the last line at the end)."""
        return self.words[min(self.at, len(self.words) - 1)][1] if self.words else 1

    def number(self, what: str, positive: bool = False) -> float:
        """Return the next word as a finite number within MAX_MAGNITUDE, else raise ConfigError."""
        line = self.line()
        text = self.word(what)
        try:
            value = float(text)
        except ValueError:
            raise ConfigError(f"{self.path}: line {line}: {what}: expected a number, got {text!r}") from None
        if not math.isfinite(value) or abs(value) > MAX_MAGNITUDE or (positive and value <= 0.0):
            bound = "a positive number" if positive else f"a finite number within {MAX_MAGNITUDE:,.0f}"
            raise ConfigError(f"{self.path}: line {line}: {what}: expected {bound}, got {text}")
        return value

    def count(self, what: str) -> int:
        """Return the next word as a count (a whole number >= 0)."""
        line = self.line()
        text = self.word(what)
        if not text.isdigit():
            raise ConfigError(f"{self.path}: line {line}: {what}: expected a count, got {text!r}")
        return int(text)

    def pose(self, what: str) -> NDArray[np.float64]:
        """Return the 4x4 pose of the next 7 numbers: x y z, then the quaternion qx qy qz qw."""
        xyz = [self.number(f"{what} position") for _ in range(3)]
        line = self.line()
        quat = [self.number(f"{what} orientation") for _ in range(4)]
        if float(np.linalg.norm(quat)) < MIN_QUATERNION_NORM:
            raise ConfigError(f"{self.path}: line {line}: {what} orientation {quat}: not a rotation (zero quaternion)")
        pose = np.eye(4)
        pose[:3, :3] = matrix_from_quaternion(quat)
        pose[:3, 3] = xyz
        return pose


def parse_scene_text(text: str, path: Path) -> SceneFile:
    """Return the objects of a MoveIt `.scene` file, checked; ConfigError names the file and line."""
    lines = text.splitlines()
    if not lines:
        raise ConfigError(f"{path}: empty; a .scene file starts with the scene's name")
    body = lines[1:]
    objects: list[SceneEntry] = []
    starts = [n for n, line in enumerate(body) if line.strip().startswith("*")]
    # MoveIt's test: the line after the first '*' has spaces (an object pose) in the newer format.
    new_format = bool(starts) and starts[0] + 1 < len(body) and " " in body[starts[0] + 1].strip()
    tokens = _Tokens(body, path)
    parts: dict[str, tuple[str, ...]] = {}
    while True:
        line = tokens.line()
        marker = tokens.word("'*' (an object) or '.' (the end)")
        if marker == ".":
            break
        if marker != "*":
            raise ConfigError(f"{path}: line {line}: expected '*' (an object) or '.' (the end), got {marker!r}")
        object_id = tokens.words[tokens.at - 1][2]
        entries = _object(tokens, object_id, line, new_format, path)
        objects.extend(entries)
        parts[object_id] = (*parts.get(object_id, ()), *(entry.name for entry in entries))
    check_shape_count(len(objects), str(path))
    return SceneFile(str(path), (), tuple(objects), (), name=lines[0], parts=parts)


def _object(tokens: _Tokens, name: str, line: int, new_format: bool, path: Path) -> list[SceneEntry]:
    """Return the shapes of the object `name`, whose '*' marker is on `line`."""
    if not name:
        raise ConfigError(f"{path}: line {line}: an object marker '*' without a name")
    where = f"object '{name}'"
    object_pose = tokens.pose(f"{where}: pose") if new_format else np.eye(4)
    count = tokens.count(f"{where}: shape count")
    shapes = []
    for k in range(count):
        shape = _shape(tokens, f"{where}: shape {k}")
        shape_pose = tokens.pose(f"{where}: shape {k} pose")
        for channel in "rgba":
            tokens.number(f"{where}: shape {k} colour {channel}")
        if shape is not None:
            shapes.append((shape, object_pose @ shape_pose))
    if new_format:
        for k in range(tokens.count(f"{where}: subframe count")):
            tokens.word(f"{where}: subframe {k} name")
            tokens.pose(f"{where}: subframe {k} pose")
            if k == 0:
                logger.warning("%s: %s: subframes are not read", path, where)
    names = [name] if len(shapes) == 1 else [f"{name}/{k}" for k in range(len(shapes))]
    return [SceneEntry(f"{path}: {where}", n, shape, pose) for n, (shape, pose) in zip(names, shapes, strict=True)]


def _shape(tokens: _Tokens, where: str) -> Shape | None:
    """Return the next shape (geometric_shapes' constructShapeFromText); None for none."""
    line = tokens.line()
    kind = tokens.word(f"{where}: its type")
    if kind == "box":
        return Shape("box", tuple(tokens.number(f"{where}: box size", positive=True) for _ in range(3)))
    if kind == "sphere":
        return Shape("sphere", (tokens.number(f"{where}: sphere radius", positive=True),))
    if kind in ("cylinder", "cone"):
        radius = tokens.number(f"{where}: {kind} radius", positive=True)
        length = tokens.number(f"{where}: {kind} length", positive=True)
        if kind == "cone":
            logger.warning("%s: a cone is checked as the cylinder that encloses it", where)
        return Shape("cylinder", (radius, length))
    if kind == "mesh":
        vertices, triangles = tokens.count(f"{where}: vertex count"), tokens.count(f"{where}: triangle count")
        points = np.array([[tokens.number(f"{where}: vertex {i}") for _ in range(3)] for i in range(vertices)])
        faces = np.array([[tokens.count(f"{where}: triangle {i}") for _ in range(3)] for i in range(triangles)])
        if not triangles or faces.max(initial=0) >= vertices:
            raise ConfigError(f"{tokens.path}: line {line}: {where}: a mesh needs triangles indexing its "
                              f"{vertices} vertices")
        return Shape("mesh", vertices=points, triangles=faces)
    if kind == "plane":
        raise ConfigError(f"{tokens.path}: line {line}: {where}: planes are not supported; use a thin box")
    raise ConfigError(f"{tokens.path}: line {line}: {where}: unknown shape {kind!r}; expected box, sphere, "
                      "cylinder, cone, mesh or plane")
