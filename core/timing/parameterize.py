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
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ..errors import PlanningFailed
from ..trajectory import quintic_peak_rates
from ..types import JointTrajectory, frozen_array
from ._blends import BlendedPath, blended_path, distinct_waypoints
from ._topp import SpeedProfile, fastest_speeds

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
_MIN_KNOT_GAP_S = 1e-4  # [s] closer knots make the quintic's coefficients lose precision (see _knot_gap)
_EPS = float(np.finfo(np.float64).eps)
_HUGE = 1e100  # [rad]/[s] or [rad]/[s]^2: larger limits count as this
_LONGEST_S = 2.0**53 / 1e9  # [s] (104 days) float64 seconds hold whole nanoseconds up to this
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
    compiled: bool = False,
) -> JointTrajectory:
    """Return a near time-optimal trajectory along `waypoints` within the (already scaled) limits.

    The result starts and ends at rest (velocity and acceleration exactly 0), its times
    are whole nanoseconds, and its quintic interpolation stays within the limits. It
    follows the straight segments between waypoints, except where it rounds a corner.

    Args:
        joint_names: Joint order of the columns.
        waypoints: Joint positions, shape (m, n), m >= 1; repeats are dropped (core.blends).
        max_velocity: In [rad]/[s], shape (n,).
        max_acceleration: In [rad]/[s]^2, shape (n,).
        max_step: Corners are rounded within 0.44 of a step from their waypoint, the
            segments divided into equal steps of at most max_step [rad] in every joint:
            closer to the polyline than a cubic spline through those steps.
        compiled: Use the compiled twins of the speed and peak computations (core/timing/_twins.py):
            the same trajectory to the bit, in less time where they are loaded already.

    Raises:
        PlanningFailed: If a shape is wrong, a waypoint is not finite, a limit or max_step is
            not positive and finite, or the motion would last longer than 2^53 ns (104 days,
            beyond which float64 seconds skip nanoseconds); never for other paths and limits.
    """
    points, max_velocity, max_acceleration = _checked(joint_names, waypoints, max_velocity, max_acceleration,
                                                      max_step)
    distinct = distinct_waypoints(points)
    if len(distinct) == 1:
        return _nudge(joint_names, points[0], points[-1], max_velocity, max_acceleration)
    path = blended_path(distinct, max_step, _CORNER_FRACTION)
    if compiled:
        from . import _twins as twins  # compiled: loaded already with the sphere filter's kernels

        speeds, peaks = twins.compiled_fastest_speeds, twins.compiled_quintic_peak_rates
    else:
        speeds, peaks = fastest_speeds, quintic_peak_rates
    profile, law = _optimal_law(path, points, max_velocity, max_acceleration, speeds)
    changes = law.changes()
    _check_duration(float(changes[-1]), "at least")
    # |dq/ds| <= 1: no joint moves faster than the top path speed.
    top_speeds = np.minimum(max_velocity, math.sqrt(profile.squared_speeds.max()))
    gap = _knot_gap(np.abs(points).max(axis=0), top_speeds, max_velocity, max_acceleration, float(changes[-1]))
    every, knots = _knots(changes, gap)
    times = every[knots]
    s, speed, acceleration = law.smoothed(every)
    positions, v, a = _sampled(path, s[knots], speed[knots], acceleration[knots], points[[0, -1]])
    return _within_limits(joint_names, times, positions, v, a, max_velocity, max_acceleration, peaks)


def _optimal_law(
    path: BlendedPath, points: NDArray[np.float64], max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64], speeds: Callable[..., SpeedProfile],
) -> tuple[SpeedProfile, _TimeLaw]:
    """Return the time-optimal speeds along `path` and the time law that follows them."""
    grid, straight = _grid(path)
    points_and_middles = np.empty(2 * len(grid) - 1)
    points_and_middles[::2], points_and_middles[1::2] = grid, (grid[:-1] + grid[1:]) / 2
    first, second = path.derivatives(points_and_middles)
    try:
        # A grid interval crossed in less than a knot gap would go without a knot of its own.
        profile = speeds(grid, first, second, straight, max_velocity, max_acceleration, _MIN_KNOT_GAP_S)
        return profile, _TimeLaw.of(profile)
    except PlanningFailed:
        # Limits so small that the squared path speeds underflow make the path look blocked.
        span = points.max(axis=0) - points.min(axis=0)
        # A joint crosses its span at most at its top speed, from rest at most at its top acceleration.
        _check_duration(max(float((span / max_velocity).max()), math.sqrt(float((span / max_acceleration).max()))),
                        "at least")
        raise


