"""A problem's collision checks, built once per robot and scene; the sphere filter once it pays for itself.

The sphere filter (core/collision/sphere_filter.py) clears a state in microseconds. Its kernels
are compiled once per install, ahead of time where a C compiler allows (core/_native.py): then a
fresh process builds the filter in ~11 ms without numba, and every problem gets it with its
collision set-up, as a benchmark's does. Where numba's JIT runs them instead (an ahead-of-time
build failed), building the filter imports numba: ~0.7 s in a fresh process. A plan of a few
steps asks about a few thousand states, which coal alone judges 3-4 us slower each than the
filter does: tens of milliseconds. So there a one-shot command starts with coal alone and builds
the filter once the states it has asked about pass `after` (all its problems' together: a
script's plans in changing scenes too). The rule is rent or buy: by then coal alone has spent
about as much more than the filter would have as building the filter costs
(benchmarks/filter_threshold.py measures both). Where the kernels are not compiled yet (a fresh
install), the build costs a compilation, so the rule waits correspondingly longer: a first plan
on a fresh machine costs what it costs warm unless it is one that would pay for the compilation
anyway. A build inside a step is kept off the search's planning-time cap (core/collision/compiled.py).
A process that has built one filter has the kernels loaded, and builds the next at once.

Every verdict is the same either way: a state the spheres clear is free under the hulls (they
are fitted to the hulls), and one they find colliding collides under them (core/collision/motion.py).
What changes is only how fast it is reached; a plan is byte for byte the same with or without the
filter (tests/pipeline/test_filter_rule.py).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..collision import (
    MAYBE,
    GeometryMode,
    MotionChecker,
    SphereFilter,
    add_setup_time,
    build_sphere_filter,
    count_unfiltered,
    kernels_loaded,
    kernels_native,
    kernels_ready,
    scene_checkers,
    sphere_filter_cached,
)
from ..model import Robot, Scene
from ..trajectory import interpolate

__all__ = ["AT_ONCE_IF_FITTED", "FILTER_AFTER_STATES", "FILTER_AFTER_STATES_UNCOMPILED", "FILTER_AFTER_STATES_UNFITTED",
           "Problem", "build_problem", "filter_threshold"]

logger = logging.getLogger(__name__)

FILTER_AFTER_STATES = 150_000
"""States a one-shot command checks with coal alone before it builds the sphere filter: the build's ~0.5 s
over the 3-3.8 us a state costs more without it (benchmarks/filter_threshold.py, MotionBenchMaker's Panda)."""
FILTER_AFTER_STATES_UNFITTED = 1_000_000
"""The same when the kernels are compiled ahead of time but the robot's spheres and distance tables are not fitted
yet: 1.7-2.0 s the Panda's, 7 s a UR5's, over the 4 us a state costs more. Fitted, the filter is built at once."""
AT_ONCE_IF_FITTED = -1
"""`after` where the kernels are compiled ahead of time: the filter at once if the robot's spheres and tables are
cached (a build of ~11 ms), else after FILTER_AFTER_STATES_UNFITTED states."""
FILTER_AFTER_STATES_UNCOMPILED = 6_000_000
"""The same when numba has yet to compile the kernels: the compilation's ~20 s over the same 3-3.8 us."""


def filter_threshold() -> int:
    """Return how many states a one-shot command checks with coal before it builds the sphere filter."""
    if kernels_native():
        return AT_ONCE_IF_FITTED
    return FILTER_AFTER_STATES if kernels_ready() else FILTER_AFTER_STATES_UNCOMPILED


@dataclass(frozen=True)
class Problem:
    """One planning problem: the robot's group, the scene, and their collision checks, built once for its steps.

    Attributes:
        robot: The robot and its planning group.
        scene: Its collision objects and frames.
        checks: Collision checks of the group in the scene; `checks.base` holds the joints
            outside the group.
    """

    robot: Robot
    scene: Scene
    checks: MotionChecker

    @property
    def base(self) -> NDArray[np.float64]:
        """Return the configuration the joints outside the group keep."""
        return self.checks.base


def build_problem(
    robot: Robot, scene: Scene, geometry: GeometryMode, base: NDArray[np.float64], after: int = 0
) -> Problem:
    """Return the problem of `robot` (other joints at `base`) in `scene`; the sphere filter comes after `after` states.

    The states are those this process has had judged without a filter, in any problem. With
    `after` 0 the filter is built now, as a benchmark wants (its set-up outside the timed steps);
    with AT_ONCE_IF_FITTED, now if it takes milliseconds (the robot's spheres and tables cached).
    """
    return Problem(robot, scene, _checks(robot, scene, geometry, base, after))


def _checks(
    robot: Robot, scene: Scene, geometry: GeometryMode, base: NDArray[np.float64], after: int
) -> MotionChecker:
    """Return the checks of `robot` (other joints at `base`) in `scene`, the filter built after `after` states."""
    checker, hulls = scene_checkers(robot, scene, geometry)

    def build() -> SphereFilter | None:
        return build_sphere_filter(robot, checker, hulls, scene, base)

    if after == AT_ONCE_IF_FITTED:
        after = 0 if sphere_filter_cached(robot, checker, hulls) else FILTER_AFTER_STATES_UNFITTED
    if after <= 0 or kernels_loaded():
        return MotionChecker(robot, checker, base, build(), hulls)
    motion = MotionChecker(robot, checker, base, None, hulls)
    # Once built, the filter replaces the stand-in: a search calls it thousands of times, each call through
    # the stand-in a Python call more.
    motion.spheres = OnDemandSpheres(robot, base, build, after, lambda built: setattr(motion, "spheres", built))
    return motion


class OnDemandSpheres:
    """The sphere filter, built on first need; until then every state is unsure (MAYBE) and goes to coal."""

    def __init__(
        self, robot: Robot, base: NDArray[np.float64], build: Callable[[], SphereFilter | None], after: int,
        built: Callable[[SphereFilter | None], None],
    ) -> None:
        """Answer for `robot` (joints outside the group at `base`); past `after` states, `build` and hand to `built`."""
        self._robot, self._base, self._build, self._built = robot, base, build, built
        self._after = after
        self._filter: SphereFilter | None = None
        self._pending = True

    def classify(self, values: NDArray[np.float64], stop: bool = False) -> tuple[
            NDArray[np.int8], NDArray[np.float64]]:
        """Return per group state (rows of `values`) CLEAR, MAYBE or COLLIDES, and the configurations (k, nq)."""
        values = np.atleast_2d(values)
        spheres = self._spheres(len(values))
        if spheres is not None:
            return spheres.classify(values, stop)
        q = self._robot.configurations(values, self._base).T
        return np.full(len(q), MAYBE, dtype=np.int8), q

    def edge(self, a: NDArray[np.float64], b: NDArray[np.float64], resolution: float, stop: bool = False) -> tuple[
            int, NDArray[np.int8], NDArray[np.float64]]:
        """Return the worst verdict on the edge's states (`b` included, `a` not), and those not CLEAR."""
        states = interpolate(a, b, resolution)[1:]
        spheres = self._spheres(len(states))
        if spheres is not None:
            return spheres.edge(a, b, resolution, stop)
        return MAYBE, np.full(len(states), MAYBE, dtype=np.int8), self._robot.configurations(states, self._base).T

    def certify(self, states: NDArray[np.float64], travel: NDArray[np.float64], floor: float) -> tuple[
            NDArray[np.int8], NDArray[np.float64], NDArray[np.float64]]:
        """Return the filter's verdicts on a motion's states, the configurations, and radii (0 until it is built)."""
        spheres = self._spheres(len(states))
        if spheres is not None:
            return spheres.certify(states, travel, floor)
        return (np.full(len(states), MAYBE, dtype=np.int8), self._robot.configurations(states, self._base).T,
                np.zeros(len(states)))

    def _spheres(self, count: int) -> SphereFilter | None:
        """Return the filter once built, else None; count the states asked about, and build it once they are enough.

        Enough is more than `after` states judged without a filter in this process, in any problem.
        """
        if self._pending and count_unfiltered(count) > self._after:
            self._settle()
        return self._filter

    def _settle(self) -> None:
        """Build the filter now, its time kept off any search's cap; return None."""
        self._pending = False
        logger.debug("building the sphere filter after %d states checked by coal alone", self._after)
        began = time.perf_counter()
        self._filter = self._build()
        add_setup_time(time.perf_counter() - began)
        self._built(self._filter)
