"""Where a plan's goals started in a recording, found from the robot's motion; and its gaps.

Where a goal started is not recorded, so it is found from the motion. Distances are the
largest joint distance, shortest angle for continuous joints, in [rad]:

* Departure: the robot, having been within a zone of the step's first point (ZONE_RAD,
  or twice MoveIt's allowed_start_tolerance if larger), moves beyond twice that radius.
  `first_start` takes the first departure; `cycle_starts` takes every departure at least
  0.9 plan durations after the previous one, each an execution of the plan.
* Alignment: the robot's departure is where it first moves DEPARTURE_THRESHOLD_RAD from
  where it rested before (interpolated between samples); the goal started as long before
  that as the plan takes to move as far from its first point. A constant lag of the robot
  behind its command is therefore not counted as error, just as the send time of a live
  goal is unknown.
* Later steps (`next_start`) are searched from the sample where the previous step was
  decided; a step whose departure is not seen starts at that sample.
* Fallbacks: a recording that never rests near the first point is aligned by its first
  departure from its first sample (MoveIt's start check then fails); one that never
  moves starts at its first sample. A robot already departing at the recording's first
  sample (its rest is not recorded) is aligned by where it leaves the zone instead: the
  goal started as long before that as the plan takes to leave it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, known
from ..trajectory import sample, shortest_angular_distance
from ..types import JointStateSeries, JointTrajectory
from .tolerances import position_error

__all__ = [
    "DEPARTURE_THRESHOLD_RAD",
    "GAP_FACTOR",
    "ZONE_RAD",
    "Samples",
    "StepProfile",
    "cycle_starts",
    "first_start",
    "find_gaps",
    "next_start",
]

DEPARTURE_THRESHOLD_RAD = 1e-3
"""How far [rad] the robot moves from where it rested before it counts as departed."""

ZONE_RAD = 0.02
"""Radius [rad] around a step's first point the robot must rest in before the step counts
as begun (at least twice MoveIt's allowed_start_tolerance, so that a start too far off is
still found, and reported); the robot must then move beyond twice this radius."""

GAP_FACTOR = 5.0
"""A pause between samples longer than this many median sample periods is reported."""

_MAX_GAPS = 1000
# Several cycles of the same plan cannot overlap: the controller follows the plan's timing.
_MIN_CYCLE_FRACTION = 0.9
_LOOKBACK_PAD_S = 0.05
_DISTANCE_BLOCK = 16384


@dataclass(frozen=True)
class StepProfile:
    """A step's trajectory in controller order and how fast it leaves its first point.

    `distance` is max over joints of |p(t) - p(0)| on the grid `times` [s]; the radii of
    the home zone and the departure threshold are scaled down for steps that barely move.
    """

    name: str
    trajectory: JointTrajectory
    times: NDArray[np.float64]
    distance: NDArray[np.float64]
    threshold: float
    zone_in: float
    zone_out: float
    _times_to: dict[float, float] = field(default_factory=dict, compare=False, repr=False)

    @staticmethod
    def build(
        name: str, trajectory: JointTrajectory, continuous: NDArray[np.bool_], zone: float
    ) -> StepProfile:
        """Return the profile of `trajectory` (in controller order), zone radius `zone` [rad]."""
        duration = trajectory.duration_s
        count = int(min(200_000, max(2, math.ceil(duration / 1e-3) + 1)))
        times = np.linspace(0.0, duration, count)
        positions, _, _ = sample(trajectory, times, derivatives=0)
        error = position_error(positions, trajectory.positions[0], continuous)
        distance = np.abs(error).max(axis=1)
        extent = float(distance.max(initial=0.0))
        if extent < 4.0 * DEPARTURE_THRESHOLD_RAD:  # too little motion to be told from noise
            return StepProfile(name, trajectory, times, distance, 0.0, 0.0, 0.0)
        zone_in = min(zone, extent / 4.0)
        zone_out = min(2.0 * zone_in, extent / 2.0)
        threshold = min(DEPARTURE_THRESHOLD_RAD, zone_in / 2.0)
        return StepProfile(name, trajectory, times, distance, threshold, zone_in, zone_out)

    @property
    def moves(self) -> bool:
        """Return True if the step moves far enough for its departure to be seen."""
        return self.zone_out > 0.0

    def time_to(self, distance: float) -> float:
        """Return when the plan is first more than `distance` from its first point, in [s]."""
        if distance not in self._times_to:
            crossing = _crossing(self.times, self.distance, distance, 0)
            self._times_to[distance] = self.trajectory.duration_s if crossing is None else crossing
        return self._times_to[distance]


@dataclass(frozen=True)
class Samples:
    """The recorded samples, read in a controller's joint order.

    Attributes:
        times: Sample times in [s] from the recording's first sample.
        positions: The recording's positions, in its own column order.
        columns: The recording's column of each controller joint.
        continuous: Per controller joint, whether its distances wrap around.
        period_s: The median time between samples in [s] (0 without two distinct times).

    """

    times: NDArray[np.float64]
    positions: NDArray[np.float64]
    columns: NDArray[np.intp]
    continuous: NDArray[np.bool_]
    period_s: float

    @staticmethod
    def build(
        series: JointStateSeries, joints: Sequence[str], continuous_joints: Iterable[str]
    ) -> Samples:
        """Return `series` read in the order of `joints`; InputError if one is missing."""
        missing = [j for j in joints if j not in series.names]
        if missing:
            raise InputError(
                f"{series.source or 'the recording'}: no joint {', '.join(missing)} in the "
                f"recording; joints present: {known(series.names)}")
        columns = np.array([series.names.index(j) for j in joints], dtype=np.intp)
        names = set(continuous_joints)
        continuous = np.array([j in names for j in joints])
        return Samples(series.times_s, series.positions, columns, continuous,
                       _median_period(series.times_s))

    def rows(self, begin: int, end: int) -> NDArray[np.float64]:
        """Return the positions of samples [begin, end) in controller order."""
        return self.positions[begin:end][:, self.columns]

    def spans(self, begins: Sequence[int], ends: Sequence[int]) -> NDArray[np.float64]:
        """Return the positions of samples [begins[i], ends[i]) end to end, in controller order."""
        block = np.concatenate([self.positions[b:e] for b, e in zip(begins, ends, strict=True)])
        if np.array_equal(self.columns, np.arange(self.positions.shape[1])):
            return block
        return block[:, self.columns]

    def distance(self, begin: int, end: int, point: NDArray[np.float64]) -> NDArray[np.float64]:
        """Return per sample in [begin, end) the largest joint distance to `point` in [rad]."""
        result = np.zeros(end - begin)
        # Block by block: a block's columns stay in cache, where the columns of an hour-long
        # recording would be read from memory once per joint.
        with np.errstate(invalid="ignore"):  # a non-finite sample is far from any point
            self._distance(begin, end, point, result)
        return result

    def _distance(
        self, begin: int, end: int, point: NDArray[np.float64], result: NDArray[np.float64]
    ) -> None:
        for at in range(begin, end, _DISTANCE_BLOCK):
            block = self.positions[at : min(at + _DISTANCE_BLOCK, end)]
            out = result[at - begin : at - begin + len(block)]
            for j, column in enumerate(self.columns):
                values = block[:, column]
                if self.continuous[j]:
                    gap = np.abs(shortest_angular_distance(point[j], values))
                else:
                    gap = np.abs(values - point[j])
                np.maximum(out, gap, out=out)


def find_gaps(samples: Samples, warnings: list[str]) -> tuple[tuple[float, float], ...]:
    """Return (start_s, length_s) of pauses longer than GAP_FACTOR median periods.

    Appends a warning naming the longest to `warnings` when there are any.
    """
    times, period = samples.times, samples.period_s
    if period <= 0.0:
        return ()
    steps = np.diff(times)
    found = np.flatnonzero(steps > GAP_FACTOR * period)
    if len(found):
        longest = int(found[np.argmax(steps[found])])
        warnings.append(
            f"{len(found)} gap(s) in the recording longer than {GAP_FACTOR:g} median sample "
            f"periods ({period * 1e3:.3g} ms), the longest {steps[longest]:.3f} s at "
            f"{times[longest]:.3f} s: the tolerances are not checked inside them")
    return tuple((float(times[i]), float(steps[i])) for i in found[:_MAX_GAPS])


def first_start(samples: Samples, profile: StepProfile) -> tuple[float, str]:
    """Return the first execution's start [s] and how it was found.

    How: "departure", "first departure" (never rested near the first point) or
    "first sample" (never moved, or the step does not move).
    """
    count = len(samples.times)
    if not profile.moves:
        return float(samples.times[0]), "first sample"
    home = profile.trajectory.positions[0]
    distance = samples.distance(0, count, home)
    exits, dwell = _exits(distance, profile.zone_in, profile.zone_out, inside_at_first=False)
    if len(exits):
        return _departure_start(samples, profile, int(exits[0]), int(dwell[0])), "departure"
    # Never rested near the first point (the start check will say so), or never left it.
    rest = samples.rows(0, 1)[0]
    moved = samples.distance(0, count, rest)
    departure = _crossing(samples.times, moved, profile.threshold, 0)
    if departure is None:
        return float(samples.times[0]), "first sample"
    return departure - profile.time_to(profile.threshold), "first departure"


def cycle_starts(samples: Samples, profiles: Sequence[StepProfile]) -> list[float]:
    """Return the start [s] of every execution of the plan: each departure from its first point.

    Raises:
        InputError: The first step does not move, or the robot never rests near its
            first point and leaves it.

    """
    profile = profiles[0]
    times, count = samples.times, len(samples.times)
    if not profile.moves:
        raise InputError("the plan's first step does not move: executions cannot be told apart")
    home = profile.trajectory.positions[0]
    distance = samples.distance(0, count, home)
    exits, dwell = _exits(distance, profile.zone_in, profile.zone_out, inside_at_first=False)
    if len(exits) == 0:
        closest = int(np.argmin(distance))
        raise InputError(
            f"no execution of the plan found: the robot never rests within {profile.zone_in:g} "
            f"rad of the plan's first point and then leaves it (closest approach "
            f"{distance[closest]:.4g} rad at {times[closest]:.3f} s)")
    cycle_s = sum(p.trajectory.duration_s for p in profiles)
    starts: list[float] = []
    accepted_exit = -math.inf
    for exit_index, lower in zip(exits.tolist(), dwell.tolist(), strict=True):
        if times[exit_index] - accepted_exit < _MIN_CYCLE_FRACTION * cycle_s:
            continue
        accepted_exit = float(times[exit_index])
        starts.append(_departure_start(samples, profile, exit_index, lower))
    return starts


def next_start(
    samples: Samples, profile: StepProfile, after: int, end: int
) -> tuple[float, str]:
    """Return a later step's start: its departure after sample `after`, else that sample's time.

    Samples at indices >= `end` are not searched. How: "departure" or "previous step".
    """
    after = max(after, 0)
    fallback = float(samples.times[min(after, len(samples.times) - 1)])
    if not profile.moves or after >= end - 1:
        return fallback, "previous step"
    # Searched in growing windows: the robot usually departs soon. Without an exit in a
    # window the robot is still inside at its end, so the next window starts inside.
    times, begin = samples.times, after
    window = profile.time_to(profile.zone_out + profile.zone_in) + 1.0
    while begin < end:
        stop = min(end, int(np.searchsorted(times, times[begin] + window, side="right")) + 1)
        distance = samples.distance(begin, stop, profile.trajectory.positions[0])
        exits, _ = _exits(distance, profile.zone_in, profile.zone_out, inside_at_first=True)
        if len(exits):
            return _departure_start(samples, profile, begin + int(exits[0]), after), "departure"
        begin, window = stop, 4.0 * window
    return fallback, "previous step"


def _median_period(times: NDArray[np.float64]) -> float:
    """Return the median time between samples in [s], over up to 100 000 spread intervals."""
    every = max(1, len(times) // 100_000)
    steps = times[every::every] - times[every - 1 : -1 : every]
    steps = np.sort(steps[steps > 0.0])
    if len(steps) == 0:
        return 0.0
    # np.median's rule: np.median itself imports numpy.ma, 40 ms of every command's start-up.
    middle = len(steps) // 2
    return float(steps[middle] if len(steps) % 2 else (steps[middle - 1] + steps[middle]) / 2)


def _crossing(
    times: NDArray[np.float64], values: NDArray[np.float64], level: float, begin: int
) -> float | None:
    """Return when `values` first rises above `level` at or after index `begin`, interpolated."""
    above = np.flatnonzero(values[begin:] > level)
    if len(above) == 0:
        return None
    k = begin + int(above[0])
    if k == 0:
        return float(times[0])
    v0, v1 = float(values[k - 1]), float(values[k])
    fraction = (level - v0) / (v1 - v0) if v1 > v0 else 1.0
    return float(times[k - 1] + min(max(fraction, 0.0), 1.0) * (times[k] - times[k - 1]))


def _exits(
    distance: NDArray[np.float64], zone_in: float, zone_out: float, inside_at_first: bool
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Return sample indices where the robot leaves the zone, and where it last entered it.

    Hysteresis: inside is within `zone_in`, outside beyond `zone_out`; in between the
    previous state holds, so noise at the boundary does not count as many departures.
    """
    event = np.zeros(len(distance), dtype=np.int8)
    event[distance <= zone_in] = 1
    event[distance > zone_out] = -1
    # The state changes only where a run of samples inside (1) or outside (-1) begins:
    # each such run is compared with the one before it, not each sample (an hour-long
    # recording holds millions of samples and a few thousand runs).
    runs = np.flatnonzero(event[1:] != event[:-1]) + 1
    if len(event):
        runs = np.concatenate(([0], runs))
    changes = runs[event[runs] != 0]
    now = event[changes]
    before = np.concatenate(([1 if inside_at_first else 0], now[:-1]))
    exits = changes[(now == -1) & (before == 1)]
    entries = changes[(now == 1) & (before != 1)]
    dwell = np.zeros(len(exits), dtype=np.intp)
    if len(entries):
        found = np.searchsorted(entries, exits, side="right") - 1
        dwell = np.where(found >= 0, entries[np.maximum(found, 0)], 0)
    return exits, dwell