def _within_limits(
    joint_names: tuple[str, ...], times: NDArray[np.float64], positions: NDArray[np.float64],
    v: NDArray[np.float64], a: NDArray[np.float64], max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64], peaks: Callable[..., tuple[NDArray[np.float64], NDArray[np.float64]]],
) -> JointTrajectory:
    """Return the knots slowed by the one factor that brings their quintics within the limits, in whole ns."""
    peak_v, peak_a = peaks(times, positions, v, a)
    excess = max(1.0, float((peak_v / max_velocity).max()), math.sqrt(float((peak_a / max_acceleration).max())))
    if excess > 1.0:
        logger.debug("interpolated trajectory peaks at %.4f of a limit; slowing it by %.4f", excess**2, excess)
    stretch = excess * (1.0 + _SAFETY)
    # Whole nanoseconds, as a message carries them. Each knot moves by less than a nanosecond
    # and its state moves along the motion with it, so the knots stay consistent with each other.
    stretched = np.rint(times * stretch * 1e9) / 1e9
    _check_duration(float(stretched[-1]), "")
    shift = (stretched / stretch - times)[:, None]
    return JointTrajectory(joint_names, stretched, positions + shift * (v + shift * a / 2),
                           (v + shift * a) / stretch, a / stretch**2)


def _checked(
    joint_names: tuple[str, ...],
    waypoints: npt.ArrayLike,
    max_velocity: npt.ArrayLike,
    max_acceleration: npt.ArrayLike,
    max_step: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return the waypoints and the velocity and acceleration limits as arrays, checked for what timing needs."""
    n = len(joint_names)
    points = np.asarray(waypoints, dtype=np.float64)
    velocity, acceleration = np.asarray(max_velocity, np.float64), np.asarray(max_acceleration, np.float64)
    if points.ndim != 2 or points.shape[0] == 0 or points.shape[1] != n or n == 0:
        raise PlanningFailed(f"time parameterisation needs waypoints of shape (m >= 1, {n}) for the joints "
                             f"{', '.join(joint_names)}; got shape {points.shape}")
    if not np.isfinite(points).all():
        i, j = np.argwhere(~np.isfinite(points))[0]
        raise PlanningFailed(f"waypoint {i} has a non-finite position for joint '{joint_names[j]}': {points[i, j]}")
    for name, limit, unit in (("max_velocity", velocity, "[rad]/[s]"),
                              ("max_acceleration", acceleration, "[rad]/[s]^2")):
        if limit.shape != (n,):
            raise PlanningFailed(f"{name} has shape {limit.shape}; expected ({n},), one per joint")
        for joint, value in zip(joint_names, limit.tolist(), strict=True):
            if not 0.0 < value < math.inf:  # NaN fails too
                raise PlanningFailed(f"{name} of joint '{joint}' is {value}; "
                                     f"expected a positive finite number in {unit}")
    if not (math.isfinite(max_step) and max_step > 0.0):
        raise PlanningFailed(f"max_step is {max_step}; expected a positive finite number in [rad]")
    # Squares of larger limits overflow; a motion within these is within the given ones.
    return points, np.minimum(velocity, _HUGE), np.minimum(acceleration, _HUGE)


def _check_duration(duration: float, qualifier: str) -> None:
    """Raise PlanningFailed if a motion of `duration` [s] is too long for times in whole nanoseconds."""
    if duration > _LONGEST_S:
        raise PlanningFailed(f"the motion would last {qualifier + ' ' if qualifier else ''}{duration:.3g} s at these "
                             f"limits, longer than the {_LONGEST_S:.3g} s (104 days) whose times a float64 "
                             "holds in whole nanoseconds")


def _nudge(
    joint_names: tuple[str, ...],
    start: NDArray[np.float64],
    end: NDArray[np.float64],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
) -> JointTrajectory:
    """Return the trajectory from `start` to `end`, at most 1e-12 rad apart: one quintic, or one point if equal."""
    distance = np.abs(end - start)
    if not distance.any():
        zeros = np.zeros((1, len(start)))
        return JointTrajectory(joint_names, np.zeros(1), start[None], zeros, zeros)
    # A quintic from rest to rest over T peaks at 1.875 d / T in velocity and 5.774 d / T^2 in acceleration.
    duration = max(float(np.max(1.875 * distance / max_velocity)),
                   math.sqrt(float(np.max(5.774 * distance / max_acceleration))))
    duration = math.ceil(duration * (1.0 + _SAFETY) * 1e9) / 1e9
    zeros = np.zeros((2, len(start)))
    return JointTrajectory(joint_names, np.array([0.0, duration]), np.stack((start, end)), zeros, zeros)


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

    def changes(self) -> NDArray[np.float64]:
        """Return the sorted times in [s] where the smoothed motion changes form, from 0 to the end a ramp late.

        Equal times (a change within rounding of another) are kept: each is a change.
        """
        grid = self.times[1:-1]
        return np.sort(np.concatenate((grid, grid + self.ramp)))

    def smoothed(
        self, times: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Return s, ds/dt and d2s/dt2 of the motion averaged over the last ramp, at `changes()` or a superset.

        The average of the position over [t - ramp, t] has as its velocity the mean
        velocity and as its acceleration the mean acceleration over that window.
        """
        count = len(times)
        at = np.concatenate((times, (times[:-1] + times[1:]) / 2))
        both = np.concatenate((at, at - self.ramp))
        interval = np.searchsorted(self.times[1:], both, side="right")  # times[0], -1e9 s, precedes them all
        # Of the closed window [t - ramp, t], t is the end of an interval it falls on the start of.
        now, before = slice(0, len(at)), slice(len(at), None)
        interval[now] -= self.times[interval[now]] == at
        tau = both - self.times[interval]
        u = self.accelerations[interval]
        speed = self.speeds[interval] + u * tau
        s = self.s[interval] + tau * (speed - 0.5 * u * tau)
        # A window within one interval has the mean speed of its middle and the interval's u:
        # differencing s there would lose digits, which a long step of a long motion multiplies.
        within = interval[now] == interval[before]
        mean_speed = np.where(within, speed[now] - u[now] * (self.ramp / 2), (s[now] - s[before]) / self.ramp)
        acceleration = np.where(within, u[now], (speed[now] - speed[before]) / self.ramp)[:count]
        # Integrate the mean speed from change to change (Simpson's rule, exact: it is quadratic
        # in between, but not across a change), rather than differencing a running integral,
        # which would lose the digits that tell two close times apart.
        edge, middle = mean_speed[:count], mean_speed[count:]
        steps = (times[1:] - times[:-1]) / 6 * (edge[:-1] + 4 * middle + edge[1:])
        return np.minimum(np.concatenate(([0.0], steps.cumsum())), self.s[-1]), edge, acceleration


def _knot_gap(
    sizes: NDArray[np.float64],
    speeds: NDArray[np.float64],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
    duration: float,
) -> float:
    """Return the least time [s] between knots at which rounding keeps within half the safety margin.

    Args:
        sizes: The joints' largest |position| [rad], shape (n,).
        speeds: The joints' top speeds in [rad]/[s], shape (n,).
        max_velocity: In [rad]/[s], shape (n,).
        max_acceleration: In [rad]/[s]^2, shape (n,).
        duration: Of the motion, in [s].
    """
    # Rounding the positions and the times (to floats, after the check of the peaks) moves a
    # knot's displacement from the one before by up to eps (|q| + speed t) [rad]; a quintic over
    # h turns an error e in its displacement into a velocity of 1.875 e / h and an acceleration
    # of 5.774 e / h^2 at most.
    error = (sizes + speeds * duration) * (_EPS / (_SAFETY / 2))  # over the budget
    return max(_MIN_KNOT_GAP_S, 1.875 * float((error / max_velocity).max()),
               math.sqrt(5.774 * float((error / max_acceleration).max())))


def _knots(changes: NDArray[np.float64], gap: float) -> tuple[NDArray[np.float64], slice | NDArray[np.intp]]:
    """Return `changes` [s] with stand-ins, sorted, and which of them are knots, at least `gap` [s] apart.

    A quintic between two knots follows the motion closely only if the motion changes
    form near one of its ends at most: a change left out, within the gap after a knot,
    gets a stand-in knot the gap after that knot (one before the end, if it precedes the end).
    """
    if (changes[1:] - changes[:-1] >= gap).all():
        return changes, slice(None)
    knots, stand_ins, skipped = [0.0], [], False
    for t in changes[1:].tolist():
        if t - knots[-1] < gap:
            skipped = True
            continue
        if skipped and t - knots[-1] >= 2 * gap:
            stand_ins.append(knots[-1] + gap)
            knots.append(stand_ins[-1])
        knots.append(t)
        skipped = False
    end = float(changes[-1])
    if skipped:
        # The end takes the place of the last knot, which lies within the gap before it.
        if len(knots) > 1:
            knots.pop()
        if end - knots[-1] >= 2 * gap:
            stand_ins.append(end - gap)
            knots.append(end - gap)
        knots.append(end)
    every = np.sort(np.concatenate((changes, stand_ins)))
    return every, np.searchsorted(every, knots)


def _sampled(
    path: BlendedPath,
    s: NDArray[np.float64],
    speed: NDArray[np.float64],
    acceleration: NDArray[np.float64],
    ends: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return the positions, velocities and accelerations of the motion s(t) along `path`, at rest at `ends`."""
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
