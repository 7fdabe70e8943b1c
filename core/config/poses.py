"""Poses and number lists as scene, request and MoveIt message files give them, checked where they are read."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ConfigError
from ..rotations import matrix_from_quaternion, matrix_from_rpy
from .fields import coordinates

__all__ = ["is_identity", "pose_matrix", "vector"]

# np.allclose(T, I, atol=1e-9) per entry: atol plus its relative tolerance (1e-5) of the identity's entry.
_IDENTITY, _IDENTITY_TOLERANCE = np.eye(4), 1e-9 + 1e-5 * np.eye(4)


def pose_matrix(xyz: Any, rpy: Any, quat: Any, where: str) -> NDArray[np.float64]:
    """Return the 4x4 transform of a position and an rpy (fixed X-Y-Z) or [x, y, z, w] quaternion."""
    transform = np.eye(4)
    transform[:3, 3] = vector(xyz if xyz is not None else [0, 0, 0], 3, f"{where}.xyz")
    if rpy is not None and quat is not None:
        raise ConfigError(f"{where}: give rpy or quat, not both")
    if quat is not None:
        try:
            transform[:3, :3] = matrix_from_quaternion(vector(quat, 4, f"{where}.quat"))
        except ValueError as exc:
            raise ConfigError(f"{where}.quat: {exc}") from None
    elif rpy is not None:
        transform[:3, :3] = matrix_from_rpy(*vector(rpy, 3, f"{where}.rpy"))
    return transform


def is_identity(transform: NDArray[np.float64]) -> bool:
    """Return True if a 4x4 transform is the identity as np.allclose(transform, I, atol=1e-9) judges it, 10x faster."""
    return bool((np.abs(transform - _IDENTITY) <= _IDENTITY_TOLERANCE).all())


def vector(value: Any, size: int, where: str) -> NDArray[np.float64]:
    """Return a list of `size` numbers from a YAML file, each within MAX_MAGNITUDE, as an array; `where` names it."""
    if not isinstance(value, list | tuple) or len(value) != size:
        shown = repr(value) if len(repr(value)) <= 80 else f"{repr(value)[:77]}..."
        raise ConfigError(f"{where}: expected a list of {size} numbers, got {shown}")
    # A coordinate of 1e18 m breaks the collision library's bounding volumes: a thousand kilometres is plenty.
    return np.array(coordinates(value, where))
