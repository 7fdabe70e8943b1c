"""Mesh files a scene names: found, and for an STL checked whole and finite before the mesh loader reads it."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import ConfigError

__all__ = ["mesh_file"]

_STL_HEADER = 84  # 80 bytes of text, then the triangle count
_STL_TRIANGLE = 50  # normal and three vertices as float32, then a 2-byte attribute
_STL_NUMBER = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)")


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
