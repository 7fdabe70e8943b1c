"""A fast conservative collision filter: the robot's enclosing spheres against the scene and themselves.

Compiled with numba (imported only when a filter is built, so commands that do not plan
never pay its start-up). One call checks a batch of configurations: forward kinematics
of the joint tree, then per owner (link or attached object) its bounding ball first and
its spheres only if that ball touches something. A state is "clear" only if no sphere
touches an obstacle or another owner's sphere; since the spheres enclose the real
geometry (core/sphere_model.py), a clear state is collision-free. Anything else is
"maybe": the caller asks the exact checker.
"""

from __future__ import annotations

from typing import Any

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from moveplan.core.robot import Robot
from moveplan.core.sphere_model import fit_shape, robot_spheres
from moveplan.core.types import CollisionObject

__all__ = ["SphereFilter", "UnsupportedJoint"]

# Joint kinds the kernel knows; anything else (planar, free-flyer, ...) makes the filter unavailable.
_REVOLUTE, _PRISMATIC, _UNBOUNDED = 1, 2, 3
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
_BOX, _SPHERE, _CYLINDER = 0, 1, 2
_KERNELS: dict[str, Any] = {}
_CLOSE: dict[str, frozenset[frozenset[str]]] = {}  # per URDF: link pairs whose spheres are mostly touching


class UnsupportedJoint(ValueError):
    """The robot has a joint the filter's kinematics do not handle."""


def _joint_kind(model: pin.Model, jid: int) -> tuple[int, tuple[float, float, float]]:
    """Return (kind, axis) of a pinocchio joint."""
    name = model.joints[jid].shortname().removeprefix("JointModel")
    for prefix, kind in (("RUB", _UNBOUNDED), ("R", _REVOLUTE), ("P", _PRISMATIC)):
        if name.startswith(prefix) and name[len(prefix):] in _AXES:
            return kind, _AXES[name[len(prefix):]]
    joint = model.joints[jid]
    if name in ("RevoluteUnaligned", "RevoluteUnboundedUnaligned", "PrismaticUnaligned"):
        kind = {"RevoluteUnaligned": _REVOLUTE, "RevoluteUnboundedUnaligned": _UNBOUNDED}.get(name, _PRISMATIC)
        return kind, tuple(float(v) for v in np.asarray(joint.extract().axis))  # type: ignore[return-value]
    raise UnsupportedJoint(f"joint '{model.names[jid]}' ({name}) is not handled by the sphere filter")


