"""The plants by name, as `--plant` and `--plant-param` give them."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from ...config import PLANT_MODELS, ControllerConfig
from ...errors import UsageError, known
from .base import Plant
from .lag import LagPlant
from .mirror import MirrorPlant
from .pid import PidPlant, pid_gains, pid_interface, pid_parameters

__all__ = ["PLANTS", "make_plant"]

PLANTS = PLANT_MODELS
"""Plant names `make_plant` knows, the default first."""


def make_plant(
    name: str,
    params: Mapping[str, float],
    controller: ControllerConfig,
    continuous_joints: Iterable[str] = (),
) -> Plant:
    """Return the plant `name` for the controller's joints, tuned by `params`.

    mirror takes no parameters; lag takes `tau` [s] for all joints and `tau.<joint>` for one
    (default 0.05 s); both follow the sampled position command whatever the controller's
    command interfaces. pid takes max_velocity [rad]/[s], max_effort [N m], inertia
    [kg m^2], noise (standard deviation of measured positions [rad]), drive_tau (the drive's
    lag [s]) and load (added to the PID output: [N m] through effort, [rad]/[s] through
    velocity), each for all joints or as `name.<joint>` for one, and the gains of
    `controller`, which must command velocity or effort alone. Raises UsageError for an
    unknown plant or parameter, naming the valid ones.
    """
    joints = controller.joints
    if name == "mirror":
        _check_params(name, params, ())
        return MirrorPlant(len(joints))
    if name == "lag":
        _check_params(name, params, ("tau", *(f"tau.{j}" for j in joints)))
        default = _positive(params, "tau", 0.05)
        return LagPlant([_positive(params, f"tau.{j}", default) for j in joints])
    if name == "pid":
        values = pid_parameters(params, joints)
        return PidPlant(pid_gains(controller), pid_interface(controller),
                        continuous=[j in set(continuous_joints) for j in joints], **values)
    raise UsageError(f"unknown plant '{name}'; known: {known(PLANTS)}")


def _check_params(name: str, params: Mapping[str, float], valid: Iterable[str]) -> None:
    allowed = set(valid)
    for key in params:
        if key not in allowed:
            raise UsageError(f"plant '{name}' has no parameter '{key}'; known: {known(allowed)}")


def _positive(params: Mapping[str, float], key: str, default: float) -> float:
    value = float(params.get(key, default))
    if not value > 0.0:
        raise UsageError(f"plant parameter '{key}' must be positive, got {value}")
    return value
