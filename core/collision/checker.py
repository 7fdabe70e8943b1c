"""Collision checking of robot states against the robot itself and the scene, with coal.

One pinocchio GeometryModel holds the robot's URDF collision geometry, the
world objects (on the universe joint) and attached objects (on their link's
joint). Only pairs whose distance can change with the joints are checked per
state; pairs that never move relative to each other are checked once, at
construction. A batch of states is checked in one C++ call.

The robot's meshes are checked as they are (`exact`, triangle BVHs) or as their
convex hulls (`convex`). A hull encloses its mesh, so a state free under hulls is
free under the meshes: convex mode is conservative, and what it certifies holds
for the real geometry.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Literal

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ..config import RobotConfig
from ..errors import ConfigError, StartInCollision, UnknownName
from ..model import Robot
from ..types import CollisionObject, Shape

__all__ = ["CONTACT_M", "CollisionChecker", "GeometryMode", "coal_geometry", "convex_hull", "robot_geometry"]

GeometryMode = Literal["exact", "convex"]

CONTACT_M = 1e-6
"""Shapes closer than this [m] count as touching. With no margin, coal's test as pinocchio asks it
called the Panda hand's convex hull free while it sank 62 um into a box (tests/collision/test_collision.py);
with a positive margin it finds that contact, and is no slower."""

logger = logging.getLogger(__name__)

# Hulls by (mesh file, scale), built once per process: qhull costs ~1 ms a mesh, and every
# CollisionChecker of a run (IK, tests, benchmarks) loads the same robot meshes.
_HULLS: dict[tuple[str, tuple[float, ...]], coal.ConvexBase] = {}
# The robot's own geometry by (URDF, config folder, package path, mode): reading its meshes costs
# ~80 ms, and a benchmark builds a checker per problem for one robot.
_ROBOT_GEOMETRY: dict[tuple[str, str, tuple[Path, ...], str], pin.GeometryModel] = {}


def coal_geometry(shape: Shape, source: str = "scene") -> coal.CollisionGeometry:
    """Return the coal geometry of a scene shape (sizes in [m])."""
    if shape.kind == "box":
        return coal.Box(*shape.dims)
    if shape.kind == "cylinder":
        radius, length = shape.dims
        return coal.Cylinder(radius, length)
    if shape.kind == "sphere":
        return coal.Sphere(shape.dims[0])
    if shape.vertices is not None and shape.triangles is not None:
        mesh = coal.BVHModelOBBRSS()
        mesh.beginModel(len(shape.triangles), len(shape.vertices))
        mesh.addVertices(np.asarray(shape.vertices) * np.array(shape.scale))
        mesh.addTriangles(np.asarray(shape.triangles))
        mesh.endModel()
        return mesh
    path = Path(shape.mesh_path)
    if not path.is_file():
        raise ConfigError(f"{source}: mesh file not found: {path}")
    try:
        return coal.MeshLoader().load(str(path), np.array(shape.scale, dtype=float))
    except (RuntimeError, ValueError) as exc:
        raise ConfigError(f"{source}: cannot read mesh {path}: {exc}") from None


def convex_hull(mesh: coal.BVHModelBase, key: tuple[str, tuple[float, ...]], source: str) -> coal.ConvexBase:
    """Return the convex hull of a triangle mesh, cached per process under `key` (file, scale).

    Raises:
        ConfigError: The mesh is flat (no hull; names `source`), or qhull fails on it.
    """
    if key not in _HULLS:
        if _is_flat(mesh):
            raise ConfigError(f"{source}: mesh {key[0]} is flat, so it has no convex hull")
        try:
            # keepTriangle=True keeps qhull's (triangulated, "Qt") facets with the hull: a coal.Convex,
            # whose volume can be compared with the mesh's (benchmarks/panda_meshes.py does).
            convex = mesh.buildConvexHull(True, "Qt")  # True: every vertex is on the hull
        except (RuntimeError, ValueError) as exc:
            raise ConfigError(f"{source}: cannot build the convex hull of mesh {key[0]}: "
                              f"{' '.join(str(exc).split())}; use planning: {{collision: exact}}") from None
        if mesh.convex is None:
            raise ConfigError(f"{source}: cannot build the convex hull of mesh {key[0]}; "
                              "use planning: {collision: exact}")
        if not convex:
            logger.info("%s: mesh %s is not convex; its hull encloses more", source, key[0])
        hull = mesh.convex
        hull.computeLocalAABB()
        _HULLS[key] = hull
    return _HULLS[key]


def _is_flat(mesh: coal.BVHModelBase) -> bool:
    """Return True if a mesh's vertices span no volume (fewer than 4, or all on a plane or line)."""
    points = np.asarray(mesh.vertices(), dtype=float).reshape(-1, 3)
    if len(points) < 4:
        return True
    spread = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    return bool(spread[2] <= 1e-6 * spread[0])


