"""Trajectory sampling as ros2_controllers' JointTrajectoryController (JTC) interpolates it.

Per segment, the spline degree follows the fields present at both ends
(joint_trajectory_controller trajectory.cpp, interpolation_method "splines"):
positions only give a linear segment, positions and velocities a cubic
Hermite, all three a quintic. After the last point the controller holds the
last point. Before the first point it blends from the state it read at its
first sample ("point before") when the first point's time_from_start is > 0,
and jumps to the first point when it is 0.

Sample times are on the controller's timeline: 0 is the first sample, the
trajectory's start (a MoveIt goal has header.stamp 0, "start now").
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from .types import JointTrajectory, frozen_array

__all__ = [
    "PointBefore", "interpolate", "peak_rates", "quintic_peak_rates", "sample", "sampler", "shortest_angular_distance",
    "straight_states",
]

Samples = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]


@dataclass(frozen=True)
class PointBefore:
    """The state the controller read at its first sample, which it blends from to the first point.

    Attributes:
        positions: Joint positions in [rad] or [m], shape (n,).
        velocities: In [rad]/[s], or None when the controller has no velocity state interface.
        accelerations: In [rad]/[s]^2, or None without an acceleration state interface.
    """

    positions: NDArray[np.float64]
    velocities: NDArray[np.float64] | None = None
    accelerations: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        positions = frozen_array(self.positions, (None,), "positions")
        object.__setattr__(self, "positions", positions)
        for name in ("velocities", "accelerations"):
            if getattr(self, name) is not None:
                value = frozen_array(getattr(self, name), positions.shape, name)
                object.__setattr__(self, name, value)


def shortest_angular_distance(
    from_rad: npt.ArrayLike, to_rad: npt.ArrayLike
) -> NDArray[np.float64]:
    """Return `to - from` in [rad] wrapped into (-pi, pi], as angles::shortest_angular_distance."""
    difference = np.asarray(to_rad, dtype=np.float64) - np.asarray(from_rad, dtype=np.float64)
    wrapped = np.fmod(difference + np.pi, 2.0 * np.pi)
    return np.where(wrapped <= 0.0, wrapped + np.pi, wrapped - np.pi)


def sample(
    trajectory: JointTrajectory,
    times_s: npt.ArrayLike,
    *,
    has_velocities: bool = True,
    has_accelerations: bool = True,
    point_before: PointBefore | None = None,
    continuous: npt.ArrayLike | None = None,
    derivatives: int = 2,
) -> Samples:
    """Return positions, velocities and accelerations, each (len(times), n), at `times_s` in [s].

    At and after the last point's time the last point is held, with its own velocities and
    accelerations (0 where absent), as JTC holds it.

    Args:
        trajectory: The trajectory as sent to the controller.
        times_s: Sample times on the controller's timeline in [s].
        has_velocities: False to sample as if the points carried no velocities; a trajectory whose
            points carry none (`trajectory.has_velocities` False) is sampled so anyway.
        has_accelerations: Likewise for accelerations.
        point_before: The state the controller read at its first sample (time 0), blended
            from if the first point's time is > 0; without it, times before the first point
            give the first point.
        continuous: Per joint, True for URDF continuous joints: the point before is shifted by
            whole turns towards the first point (JTC `wraparound_joint`).
        derivatives: 2 for velocities and accelerations, 1 for velocities only, 0 for neither;
            what is not computed is returned as zeros (checks of long recordings need less).
    """
    knots = trajectory.times_s
    positions = trajectory.positions
    count, n = positions.shape
    has_velocities = has_velocities and trajectory.has_velocities
    has_accelerations = has_accelerations and trajectory.has_accelerations
    velocities = trajectory.velocities if has_velocities else np.zeros((count, n))
    accelerations = trajectory.accelerations if has_accelerations else np.zeros((count, n))
    has_v = np.full(count, has_velocities)
    has_a = np.full(count, has_velocities and has_accelerations)
    if point_before is not None and knots[0] > 0.0:
        start = _wraparound(point_before.positions, positions[0], continuous)
        knots = np.concatenate(([0.0], knots))
        positions = np.vstack((start, positions))
        velocities = np.vstack((_or_zeros(point_before.velocities, n), velocities))
        accelerations = np.vstack((_or_zeros(point_before.accelerations, n), accelerations))
        has_v = np.concatenate(([point_before.velocities is not None], has_v))
        has_a = np.concatenate(([point_before.accelerations is not None and has_v[0]], has_a))
    t = np.atleast_1d(np.asarray(times_s, dtype=np.float64))
    return _sample_points(knots, positions, velocities, accelerations, has_v, has_a, t, derivatives)


def sampler(trajectory: JointTrajectory) -> Callable[[NDArray[np.float64], int], Samples]:
    """Return `sample` of `trajectory` (no point before) as a function of times and derivatives.

    The segments' coefficients are computed once: a certification samples one trajectory twice.
    """
    knots, p, v, a = trajectory.times_s, trajectory.positions, trajectory.velocities, trajectory.accelerations
    if len(knots) == 1:
        def held(t: NDArray[np.float64], derivatives: int = 2) -> Samples:
            return _hold(p[0], v[0], a[0], len(t))
        return held
    has_v = np.full(len(knots), trajectory.has_velocities)
    has_a = np.full(len(knots), trajectory.has_velocities and trajectory.has_accelerations)
    coefficients = _coefficients(knots, p, v, a, has_v, has_a)

    def evaluated(t: NDArray[np.float64], derivatives: int = 2) -> Samples:
        return _evaluate(knots, coefficients, p, v, a, t, derivatives)
    return evaluated


def peak_rates(trajectory: JointTrajectory) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return per joint the largest |velocity| and |acceleration| anywhere along the interpolation."""
    return quintic_peak_rates(trajectory.times_s, trajectory.positions, trajectory.velocities,
                              trajectory.accelerations)


