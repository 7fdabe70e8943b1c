"""Certification places states by the motion travelled and skips what clearances prove free: never a colliding one."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from moveplan.core.collision import _certify as certify
from moveplan.core.collision.motion import CERTIFY_STEP_M, MotionChecker, exact_checks, scene_checks
from moveplan.core.collision.sphere_filter import SphereFilter
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene
from moveplan.core.timing import time_parameterize
from moveplan.core.trajectory import sample
from moveplan.core.types import JointTrajectory

MBM = ROOT / "tests" / "data" / "mbm"


@pytest.fixture(scope="module")
def shelf() -> tuple[MotionChecker, MotionChecker]:
    """The Panda (exact meshes) before MotionBenchMaker's bookshelf, and the exact-mesh referee."""
    robot = Robot(load_robot_config(MBM / "panda_robot"))
    scene = load_scene(MBM / "bookshelf_scene0093.yaml", robot)
    checks = scene_checks(robot, scene, "exact", robot.neutral())
    assert isinstance(checks.spheres, SphereFilter)
    return checks, exact_checks(checks, scene)


def _waypoints(robot: Robot, fractions: list[list[float]]) -> np.ndarray:
    """Return joint values at the given fractions of each joint's range (rows: waypoints)."""
    return robot.lower + np.clip(np.array(fractions), 0.0, 1.0) * (robot.upper - robot.lower)


def _timed(robot: Robot, waypoints: np.ndarray) -> JointTrajectory:
    return time_parameterize(robot.joint_names, waypoints, robot.max_velocity, robot.max_acceleration)


_FRACTIONS = st.lists(st.lists(st.floats(0.05, 0.95), min_size=7, max_size=7), min_size=2, max_size=4)
_SETTINGS = settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


def _corners(checks: MotionChecker) -> list[tuple[int, np.ndarray]]:
    """Return per robot shape its joint and its box corners in that joint's frame (what reach bounds)."""
    out = []
    for obj in checks.checker.geometry.geometryObjects:
        if obj.parentJoint == 0:
            continue
        obj.geometry.computeLocalAABB()
        lo, hi = np.asarray(obj.geometry.aabb_local.min_), np.asarray(obj.geometry.aabb_local.max_)
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        out.append((obj.parentJoint, corners @ np.asarray(obj.placement.rotation).T + obj.placement.translation))
    return out


@_SETTINGS
@given(fractions=_FRACTIONS)
def test_certified_states_are_5_mm_of_travel_apart_and_travel_bounds_every_robot_point(
    shelf: tuple[MotionChecker, MotionChecker], fractions: list[list[float]]
) -> None:
    checks, _ = shelf
    robot = checks.robot
    trajectory = _timed(robot, _waypoints(robot, fractions))
    states, travel = certify.trajectory_states(trajectory, checks.reach, CERTIFY_STEP_M)
    assert np.allclose(states[[0, -1]], trajectory.positions[[0, -1]])
    assert np.all(np.diff(travel) <= CERTIFY_STEP_M * (1 + 1e-12))
    # Fewer states than spacing them in time at the peak speed, as before.
    assert len(states) <= len(certify.uniform_states(trajectory, checks.reach, CERTIFY_STEP_M))
    # The real motion, finely sampled: every shape's box corners, each point's path length so far.
    times = np.linspace(trajectory.times_s[0], trajectory.times_s[-1], 20 * len(states))
    fine, _, _ = sample(trajectory, times, derivatives=0)
    corners = _corners(checks)
    data = robot.model.createData()
    placed = []
    for values in fine:
        pin.forwardKinematics(robot.model, data, robot.configuration(values, checks.base))
        placed.append(np.concatenate([c @ np.asarray(data.oMi[j].rotation).T + data.oMi[j].translation
                                      for j, c in corners]))
    steps = np.linalg.norm(np.diff(np.array(placed), axis=0), axis=2)  # (samples - 1, points)
    moved = np.vstack((np.zeros(steps.shape[1]), np.cumsum(steps, axis=0)))
    assert moved[-1].max() <= travel[-1] + 1e-9


