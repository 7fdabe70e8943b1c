"""Speed and optimality of `time_parameterize`, beside the TOPPRA-based version it replaced.

Run from the repository root with moveplan installed:
    python benchmarks/timing_speed.py [--paths 200] [--seed 0] [--max-step 0.05] [--repeats 5] [--no-old]

Paths (fixed seed), each timed at velocity and acceleration scaling 1.0 and 0.1 with the
limits of configs/panda and configs/ur10e (the Panda's arm limits are those of
tests/data/mbm/panda_robot/joint_limits.yaml):
  - 60 %: Panda, 2-8 waypoints, the largest joint moving 1-4 rad from start to goal, the
    inner waypoints on the straight line between them pushed off it by N(0, 0.3 rad) per
    joint (a planner's path after shortcutting: a few waypoints, detours around obstacles);
  - 20 %: the same on the UR10e (6 joints);
  - 20 %: single-joint moves of the Panda (one joint moves 1-4 rad or its whole range).

Reference duration: TOPPRA's optimum on the path the replaced version timed, the cubic
spline (not-a-knot, chord-length parameter) through the waypoints resampled at max_step,
with the same scaled limits and nothing else: no margins, no soft ends, no smoothing.
TOPPRA's discrete optimum shrinks towards the exact one as the grid refines, linearly in the
grid step (at corners, by 0.7 % from 16 to 32 points per resampled interval, 0.35 % from 32
to 64): the reference is extrapolated from 16 and 32 points per interval to step 0, within
~1e-4 of the extrapolation from 64 and 128. A denser resampling than max_step would make a
different path, with sharper corners and a slower optimum: this reference is the stricter.
It bounds only motions along that spline; the new version rounds corners its own way, a
little tighter (see the deviation figures), so a ratio below 1 is possible.

Deviation: the largest joint-space distance [rad] (Euclidean) from the polyline through the
waypoints, over the controller's interpolation sampled at 32 points per knot interval. The
collision checks of a plan certify the polyline's segments; the trajectory must stay close.

Times are per call, the fastest of --repeats calls (the old version: of one call) per path,
as wall time and as the process's CPU time (which leaves out the time other processes held
the CPU); the table gives median and 95th percentile over paths. Machines are shared and
noisy: compare medians and ratios, not single times. No asserts on time.
"""

from __future__ import annotations

import argparse
import functools
import logging
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import toppra
import toppra.algorithm
import toppra.constraint
import toppra.parametrizer
from numpy.typing import NDArray

from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import PlanningFailed
from moveplan.core.timing.parameterize import time_parameterize
from moveplan.core.trajectory import peak_rates, sample
from moveplan.core.types import JointTrajectory

logging.getLogger("toppra").setLevel(logging.CRITICAL)

Limits = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]


def limits(robot: str) -> Limits:
    """Return lower, upper [rad], max velocity and max acceleration of the robot's default group."""
    config = load_robot_config(robot)
    joints = [config.limits[j] for j in config.group().joints]
    return (np.array([j.lower for j in joints]), np.array([j.upper for j in joints]),
            np.array([j.max_velocity for j in joints]), np.array([j.max_acceleration for j in joints]))


def random_path(rng: np.random.Generator, lower: NDArray[np.float64], upper: NDArray[np.float64],
                single_joint: bool) -> NDArray[np.float64]:
    """Return waypoints within the limits whose largest joint moves 1-4 rad from start to goal."""
    n = len(lower)
    span = rng.uniform(1.0, 4.0)
    if single_joint:
        direction = np.zeros(n)
        joint = rng.integers(n)
        direction[joint] = rng.choice([-1.0, 1.0]) * min(span, 0.95 * (upper[joint] - lower[joint]))
        count = 2
    else:
        direction = rng.normal(size=n)
        direction *= span / np.max(np.abs(direction))
        direction = np.clip(direction, -0.9 * (upper - lower), 0.9 * (upper - lower))
        count = int(rng.integers(2, 9))
    low, high = np.maximum(lower, lower - direction), np.minimum(upper, upper - direction)
    start = rng.uniform(low, high)
    waypoints = start + np.linspace(0.0, 1.0, count)[:, None] * direction
    waypoints[1:-1] += rng.normal(scale=0.3, size=(count - 2, n))
    return np.clip(waypoints, lower, upper)


