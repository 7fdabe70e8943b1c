"""Where to check a motion so that no point of the robot moves more than a distance between checks.

A joint turning by d [rad] moves a point at distance r from its origin by at most
r * |d|. `reach` bounds r for each group joint over every configuration: the joint
origins down the kinematic tree are a fixed distance apart, and each collision shape
lies within a fixed distance of its own joint. Summed over the joints, that bounds
how far any robot point (attached objects included) moves in a joint-space step, so
states placed by it certify a motion at a resolution given in metres, not radians.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ..errors import ConfigError, InputError
from ..model import Robot
from ..trajectory import peak_rates, sample, sampler, straight_states
from ..types import JointTrajectory

__all__ = [
    "MAX_REACH_M", "MAX_STATES", "PIECE", "Between", "farthest_point", "is_prismatic", "path_between", "path_states",
    "reach", "segment_states", "state_count", "trajectory_between", "trajectory_states", "uniform_states",
]

Between = Callable[[NDArray[np.float64]], NDArray[np.float64]]
"""The states a motion passes at given travel values (ascending) [m], rows of group values."""

PIECE = 4  # states at the peak speed per piece whose speed bound is taken from its ends

# farthest_point of a mesh file's shape by (file, scale, placement): its hull's is the same (the
# extreme vertices are on the hull).
_FARTHEST: dict[tuple[str, tuple[float, ...], bytes], float] = {}

MAX_REACH_M = 1_000.0
"""Farthest [m] collision geometry may lie from a group joint's axis, prismatic travel below it included:
a 50 m crane boom is far within; a kilometre is a description not in metres, whose every motion would
take millions of checks."""

MAX_STATES = 2_000_000
"""States one certified motion may take: a robot point moving 10 km at 5 mm apart (a 50 m boom turning
32 times), some 400 MB while they are checked."""


def reach(robot: Robot, geometry: pin.GeometryModel) -> NDArray[np.float64]:
    """Return per group joint the largest distance [m] any robot collision point moves per unit of the joint.

    For a prismatic joint the answer is 1: a point moves as far as the joint. A joint's mimic
    joints add what they move.
    """
    model = robot.model
    extent = np.zeros(model.njoints)  # per joint: farthest point of the shapes it carries
    for obj in geometry.geometryObjects:
        if obj.parentJoint == 0:
            continue  # world objects do not move
        extent[obj.parentJoint] = max(extent[obj.parentJoint], farthest_point(obj))
    travel = np.zeros(model.njoints)  # how far a prismatic joint can push its children out
    for jid in range(1, model.njoints):
        if is_prismatic(model.joints[jid].shortname()):
            index = model.idx_qs[jid]
            travel[jid] = max(abs(model.lowerPositionLimit[index]), abs(model.upperPositionLimit[index]))
    # Farthest point below each joint, from the leaves up: a child's origin is a fixed offset away.
    below = extent.copy()
    for jid in range(model.njoints - 1, 0, -1):
        parent = model.parents[jid]
        if parent > 0:
            offset = np.linalg.norm(model.jointPlacements[jid].translation) + travel[jid]
            below[parent] = max(below[parent], offset + below[jid])
    def moves(jid: int) -> float:
        return 1.0 if is_prismatic(model.joints[jid].shortname()) else float(below[jid])

    out = [moves(model.getJointId(name)) for name in robot.joint_names]
    # A leader moving by d moves its mimic joints by multiplier * d, and every point below them with it.
    for mimic in robot.mimics:
        out[mimic.leader] += abs(mimic.multiplier) * moves(model.getJointId(mimic.joint))
    worst = int(np.argmax(out))
    if not out[worst] <= MAX_REACH_M:
        raise ConfigError(f"{robot.config.urdf_path}: joint '{robot.joint_names[worst]}' carries collision geometry "
                          f"up to {out[worst]:.6g} m from its axis (prismatic travel below it included); moveplan "
                          f"plans for robots within {MAX_REACH_M:,.0f} m of each joint: are the lengths in metres?")
    return np.array(out)


def state_count(motion_m: float, step_m: float) -> int:
    """Return the states that certify a motion moving robot points `motion_m` [m], `step_m` apart; at least 1.

    Raises:
        InputError: More than MAX_STATES, before any is placed (a goal far beyond a turn, a huge robot).
    """
    count = motion_m / step_m
    if not count <= MAX_STATES:  # NaN too
        raise InputError(f"a motion moves robot points up to {motion_m:.6g} m: certifying it {step_m * 1000:g} mm "
                         f"at a time takes {count:.6g} collision checks, more than moveplan's {MAX_STATES:,} "
                         "(a goal many turns away, or joint limits far apart?)")
    return max(1, int(np.ceil(count)))


def is_prismatic(kind: str) -> bool:
    """Return True for pinocchio's prismatic joint models (JointModelPX/PY/PZ/PrismaticUnaligned)."""
    return kind in ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned")


