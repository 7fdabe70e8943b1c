"""IK on the UR10e: accuracy, limits, nearest solution, collisions, failures, determinism."""

from __future__ import annotations

import dataclasses
import re
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import TABLE_SCENE, UR10E

from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.config.robot_config import RobotConfig, load_robot_config
from moveplan.core.errors import GoalUnreachable, InputError, UnknownName
from moveplan.core.model.kinematics import IkSolution, solve_ik
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene

HOME = np.array([0.0, -np.pi / 2, -np.pi / 2, 0.0, 0.0, 0.0])
# A regular configuration: away from the wrist (wrist_2 = 0), elbow and shoulder singularities.
REGULAR = np.array([0.4, -1.6, 1.3, -1.0, 1.2, 0.5])
TWO_PI = 2 * np.pi


@pytest.fixture(scope="module")
def self_checker(ur10e: Robot) -> CollisionChecker:
    return CollisionChecker(ur10e)


@pytest.fixture(scope="module")
def table_checker(ur10e: Robot) -> CollisionChecker:
    return CollisionChecker(ur10e, load_scene(TABLE_SCENE, ur10e).objects)


def tool_pose(robot: Robot, values: np.ndarray) -> np.ndarray:
    return robot.frame_pose(robot.configuration(values), "tool0")


def pose_errors(robot: Robot, values: np.ndarray, target: np.ndarray) -> tuple[float, float]:
    reached = tool_pose(robot, values)
    angle = np.linalg.norm(pin.log3(reached[:3, :3].T @ target[:3, :3]))
    return float(np.linalg.norm(reached[:3, 3] - target[:3, 3])), float(angle)


def random_free_values(
    robot: Robot, checker: CollisionChecker, count: int, seed: int
) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    found: list[np.ndarray] = []
    while len(found) < count:
        values = rng.uniform(robot.lower, robot.upper)
        if not checker.in_collision(robot.configuration(values)):
            found.append(values)
    return found


def is_free_with(robot: Robot, checker: CollisionChecker) -> Callable[[np.ndarray], bool]:
    return lambda values: not checker.in_collision(robot.configuration(values))


def test_random_reachable_poses_are_reached_within_tolerance_inside_limits_and_free(
    ur10e: Robot, self_checker: CollisionChecker
) -> None:
    is_free = is_free_with(ur10e, self_checker)
    for values in random_free_values(ur10e, self_checker, 40, seed=1):
        target = tool_pose(ur10e, values)
        solution = solve_ik(ur10e, target, "tool0", HOME, is_free=is_free)
        position, angle = pose_errors(ur10e, solution.values, target)
        assert position <= 1e-4 and angle <= 1e-3
        np.testing.assert_allclose([solution.position_error_m, solution.orientation_error_rad],
                                   [position, angle], atol=1e-9)
        assert np.all(solution.values >= ur10e.lower) and np.all(solution.values <= ur10e.upper)
        assert is_free(solution.values)


def test_tighter_tolerances_are_met(ur10e: Robot) -> None:
    target = tool_pose(ur10e, REGULAR + 0.3)
    solution = solve_ik(ur10e, target, "tool0", REGULAR, position_tolerance=1e-7,
                        orientation_tolerance=1e-7)
    position, angle = pose_errors(ur10e, solution.values, target)
    assert position <= 1e-7 and angle <= 1e-7


def test_narrowed_elbow_limits_give_the_other_elbow_branch(
    ur10e_config: RobotConfig, ur10e: Robot
) -> None:
    elbow = ur10e_config.limits["elbow_joint"]
    narrowed = dataclasses.replace(ur10e_config, limits={
        **ur10e_config.limits, "elbow_joint": dataclasses.replace(elbow, lower=-np.pi, upper=0.0)})
    robot = Robot(narrowed)
    target = tool_pose(ur10e, REGULAR)  # elbow at +1.3, outside the narrowed range
    solution = solve_ik(robot, target, "tool0", REGULAR)
    assert -np.pi <= solution.values[2] <= 0.0
    assert np.all(solution.values >= robot.lower) and np.all(solution.values <= robot.upper)
    position, angle = pose_errors(ur10e, solution.values, target)
    assert position <= 1e-4 and angle <= 1e-3


