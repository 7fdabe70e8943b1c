"""A certified motion is free at every instant, not only at its states: a graze between two of them is found."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

from moveplan.core.collision import _certify as certify
from moveplan.core.collision._cover import RUN
from moveplan.core.collision.motion import CERTIFY_STEP_M, MotionChecker, scene_checks
from moveplan.core.collision.sphere_filter import SphereFilter
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene import Scene
from moveplan.core.timing import time_parameterize
from moveplan.core.types import CollisionObject, Shape

MBM = ROOT / "tests" / "data" / "mbm"
BALL_M, GRAIN_M = 0.01, 0.0005  # a ball the hand holds, and a grain of grit in its way
OFFSET = np.eye(4)
OFFSET[2, 3] = 0.2  # past the fingertips
HELD = CollisionObject("held ball", Shape("sphere", (BALL_M,)), OFFSET, link="panda_hand",
                       touch_links=("panda_leftfinger", "panda_rightfinger"))
READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])


@pytest.fixture(scope="module")
def robot() -> Robot:
    """The Panda of MotionBenchMaker's problems."""
    return Robot(load_robot_config(MBM / "panda_robot"))


def _waypoints() -> np.ndarray:
    """Return a sweep of the wrist, the arm held ready: the held ball is the point that moves farthest."""
    return np.array([READY + [0, 0, 0, 0, 0, -0.4, 0], READY + [0, 0, 0, 0, 0, 0.4, 0]])


def _motion(robot: Robot, kind: str) -> tuple[np.ndarray, np.ndarray, certify.Between]:
    """Return the certified states of the sweep (timed, or along its straight segment), their travel, and between."""
    reach = MotionChecker(robot, scene_checks(robot, _scene(()), "exact", robot.neutral()).checker,
                          robot.neutral()).reach
    if kind == "trajectory":
        trajectory = _timed(robot)
        states, travel = certify.trajectory_states(trajectory, reach, CERTIFY_STEP_M)
        return states, travel, certify.trajectory_between(trajectory, reach, CERTIFY_STEP_M)
    states, travel = certify.path_states(_waypoints(), reach, CERTIFY_STEP_M)
    return states, travel, certify.path_between(states, travel)


def _timed(robot: Robot):  # type: ignore[no-untyped-def]
    return time_parameterize(robot.joint_names, _waypoints(), robot.max_velocity, robot.max_acceleration)


def _scene(objects: tuple[CollisionObject, ...]) -> Scene:
    return Scene(source="graze test", frames=(), objects=(HELD, *objects), anchors={})


def _ball_centre(robot: Robot) -> Callable[[np.ndarray], np.ndarray]:
    """Return the held ball's centre [m] at group states (rows)."""
    data = robot.model.createData()
    hand = robot.model.getFrameId("panda_hand")

    def at(states: np.ndarray) -> np.ndarray:
        out = []
        for values in states:
            pin.framesForwardKinematics(robot.model, data, robot.configuration(values, robot.neutral()))
            out.append((data.oMf[hand] * pin.SE3(OFFSET)).translation.copy())
        return np.array(out)

    return at


def _grain(robot: Robot, kind: str, depth_m: float, at: int = 0) -> tuple[CollisionObject, float, float]:
    """Return a grain of grit the ball passes `depth_m` into (negative: that far clear) halfway between two states.

    The two states are the motion's middle ones, moved `at` states on.

    Also returns the closest the ball comes to it at a certified state and over the whole motion [m].
    """
    states, travel, between = _motion(robot, kind)
    centre = _ball_centre(robot)
    k = len(states) // 2 + at
    ends = centre(states[[k, k + 1]])
    middle = centre(between(np.array([(travel[k] + travel[k + 1]) / 2])))[0]
    along = (ends[1] - ends[0]) / np.linalg.norm(ends[1] - ends[0])
    down = np.array([0.0, 0.0, -1.0])
    side = down - (down @ along) * along  # square to the motion: the ball passes it closest here
    place = np.eye(4)
    place[:3, 3] = middle + (BALL_M + GRAIN_M - depth_m) * side / np.linalg.norm(side)
    grain = CollisionObject("grain", Shape("sphere", (GRAIN_M,)), place)

    def gap(values: np.ndarray) -> float:
        return float(np.min(np.linalg.norm(centre(values) - place[:3, 3], axis=1)) - BALL_M - GRAIN_M)

    fine = between(np.linspace(travel[k - 1], travel[k + 2], 600))
    return grain, gap(states), gap(fine)


