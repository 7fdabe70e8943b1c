"""A fast conservative collision filter: the robot's enclosing spheres against the scene and themselves.

Compiled with numba (ahead of time where it can be, core/collision/compiled.py; loaded only
when a filter is built, so commands that do not plan never pay for it). One call checks a
batch of configurations: forward kinematics of the joint tree, then per owner (link or
attached object) its bounding ball first and its spheres only if that ball touches
something. Link pairs whose distance depends on one or two joints are looked up in distance
tables instead (core/collision/_pair_tables.py). A
state is "clear" only if no sphere touches an obstacle or another owner's sphere and
every tabulated pair is apart; since the spheres enclose the robot's convex hulls
(core/collision/_sphere_fit.py), which enclose its meshes, a clear state is free under the hulls:
the search, which stops at the hulls, gets the same answer with the spheres as without them. A
state where a ball inside a convex hull touches an obstacle or another link's inner ball, or a
table says a pair overlaps, surely collides under the hulls. Anything else is "maybe": the
caller asks coal.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple, cast

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from .._kept import kept
from ..errors import UnsupportedJoint
from ..model import Robot
from ..types import CollisionObject, JointTrajectory
from . import _certify as certify
from ._cache import announce_compilation
from ._inner_spheres import inner_entry, inner_spheres
from ._packing import pack, pack_robot
from ._pair_tables import PairTable, pair_tables, tables_entry
from ._sphere_fit import SphereSet, fit_shape, robot_spheres, spheres_entry
from ._verdicts import CLEAR, COLLIDES, MAYBE
from .compiled import collision_kernels, kernels_loaded, kernels_ready, mark_kernels_loaded

__all__ = ["CLEAR", "COLLIDES", "MAYBE", "SphereFilter", "UnsupportedJoint", "filter_cached"]


# Joint kinds the kernel knows; anything else (planar, free-flyer, ...) makes the filter unavailable.
_REVOLUTE, _PRISMATIC, _UNBOUNDED = 1, 2, 3
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
_BOX, _SPHERE, _CYLINDER = 0, 1, 2
# The most clearance a state is credited with [m]: past ~5 cm, finding it costs more than the states it skips.
CLEARANCE_CAP_M = 0.05


def _joint_kind(model: pin.Model, jid: int) -> tuple[int, tuple[float, float, float]]:
    """Return (kind, axis) of a pinocchio joint."""
    name = model.joints[jid].shortname().removeprefix("JointModel")
    for prefix, kind in (("RUB", _UNBOUNDED), ("R", _REVOLUTE), ("P", _PRISMATIC)):
        if name.startswith(prefix) and name[len(prefix):] in _AXES:
            return kind, _AXES[name[len(prefix):]]
    joint = model.joints[jid]
    if name in ("RevoluteUnaligned", "RevoluteUnboundedUnaligned", "PrismaticUnaligned"):
        kind = {"RevoluteUnaligned": _REVOLUTE, "RevoluteUnboundedUnaligned": _UNBOUNDED}.get(name, _PRISMATIC)
        x, y, z = (float(v) for v in np.asarray(joint.extract().axis))
        return kind, (x, y, z)
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
        hulls: pin.GeometryModel | None = None,
        shapes: Mapping[str, coal.CollisionGeometry] | None = None,
    ) -> None:
        """Fit spheres to `robot` (its `hulls`, else `geometry`), add attached objects, and list what to check.

        States are the group's joint values; the other joints stay at `base` (default: the neutral
        configuration). Link pairs with distance tables are tabulated from `hulls` (the robot's
        shapes as convex hulls; default `geometry`). `shapes` holds the objects' coal geometries
        by name where a checker has made them: a mesh file is then not read again.

        Raises:
            UnsupportedJoint: The robot has a joint kind the kernel does not handle.
        """
        model = robot.model
        base = robot.neutral() if base is None else base
        part = _robot_part(robot, tuple(obj for obj in objects if obj.link), allowed, base, hulls or geometry)
        self.tabulated = part.tabulated
        world = [obj for obj in objects if not obj.link]
        check = _world_checks(part.names, part.owner_joint, world, allowed)
        # the peak rates the states are placed by, and the timing passes of a plan with a filter
        from ..timing import compiled_fastest_speeds, compiled_quintic_peak_rates

        if not kernels_loaded():  # before the kernels are asked for: they may be compiled now
            announce_compilation("compiling the collision kernels (once per install)", compiled=kernels_ready())
        self._kernels = collision_kernels()
        self._peak_rates = compiled_quintic_peak_rates
        # Packed once: the kernels run thousands of times per search, and a call costs per argument; the
        # robot's arrays (660 kB with its distance tables) were packed with its part, only the world's are added.
        self._packed = pack(part.packed, {**_obstacles(world, shapes or {}), "check": check})
        self._nq = model.nq
        # Reused by every `edge` call: returning fresh arrays from compiled code costs more than judging a state.
        self._verdicts, self._unclear = np.empty(64, dtype=np.int8), np.empty((64, model.nq))
        if kernels_loaded():
            return
        # Compile (or load) every kernel now, not mid-search: numba's JIT compiles on a first call.
        self.classify(robot.values(base)[None, :])
        self.edge(robot.values(base), robot.values(base), 1.0)
        self.certify(robot.values(base)[None, :], np.zeros(1), 0.0)
        still = np.zeros((2, robot.dof))
        self.trajectory_states(JointTrajectory(robot.joint_names, np.array([0.0, 1.0]), still, still, still),
                               np.ones(robot.dof), 1.0)
        # A plan with a filter times its paths with the compiled passes too (core/pipeline/_step.py).
        compiled_fastest_speeds(np.array([0.0, 1.0]), np.ones((3, 1)), np.zeros((3, 1)), np.array([True]),
                                np.ones(1), np.ones(1))
        mark_kernels_loaded()

    def classify(
        self, values: NDArray[np.float64], stop: bool = False
    ) -> tuple[NDArray[np.int8], NDArray[np.float64]]:
        """Return per group state (rows of `values`) CLEAR, MAYBE or COLLIDES, and the configurations (k, nq).

        With `stop`, only the states up to the first that COLLIDES are judged and returned.
        """
        q = np.empty((len(values), self._nq))
        out = np.empty(len(values), dtype=np.int8)
        judged = self._kernels.classify(_plain(values), stop, *self._packed, q, out)
        return out[:judged], q[:judged]

    def certify(
        self, values: NDArray[np.float64], travel: NDArray[np.float64], floor: float
    ) -> tuple[NDArray[np.int8], NDArray[np.float64], NDArray[np.float64]]:
        """Return per state along a motion (rows of `values`) CLEAR, MAYBE or COLLIDES, the configurations, and radii.

        `travel[k]` bounds how far any robot point moves from the first state to state k. The
        states a CLEAR state's clearance proves free are not judged by the spheres (core/collision/
        _clearance.py `certify`): they read CLEAR where the distance tables say apart. A CLEAR
        state's radius [m] bounds every checked pair's distance there from below (0 for the
        rest); clearances are sought at least `floor` beyond the motion's end.
        """
        q = np.empty((len(values), self._nq))
        out = np.empty(len(values), dtype=np.int8)
        radius = np.empty(len(values))
        self._kernels.certify(_plain(values), _plain(travel), CLEARANCE_CAP_M, floor, *self._packed, q, out, radius)
        return out, q, radius

    def trajectory_states(
        self, trajectory: JointTrajectory, reach_m: NDArray[np.float64], step_m: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Return core/collision/_certify.py `trajectory_states` (the same numbers to rounding), compiled.

        Placing a trajectory's certified states costs numpy a tenth of a median plan step.
        """
        if len(trajectory.times_s) == 1:
            return certify.trajectory_states(trajectory, reach_m, step_m)
        knots, p, v, a = (_plain(x) for x in (trajectory.times_s, trajectory.positions, trajectory.velocities,
                                              trajectory.accelerations))
        peak_v, peak_a = self._peak_rates(knots, p, v, a)
        certify.state_count(float(peak_v @ reach_m) * float(knots[-1] - knots[0]), step_m)  # before numba places them
        states = self._kernels.trajectory_states(knots, p, v, a, peak_v, peak_a, _plain(reach_m), step_m, certify.PIECE)
        return cast(tuple[NDArray[np.float64], NDArray[np.float64]], states)

    def edge(
        self, a: NDArray[np.float64], b: NDArray[np.float64], resolution: float, stop: bool = False
    ) -> tuple[int, NDArray[np.int8], NDArray[np.float64]]:
        """Return the worst verdict on the edge from `a` to `b`, and the verdicts and configurations not CLEAR.

        The edge's states are `resolution` [rad] apart in every joint, `b` included, `a` not.
        With `stop`, judging ends at the first state that COLLIDES. The arrays returned are
        overwritten by the next call.
        """
        a, b = _plain(a), _plain(b)
        worst, kept = self._kernels.edge(a, b, resolution, stop, *self._packed, self._verdicts, self._unclear)
        if kept < 0:  # more states than the buffers hold
            self._verdicts, self._unclear = np.empty(-kept, dtype=np.int8), np.empty((-kept, self._nq))
            return self.edge(a, b, resolution, stop)
        return worst, self._verdicts[:kept], self._unclear[:kept]