def test_small_target_changes_keep_the_start_branch_without_elbow_or_wrist_flip(
    ur10e: Robot,
) -> None:
    rng = np.random.default_rng(7)
    start_pose = tool_pose(ur10e, REGULAR)
    for _ in range(20):
        twist = np.concatenate([rng.normal(0, 0.01, 3), rng.normal(0, 0.02, 3)])  # [m], [rad]
        nudge = pin.exp6(twist).homogeneous
        solution = solve_ik(ur10e, start_pose @ nudge, "tool0", REGULAR)
        assert solution.attempts == 1
        assert np.max(np.abs(solution.values - REGULAR)) < 0.1


def test_solution_from_a_start_on_another_branch_stays_on_that_branch(ur10e: Robot) -> None:
    # The same pose as REGULAR, reached with the elbow and wrist flipped: starting next to that
    # solution must return it, not REGULAR's branch.
    flipped = solve_ik(ur10e, tool_pose(ur10e, REGULAR), "tool0", REGULAR,
                       is_free=lambda values: bool(values[2] < 0)).values
    nudge = pin.exp6(np.array([0.005, -0.005, 0.005, 0.01, 0.0, -0.01])).homogeneous
    solution = solve_ik(ur10e, tool_pose(ur10e, flipped) @ nudge, "tool0", flipped)
    assert np.max(np.abs(solution.values - flipped)) < 0.1


def test_multiturn_joints_take_the_turn_nearest_the_start(
    ur10e: Robot, self_checker: CollisionChecker
) -> None:
    start = np.array([4.0, -1.2, 1.4, -4.5, 1.2, 5.0])
    multiturn = np.flatnonzero(ur10e.upper - ur10e.lower > TWO_PI)
    assert multiturn.tolist() == [0, 1, 3, 4, 5]  # all but the elbow
    for values in random_free_values(ur10e, self_checker, 15, seed=2):
        solution = solve_ik(ur10e, tool_pose(ur10e, values), "tool0", start)
        for i in multiturn:
            value = solution.values[i]
            for other in (value - TWO_PI, value + TWO_PI):
                # A turn nearer the start would have been taken unless it leaves the limits.
                if ur10e.lower[i] <= other <= ur10e.upper[i]:
                    assert abs(value - start[i]) <= abs(other - start[i])


def test_a_full_turn_of_the_wrist_is_not_added_when_the_start_is_near_it(ur10e: Robot) -> None:
    start = REGULAR.copy()
    start[5] = 6.0
    goal = start.copy()
    goal[5] = 6.0 + 0.1 - TWO_PI  # the same pose as 6.1, which is within the limit
    solution = solve_ik(ur10e, tool_pose(ur10e, goal), "tool0", start)
    np.testing.assert_allclose(solution.values[5], 6.1, atol=1e-4)


def test_continuous_joint_turns_across_pi_and_is_reported_within_pi(tmp_path: Path) -> None:
    config = tmp_path / "ur10e"
    shutil.copytree(UR10E, config)
    urdf = config / "ur10e.urdf"
    urdf.write_text(urdf.read_text().replace('<joint name="wrist_3_joint" type="revolute">',
                                             '<joint name="wrist_3_joint" type="continuous">'))
    robot = Robot(load_robot_config(config))
    assert robot.continuous.tolist() == [False] * 5 + [True]
    start = REGULAR.copy()
    start[5] = 3.0
    goal = start.copy()
    goal[5] = 3.3  # past +pi: the descent must not stop at the (-pi, pi) bounds
    solution = solve_ik(robot, tool_pose(robot, goal), "tool0", start)
    assert solution.attempts == 1
    np.testing.assert_allclose(solution.values[5], 3.3 - TWO_PI, atol=1e-4)