def reference_duration(waypoints: NDArray[np.float64], max_velocity: NDArray[np.float64],
                       max_acceleration: NDArray[np.float64], max_step: float) -> float:
    """Return TOPPRA's optimal duration [s] along the replaced version's spline path, extrapolated to a fine grid."""
    path = _old_resample(waypoints, max_step)
    arc = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))))
    arc /= arc[-1]
    spline = toppra.SplineInterpolator(arc, path)
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.stack([-max_velocity, max_velocity], axis=1)),
        toppra.constraint.JointAccelerationConstraint(np.stack([-max_acceleration, max_acceleration], axis=1)),
    ]
    durations = []
    for per_interval in (16, 32):
        grid = np.unique(np.concatenate([np.linspace(a, b, per_interval + 1)
                                         for a, b in zip(arc[:-1], arc[1:], strict=True)]))
        algorithm = toppra.algorithm.TOPPRA(constraints, spline, gridpoints=grid, solver_wrapper="seidel")
        _, sd, _ = algorithm.compute_parameterization(0.0, 0.0)
        durations.append(float(np.sum(2 * np.diff(grid) / (sd[:-1] + sd[1:]))))
    # The discrete optimum converges linearly in the grid step: extrapolate to step 0 (Richardson).
    return 2 * durations[1] - durations[0]


def deviation(trajectory: JointTrajectory, waypoints: NDArray[np.float64]) -> float:
    """Return the largest distance [rad] of the interpolated trajectory from the waypoints' polyline."""
    knots = trajectory.times_s
    fractions = np.linspace(0.0, 1.0, 33)[:-1]
    times = np.append((knots[:-1, None] + np.diff(knots)[:, None] * fractions).ravel(), knots[-1])
    positions, _, _ = sample(trajectory, times, derivatives=0)
    a, b = waypoints[:-1], waypoints[1:]
    along = b - a
    length2 = np.maximum(np.sum(along**2, axis=1), 1e-300)
    t = np.clip(np.einsum("psn,sn->ps", positions[:, None, :] - a, along) / length2, 0.0, 1.0)
    nearest = a + t[:, :, None] * along
    return float(np.max(np.min(np.linalg.norm(positions[:, None, :] - nearest, axis=2), axis=1)))


def fastest(call: Callable[[], JointTrajectory], repeats: int) -> tuple[float, float, JointTrajectory]:
    """Return the fastest wall time and the fastest CPU time [s] of `repeats` calls, and the result."""
    wall = cpu = float("inf")
    for _ in range(repeats):
        began, began_cpu = time.perf_counter(), time.process_time()
        result = call()
        cpu = min(cpu, time.process_time() - began_cpu)
        wall = min(wall, time.perf_counter() - began)
    return wall, cpu, result


def within_limits(trajectory: JointTrajectory, max_velocity: NDArray[np.float64],
                  max_acceleration: NDArray[np.float64]) -> bool:
    """Return True if the exact peaks of the interpolation are within the limits."""
    peak_v, peak_a = peak_rates(trajectory)
    return bool(np.all(peak_v <= max_velocity) and np.all(peak_a <= max_acceleration))


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--paths", type=int, default=200)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--max-step", type=float, default=0.05)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--no-old", action="store_true", help="skip the replaced version (the slow part)")
    args = parser.parse_args()
    robots = {"panda": limits("panda"), "ur10e": limits("ur10e")}
    rng = np.random.default_rng(args.seed)
    cases = []
    for k in range(args.paths):
        kind = ("panda", "panda", "panda", "ur10e", "single")[k % 5]
        lower, upper, v, a = robots["ur10e" if kind == "ur10e" else "panda"]
        cases.append((kind, random_path(rng, lower, upper, kind == "single"), v, a))
    names = {7: tuple(f"panda_joint{i + 1}" for i in range(7)), 6: tuple(f"joint{i + 1}" for i in range(6))}
    versions: dict[str, Callable[..., JointTrajectory]] = {"new": time_parameterize}
    if not args.no_old:
        versions["old"] = old_time_parameterize
    rows: dict[str, dict[str, list[Any]]] = {
        v: {"time": [], "cpu": [], "ratio": [], "deviation": [], "valid": []} for v in versions}
    for kind, waypoints, max_v, max_a in cases:
        for scaling in (1.0, 0.1):
            v, a = max_v * scaling, max_a * scaling
            reference = reference_duration(waypoints, v, a, args.max_step)
            for version, function in versions.items():
                call = functools.partial(function, names[len(v)], waypoints, v, a, max_step=args.max_step)
                try:
                    elapsed, cpu, trajectory = fastest(call, args.repeats if version == "new" else 1)
                except PlanningFailed as error:
                    print(f"{version} failed on a {kind} path: {error}")
                    continue
                row = rows[version]
                row["time"].append(elapsed)
                row["cpu"].append(cpu)
                row["ratio"].append(trajectory.duration_s / reference)
                row["deviation"].append(deviation(trajectory, waypoints))
                row["valid"].append(within_limits(trajectory, v, a))
    count = 2 * len(cases)
    print(f"{len(cases)} paths x scaling 1.0 and 0.1 = {count} timings, max_step {args.max_step} rad")
    print(f"{'':5} {'wall median':>12} {'p95':>9} {'CPU median':>11} {'p95':>9} {'duration/ref median':>20} "
          f"{'max':>7} {'deviation median':>17} {'max':>7} {'within limits':>14}")
    for version, row in rows.items():
        wall_ms, cpu_ms = np.array(row["time"]) * 1e3, np.array(row["cpu"]) * 1e3
        ratios, deviations = np.array(row["ratio"]), np.array(row["deviation"])
        print(f"{version:5} {np.median(wall_ms):9.2f} ms {np.percentile(wall_ms, 95):6.2f} ms "
              f"{np.median(cpu_ms):8.2f} ms {np.percentile(cpu_ms, 95):6.2f} ms "
              f"{np.median(ratios):20.4f} {np.max(ratios):7.4f} {np.median(deviations):13.4f} rad "
              f"{np.max(deviations):7.4f} {sum(row['valid']):>8}/{len(wall_ms)}")
    if "old" in rows and len(rows["old"]["deviation"]) == len(rows["new"]["deviation"]):
        ratio = np.array(rows["new"]["deviation"]) / np.maximum(np.array(rows["old"]["deviation"]), 1e-12)
        moving = np.array(rows["old"]["deviation"]) > 1e-6  # straight paths: both ~0
        print(f"deviation new/old per path (paths with corners): median {np.median(ratio[moving]):.3f}, "
              f"max {np.max(ratio[moving]):.3f}; new larger on {int(np.sum(ratio[moving] > 1.0))} of "
              f"{int(np.sum(moving))}")


