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

from ..errors import PlanningFailed
from ..types import frozen_array

__all__ = ["STILL", "SpeedProfile", "fastest_speeds"]

STILL = 1e-9  # |dq/ds| below this: the joint does not move along the path there


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


# A joint at rest along the path (a derivative of 0), or with a limit so large that its square
# overflows, gives an infinite bound: none.
@np.errstate(divide="ignore", invalid="ignore", over="ignore")
def fastest_speeds(
    grid: NDArray[np.float64],
    first: NDArray[np.float64],
    second: NDArray[np.float64],
    straight: NDArray[np.bool_],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
    min_interval_s: float = 0.0,
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
        min_interval_s: Each interval takes at least this long [s].
    """
    delta = grid[1:] - grid[:-1]
    # x is linear along an interval and dq/ds nearly so, but their product can peak inside
    # (at a reversal, where dq/ds drops to 0 and x soars): x within the velocity limits at both
    # ends and the middle, wherever it is on the interval, keeps the velocity within all along.
    bounds = np.min((max_velocity / first) ** 2, axis=1)  # at the grid points and middles
    ceiling = np.minimum(np.minimum(bounds[:-2:2], bounds[1::2]), bounds[2::2])  # per interval
    if min_interval_s > 0.0:
        ceiling = np.minimum(ceiling, (delta / min_interval_s) ** 2)  # ds/dt at most delta / min_interval_s
    cap = np.minimum(ceiling, np.concatenate((ceiling[:1], ceiling[:-1])))  # x_i: on intervals i - 1 and i
    grow, step, cap = _step_lines(first, second, delta, cap, max_acceleration)
    grows, steps = grow.tolist(), step.tolist()
    x = _forward(_backward(cap.tolist(), grows, steps), grows, steps)
    if not np.all(np.isfinite(x)):
        raise PlanningFailed("time parameterisation found no motion along the path within the limits")
    return _with_switches(grid, x, straight, first[::2], ceiling, max_acceleration)


def _step_lines(
    first: NDArray[np.float64],
    second: NDArray[np.float64],
    delta: NDArray[np.float64],
    cap: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return per interval the lines x_i -> x_{i+1} at the largest u, and `cap` lowered to where u runs out.

    Each joint's limit holds at the start, the middle and the end of the interval:
    |q'' (x_i + 2 o u) + q' u| <= a at offset o reads |u + B x_i| <= A, so at the largest
    u = min(A - B x_i), x_{i+1} = min over the limits of (1 - 2 delta B) x_i + 2 delta A.
    Along a straight interval B = 0: the lines are x_i + 2 delta A, the lowest of them the exact step.
    """
    points = 2 * np.arange(len(delta))[:, None] + np.arange(3)  # the start, middle and end of each interval
    d2 = second[points]
    d1 = first[points] + (delta[:, None] * (0.0, 1.0, 2.0))[:, :, None] * d2  # (N, 3, n)
    size = np.abs(d1)
    reach = max_acceleration / size  # A: the bound on u at x = 0
    slope = d2 / d1  # B: how x shifts the bound on u
    still = size <= STILL
    if still.any():
        # The joint's velocity is 0 there: its acceleration q'' x bounds x alone.
        cap = np.minimum(cap, np.where(still, max_acceleration / np.abs(d2), np.inf).min(axis=(1, 2)))
        reach[still], slope[still] = np.inf, 0.0
    reach, slope = reach.reshape(len(delta), -1), slope.reshape(len(delta), -1)
    two_delta = 2 * delta[:, None]
    return 1.0 - two_delta * slope, two_delta * reach, _acceleration_cap(reach, slope, cap)


def _acceleration_cap(
    reach: NDArray[np.float64], slope: NDArray[np.float64], cap: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Return per interval the largest x <= cap for which some u meets every |u + B x| <= A.

    An upper bound A_k - B_k x on u and a lower one -A_j - B_j x cross where
    (B_k - B_j) x = A_j + A_k: u runs out at 1 / the largest (B_k - B_j) / (A_j + A_k)
    over all pairs (at least 0, from j = k; 1 / 0 = inf: it never does).
    """
    rate = slope[:, None, :] - slope[:, :, None]  # B_k - B_j
    rate /= reach[:, None, :] + reach[:, :, None]
    largest: NDArray[np.float64] = rate.max(axis=(1, 2))
    # The j = k pairs make `largest` at least 0, but a straight interval gives -0.0, and
    # 1 / -0.0 is -inf: compare instead of dividing by the sign.
    never = largest <= 0.0
    return np.minimum(cap, np.where(never, np.inf, 1.0 / np.where(never, 1.0, largest)))


# Python floats in plain loops: each step is a handful of scalar operations, which numpy
# would make ten times slower.

def _backward(cap: list[float], grows: list[list[float]], steps: list[list[float]]) -> list[float]:
    """Return the largest squared speeds K_i from which the motion can still stop at the end."""
    controllable = [0.0] * (len(cap) + 1)
    bound = 0.0
    for i in range(len(cap) - 1, -1, -1):
        best = cap[i]
        for grow, step in zip(grows[i], steps[i], strict=True):
            # Braking at u = -A - B x_i must reach at most K_{i+1}: grow x_i - step <= K_{i+1}
            # (which bounds x_i only where grow > 0).
            if grow > 0.0:
                value = (bound + step) / grow
                if value < best:
                    best = value
        controllable[i] = bound = best
    return controllable


def _forward(controllable: list[float], grows: list[list[float]], steps: list[list[float]]) -> NDArray[np.float64]:
    """Return the squared speeds from rest, each step as fast as the limits and `controllable` allow."""
    count = len(controllable) - 1
    x = [0.0] * (count + 1)
    current = 0.0
    for i in range(count - 1):
        best = controllable[i + 1]
        for grow, step in zip(grows[i], steps[i], strict=True):
            value = grow * current + step
            if value < best:
                best = value
        x[i + 1] = current = max(best, 0.0)
    return np.array(x)


def _with_switches(
    grid: NDArray[np.float64],
    x: NDArray[np.float64],
    straight: NDArray[np.bool_],
    velocity: NDArray[np.float64],
    ceiling: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
) -> SpeedProfile:
    """Return the profile with the exact optimum along each straight interval: ramp up, cruise, ramp down.

    Args:
        grid: Path parameter of the grid points, shape (N + 1,).
        x: Squared path speeds at the grid points, shape (N + 1,).
        straight: Per interval, True where dq/ds is constant, shape (N,).
        velocity: dq/ds at the grid points, shape (N + 1, n).
        ceiling: Per interval, the largest squared path speed, shape (N,).
        max_acceleration: In [rad]/[s]^2, shape (n,).
    """
    i = np.flatnonzero(straight)
    ramps = 2 * np.min(max_acceleration / np.abs(velocity[i]), axis=1)  # dx/ds at full acceleration
    at, squares = grid.tolist(), x.tolist()
    ups, downs, tops = [], [], []
    for k, ramp, cruise in zip(i.tolist(), ramps.tolist(), ceiling[i].tolist(), strict=True):
        start, end, x_start, x_end = at[k], at[k + 1], squares[k], squares[k + 1]
        meet = (x_end - x_start + ramp * (start + end)) / (2 * ramp)  # where the two ramps cross
        peak = x_start + ramp * (meet - start)
        up = down = meet
        if peak > cruise:
            up, down = start + (cruise - x_start) / ramp, end - (cruise - x_end) / ramp
        ups.append(min(max(up, start), end))
        downs.append(min(max(down, start), end))
        tops.append(min(peak, cruise))
    s = np.concatenate((grid, ups, downs))
    squared = np.concatenate((x, tops, tops))
    order = np.argsort(s, kind="stable")
    s, squared = s[order], squared[order]
    # A switch that rounds to a grid point's s adds nothing: keep the grid point, first of equals
    # in the stable sort. Dropping a switch is always safe, as it only spreads a ramp over a longer
    # interval; a grid point carries the speed that the ends and the neighbours were planned with.
    keep = np.concatenate(([True], s[1:] > s[:-1]))
    return SpeedProfile(s[keep], squared[keep])
