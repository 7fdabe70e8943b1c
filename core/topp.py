"""Time-optimal path speeds within joint velocity and acceleration limits, by reachability analysis (TOPP-RA).

Along a path q(s), with x = (ds/dt)^2 and u = d2s/dt2, the joint velocities are
q'(s) sqrt(x) and the accelerations q''(s) x + q'(s) u. On a grid s_0 < ... < s_N,
u is constant on each interval, so x grows linearly: x_{i+1} = x_i + 2 (s_{i+1} - s_i) u_i.
Each acceleration limit then reads |u + B x_i| <= A at a point of the interval,
and the usual two passes (largest controllable speeds backwards from rest at the
end, then the fastest controllable speeds forwards from rest at the start) have
closed forms: each step is a minimum over a few straight lines.

The limits are imposed at both ends and the middle of every interval (TOPP-RA's
"interpolation" discretisation, plus a midpoint), which keeps the accelerations
between grid points within a fraction of a percent of the limits on a smooth path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from moveplan.core.errors import PlanningFailed
from moveplan.core.types import frozen_array

__all__ = ["SpeedProfile", "fastest_speeds"]

_STILL = 1e-9  # |dq/ds| below this: the joint does not move along the path there


@dataclass(frozen=True)
class SpeedProfile:
    """Squared path speeds at grid points; the path acceleration is constant between them.

    Attributes:
        s: Path parameter at the grid points, strictly increasing, shape (N + 1,).
        squared_speeds: (ds/dt)^2 at the grid points, 0 at both ends, shape (N + 1,).
    """

    s: NDArray[np.float64]
    squared_speeds: NDArray[np.float64]

    def __post_init__(self) -> None:
        s = frozen_array(self.s, (None,), "s")
        object.__setattr__(self, "s", s)
        object.__setattr__(self, "squared_speeds", frozen_array(self.squared_speeds, s.shape, "squared_speeds"))


# A joint at rest along the path (a derivative of 0) gives an infinite bound: none.
@np.errstate(divide="ignore", invalid="ignore")
def fastest_speeds(
    grid: NDArray[np.float64],
    first: NDArray[np.float64],
    second: NDArray[np.float64],
    straight: NDArray[np.bool_],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
) -> SpeedProfile:
    """Return the time-optimal rest-to-rest speeds along a path within the joint limits.

    Along a straight interval the limits are constant and the exact optimum (at most a
    ramp up, a cruise and a ramp down) is returned, its switches as extra grid points.

    Args:
        grid: Path parameter of the grid points, strictly increasing, shape (N + 1,).
        first: dq/ds at the grid points and at the middle of each interval, in order
            s_0, middle_0, s_1, ..., s_N, shape (2N + 1, n).
        second: d2q/ds2 at the same points, shape (2N + 1, n).
        straight: Per interval, True where dq/ds is constant and d2q/ds2 zero, shape (N,).
        max_velocity: In [rad]/[s], shape (n,).
        max_acceleration: In [rad]/[s]^2, shape (n,).
    """
    delta = grid[1:] - grid[:-1]
    velocity = first[::2]
    cap = np.min((max_velocity / velocity) ** 2, axis=1)[:-1]
    # Along a straight interval the limits are the same everywhere: |u| <= A = min_j a_j / |q'_j|,
    # one line of gain 1 for both passes: x_{i+1} <= x_i + 2 delta A, x_i <= K_{i+1} + 2 delta A.
    straight_step = np.where(straight, 2 * delta * np.min(max_acceleration / np.abs(velocity[:-1]), axis=1), np.inf)
    curved = np.flatnonzero(~straight)
    back = forward = _Lines(curved, np.zeros(0), np.zeros(0))
    if len(curved):
        grow, step, cap[curved] = _curved_bounds(first, second, delta, curved, cap[curved], max_acceleration)
        # Backwards, braking at u = -A - B x_i must reach at most K_{i+1}: x_i <= (K_{i+1} + 2 delta A) / grow.
        positive = grow > 0.0
        back = _Lines.lowest(curved, np.where(positive, 1.0 / grow, 0.0), np.where(positive, step / grow, np.inf),
                             np.append(cap, 0.0)[curved + 1])
    controllable = _backward(cap.tolist(), straight_step.tolist(), back)
    if len(curved):
        forward = _Lines.lowest(curved, grow, step, np.array(controllable)[curved])
    x = _forward(controllable, straight_step.tolist(), forward)
    if not np.all(np.isfinite(x)):
        raise PlanningFailed("time parameterisation found no motion along the path within the limits")
    return _with_switches(grid, x, straight, velocity, max_velocity, max_acceleration)


def _curved_bounds(
    first: NDArray[np.float64],
    second: NDArray[np.float64],
    delta: NDArray[np.float64],
    rows: NDArray[np.intp],
    cap: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return, for the intervals `rows`, the lines x_i -> x_{i+1} at the largest u, and the caps on x_i.

    Each joint's limit holds at the start, the middle and the end of the interval:
    |q'' (x_i + 2 o u) + q' u| <= a at offset o reads |u + B x_i| <= A, so at the largest
    u = min(A - B x_i), x_{i+1} = min over the limits of (1 - 2 delta B) x_i + 2 delta A.
    """
    offset = delta[rows, None]
    at_start, at_middle, at_end = 2 * rows, 2 * rows + 1, 2 * rows + 2
    middle, end = second[at_middle], second[at_end]
    d1 = np.concatenate((first[at_start], first[at_middle] + offset * middle, first[at_end] + 2 * offset * end), axis=1)
    d2 = np.concatenate((second[at_start], middle, end), axis=1)
    bound = np.tile(max_acceleration, 3)
    reach = bound / np.abs(d1)  # A: the bound on u at x = 0
    slope = d2 / d1  # B: how x shifts the bound on u
    still = np.abs(d1) <= _STILL
    if still.any():
        # The joint's velocity is 0 there: its acceleration q'' x bounds x alone.
        cap = np.minimum(cap, np.min(np.where(still, bound / np.abs(d2), np.inf), axis=1))
        reach[still], slope[still] = np.inf, 0.0
    cap = _acceleration_cap(reach, slope, cap)
    two_delta = 2 * offset
    return 1.0 - two_delta * slope, two_delta * reach, cap


