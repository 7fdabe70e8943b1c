"""A scene mesh read from its file into vertices and triangles, as MoveIt holds a mesh (shapes::Mesh)."""

from __future__ import annotations

import numpy as np

from ..types import Shape
from .checker import coal_geometry

__all__ = ["inline_mesh"]


def inline_mesh(shape: Shape, source: str) -> Shape:
    """Return `shape` with its mesh file read into vertices (scaled, in [m]) and triangles; other shapes as they are.

    Read by the loader collision checking uses (assimp, through coal), so the triangles are
    those checked.

    Raises:
        ConfigError: The file is missing or cannot be read as a mesh (names `source`).
    """
    if shape.kind != "mesh" or shape.vertices is not None:
        return shape
    mesh = coal_geometry(shape, source)
    vertices = np.asarray(mesh.vertices(), dtype=np.float64).reshape(-1, 3)
    triangles = np.array([[mesh.tri_indices(k)[i] for i in range(3)] for k in range(mesh.num_tris)], dtype=np.int64)
    return Shape("mesh", vertices=vertices, triangles=triangles)
