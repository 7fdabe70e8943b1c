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

Scans over the whole recording (departures, gaps) read it block by block through
core.control.check.samples, carrying the zone state from block to block: the result is
the same for any cut into blocks, and a recording of a shift is never held whole.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ...errors import InputError
from ...trajectory import sample
from ...types import JointTrajectory
from ..tolerances import position_error
from .samples import SCAN_ROWS, Samples

__all__ = [
    "DEPARTURE_THRESHOLD_RAD",
    "GAP_FACTOR",
    "PROFILE_SAMPLES",
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

PROFILE_SAMPLES = 200_000
"""The most points a step's profile has (a step over 200 s is profiled more coarsely than every 1 ms)."""

_MAX_GAPS = 1000
# Several cycles of the same plan cannot overlap: the controller follows the plan's timing.
_MIN_CYCLE_FRACTION = 0.9
_LOOKBACK_PAD_S = 0.05


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
        name: str, trajectory: JointTrajectory, continuous: NDArray[np.bool_], zone: float,
        resolution_s: float = 1e-3,
    ) -> StepProfile:
        """Return the profile of `trajectory` (in controller order), zone radius `zone` [rad], on a `resolution_s` grid.

        The grid has at most PROFILE_SAMPLES points: a step of a day is not sampled every millisecond.
        """
        duration = trajectory.duration_s
        count = int(min(PROFILE_SAMPLES, max(2, math.ceil(duration / resolution_s) + 1)))
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



def find_gaps(samples: Samples, warnings: list[str]) -> tuple[tuple[float, float], ...]:
    """Return (start_s, length_s) of the first pauses longer than GAP_FACTOR median periods.

    Appends a warning naming the longest to `warnings` when there are any.
    """
    period = samples.period_s
    if period <= 0.0:
        return ()
    found = 0
    longest = (-math.inf, 0.0)  # (length, start) of the first longest
    gaps: list[tuple[float, float]] = []
    previous = np.zeros(0)
    for _, times in samples.time_blocks():
        joined = np.concatenate((previous, times))
        steps = np.diff(joined)
        where = np.flatnonzero(steps > GAP_FACTOR * period)
        if len(where):
            found += len(where)
            worst = int(where[np.argmax(steps[where])])
            if steps[worst] > longest[0]:
                longest = (float(steps[worst]), float(joined[worst]))
            gaps += [(float(joined[i]), float(steps[i])) for i in where[: _MAX_GAPS - len(gaps)]]
        previous = times[-1:]
    if found:
        warnings.append(
            f"{found} gap(s) in the recording longer than {GAP_FACTOR:g} median sample "
            f"periods ({period * 1e3:.3g} ms), the longest {longest[0]:.3f} s at "
            f"{longest[1]:.3f} s: the tolerances are not checked inside them")
    return tuple(gaps)


def first_start(samples: Samples, profile: StepProfile) -> tuple[float, str]:
    """Return the first execution's start [s] and how it was found.

    How: "departure", "first departure" (never rested near the first point) or
    "first sample" (never moved, or the step does not move).
    """
    if not profile.moves:
        return samples.first_time, "first sample"
    zone = _Zone(profile.zone_in, profile.zone_out, inside_at_first=False)
    for at, distance in samples.distances(0, samples.count, profile.trajectory.positions[0]):
        if len(zone.feed(at, distance)):
            break
    if zone.exits:
        exits, dwell = zone.result()
        return _departure_start(samples, profile, int(exits[0]), int(dwell[0])), "departure"
    # Never rested near the first point (the start check will say so), or never left it.
    departure = _first_crossing(samples, samples.rows(0, 1)[0], profile.threshold)
    if departure is None:
        return samples.first_time, "first sample"
    return departure - profile.time_to(profile.threshold), "first departure"


def cycle_starts(samples: Samples, profiles: Sequence[StepProfile]) -> list[float]:
    """Return the start [s] of every execution of the plan: each departure from its first point.

    Raises:
        InputError: The first step does not move, or the robot never rests near its
            first point and leaves it.

    """
    profile = profiles[0]
    if not profile.moves:
        raise InputError("the plan's first step does not move: executions cannot be told apart")
    zone = _Zone(profile.zone_in, profile.zone_out, inside_at_first=False)
    closest = (math.inf, 0)  # (distance, index): np.argmin's choice, the first NaN if any
    for at, distance in samples.distances(0, samples.count, profile.trajectory.positions[0]):
        zone.feed(at, distance)
        nearest = int(np.argmin(distance))
        value = float(distance[nearest])
        if not math.isnan(closest[0]) and (math.isnan(value) or value < closest[0]):
            closest = (value, at + nearest)
    if not zone.exits:
        raise InputError(
            f"no execution of the plan found: the robot never rests within {profile.zone_in:g} "
            f"rad of the plan's first point and then leaves it (closest approach "
            f"{closest[0]:.4g} rad at {samples.time(closest[1]):.3f} s)")
    cycle_s = sum(p.trajectory.duration_s for p in profiles)
    starts: list[float] = []
    accepted_exit = -math.inf
    exits, dwell = zone.result()
    for exit_index, lower in zip(exits.tolist(), dwell.tolist(), strict=True):
        exit_time = samples.time(exit_index)
        if exit_time - accepted_exit < _MIN_CYCLE_FRACTION * cycle_s:
            continue
        accepted_exit = exit_time
        starts.append(_departure_start(samples, profile, exit_index, lower))
    return starts