def robot_geometry(robot: Robot, mode: GeometryMode) -> pin.GeometryModel:
    """Return the robot's own collision geometry in `mode`, built once per process and config."""
    config = robot.config
    key = (config.urdf, str(config.root), config.package_paths, mode)
    if key in _ROBOT_GEOMETRY:
        return _ROBOT_GEOMETRY[key]
    # Mesh files are resolved (and a missing one reported) by the config, which knows the
    # package path; pinocchio gets the expanded URDF text with absolute mesh paths.
    try:
        geom = pin.buildGeomFromUrdfString(robot.model, config.collision_urdf(), pin.GeometryType.COLLISION)
    except (RuntimeError, ValueError, OSError) as exc:
        raise _geometry_error(config, exc) from None
    if mode == "convex":
        # Only the robot's meshes: scene meshes are the world, checked exactly. A hull
        # there would block space the robot may use (a bin's inside, a shelf's bays).
        for obj in geom.geometryObjects:
            if not isinstance(obj.geometry, coal.BVHModelBase):
                continue
            if _is_flat(obj.geometry):
                # No hull, and coal 3.0.3's qhull crashes the process (SIGSEGV) on coplanar
                # points. Kept as a mesh, it is checked as it really is: still conservative.
                logger.info("%s: mesh %s is flat; checked as a mesh", obj.name, obj.meshPath)
            else:
                hull_key = (str(obj.meshPath), tuple(float(v) for v in obj.meshScale))
                obj.geometry = convex_hull(obj.geometry, hull_key, f"{config.urdf_path}: {obj.name}")
    _ROBOT_GEOMETRY[key] = geom
    return geom


def _geometry_error(config: RobotConfig, exc: Exception) -> ConfigError:
    """Return a one-line error naming the mesh pinocchio (through coal and assimp) could not read."""
    text = str(exc)
    # coal's message: "From file: ... message: Could not load resource <path>\n<assimp reason>\nHint: ..."
    lines = [line.strip() for line in text.split("message:", 1)[-1].splitlines() if line.strip()]
    reason = "; ".join(line for line in lines if not line.startswith(("Could not load", "Hint:")))
    reason = reason or (lines[0] if lines else type(exc).__name__)
    for mesh in config.collision_meshes():
        if str(mesh.path.resolve()) in text:
            package = f" (package '{mesh.package}')" if mesh.package else ""
            return ConfigError(f"{config.urdf_path}: link '{mesh.link}': cannot read collision mesh "
                               f"{mesh.path}{package} for {mesh.uri}: {reason}")
    return ConfigError(f"{config.urdf_path}: cannot load collision geometry: {' '.join(text.split())}")


def _pairs_to_check(
    owner: list[str],
    touch: list[frozenset[str]],
    joint_of: list[int],
    robot_count: int,
    disabled: frozenset[frozenset[str]],
) -> tuple[list[tuple[int, int]], list[tuple[int, int]]]:
    """Return the geometry pairs (i < j) that may touch: on two joints (checked per state), and on one."""
    moving: list[tuple[int, int]] = []
    fixed: list[tuple[int, int]] = []
    for i in range(len(owner)):
        for j in range(i + 1, len(owner)):
            a, b = owner[i], owner[j]
            if a == b or frozenset((a, b)) in disabled:
                continue
            if a in touch[j] or b in touch[i]:
                continue  # an attached object may touch its link and touch_links
            if i >= robot_count and j >= robot_count and (joint_of[i] == 0 and joint_of[j] == 0):
                continue  # world objects never move relative to each other
            (fixed if joint_of[i] == joint_of[j] else moving).append((i, j))
    return moving, fixed


