"""Collision checks of group motions: states, edges for the search, and certification of what is written.

Up to three geometries answer, cheapest first. A sphere model (core/collision/sphere_filter.py)
clears most states in microseconds; what it cannot clear goes to coal with the robot's
meshes as convex hulls (~14 us a state), and what those cannot clear to coal with the
real collision geometry (~55 us). The spheres enclose the hulls and the hulls
enclose the meshes, so a state an earlier stage clears is free, and every answer is the
real geometry's answer. The search may stop at the hulls (`conservative`): it then
loses only the little space between a mesh and its hull.

Certification checks a trajectory as the controller interpolates it, at states so
close that no point of the robot moves more than `step_m` between two of them
(core/collision/_certify.py bounds that motion). The spheres skip the states a clearance
proves free (core/collision/_clearance.py `certify`); coal decides the rest in one batch.
Without the spheres, coal checks the middle state of each run of a few with a margin reaching
the run's ends, and only the states of runs that fail one by one. Then the states' clearances
must cover the motion between them (core/collision/_cover.py).

Without the spheres, an edge's states go to coal as OMPL's DiscreteMotionValidator checks them:
the end state, then the middle, then the middles of the halves, so a blocked edge is refused
after a few. (With them, coal gets the few states they leave unsure, in order.)
"""

from __future__ import annotations

import functools
import logging
from typing import Any, Protocol

import coal
import numpy as np
from numpy.typing import NDArray

from .._kept import kept
from ..errors import ConfigError
from ..model import Robot, Scene
from ..trajectory import interpolate
from ..types import JointTrajectory
from . import _certify as certify
from ._cover import RUN, needed, run_margins, uncovered_collision
from .checker import CONTACT_M, CollisionChecker, GeometryMode, robot_geometry
from .sphere_filter import CLEAR, COLLIDES, MAYBE, SphereFilter, UnsupportedJoint, filter_cached

__all__ = ["CERTIFY_STEP_M", "MotionChecker", "build_sphere_filter", "exact_checks", "scene_checkers",
           "scene_checks", "sphere_filter_cached"]

logger = logging.getLogger(__name__)

CERTIFY_STEP_M = 0.005  # the most any robot point moves between two certified states [m]


class Filter(Protocol):
    """A pre-check: per group state, certainly free (CLEAR), unsure, or surely colliding under the hulls."""

    def classify(self, values: NDArray[np.float64]) -> tuple[NDArray[np.int8], NDArray[np.float64]]:
        """Return per group state (rows of `values`) CLEAR, MAYBE or COLLIDES, and the configurations (k, nq)."""
        ...

    def edge(
        self, a: NDArray[np.float64], b: NDArray[np.float64], resolution: float, stop: bool
    ) -> tuple[int, NDArray[np.int8], NDArray[np.float64]]:
        """Return the worst verdict on the edge's states, and the verdicts and configurations not CLEAR."""
        ...

    def certify(
        self, values: NDArray[np.float64], travel: NDArray[np.float64], floor: float
    ) -> tuple[NDArray[np.int8], NDArray[np.float64], NDArray[np.float64]]:
        """Return per state along a motion its verdict, the configurations, and radii (see SphereFilter.certify).

        `travel[k]` bounds how far any robot point moves from the first state to state k.
        """
        ...