def next_start(
    samples: Samples, profile: StepProfile, after: int, end: int
) -> tuple[float, str]:
    """Return a later step's start: its departure after sample `after`, else that sample's time.

    Samples at indices >= `end` are not searched. How: "departure" or "previous step".
    """
    after = max(after, 0)
    fallback = samples.time(min(after, samples.count - 1))
    if not profile.moves or after >= end - 1:
        return fallback, "previous step"
    # Searched in growing windows: the robot usually departs soon. Without an exit in a
    # window the robot is still inside at its end, so the next window starts inside.
    begin = after
    window = profile.time_to(profile.zone_out + profile.zone_in) + 1.0
    while begin < end:
        stop = min(end, samples.search(samples.time(begin) + window, side="right") + 1,
                   begin + SCAN_ROWS)
        distance = samples.distance(begin, stop, profile.trajectory.positions[0])
        zone = _Zone(profile.zone_in, profile.zone_out, inside_at_first=True)
        exits = zone.feed(begin, distance)
        if len(exits):
            return _departure_start(samples, profile, int(exits[0]), after), "departure"
        begin, window = stop, 4.0 * window
    return fallback, "previous step"


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


def _first_crossing(samples: Samples, point: NDArray[np.float64], level: float) -> float | None:
    """Return `_crossing` of the distances of every sample to `point`, scanned block by block."""
    for at, distance in samples.distances(0, samples.count, point):
        above = np.flatnonzero(distance > level)
        if len(above):
            k = at + int(above[0])
            if k == 0:
                return samples.first_time
            return _crossing(samples.times(k - 1, k + 1), samples.distance(k - 1, k + 1, point),
                             level, 0)
    return None


@dataclass
class _Zone:
    """Where the robot leaves and enters a zone, found block by block of its distances to it.

    Hysteresis: inside is within `zone_in`, outside beyond `zone_out`; in between the
    previous state holds, so noise at the boundary does not count as many departures.
    """

    zone_in: float
    zone_out: float
    inside_at_first: bool
    exits: list[int] = field(default_factory=list)
    entries: list[int] = field(default_factory=list)
    _state: int = 0
    _last: int | None = None

    def __post_init__(self) -> None:
        self._state = 1 if self.inside_at_first else 0

    def feed(self, at: int, distance: NDArray[np.float64]) -> NDArray[np.intp]:
        """Take the distances of samples from index `at` on; return the exits found among them."""
        if len(distance) == 0:
            return np.zeros(0, dtype=np.intp)
        event = np.zeros(len(distance), dtype=np.int8)
        event[distance <= self.zone_in] = 1
        event[distance > self.zone_out] = -1
        # The state changes only where a run of samples inside (1) or outside (-1) begins:
        # each such run is compared with the one before it, not each sample (an hour-long
        # recording holds millions of samples and a few thousand runs).
        runs = np.flatnonzero(event[1:] != event[:-1]) + 1
        if self._last is None or event[0] != self._last:
            runs = np.concatenate(([0], runs))
        self._last = int(event[-1])
        changes = runs[event[runs] != 0]
        now = event[changes]
        before = np.concatenate(([self._state], now[:-1]))
        exits = at + changes[(now == -1) & (before == 1)]
        self.exits += exits.tolist()
        self.entries += (at + changes[(now == 1) & (before != 1)]).tolist()
        if len(now):
            self._state = int(now[-1])
        return cast(NDArray[np.intp], exits)

    def result(self) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """Return the exits, and for each where the robot last entered the zone before it (0 if never)."""
        exits = np.array(self.exits, dtype=np.intp)
        entries = np.array(self.entries, dtype=np.intp)
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
    lookback = profile.time_to(profile.zone_out + profile.zone_in) + _LOOKBACK_PAD_S
    lookback += 3.0 * samples.period_s
    exit_time = samples.time(exit_index)
    rest = samples.search(exit_time - lookback, side="left")
    rest = min(max(rest, lower), exit_index)
    moved = samples.distance(rest, exit_index + 1, samples.rows(rest, rest + 1)[0])
    departure = _crossing(samples.times(rest, exit_index + 1), moved, profile.threshold, 0)
    if departure is None:
        departure = exit_time
    start = departure - profile.time_to(profile.threshold)
    if rest == 0 and start < samples.first_time:
        # Moving already at the first sample, which is then no rest to measure from.
        home = profile.trajectory.positions[0]
        away = samples.distance(0, exit_index + 1, home)
        leaves = _crossing(samples.times(0, exit_index + 1), away, profile.zone_out, 0)
        if leaves is not None:
            start = min(start, leaves - profile.time_to(profile.zone_out))
    return start
