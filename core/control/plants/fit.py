"""The pid plant fitted to a recording: parameters under which replaying the plan reproduces what the robot did.

Each recorded step is replayed from the recorded state at its start: the controller's
reference sampled as JTC samples it, the PID adapter with the gains the robot ran with, and
a plant whose parameters are searched, one at a time on a grid with the others held, for
two rounds (coordinate descent), to make the simulated positions closest to the recorded
ones in the least-squares sense. Joints are independent in the plant, so each joint gets
its own parameters, and every candidate of every joint runs in one vectorised pass. The
measurement noise is the recording's own (quality.noise_level), not fitted.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ...trajectory import PointBefore, sample
from ...types import JointTrajectory
from ..quality import noise_level
from .pid import PidPlant

__all__ = ["FITTED", "JointFit", "PlantFit", "RecordedStep", "fit_plant"]

_TAUS = [0.0, *(0.002 * 1.6**k for k in range(14))]
_LIMITS = [math.inf, *(0.5 * 1.8**k for k in range(14))]
_INERTIAS = [1.0, *(0.05 * 1.8**k for k in range(14))]
_LOADS = [0.0, *(s * 10.0**e for e in np.linspace(-4.0, 1.0, 11) for s in (1.0, -1.0))]
FITTED = {"velocity": ("drive_tau", "max_effort", "load"), "effort": ("inertia", "drive_tau", "max_effort", "load")}
"""Parameters fitted per interface; through velocity only max_effort / inertia matters, so inertia stays 1.
max_velocity is not fitted: a plan that never reaches it says nothing of it."""


@dataclass(frozen=True)
class RecordedStep:
    """One step as the robot executed it.

    Attributes:
        trajectory: The plan's step, columns in the order of the recorded positions.
        times_s: Sample times [s] from where the check aligned the step's start, (K,),
            increasing; samples before it (the robot at rest) are negative.
        positions: Recorded positions (K, n).
    """

    trajectory: JointTrajectory
    times_s: NDArray[np.float64]
    positions: NDArray[np.float64]


@dataclass(frozen=True)
class JointFit:
    """How the fitted plant reproduces one joint: its parameters, RMS position error [rad], travel [rad]."""

    joint: str
    params: dict[str, float]
    rms_error: float
    travel: float

    @property
    def fraction(self) -> float | None:
        """Return the RMS error as a fraction of the joint's travel, None for a joint that did not move."""
        return self.rms_error / self.travel if self.travel > 0.0 else None


@dataclass(frozen=True)
class PlantFit:
    """The fitted plant: per joint parameters and errors, and over all joints and samples.

    `shifts_s` are per step where the goal was sent, in [s] from where the check aligned it.
    """

    joints: tuple[JointFit, ...]
    rms_error: float
    travel: float
    samples: int
    shifts_s: tuple[float, ...] = ()

    @property
    def fraction(self) -> float | None:
        """Return the RMS error as a fraction of the largest joint travel."""
        return self.rms_error / self.travel if self.travel > 0.0 else None

    def plant_params(self) -> dict[str, float]:
        """Return the parameters that differ from pid's defaults as `--plant-param` keys, `name.<joint>` each."""
        return {f"{key}.{fit.joint}": value for fit in self.joints for key, value in fit.params.items()
                if value != _DEFAULTS.get(key, 0.0)}


def fit_plant(
    steps: Sequence[RecordedStep],
    interface: str,
    dt: float,
    gains: Mapping[str, NDArray[np.float64]],
    given: Mapping[str, NDArray[np.float64]],
    continuous: NDArray[np.bool_],
    rounds: int = 2,
) -> PlantFit:
    """Return the plant parameters, per joint, that replay `steps` closest to the recording.

    Args:
        steps: The recorded steps, at least one with samples.
        interface: velocity or effort.
        dt: Control period [s].
        gains: The PID gains the robot ran with, arrays over the joints (plants.pid_gains).
        given: pid's parameters the user set, arrays over the joints: kept, not fitted.
        continuous: Per joint, True for continuous joints.
        rounds: Passes over the parameters.
    """
    joints = steps[0].trajectory.joint_names
    n = len(joints)
    current = {key: np.full(n, default) for key, default in _DEFAULTS.items()}
    current.update({key: np.asarray(value, dtype=np.float64) for key, value in given.items() if key in _DEFAULTS})
    fitted = [key for key in FITTED[interface] if key not in given]
    shifts = np.zeros(len(steps))
    for number in range(rounds):
        shifts = _best_shifts(steps, interface, dt, gains, current, continuous)
        for key in fitted:
            # Round 0 searches the whole grid, later rounds around the value found (per joint).
            grid = np.tile(np.asarray(_GRIDS[key], dtype=np.float64)[:, None], (1, n))
            if number:
                grid = _around(current[key], key)
            trials = {name: np.tile(value, len(grid)) for name, value in current.items()}
            trials[key] = grid.reshape(-1)
            errors = sum(_step_error(step, interface, dt, gains, trials, continuous, np.full(len(grid), shift))
                         for step, shift in zip(steps, shifts, strict=True))
            errors = np.reshape(errors, grid.shape)
            best = np.argmin(errors, axis=0)
            # A value the recording cannot tell from the default (a joint that does not move) stays the default.
            default = np.array([np.flatnonzero(grid[:, j] == _DEFAULTS[key])[:1] for j in range(n)], dtype=object)
            for j in range(n):
                kept = default[j]
                if len(kept) and errors[kept[0], j] <= _INDIFFERENT * errors[best[j], j] + 1e-18:
                    best[j] = kept[0]
            current[key] = grid[best, np.arange(n)]
    step_errors = (_step_error(step, interface, dt, gains, current, continuous, np.array([shift]))
                   for step, shift in zip(steps, shifts, strict=True))
    final = cast(NDArray[np.float64], sum(step_errors))
    counts = sum(len(s.times_s) for s in steps)
    noise = noise_level(np.vstack([s.positions for s in steps]))
    travel = np.max([np.ptp(s.positions, axis=0) for s in steps], axis=0)
    fits = tuple(
        JointFit(joint, {**{key: float(current[key][j]) for key in fitted}, "noise": float(noise[j])},
                 float(math.sqrt(final[j] / max(counts, 1))), float(travel[j]))
        for j, joint in enumerate(joints)
    )
    rms = math.sqrt(float(np.sum(final)) / max(counts * n, 1))
    return PlantFit(fits, rms, float(np.max(travel)), counts, tuple(float(x) for x in shifts))