@_SETTINGS
@given(fractions=_FRACTIONS)
def test_the_filters_compiled_placement_gives_numpys_states(
    shelf: tuple[MotionChecker, MotionChecker], fractions: list[list[float]]
) -> None:
    checks, _ = shelf
    spheres = checks.spheres
    assert isinstance(spheres, SphereFilter)
    trajectory = _timed(checks.robot, _waypoints(checks.robot, fractions))
    states, travel = certify.trajectory_states(trajectory, checks.reach, CERTIFY_STEP_M)
    compiled, compiled_travel = spheres.trajectory_states(trajectory, checks.reach, CERTIFY_STEP_M)
    assert compiled.shape == states.shape
    assert np.allclose(compiled, states, rtol=0.0, atol=1e-12) and np.allclose(compiled_travel, travel, atol=1e-12)


@_SETTINGS
@given(fractions=_FRACTIONS)
def test_every_state_a_clearance_skips_is_one_the_spheres_clear(
    shelf: tuple[MotionChecker, MotionChecker], fractions: list[list[float]]
) -> None:
    checks, _ = shelf
    robot = checks.robot
    spheres = checks.spheres
    assert isinstance(spheres, SphereFilter)
    for states, travel in (certify.trajectory_states(_timed(robot, _waypoints(robot, fractions)), checks.reach,
                                                     CERTIFY_STEP_M),
                           certify.path_states(_waypoints(robot, fractions), checks.reach, CERTIFY_STEP_M / 10)):
        walked, _, _ = spheres.certify(states, travel, CERTIFY_STEP_M)
        judged, _ = spheres.classify(states)
        assert np.array_equal(walked, judged)


@_SETTINGS
@given(fractions=_FRACTIONS)
def test_a_trajectory_certified_free_has_every_state_free_under_the_exact_meshes(
    shelf: tuple[MotionChecker, MotionChecker], fractions: list[list[float]]
) -> None:
    checks, referee = shelf
    robot = checks.robot
    waypoints = _waypoints(robot, fractions)
    trajectory = _timed(robot, waypoints)
    if checks.first_collision_on_trajectory(trajectory) is None:
        states, travel = certify.trajectory_states(trajectory, checks.reach, CERTIFY_STEP_M)
        assert referee.free(states).all()
        assert referee.first_collision_on_trajectory(trajectory) is None
        # Between the states too: ten times as dense.
        between = certify.trajectory_between(trajectory, checks.reach, CERTIFY_STEP_M)
        assert referee.free(between(np.linspace(0.0, travel[-1], 10 * len(states)))).all()
    if checks.first_collision_on_path(waypoints) is None:
        states, travel = certify.path_states(waypoints, checks.reach, CERTIFY_STEP_M)
        assert referee.free(states).all()
        between = certify.path_between(states, travel)
        assert referee.free(between(np.linspace(0.0, travel[-1], 10 * len(states)))).all()


@_SETTINGS
@given(fractions=_FRACTIONS)
def test_every_radius_the_spheres_give_is_at_most_the_exact_distance(
    shelf: tuple[MotionChecker, MotionChecker], fractions: list[list[float]]
) -> None:
    checks, referee = shelf
    spheres = checks.spheres
    assert isinstance(spheres, SphereFilter)
    states, travel = certify.path_states(_waypoints(checks.robot, fractions), checks.reach, CERTIFY_STEP_M)
    verdict, q, radius = spheres.certify(states, travel, CERTIFY_STEP_M)
    model, checker = checks.robot.model, referee.checker
    data = model.createData()
    for k in np.linspace(0, len(states) - 1, 25).astype(int):
        if radius[k] == 0.0:
            continue
        pin.computeDistances(model, data, checker.geometry, checker.data, q[k])
        exact = min(result.min_distance for result in checker.data.distanceResults)
        assert radius[k] <= exact + 1e-9


def test_a_trajectory_through_the_shelf_is_found_colliding(shelf: tuple[MotionChecker, MotionChecker]) -> None:
    checks, referee = shelf
    robot = checks.robot
    # From one side of the shelf to the other, through its boards: found by certification and referee alike.
    waypoints = _waypoints(robot, [[0.1, 0.5, 0.5, 0.2, 0.5, 0.6, 0.5], [0.9, 0.7, 0.5, 0.6, 0.5, 0.6, 0.5]])
    states = certify.path_states(waypoints, checks.reach, CERTIFY_STEP_M / 10)[0]
    assert not referee.free(states).all(), "pick waypoints whose segment crosses the shelf"
    hit = checks.first_collision_on_trajectory(_timed(robot, waypoints))
    assert hit is not None and checks.colliding_pair(hit) is not None
