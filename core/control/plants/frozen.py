"""The frozen plant: hardware that ignores its commands (ros2_controllers' tests hold state and command apart)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .base import Plant, State

__all__ = ["FrozenPlant"]


class FrozenPlant(Plant):
    """Hardware that ignores commands (the upstream tests' separate command and state values)."""

    def step(
        self,
        command_positions: NDArray[np.float64],
        command_velocities: NDArray[np.float64],
        command_accelerations: NDArray[np.float64],
        dt: float,
    ) -> State:
        """Return the unchanged state."""
        self.last_output = command_positions
        return self._measure()