def _departure_start(samples: Samples, profile: StepProfile, exit_index: int, lower: int) -> float:
    """Return the goal's start [s] for a departure that leaves the zone at `exit_index`.

    The robot rested before it: the sample taken as rest is far enough before the exit
    for the plan to have been still, and not before `lower`.
    """
    times = samples.times
    lookback = profile.time_to(profile.zone_out + profile.zone_in) + _LOOKBACK_PAD_S
    lookback += 3.0 * samples.period_s
    rest = int(np.searchsorted(times, times[exit_index] - lookback, side="left"))
    rest = min(max(rest, lower), exit_index)
    moved = samples.distance(rest, exit_index + 1, samples.rows(rest, rest + 1)[0])
    departure = _crossing(times[rest : exit_index + 1], moved, profile.threshold, 0)
    if departure is None:
        departure = float(times[exit_index])
    start = departure - profile.time_to(profile.threshold)
    if rest == 0 and start < times[0]:
        # Moving already at the first sample, which is then no rest to measure from.
        home = profile.trajectory.positions[0]
        away = samples.distance(0, exit_index + 1, home)
        leaves = _crossing(times[: exit_index + 1], away, profile.zone_out, 0)
        if leaves is not None:
            start = min(start, leaves - profile.time_to(profile.zone_out))
    return start
