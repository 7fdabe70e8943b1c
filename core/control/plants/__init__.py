"""Simulated hardware behind a JointTrajectoryController: what happens to the commands it writes.

A plant receives, once per control cycle, the command the controller samples and returns the
state the controller will read on the next cycle: one plant a module around `base.Plant`.
`mirror` copies commands to states like ros2_control's mock_components/GenericSystem, `lag`
follows them with a first-order delay, `pid` is a double integrator per joint driven through
the velocity or effort interface by JTC's PID adapter, `frozen` ignores them. `catalog` makes
them by name; `responses` and `fit` are what tuning learns of a plant from its step response.
"""

from .base import Plant
from .catalog import PLANTS, make_plant
from .frozen import FrozenPlant
from .lag import LagPlant
from .mirror import MirrorPlant
from .pid import PidPlant, pid_gains, pid_interface, pid_parameters

__all__ = [
    "PLANTS", "FrozenPlant", "LagPlant", "MirrorPlant", "PidPlant", "Plant", "make_plant", "pid_gains",
    "pid_interface", "pid_parameters",
]