def _acceleration_cap(
    reach: NDArray[np.float64], slope: NDArray[np.float64], cap: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Return per interval the largest x <= cap for which some u meets every |u + B x| <= A.

    An upper bound A_k - B_k x on u and a lower one -A_j - B_j x cross where
    (B_k - B_j) x = A_j + A_k; the smallest such x over all pairs is where u runs out.
    """
    gap = slope[:, None, :] - slope[:, :, None]  # B_k - B_j
    crossing = (reach[:, None, :] + reach[:, :, None]) / gap
    lowest: NDArray[np.float64] = np.min(np.where(gap > 0.0, crossing, np.inf), axis=(1, 2))
    return np.minimum(cap, lowest)


@dataclass(frozen=True)
class _Lines:
    """Per curved interval, the lines gain y + offset whose minimum bounds one pass step, flattened.

    Attributes:
        row: The interval of each line, non-decreasing, shape (L,).
        gain: Shape (L,).
        offset: Shape (L,).
    """

    row: NDArray[np.intp]
    gain: NDArray[np.float64]
    offset: NDArray[np.float64]

    @classmethod
    def lowest(
        cls, rows: NDArray[np.intp], gain: NDArray[np.float64], offset: NDArray[np.float64], end: NDArray[np.float64]
    ) -> _Lines:
        """Return the lines of each row of `gain` and `offset` that can be lowest somewhere on [0, end].

        The lowest at 0 and the lowest at `end` are kept, and any other line below both where
        they cross: a line above the lowest at both ends of an interval stays above it in between.
        """
        index = np.arange(len(gain))
        at_end = gain * end[:, None] + offset
        low_start, low_end = np.argmin(offset, axis=1), np.argmin(at_end, axis=1)
        g0, o0 = gain[index, low_start], offset[index, low_start]
        g1, o1 = gain[index, low_end], offset[index, low_end]
        cross = np.minimum(np.maximum((o1 - o0) / (g0 - g1), 0.0), end)
        cross = np.where(np.isfinite(cross), cross, 0.0)
        tent = np.minimum(g0 * cross + o0, g1 * cross + o1)
        keep = gain * cross[:, None] + offset < tent[:, None]
        keep[index, low_start] = True
        keep[index, low_end] = True
        row, column = np.nonzero(keep)
        return cls(rows[row], gain[row, column], offset[row, column])

    def lists(self, count: int) -> tuple[list[float], list[float], list[int]]:
        """Return gains and offsets as lists, and per row i the index of its first line (row i ends at first[i + 1])."""
        return self.gain.tolist(), self.offset.tolist(), np.searchsorted(self.row, np.arange(count + 1)).tolist()


# Python floats in plain loops: each step is a handful of scalar operations, which numpy
# would make ten times slower.

def _backward(cap: list[float], straight_step: list[float], lines: _Lines) -> list[float]:
    """Return the largest squared speeds K_i from which the motion can still stop at the end."""
    gains, offsets, first = lines.lists(len(cap))
    controllable = [0.0] * (len(cap) + 1)
    bound = 0.0
    for i in range(len(cap) - 1, -1, -1):
        best = min(cap[i], bound + straight_step[i])
        for k in range(first[i], first[i + 1]):
            value = gains[k] * bound + offsets[k]
            if value < best:
                best = value
        controllable[i] = bound = best
    return controllable


def _forward(controllable: list[float], straight_step: list[float], lines: _Lines) -> NDArray[np.float64]:
    """Return the squared speeds from rest, each step as fast as the limits and `controllable` allow."""
    count = len(controllable) - 1
    gains, offsets, first = lines.lists(count)
    x = [0.0] * (count + 1)
    current = 0.0
    for i in range(count - 1):
        best = min(controllable[i + 1], current + straight_step[i])
        for k in range(first[i], first[i + 1]):
            value = gains[k] * current + offsets[k]
            if value < best:
                best = value
        x[i + 1] = current = max(best, 0.0)
    return np.array(x)


def _with_switches(
    grid: NDArray[np.float64],
    x: NDArray[np.float64],
    straight: NDArray[np.bool_],
    velocity: NDArray[np.float64],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
) -> SpeedProfile:
    """Return the profile with the exact optimum along each straight interval: ramp up, cruise, ramp down."""
    i = np.flatnonzero(straight)
    speed = np.abs(velocity[i])
    ramp = 2 * np.min(max_acceleration / speed, axis=1)  # dx/ds at full acceleration
    cruise = np.min((max_velocity / speed) ** 2, axis=1)
    start, end, x_start, x_end = grid[i], grid[i + 1], x[i], x[i + 1]
    meet = (x_end - x_start + ramp * (start + end)) / (2 * ramp)  # where the two ramps cross
    peak = x_start + ramp * (meet - start)
    cruising = peak > cruise
    up = np.minimum(np.maximum(np.where(cruising, start + (cruise - x_start) / ramp, meet), start), end)
    down = np.minimum(np.maximum(np.where(cruising, end - (cruise - x_end) / ramp, meet), start), end)
    top = np.minimum(peak, cruise)
    s = np.concatenate((grid, up, down))
    squared = np.concatenate((x, top, top))
    order = np.argsort(s, kind="stable")
    s, squared = s[order], squared[order]
    # A switch at (or within rounding of) a grid point adds nothing: keep the grid point.
    keep = np.concatenate(([True], np.diff(s) > 1e-12 * grid[-1]))
    keep[-1] = True
    s, squared = s[keep], squared[keep]
    s[-1] = grid[-1]
    return SpeedProfile(s, squared)
