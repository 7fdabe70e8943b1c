"""MoveIt's text `.scene` format, written as PlanningScene::saveGeometryToStream writes it (the newer layout).

    scene name
    * object id
    x y z                      (the object's pose in the planning frame: MoveIt's writePoseToText)
    qx qy qz qw
    shape count
    box                        (geometric_shapes' saveAsText: box full sizes | sphere radius |
    dx dy dz                    cylinder radius length | mesh vertex and triangle counts, then both)
    x y z                      (the shape's pose in the object's frame)
    qx qy qz qw
    0 0 0 0                    (its colour: moveplan keeps none, and MoveIt writes this for none)
    0                          (subframe count)
    .

An object of several shapes sits at its first shape's pose, the others relative to it. Numbers
are the shortest text that reads back as the same double (Python's repr), a whole number without
its `.0`, as C++ streams print it; meshes are written scaled.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from ..errors import ConfigError
from ..rotations import quaternion_from_matrix
from ..types import CollisionObject, Shape

__all__ = ["format_scene_text"]


def format_scene_text(name: str, objects: Mapping[str, Sequence[CollisionObject]], source: str) -> str:
    """Return the text of a `.scene` file named `name` holding `objects`: id -> its parts, in the planning frame.

    Every part is a world object whose mesh, if any, is inline (vertices and triangles).

    Raises:
        ConfigError: An id is empty, or the name or an id holds a line break (a .scene file is read by
            lines); names `source`.
        ValueError: A part is attached to a link, or its mesh is a file.
    """
    if name and name.splitlines() != [name]:
        raise ConfigError(f"{source}: scene name {name!r}: a .scene file cannot hold a name with a line break")
    lines = [name]
    for object_id, parts in objects.items():
        if object_id.splitlines() != [object_id] or not object_id.strip():
            raise ConfigError(f"{source}: object id {object_id!r}: a .scene file cannot hold an empty id or one "
                              "with a line break")
        planning_T_object = parts[0].transform
        object_T_planning = _inverse(planning_T_object)
        lines += [f"* {object_id}", *_pose(planning_T_object), str(len(parts))]
        for k, part in enumerate(parts):
            if part.link:
                raise ValueError(f"{part.name}: attached to {part.link}; a .scene file holds world objects only")
            object_T_shape = np.eye(4) if k == 0 else object_T_planning @ part.transform
            lines += [*_shape(part.shape, part.name), *_pose(object_T_shape), "0 0 0 0"]
        lines.append("0")
    lines.append(".")
    return "\n".join(lines) + "\n"


def _shape(shape: Shape, name: str) -> list[str]:
    """Return a shape's lines as geometric_shapes' saveAsText writes them: its type, then its sizes."""
    if shape.kind == "mesh":
        if shape.vertices is None or shape.triangles is None:
            raise ValueError(f"{name}: mesh file {shape.mesh_path}: give its vertices and triangles")
        vertices = np.asarray(shape.vertices) * np.asarray(shape.scale)
        return ["mesh", f"{len(vertices)} {len(shape.triangles)}", *(_numbers(v) for v in vertices),
                *(" ".join(str(int(i)) for i in triangle) for triangle in shape.triangles)]
    return [shape.kind, _numbers(shape.dims)]  # box: x y z; sphere: r; cylinder: r then length, as moveplan keeps them


def _pose(pose: NDArray[np.float64]) -> list[str]:
    """Return a pose's two lines as MoveIt's writePoseToText writes them: `x y z`, then `qx qy qz qw`."""
    return [_numbers(pose[:3, 3]), _numbers(quaternion_from_matrix(pose[:3, :3]))]


def _inverse(pose: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return the inverse of a rigid transform, exact for the rotation (its transpose)."""
    inverse = np.eye(4)
    inverse[:3, :3] = pose[:3, :3].T
    inverse[:3, 3] = -pose[:3, :3].T @ pose[:3, 3]
    return inverse


def _numbers(values: Sequence[float] | NDArray[np.float64]) -> str:
    """Return numbers separated by spaces, each the shortest text that reads back as the same double."""
    texts = (repr(float(v)) for v in values)
    return " ".join(text[:-2] if text.endswith(".0") else text for text in texts)