# A joint at rest over a segment has no jerk: its quadratic's roots are 0 / 0.
@np.errstate(divide="ignore", invalid="ignore")
def quintic_peak_rates(
    knots: NDArray[np.float64], p: NDArray[np.float64], v: NDArray[np.float64], a: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return per joint the largest |velocity| and |acceleration| of the quintics through the points, as JTC's.

    Exact (to rounding): the acceleration of a segment is a cubic, largest at an end or
    where the jerk (a quadratic) is zero; between those points it is monotonic, so its
    zeros, where the velocity peaks, are found by a safeguarded Newton iteration inside
    each bracket where it changes sign.

    Args:
        knots: Times of the points in [s], strictly increasing, shape (N,).
        p: Positions, shape (N, n).
        v: Velocities, shape (N, n).
        a: Accelerations, shape (N, n).
    """
    if len(knots) == 1:
        return np.abs(v[0]), np.abs(a[0])
    h = (knots[1:] - knots[:-1])[:, None]
    v0, a0 = v[:-1], a[:-1]
    jerk = _quintic(h, p[1:] - p[:-1], v0, v[1:], a0, a[1:]) * _JERK  # coefficients of x^0..2
    higher_a = jerk / _POWER  # the acceleration's coefficients of x^1..3 (of x^0: a0)
    higher_v = higher_a / (_POWER + 1)  # the velocity's of x^2..4 (of x^0 and x^1: v0 and a0)
    acceleration, velocity = (a0, *higher_a), (v0, a0, *higher_v)
    r1, r2 = (np.where((r > 0.0) & (r < h), r, 0.0) for r in _quadratic_roots(jerk[2], jerk[1], jerk[0]))
    bounds = np.zeros((4, *v0.shape))  # 0, the jerk's zeros in the segment (else 0), h
    bounds[1], bounds[2], bounds[3] = np.minimum(r1, r2), np.maximum(r1, r2), h
    inner = bounds[1:3]
    # At the knots the segment meets its given velocity and acceleration; between, evaluate.
    a = np.concatenate((a0[None], _horner(acceleration, inner), a[None, 1:]))
    v = np.concatenate((v0[None], _horner(velocity, inner), v[None, 1:]))
    n = v0.shape[1]
    size_a, size_v = np.abs(a), np.abs(v)
    peak_a = size_a.reshape(-1, n).max(axis=0)
    peak_v = size_v.reshape(-1, n).max(axis=0)
    # Where the acceleration is monotonic, the velocity moves from its value at a bracket's end
    # by at most the larger end acceleration times the bracket's length: a bracket that cannot
    # beat the joint's peak found so far by more than rounding (1e-12) needs no search.
    reach = np.maximum(size_v[:-1], size_v[1:]) + np.maximum(size_a[:-1], size_a[1:]) * (bounds[1:] - bounds[:-1])
    crossing = (a[:-1] * a[1:] < 0.0) & (reach > peak_v * (1.0 + 1e-12))
    if crossing.any():
        _, segment, joint = np.nonzero(crossing)
        brackets = np.stack((v0[segment, joint], a0[segment, joint], *higher_a[:, segment, joint],
                             bounds[:-1][crossing], bounds[1:][crossing], a[:-1][crossing], a[1:][crossing]), axis=1)
        peaks = peak_v.tolist()
        for j, bracket in zip(joint.tolist(), brackets.tolist(), strict=True):
            peaks[j] = max(peaks[j], abs(_velocity_extreme(*bracket)))
        peak_v = np.array(peaks)
    return peak_v, peak_a


# The jerk's coefficients from c3..c5, and the powers of x they multiply in the acceleration.
_JERK = np.array([6.0, 24.0, 60.0])[:, None, None]
_POWER = np.array([1.0, 2.0, 3.0])[:, None, None]


# Python floats: a few brackets of a few Newton steps each, which numpy would make ten times slower.
def _velocity_extreme(
    v0: float, a0: float, a1: float, a2: float, a3: float, lo: float, hi: float, f_lo: float, f_hi: float
) -> float:
    """Return the velocity v0 + a0 x + a1 x^2 / 2 + a2 x^3 / 3 + a3 x^4 / 4 where the acceleration is 0.

    The acceleration a0 + a1 x + a2 x^2 + a3 x^3 is monotonic on [lo, hi], where it goes from
    f_lo to f_hi, of the other sign; its zero is found by Newton's method, kept in the bracket.
    """
    x = lo - f_lo * (hi - lo) / (f_hi - f_lo)  # false position: exact for a linear acceleration
    rising = f_hi > 0.0
    # The velocity is flat at the zero: locating it within 1e-7 of the bracket leaves an error
    # in the velocity of ~1e-14 of the bracket's velocity change.
    tolerance = 1e-7 * (hi - lo)
    for _ in range(64):  # Newton converges in a few steps; bisection, its fallback, within 24
        f = a0 + x * (a1 + x * (a2 + x * a3))
        if (f < 0.0) == rising:  # the zero lies right of x
            lo = x
        else:
            hi = x
        jerk = a1 + x * (2 * a2 + x * (3 * a3))
        newton = x - f / jerk if jerk else math.inf
        step = newton if lo <= newton <= hi else (lo + hi) / 2
        converged = abs(step - x) <= tolerance
        x = step
        if converged:
            break
    return v0 + x * (a0 + x * (a1 / 2 + x * (a2 / 3 + x * (a3 / 4))))


def _quadratic_roots(
    a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the real roots of a x^2 + b x + c elementwise (NaN or inf where there are none: ignore the warnings)."""
    root = np.sqrt(b * b - 4 * a * c)
    # The numerically stable form; with a = 0 the second root is the linear one, -c / b.
    q = -0.5 * (b + np.copysign(root, b))
    return q / a, c / q


def _or_zeros(values: NDArray[np.float64] | None, n: int) -> NDArray[np.float64]:
    return np.zeros(n) if values is None else values


def _wraparound(
    start: NDArray[np.float64], first: NDArray[np.float64], continuous: npt.ArrayLike | None
) -> NDArray[np.float64]:
    """Return `start` with continuous joints moved by whole turns to lie nearest to `first`."""
    if continuous is None:
        return start
    distance = shortest_angular_distance(start, first)
    # At exactly half a turn, JTC resolves the tie towards the side the first point lies on.
    tie = np.abs(np.abs(distance) - np.pi) < 1e-9
    distance = np.where(tie, np.where(first > start, np.abs(distance), -np.abs(distance)), distance)
    return np.where(np.asarray(continuous, dtype=bool), first - distance, start)


def _sample_points(
    knots: NDArray[np.float64],
    p: NDArray[np.float64],
    v: NDArray[np.float64],
    a: NDArray[np.float64],
    has_v: NDArray[np.bool_],
    has_a: NDArray[np.bool_],
    t: NDArray[np.float64],
    derivatives: int = 2,
) -> Samples:
    """Return samples of the spline through the points; `has_v`/`has_a`: fields each point has."""
    if len(p) == 1:
        return _hold(p[0], v[0], a[0], len(t))
    return _evaluate(knots, _coefficients(knots, p, v, a, has_v, has_a), p, v, a, t, derivatives)


def _evaluate(
    knots: NDArray[np.float64],
    coefficients: NDArray[np.float64],
    p: NDArray[np.float64],
    v: NDArray[np.float64],
    a: NDArray[np.float64],
    t: NDArray[np.float64],
    derivatives: int,
) -> Samples:
    """Return samples at `t` of the spline with these segment `coefficients` (6, segments, n) through the points."""
    seg = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(knots) - 2)
    # np.take copies rows contiguously; fancy indexing on axis 1 left strided arrays (2x slower).
    c0, c1, c2, c3, c4, c5 = np.take(coefficients, seg, axis=1)
    h = (knots[seg + 1] - knots[seg])[:, None]
    x = np.clip(t[:, None] - knots[seg][:, None], 0.0, h)
    pos = _horner((c0, c1, c2, c3, c4, c5), x)
    # Zeros from calloc cost nothing until written: long recordings need positions only.
    vel = _horner((c1, 2 * c2, 3 * c3, 4 * c4, 5 * c5), x) if derivatives >= 1 else np.zeros_like(pos)
    acc = _horner((2 * c2, 6 * c3, 12 * c4, 20 * c5), x) if derivatives >= 2 else np.zeros_like(pos)
    after = t >= knots[-1]
    pos[after], vel[after], acc[after] = p[-1], v[-1] if derivatives >= 1 else 0.0, a[-1] if derivatives >= 2 else 0.0
    before = t < knots[0]
    pos[before], vel[before], acc[before] = p[0], 0.0, 0.0
    return pos, vel, acc