class SphereFilter:
    """Clears robot configurations whose enclosing spheres touch nothing."""

    def __init__(
        self,
        robot: Robot,
        geometry: pin.GeometryModel,
        objects: tuple[CollisionObject, ...],
        allowed: frozenset[frozenset[str]] = frozenset(),
        base: NDArray[np.float64] | None = None,
    ) -> None:
        """Fit spheres to `robot` (its `geometry`), add attached objects, and list what to check.

        States are the group's joint values; the other joints stay at `base` (default: the neutral
        configuration).

        Raises:
            UnsupportedJoint: The robot has a joint kind the kernel does not handle.
        """
        model = robot.model
        kinds = [(0, (0.0, 0.0, 1.0))] + [_joint_kind(model, j) for j in range(1, model.njoints)]
        self._parents = np.array(model.parents, dtype=np.int64)
        self._kind = np.array([k for k, _ in kinds], dtype=np.int64)
        self._axis = np.array([a for _, a in kinds], dtype=float)
        self._iq = np.array(model.idx_qs, dtype=np.int64)
        self._rot = np.array([np.asarray(p.rotation) for p in model.jointPlacements])
        self._trans = np.array([np.asarray(p.translation) for p in model.jointPlacements])

        robot_set = robot_spheres(model, geometry, robot.config.urdf)
        centres, radii = [robot_set.centres], [robot_set.radii]
        joints, owners = [robot_set.joints], list(robot_set.owners)
        touch: dict[str, frozenset[str]] = {}
        world = [obj for obj in objects if not obj.link]
        for obj in objects:
            if obj.link:
                frame = model.frames[model.getFrameId(obj.link)]
                c, r = fit_shape(obj.shape, np.asarray(frame.placement.homogeneous) @ obj.transform)
                centres.append(c)
                radii.append(r)
                joints.append(np.full(len(r), frame.parentJoint))
                owners.extend([obj.name] * len(r))
                touch[obj.name] = frozenset((obj.link, *obj.touch_links))
        centres_all, radii_all, joints_all = np.concatenate(centres), np.concatenate(radii), np.concatenate(joints)
        names = list(dict.fromkeys(owners))
        owner_index = np.array([names.index(o) for o in owners], dtype=np.int64)
        order = np.argsort(owner_index, kind="stable")
        self._centres, self._radii = centres_all[order], radii_all[order]
        self._sjoint, owner_index = joints_all[order], owner_index[order]
        self._start = np.searchsorted(owner_index, np.arange(len(names) + 1)).astype(np.int64)
        # Each owner's bounding ball, in its joint's frame.
        self._ojoint = self._sjoint[self._start[:-1]]
        self._ocentre = np.zeros((len(names), 3))
        self._oradius = np.zeros(len(names))
        for k in range(len(names)):
            c, r = self._centres[self._start[k]:self._start[k + 1]], self._radii[self._start[k]:self._start[k + 1]]
            middle = (c.min(axis=0) + c.max(axis=0)) / 2
            self._ocentre[k] = middle
            self._oradius[k] = np.max(np.linalg.norm(c - middle, axis=1) + r)

        disabled = robot.config.srdf.disabled_pairs | allowed
        pairs = []
        for a in range(len(names)):
            for b in range(a + 1, len(names)):
                na, nb = names[a], names[b]
                if self._ojoint[a] == self._ojoint[b] or frozenset((na, nb)) in disabled:
                    continue
                if na in touch.get(nb, ()) or nb in touch.get(na, ()):
                    continue
                pairs.append((a, b))
        pairs_array = np.array(pairs, dtype=np.int64).reshape(-1, 2)
        # Links that sit a few millimetres apart in most configurations (a wrist's neighbours)
        # would keep most states "maybe"; those pairs are checked exactly instead, in one batch.
        key = robot.config.urdf
        if key not in _CLOSE:
            robot_owners = sorted({names.index(o) for o in robot_set.owners})
            every = np.array([(a, b) for a in robot_owners for b in robot_owners
                              if a < b and self._ojoint[a] != self._ojoint[b]], dtype=np.int64).reshape(-1, 2)
            close = self._always_close(robot, every)
            _CLOSE[key] = frozenset(frozenset((names[a], names[b])) for a, b in every[close])
        hard = np.array([frozenset((names[a], names[b])) in _CLOSE[key] for a, b in pairs_array], dtype=bool)
        self._pairs = pairs_array[~hard]
        self.exact_pairs = tuple((names[a], names[b]) for a, b in pairs_array[hard])
        self._exact = _pair_pool(robot, geometry, self.exact_pairs)
        self._check = np.array([[frozenset((name, obj.name)) not in allowed for obj in world] for name in names],
                               dtype=np.bool_).reshape(len(names), len(world))
        self._kernel = _kernels()
        base = robot.neutral() if base is None else base
        kind, centre, rot, size = _obstacles(world)
        # Built once: the kernel runs thousands of times per search, and its call costs more than its work.
        self._args = (np.asarray(base, dtype=float), np.asarray(robot.q_index, dtype=np.int64),
                      np.asarray(robot.continuous, dtype=np.bool_), self._parents, self._kind, self._axis, self._iq,
                      self._rot, self._trans, self._centres, self._radii, self._sjoint, self._start, self._ojoint,
                      self._ocentre, self._oradius, self._pairs, kind, centre, rot, size, self._check)
        self._nq = model.nq
        self.clear(robot.values(base)[None, :])  # compile (or load) the kernel now, not mid-search

    def clear(self, values: NDArray[np.float64]) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
        """Return per group state (rows of `values`) True if certainly collision-free, and the configurations."""
        q = np.empty((len(values), self._nq))
        out = np.empty(len(values), dtype=np.bool_)
        self._kernel(values, *self._args, q, out)
        if self._exact is not None and out.any():
            cleared = np.flatnonzero(out)
            hits = pin.computeCollisionsInParallel(1, self._exact, q[cleared].T, True, False)
            out[cleared] = ~np.asarray(hits, dtype=bool)
        return out, q

    def _always_close(self, robot: Robot, pairs: NDArray[np.int64], samples: int = 200) -> NDArray[np.bool_]:
        """Return per owner pair True if its spheres touch in over a third of random configurations."""
        model = robot.model
        rng = np.random.default_rng(0)
        lower = np.nan_to_num(np.asarray(model.lowerPositionLimit), nan=-np.pi, posinf=np.pi, neginf=-np.pi)
        upper = np.nan_to_num(np.asarray(model.upperPositionLimit), nan=np.pi, posinf=np.pi, neginf=-np.pi)
        data = model.createData()
        touching = np.zeros(len(pairs))
        for _ in range(samples):
            q = pin.normalize(model, rng.uniform(np.maximum(lower, -np.pi), np.minimum(upper, np.pi)))
            pin.forwardKinematics(model, data, q)
            rotations = np.array([np.asarray(data.oMi[int(j)].rotation) for j in self._sjoint])
            translations = np.array([np.asarray(data.oMi[int(j)].translation) for j in self._sjoint])
            world = np.einsum("sij,sj->si", rotations, self._centres) + translations
            for k, (a, b) in enumerate(pairs):
                sa, sb = slice(self._start[a], self._start[a + 1]), slice(self._start[b], self._start[b + 1])
                gaps = np.linalg.norm(world[sa, None] - world[None, sb], axis=2)
                touching[k] += bool(np.any(gaps <= self._radii[sa, None] + self._radii[None, sb]))
        return touching > samples / 3