class CollisionChecker:
    """Answers whether robot configurations collide, and which pair collides."""

    def __init__(
        self,
        robot: Robot,
        objects: tuple[CollisionObject, ...] = (),
        source: str = "scene",
        geometry: GeometryMode = "exact",
        allowed: frozenset[frozenset[str]] = frozenset(),
        hulls: CollisionChecker | None = None,
    ) -> None:
        """Build the geometry model of `robot` and `objects` and decide which pairs to check.

        Args:
            robot: The robot, with its config's URDF collision geometry.
            objects: World and attached scene objects.
            source: The scene file, for messages.
            geometry: `exact` checks the URDF's meshes as triangle BVHs; `convex` checks each
                robot mesh's convex hull instead (faster; conservative, since a hull encloses
                its mesh). Scene objects are checked as given in both modes.
            allowed: Pairs of link or object names allowed to touch (a scene's allowed
                collision matrix), in addition to the SRDF's disabled pairs.
            hulls: The `convex` checker of the same robot, objects and allowed pairs: its pairs
                are this one's, and it has checked the pairs that never move (a hull encloses
                its mesh, so what no hull touches no mesh does).

        Raises:
            ConfigError: A mesh cannot be read, or (convex) qhull fails on one.
            StartInCollision: Objects that never move relative to each other touch.
        """
        if geometry not in ("exact", "convex"):
            raise ValueError(f"collision geometry '{geometry}': expected exact or convex")
        self.robot = robot
        self.mode: GeometryMode = geometry
        model = robot.model
        config = robot.config
        self.robot_geometry = robot_geometry(robot, geometry)  # shared per process: never modify
        geom = self.robot_geometry.copy()
        # The hulls' checker placed the same objects: their shapes are taken, a scene's mesh files read once.
        placed = (hulls.geometry.geometryObjects[len(hulls.robot_geometry.geometryObjects):] if hulls is not None
                  else [self._placed(obj, source) for obj in objects])
        for obj in placed:
            geom.addGeometryObject(obj)
        self.attached = any(obj.link for obj in objects)
        self.geometry: pin.GeometryModel = geom
        self._data: pin.GeometryData | None = None
        self._pool: pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager | None = None
        self.owner: tuple[str, ...]
        self._active: NDArray[np.bool_]
        if hulls is not None:
            self.owner, self._active = hulls.owner, hulls._active
            geom.setCollisionPairs(self._active)
            return
        owner = [str(model.frames[g.parentFrame].name) for g in self.robot_geometry.geometryObjects]
        touch: list[frozenset[str]] = [frozenset() for _ in owner]
        for obj in objects:
            owner.append(obj.link or obj.name)
            touch.append(frozenset((obj.link, *obj.touch_links)) if obj.link else frozenset())
        self.owner = tuple(owner)
        robot_count = len(owner) - len(objects)
        moving_pairs, fixed_pairs = _pairs_to_check(owner, touch, [g.parentJoint for g in geom.geometryObjects],
                                                    robot_count, config.srdf.disabled_pairs | allowed)
        self._active = np.zeros((len(owner), len(owner)), dtype=bool)
        if moving_pairs:
            self._active[tuple(np.transpose(moving_pairs))] = True
        geom.setCollisionPairs(self._active)  # in (i, j) order, as colliding_pair reports the first
        self._check_fixed_pairs(fixed_pairs, robot_count)

    @property
    def data(self) -> pin.GeometryData:
        """Return the geometry data single configurations are checked with, made on first use (0.06 ms).

        A problem's checkers judge batches (their broadphase's own data); this one answers
        `in_collision` and `colliding_pair`, which most problems never ask.
        """
        if self._data is None:
            self._data = pin.GeometryData(self.geometry)
            self._margins(CONTACT_M, [self._data])
        return self._data

    def _placed(self, obj: CollisionObject, source: str) -> pin.GeometryObject:
        model = self.robot.model
        if obj.link:
            if not model.existFrame(obj.link):
                raise UnknownName("link", obj.link, f"{source}: attached object '{obj.name}'", self.robot.link_names)
            frame = model.frames[model.getFrameId(obj.link)]
            placement = frame.placement * pin.SE3(obj.transform)
            return pin.GeometryObject(obj.name, frame.parentJoint, model.getFrameId(obj.link),
                                      placement, coal_geometry(obj.shape, source))
        return pin.GeometryObject(obj.name, 0, 0, pin.SE3(obj.transform), coal_geometry(obj.shape, source))

    def _check_fixed_pairs(self, pairs: list[tuple[int, int]], robot_count: int) -> None:
        """Raise StartInCollision if a pair that never moves is in contact (it would be, always)."""
        model, data = self.robot.model, self.robot.data
        pin.forwardKinematics(model, data, self.robot.neutral())
        request = coal.CollisionRequest()
        request.security_margin = CONTACT_M
        objects = self.geometry.geometryObjects
        for i, j in pairs:
            if i < robot_count and j < robot_count:
                continue  # links on one joint are rigidly attached: their contact is by design
            result = coal.CollisionResult()
            a, b = objects[i], objects[j]
            if coal.collide(a.geometry, coal.Transform3s(data.oMi[a.parentJoint] * a.placement), b.geometry,
                            coal.Transform3s(data.oMi[b.parentJoint] * b.placement), request, result):
                raise StartInCollision((self.owner[i], self.owner[j]), where="every state")

    def in_collision(self, q: NDArray[np.float64]) -> bool:
        """Return True if configuration `q` collides."""
        return bool(pin.computeCollisions(self.robot.model, self.robot.data, self.geometry, self.data, q, True))

    def colliding_pair(self, q: NDArray[np.float64]) -> tuple[str, str] | None:
        """Return the names of the first colliding pair in configuration `q`, or None."""
        if not self.in_collision(q):
            return None
        for k, result in enumerate(self.data.collisionResults):
            if result.isCollision():
                pair = self.geometry.collisionPairs[k]
                return self.owner[pair.first], self.owner[pair.second]
        return None  # pragma: no cover - computeCollisions said there was one

    def free_batch(
        self, q: NDArray[np.float64], stop_at_first: bool = False, margin: float = CONTACT_M
    ) -> NDArray[np.bool_]:
        """Return, for configurations of shape (nq, k), which are collision-free: every checked pair `margin` [m] apart.

        With `stop_at_first`, checking ends at the first colliding state; states after it
        read as free, so only `all()` of the answer is meaningful.
        """
        pool = self._batch_pool()
        if margin != CONTACT_M:
            self._margins(margin, pool.getGeometryDatas())
        try:
            hits = pin.computeCollisionsInParallel(1, pool, np.asfortranarray(q), True, stop_at_first)
        finally:
            if margin != CONTACT_M:
                self._margins(CONTACT_M, pool.getGeometryDatas())
        return ~np.asarray(hits, dtype=bool)

    def prepare_batches(self) -> None:
        """Make the broadphase that checks batches now, not on the first batch; return None."""
        self._batch_pool()

    def _batch_pool(self) -> pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager:
        """Return the broadphase that checks batches, made on the first batch (0.3 ms).

        A broadphase (AABB tree) culls most pairs: 3-4x faster per state than testing each pair.
        Made when first needed: the meshes' checker behind the hulls never checks a batch in two
        problems of three (the spheres and hulls decide every state).
        """
        if self._pool is None:
            self._pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager(self.robot.model, self.geometry, 1)
            self._margins(CONTACT_M, self._pool.getGeometryDatas())
        return self._pool

    def _margins(self, margin: float, datas: Sequence[pin.GeometryData]) -> None:
        """Make every check of `datas` find pairs closer than `margin` [m] (a broadphase widens its boxes by it)."""
        count = len(self.geometry.geometryObjects)
        for data in datas:
            # One call, not a Python loop over the pairs' requests; their distance bounds stay as they are.
            data.setSecurityMargins(self.geometry, np.full((count, count), margin), True, False)