def _horner(coefficients: tuple[NDArray[np.float64], ...], x: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return sum_k coefficients[k] x^k, evaluated in place (one array, no temporaries per term)."""
    result = coefficients[-1] * x
    for coefficient in coefficients[-2:0:-1]:
        result += coefficient
        result *= x
    result += coefficients[0]
    return result


def _hold(
    p: NDArray[np.float64], v: NDArray[np.float64], a: NDArray[np.float64], count: int
) -> Samples:
    return np.tile(p, (count, 1)), np.tile(v, (count, 1)), np.tile(a, (count, 1))


def _coefficients(
    knots: NDArray[np.float64],
    p: NDArray[np.float64],
    v: NDArray[np.float64],
    a: NDArray[np.float64],
    has_v: NDArray[np.bool_],
    has_a: NDArray[np.bool_],
) -> NDArray[np.float64]:
    """Return coefficients c0..c5 of powers of time per segment, shape (6, segments, n)."""
    h = np.diff(knots)[:, None]
    p0, v0, a0, p1, v1, a1 = p[:-1], v[:-1], a[:-1], p[1:], v[1:], a[1:]
    dp = p1 - p0
    cubic = (has_v[:-1] & has_v[1:])[:, None]
    quintic = cubic & (has_a[:-1] & has_a[1:])[:, None]
    zeros = np.zeros_like(p0)
    c1 = np.where(cubic, v0, dp / h)
    c2 = np.where(quintic, a0 / 2, np.where(cubic, (3 * dp - (2 * v0 + v1) * h) / h**2, zeros))
    q3, q4, q5 = _quintic(h, dp, v0, v1, a0, a1)
    c3 = np.where(quintic, q3, np.where(cubic, (-2 * dp + (v0 + v1) * h) / h**3, zeros))
    c4 = np.where(quintic, q4, zeros)
    c5 = np.where(quintic, q5, zeros)
    return np.stack((p0, c1, c2, c3, c4, c5))


def _quintic(
    h: NDArray[np.float64],
    dp: NDArray[np.float64],
    v0: NDArray[np.float64],
    v1: NDArray[np.float64],
    a0: NDArray[np.float64],
    a1: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Return c3, c4, c5 (stacked) of the quintic with c0..c2 = p0, v0, a0 / 2 reaching p0 + dp, v1, a1 after h."""
    # Written out rather than as a matrix product: BLAS may sum in any order (and fuse), which would
    # make a plan's last bits depend on the machine, and the compiled twin (core/timing/_compiled.py)
    # could not repeat them.
    h2 = h * h
    v0, v1, a0, a1 = v0 * h, v1 * h, a0 * h2, a1 * h2
    return np.stack(((20.0 * dp - 12.0 * v0 - 8.0 * v1 - 3.0 * a0 + a1) / (2 * h2 * h),
                     (-30.0 * dp + 16.0 * v0 + 14.0 * v1 + 3.0 * a0 - 2.0 * a1) / (2 * h2 * h2),
                     (12.0 * dp - 6.0 * v0 - 6.0 * v1 - a0 + a1) / (2 * h2 * h2 * h)))


def straight_states(a: NDArray[np.float64], b: NDArray[np.float64], count: int) -> NDArray[np.float64]:
    """Return `count` + 1 evenly spaced states on the straight segment from `a` to `b`, both included."""
    return a + (b - a) * (np.arange(count + 1) / count)[:, None]


def interpolate(a: NDArray[np.float64], b: NDArray[np.float64], resolution: float) -> NDArray[np.float64]:
    """Return states from `a` to `b` (both included), no joint moving more than `resolution` [rad] per step."""
    return straight_states(a, b, max(1, int(np.ceil(np.max(np.abs(b - a)) / resolution))))