def _pair_pool(robot: Robot, geometry: pin.GeometryModel, pairs: tuple[tuple[str, str], ...]) -> Any:
    """Return a pinocchio pool that checks the convex hulls of the shapes of `pairs` (link names), or None."""
    if not pairs:
        return None
    from moveplan.core.collision import convex_hull

    model = robot.model
    exact = geometry.copy()
    exact.removeAllCollisionPairs()
    for obj in exact.geometryObjects:
        # Hulls enclose their meshes (so a pair free as hulls is free) and cost a fraction of a mesh check.
        if isinstance(obj.geometry, coal.BVHModelBase) and obj.meshPath:
            key = (str(obj.meshPath), tuple(float(v) for v in obj.meshScale))
            obj.geometry = convex_hull(obj.geometry, key, f"{robot.config.urdf_path}: {obj.name}")
    owner = [str(model.frames[g.parentFrame].name) for g in exact.geometryObjects]
    wanted = {frozenset(p) for p in pairs}
    for i in range(len(owner)):
        for j in range(i + 1, len(owner)):
            if frozenset((owner[i], owner[j])) in wanted:
                exact.addCollisionPair(pin.CollisionPair(i, j))
    return pin.GeometryPool(model, exact, 1)


def _obstacles(world: list[CollisionObject]) -> tuple[NDArray[Any], ...]:
    """Return world obstacles as arrays: kind, centre, rotation, size (box half sides; radius; radius, half length)."""
    from moveplan.core.collision import coal_geometry

    kinds, centres, rotations, sizes = [], [], [], []
    for obj in world:
        shape, transform = obj.shape, np.asarray(obj.transform)
        rotation, centre = transform[:3, :3], transform[:3, 3]
        if shape.kind == "box":
            kind, size = _BOX, np.array([*shape.dims]) / 2
        elif shape.kind == "sphere":
            kind, size = _SPHERE, np.array([shape.dims[0], 0.0, 0.0])
        elif shape.kind == "cylinder":
            kind, size = _CYLINDER, np.array([shape.dims[0], shape.dims[1] / 2, 0.0])
        else:
            # A mesh counts as its bounding box in its own frame: it encloses the mesh.
            mesh = coal_geometry(shape, obj.name)
            mesh.computeLocalAABB()
            lo, hi = np.asarray(mesh.aabb_local.min_), np.asarray(mesh.aabb_local.max_)
            kind, size = _BOX, (hi - lo) / 2
            centre = centre + rotation @ ((hi + lo) / 2)
        kinds.append(kind)
        centres.append(centre)
        rotations.append(rotation)
        sizes.append(size)
    count = len(world)
    return (np.array(kinds, dtype=np.int64), np.array(centres, dtype=float).reshape(count, 3),
            np.array(rotations, dtype=float).reshape(count, 3, 3), np.array(sizes, dtype=float).reshape(count, 3))


def _kernels() -> Any:
    """Return the compiled batch kernel (compiled once, then loaded from numba's disk cache)."""
    if "clear" not in _KERNELS:
        from moveplan.core.sphere_kernels import clear

        _KERNELS["clear"] = clear
    return _KERNELS["clear"]