def farthest_point(obj: pin.GeometryObject) -> float:
    """Return the largest distance from its joint's origin to a point of a collision shape."""
    placement = obj.placement
    # A mesh file's answer is kept for the process: a benchmark asks for a robot's once a problem.
    key = (str(obj.meshPath), tuple(float(v) for v in obj.meshScale), np.asarray(placement.homogeneous).tobytes()) \
        if obj.meshPath else None
    if key is not None and key in _FARTHEST:
        return _FARTHEST[key]
    geometry = obj.geometry
    geometry.computeLocalAABB()  # pinocchio has already scaled a mesh when it loaded it
    lo, hi = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    points = corners @ np.asarray(placement.rotation).T + np.asarray(placement.translation)
    farthest = float(np.max(np.linalg.norm(points, axis=1)))
    if key is not None:
        _FARTHEST[key] = farthest
    return farthest


def segment_states(
    a: NDArray[np.float64], b: NDArray[np.float64], reach_m: NDArray[np.float64], step_m: float
) -> NDArray[np.float64]:
    """Return states from `a` to `b` (both included) along the straight segment, at most `step_m` of motion apart."""
    return straight_states(a, b, state_count(float(np.abs(b - a) @ reach_m), step_m))


def path_states(
    waypoints: NDArray[np.float64], reach_m: NDArray[np.float64], step_m: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return states along the straight segments between waypoints, at most `step_m` of motion apart, and their travel.

    travel[k] [m] bounds how far any robot point moves from the first state to state k: on a
    straight segment every joint moves monotonically, so by exactly its change.
    """
    if len(waypoints) < 2:
        return np.asarray(waypoints), np.zeros(len(waypoints))
    state_count(float(np.abs(np.diff(waypoints, axis=0)).sum(axis=0) @ reach_m), step_m)  # all segments together
    states = np.concatenate([segment_states(a, b, reach_m, step_m)[:-1] for a, b in zip(waypoints[:-1], waypoints[1:],
                                                                                     strict=True)] + [waypoints[-1:]])
    travel = np.concatenate(([0.0], np.cumsum(np.abs(np.diff(states, axis=0)) @ reach_m)))
    return states, travel


def path_between(states: NDArray[np.float64], travel: NDArray[np.float64]) -> Between:
    """Return the states at travel values along the straight segments through `path_states`' states and travel.

    Two neighbouring states lie on one straight segment, along which travel grows linearly.
    """
    def at(values: NDArray[np.float64]) -> NDArray[np.float64]:
        k = np.clip(np.searchsorted(travel, values, side="right") - 1, 0, len(travel) - 2)
        span = travel[k + 1] - travel[k]
        into = np.divide(values - travel[k], span, out=np.zeros(len(values)), where=span > 0.0)
        return np.asarray(states[k] + np.clip(into, 0.0, 1.0)[:, None] * (states[k + 1] - states[k]))

    return at


def trajectory_states(
    trajectory: JointTrajectory, reach_m: NDArray[np.float64], step_m: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return states along the interpolated trajectory, at most `step_m` of robot motion apart, and their travel.

    travel[k] [m] bounds how far any robot point moves from the first state to state k. States
    are spaced by the motion the joints actually cover, not by their peak speed over the whole
    trajectory: the trajectory is cut into pieces of at most PIECE states at the peak speed, and
    within a piece of duration h whose ends move at |v0| and |v1|, a joint whose acceleration never
    exceeds A moves no faster than min(|v0| + A t, |v1| + A (h - t)) <= (|v0| + |v1| + A h) / 2
    (A: its peak over the trajectory, exact for the controller's quintics). Summed over the
    joints with their reach, that bounds every robot point's speed in the piece; states are placed
    at equal increments of the time integral of that bound, none larger than `step_m`.
    """
    knots = trajectory.times_s
    if len(knots) == 1:
        return np.asarray(trajectory.positions), np.zeros(1)
    at_travel, total = _travel_clock(trajectory, reach_m, step_m)
    count = max(1, int(np.ceil(total / step_m)))
    travel = total * (np.arange(count + 1) / count)
    times = at_travel(travel)
    times[0], times[-1] = knots[0], knots[-1]
    return sampler(trajectory)(times, 0)[0], travel


def trajectory_between(trajectory: JointTrajectory, reach_m: NDArray[np.float64], step_m: float) -> Between:
    """Return the states of the interpolated trajectory at travel values, as `trajectory_states` places them.

    The pieces are worked out on the first call: most certified trajectories need no state between.
    """
    @functools.cache
    def clock() -> tuple[Callable[[NDArray[np.float64]], NDArray[np.float64]], Any]:
        return _travel_clock(trajectory, reach_m, step_m)[0], sampler(trajectory)

    def between(travel: NDArray[np.float64]) -> NDArray[np.float64]:
        at_travel, at = clock()
        return np.asarray(at(at_travel(travel), 0)[0])

    return between


def _travel_clock(
    trajectory: JointTrajectory, reach_m: NDArray[np.float64], step_m: float
) -> tuple[Callable[[NDArray[np.float64]], NDArray[np.float64]], float]:
    """Return the time [s] at which the trajectory reaches travel values [m] (see `trajectory_states`), and its travel.

    The travel bound is linear within each piece, so the time of a travel value is too.
    """
    knots = trajectory.times_s
    peak_v, peak_a = peak_rates(trajectory)
    speed, duration = float(peak_v @ reach_m), float(knots[-1] - knots[0])  # [m/s], bounds every point's speed
    state_count(speed * duration, step_m)
    pieces = max(1, int(np.ceil(speed * duration / (PIECE * step_m))))
    h = duration / pieces
    ends = np.linspace(knots[0], knots[-1], pieces + 1)
    rate = np.abs(sampler(trajectory)(ends, 1)[1]) @ reach_m  # [m/s] at the pieces' ends
    motion = np.minimum((rate[:-1] + rate[1:] + float(peak_a @ reach_m) * h) / 2, speed) * h  # per piece [m]
    covered = np.concatenate(([0.0], np.cumsum(motion)))

    def at_travel(travel: NDArray[np.float64]) -> NDArray[np.float64]:
        piece = np.clip(np.searchsorted(covered, travel, side="right") - 1, 0, pieces - 1)
        into = np.divide(travel - covered[piece], motion[piece], out=np.zeros(len(travel)), where=motion[piece] > 0.0)
        return np.asarray(ends[piece] + np.clip(into, 0.0, 1.0) * h, dtype=np.float64)

    return at_travel, float(covered[-1])


def uniform_states(
    trajectory: JointTrajectory, reach_m: NDArray[np.float64], step_m: float
) -> NDArray[np.float64]:
    """Return states along the interpolated trajectory, equally spaced in time, at most `step_m` of robot motion apart.

    Between two samples dt apart a joint moves at most its peak speed times dt, and the
    peaks are exact for the controller's quintic segments. Denser than `trajectory_states`,
    and independent of it: the exact-mesh referee checks these.
    """
    knots = trajectory.times_s
    if len(knots) == 1:
        return np.asarray(trajectory.positions)
    speed = float(peak_rates(trajectory)[0] @ reach_m)  # [m/s], bounds every point's speed
    count = state_count(speed * float(knots[-1] - knots[0]), step_m)
    times = np.linspace(knots[0], knots[-1], count + 1)
    positions, _, _ = sample(trajectory, times, derivatives=0)
    return positions
