"""The certified states of a timed trajectory, placed by compiled code (numba).

The same computation as core/collision/_certify.py `trajectory_states`, with the samples of
core/trajectory.py `sample`; the peak rates come from timing's compiled twin, the numbers numpy's
gives. numpy's version costs a tenth of a median MotionBenchMaker plan step in array calls on a
few thousand numbers, this one a hundredth. The numbers agree to rounding
(tests/collision/test_certify_soundness.py); numpy's version is the reference, and the one used before the
sphere filter (and numba) is loaded.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

__all__ = ["trajectory_states"]


@numba.njit(cache=True)
def trajectory_states(knots: Any, p: Any, v: Any, a: Any, peak_v: Any, peak_a: Any, reach: Any, step: float,
                      piece: int) -> Any:
    """Return states along the controller's quintics through the points, at most `step` [m] of motion apart, and travel.

    As certify.trajectory_states: pieces of at most `piece` states at the peak speed, each with
    the speed bound (|v0| + |v1| + A h) / 2 of its ends; states at equal increments of its integral.
    `peak_v` and `peak_a` are the joints' peak rates (trajectory.quintic_peak_rates, or its twin).
    """
    coefficients = _coefficients(knots, p, v, a)
    speed, accel = 0.0, 0.0
    for i in range(len(reach)):
        speed += peak_v[i] * reach[i]
        accel += peak_a[i] * reach[i]
    duration = knots[-1] - knots[0]
    pieces = max(1, int(np.ceil(speed * duration / (piece * step))))
    h = duration / pieces
    ends = np.linspace(knots[0], knots[-1], pieces + 1)
    rate = np.zeros(pieces + 1)
    velocity = np.empty((pieces + 1, len(reach)))
    position = np.empty((pieces + 1, len(reach)))
    spline(knots, coefficients, p, v, ends, 1, position, velocity)
    for k in range(pieces + 1):
        for i in range(len(reach)):
            rate[k] += abs(velocity[k, i]) * reach[i]
    motion = np.empty(pieces)
    covered = np.zeros(pieces + 1)
    for k in range(pieces):
        motion[k] = min((rate[k] + rate[k + 1] + accel * h) / 2, speed) * h
        covered[k + 1] = covered[k] + motion[k]
    count = max(1, int(np.ceil(covered[-1] / step)))
    travel = covered[-1] * (np.arange(count + 1) / count)
    times = np.empty(count + 1)
    k = 0  # the piece holding travel[m], the last whose start is at or before it (numba's searchsorted is slow)
    for m in range(count + 1):
        while k < pieces - 1 and covered[k + 1] <= travel[m]:
            k += 1
        into = (travel[m] - covered[k]) / motion[k] if motion[k] > 0.0 else 0.0
        times[m] = ends[k] + min(max(into, 0.0), 1.0) * h
    times[0], times[-1] = knots[0], knots[-1]
    values = np.empty((count + 1, len(reach)))
    spline(knots, coefficients, p, v, times, 0, values, values)
    return values, travel


@numba.njit(cache=True)
def spline(knots: Any, coefficients: Any, p: Any, v: Any, t: Any, derivatives: int, pos: Any, vel: Any) -> None:
    """Write the positions (and if `derivatives` >= 1 velocities) at times `t` into `pos` (and `vel`), as `sample`.

    The last point is held from its time on; before the first, its position, at rest.
    """
    last, seg = len(knots) - 2, 0
    for k in range(len(t)):
        now = t[k]
        if now >= knots[-1] or now < knots[0]:
            after = now >= knots[-1]
            for i in range(coefficients.shape[2]):
                pos[k, i] = p[-1, i] if after else p[0, i]
                if derivatives >= 1:
                    vel[k, i] = v[-1, i] if after else 0.0
            continue
        # The segment holding `now`: the last whose start is at or before it (times usually ascend).
        if now < knots[seg]:
            seg = 0
        while seg < last and knots[seg + 1] <= now:
            seg += 1
        x = min(max(now - knots[seg], 0.0), knots[seg + 1] - knots[seg])
        for i in range(coefficients.shape[2]):
            c1, c2, c3, c4, c5 = (coefficients[1, seg, i], coefficients[2, seg, i], coefficients[3, seg, i],
                                  coefficients[4, seg, i], coefficients[5, seg, i])
            pos[k, i] = ((((c5 * x + c4) * x + c3) * x + c2) * x + c1) * x + coefficients[0, seg, i]
            if derivatives >= 1:
                vel[k, i] = (((5 * c5 * x + 4 * c4) * x + 3 * c3) * x + 2 * c2) * x + c1


@numba.njit(cache=True)
def _coefficients(knots: Any, p: Any, v: Any, a: Any) -> Any:
    """Return c0..c5 of each segment's quintic in powers of time from its start, shape (6, segments, n)."""
    out = np.empty((6, len(knots) - 1, p.shape[1]))
    for s in range(len(knots) - 1):
        h = knots[s + 1] - knots[s]
        h2 = h * h
        for i in range(p.shape[1]):
            dp, v0, v1, a0, a1 = p[s + 1, i] - p[s, i], v[s, i] * h, v[s + 1, i] * h, a[s, i] * h2, a[s + 1, i] * h2
            out[0, s, i], out[1, s, i], out[2, s, i] = p[s, i], v[s, i], a[s, i] / 2
            out[3, s, i] = (20.0 * dp - 12.0 * v0 - 8.0 * v1 - 3.0 * a0 + a1) / (2 * h2 * h)
            out[4, s, i] = (-30.0 * dp + 16.0 * v0 + 14.0 * v1 + 3.0 * a0 - 2.0 * a1) / (2 * h2 * h2)
            out[5, s, i] = (12.0 * dp - 6.0 * v0 - 6.0 * v1 - a0 + a1) / (2 * h2 * h2 * h)
    return out
