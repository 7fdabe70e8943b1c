"""Time parameterisation of a joint-space path within the velocity and acceleration limits, as interpolated.

The path's corners are rounded (core.blends), the fastest speeds along it come
from TOPP-RA (core.topp), and the result is smoothed so that the controller's
quintics can follow it: the optimum switches between full acceleration and full
braking in an instant, which no quintic between sampled points reproduces.
Averaging the path position over a sliding window turns every switch into a
linear ramp as long as the window (10 ms, or 0.25 % of shorter motions), and adds
that much to the duration. Knots go where the smoothed motion changes form,
so between knots it is almost exactly the quintic the controller draws. The
exact peaks of those quintics are then checked, and where they exceed a limit
(typically by about 0.5 %, at corners, where the ramps meet the curvature, and
where the discretised optimum strays between grid points), the whole trajectory
is slowed by the one factor that brings it within: stretching time by k divides
velocities by k and accelerations by k^2, quintics included.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..errors import PlanningFailed
from ..trajectory import quintic_peak_rates
from ..types import JointTrajectory, frozen_array
from .blends import BlendedPath, blended_path
from .topp import SpeedProfile, fastest_speeds

__all__ = ["rest_to_rest", "time_parameterize"]

logger = logging.getLogger(__name__)

# A cubic spline through a corner's segments resampled one step h apart strays from the corner
# by 0.085 h |d_out - d_in| cos(angle / 2) (less with unequal steps); a blend taking 0.44 h from
# each segment strays by 3/16 0.44 = 0.0825 times the same (benchmarks/timing_speed.py measures).
_CORNER_FRACTION = 0.44
_GRID_PER_BLEND = 8  # intervals per blend; a straight piece is one exact interval
_RAMP_S = 0.01  # [s] every switch of the path acceleration becomes a linear ramp this long,
_RAMP_FRACTION = 0.0025  # or this fraction of the optimal duration if shorter,
_MIN_RAMP_S = 1e-3  # but not shorter than this [s]
_MIN_KNOT_GAP_S = 1e-4  # [s] closer knots make the quintic's coefficients lose precision
_REST_S = 1e9  # [s] the time law's rest before its start and after its end
# Relative slow-down covering the rounding of knot times to whole nanoseconds: moving a knot by
# 0.5 ns changes its acceleration by the jerk times that, < 1e-6 of a limit with ramps >= 1 ms.
_SAFETY = 1e-5


def time_parameterize(
    joint_names: tuple[str, ...],
    waypoints: npt.ArrayLike,
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
    max_step: float = 0.05,
) -> JointTrajectory:
    """Return a near time-optimal trajectory along `waypoints` within the (already scaled) limits.

    The result starts and ends at rest (velocity and acceleration exactly 0), its times
    are whole nanoseconds, and its quintic interpolation stays within the limits. It
    follows the straight segments between waypoints, except where it rounds a corner.

    Args:
        joint_names: Joint order of the columns.
        waypoints: Joint positions, shape (m, n).
        max_velocity: In [rad]/[s], shape (n,).
        max_acceleration: In [rad]/[s]^2, shape (n,).
        max_step: Corners are rounded within 0.44 of a step from their waypoint, the
            segments divided into equal steps of at most max_step [rad] in every joint:
            closer to the polyline than a cubic spline through those steps.
    """
    points = np.asarray(waypoints, dtype=np.float64)
    if not (np.abs(points - points[0]) > 1e-12).any():
        zeros = np.zeros_like(points[:1])
        return JointTrajectory(joint_names, np.zeros(1), points[:1], zeros, zeros)
    path = blended_path(points, max_step, _CORNER_FRACTION)
    grid, straight = _grid(path)
    points_and_middles = np.empty(2 * len(grid) - 1)
    points_and_middles[::2], points_and_middles[1::2] = grid, (grid[:-1] + grid[1:]) / 2
    first, second = path.derivatives(points_and_middles)
    profile = fastest_speeds(grid, first, second, straight, max_velocity, max_acceleration)
    law = _TimeLaw.of(profile)
    times = law.knots()
    positions, v, a = _sampled(path, law, points[[0, -1]], times)
    peak_v, peak_a = quintic_peak_rates(times, positions, v, a)
    excess = max(1.0, float((peak_v / max_velocity).max()), math.sqrt(float((peak_a / max_acceleration).max())))
    if excess > 1.0:
        logger.debug("interpolated trajectory peaks at %.4f of a limit; slowing it by %.4f", excess**2, excess)
    stretch = excess * (1.0 + _SAFETY)
    # Whole nanoseconds, as a message carries them. Each knot moves by less than a nanosecond
    # and its state moves along the motion with it, so the knots stay consistent with each other.
    stretched = np.rint(times * stretch * 1e9) / 1e9
    shift = (stretched / stretch - times)[:, None]
    return JointTrajectory(joint_names, stretched, positions + shift * (v + shift * a / 2),
                           (v + shift * a) / stretch, a / stretch**2)


def _grid(path: BlendedPath) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Return grid points along the path and, per interval, whether it is straight."""
    # Turning by more than ~145 degrees (|turn| > 1.9), a blend's dq/ds comes close to 0 in
    # its middle (at a reversal, 0: a singular point of the time law); a finer grid follows it.
    blend = path.blend
    counts = np.where(blend, np.where(path.turns > 1.9, 2 * _GRID_PER_BLEND, _GRID_PER_BLEND), 1)
    piece = np.repeat(np.arange(len(counts)), counts)
    ends = counts.cumsum()
    within = np.arange(ends[-1]) - (ends - counts)[piece]
    breaks = path.breaks
    starts = breaks[piece] + (breaks[1:] - breaks[:-1])[piece] * within / counts[piece]
    return np.concatenate((starts, breaks[-1:])), ~blend[piece]