def test_a_colliding_local_solution_is_replaced_by_a_free_one(ur10e: Robot) -> None:
    target = tool_pose(ur10e, REGULAR)

    def elbow_down_only(values: np.ndarray) -> bool:
        return bool(values[2] < 0)

    solution = solve_ik(ur10e, target, "tool0", REGULAR, is_free=elbow_down_only)
    assert solution.values[2] < 0 and solution.attempts > 1
    position, angle = pose_errors(ur10e, solution.values, target)
    assert position <= 1e-4 and angle <= 1e-3


def test_pose_reachable_only_in_collision_raises_and_names_the_pair(
    ur10e: Robot, table_checker: CollisionChecker
) -> None:
    below_table = np.eye(4)
    below_table[:3, 3] = [0.6, 0.2, -0.3]
    expected = r"all \d+ solutions found collide \(nearest the start: \w+ touches table\) after 10"
    with pytest.raises(GoalUnreachable, match=expected):
        solve_ik(ur10e, below_table, "tool0", HOME, is_free=is_free_with(ur10e, table_checker),
                 colliding_pair=table_checker.colliding_pair, max_attempts=10)


def test_all_solutions_colliding_without_pair_callback_says_so(ur10e: Robot) -> None:
    with pytest.raises(GoalUnreachable, match=r"all \d solutions found collide after 3 attempts$"):
        solve_ik(ur10e, tool_pose(ur10e, REGULAR), "tool0", REGULAR, is_free=lambda values: False,
                 max_attempts=3)


def test_unreachable_pose_raises_with_the_closest_distance_reached(ur10e: Robot) -> None:
    far = np.eye(4)
    far[:3, 3] = [3.0, 0.0, 0.5]
    with pytest.raises(GoalUnreachable) as error:
        solve_ik(ur10e, far, "tool0", HOME, max_attempts=12)
    message = str(error.value)
    match = re.fullmatch(r"no IK solution for link 'tool0' at \[3\.000 0\.000 0\.500\]: "
                         r"closest reached ([\d.]+) mm, ([\d.e-]+) rad away after 12 attempts",
                         message)
    assert match, message
    # The UR10e reaches about 1.3 m from its shoulder, so it stays well over 1.5 m short.
    assert 1500 < float(match.group(1)) < 2000


def test_same_seed_gives_the_same_solution(ur10e: Robot) -> None:
    target = tool_pose(ur10e, REGULAR)

    def solve(seed: int) -> IkSolution:
        return solve_ik(ur10e, target, "tool0", REGULAR, is_free=lambda values: bool(values[2] < 0),
                        seed=seed)

    first, again = solve(3), solve(3)
    assert first.attempts > 1  # the random restarts ran
    np.testing.assert_array_equal(first.values, again.values)
    assert first.attempts == again.attempts


def test_exhaustive_search_is_at_least_as_near_as_the_default(ur10e: Robot) -> None:
    target = tool_pose(ur10e, np.array([1.9, -0.8, 2.0, -2.5, -1.1, 2.2]))
    quick = solve_ik(ur10e, target, "tool0", HOME)
    thorough = solve_ik(ur10e, target, "tool0", HOME, exhaustive=True, max_attempts=20)
    assert thorough.attempts == 20
    assert np.linalg.norm(thorough.values - HOME) <= np.linalg.norm(quick.values - HOME) + 1e-9


def test_solution_values_are_read_only(ur10e: Robot) -> None:
    solution = solve_ik(ur10e, tool_pose(ur10e, REGULAR), "tool0", REGULAR)
    with pytest.raises(ValueError):
        solution.values[0] = 1.0


def test_unknown_link_lists_the_known_links(ur10e: Robot) -> None:
    with pytest.raises(UnknownName, match="link 'tol0' not found.*tool0"):
        solve_ik(ur10e, np.eye(4), "tol0", HOME)


def test_target_that_is_not_a_rigid_transform_is_rejected(ur10e: Robot) -> None:
    scaled = tool_pose(ur10e, REGULAR)
    scaled[:3, :3] *= 2.0
    with pytest.raises(InputError, match="tool0.*not a finite rigid transform"):
        solve_ik(ur10e, scaled, "tool0", HOME)
