"""Execution quality: how well each joint tracked its reference, and whether it rings after stopping.

Tolerances say pass or fail; these figures say how close to failing and how a joint behaves
once its reference has stopped, which is what a user tuning gains looks at: the peak
tracking error, the overshoot past the goal, the settling time into the goal tolerance, the
oscillations after the stop and the final error. They are computed the same way on a
simulated execution and on a recording.

Oscillations are sign changes of the tracking error with hysteresis: the error must leave
the band +-`band` on one side and then on the other for a change to count, so that numeric
noise and sensor noise do not count. The band is the larger of BAND_FLOOR and NOISE_BANDS
times the measurement noise, estimated from the error's second differences (a smooth
motion has next to none, white noise of standard deviation s has sqrt(6) s).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from .._median import median

__all__ = [
    "BAND_FLOOR", "NOISE_BANDS", "RINGING_OSCILLATIONS", "JointTracking", "crossings", "merged_tracking",
    "noise_level", "tracking",
]

BAND_FLOOR = 1e-4
"""Smallest hysteresis band [rad] (or [m]): errors inside it are no oscillation."""
NOISE_BANDS = 4.0
"""The band is at least this many standard deviations of the measurement noise."""
RINGING_OSCILLATIONS = 3
"""A joint whose error changes sign this often after its reference stopped is ringing."""


@dataclass(frozen=True)
class JointTracking:
    """How one joint tracked its reference in one step; positions in [rad] (or [m] for prismatic joints).

    Attributes:
        peak_error: Largest |reference - actual| over the step.
        overshoot: Largest excursion past the goal, in the direction of the motion, once the
            reference stopped, less NOISE_BANDS standard deviations of the measurement noise
            (0 for a joint that does not move).
        settling_time_s: Time [s] from the last point until |error| stays within the goal
            tolerance (the band where that tolerance is 0); None if it does not within what
            was observed.
        oscillations: Sign changes of the error beyond +-band once the reference stopped; for a
            step that ended before its last point (aborted in motion), over the whole step.
        final_error: reference - actual at the last observed sample.
        band: The hysteresis band used.
        observed_s: How long [s] after the last point the joint was observed.
        ringing: oscillations >= RINGING_OSCILLATIONS.
    """

    peak_error: float
    overshoot: float
    settling_time_s: float | None
    oscillations: int
    final_error: float
    band: float
    observed_s: float
    ringing: bool


def noise_level(values: npt.ArrayLike) -> NDArray[np.float64]:
    """Return per column the estimated standard deviation of white noise on `values` (K, n).

    From the median absolute deviation of second differences, which smooth motion and the
    few samples around a bump or a corner barely move.
    """
    array = np.asarray(values, dtype=np.float64)
    if array.ndim == 1:
        array = array[:, None]
    if len(array) < 5:
        return np.zeros(array.shape[1])
    second = np.diff(array, n=2, axis=0)
    second = second[np.isfinite(second).all(axis=1)]
    if len(second) < 3:
        return np.zeros(array.shape[1])
    deviation = median(np.abs(second - median(second)))
    # 1.4826 turns a median absolute deviation into a normal standard deviation.
    return np.asarray(1.4826 * deviation / math.sqrt(6.0), dtype=np.float64)


def crossings(values: npt.ArrayLike, band: float) -> NDArray[np.intp]:
    """Return the indices at which the 1-D `values` change sign beyond +-band (hysteresis)."""
    array = np.asarray(values, dtype=np.float64)
    side = np.where(array > band, 1, np.where(array < -band, -1, 0))
    outside = np.flatnonzero(side)
    changed = side[outside[1:]] != side[outside[:-1]]
    indices: NDArray[np.intp] = outside[1:][changed]
    return indices


def tracking(
    joints: Sequence[str],
    times_s: npt.ArrayLike,
    reference: npt.ArrayLike,
    error: npt.ArrayLike,
    last_point_s: float,
    goal_tolerances: npt.ArrayLike,
) -> dict[str, JointTracking]:
    """Return per joint how it tracked its reference over one step's observed samples.

    Args:
        joints: Column names.
        times_s: Sample times from the step's start in [s], (K,), increasing.
        reference: Reference positions (K, n); after the last point, the last point.
        error: reference - actual (K, n), wrapped for continuous joints.
        last_point_s: Time of the step's last point in [s]: the reference stops there.
        goal_tolerances: Per joint goal tolerance [rad]; 0 = not checked.
    """
    times = np.asarray(times_s, dtype=np.float64)
    ref = np.asarray(reference, dtype=np.float64)
    err = np.asarray(error, dtype=np.float64)
    tolerances = np.asarray(goal_tolerances, dtype=np.float64)
    if len(times) == 0:
        return {}
    noise = noise_level(err)
    # The last sample before the stop belongs to the stopped part: at coarse rates it may be the only one.
    after = times >= last_point_s - 1e-9
    observed = float(times[-1] - last_point_s) if after.any() else 0.0
    return {
        joint: _joint(times, ref[:, j], err[:, j], after, last_point_s, float(tolerances[j]),
                      NOISE_BANDS * float(noise[j]), observed)
        for j, joint in enumerate(joints)
    }


def _joint(
    times: NDArray[np.float64], reference: NDArray[np.float64], error: NDArray[np.float64],
    after: NDArray[np.bool_], last_point_s: float, tolerance: float, noise: float, observed: float,
) -> JointTracking:
    """Return one joint's figures; `after` marks the samples after the stop, `noise` is NOISE_BANDS sigma."""
    band = max(BAND_FLOOR, noise)
    finite = np.isfinite(error)
    peak = float(np.max(np.abs(error[finite]))) if finite.any() else math.inf
    post, post_times = error[after], times[after]
    if not finite.all():
        return JointTracking(peak, math.nan, None, 0, float(error[-1]), band, observed, False)
    travel = reference[-1] - reference[0]
    direction = 0.0 if abs(travel) <= band else math.copysign(1.0, travel)
    # Past the goal in the direction of motion (actual - goal = -error once the reference stopped),
    # beyond what measurement noise alone reaches.
    overshoot = max(0.0, float(np.max(-direction * post)) - noise) if len(post) and direction else 0.0
    # An execution aborted in motion never stops: an oscillation growing to the limit shows over the step.
    oscillations = len(crossings(post if len(post) else error, band))
    return JointTracking(
        peak_error=peak,
        overshoot=overshoot,
        settling_time_s=_settling(post, post_times, last_point_s, tolerance if tolerance > 0.0 else band),
        oscillations=oscillations,
        final_error=float(error[-1]),
        band=band,
        observed_s=observed,
        ringing=oscillations >= RINGING_OSCILLATIONS,
    )


