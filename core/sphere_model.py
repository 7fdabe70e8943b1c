"""Spheres that enclose a robot's collision geometry, fitted from the URDF (no hand-written sphere files).

Every shape becomes a triangle surface (a mesh as it is; a box by its faces; a
cylinder by the prism around it); long triangles are split, the triangles are
clustered (k-means on their centroids), and each cluster gets the ball about its
bounding box's centre that holds all its vertices. A ball holding a triangle's three corners holds the
whole triangle, so the union of the balls holds the whole surface: a state whose
spheres touch nothing has a robot that touches nothing.
"""

from __future__ import annotations

import hashlib
import logging
import os
import pickle
from dataclasses import dataclass
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from moveplan.core.types import Shape

__all__ = ["SphereSet", "fit_geometry", "fit_shape", "robot_spheres"]

logger = logging.getLogger(__name__)

_VERSION = 8  # bump when the fit changes, so cached models are rebuilt
_EDGE_M = 0.03  # longest triangle edge kept before clustering [m]
_SPHERE_M = 0.03  # about one sphere per this much of a shape's extent [m]
_MARGIN_M = 1e-6
_CACHE: dict[str, SphereSet] = {}


@dataclass(frozen=True)
class SphereSet:
    """Spheres in their joint's frame: centres (S, 3) [m], radii (S,) [m], joint id and owner name per sphere."""

    centres: NDArray[np.float64]
    radii: NDArray[np.float64]
    joints: NDArray[np.int64]
    owners: tuple[str, ...]


def robot_spheres(model: pin.Model, geometry: pin.GeometryModel, urdf: str) -> SphereSet:
    """Return spheres enclosing every shape of the robot's collision `geometry`, cached in memory and on disk."""
    digest = hashlib.sha256(f"{_VERSION}\n{urdf}".encode())
    for obj in geometry.geometryObjects:
        if obj.meshPath and Path(obj.meshPath).is_file():
            digest.update(Path(obj.meshPath).read_bytes())
    key = digest.hexdigest()
    if key in _CACHE:
        return _CACHE[key]
    path = _cache_dir() / f"spheres-{key[:32]}.pickle"
    spheres = _read(path)
    if spheres is None:
        objects = geometry.geometryObjects
        parts = [fit_geometry(obj) for obj in objects]
        owners = [str(model.frames[obj.parentFrame].name) for obj in objects]
        joints = [obj.parentJoint for obj in objects]
        spheres = SphereSet(
            np.concatenate([c for c, _ in parts]), np.concatenate([r for _, r in parts]),
            np.concatenate([np.full(len(r), j) for (_, r), j in zip(parts, joints, strict=True)]),
            tuple(o for (_, r), o in zip(parts, owners, strict=True) for _ in range(len(r))),
        )
        _write(path, spheres)
    _CACHE[key] = spheres
    return spheres