# The replaced version, kept here only to compare against: TOPPRA through the `toppra` package
# on a cubic spline through the resampled path, with margins and re-tries checked by the
# bisection version of `peak_rates` it shipped with.

def _old_resample(waypoints: NDArray[np.float64], max_step: float) -> NDArray[np.float64]:
    points = [waypoints[:1]]
    for a, b in zip(waypoints[:-1], waypoints[1:], strict=True):
        count = max(1, int(np.ceil(np.max(np.abs(b - a)) / max_step)))
        points.append(a + (b - a) * (np.arange(1, count + 1) / count)[:, None])
    return np.concatenate(points)


def old_time_parameterize(joint_names: tuple[str, ...], waypoints: NDArray[np.float64],
                          max_velocity: NDArray[np.float64], max_acceleration: NDArray[np.float64],
                          sample_period_s: float = 0.01, max_step: float = 0.05) -> JointTrajectory:
    """Return the replaced version's trajectory."""
    path = _old_resample(waypoints, max_step)
    keep = np.concatenate(([True], np.any(np.abs(np.diff(path, axis=0)) > 1e-12, axis=1)))
    path = path[keep]
    if len(path) == 1:
        zeros = np.zeros_like(path)
        return JointTrajectory(joint_names, np.zeros(1), path, zeros, zeros)
    velocity_margin, acceleration_margin = 0.99, 0.86
    for _ in range(6):
        trajectory = _old_toppra(joint_names, path, max_velocity * velocity_margin,
                                 max_acceleration * acceleration_margin, sample_period_s)
        peak_v, peak_a = _old_peak_rates(trajectory)
        excess_v = float(np.max(peak_v / max_velocity))
        excess_a = float(np.max(peak_a / max_acceleration))
        if excess_v <= 1.0 and excess_a <= 1.0:
            return trajectory
        velocity_margin *= min(1.0, 0.995 / excess_v)
        acceleration_margin *= min(1.0, 0.995 / excess_a)
    raise PlanningFailed("time parameterisation could not keep the interpolated trajectory within the limits")


def _old_gridpoints(count: int) -> NDArray[np.float64]:
    ends = np.geomspace(1e-5, 2.0 / count, 30)
    return np.unique(np.concatenate((np.linspace(0.0, 1.0, count + 1), ends, 1.0 - ends)))


