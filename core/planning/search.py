"""Joint-space path planning with OMPL's geometric planners.

The planner sees the group's joint values in a box of joint limits. States and
whole edges are checked by the caller's `Validity` (one call per edge, so the
caller can check all its states in one batch). The straight segment from start
to goal is tried first; a searched path is shortened by OMPL's rope shortcutting
under the same checks.

A search is bounded by work, not by the clock: it may check a number of motions
(states and edges) proportional to its planning time, so the same seed gives the same
path, or the same failure, on any machine under any load. The wall clock is only a safety
limit, apart from the budget and far above it (`--timeout`, by default 20 times the planning
time and at least 60 s): a search that reaches it fails and says so.
"""

from __future__ import annotations

import functools
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from operator import itemgetter

import numpy as np
from numpy.typing import NDArray
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ..collision import setup_time_spent
from ..config import PILZ_PLANNERS, PLANNERS
from ..errors import PlanningFailed, PlanningTimeExceeded, UsageError, known
from ..types import frozen_array

__all__ = ["PLANNERS", "PathResult", "Validity", "default_timeout", "plan_path", "repair_path", "seed_planner"]

logger = logging.getLogger(__name__)
ou.setLogLevel(ou.LOG_ERROR)


_RANGE_RAD = 1.0  # the longest edge a tree-growing planner adds in one step
# RRTConnect grows each tree by whole edges of up to a range toward uniform samples. From a goal deep
# in a shelf almost none is free (MotionBenchMaker bookshelf 0093: 0 of 1,000 at 1 rad, 11 % at
# 0.1 rad), so the goal tree stays at 2-11 states while the start tree grows to thousands, and no
# range, intermediate states or mesh checks fix that within 1 s. LBKPIECE1 expands from the least
# explored cells and checks edges only on candidate paths: it solves those goals in tens of ms.
# RRTConnect searches alone for the first part of the budget, where it solves all but such
# problems; LBKPIECE1 then searches on.
_FALLBACK = {"RRTConnect": "LBKPIECE1"}
_FALLBACK_AFTER = 0.2  # of the search's budget
# Checked motions a search may spend per second of planning time: the fixed reference rate. A
# Panda search among MotionBenchMaker obstacles checks 30,000-75,000 a second on one core of a
# 2-core machine, so its budget is spent in under half the planning time quiet; a robot without
# a sphere filter checks fewer, and spends its budget in more wall time than its planning time.
_CHECKS_PER_S = 20_000
# The wall-clock safety limit, unless given: so far above the budget that only a machine stalled
# or loaded far beyond eight busy processes per core reaches it.
TIMEOUT_FACTOR, TIMEOUT_MIN_S = 20.0, 60.0


def default_timeout(planning_time_s: float) -> float:
    """Return the wall-clock safety limit of a search with `planning_time_s` of budget, in [s]."""
    return max(TIMEOUT_MIN_S, TIMEOUT_FACTOR * planning_time_s)


def seed_planner(seed: int) -> None:
    """Seed OMPL's process-wide generator of seeds: every planner, sampler and simplifier made after draws from it."""
    # OMPL logs an error when it is reseeded after first use, yet reseeds. Each search makes its
    # planner, sampler and simplifier anew, so a plan seeded first draws from `seed` alone,
    # whatever ran in the process before it. OMPL's seeds are 32-bit and never 0.
    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(seed % (2**32 - 1) + 1)
    ou.setLogLevel(ou.LOG_ERROR)


@dataclass(frozen=True)
class Validity:
    """The search's collision checks on group joint values: one state, and the straight edge between two."""

    state_free: Callable[[NDArray[np.float64]], bool]
    edge_free: Callable[[NDArray[np.float64], NDArray[np.float64]], bool]


@dataclass(frozen=True)
class PathResult:
    """A collision-free joint-space path and how it was found.

    Attributes:
        waypoints: Path vertices, shape (K, dof), first = start, last = goal.
        planner: The OMPL planner's name.
        planning_s: Wall time of the search in [s].
        simplify_s: Wall time of simplification in [s].
        checks: Motions (states and edges) the search checked.
    """

    waypoints: NDArray[np.float64]
    planner: str
    planning_s: float
    simplify_s: float
    checks: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "waypoints", frozen_array(self.waypoints, (None, None), "waypoints"))


