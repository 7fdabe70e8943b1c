"""The simulated hardware's interface: a plant takes a command each control cycle and returns the state."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

__all__ = ["Plant", "Run", "State"]

State = tuple[NDArray[np.float64], NDArray[np.float64]]
Run = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]


class Plant(ABC):
    """Simulated hardware for n joints; positions in [rad] or [m], velocities in [rad]/[s].

    Attributes:
        interface: The command interface the plant is driven through.
        last_output: The value written to that interface by the last `step`, shape (n,).
    """

    interface = "position"

    def __init__(self, joint_count: int) -> None:
        self._q = np.zeros(joint_count)
        self._qd = np.zeros(joint_count)
        self.last_output = np.zeros(joint_count)

    def reset(self, positions: npt.ArrayLike, seed: int = 0) -> State:
        """Return the measured state after placing the joints at rest at `positions`."""
        self._q = np.array(positions, dtype=np.float64)
        self._qd = np.zeros_like(self._q)
        self.last_output = self._q.copy()
        return self._measure()

    @abstractmethod
    def step(
        self,
        command_positions: NDArray[np.float64],
        command_velocities: NDArray[np.float64],
        command_accelerations: NDArray[np.float64],
        dt: float,
    ) -> State:
        """Return the measured positions and velocities after applying one command for `dt` [s]."""

    def displace(self, delta: NDArray[np.float64]) -> State:
        """Return the measured state after a bump moved the joints by `delta`."""
        self._q = self._q + delta
        return self._measure()

    def run(
        self,
        command_positions: NDArray[np.float64],
        command_velocities: NDArray[np.float64],
        command_accelerations: NDArray[np.float64],
        dt: float,
        bumps: NDArray[np.float64],
    ) -> Run:
        """Return measured positions, velocities and outputs, (K, n) each, after each of K commands.

        Row k is the state after command k and then bump k (a displacement, usually zero).
        """
        count, n = command_positions.shape
        positions, velocities, outputs = (np.empty((count, n)) for _ in range(3))
        bumped = np.any(bumps != 0.0, axis=1)
        for k in range(count):
            p, v = self.step(
                command_positions[k], command_velocities[k], command_accelerations[k], dt
            )
            outputs[k] = self.last_output
            if bumped[k]:
                p, v = self.displace(bumps[k])
            positions[k], velocities[k] = p, v
        return positions, velocities, outputs

    def _measure(self) -> State:
        # Plants rebind their state arrays and never modify them in place, so no copies.
        return self._q, self._qd
