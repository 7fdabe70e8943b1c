"""Compiled twins (numba) of core/timing/_topp.py `fastest_speeds` and core/trajectory.py `quintic_peak_rates`.

numpy's versions spend a sixth of a median MotionBenchMaker plan step in array calls on a few
hundred numbers and in plain Python loops. These repeat each of their floating-point operations
in the same order (numba, like numpy, contracts nothing into fused multiply-adds), so a plan is
byte for byte the same whichever runs; tests/timing/test_timing_properties.py holds them together.
Compiled ahead of time into an extension module, or run by numba's JIT where that cannot be built
(core/timing/_twins.py): imported only then.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from .. import trajectory
from ._topp import STILL

# numba caches a kernel by this file's bytes alone; the line below changes them with the sources its
# kernels compile in (tests/foundation/test_kernel_inputs.py says what it must read).
# Compiled in (sha256): trajectory.py 3f2cffe29b89, timing/_topp.py bd237749bcf1

__all__ = ["KERNELS"]


# The Newton search is plain Python on floats: numba compiles the very function numpy's version calls.
_velocity_extreme = numba.njit(cache=True, error_model="numpy")(trajectory._velocity_extreme)


# Python's min and max, which numpy's passes use on floats: the first argument on a tie.
@numba.njit(cache=True)
def _min(a: float, b: float) -> float:
    return b if b < a else a


@numba.njit(cache=True)
def _max(a: float, b: float) -> float:
    return b if b > a else a


@numba.njit(cache=True, error_model="numpy")
def _speeds(grid: Any, first: Any, second: Any, max_velocity: Any, max_acceleration: Any, straight: Any,
            min_interval_s: float) -> Any:
    """Return the profile's s and squared speeds, and whether every speed is finite (topp.fastest_speeds)."""
    count, n = len(grid) - 1, len(max_velocity)
    bounds = np.empty(2 * count + 1)  # the velocity limits' bound on x at the grid points and middles
    for k in range(2 * count + 1):
        bounds[k] = np.inf
        for j in range(n):
            ratio = max_velocity[j] / first[k, j]
            bounds[k] = _min(bounds[k], ratio * ratio)
    ceiling, cap = np.empty(count), np.empty(count)
    for i in range(count):
        ceiling[i] = _min(_min(bounds[2 * i], bounds[2 * i + 1]), bounds[2 * i + 2])
        if min_interval_s > 0.0:
            fastest = (grid[i + 1] - grid[i]) / min_interval_s
            ceiling[i] = _min(ceiling[i], fastest * fastest)
    for i in range(count):
        cap[i] = _min(ceiling[i], ceiling[i - 1] if i > 0 else ceiling[0])
    # The lines x_{i+1} <= grow x_i + step of each interval's start, middle and end (topp._step_lines).
    grow, step = np.empty((count, 3 * n)), np.empty((count, 3 * n))
    reach, slope = np.empty(3 * n), np.empty(3 * n)
    for i in range(count):
        delta = grid[i + 1] - grid[i]
        still_cap = np.inf
        for p in range(3):
            for j in range(n):
                d2 = second[2 * i + p, j]
                d1 = first[2 * i + p, j] + (delta * float(p)) * d2
                size = abs(d1)
                if size <= STILL:
                    still_cap = _min(still_cap, max_acceleration[j] / abs(d2))
                    reach[p * n + j], slope[p * n + j] = np.inf, 0.0
                else:
                    reach[p * n + j], slope[p * n + j] = max_acceleration[j] / size, d2 / d1
        cap[i] = _min(cap[i], still_cap)
        largest = -np.inf
        for a in range(3 * n):
            grow[i, a], step[i, a] = 1.0 - (2 * delta) * slope[a], (2 * delta) * reach[a]
            for b in range(3 * n):
                largest = max(largest, (slope[b] - slope[a]) / (reach[b] + reach[a]))
        cap[i] = _min(cap[i], np.inf if largest <= 0.0 else 1.0 / largest)
    # Backwards from rest at the end (topp._backward), then forwards from rest (topp._forward).
    controllable = np.zeros(count + 1)
    bound = 0.0
    for i in range(count - 1, -1, -1):
        best = cap[i]
        for a in range(3 * n):
            if grow[i, a] > 0.0:
                value = (bound + step[i, a]) / grow[i, a]
                if value < best:
                    best = value
        controllable[i] = bound = best
    x = np.zeros(count + 1)
    current = 0.0
    for i in range(count - 1):
        best = controllable[i + 1]
        for a in range(3 * n):
            value = grow[i, a] * current + step[i, a]
            if value < best:
                best = value
        x[i + 1] = current = _max(best, 0.0)
    finite = True
    for i in range(count + 1):
        finite = finite and np.isfinite(x[i])
    if not finite:
        return grid, x, False
    # The exact optimum along each straight interval: ramp up, cruise, ramp down (topp._with_switches).
    ups, downs, tops = np.empty(count), np.empty(count), np.empty(count)
    used = 0
    for k in range(count):
        if not straight[k]:
            continue
        least = np.inf
        for j in range(n):
            least = min(least, max_acceleration[j] / abs(first[2 * k, j]))
        ramp, cruise = 2 * least, ceiling[k]
        start, end, x_start, x_end = grid[k], grid[k + 1], x[k], x[k + 1]
        meet = (x_end - x_start + ramp * (start + end)) / (2 * ramp)
        peak = x_start + ramp * (meet - start)
        up = down = meet
        if peak > cruise:
            up, down = start + (cruise - x_start) / ramp, end - (cruise - x_end) / ramp
        ups[used], downs[used], tops[used] = _min(_max(up, start), end), _min(_max(down, start), end), \
            _min(peak, cruise)
        used += 1
    s = np.concatenate((grid, ups[:used], downs[:used]))
    squared = np.concatenate((x, tops[:used], tops[:used]))
    order = np.argsort(s, kind="mergesort")
    s, squared = s[order], squared[order]
    keep = np.ones(len(s), dtype=np.bool_)
    for k in range(1, len(s)):
        keep[k] = s[k] > s[k - 1]
    return s[keep], squared[keep], True