def _settling(
    post: NDArray[np.float64], times: NDArray[np.float64], last_point_s: float, tolerance: float
) -> float | None:
    """Return the time [s] after the last point from which |error| stays within `tolerance`."""
    if not len(post):
        return None
    outside = np.flatnonzero(np.abs(post) > tolerance)
    if not len(outside):
        return 0.0
    if outside[-1] == len(post) - 1:
        return None
    return max(0.0, float(times[outside[-1] + 1] - last_point_s))


def merged_tracking(steps: Sequence[dict[str, JointTracking]]) -> dict[str, JointTracking]:
    """Return per joint the worst figures over several steps (the last step's final error)."""
    merged: dict[str, JointTracking] = {}
    for step in steps:
        for joint, now in step.items():
            before = merged.get(joint)
            if before is None:
                merged[joint] = now
                continue
            settling = (None if before.settling_time_s is None or now.settling_time_s is None
                        else max(before.settling_time_s, now.settling_time_s))
            oscillations = max(before.oscillations, now.oscillations)
            merged[joint] = JointTracking(
                peak_error=max(before.peak_error, now.peak_error),
                overshoot=max(before.overshoot, now.overshoot),
                settling_time_s=settling,
                oscillations=oscillations,
                final_error=now.final_error,
                band=max(before.band, now.band),
                observed_s=min(before.observed_s, now.observed_s),
                ringing=before.ringing or now.ringing,
            )
    return merged
