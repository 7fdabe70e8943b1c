"""The lag plant: a first-order response to the position command."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from .base import Plant, State

__all__ = ["LagPlant"]


class LagPlant(Plant):
    """First-order response to the position command with time constant `tau_s` per joint [s]."""

    def __init__(self, tau_s: npt.ArrayLike) -> None:
        self._tau = np.array(tau_s, dtype=np.float64)
        self._dt, self._decay = math.nan, np.ones_like(self._tau)
        super().__init__(len(self._tau))

    def step(
        self,
        command_positions: NDArray[np.float64],
        command_velocities: NDArray[np.float64],
        command_accelerations: NDArray[np.float64],
        dt: float,
    ) -> State:
        """Return the state after moving exponentially towards the command for `dt`."""
        if dt != self._dt:
            self._dt, self._decay = dt, np.exp(-dt / self._tau)
        self._q = command_positions + (self._q - command_positions) * self._decay
        self._qd = (command_positions - self._q) / self._tau
        self.last_output = command_positions
        return self._measure()