def filter_cached(robot: Robot, hulls: pin.GeometryModel) -> bool:
    """Return True if the robot's spheres, distance tables and inner balls (fitted to `hulls`) are cached on disk.

    Then a filter of it is built in milliseconds; else it fits them first, for seconds.
    """
    urdf = robot.config.urdf
    entries = (spheres_entry(hulls, urdf), tables_entry(hulls, robot.config.srdf.disabled_pairs, urdf),
               inner_entry(hulls, urdf))
    return all(path.is_file() for _, path in entries)


class _RobotPart(NamedTuple):
    """What a filter of one robot holds whatever the world: owners, tabulated pairs and the kernels' robot arrays."""

    names: tuple[str, ...]  # owners: links, then attached objects
    owner_joint: NDArray[np.int64]
    tabulated: tuple[tuple[str, str], ...]
    packed: tuple[Any, Any]  # the kernels' robot arrays, before and after the world's (_packing.pack_robot)


_ROBOT_PARTS: dict[tuple[Any, ...], _RobotPart] = {}


def _robot_part(
    robot: Robot, attached: tuple[CollisionObject, ...], allowed: frozenset[frozenset[str]],
    base: NDArray[np.float64], hulls: pin.GeometryModel,
) -> _RobotPart:
    """Return the robot's part of a filter: the same for every scene with nothing attached, so built once for them.

    A benchmark plans hundreds of scenes of one robot: fitting, grouping and packing its spheres
    and tables again for each was half of a filter's 2 ms set-up. The key holds the hulls'
    geometry model itself (compared by identity: core/collision/checker.py builds it once per
    config), the URDF and SRDF, the group and the other joints' values.
    """
    def built() -> _RobotPart:
        return _built_part(robot, attached, allowed, base, hulls)

    if attached:
        return built()
    key = (hulls, robot.config.urdf, robot.config.srdf.disabled_pairs, robot.joint_names, allowed, base.tobytes())
    return kept(_ROBOT_PARTS, key, built)


