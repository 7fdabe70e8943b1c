"""Spheres that enclose a robot's collision geometry, fitted from the URDF (no hand-written sphere files).

Every shape becomes a triangle surface (a mesh as it is; a box by its faces; a
cylinder by the prism around it), its long triangles split. A ball holding a
triangle's three corners holds the whole triangle, so balls that together hold
every triangle hold the whole surface: a state whose spheres touch nothing has a
robot that touches nothing.

The balls are tight: a centre c inside the shape's convex hull, at depth d(c) below
its nearest facet, gets radius d(c) + e, so no ball reaches more than the excess e
past the hull. Centres are picked from candidates (points pulled inward from the
surface, and a grid inside the hull) by a greedy set cover, most uncovered surface
first; each triangle goes to the first ball holding its corners, and each ball then
shrinks to its own triangles. A link gets about `_MOST` balls, shared among its
shapes by surface area; a shape that would need more than its share is fitted again
with a larger excess.
"""

from __future__ import annotations

import itertools
import logging
from dataclasses import dataclass
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ..types import Shape
from . import _cache as disk_cache

__all__ = ["SphereSet", "fit_geometry", "fit_shape", "robot_spheres", "spheres_entry"]

logger = logging.getLogger(__name__)

_VERSION = 9  # bump when the fit changes, so cached models are rebuilt
_EXCESS_M = 0.015  # how far a ball may reach past its shape's convex hull [m]; more when the budget binds
_DETAIL = 25  # a shape's excess is at least its extent over this: a big shape is fitted coarser
_MOST = 24  # balls per link (the kernel's cost grows with them); a fit needing more is redone coarser
_MARGIN_M = 1e-6
_CACHE: dict[str, SphereSet] = {}


@dataclass(frozen=True)
class SphereSet:
    """Spheres in their joint's frame: centres (S, 3) [m], radii (S,) [m], joint id and owner name per sphere."""

    centres: NDArray[np.float64]
    radii: NDArray[np.float64]
    joints: NDArray[np.int64]
    owners: tuple[str, ...]


def spheres_entry(geometry: pin.GeometryModel, urdf: str) -> tuple[str, Path]:
    """Return the key of the spheres fitted to the robot's collision `geometry`, and their cache entry."""
    # The fit's settings and each shape's kind (a mesh, or its hull) are part of the key.
    settings = (_VERSION, _EXCESS_M, _DETAIL, _MOST)
    kinds = [type(obj.geometry).__name__ for obj in geometry.geometryObjects]
    key = disk_cache.digest(f"{settings}\n{kinds}\n{urdf}", geometry)
    return key, disk_cache.path(f"spheres-{key[:32]}.entry")


def robot_spheres(model: pin.Model, geometry: pin.GeometryModel, urdf: str) -> SphereSet:
    """Return spheres enclosing every shape of the robot's collision `geometry`, cached in memory and on disk."""
    key, path = spheres_entry(geometry, urdf)
    if key in _CACHE:
        return _CACHE[key]
    spheres = disk_cache.read(path, SphereSet)
    if spheres is None:
        disk_cache.announce(f"fitting collision spheres for {model.name}", path)
        objects = geometry.geometryObjects
        owners = [str(model.frames[obj.parentFrame].name) for obj in objects]
        surfaces = [None if isinstance(obj.geometry, coal.Sphere | coal.Capsule) else _surface(obj.geometry)
                    for obj in objects]
        # A link's balls are shared among its shapes by surface area: the kernel's cost grows per link.
        areas = [_area(*surface) if surface else 0.0 for surface in surfaces]
        link_area = {o: sum(a for a, p in zip(areas, owners, strict=True) if p == o) for o in owners}
        parts = []
        for obj, surface, area, owner in zip(objects, surfaces, areas, owners, strict=True):
            if surface is None:
                parts.append(_placed(obj, *_fit_coal(obj.geometry)))
                continue
            share = max(1, round(_MOST * area / link_area[owner])) if link_area[owner] > 0 else _MOST
            parts.append(_placed(obj, *_fit_triangles(*surface, share)))
        joints = [obj.parentJoint for obj in objects]
        # A robot without collision geometry (a bare kinematic model) has no spheres.
        spheres = SphereSet(
            np.concatenate([c for c, _ in parts]), np.concatenate([r for _, r in parts]),
            np.concatenate([np.full(len(r), j) for (_, r), j in zip(parts, joints, strict=True)]),
            tuple(o for (_, r), o in zip(parts, owners, strict=True) for _ in range(len(r))),
        ) if parts else SphereSet(np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=np.int64), ())
        disk_cache.write(path, spheres)
    _CACHE[key] = spheres
    return spheres


