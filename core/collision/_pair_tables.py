"""Distance tables for the robot's link pairs whose relative pose depends on at most two joints.

A wrist's links sit millimetres apart in most configurations, so spheres around them
would touch almost always. Their relative pose depends only on the one or two joints
between them, so their distance, as convex hulls, is tabulated once per robot over a
grid of those joints. Between grid points the lower link moves relative to the upper
one by at most half a grid step times each joint's lever arm (the table's margin):
a pair whose tabulated distance at the nearest grid point exceeds the margin is apart.

The grid has a budget of points per table. Where a pair sits closer than that grid's margin in
most configurations (a UR5's upper arm passes ~13 mm over its base, its joints turn through
two full turns, so the budget leaves a 25 mm margin), the table could never call it apart,
and every state would go to coal: its grid is refined until the margin is about half the pair's
median distance, up to a larger budget.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from . import _cache as disk_cache
from ._certify import farthest_point, is_prismatic

__all__ = ["PairTable", "pair_tables", "tables_entry"]

_VERSION = 2  # bump when the tables change, so cached ones are rebuilt
_GRID_POINTS = 20000  # per table: ~0.2 s to build, 160 kB
_FINE_GRID_POINTS = 400_000  # the most a refined grid takes: ~4 s to build (once per robot), 3.2 MB
_MEMORY: dict[str, tuple[PairTable, ...]] = {}


@dataclass(frozen=True)
class PairTable:
    """Hull distances [m] of links `upper` and `lower` over a grid of the joints between them.

    Attributes:
        upper: The link whose joint is an ancestor of the other's.
        lower: The other link.
        q_index: Per grid axis, the configuration index of its joint.
        start: Per axis, the grid's first joint value [rad or m].
        step: Per axis, the grid spacing.
        distances: The hull distance at each grid point, shape (points per axis...).
        margin: The most `lower` moves relative to `upper` between a state and its nearest grid point [m].
    """

    upper: str
    lower: str
    q_index: tuple[int, ...]
    start: tuple[float, ...]
    step: tuple[float, ...]
    distances: NDArray[np.float64]
    margin: float


def tables_entry(hulls: pin.GeometryModel, disabled: frozenset[frozenset[str]], urdf: str) -> tuple[str, Path]:
    """Return the key of the robot's distance tables (see `pair_tables`), and their cache entry."""
    key = disk_cache.digest(f"pairs {_VERSION}\n{urdf}\n{sorted(map(sorted, disabled))}", hulls)
    return key, disk_cache.path(f"pairs-{key[:32]}.entry")


def pair_tables(
    model: pin.Model, hulls: pin.GeometryModel, disabled: frozenset[frozenset[str]], urdf: str
) -> tuple[PairTable, ...]:
    """Return a table for every checked link pair of `hulls` (the robot's convex geometry) that allows one.

    Cached in memory and on disk, keyed by the URDF, its meshes and the disabled pairs.
    """
    key, path = tables_entry(hulls, disabled, urdf)
    if key not in _MEMORY:
        tables = disk_cache.read(path, tuple)
        if tables is None:
            disk_cache.announce(f"tabulating distances of wrist link pairs for {model.name}", path)
            by_joints: dict[tuple[int, ...], list[tuple[str, str]]] = {}
            for upper, lower, joints in _tabulable(model, hulls, disabled):
                by_joints.setdefault(joints, []).append((upper, lower))
            tables = tuple(t for joints, pairs in by_joints.items() for t in _tables(model, hulls, pairs, joints))
            disk_cache.write(path, tables)
        _MEMORY[key] = tables
    return _MEMORY[key]


def _tabulable(
    model: pin.Model, hulls: pin.GeometryModel, disabled: frozenset[frozenset[str]]
) -> list[tuple[str, str, tuple[int, ...]]]:
    """Return (upper link, lower link, joints between) for each pair with one or two bounded joints between."""
    joint_of = {str(model.frames[g.parentFrame].name): g.parentJoint for g in hulls.geometryObjects}
    found = []
    for upper, ju in joint_of.items():
        for lower, jl in joint_of.items():
            if ju == jl or frozenset((upper, lower)) in disabled:
                continue
            between, j = list[int](), jl
            while j > 0 and j != ju and len(between) <= 2:
                between.append(j)
                j = model.parents[j]
            if j == ju and len(between) <= 2 and all(_bounded(model, k) for k in between):
                found.append((upper, lower, tuple(between)))
    return found