def _old_soft_ends(grid: NDArray[np.float64], sd: NDArray[np.float64], ramp_s: float) -> NDArray[np.float64]:
    speed2 = sd**2
    for x, side in ((1.0 - grid, slice(-6, None)), (grid, slice(0, 6))):
        window = grid[side]
        decel = np.abs(np.diff(speed2[side])) / (2 * np.diff(window))
        rate = float(np.max(decel))
        if rate <= 0.0:
            continue
        delta = rate * ramp_s**2 / 12.0
        cap = np.where(x < delta, 4.0 / 3.0 * rate * x**1.5 / np.sqrt(delta), 2 * rate * x - 2.0 / 3.0 * rate * delta)
        speed2 = np.minimum(speed2, cap)
    return np.sqrt(np.maximum(speed2, 0.0))


def _old_toppra(joint_names: tuple[str, ...], path: NDArray[np.float64], max_velocity: NDArray[np.float64],
                max_acceleration: NDArray[np.float64], sample_period_s: float) -> JointTrajectory:
    arc = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))))
    spline = toppra.SplineInterpolator(arc / arc[-1], path)
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.stack([-max_velocity, max_velocity], axis=1)),
        toppra.constraint.JointAccelerationConstraint(np.stack([-max_acceleration, max_acceleration], axis=1)),
    ]
    grid = _old_gridpoints(max(100, 4 * len(path)))
    algorithm = toppra.algorithm.TOPPRA(constraints, spline, gridpoints=grid)
    _, sd, _ = algorithm.compute_parameterization(0.0, 0.0)
    if sd is None or not np.all(np.isfinite(sd)):
        raise PlanningFailed("TOPPRA found no feasible time parameterisation of the path")
    sd = _old_soft_ends(grid, sd, 10 * sample_period_s)
    timed = toppra.parametrizer.ParametrizeSpline(spline, grid, sd)
    duration = float(timed.duration)
    times = np.linspace(0.0, duration, max(2, int(np.ceil(duration / sample_period_s)) + 1))
    times = np.unique(np.round(times * 1e9)) / 1e9
    positions, velocities, accelerations = timed(times), timed(times, 1), timed(times, 2)
    positions[0], positions[-1] = path[0], path[-1]
    for rates in (velocities, accelerations):
        rates[0], rates[-1] = 0.0, 0.0
    return JointTrajectory(joint_names, times, positions, velocities, accelerations)


def _old_peak_rates(trajectory: JointTrajectory) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    knots, p, v, a = trajectory.times_s, trajectory.positions, trajectory.velocities, trajectory.accelerations
    h = np.diff(knots)[:, None]
    dp = p[1:] - p[:-1]
    v0, v1, a0, a1 = v[:-1], v[1:], a[:-1], a[1:]
    c1, c2 = v0, a0 / 2
    c3 = (20 * dp - (8 * v1 + 12 * v0) * h - (3 * a0 - a1) * h**2) / (2 * h**3)
    c4 = (-30 * dp + (14 * v1 + 16 * v0) * h + (3 * a0 - 2 * a1) * h**2) / (2 * h**4)
    c5 = (12 * dp - 6 * (v1 + v0) * h - (a0 - a1) * h**2) / (2 * h**5)
    h = np.broadcast_to(h, c1.shape)

    def velocity(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return c1 + x * (2 * c2 + x * (3 * c3 + x * (4 * c4 + x * 5 * c5)))

    def acceleration(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return 2 * c2 + x * (6 * c3 + x * (12 * c4 + x * 20 * c5))

    with np.errstate(divide="ignore", invalid="ignore"):
        qa, qb, qc = 60 * c5, 24 * c4, 6 * c3
        root = np.sqrt(qb * qb - 4 * qa * qc)
        q = -0.5 * (qb + np.copysign(root, qb))
        roots = (q / qa, qc / q)
    jerk_zeros = [np.where((r >= 0) & (r <= h), r, 0.0) for r in roots]
    bounds = np.sort(np.stack([np.zeros_like(h), *jerk_zeros, h]), axis=0)
    peak_a = np.max(np.abs(np.stack([acceleration(x) for x in bounds])), axis=(0, 1))
    candidates = [velocity(x) for x in bounds]
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        a_lo = acceleration(lo)
        crossing = np.sign(a_lo) * np.sign(acceleration(hi)) < 0
        lo, hi = lo.copy(), hi.copy()
        for _ in range(32):
            mid = (lo + hi) / 2
            same = np.sign(acceleration(mid)) == np.sign(a_lo)
            lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        candidates.append(np.where(crossing, velocity(lo), 0.0))
    peak_v = np.max(np.abs(np.stack(candidates)), axis=(0, 1))
    return peak_v, peak_a


if __name__ == "__main__":
    main()