def _built_part(
    robot: Robot, attached: tuple[CollisionObject, ...], allowed: frozenset[frozenset[str]],
    base: NDArray[np.float64], hulls: pin.GeometryModel,
) -> _RobotPart:
    """Return the robot's part of a filter, its spheres fitted to `hulls`, grouped and packed (see `_robot_part`)."""
    model = robot.model
    joints = _joint_arrays(model)  # first: an unsupported joint fails before the spheres are fitted
    spheres, touch = _owned_spheres(robot, hulls, attached)
    names = spheres.names
    owner_joint, owner_centre, owner_radius = _owner_balls(spheres)
    disabled = robot.config.srdf.disabled_pairs | allowed
    # Pairs whose distance depends on one or two joints (a wrist's links) are looked up in tables.
    tables = [t for t in pair_tables(model, hulls, robot.config.srdf.disabled_pairs, robot.config.urdf)
              if frozenset((t.upper, t.lower)) not in disabled]
    pairs = _owner_pairs(names, owner_joint, disabled, touch, tables)
    inner = inner_spheres(model, hulls, robot.config.urdf)
    arrays = {
        "base": base, "group": robot.q_index, "continuous": robot.continuous, **_table_arrays(tables), **joints,
        "centres": spheres.centre, "radii": spheres.radius, "sjoint": spheres.joint, "start": spheres.start,
        "ojoint": owner_joint, "ocentre": owner_centre, "oradius": owner_radius, **_inner_arrays(inner, names),
        "pairs": np.reshape(pairs, (-1, 2)), **_mimic_arrays(robot)}
    return _RobotPart(tuple(names), owner_joint, tuple((t.upper, t.lower) for t in tables), pack_robot(arrays))


