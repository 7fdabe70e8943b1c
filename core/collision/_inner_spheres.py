"""Balls inside the robot's convex collision shapes: a ball of one touching an obstacle proves a collision.

The search treats a state as colliding when the convex hulls of the robot's shapes
touch something (core/collision/motion.py, conservative mode), and most states it asks coal
about do collide. A few of the largest balls inside each hull settle those without
coal: if one of them touches an obstacle, so does the hull.
"""

from __future__ import annotations

from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from . import _cache as disk_cache
from ._sphere_fit import SphereSet

__all__ = ["inner_entry", "inner_spheres"]

_VERSION = 1  # bump when the fit changes, so cached balls are rebuilt
_MEMORY: dict[str, SphereSet] = {}
_PER_SHAPE = 6  # balls per shape at most
_SMALLEST = 0.3  # stop at balls smaller than this fraction of a shape's largest
_GRID = 12  # candidate centres per axis of a shape's bounding box


def inner_entry(hulls: pin.GeometryModel, urdf: str) -> tuple[str, Path]:
    """Return the key of the balls inside the robot's hulls, and their cache entry."""
    key = disk_cache.digest(f"inner {_VERSION}\n{urdf}", hulls)
    return key, disk_cache.path(f"inner-{key[:32]}.entry")


def inner_spheres(model: pin.Model, hulls: pin.GeometryModel, urdf: str) -> SphereSet:
    """Return balls inside the convex shapes of `hulls` (the robot's geometry as convex hulls), per joint.

    Cached in memory and on disk, keyed by the URDF and its meshes: they take ~0.1 s to find.
    """
    key, path = inner_entry(hulls, urdf)
    if key not in _MEMORY:
        balls = disk_cache.read(path, SphereSet)
        if balls is None:
            balls = _fit(model, hulls)
            disk_cache.write(path, balls)
        _MEMORY[key] = balls
    return _MEMORY[key]


def _fit(model: pin.Model, hulls: pin.GeometryModel) -> SphereSet:
    """Return the balls inside every shape of `hulls`."""
    centres, radii, joints, owners = [], [], [], []
    for obj in hulls.geometryObjects:
        c, r = _inside(obj.geometry)
        placement = obj.placement
        centres.append(c @ np.asarray(placement.rotation).T + np.asarray(placement.translation))
        radii.append(r)
        joints.append(np.full(len(r), obj.parentJoint, dtype=np.int64))
        owners.extend([str(model.frames[obj.parentFrame].name)] * len(r))
    if not radii:  # a robot without collision geometry
        return SphereSet(np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=np.int64), ())
    return SphereSet(np.concatenate(centres).reshape(-1, 3), np.concatenate(radii),
                     np.concatenate(joints), tuple(owners))


def _inside(geometry: coal.CollisionGeometry) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return centres and radii of balls inside a convex coal shape (none for a shape that is not convex)."""
    if isinstance(geometry, coal.Sphere):
        return np.zeros((1, 3)), np.array([geometry.radius])
    if isinstance(geometry, coal.Capsule):
        z = np.linspace(-geometry.halfLength, geometry.halfLength, 3)
        return np.column_stack([np.zeros(3), np.zeros(3), z]), np.full(3, geometry.radius)
    if isinstance(geometry, coal.ConvexBase):
        points = np.asarray(geometry.points(), dtype=float)
    elif isinstance(geometry, coal.Box):
        x, y, z = np.asarray(geometry.halfSide)
        points = np.array([[sx * x, sy * y, sz * z] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    elif isinstance(geometry, coal.Cylinder):
        # A polygon inscribed in the circle: its prism lies inside the cylinder.
        angles = 2 * np.pi * np.arange(16) / 16
        ring = geometry.radius * np.column_stack([np.cos(angles), np.sin(angles)])
        h = geometry.halfLength
        points = np.vstack([np.column_stack([ring, np.full(16, -h)]), np.column_stack([ring, np.full(16, h)])])
    else:
        return np.zeros((0, 3)), np.zeros(0)  # a mesh (not convex): nothing is surely inside
    return _largest_balls(points)


def _largest_balls(points: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return up to a few of the largest balls inside the convex hull of `points`, greedily spread."""
    # Imported here: scipy.spatial costs ~0.4 s of start-up, and the balls are fitted once per robot.
    from scipy.spatial import ConvexHull, QhullError

    try:
        equations = ConvexHull(points).equations  # rows (n, b): n . x + b <= 0 inside, |n| = 1
    except QhullError:
        return np.zeros((0, 3)), np.zeros(0)  # flat: no volume
    lo, hi = points.min(axis=0), points.max(axis=0)
    axes = [np.linspace(a, b, _GRID + 2)[1:-1] for a, b in zip(lo, hi, strict=True)]
    candidates = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    depth = -np.max(candidates @ equations[:, :3].T + equations[:, 3], axis=1)
    keep = depth > 0
    candidates, depth = candidates[keep], depth[keep]
    centres: list[NDArray[np.float64]] = []
    radii: list[float] = []
    while len(depth) and len(radii) < _PER_SHAPE:
        best = int(np.argmax(depth))
        if radii and depth[best] < _SMALLEST * radii[0]:
            break
        centres.append(candidates[best])
        radii.append(float(depth[best]))
        outside = np.linalg.norm(candidates - candidates[best], axis=1) > depth[best]
        candidates, depth = candidates[outside], depth[outside]
    return np.array(centres).reshape(-1, 3), np.array(radii)
