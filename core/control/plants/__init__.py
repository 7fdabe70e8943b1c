"""Simulated hardware behind a JointTrajectoryController: what happens to the commands it writes.

A plant receives, once per control cycle, the command the controller samples and returns the
state the controller will read on the next cycle: one plant a module around `base.Plant`.
`mirror` copies commands to states like ros2_control's mock_components/GenericSystem, `lag`
follows them with a first-order delay, `pid` is a double integrator per joint driven through
the velocity or effort interface by JTC's PID adapter, `frozen` ignores them. `catalog` makes
them by name; `responses` and `fit` are what tuning learns of a plant from its step response.
"""

from typing import TYPE_CHECKING

from ..._faces import lazy_exports

if TYPE_CHECKING:
    from .base import Plant
    from .catalog import PLANTS, make_plant
    from .fit import PlantFit, RecordedStep, fit_plant
    from .frozen import FrozenPlant
    from .lag import LagPlant
    from .mirror import MirrorPlant
    from .pid import PidPlant, pid_gains, pid_interface, pid_parameters
    from .responses import Response, measure, simulate_responses

__all__ = [
    "FrozenPlant",
    "LagPlant",
    "MirrorPlant",
    "PLANTS",
    "PidPlant",
    "Plant",
    "PlantFit",
    "RecordedStep",
    "Response",
    "fit_plant",
    "make_plant",
    "measure",
    "pid_gains",
    "pid_interface",
    "pid_parameters",
    "simulate_responses",
]

__getattr__ = lazy_exports(__name__, {
    "FrozenPlant": "frozen",
    "LagPlant": "lag",
    "MirrorPlant": "mirror",
    "PLANTS": "catalog",
    "PidPlant": "pid",
    "Plant": "base",
    "PlantFit": "fit",
    "RecordedStep": "fit",
    "Response": "responses",
    "fit_plant": "fit",
    "make_plant": "catalog",
    "measure": "responses",
    "pid_gains": "pid",
    "pid_interface": "pid",
    "pid_parameters": "pid",
    "simulate_responses": "responses",
})
