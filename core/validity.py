"""Collision checks of group motions: states, edges for the search, and certification of what is written.

Two geometries answer. A conservative sphere model (core/fastcheck.py) clears most
states in microseconds; whatever it cannot clear goes to coal with the robot's real
collision geometry (core/collision.py). Since the spheres enclose the real geometry,
a state they clear is free, so every answer is the real geometry's answer.

Certification checks a trajectory as the controller interpolates it, at states so
close that no point of the robot moves more than `step_m` between two of them
(core/certify.py bounds that motion).
"""

from __future__ import annotations

import logging
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from moveplan.core import certify
from moveplan.core.collision import CollisionChecker
from moveplan.core.robot import Robot
from moveplan.core.types import JointTrajectory

__all__ = ["CERTIFY_STEP_M", "MotionChecker"]

logger = logging.getLogger(__name__)

CERTIFY_STEP_M = 0.005  # the most any robot point moves between two certified states [m]
_STRIDE = 8


class Filter(Protocol):
    """A conservative pre-check: True where a configuration is certainly free."""

    def clear(self, q: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Return per configuration (rows of shape (k, nq)) True if it is certainly collision-free."""
        ...


class MotionChecker:
    """Answers whether group states, straight edges and timed trajectories are collision-free."""

    def __init__(
        self, robot: Robot, checker: CollisionChecker, base: NDArray[np.float64], spheres: Filter | None = None
    ) -> None:
        """Check `robot` with its other joints at `base`, by `checker`'s geometry, pre-filtered by `spheres`."""
        self.robot = robot
        self.checker = checker
        self.base = base
        self.spheres = spheres
        self.reach = certify.reach(robot, checker.geometry)
        self.coal_states = 0  # states the spheres could not clear, for statistics

    def free(self, values: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Return per group state (rows of `values`) True if it is collision-free."""
        q = self.robot.configurations(np.atleast_2d(values), self.base)
        if self.spheres is None:
            return self.checker.free_batch(q)
        free = np.asarray(self.spheres.clear(np.ascontiguousarray(q.T)), dtype=bool)
        unclear = np.flatnonzero(~free)
        if len(unclear):
            self.coal_states += len(unclear)
            free[unclear] = self.checker.free_batch(q[:, unclear])
        return free

    def state_free(self, values: NDArray[np.float64]) -> bool:
        """Return True if one group state is collision-free."""
        return bool(self.free(values[None, :])[0])

    def edge_free(self, a: NDArray[np.float64], b: NDArray[np.float64], resolution: float) -> bool:
        """Return True if the straight edge from `a` to `b` is free at states `resolution` [rad] apart."""
        count = max(1, int(np.ceil(np.max(np.abs(b - a)) / resolution)))
        states = a + (b - a) * (np.arange(1, count + 1) / count)[:, None]
        # Most edges a search tries run into something, over many states in a row: every
        # eighth state first finds most collisions with an eighth of the checks.
        coarse = np.zeros(count, dtype=bool)
        coarse[_STRIDE - 1 :: _STRIDE] = True
        return self._all_free(states[coarse]) and self._all_free(states[~coarse])

    def _all_free(self, states: NDArray[np.float64]) -> bool:
        """Return True if every state is free, stopping at the first collision."""
        if len(states) == 0:
            return True
        q = self.robot.configurations(states, self.base)
        if self.spheres is None:
            return bool(self.checker.free_batch(q, stop_at_first=True).all())
        unclear = np.flatnonzero(~np.asarray(self.spheres.clear(np.ascontiguousarray(q.T)), dtype=bool))
        self.coal_states += len(unclear)
        return len(unclear) == 0 or bool(self.checker.free_batch(q[:, unclear], stop_at_first=True).all())

    def edge_free_certified(self, a: NDArray[np.float64], b: NDArray[np.float64]) -> bool:
        """Return True if the straight edge is free at the states certification checks on it."""
        return self.first_collision_on_path(np.array([a, b])) is None

    def first_collision_on_trajectory(self, trajectory: JointTrajectory) -> NDArray[np.float64] | None:
        """Return the first colliding state along the interpolated trajectory, or None if it is free."""
        return self._first_collision(certify.trajectory_states(trajectory, self.reach, CERTIFY_STEP_M))

    def first_collision_on_path(self, waypoints: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """Return the first colliding state along the straight segments between waypoints, or None."""
        states = [certify.segment_states(a, b, self.reach, CERTIFY_STEP_M)
                  for a, b in zip(waypoints[:-1], waypoints[1:], strict=True)]
        return self._first_collision(np.concatenate(states) if states else waypoints)

    def _first_collision(self, states: NDArray[np.float64]) -> NDArray[np.float64] | None:
        free = self.free(states)
        return None if free.all() else states[int(np.argmin(free))]

    def colliding_pair(self, values: NDArray[np.float64]) -> tuple[str, str] | None:
        """Return the names of a colliding pair at a group state, or None."""
        return self.checker.colliding_pair(self.robot.configuration(values, self.base))
