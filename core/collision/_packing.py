"""How the sphere filter's arrays travel to its kernels: packed in one float and one integer array.

A search calls the kernels thousands of times, and each array argument costs a call as much as
judging a state: the kernels take three arrays instead of 39. `unpack` in core/collision/_kernels.py
reads them back in LAYOUT's order. Plain numpy: packing needs no numba.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["LAYOUT", "WORLD", "Packed", "pack", "pack_robot"]

# The filter's arrays, in the order `pack` stores and `unpack` reads them: name, dimensions, integer.
LAYOUT = (
    ("base", 1, False), ("group", 1, True), ("continuous", 1, True),
    ("table_axes", 2, True), ("table_start", 2, False), ("table_step", 2, False), ("table_count", 2, True),
    ("table_offset", 1, True), ("table_margin", 1, False), ("table_distance", 1, False),
    ("parents", 1, True), ("kinds", 1, True), ("axes", 2, False), ("iq", 1, True), ("prot", 3, False),
    ("ptrans", 2, False),
    ("centres", 2, False), ("radii", 1, False), ("sjoint", 1, True), ("start", 1, True),
    ("ojoint", 1, True), ("ocentre", 2, False), ("oradius", 1, False),
    ("icentres", 2, False), ("iradii", 1, False), ("ijoint", 1, True), ("istart", 1, True),
    ("pairs", 2, True),
    ("okind", 1, True), ("opos", 2, False), ("orot", 3, False), ("osize", 2, False), ("osolid", 1, True),
    ("check", 2, True), ("oball", 1, False),
    ("mimic_q", 1, True), ("mimic_leader", 1, True), ("mimic_scale", 1, False), ("mimic_offset", 1, False),
)


WORLD = ("okind", "opos", "orot", "osize", "osolid", "check", "oball")
"""The world's arrays, one run of LAYOUT; the others are the robot's."""
_AT = [name for name, _, _ in LAYOUT].index(WORLD[0])
_PARTS = (range(_AT), range(_AT, _AT + len(WORLD)), range(_AT + len(WORLD), len(LAYOUT)))
_INTEGER = np.array([integer for _, _, integer in LAYOUT])
Packed = tuple[Any, Any, Any]
"""Float values, integer values, and per LAYOUT entry its offset and shape among them."""


def pack_robot(arrays: dict[str, Any]) -> tuple[Packed, Packed]:
    """Return the robot's arrays before and after the world's in LAYOUT, each packed as `pack` packs them."""
    return _piece(arrays, _PARTS[0]), _piece(arrays, _PARTS[2])


def pack(robot: tuple[Packed, Packed], world: dict[str, Any]) -> Packed:
    """Return a filter's arrays as one float and one integer array and where each lies: `robot`'s and `world`'s.

    A compiled call costs ~0.07 us per array argument: the kernels take these three instead of 39.
    The robot's pieces (`pack_robot`, 660 kB with its distance tables) are copied, not converted again.
    """
    pieces = (robot[0], _piece(world, _PARTS[1]), robot[1])
    head, sizes = np.zeros((len(LAYOUT), 4), dtype=np.int64), [0, 0]
    for (floats, ints, rows), part in zip(pieces, _PARTS, strict=True):
        head[part] = rows
        head[part, 0] += np.where(_INTEGER[part], sizes[1], sizes[0])
        sizes[0], sizes[1] = sizes[0] + len(floats), sizes[1] + len(ints)
    return np.concatenate([p[0] for p in pieces]), np.concatenate([p[1] for p in pieces]), head


def _piece(arrays: dict[str, Any], part: range) -> Packed:
    """Return the LAYOUT arrays of `part` as float and integer values, and per entry its offset and shape among them."""
    floats: list[NDArray[Any]] = []
    ints: list[NDArray[Any]] = []
    head, sizes = np.zeros((len(part), 4), dtype=np.int64), [0, 0]
    for row, (name, ndim, integer) in enumerate(LAYOUT[part.start:part.stop]):
        array = np.asarray(arrays[name], dtype=np.int64 if integer else np.float64)
        if array.ndim != ndim:
            raise ValueError(f"{name}: expected {ndim} dimensions, got shape {array.shape}")
        head[row, 0] = sizes[integer]
        head[row, 1:1 + ndim] = array.shape
        (ints if integer else floats).append(array.ravel())
        sizes[integer] += array.size
    return (np.concatenate(floats) if floats else np.zeros(0), np.concatenate(ints) if ints else np.zeros(0, np.int64),
            head)