def _joint_arrays(model: pin.Model) -> dict[str, Any]:
    """Return the joint tree as the kernel's arrays (raises UnsupportedJoint for a kind the kernel lacks)."""
    kinds = [(0, (0.0, 0.0, 1.0))] + [_joint_kind(model, j) for j in range(1, model.njoints)]
    return {"parents": model.parents, "kinds": [k for k, _ in kinds], "axes": [a for _, a in kinds],
            "iq": model.idx_qs, "prot": [np.asarray(p.rotation) for p in model.jointPlacements],
            "ptrans": [np.asarray(p.translation) for p in model.jointPlacements]}


class _Spheres(NamedTuple):
    """Every owner's enclosing spheres, grouped by owner: owner `k`'s are rows `start[k]:start[k + 1]`."""

    names: list[str]  # owners: links, then attached objects
    centre: NDArray[np.float64]  # (n, 3), in the frame of the sphere's joint [m]
    radius: NDArray[np.float64]  # (n,) [m]
    joint: NDArray[np.int64]  # (n,) pinocchio joint index
    start: NDArray[np.int64]  # (owners + 1,)


def _owned_spheres(
    robot: Robot, geometry: pin.GeometryModel, objects: tuple[CollisionObject, ...]
) -> tuple[_Spheres, dict[str, frozenset[str]]]:
    """Return the spheres of the robot and its attached objects by owner, and per attached object what it may touch."""
    model = robot.model
    robot_set = robot_spheres(model, geometry, robot.config.urdf)
    centres, radii = [robot_set.centres], [robot_set.radii]
    joints, owners = [robot_set.joints], list(robot_set.owners)
    touch: dict[str, frozenset[str]] = {}
    for obj in objects:
        if obj.link:
            frame = model.frames[model.getFrameId(obj.link)]
            c, r = fit_shape(obj.shape, np.asarray(frame.placement.homogeneous) @ obj.transform)
            centres.append(c)
            radii.append(r)
            joints.append(np.full(len(r), frame.parentJoint))
            owners.extend([obj.name] * len(r))
            touch[obj.name] = frozenset((obj.link, *obj.touch_links))
    names = list(dict.fromkeys(owners))
    owner_index = np.array([names.index(o) for o in owners], dtype=np.int64)
    order = np.argsort(owner_index, kind="stable")
    start = np.searchsorted(owner_index[order], np.arange(len(names) + 1))
    return _Spheres(names, np.concatenate(centres)[order], np.concatenate(radii)[order],
                    np.concatenate(joints)[order], start), touch