class _Work:
    """The checked motions a search has spent against its budget, and its wall-clock safety limit."""

    def __init__(self, time_s: float, timeout_s: float | None) -> None:
        self.time_s = time_s
        self.timeout_s = default_timeout(time_s) if timeout_s is None else timeout_s
        self.budget = max(1, math.ceil(time_s * _CHECKS_PER_S))
        self.deadline = time.perf_counter() + self.timeout_s
        self.set_up_before = setup_time_spent()
        self.used = 0

    def until(self, checks: int) -> ob.PlannerTerminationCondition:
        """Return OMPL's condition that ends a search after `checks` motions in all, or at the safety limit."""
        return ob.PlannerTerminationCondition(lambda: self.used >= checks or self.out_of_time())

    def out_of_time(self) -> bool:
        """Return True once the wall-clock limit is reached, not counting set-up done meanwhile (add_setup_time)."""
        return time.perf_counter() - (setup_time_spent() - self.set_up_before) > self.deadline

    def failure(self, planner: str, status: object) -> PlanningFailed:
        """Return the error for a search that found no path, naming what ended it."""
        if self.used < self.budget and self.out_of_time():
            return PlanningTimeExceeded(
                f"{planner} timed out: {self.timeout_s:g} s of wall time passed after {self.used} of its "
                f"{self.budget} checked motions ({self.time_s:g} s of planning time); the machine is stalled "
                "or far busier than the safety limit allows: raise --timeout")
        return PlanningFailed(f"{planner} found no path within {self.budget} checked motions "
                              f"({self.time_s:g} s of planning time) ({status})")


def plan_path(
    start: NDArray[np.float64],
    goal: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    validity: Validity,
    planner: str = "RRTConnect",
    time_s: float = 1.0,
    timeout_s: float | None = None,
) -> PathResult:
    """Return a collision-free path from `start` to `goal`, both given as group joint values.

    The search may check `time_s` x 20,000 motions; it fails when those find no path, or
    when `timeout_s` seconds of wall time (default: `default_timeout(time_s)`) pass first.
    """
    if planner not in PLANNERS:
        raise UsageError(f"unknown planner '{planner}'; OMPL geometric planners: {known(PLANNERS)}; Pilz's: "
                         f"{', '.join(PILZ_PLANNERS)}")
    return _plan(start, goal, lower, upper, validity, planner, _Work(time_s, timeout_s))


def repair_path(
    waypoints: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    validity: Validity,
    planner: str,
    time_s: float,
    timeout_s: float | None = None,
) -> PathResult:
    """Return `waypoints` with each segment `validity` rejects replaced by a path searched between its ends.

    Raises PlanningFailed when a waypoint is not free (a shortcut can put one between two
    checked states of an edge), or a segment's search finds no path within what remains of the
    budget of `time_s`.
    """
    began = time.perf_counter()
    work = _Work(time_s, timeout_s)
    pieces, simplify_s, used = [waypoints[:1]], 0.0, planner
    for a, b in zip(waypoints[:-1], waypoints[1:], strict=True):
        if validity.edge_free(a, b):
            pieces.append(b[None, :])
            continue
        if not validity.state_free(b):
            raise PlanningFailed("a waypoint of the path collides")
        detour = _plan(a, b, lower, upper, validity, planner, work)
        pieces.append(detour.waypoints[1:])
        simplify_s += detour.simplify_s
        if detour.planner != planner:
            used = detour.planner  # the fallback found this detour
    return PathResult(np.concatenate(pieces), used, time.perf_counter() - began - simplify_s, simplify_s, work.used)


def _planner(name: str, info: ob.SpaceInformation) -> ob.Planner:
    """Return OMPL planner `name` on `info`, its range (if it has one) set."""
    search = getattr(og, name)(info)
    if hasattr(search, "setRange"):
        # OMPL's default, a fifth of the space's diagonal (2.4 rad for a Panda), fails more often
        # in clutter: 5 of 60 MotionBenchMaker bookshelf runs in 1 s, against 1 with 1 rad, which
        # is as fast or faster on the box and table scenes too.
        search.setRange(_RANGE_RAD)
    return search


def _plan(
    start: NDArray[np.float64],
    goal: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    validity: Validity,
    planner: str,
    work: _Work,
) -> PathResult:
    """Return the straight segment if free, else the path OMPL planner `planner` finds within `work`, shortened."""
    space = _bounded_space(len(start), lower, upper)
    setup = og.SimpleSetup(space)
    values = _state_reader(len(start))
    info = _checked_by(setup, validity, work, values)
    endpoints = [_state(space, point) for point in (start, goal)]
    setup.setStartAndGoalStates(endpoints[0], endpoints[1])
    setup.setPlanner(_planner(planner, info))

    began, spent_before = time.perf_counter(), work.used
    work.used += 1
    if validity.edge_free(start, goal):
        # A free straight segment is what any search plus shortcutting converges to.
        return PathResult(np.array([start, goal]), planner, time.perf_counter() - began, 0.0, 1)
    planner, status = _search(setup, info, planner, work)
    planning_s = time.perf_counter() - began
    if not setup.haveExactSolutionPath():
        raise work.failure(planner, status)
    began = time.perf_counter()
    waypoints = _shortened(setup, info, values)
    simplify_s = time.perf_counter() - began
    waypoints[0], waypoints[-1] = start, goal
    return PathResult(waypoints, planner, planning_s, simplify_s, work.used - spent_before)