_INDIFFERENT = 1.01
"""A fitted value must cut the squared error by more than this factor to replace the default."""


def _around(values: NDArray[np.float64], key: str) -> NDArray[np.float64]:
    """Return a finer grid (rows) around each joint's value (columns), the default included."""
    if key == "load":
        steps = np.linspace(-0.5, 0.5, 9)[:, None] * (np.abs(values) + 1e-4)
        return np.vstack((values + steps, np.zeros_like(values)))
    finite = np.where(np.isfinite(values) & (values > 0.0), values, np.nan)
    ratios = 1.6 ** np.linspace(-1.0, 1.0, 9)[:, None]
    rows = np.where(np.isnan(finite), values, finite * ratios)
    return np.vstack((rows, np.full_like(values, _DEFAULTS[key])))


_DEFAULTS = {"inertia": 1.0, "max_effort": math.inf, "max_velocity": math.inf, "drive_tau": 0.0, "load": 0.0}
_GRIDS = {"drive_tau": _TAUS, "max_effort": _LIMITS, "inertia": _INERTIAS, "load": _LOADS}
SHIFT_S = 0.1
"""The goal's send time is searched this far [s] either side of where the check aligned each step."""


def _best_shifts(
    steps: Sequence[RecordedStep], interface: str, dt: float, gains: Mapping[str, NDArray[np.float64]],
    current: Mapping[str, NDArray[np.float64]], continuous: NDArray[np.bool_],
) -> NDArray[np.float64]:
    """Return per step the send time [s] (from its aligned start) whose replay is closest to the recording."""
    shifts = np.arange(-SHIFT_S, SHIFT_S + 0.5 * dt, max(dt, 0.002))
    params = {name: np.tile(value, len(shifts)) for name, value in current.items()}
    best = []
    for step in steps:
        errors = _step_error(step, interface, dt, gains, params, continuous, shifts)
        best.append(shifts[np.argmin(np.reshape(errors, (len(shifts), -1)).sum(axis=1))])
    return np.array(best)


def _step_error(
    step: RecordedStep, interface: str, dt: float, gains: Mapping[str, NDArray[np.float64]],
    params: Mapping[str, NDArray[np.float64]], continuous: NDArray[np.bool_], shifts: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Return per column the summed squared error of one step replayed with the goal sent at each shift [s].

    Columns come in blocks of the step's joints, one block per shift; the replay starts from
    the last sample at or before the send time, at rest.
    """
    times, recorded = step.times_s, step.positions
    n, copies = recorded.shape[1], len(shifts)
    count = int(math.ceil((float(times[-1]) - float(np.min(shifts))) / dt)) + 2
    since = np.arange(count) * dt
    starts = np.vstack([recorded[max(0, int(np.searchsorted(times, shift, side="right")) - 1)] for shift in shifts])
    parts = [sample(step.trajectory, since, point_before=PointBefore(start, None, None), continuous=continuous)
             for start in starts]
    ref_p, ref_v, ref_a = (np.hstack([part[k] for part in parts]) for k in range(3))
    plant = PidPlant({name: np.tile(value, copies) for name, value in gains.items()}, interface,
                     max_velocity=params["max_velocity"], max_effort=params["max_effort"],
                     inertia=params["inertia"], drive_tau=params["drive_tau"], load=params["load"])
    first, _ = plant.reset(starts.reshape(-1))
    with np.errstate(over="ignore", invalid="ignore"):
        # JTC writes the sample one period ahead: the state after command k is read at since[k + 1].
        simulated, _, _ = plant.run(ref_p[1:], ref_v[1:], ref_a[1:], dt, np.zeros_like(ref_p[1:]))
        simulated = np.vstack((first, simulated))
        rows = np.clip(np.round((times[:, None] - shifts[None, :]) / dt).astype(np.intp), 0, count - 1)
        columns = np.arange(copies * n).reshape(copies, n)
        replayed = simulated[rows[:, :, None], columns[None, :, :]].reshape(len(times), copies * n)
        error = replayed - np.tile(recorded, (1, copies))
        squared = np.sum(error * error, axis=0)
    return np.where(np.isfinite(squared), squared, np.inf)