class MotionChecker:
    """Answers whether group states, straight edges and timed trajectories are collision-free."""

    def __init__(
        self,
        robot: Robot,
        checker: CollisionChecker,
        base: NDArray[np.float64],
        spheres: Filter | None = None,
        hulls: CollisionChecker | None = None,
    ) -> None:
        """Check `robot` with its other joints at `base`, by `checker`'s geometry.

        `spheres` and `hulls` (the robot's meshes as convex hulls) are conservative geometries
        asked first, in that order: a state they clear is free under `checker`'s geometry. A
        state `spheres` finds surely colliding collides under the hulls (or, without them,
        under `checker`'s geometry).
        """
        self.robot = robot
        self.checker = checker
        self.base = base
        self.spheres = spheres
        self.reach = _reach(robot, checker)
        self._stages: tuple[CollisionChecker, ...] = (checker,) if hulls is None else (hulls, checker)
        # The first stage checks what the spheres leave unsure in nearly every search: its broadphase is
        # set up here, not in the search's time; the meshes' behind the hulls only if a state needs them.
        self._stages[0].prepare_batches()
        self.conservative_available = hulls is not None

    @property
    def compiled(self) -> bool:
        """Return True if a built sphere filter answers: its kernels are loaded, so timing takes its compiled passes."""
        return isinstance(self.spheres, SphereFilter)

    def free(self, values: NDArray[np.float64], conservative: bool = False) -> NDArray[np.bool_]:
        """Return per group state (rows of `values`) True if it is collision-free.

        With `conservative`, a state is free only if the spheres or the hulls clear it; one
        that only the real geometry would free reads as colliding. The search uses this:
        a hull check costs a quarter of a mesh check.
        """
        verdict, q = self._classified(values)
        return self._decided(verdict, q, conservative)

    def _decided(
        self, verdict: NDArray[np.int8], q: NDArray[np.float64], conservative: bool = False
    ) -> NDArray[np.bool_]:
        """Return per state True if free, given the spheres' verdicts and the configurations (k, nq).

        What the spheres leave unsure goes to coal in one batch per geometry, hulls first.
        """
        free: NDArray[np.bool_] = verdict == CLEAR
        maybe = np.flatnonzero(verdict == MAYBE)
        if len(maybe):
            free[maybe] = self._stages[0].free_batch(q[maybe].T)
        if conservative or len(self._stages) == 1:
            return free
        rest = np.flatnonzero(~free)  # colliding under the hulls: only the meshes can tell
        if len(rest):
            free[rest] = self._stages[1].free_batch(q[rest].T)
        return free

    def state_free(self, values: NDArray[np.float64], conservative: bool = False) -> bool:
        """Return True if one group state is collision-free (see `free` for `conservative`)."""
        return self.edge_free(values, values, 1.0, conservative)

    def edge_free(
        self, a: NDArray[np.float64], b: NDArray[np.float64], resolution: float, conservative: bool = False
    ) -> bool:
        """Return True if the straight edge from `a` to `b` is free at states `resolution` [rad] apart.

        The states checked are `b` and those between, not `a`: a search asks about an edge
        from a state it already knows to be free.
        """
        final = conservative or len(self._stages) == 1
        if self.spheres is None:
            states = interpolate(a, b, resolution)[1:]
            worst, verdict, q = MAYBE, np.full(len(states), MAYBE), self.robot.configurations(states, self.base).T
        else:
            worst, verdict, q = self.spheres.edge(a, b, resolution, stop=final)
        if worst == CLEAR:
            return True
        if final:
            if not self.compiled:  # coal judges every state: in halving order a blocked edge fails early
                q = q[_halving(len(q))]
            return worst != COLLIDES and bool(self._stages[0].free_batch(q.T, stop_at_first=True).all())
        free = np.zeros(len(verdict), dtype=bool)
        maybe = verdict == MAYBE
        if maybe.any():
            free[maybe] = self._stages[0].free_batch(q[maybe].T)
        return bool(free.all()) or bool(self._stages[1].free_batch(q[~free].T, stop_at_first=True).all())

    def _classified(self, values: NDArray[np.float64]) -> tuple[NDArray[np.int8], NDArray[np.float64]]:
        """Return the spheres' verdict per state, and the states' configurations (k, nq)."""
        if self.spheres is None:
            q = self.robot.configurations(np.atleast_2d(values), self.base).T
            return np.full(len(q), MAYBE, dtype=np.int8), q
        return self.spheres.classify(values)

    def edge_free_certified(self, a: NDArray[np.float64], b: NDArray[np.float64]) -> bool:
        """Return True if the straight edge is certified free (see `first_collision_on_path`)."""
        return self.first_collision_on_path(np.array([a, b])) is None

    def first_collision_on_trajectory(
        self, trajectory: JointTrajectory, between: bool = True
    ) -> NDArray[np.float64] | None:
        """Return a colliding state along the interpolated trajectory (the first found), or None if it is free.

        Free means free at every instant; with `between` False, only at the certification states.
        """
        # The built filter places the states compiled; its stand-in (core/pipeline/_checks.py) has no numba yet.
        place = getattr(self.spheres, "trajectory_states", certify.trajectory_states)
        states, travel = place(trajectory, self.reach, CERTIFY_STEP_M)
        return self._first_collision(states, travel, (
            certify.trajectory_between(trajectory, self.reach, CERTIFY_STEP_M) if between else None))

    def first_collision_on_path(self, waypoints: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """Return a colliding state along the straight segments between waypoints (the first found), or None."""
        states, travel = certify.path_states(waypoints, self.reach, CERTIFY_STEP_M)
        return self._first_collision(states, travel, certify.path_between(states, travel))

    def _first_collision(
        self, states: NDArray[np.float64], travel: NDArray[np.float64], between: certify.Between | None
    ) -> NDArray[np.float64] | None:
        """Return the first colliding state of a motion through `states`, else one `between` them (if given), or None.

        `travel`: see certify.trajectory_states. `between` gives the motion's states at travel values.
        """
        # The states alone need no radius beyond coal's contact distance: no margin is asked of coal then.
        free, radius = self._judged(states, travel, None if between is not None else np.full(len(states), CONTACT_M))
        if not free.all():
            return np.asarray(states[int(np.argmin(free))], dtype=np.float64)
        if between is None:
            return None
        return uncovered_collision(states, travel, radius, between, self._judged, self._states_within)

    def _judged(
        self, states: NDArray[np.float64], travel: NDArray[np.float64], margin: NDArray[np.float64] | None = None
    ) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
        """Return per state of a motion whether it is free, and a lower bound [m] on its checked pairs' distance.

        What the spheres leave unsure goes to coal first with a margin [m]: `margin`, else the
        one that covers the gaps to its neighbours (core/collision/_cover.py). Most of those
        states are that far from everything, and one check then says so.
        """
        if self.spheres is None:
            verdict, q = self._classified(states)
            radius = np.zeros(len(states))
        else:
            verdict, q, radius = self.spheres.certify(states, travel, CERTIFY_STEP_M)
        free = verdict == CLEAR
        radius = np.where(free, radius, 0.0)
        if margin is None and not self.compiled and len(states) > RUN:
            # No clearances from the spheres: one coal check a run proves the run's states free.
            middle, run_margin, run, proven = run_margins(travel, CERTIFY_STEP_M)
            apart = self._free_within(q[middle].T, run_margin, meshes=False)[run]
            free |= apart
            radius = np.where(apart, proven, radius)
        maybe = np.flatnonzero((verdict == MAYBE) & ~free)
        if len(maybe) and (margin is not None or len(states) > 1):
            wanted = needed(travel, radius, maybe) if margin is None else margin[maybe]
            apart = self._free_within(q[maybe].T, wanted)
            free[maybe[apart]], radius[maybe[apart]] = True, wanted[apart]
        rest = np.flatnonzero(~free)
        if len(rest):
            free[rest] = self._decided(verdict[rest], q[rest])
            radius[rest[free[rest]]] = CONTACT_M
        return free, radius

    def _free_within(
        self, q: NDArray[np.float64], margin: NDArray[np.float64], meshes: bool = True
    ) -> NDArray[np.bool_]:
        """Return per configuration (columns of `q`) True if every checked pair is at least its `margin` [m] apart.

        The hulls are asked first: a configuration they find that far apart is, under the meshes.
        Without `meshes`, the hulls' answer is final (False may then be a mesh that far apart).
        """
        out = np.zeros(q.shape[1], dtype=bool)
        for value in sorted(set(margin.tolist())):  # not np.unique: its first call imports numpy.ma, 11 ms
            rows = np.flatnonzero(margin == value)
            out[rows] = self._stages[0].free_batch(q[:, rows], margin=float(value))
            rest = rows[~out[rows]]  # too near under the hulls: only the meshes can tell
            if len(rest) and len(self._stages) > 1 and meshes:
                out[rest] = self._stages[1].free_batch(q[:, rest], margin=float(value))
        return out

    def _states_within(self, values: NDArray[np.float64], margin: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Return per group state (rows of `values`) True if every checked pair is at least its `margin` [m] apart."""
        return self._free_within(self.robot.configurations(values, self.base), margin)

    def colliding_pair(self, values: NDArray[np.float64]) -> tuple[str, str] | None:
        """Return the names of a colliding pair at a group state, or None."""
        if self.free(np.atleast_2d(values))[0]:  # the spheres clear a free state in microseconds, coal in 100
            return None
        return self.checker.colliding_pair(self.robot.configuration(values, self.base))


def scene_checks(robot: Robot, scene: Scene, geometry: GeometryMode, base: NDArray[np.float64]) -> MotionChecker:
    """Return the checks of `robot` (other joints at `base`) in `scene`: `geometry`, with the stages before it.

    The sphere filter clears most states first; with meshes, their convex hulls judge what
    it leaves before the meshes do. Either stage is left out where the robot cannot have it.
    """
    checker, hulls = scene_checkers(robot, scene, geometry)
    return MotionChecker(robot, checker, base, build_sphere_filter(robot, checker, hulls, scene, base), hulls)


def scene_checkers(
    robot: Robot, scene: Scene, geometry: GeometryMode
) -> tuple[CollisionChecker, CollisionChecker | None]:
    """Return the checker of `robot` in `scene` by `geometry`, and the hulls' checker asked before it, if any.

    The hulls are built first, and the checker takes their pairs: the same robot, objects and
    allowed pairs give the same ones.
    """
    hulls = _hull_checker(robot, geometry, scene)
    return CollisionChecker(robot, scene.objects, scene.source, geometry, scene.allowed, hulls), hulls


def exact_checks(checks: MotionChecker, scene: Scene) -> MotionChecker:
    """Return checks of the same robot and scene under the URDF's exact meshes alone, as a referee."""
    checker = checks.checker
    if checker.mode != "exact":
        checker = CollisionChecker(checks.robot, scene.objects, scene.source, geometry="exact", allowed=scene.allowed)
    return MotionChecker(checks.robot, checker, checks.base)


@functools.lru_cache(maxsize=256)  # an edge's state count: a few hundred at most in a search
def _halving(count: int) -> NDArray[np.intp]:
    """Return 0..count-1 in halving order: the last, the middle, then the middles of the halves, and so on."""
    order, spans = [count - 1], [(-1, count - 1)]
    while spans:
        later = []
        for low, high in spans:
            if high - low > 1:
                middle = (low + high) // 2
                order.append(middle)
                later += [(low, middle), (middle, high)]
        spans = later
    return np.array(order, dtype=np.intp)


_REACH: dict[tuple[Any, ...], NDArray[np.float64]] = {}


def _reach(robot: Robot, checker: CollisionChecker) -> NDArray[np.float64]:
    """Return certify.reach of the robot's geometry in `checker`, worked out once per robot unless objects are attached.

    World objects do not move, so the reach is the robot's alone in every scene that attaches nothing.
    """
    if checker.attached:
        return certify.reach(robot, checker.geometry)

    def worked_out() -> NDArray[np.float64]:
        reach = certify.reach(robot, checker.robot_geometry)
        reach.setflags(write=False)
        return reach

    # The geometry is built once per config: its identity stands for the robot's shapes.
    return kept(_REACH, (checker.robot_geometry, robot.config.urdf, robot.joint_names), worked_out)


def build_sphere_filter(
    robot: Robot, checker: CollisionChecker, hulls: CollisionChecker | None, scene: Scene, base: NDArray[np.float64]
) -> SphereFilter | None:
    """Return the fast conservative pre-check for `robot` (other joints at `base`) in `scene`, or None."""
    placed = checker.geometry.geometryObjects[len(checker.robot_geometry.geometryObjects):]
    try:
        return SphereFilter(robot, checker.robot_geometry, scene.objects, scene.allowed, base,
                            (hulls or checker).robot_geometry, {obj.name: obj.geometry for obj in placed})
    except UnsupportedJoint as exc:
        logger.info("no sphere filter (%s): every state is checked by coal", exc)
        return None


def sphere_filter_cached(robot: Robot, checker: CollisionChecker, hulls: CollisionChecker | None) -> bool:
    """Return True if what `build_sphere_filter` fits for `robot` is cached on disk: it builds in milliseconds."""
    return filter_cached(robot, (hulls or checker).robot_geometry)


def _hull_checker(robot: Robot, geometry: GeometryMode, scene: Scene) -> CollisionChecker | None:
    """Return a checker of the robot's meshes as convex hulls in `scene` if `geometry` is exact meshes, else None."""
    if geometry != "exact" or not any(isinstance(obj.geometry, coal.BVHModelBase)
                                      for obj in robot_geometry(robot, "exact").geometryObjects):
        return None  # the hulls would be the checker's own shapes, checked twice
    try:
        return CollisionChecker(robot, scene.objects, scene.source, geometry="convex", allowed=scene.allowed)
    except ConfigError as exc:
        logger.info("no hull stage (%s): states the spheres cannot clear go to the meshes", exc)
        return None
