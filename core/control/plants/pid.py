"""The pid plant: a double integrator per joint, driven through velocity or effort by JTC's PID adapter."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ...config import ControllerConfig
from ...errors import UsageError, known
from ..tolerances import position_error
from .base import Plant, State

__all__ = ["PidPlant", "pid_gains", "pid_interface", "pid_parameters"]


class PidPlant(Plant):
    """Double integrator per joint, driven through velocity or effort by JTC's PID adapter.

    The adapter writes u = ff_velocity_scale * v_command + PID(e_pos, e_vel) (control_toolbox
    Pid; the integral term is clamped to +-i_clamp, so i_clamp 0, JTC's default, turns it off).
    Errors are desired - measured at the current cycle; with JTC sampling the command one
    period ahead, the desired state of this cycle is the previous command, which is what the
    plant keeps. Through `effort`, u is a torque (acceleration = u / inertia, saturated at
    max_effort); through `velocity`, the drive reaches the velocity u (saturated at
    max_velocity) as fast as max_effort allows. Two additions model a real drive: `load` is
    added to u (a torque such as gravity through effort, a velocity offset such as a leaking
    valve through velocity), and the drive applies u through a first-order lag of time
    constant `drive_tau` [s] (0: at once). Every parameter is a scalar or one value per joint.
    """

    def __init__(
        self,
        gains: Mapping[str, NDArray[np.float64]],
        interface: str,
        *,
        max_velocity: npt.ArrayLike = math.inf,
        max_effort: npt.ArrayLike = math.inf,
        inertia: npt.ArrayLike = 1.0,
        noise: npt.ArrayLike = 0.0,
        continuous: npt.ArrayLike | None = None,
        drive_tau: npt.ArrayLike = 0.0,
        load: npt.ArrayLike = 0.0,
    ) -> None:
        self._p, self._i, self._d = gains["p"], gains["i"], gains["d"]
        self._i_clamp, self._ff = gains["i_clamp"], gains["ff_velocity_scale"]
        super().__init__(len(self._p))
        self.interface = interface
        self._max_velocity, self._max_effort = _limit(max_velocity), _limit(max_effort)
        self._inertia = np.asarray(inertia, dtype=np.float64)
        self._max_acceleration = _limit(np.asarray(max_effort, dtype=np.float64) / self._inertia)
        self._noise = np.asarray(noise, dtype=np.float64)
        self._drive_tau = np.asarray(drive_tau, dtype=np.float64)
        self._load = np.asarray(load, dtype=np.float64)
        self._lags = bool(np.any(self._drive_tau > 0.0))
        self._dt, self._follow = math.nan, np.ones(1)
        self._drive = np.zeros_like(self._p)
        mask = np.asarray(False if continuous is None else continuous, dtype=bool)
        self._continuous = mask if mask.any() else None
        self._integrates = bool(np.any((self._i != 0.0) & (self._i_clamp > 0.0)))
        self._rng = np.random.default_rng(0)
        self._integral = np.zeros_like(self._p)
        self._desired: State = (self._q, self._qd)
        self._measured: State = (self._q, self._qd)

    def reset(self, positions: npt.ArrayLike, seed: int = 0) -> State:
        """Return the (noisy) measured state after placing the joints at rest; reseeds the noise."""
        self._rng = np.random.default_rng(seed)
        state = super().reset(positions)
        self.last_output = np.zeros_like(self._q)
        self._integral = np.zeros_like(self._q)
        self._drive = np.zeros_like(self._q)
        # The first cycle's desired state: a MoveIt trajectory starts where the robot is.
        self._desired = (self._q, np.zeros_like(self._q))
        return state

    def step(
        self,
        command_positions: NDArray[np.float64],
        command_velocities: NDArray[np.float64],
        command_accelerations: NDArray[np.float64],
        dt: float,
    ) -> State:
        """Return the measured state after one cycle of PID output applied to the joints."""
        output = self._applied(self._pid(command_velocities, dt), dt)
        self._desired = (command_positions, command_velocities)
        if self.interface == "effort":
            acceleration = _saturate(output, self._max_effort) / self._inertia
        else:
            target = _saturate(output, self._max_velocity)
            acceleration = _saturate((target - self._qd) / dt, self._max_acceleration)
        # Exact for an acceleration held over the period (zero-order hold of the output).
        self._q = self._q + (self._qd + 0.5 * dt * acceleration) * dt
        self._qd = _saturate(self._qd + acceleration * dt, self._max_velocity)
        return self._measure()

    def _applied(self, output: NDArray[np.float64], dt: float) -> NDArray[np.float64]:
        """Return what the drive applies this cycle: the PID output plus the load, through its lag."""
        if self._load.any():
            output = output + self._load
        if not self._lags:
            return output
        if dt != self._dt:
            # Exact for an output held over the period, as the position update is.
            self._dt, self._follow = dt, -np.expm1(-dt / np.maximum(self._drive_tau, 1e-300))
        self._drive = self._drive + (output - self._drive) * self._follow
        return self._drive

    def _pid(self, command_velocities: NDArray[np.float64], dt: float) -> NDArray[np.float64]:
        """Return JTC's PID adapter output for this cycle and remember it as `last_output`."""
        desired_p, desired_v = self._desired
        measured_p, measured_v = self._measured
        if self._continuous is None:
            error = desired_p - measured_p
        else:
            error = position_error(desired_p, measured_p, self._continuous)
        output = self._ff * command_velocities + self._p * error
        output += self._d * (desired_v - measured_v)
        if self._integrates:
            integral = self._integral + self._i * error * dt
            self._integral = np.clip(integral, -self._i_clamp, self._i_clamp)
            output += self._integral
        self.last_output = output
        return output

    def _measure(self) -> State:
        positions = self._q
        if self._noise.any():
            positions = positions + self._rng.normal(0.0, 1.0, len(positions)) * self._noise
        self._measured = (positions, self._qd)
        return self._measured


def _limit(value: npt.ArrayLike) -> float | NDArray[np.float64]:
    """Return a saturation limit: a float when one value holds for every joint (the common case)."""
    array = np.asarray(value, dtype=np.float64)
    return float(array.flat[0]) if array.size == 1 or np.all(array == array.flat[0]) else array


def _saturate(values: NDArray[np.float64], limit: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """Return `values` limited to +-limit; cheap for an infinite limit, the common case."""
    if isinstance(limit, float) and math.isinf(limit):
        return values
    return np.minimum(np.maximum(values, -limit), limit)


_PID_PARAMS = {"inertia": 1.0, "max_effort": math.inf, "max_velocity": math.inf, "noise": 0.0,
               "drive_tau": 0.0, "load": 0.0}
"""pid's parameters and their defaults; each also per joint, `name.<joint>`."""
_GAINS = ("p", "i", "d", "i_clamp", "ff_velocity_scale")


def pid_parameters(params: Mapping[str, float], joints: Sequence[str]) -> dict[str, NDArray[np.float64]]:
    """Return pid's parameters per joint (arrays in the order of `joints`), defaults filled in.

    Raises:
        UsageError: An unknown parameter (the message lists the valid ones), or a value out
            of range: inertia, max_effort and max_velocity must be positive, noise and
            drive_tau >= 0.
    """
    for key in params:
        if key not in _PID_PARAMS and key.split(".", 1) not in ([k, j] for k in _PID_PARAMS for j in joints):
            raise UsageError(f"plant 'pid' has no parameter '{key}'; known: {known(_PID_PARAMS)}, "
                             f"each also as NAME.<joint> for one of {known(joints)}")
    values = {}
    for key, default in _PID_PARAMS.items():
        common = float(params.get(key, default))
        values[key] = np.array([float(params.get(f"{key}.{j}", common)) for j in joints])
        rule, holds = _RANGES[key]
        for which, value in zip([key, *(f"{key}.{j}" for j in joints)], [common, *values[key]], strict=True):
            if not holds(value):
                raise UsageError(f"plant parameter '{which}' must be {rule}, got {value}")
    return values


_RANGES: dict[str, tuple[str, Callable[[float], bool]]] = {
    key: (">= 0", lambda v: v >= 0.0) for key in ("noise", "drive_tau")} | {
    key: ("positive", lambda v: v > 0.0) for key in ("inertia", "max_effort", "max_velocity")} | {
    "load": ("a finite number", math.isfinite)}


def pid_interface(controller: ControllerConfig) -> str:
    """Return the interface JTC's PID adapter drives: velocity or effort, alone."""
    commands = controller.command_interfaces
    if commands in (("velocity",), ("effort",)):
        return commands[0]
    raise UsageError(
        f"plant 'pid' needs JTC's PID adapter, which runs only with command_interfaces "
        f"[velocity] or [effort]; controller '{controller.name}' has [{', '.join(commands)}]"
    )


def pid_gains(controller: ControllerConfig) -> dict[str, NDArray[np.float64]]:
    """Return each PID gain as an array over the controller's joints (missing: 0, as in JTC)."""
    return {
        gain: np.array([controller.gains.get(j, {}).get(gain, 0.0) for j in controller.joints])
        for gain in _GAINS
    }