@numba.njit(cache=True, error_model="numpy")
def _peaks(knots: Any, p: Any, v: Any, a: Any) -> Any:
    """Return per joint the largest |velocity| and |acceleration| of the quintics (trajectory.quintic_peak_rates)."""
    segments, n = len(knots) - 1, p.shape[1]
    at = np.zeros((4, segments, n))  # 0, the jerk's zeros in the segment (else 0), h
    acc, vel = np.empty((4, segments, n)), np.empty((4, segments, n))
    higher = np.empty((3, segments, n))  # the acceleration's coefficients of x^1..3
    for s in range(segments):
        h = knots[s + 1] - knots[s]
        h2 = h * h
        for j in range(n):
            dp, v0, v1, a0, a1 = p[s + 1, j] - p[s, j], v[s, j] * h, v[s + 1, j] * h, a[s, j] * h2, a[s + 1, j] * h2
            j0 = (20.0 * dp - 12.0 * v0 - 8.0 * v1 - 3.0 * a0 + a1) / (2 * h2 * h) * 6.0
            j1 = (-30.0 * dp + 16.0 * v0 + 14.0 * v1 + 3.0 * a0 - 2.0 * a1) / (2 * h2 * h2) * 24.0
            j2 = (12.0 * dp - 6.0 * v0 - 6.0 * v1 - a0 + a1) / (2 * h2 * h2 * h) * 60.0
            higher[0, s, j], higher[1, s, j], higher[2, s, j] = j0 / 1.0, j1 / 2.0, j2 / 3.0
            root = np.sqrt(j1 * j1 - 4 * j2 * j0)
            q = -0.5 * (j1 + np.copysign(root, j1))
            r1, r2 = q / j2, j0 / q
            r1 = r1 if (r1 > 0.0) and (r1 < h) else 0.0
            r2 = r2 if (r2 > 0.0) and (r2 < h) else 0.0
            at[1, s, j], at[2, s, j], at[3, s, j] = np.minimum(r1, r2), np.maximum(r1, r2), h
            ha1, ha2, ha3 = higher[0, s, j], higher[1, s, j], higher[2, s, j]
            hv2, hv3, hv4 = ha1 / 2.0, ha2 / 3.0, ha3 / 4.0
            acc[0, s, j], vel[0, s, j] = a[s, j], v[s, j]
            acc[3, s, j], vel[3, s, j] = a[s + 1, j], v[s + 1, j]
            for k in (1, 2):
                x = at[k, s, j]
                acc[k, s, j] = ((ha3 * x + ha2) * x + ha1) * x + a[s, j]
                vel[k, s, j] = (((hv4 * x + hv3) * x + hv2) * x + a[s, j]) * x + v[s, j]
    peak_v, peak_a = np.zeros(n), np.zeros(n)
    for k in range(4):
        for s in range(segments):
            for j in range(n):
                peak_a[j] = max(peak_a[j], abs(acc[k, s, j]))
                peak_v[j] = max(peak_v[j], abs(vel[k, s, j]))
    # A bracket whose velocity cannot beat the joint's peak by more than rounding needs no search.
    found = peak_v.copy()
    for k in range(3):
        for s in range(segments):
            for j in range(n):
                reach = max(abs(vel[k, s, j]), abs(vel[k + 1, s, j])) + max(abs(acc[k, s, j]), abs(acc[k + 1, s, j])) \
                    * (at[k + 1, s, j] - at[k, s, j])
                if acc[k, s, j] * acc[k + 1, s, j] < 0.0 and reach > peak_v[j] * (1.0 + 1e-12):
                    extreme = abs(_velocity_extreme(v[s, j], a[s, j], higher[0, s, j], higher[1, s, j], higher[2, s, j],
                                                    at[k, s, j], at[k + 1, s, j], acc[k, s, j], acc[k + 1, s, j]))
                    found[j] = _max(found[j], extreme)
    return found, peak_a


# pycc compiles an exported function with numba's default error model (a division by zero raises),
# whatever its decorator asks: the entry points below call the kernels, which keep the one they ask for.
@numba.njit(cache=True)
def speeds(grid: Any, first: Any, second: Any, max_velocity: Any, max_acceleration: Any, straight: Any,
           min_interval_s: float) -> Any:
    """Return `_speeds(...)`, called from Python."""
    return _speeds(grid, first, second, max_velocity, max_acceleration, straight, min_interval_s)


@numba.njit(cache=True)
def peaks(knots: Any, p: Any, v: Any, a: Any) -> Any:
    """Return `_peaks(...)`, called from Python."""
    return _peaks(knots, p, v, a)


KERNELS = {"speeds": speeds, "peaks": peaks}
"""The kernels called from Python (core/timing/_twins.py), by the name they are compiled under."""