def fit_geometry(obj: pin.GeometryObject, most: int = _MOST) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return centres (in the object's joint frame) and radii of about `most` spheres enclosing one geometry object."""
    return _placed(obj, *_fit_coal(obj.geometry, most))


def fit_shape(shape: Shape, transform: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return centres (in the frame `transform` places the shape in) and radii enclosing a scene shape."""
    from .checker import coal_geometry

    centres, radii = _fit_coal(coal_geometry(shape))
    return centres @ transform[:3, :3].T + transform[:3, 3], radii


def _placed(obj: pin.GeometryObject, centres: NDArray[np.float64], radii: NDArray[np.float64]) -> tuple[
        NDArray[np.float64], NDArray[np.float64]]:
    """Return spheres given in a geometry object's own frame in its joint's frame."""
    placement = obj.placement
    return centres @ np.asarray(placement.rotation).T + np.asarray(placement.translation), radii


def _fit_coal(geometry: coal.CollisionGeometry, most: int = _MOST) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return spheres enclosing a coal shape, in the shape's own frame (about `most` for a meshed shape)."""
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
    return _fit_triangles(vertices, triangles, most)


def _area(vertices: NDArray[np.float64], triangles: NDArray[np.int64]) -> float:
    """Return the area of a triangle surface [m^2]."""
    a, b, c = vertices[triangles[:, 0]], vertices[triangles[:, 1]], vertices[triangles[:, 2]]
    return float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2)


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


def _fit_triangles(vertices: NDArray[np.float64], triangles: NDArray[np.int64], most: int) -> tuple[
        NDArray[np.float64], NDArray[np.float64]]:
    """Return at most `most` spheres covering every triangle, each reaching little past the shape's hull."""
    corners = vertices[triangles]
    if len(corners) == 0:
        return np.zeros((0, 3)), np.zeros(0)
    hull = _hull_planes(corners.reshape(-1, 3))
    extent = float(np.linalg.norm(np.ptp(corners.reshape(-1, 3), axis=0)))
    # A shape needs a ball per excess or two of its extent, often more: finer starts only overshoot the budget.
    excess = max(_EXCESS_M, extent / _DETAIL, extent / (2 * most))
    while True:
        centres, radii = _cover(corners, hull, excess)
        # Once the excess passes the extent, one ball holds everything: the loop ends there at the latest.
        if len(radii) <= most or excess > extent:
            return centres, radii
        # The count falls about as 1/excess (thick shapes) to 1/excess^2 (thin plates).
        excess *= max(1.2, np.sqrt(len(radii) / most))


def _cover(corners: NDArray[np.float64], hull: tuple[NDArray[np.float64], NDArray[np.float64]],
           excess: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return spheres covering every triangle (T, 3, 3), each reaching at most `excess` [m] past the `hull` planes."""
    corners = _split(corners, excess)
    normals, offsets = hull
    owner = np.full(len(corners), -1, dtype=np.int64)
    chosen: list[NDArray[np.float64]] = []
    # Centres are picked to cover points on the surface (cheap); a ball held back by half an
    # edge there mostly holds whole triangles. Each triangle then goes to the first pick that
    # holds its three corners. Triangles no pick holds get a second pass with centres on them.
    candidates = _candidates(corners, normals, offsets, excess)
    points = _thin(corners.reshape(-1, 3), excess / 2)
    for _ in range(2):
        radii = _depth(candidates, normals, offsets) + excess
        for c in _greedy_cover(points, candidates, radii - excess / 2):
            if _claim(corners, owner, candidates[c], radii[c], len(chosen)):
                chosen.append(candidates[c])
        missed = corners[owner < 0]
        candidates, points = np.vstack([missed.mean(axis=1), missed.reshape(-1, 3)]), missed.reshape(-1, 3)
    centres = np.array(chosen).reshape(-1, 3)
    kept = _prune(corners, owner, centres, _depth(centres, normals, offsets) + excess)
    radii_out = [float(np.max(np.linalg.norm(corners[owner == k].reshape(-1, 3) - centres[k], axis=1))) + _MARGIN_M
                 for k in kept]
    centres_out = list(centres[kept])
    # Whatever is left (rarely anything: every triangle is within `excess` of its centroid): its own ball.
    for triangle in corners[owner < 0]:
        centre = (triangle.min(axis=0) + triangle.max(axis=0)) / 2
        centres_out.append(centre)
        radii_out.append(float(np.max(np.linalg.norm(triangle - centre, axis=1))) + _MARGIN_M)
    return np.array(centres_out).reshape(-1, 3), np.array(radii_out)


def _claim(corners: NDArray[np.float64], owner: NDArray[np.int64], centre: NDArray[np.float64], radius: float,
           index: int) -> bool:
    """Return whether the ball holds any unowned triangle (all three corners), marking those `owner` = `index`."""
    free = np.flatnonzero(owner < 0)
    reach = np.linalg.norm(corners[free] - centre, axis=2).max(axis=1)
    held = free[reach <= radius - _MARGIN_M]
    owner[held] = index
    return len(held) > 0


def _prune(corners: NDArray[np.float64], owner: NDArray[np.int64], centres: NDArray[np.float64],
           radii: NDArray[np.float64]) -> list[int]:
    """Return the balls still needed once each ball whose triangles the others hold is dropped (`owner` updated)."""
    kept = np.ones(len(centres), dtype=bool)
    for k in np.argsort(np.bincount(owner[owner >= 0], minlength=len(centres)), kind="stable"):
        mine = np.flatnonzero(owner == k)
        # Only balls that overlap this one can hold its triangles.
        overlap = np.linalg.norm(centres - centres[k], axis=1) < radii + radii[k]
        others = np.flatnonzero(kept & overlap & (np.arange(len(centres)) != k))
        reach = np.linalg.norm(corners[mine, None] - centres[None, others, None], axis=3).max(axis=2)
        holds = reach <= radii[others] - _MARGIN_M
        if holds.any(axis=1).all():
            owner[mine] = others[np.argmax(holds, axis=1)]
            kept[k] = False
    return [int(k) for k in np.flatnonzero(kept)]


def _split(corners: NDArray[np.float64], edge: float) -> NDArray[np.float64]:
    """Return triangles (T, 3, 3) covering the same surface, halving longest edges until none exceeds `edge` [m]."""
    while True:
        edges = np.linalg.norm(corners - np.roll(corners, -1, axis=1), axis=2)  # edge k: corner k -> k+1
        longest = np.argmax(edges, axis=1)
        split = edges[np.arange(len(corners)), longest] > edge
        if not split.any():
            return corners
        keep, cut = corners[~split], corners[split]
        k = longest[split]
        rows = np.arange(len(cut))
        a, b, c = cut[rows, k], cut[rows, (k + 1) % 3], cut[rows, (k + 2) % 3]
        middle = (a + b) / 2
        corners = np.concatenate([keep, np.stack([a, middle, c], axis=1), np.stack([middle, b, c], axis=1)])


def _hull_planes(points: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the hull's outward facet normals (F, 3) and offsets (F,), n.x + offset <= 0 inside; none if flat."""
    from scipy.spatial import ConvexHull, QhullError

    spread = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    if len(points) < 4 or spread[2] <= 1e-6 * spread[0]:
        return np.zeros((0, 3)), np.zeros(0)
    try:
        equations = ConvexHull(points).equations
    except QhullError:
        return np.zeros((0, 3)), np.zeros(0)
    return equations[:, :3], equations[:, 3]


def _depth(points: NDArray[np.float64], normals: NDArray[np.float64], offsets: NDArray[np.float64]) -> NDArray[
        np.float64]:
    """Return each point's distance inside the hull [m] (0 outside it, and for a flat shape)."""
    if len(normals) == 0:
        return np.zeros(len(points))
    depth: NDArray[np.float64] = np.maximum(-(points @ normals.T + offsets).max(axis=1), 0.0)
    return depth


def _candidates(corners: NDArray[np.float64], normals: NDArray[np.float64], offsets: NDArray[np.float64],
                excess: float) -> NDArray[np.float64]:
    """Return candidate centres inside the hull: surface points pulled inward, and a grid `excess` * 2/3 apart."""
    if len(normals) == 0:
        return np.zeros((0, 3))
    points = _thin(corners.reshape(-1, 3), excess / 2)
    # Inward along the nearest facet's normal: deeper centres take bigger balls that still end `excess` out.
    nearest = normals[np.argmax(points @ normals.T + offsets, axis=1)]
    pulled = [points - depth * nearest for depth in excess * np.array([0.5, 1.0, 2.0, 4.0])]
    lo, hi = points.min(axis=0), points.max(axis=0)
    axes = [np.arange(a + excess / 3, b, excess * 2 / 3) for a, b in zip(lo, hi, strict=True)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    everywhere = np.vstack([*pulled, grid])
    inside: NDArray[np.float64] = everywhere[(everywhere @ normals.T + offsets).max(axis=1) < 0.0]
    return inside


def _thin(points: NDArray[np.float64], spacing: float) -> NDArray[np.float64]:
    """Return one of `points` per occupied cell of a grid with `spacing` [m]."""
    cells = np.round(points / spacing).astype(np.int64)
    cells -= cells.min(axis=0)
    size = cells.max(axis=0) + 1
    _, first = np.unique((cells[:, 0] * size[1] + cells[:, 1]) * size[2] + cells[:, 2], return_index=True)
    return points[first]


def _greedy_cover(points: NDArray[np.float64], centres: NDArray[np.float64], radii: NDArray[np.float64]) -> list[
        int]:
    """Return the balls a greedy set cover of `points` picks, each covering the most still uncovered points."""
    from scipy.sparse import csr_matrix
    from scipy.spatial import cKDTree

    if len(points) == 0 or len(centres) == 0:
        return []
    near = cKDTree(points).query_ball_point(centres, np.maximum(radii, 0.0))
    counts = np.fromiter(map(len, near), dtype=np.int64, count=len(near))
    rows = np.repeat(np.arange(len(centres)), counts)
    cols = np.fromiter(itertools.chain.from_iterable(near), dtype=np.int64, count=int(counts.sum()))
    holds = csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(centres), len(points)))
    held_by = holds.T.tocsr()
    gains = counts.astype(float)
    covered = np.zeros(len(points), dtype=bool)
    chosen: list[int] = []
    while gains.max() > 0.5:
        best = int(np.argmax(gains))
        row = holds.indices[holds.indptr[best]:holds.indptr[best + 1]]
        new = row[~covered[row]]
        covered[new] = True
        chosen.append(best)
        # Every ball holding a newly covered point gains one point less.
        sizes = held_by.indptr[new + 1] - held_by.indptr[new]
        entries = np.repeat(held_by.indptr[new] - np.cumsum(sizes) + sizes, sizes) + np.arange(sizes.sum())
        gains -= np.bincount(held_by.indices[entries], minlength=len(gains))
    return chosen