def _owner_balls(
    spheres: _Spheres,
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    """Return each owner's joint, and the centre (in that joint's frame) and radius of its bounding ball."""
    start, count = spheres.start, len(spheres.names)
    owner_centre, owner_radius = np.zeros((count, 3)), np.zeros(count)
    for k in range(count):
        c, r = spheres.centre[start[k]:start[k + 1]], spheres.radius[start[k]:start[k + 1]]
        owner_centre[k] = (c.min(axis=0) + c.max(axis=0)) / 2
        owner_radius[k] = np.max(np.linalg.norm(c - owner_centre[k], axis=1) + r)
    return spheres.joint[start[:-1]], owner_centre, owner_radius


def _owner_pairs(
    names: list[str],
    owner_joint: NDArray[np.int64],
    disabled: frozenset[frozenset[str]],
    touch: dict[str, frozenset[str]],
    tables: list[PairTable],
) -> list[tuple[int, int]]:
    """Return the owner pairs (a < b) whose spheres are checked: on two joints, never allowed to touch, untabulated."""
    tabulated = {frozenset((t.upper, t.lower)) for t in tables}
    pairs = []
    for a in range(len(names)):
        for b in range(a + 1, len(names)):
            na, nb = names[a], names[b]
            if owner_joint[a] == owner_joint[b] or frozenset((na, nb)) in disabled:
                continue
            if na in touch.get(nb, ()) or nb in touch.get(na, ()):
                continue
            if frozenset((na, nb)) not in tabulated:
                pairs.append((a, b))
    return pairs


def _world_checks(
    names: Sequence[str], owner_joint: NDArray[np.int64], world: list[CollisionObject],
    allowed: frozenset[frozenset[str]],
) -> NDArray[np.bool_]:
    """Return per owner and world obstacle whether a state must check them, shape (owners, obstacles)."""
    # A link fixed to the world (a base) never moves relative to world obstacles: the collision
    # checker tests those pairs once, when the scene loads, so no state needs to.
    return np.array([[frozenset((name, obj.name)) not in allowed and owner_joint[k] != 0 for obj in world]
                     for k, name in enumerate(names)]).reshape(len(names), len(world))


def _plain(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return `values` as a writable, C-ordered float64 array, copied only if it is not one already.

    numba compiles a version of a kernel per array type, read-only and strided ones included
    (a planned path's frozen waypoints): seconds on a fresh machine, in the middle of a search.
    """
    if values.dtype == np.float64 and values.flags.c_contiguous and values.flags.writeable:
        return values
    return np.array(values, dtype=np.float64, order="C")


def _inner_arrays(inner: SphereSet, names: list[str]) -> dict[str, NDArray[Any]]:
    """Return the inner balls as the kernel's arrays, grouped by owner as `names` orders them."""
    index = np.array([names.index(o) if o in names else len(names) for o in inner.owners], dtype=np.int64)
    order = np.argsort(index, kind="stable")
    start = np.searchsorted(index[order], np.arange(len(names) + 1)).astype(np.int64)
    return {"icentres": inner.centres[order], "iradii": inner.radii[order], "ijoint": inner.joints[order],
            "istart": start}


def _table_arrays(tables: list[PairTable]) -> dict[str, NDArray[Any]]:
    """Return the tables as the kernel's arrays.

    Per table and axis: q index (-1: no such axis), start, step, count; per table: offset
    into the flat distances, margin; then the flat distances.
    """
    axes = np.full((len(tables), 2), -1, dtype=np.int64)
    start, step = np.zeros((len(tables), 2)), np.ones((len(tables), 2))
    count = np.ones((len(tables), 2), dtype=np.int64)
    for k, table in enumerate(tables):
        n = len(table.q_index)
        axes[k, :n], start[k, :n], step[k, :n], count[k, :n] = table.q_index, table.start, table.step, \
            table.distances.shape
    sizes = [t.distances.size for t in tables]
    offset = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64) if tables else np.zeros(0, np.int64)
    margin = np.array([t.margin for t in tables], dtype=float)
    flat = np.concatenate([t.distances.ravel() for t in tables]) if tables else np.zeros(0)
    return {"table_axes": axes, "table_start": start, "table_step": step, "table_count": count,
            "table_offset": offset, "table_margin": margin, "table_distance": flat}


def _obstacles(world: list[CollisionObject], shapes: Mapping[str, coal.CollisionGeometry]) -> dict[str, NDArray[Any]]:
    """Return world obstacles as arrays: kind, centre, rotation, size, whether each is that solid, and a ball's radius.

    The ball, about the centre, encloses the obstacle: a sphere missing it misses the obstacle.
    Sizes: a box's half sides; a sphere's radius; a cylinder's radius and half length. A
    mesh is its bounding box, which is not solid: a ball touching it proves nothing.
    """
    from .checker import coal_geometry

    kinds, centres, rotations, sizes, balls = [], [], [], [], []
    solid = [obj.shape.kind in ("box", "sphere", "cylinder") for obj in world]
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
            mesh = shapes[obj.name] if obj.name in shapes else coal_geometry(shape, obj.name)
            mesh.computeLocalAABB()
            lo, hi = np.asarray(mesh.aabb_local.min_), np.asarray(mesh.aabb_local.max_)
            kind, size = _BOX, (hi - lo) / 2
            centre = centre + rotation @ ((hi + lo) / 2)
        balls.append(float(np.linalg.norm(size)) if kind == _BOX else float(np.hypot(size[0], size[1])))
        kinds.append(kind)
        centres.append(centre)
        rotations.append(rotation)
        sizes.append(size)
    count = len(world)
    return {"okind": np.array(kinds, dtype=np.int64), "opos": np.array(centres, dtype=float).reshape(count, 3),
            "orot": np.array(rotations, dtype=float).reshape(count, 3, 3),
            "osize": np.array(sizes, dtype=float).reshape(count, 3), "osolid": np.array(solid, dtype=np.bool_),
            "oball": np.array(balls, dtype=float)}


def _mimic_arrays(robot: Robot) -> dict[str, Any]:
    """Return the kernels' arrays of the joints that follow a group joint (core/model/robot.py's Mimic)."""
    mimics = robot.mimics
    return {"mimic_q": [m.q_index for m in mimics], "mimic_leader": [m.leader for m in mimics],
            "mimic_scale": [m.multiplier for m in mimics], "mimic_offset": [m.offset for m in mimics]}