def _bounded(model: pin.Model, jid: int) -> bool:
    """Return True for a one-coordinate joint with finite limits (revolute or prismatic)."""
    index = model.idx_qs[jid]
    return bool(model.nqs[jid] == 1 and np.isfinite(model.lowerPositionLimit[index])
                and np.isfinite(model.upperPositionLimit[index]))


def _tables(
    model: pin.Model, hulls: pin.GeometryModel, pairs: list[tuple[str, str]], joints: tuple[int, ...],
    points: int = _GRID_POINTS,
) -> list[PairTable]:
    """Return the distance tables of `pairs`, which all depend on `joints`, over one grid of those joints.

    The grid has about `points` points, more where a pair is mostly nearer than its margin (`_finer`).
    """
    pair_model = pin.GeometryModel()
    ids: dict[str, list[int]] = {}
    for obj in hulls.geometryObjects:
        owner = str(model.frames[obj.parentFrame].name)
        if any(owner in pair for pair in pairs):
            ids.setdefault(owner, []).append(pair_model.addGeometryObject(obj.copy()))
    slices = []
    for upper, lower in pairs:
        first = len(pair_model.collisionPairs)
        for i in ids[upper]:
            for j in ids[lower]:
                pair_model.addCollisionPair(pin.CollisionPair(i, j))
        slices.append(slice(first, len(pair_model.collisionPairs)))
    levers = np.array([[_lever(model, hulls, lower, joint) for joint in joints] for _, lower in pairs])
    widest = levers.max(axis=0)
    index = [model.idx_qs[j] for j in joints]
    starts = np.array([model.lowerPositionLimit[i] for i in index])
    spans = np.array([model.upperPositionLimit[i] for i in index]) - starts
    # Equal margin per axis, as fine as the grid budget allows.
    per_axis = (np.prod(spans * widest) / points) ** (1 / len(joints)) / 2
    counts = np.maximum(2, np.ceil(spans * widest / (2 * per_axis)).astype(int) + 1)
    steps = spans / (counts - 1)
    grid = np.stack(np.meshgrid(*[a + d * np.arange(n) for a, d, n in zip(starts, steps, counts, strict=True)],
                                indexing="ij"), axis=-1).reshape(-1, len(joints))
    data, geometry_data = model.createData(), pair_model.createData()
    q = pin.neutral(model)
    distances = np.empty((len(grid), len(pair_model.collisionPairs)))
    results = geometry_data.distanceResults
    for k, values in enumerate(grid):
        q[index] = values
        pin.computeDistances(model, data, pair_model, geometry_data, q)
        distances[k] = [r.min_distance for r in results]
    tables = [PairTable(upper, lower, tuple(int(i) for i in index), tuple(map(float, starts)),
                        tuple(map(float, steps)), distances[:, where].min(axis=1).reshape(tuple(counts)),
                        float(steps / 2 @ lever))
              for (upper, lower), where, lever in zip(pairs, slices, levers, strict=True)]
    finer = _finer(tables, points, len(joints))
    return tables if finer is None else _tables(model, hulls, pairs, joints, finer)


def _finer(tables: list[PairTable], points: int, axes: int) -> int | None:
    """Return the grid points that bring each table's margin to about half its pair's median distance, if needed.

    A table needs more where its pair is no farther than its margin at most grid points: it
    would call the pair apart almost nowhere. None if none does, or the grid is at its largest.
    """
    shrink = max((t.margin / (float(np.median(t.distances)) / 2) for t in tables
                  if np.mean(t.distances > t.margin) < 0.5 and np.median(t.distances) > 0), default=1.0)
    wanted = min(_FINE_GRID_POINTS, int(np.ceil(points * shrink**axes)))  # the margin goes as points^(-1/axes)
    return wanted if wanted > points else None


def _lever(model: pin.Model, hulls: pin.GeometryModel, lower: str, joint: int) -> float:
    """Return how far [m] `lower`'s shapes move per unit of `joint` (a bound over all configurations)."""
    if is_prismatic(model.joints[joint].shortname()):
        return 1.0
    shapes = [g for g in hulls.geometryObjects if str(model.frames[g.parentFrame].name) == lower]
    # The shapes' joint origin sits a fixed chain of offsets (stretched by prismatic travel) below `joint`.
    offset, j = 0.0, shapes[0].parentJoint
    while j != joint:
        travel = 0.0
        if is_prismatic(model.joints[j].shortname()):
            k = model.idx_qs[j]
            travel = max(abs(model.lowerPositionLimit[k]), abs(model.upperPositionLimit[k]))
        offset += float(np.linalg.norm(model.jointPlacements[j].translation)) + travel
        j = model.parents[j]
    return offset + max(farthest_point(g) for g in shapes)