def fit_geometry(obj: pin.GeometryObject) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return centres (in the object's joint frame) and radii of spheres enclosing one geometry object."""
    centres, radii = _fit_coal(obj.geometry)
    placement = obj.placement
    return centres @ np.asarray(placement.rotation).T + np.asarray(placement.translation), radii


def fit_shape(shape: Shape, transform: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return centres (in the frame `transform` places the shape in) and radii enclosing a scene shape."""
    from moveplan.core.collision import coal_geometry

    centres, radii = _fit_coal(coal_geometry(shape))
    return centres @ transform[:3, :3].T + transform[:3, 3], radii


def _fit_coal(geometry: coal.CollisionGeometry) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return spheres enclosing a coal shape, in the shape's own frame."""
    if isinstance(geometry, coal.Sphere):
        return np.zeros((1, 3)), np.array([geometry.radius + _MARGIN_M])
    if isinstance(geometry, coal.Capsule):
        # A capsule is the union of balls along its axis: balls of radius sqrt(r^2 + (s/2)^2),
        # s apart, cover it.
        r, h = geometry.radius, geometry.halfLength
        count = max(1, int(np.ceil(2 * h / r)))
        z = np.linspace(-h, h, count + 1)
        step = 2 * h / count
        centres = np.column_stack([np.zeros_like(z), np.zeros_like(z), z])
        return centres, np.full(len(z), np.hypot(r, step / 2) + _MARGIN_M)
    vertices, triangles = _surface(geometry)
    return _fit_triangles(vertices, triangles)


def _surface(geometry: coal.CollisionGeometry) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Return a triangle surface enclosing a coal shape: its own triangles, or a polyhedron around it."""
    if isinstance(geometry, coal.BVHModelBase):
        vertices = np.asarray(geometry.vertices(), dtype=float)
        triangles = np.array([[t[0], t[1], t[2]] for t in (geometry.tri_indices(i) for i in range(geometry.num_tris))],
                             dtype=np.int64).reshape(-1, 3)
        return vertices, triangles
    if isinstance(geometry, coal.ConvexBase):
        # Hull vertices: their convex hull is the shape, and clustering the points as one
        # triangle fan per cluster would not hold; enclose every vertex and the hull's
        # triangles through qhull's triangulation of the same points.
        points = np.asarray(geometry.points(), dtype=float)
        return points, _hull_triangles(points)
    if isinstance(geometry, coal.Box):
        x, y, z = np.asarray(geometry.halfSide)
        corners = np.array([[sx * x, sy * y, sz * z] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        return corners, _hull_triangles(corners)
    if isinstance(geometry, coal.Cylinder | coal.Cone):
        # The prism around the cylinder: a polygon circumscribing its circle.
        sides = 16
        r, h = geometry.radius / np.cos(np.pi / sides), geometry.halfLength
        angles = 2 * np.pi * np.arange(sides) / sides
        ring = np.column_stack([r * np.cos(angles), r * np.sin(angles)])
        points = np.vstack([np.column_stack([ring, np.full(sides, -h)]), np.column_stack([ring, np.full(sides, h)])])
        return points, _hull_triangles(points)
    raise ValueError(f"no sphere fit for coal shape {type(geometry).__name__}")


def _hull_triangles(points: NDArray[np.float64]) -> NDArray[np.int64]:
    """Return the triangles of the convex hull of `points` (indices into `points`)."""
    from scipy.spatial import ConvexHull

    return np.asarray(ConvexHull(points).simplices, dtype=np.int64)


def _fit_triangles(vertices: NDArray[np.float64], triangles: NDArray[np.int64]) -> tuple[
        NDArray[np.float64], NDArray[np.float64]]:
    """Return spheres covering every triangle: split long ones, cluster them, one ball per cluster."""
    corners = vertices[triangles]  # (T, 3, 3)
    while True:
        edges = np.linalg.norm(corners - np.roll(corners, -1, axis=1), axis=2)  # edge k: corner k -> k+1
        longest = np.argmax(edges, axis=1)
        split = edges[np.arange(len(corners)), longest] > _EDGE_M
        if not split.any():
            break
        keep, cut = corners[~split], corners[split]
        k = longest[split]
        rows = np.arange(len(cut))
        a, b, c = cut[rows, k], cut[rows, (k + 1) % 3], cut[rows, (k + 2) % 3]
        middle = (a + b) / 2
        corners = np.concatenate([keep, np.stack([a, middle, c], axis=1), np.stack([middle, b, c], axis=1)])
    centroids = corners.mean(axis=1)
    extent = np.linalg.norm(np.ptp(centroids, axis=0))
    count = int(np.clip(np.ceil(extent / _SPHERE_M), 1, 24))
    labels = _kmeans(centroids, count)
    centres, radii = [], []
    for label in np.unique(labels):
        points = corners[labels == label].reshape(-1, 3)
        centre = (points.min(axis=0) + points.max(axis=0)) / 2
        centres.append(centre)
        radii.append(np.max(np.linalg.norm(points - centre, axis=1)) + _MARGIN_M)
    return np.array(centres), np.array(radii)


def _kmeans(points: NDArray[np.float64], count: int, rounds: int = 25) -> NDArray[np.int64]:
    """Return a cluster label per point: k-means from farthest-point seeds (deterministic)."""
    seeds = [0]
    distance = np.linalg.norm(points - points[0], axis=1)
    for _ in range(1, min(count, len(points))):
        seeds.append(int(np.argmax(distance)))
        distance = np.minimum(distance, np.linalg.norm(points - points[seeds[-1]], axis=1))
    centres = points[seeds]
    labels = np.zeros(len(points), dtype=np.int64)
    for _ in range(rounds):
        labels = np.argmin(np.linalg.norm(points[:, None, :] - centres[None], axis=2), axis=1)
        updated = np.array([points[labels == k].mean(axis=0) if (labels == k).any() else centres[k]
                            for k in range(len(centres))])
        if np.allclose(updated, centres):
            break
        centres = updated
    return labels


def _cache_dir() -> Path:
    """Return where fitted sphere sets are kept between runs."""
    if os.environ.get("MOVEPLAN_CACHE_DIR"):
        return Path(os.environ["MOVEPLAN_CACHE_DIR"])
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "moveplan"


def _read(path: Path) -> SphereSet | None:
    """Return the sphere set cached at `path`, or None if there is none or it is unreadable."""
    try:
        with path.open("rb") as stream:
            spheres = pickle.load(stream)  # noqa: S301 - our own cache file, written by _write
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ValueError):
        return None
    return spheres if isinstance(spheres, SphereSet) else None


def _write(path: Path, spheres: SphereSet) -> None:
    """Cache a sphere set at `path`; a cache that cannot be written is skipped."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_name(f"{path.name}.{os.getpid()}.partial")
        with partial.open("wb") as stream:
            pickle.dump(spheres, stream)
        partial.replace(path)
    except OSError as exc:
        logger.debug("sphere cache not written: %s", exc)