def _bounded_space(dof: int, lower: NDArray[np.float64], upper: NDArray[np.float64]) -> ob.RealVectorStateSpace:
    """Return OMPL's space of `dof` group joint values, bounded by the joint limits."""
    return _space(dof, tuple(lower.tolist()), tuple(upper.tolist()))


# A space holds no state of a search (samplers and their seeds come from the planner), so every
# search of a robot shares one: making it costs a tenth of a median search.
@functools.lru_cache(maxsize=16)
def _space(dof: int, lower: tuple[float, ...], upper: tuple[float, ...]) -> ob.RealVectorStateSpace:
    """Return OMPL's space of `dof` values within `lower` and `upper`, made once per bounds."""
    space = ob.RealVectorStateSpace(dof)
    bounds = ob.RealVectorBounds(dof)
    for i in range(dof):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    return space


def _state_reader(dof: int) -> Callable[[ob.State], NDArray[np.float64]]:
    """Return the function that reads an OMPL state's `dof` coordinates as an array."""
    coordinates = itemgetter(*range(dof))  # a tenth of the cost of indexing in a Python loop

    def values(state: ob.State) -> NDArray[np.float64]:
        return np.array(coordinates(state), ndmin=1)

    return values


def _checked_by(
    setup: og.SimpleSetup, validity: Validity, work: _Work, values: Callable[[ob.State], NDArray[np.float64]]
) -> ob.SpaceInformation:
    """Return `setup`'s space information, its states and edges now checked by `validity`, each check counted."""

    def state_free(state: ob.State) -> bool:
        work.used += 1
        return validity.state_free(values(state))

    def edge_free(s1: ob.State, s2: ob.State) -> bool:
        work.used += 1
        return validity.edge_free(values(s1), values(s2))

    setup.setStateValidityChecker(state_free)
    info = setup.getSpaceInformation()
    info.setMotionValidator(_EdgeValidator(info, edge_free))
    return info


class _EdgeValidator(ob.MotionValidator):  # type: ignore[misc]  # ompl ships no stubs
    """Checks a whole edge in one call of `edge_free`."""

    def __init__(self, info: ob.SpaceInformation, edge_free: Callable[[ob.State, ob.State], bool]) -> None:
        super().__init__(info)
        self.edge_free = edge_free

    def checkMotion(self, s1: ob.State, s2: ob.State, *rest: object) -> bool:  # noqa: N802 - OMPL's name
        return self.edge_free(s1, s2)


def _state(space: ob.RealVectorStateSpace, point: NDArray[np.float64]) -> ob.State:
    """Return a new OMPL state of `space` at `point`."""
    state = space.allocState()
    for i, value in enumerate(point):
        state[i] = float(value)
    return state


def _search(
    setup: og.SimpleSetup, info: ob.SpaceInformation, planner: str, work: _Work
) -> tuple[str, ob.PlannerStatus]:
    """Return the planner name, "+fallback" if its first share of the budget found no path, and OMPL's status."""
    fallback = _FALLBACK.get(planner)
    first_share = work.used + math.ceil((work.budget - work.used) * _FALLBACK_AFTER) if fallback else work.budget
    status = setup.solve(work.until(first_share))
    if fallback and not setup.haveExactSolutionPath() and not work.out_of_time():
        setup.getProblemDefinition().clearSolutionPaths()  # RRTConnect's approximate one
        setup.setPlanner(_planner(fallback, info))
        planner = f"{planner}+{fallback}"
        status = setup.solve(work.until(work.budget))
    return planner, status


def _shortened(
    setup: og.SimpleSetup, info: ob.SpaceInformation, values: Callable[[ob.State], NDArray[np.float64]]
) -> NDArray[np.float64]:
    """Return the waypoints of `setup`'s solution path after rope shortcutting, shape (K, dof)."""
    path = setup.getSolutionPath()
    # Rope shortcutting (OMPL 2.0) reaches the quality of the full simplify() on MotionBenchMaker
    # problems with about a tenth of its edge checks.
    og.PathSimplifier(info).ropeShortcutPath(path)
    return np.array([values(path.getState(k)) for k in range(path.getStateCount())])
