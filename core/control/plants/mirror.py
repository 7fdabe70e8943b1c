"""The mirror plant: joints are where they were told to be, like mock_components/GenericSystem."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .base import Plant, Run, State

__all__ = ["MirrorPlant"]


class MirrorPlant(Plant):
    """State = command, like mock_components/GenericSystem: joints are where they were told to be.

    GenericSystem reports velocity 0 unless velocity is commanded; this reports the commanded
    velocity, which JTC only compares when it commands velocity or effort.
    """

    def step(
        self,
        command_positions: NDArray[np.float64],
        command_velocities: NDArray[np.float64],
        command_accelerations: NDArray[np.float64],
        dt: float,
    ) -> State:
        """Return the command as the new state."""
        self._q, self._qd = command_positions, command_velocities
        self.last_output = command_positions
        return self._measure()

    def run(
        self,
        command_positions: NDArray[np.float64],
        command_velocities: NDArray[np.float64],
        command_accelerations: NDArray[np.float64],
        dt: float,
        bumps: NDArray[np.float64],
    ) -> Run:
        """Return the commands as states, plus the bumps: no loop, the state is the command."""
        self._q, self._qd = command_positions[-1] + bumps[-1], command_velocities[-1].copy()
        self.last_output = command_positions[-1].copy()
        return command_positions + bumps, command_velocities.copy(), command_positions.copy()