def _checks(robot: Robot, grain: CollisionObject, filtered: bool) -> MotionChecker:
    checks = scene_checks(robot, _scene((grain,)), "exact", robot.neutral())
    if filtered:
        assert isinstance(checks.spheres, SphereFilter)
        return checks
    return MotionChecker(robot, checks.checker, checks.base)  # coal alone: no clearances to start from


def _first_collision(checks: MotionChecker, robot: Robot, kind: str, between: bool = True) -> np.ndarray | None:
    if kind == "trajectory":
        return checks.first_collision_on_trajectory(_timed(robot), between=between)
    return checks.first_collision_on_path(_waypoints()) if between else None


@pytest.mark.parametrize("filtered", [True, False], ids=["sphere filter", "coal alone"])
@pytest.mark.parametrize("kind", ["trajectory", "path"])
@pytest.mark.parametrize("at", range(RUN), ids=lambda at: f"state {at} on")
def test_a_graze_of_tens_of_micrometres_between_two_certified_states_is_found(
    robot: Robot, kind: str, filtered: bool, at: int
) -> None:
    # Coal alone proves a run of RUN states from its middle one: the grain sits at every place in a run.
    grain, at_states, closest = _grain(robot, kind, depth_m=20e-6, at=at)
    assert at_states > 1e-4, "every certified state clears the grain by more than 0.1 mm"
    assert -30e-6 < closest < -10e-6, "between two of them the ball sinks 10-30 um into it"
    checks = _checks(robot, grain, filtered)
    if kind == "trajectory":
        assert _first_collision(checks, robot, kind, between=False) is None  # the states alone pass
    hit = _first_collision(checks, robot, kind)
    assert hit is not None
    assert checks.colliding_pair(hit) == ("panda_hand", "grain")  # what the hand holds is the hand's


@pytest.mark.parametrize("filtered", [True, False], ids=["sphere filter", "coal alone"])
@pytest.mark.parametrize("kind", ["trajectory", "path"])
def test_a_motion_passing_twenty_micrometres_clear_is_certified_free(robot: Robot, kind: str, filtered: bool) -> None:
    grain, _, closest = _grain(robot, kind, depth_m=-20e-6)
    assert 10e-6 < closest < 30e-6
    assert _first_collision(_checks(robot, grain, filtered), robot, kind) is None


@pytest.mark.parametrize("kind", ["trajectory", "path"])
def test_coal_alone_certifies_a_motion_clear_of_everything_with_a_check_per_run_of_states(
    robot: Robot, kind: str
) -> None:
    states, _, _ = _motion(robot, kind)
    checks = _checks(robot, _grain(robot, kind, depth_m=-0.1)[0], filtered=False)  # the grain 10 cm away
    batches = _counting(checks)
    assert _first_collision(checks, robot, kind) is None
    checked = sum(batch.shape[1] for batch in batches)
    assert checked <= len(states) / RUN + 1 < len(states) / 2, "one coal check proves a run of states"


def test_coal_alone_checks_an_edge_halving_it_so_that_a_blocked_edge_fails_early(robot: Robot) -> None:
    """OMPL's DiscreteMotionValidator::checkMotion checks the end state, then halves the edge again and again."""
    states, _, _ = _motion(robot, "path")
    checks = _checks(robot, _grain(robot, "path", depth_m=0.002)[0], filtered=False)
    batches = _counting(checks)
    a, b = states[0], states[-1]
    resolution = float(np.max(np.abs(b - a))) / 64  # 64 states after a, the grain in the middle
    assert not checks.edge_free(a, b, resolution, conservative=True)
    [batch] = batches
    end, middle = (robot.configuration(values, robot.neutral()) for values in (b, (a + b) / 2))
    assert np.allclose(batch[:, 0], end) and np.allclose(batch[:, 1], middle)
    assert not checks.state_free((a + b) / 2, conservative=True)  # the second state coal checks collides


def _counting(checks: MotionChecker) -> list[np.ndarray]:
    """Return a list that gets each batch of configurations (nq, k) the first coal stage judges, in order."""
    batches: list[np.ndarray] = []
    stage = checks._stages[0]
    judge = stage.free_batch

    def counted(q: np.ndarray, *args: object, **kwargs: object) -> np.ndarray:
        batches.append(q)
        return judge(q, *args, **kwargs)

    stage.free_batch = counted  # type: ignore[method-assign]
    return batches