@dataclass(frozen=True)
class _TimeLaw:
    """The optimal time law s(t): path acceleration u constant between grid points, at rest before and after.

    The arrays hold the grid points' intervals and, first and last, a rest of 1e9 s
    before the start and after the end, so that any time finds its interval.

    Attributes:
        times: Start of each interval in [s], the grid points' times from index 1, shape (N + 3,).
        s: Path parameter at the start of each interval, shape (N + 3,).
        speeds: ds/dt at the start of each interval, shape (N + 3,).
        accelerations: d2s/dt2 on each interval, shape (N + 3,).
        ramp: The averaging window of the smoothed motion in [s].
    """

    times: NDArray[np.float64]
    s: NDArray[np.float64]
    speeds: NDArray[np.float64]
    accelerations: NDArray[np.float64]
    ramp: float

    def __post_init__(self) -> None:
        times = frozen_array(self.times, (None,), "times")
        object.__setattr__(self, "times", times)
        for name in ("s", "speeds", "accelerations"):
            object.__setattr__(self, name, frozen_array(getattr(self, name), times.shape, name))

    @classmethod
    def of(cls, profile: SpeedProfile) -> _TimeLaw:
        """Return the time law that follows the squared speeds of `profile`."""
        speeds = np.sqrt(profile.squared_speeds)
        steps = profile.s[1:] - profile.s[:-1]
        with np.errstate(divide="ignore"):
            durations = 2 * steps / (speeds[:-1] + speeds[1:])  # constant acceleration: mean speed
        if not np.isfinite(durations).all():
            raise PlanningFailed("time parameterisation found the path blocked: the speed along it drops to 0")
        accelerations = (profile.squared_speeds[1:] - profile.squared_speeds[:-1]) / (2 * steps)
        times = np.concatenate(([-_REST_S, 0.0], durations.cumsum(), [_REST_S]))
        times[-1] += times[-2]
        ramp = min(_RAMP_S, max(_MIN_RAMP_S, _RAMP_FRACTION * float(times[-2])))
        rest = np.zeros(1)
        return cls(times, np.concatenate((rest, profile.s, profile.s[-1:])), np.concatenate((rest, speeds, rest)),
                   np.concatenate((rest, accelerations, rest, rest)), ramp)

    def knots(self) -> NDArray[np.float64]:
        """Return the times in [s] where the smoothed motion changes form (it starts at 0, ends a ramp late)."""
        grid = self.times[1:-1]
        times = np.sort(np.concatenate((grid, grid + self.ramp)))
        keep = np.concatenate(([True], times[1:] - times[:-1] > _MIN_KNOT_GAP_S))  # drops repeats too
        times = times[keep]
        times[-1] = grid[-1] + self.ramp
        return times

    def smoothed(
        self, times: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Return s, ds/dt and d2s/dt2 of the motion averaged over the last ramp, at sorted `times` from 0.

        The average of the position over [t - ramp, t] has as its velocity the mean
        velocity and as its acceleration the mean acceleration over that window.
        """
        count = len(times)
        at = np.concatenate((times, (times[:-1] + times[1:]) / 2))
        at = np.concatenate((at, at - self.ramp))
        interval = np.searchsorted(self.times[1:], at, side="right")  # times[0], -1e9 s, precedes them all
        tau = at - self.times[interval]
        u = self.accelerations[interval]
        speed = self.speeds[interval] + u * tau
        s = self.s[interval] + tau * (speed - 0.5 * u * tau)
        mean_speed = (s[: 2 * count - 1] - s[2 * count - 1 :]) / self.ramp
        acceleration = (speed[:count] - speed[2 * count - 1 : 3 * count - 1]) / self.ramp
        # Integrate the mean speed knot to knot (Simpson's rule, exact: it is quadratic in
        # between), rather than differencing a running integral, which would lose the digits
        # that tell two close knots apart.
        edge, middle = mean_speed[:count], mean_speed[count:]
        steps = (times[1:] - times[:-1]) / 6 * (edge[:-1] + 4 * middle + edge[1:])
        return np.minimum(np.concatenate(([0.0], steps.cumsum())), self.s[-1]), edge, acceleration


def _sampled(
    path: BlendedPath, law: _TimeLaw, ends: NDArray[np.float64], times: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return the positions, velocities and accelerations of the smoothed motion at `times` [s], at rest at `ends`."""
    s, speed, acceleration = law.smoothed(times)
    positions, first, second = path(s)
    velocities = first * speed[:, None]
    accelerations = second * (speed**2)[:, None] + first * acceleration[:, None]
    positions[0], positions[-1] = ends
    velocities[0] = velocities[-1] = accelerations[0] = accelerations[-1] = 0.0
    return positions, velocities, accelerations


def rest_to_rest(
    joint_names: tuple[str, ...],
    waypoints: NDArray[np.float64],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
) -> JointTrajectory:
    """Return a trajectory that stops at every waypoint, each segment timed on its own straight line."""
    segments = [time_parameterize(joint_names, waypoints[k : k + 2], max_velocity, max_acceleration)
                for k in range(len(waypoints) - 1)]
    segments = [s for s in segments if len(s.times_s) > 1] or segments[:1]
    times, rows = [segments[0].times_s], [segments[0]]
    for segment in segments[1:]:
        # Consecutive segments share their joining point; keep it once, at the end of the first.
        times.append(times[-1][-1] + segment.times_s[1:])
        rows.append(segment)
    first = [rows[0].positions, rows[0].velocities, rows[0].accelerations]
    rest = [[r.positions[1:], r.velocities[1:], r.accelerations[1:]] for r in rows[1:]]
    columns = [np.concatenate([first[i], *(r[i] for r in rest)]) for i in range(3)]
    return JointTrajectory(joint_names, np.round(np.concatenate(times) * 1e9) / 1e9, *columns)
