"""Disturbance responses of one joint on the pid plant: many gain sets simulated at once, and measured.

A response is the joint at rest at its setpoint (the controller holding it, reference still)
bumped by a step displacement, or pushed by a constant load, simulated for a window at the
controller's update rate. The joints of PidPlant are independent, so a column per gain set
simulates a whole ladder of gains in one pass.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..quality import BAND_FLOOR, NOISE_BANDS, crossings, noise_level
from .pid import PidPlant

__all__ = ["DIVERGED", "SETTLE_FRACTION", "Response", "measure", "simulate_responses"]

SETTLE_FRACTION = 0.02
"""A bump response has settled once within this fraction of the bump (or the noise band)."""
DIVERGED = 100.0
"""A response that moves this many bumps away has diverged."""


@dataclass(frozen=True)
class Response:
    """What a disturbance response did; positions in [rad] (or [m]), times in [s].

    Attributes:
        oscillations: Sign changes of the error beyond the hysteresis band (quality.crossings).
        decay_ratio: Geometric mean of successive half-cycle peak ratios: about 1 for a
            steady oscillation, above 1 growing, 0 with fewer than one sign change.
        overshoot: Largest excursion past the setpoint, away from the side the bump pushed to.
        settling_time_s: Time until within SETTLE_FRACTION of the bump for good; None if never.
        peak_error: Largest |error|.
        final_error: Error (setpoint - position) at the end of the window.
        period_s: Mean oscillation period (twice the mean time between sign changes), None
            with fewer than two sign changes.
        diverged: The response grew past DIVERGED bumps or stopped being finite.
        damped: Critically damped or more: it settles, overshooting at most SETTLE_FRACTION
            of the bump.
    """

    oscillations: int
    decay_ratio: float
    overshoot: float
    settling_time_s: float | None
    peak_error: float
    final_error: float
    period_s: float | None
    diverged: bool
    damped: bool

    def as_dict(self) -> dict[str, float | int | bool | None]:
        """Return the figures as a JSON-ready mapping."""
        return {"oscillations": self.oscillations, "decay_ratio": self.decay_ratio, "overshoot": self.overshoot,
                "settling_time_s": self.settling_time_s, "peak_error": self.peak_error,
                "final_error": self.final_error, "period_s": self.period_s, "diverged": self.diverged,
                "damped": self.damped}


def simulate_responses(
    interface: str,
    dt: float,
    gains: Mapping[str, npt.ArrayLike],
    plant: Mapping[str, float],
    window_s: float,
    *,
    bump: float = 0.0,
    load: float = 0.0,
    seed: int = 0,
) -> NDArray[np.float64]:
    """Return measured positions relative to the setpoint, (K + 1, m), of m gain sets over the window.

    Row 0 is the state right after the bump (or at rest, under `load`); row k the state k
    control periods later. `gains` maps p, i, d, i_clamp, ff_velocity_scale to one value or m;
    `plant` holds pid's parameters for this joint (plants.pid_parameters), its own load
    replaced by `load`.
    """
    columns = {key: np.atleast_1d(np.asarray(value, dtype=np.float64)) for key, value in gains.items()}
    count = max(len(v) for v in columns.values())
    columns = {key: np.broadcast_to(value, (count,)).copy() for key, value in columns.items()}
    pid = PidPlant(columns, interface, max_velocity=plant["max_velocity"], max_effort=plant["max_effort"],
                   inertia=plant["inertia"], noise=plant["noise"], drive_tau=plant["drive_tau"], load=load)
    cycles = max(1, round(window_s / dt))
    first, _ = pid.reset(np.zeros(count), seed)
    if bump:
        first, _ = pid.displace(np.full(count, bump))
    still = np.zeros((cycles, count))
    with np.errstate(over="ignore", invalid="ignore"):
        positions, _, _ = pid.run(still, still, still, dt, still)
    return np.vstack((first, positions))


def measure(positions: npt.ArrayLike, dt: float, scale: float) -> list[Response]:
    """Return the figures of each column of `positions` (K, m) relative to the setpoint.

    `scale` [rad] sets the settling band (SETTLE_FRACTION of it) and what counts as diverged:
    the bump, or the steady error a load would leave.
    """
    traces = np.asarray(positions, dtype=np.float64)
    noise = noise_level(traces)
    return [_measured(traces[:, m], dt, scale, float(noise[m])) for m in range(traces.shape[1])]


def _measured(trace: NDArray[np.float64], dt: float, scale: float, noise: float) -> Response:
    error = -trace
    finite = bool(np.all(np.isfinite(error)))
    peak = float(np.max(np.abs(error))) if finite else math.inf
    if not finite or peak > DIVERGED * scale:
        return Response(len(crossings(error[np.isfinite(error)], BAND_FLOOR)), math.inf, math.inf, None, peak,
                        float(error[-1]), None, True, False)
    band = max(BAND_FLOOR, NOISE_BANDS * noise)
    changes = crossings(error, band)
    pushed = math.copysign(1.0, float(trace[0])) if trace[0] else 1.0
    overshoot = max(0.0, float(np.max(-pushed * trace)) - NOISE_BANDS * noise)
    period = 2.0 * dt * float(np.mean(np.diff(changes))) if len(changes) > 1 else None
    settling = _settling(error, dt, max(SETTLE_FRACTION * scale, band))
    return Response(
        oscillations=len(changes),
        decay_ratio=_decay_ratio(error, changes),
        overshoot=overshoot,
        settling_time_s=settling,
        peak_error=peak,
        final_error=float(error[-1]),
        period_s=period,
        diverged=False,
        damped=settling is not None and overshoot <= SETTLE_FRACTION * scale,
    )


def _decay_ratio(error: NDArray[np.float64], changes: Sequence[int] | NDArray[np.intp]) -> float:
    """Return the geometric mean ratio of successive half-cycle peaks (0 without a sign change)."""
    if len(changes) == 0:
        return 0.0
    bounds = [0, *[int(c) for c in changes], len(error)]
    peaks = np.array([np.max(np.abs(error[a:b])) for a, b in zip(bounds[:-1], bounds[1:], strict=True)])
    # The last half-cycle is cut by the window: compare it only if it is not the sole one left.
    ratios = peaks[1:] / np.maximum(peaks[:-1], 1e-300)
    if len(ratios) > 1:
        ratios = ratios[:-1]
    return float(np.exp(np.mean(np.log(np.maximum(ratios, 1e-300)))))


def _settling(error: NDArray[np.float64], dt: float, band: float) -> float | None:
    """Return the time [s] from which |error| stays within `band`, None if not by the window's end."""
    outside = np.flatnonzero(np.abs(error) > band)
    if not len(outside):
        return 0.0
    if outside[-1] == len(error) - 1:
        return None
    return float((outside[-1] + 1) * dt)
