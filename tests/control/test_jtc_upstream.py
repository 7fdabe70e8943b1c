"""ros2_controllers' JointTrajectoryController tolerance tests (Jazzy branch), rebuilt as moveplan scenarios.

One test per upstream case, named after it; its docstring names the upstream file and case. Sources:
ros-controls/ros2_controllers, branch jazzy at ed360c97d (after 4.42.1), joint_trajectory_controller/test/.

The fixture (test_trajectory_controller_utils.hpp) becomes: joints joint1..joint3 at 1.1, 2.1, 3.1, 100 Hz,
command [position] and state [position, velocity] unless a case varies them, and
allow_nonzero_velocity_at_trajectory_end true (SetUpAndActivateTrajectoryController adds it unless a case sets
it). Its hardware mirrors commands into states (MirrorPlant) or, with separate_cmd_and_state_values, never moves
(FrozenPlant, whatever the command interface). No MoveIt is in the loop: no start-state check, no duration
monitor. An action goal carries its goal_time_tolerance (mostly 1.0 s), which replaces constraints.goal_time.
Upstream's topic-interface cases (test_trajectory_controller.cpp) are sent as action goals: moveplan simulates
goals, and the verdict stands for the hold upstream observes. moveplan's report ends on the cycle that decides;
JTC then holds the position it read on that cycle (set_hold_position), the report's last actual position.

Known difference, not a failing test: with goal_time 0 JTC waits for the goal tolerance forever; moveplan ends
such a goal WAIT_LIMIT_S (10 s) after the last point as TIMED_OUT. No rebuilt case gets there (see the comments).

Not rebuilt, test_trajectory_actions.cpp:
- preempted_goal_receives_aborted_result: preemption by a second action goal; moveplan runs one goal at a time.
- test_cancel_hold_position: cancels the goal through the action client (ROS plumbing).
- test_cancel_decelerate_to_hold_position: action cancel with decelerate_on_cancel; neither is modelled.
- test_cancel_decelerate_fallback: action cancel with decelerate_on_cancel; neither is modelled.
- deactivate_controller_aborts_action: lifecycle deactivation while a goal runs (ROS plumbing).
- test_scaling_execution_time_succeeds with factors 0.25, 0.87, 2.0: speed scaling is not modelled (1.0 is).
- test_scaling_sampling_is_correct: sampling under speed scaling, not modelled and not about tolerances.
Not rebuilt, test_trajectory_controller.cpp:
- invalid_robot_description: URDF parsing at configure, no tolerance.
- continuous_joint_without_urdf_limits: URDF joint types at configure, no tolerance.
- check_interface_names: ROS interface names.
- check_interface_names_with_command_joints: ROS interface names; command_joints not modelled.
- check_interface_names_with_command_joints_less_than_dof: same.
- check_interface_names_with_command_joints_greater_than_dof: same.
- check_interface_names_with_command_joints_different_than_dof: same.
- activate: lifecycle.
- cleanup: lifecycle.
- cleanup_after_configure: lifecycle.
- correct_initialization_using_parameters: deactivate/reactivate hold (lifecycle), no tolerance.
- state_topic_consistency: the controller_state topic.
- state_topic_consistency_command_joints_less_than_dof: the controller_state topic.
- time_from_start_populated: the controller_state topic.
- update_dynamic_parameters: PID gain reload.
- hold_on_startup: activation hold, no goal.
- compute_error_angle_wraparound_true: error arithmetic, no tolerance (continuous joints: test_controller.py).
- compute_error_angle_wraparound_false: same.
- position_error_not_angle_wraparound: error and PID sign, no tolerance.
- position_error_angle_wraparound: same (A16 in test_controller.py).
- trajectory_error_command_joints_less_than_dof: command_joints not modelled.
- trajectory_error_command_joints_less_than_dof_jumbled: command_joints not modelled.
- accept_correct_cmd_timeout: cmd_timeout is not modelled (parse_controllers accepts the key and drops it).
- decline_false_cmd_timeout: cmd_timeout is not modelled.
- no_timeout: cmd_timeout (0) on a topic trajectory; not modelled.
- timeout: cmd_timeout hold on a topic trajectory; not modelled.
- use_closed_loop_pid: which interfaces use the PID adapter (test_controller.py covers the plant).
- missing_positions_message_accepted: allow_integration_in_goal_trajectories; a moveplan goal always has positions.
- test_trajectory_replace: replacing a running topic trajectory.
- test_ignore_old_trajectory: header stamps; moveplan's goals start now.
- test_ignore_partial_old_trajectory: header stamps.
- test_execute_partial_traj_in_future: header stamps (and disabled upstream).
- test_jump_when_state_tracking_error_updated: interpolate_from_desired_state, no tolerance.
- test_no_jump_when_state_tracking_error_not_updated: same.
- test_hw_states_has_offset_first_controller_start: activation state, no tolerance.
- test_hw_states_has_offset_later_controller_start: activation state, no tolerance.
- test_set_last_command_interface_on_activation_false: activation state, no tolerance.
- incorrect_initialization_using_interface_parameters: interface combinations (tests/config covers them).
- setting_scaling_factor_works_correctly: speed scaling, not modelled.
- scaling_factor_from_param: speed scaling.
- wrong_scaling_state_interface_parameter_controller_fails_activation: speed scaling.
- wrong_scaling_command_interface_parameter_controller_fails_activation: speed scaling.
- scaling_state_interface_sets_value: speed scaling.
- scaling_command_interface_sets_value: speed scaling.
- activate_with_scaling_interfaces: speed scaling.
- decelerate_to_hold_position_fallback_no_velocity_state: decelerate_on_cancel, not modelled.
- decelerate_to_hold_position_fallback_zero_max_decel: same.
- decelerate_to_hold_position_positive_velocity: same.
- decelerate_to_hold_position_negative_velocity: same.
- decelerate_to_hold_position_per_joint_calculation: same.
- decelerate_to_hold_position_velocity_command_ramps_to_zero: same.
test_tolerances.cpp: every case is rebuilt.
"""

from pathlib import Path

import numpy as np
import pytest

from moveplan.core.config.controllers import ControllerConfig, ExecutionConfig, parse_controllers
from moveplan.core.control.controller import Disturbance, ExecutionReport, simulate
from moveplan.core.control.goal_validation import validate_goal, validate_goal_end
from moveplan.core.control.plants import FrozenPlant, MirrorPlant, Plant
from moveplan.core.control.tolerances import (
    SegmentTolerances,
    StateTolerance,
    goal_segment_tolerances,
    segment_tolerances,
)
from moveplan.core.errors import InputError, UnknownName
from moveplan.core.types import GoalTolerances, JointTolerance, JointTrajectory

JOINTS = ("joint1", "joint2", "joint3")
INITIAL = np.array([1.1, 2.1, 3.1])  # INITIAL_POS_JOINTS
COMMON_THRESHOLD = 0.001
# The upstream tests run JTC alone: no MoveIt start-state check, no duration monitor.
JTC_ONLY = ExecutionConfig(allowed_start_tolerance=0.0, execution_duration_monitoring=False)


def _interfaces(*combinations):
    return [pytest.param(commands, states, id=f"{'_'.join(commands)}-{'_'.join(states)}")
            for commands, states in combinations]


P, PV, PVA = ("position",), ("position", "velocity"), ("position", "velocity", "acceleration")
# INSTANTIATE_TEST_SUITE_P of test_trajectory_actions.cpp and of test_trajectory_controller.cpp.
ACTION_INTERFACES = _interfaces((P, P), (P, PV), (P, PVA), (PV, P), (PV, PV), (PV, PVA),
                                (("velocity",), PV), (("velocity",), PVA), (("effort",), PV), (("effort",), PVA))
CONTROLLER_INTERFACES = _interfaces((P, P), (P, PV), (P, PVA), (PV, P), (PV, PV), (PV, PVA), (PVA, P), (PVA, PV),
                                    (PVA, PVA), (("velocity",), PV), (("velocity",), PVA), (("effort",), PV),
                                    (("effort",), PVA), (("position", "effort"), PV), (("position", "effort"), PVA))


def jtc(commands=P, states=PV, *, trajectory=0.0, goal=0.0, goal_time=0.0, stopped_velocity=0.01,
        allow_nonzero_velocity=True) -> ControllerConfig:
    """The fixture's controller; keywords are the constraints.* parameters a case sets."""
    return ControllerConfig(
        name="test_joint_trajectory_controller", joints=JOINTS, update_rate_hz=100.0,
        command_interfaces=commands, state_interfaces=states, goal_time_s=goal_time,
        stopped_velocity_tolerance=stopped_velocity, trajectory_tolerance=dict.fromkeys(JOINTS, trajectory),
        goal_tolerance=dict.fromkeys(JOINTS, goal), gains={},
        allow_nonzero_velocity_at_trajectory_end=allow_nonzero_velocity,
    )


def points(times, positions, velocities=None, accelerations=None, joints=JOINTS) -> JointTrajectory:
    """A goal's points; without velocities JTC interpolates positions linearly."""
    positions = np.atleast_2d(np.asarray(positions, dtype=float))
    zeros = np.zeros_like(positions)
    return JointTrajectory(
        joints, times, positions,
        zeros if velocities is None else np.atleast_2d(velocities),
        zeros if accelerations is None else np.atleast_2d(accelerations),
        has_velocities=velocities is not None, has_accelerations=accelerations is not None,
    )


def send_goal(trajectory: JointTrajectory, controller: ControllerConfig, plant: Plant, *, goal_time: float,
              path=(), goal=(), start=INITIAL, disturbances=()) -> ExecutionReport:
    """sendActionGoal: the goal is validated as JTC accepts it (InputError: rejected), then executed."""
    validate_goal(trajectory, "goal")
    validate_goal_end(trajectory, controller.allow_nonzero_velocity_at_trajectory_end, "goal")
    return simulate(trajectory, controller, JTC_ONLY, plant, start_positions=start, disturbances=disturbances,
                    goal_tolerances=GoalTolerances(tuple(path), tuple(goal), goal_time))


def held(report: ExecutionReport) -> np.ndarray:
    """The position JTC holds after an abort: the one it read on the aborting cycle, where the report ends."""
    return report.actual_positions[-1]


def controller_from_yaml(tmp_path: Path, parameters: str) -> ControllerConfig:
    """The fixture's controller read from a ros2_controllers.yaml with extra `parameters` (indented 4)."""
    path = tmp_path / "ros2_controllers.yaml"
    path.write_text(
        "controller_manager:\n  ros__parameters:\n    update_rate: 100\n"
        "    test_joint_trajectory_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n"
        "test_joint_trajectory_controller:\n  ros__parameters:\n    joints: [joint1, joint2, joint3]\n"
        "    command_interfaces: [position]\n    state_interfaces: [position, velocity]\n" + parameters)
    return parse_controllers(path)["test_joint_trajectory_controller"]


# --- test_trajectory_actions.cpp ---------------------------------------------------------------------------------


def test_success_single_point_sendgoal() -> None:
    """test_trajectory_actions.cpp test_success_single_point_sendgoal: (1, 2, 3) at 0.5 s succeeds and is held."""
    report = send_goal(points([0.5], [1.0, 2.0, 3.0]), jtc(stopped_velocity=0.0), MirrorPlant(3), goal_time=1.0)
    assert report.result.name == "SUCCESSFUL"
    np.testing.assert_allclose(report.output[-1], [1.0, 2.0, 3.0], atol=COMMON_THRESHOLD)
    # Positions only: interpolated linearly from the state read, at a constant (1 - 1.1) / 0.5 rad/s.
    np.testing.assert_allclose(report.reference_velocities, -0.2, atol=1e-12)


def test_success_single_point_with_velocity_sendgoal() -> None:
    """test_trajectory_actions.cpp test_success_single_point_with_velocity_sendgoal: ending at 1 rad/s succeeds."""
    goal = points([0.5], [1.0, 2.0, 3.0], velocities=[1.0, 1.0, 1.0])
    report = send_goal(goal, jtc(stopped_velocity=0.0), MirrorPlant(3), goal_time=1.0)
    assert report.result.name == "SUCCESSFUL"
    # Upstream also reads the velocity command (1, 1, 1); moveplan reports the position command only.
    np.testing.assert_allclose(report.output[-1], [1.0, 2.0, 3.0], atol=COMMON_THRESHOLD)


def test_success_multi_point_sendgoal() -> None:
    """test_trajectory_actions.cpp test_success_multi_point_sendgoal: (4, 5, 6) at 0.2 s, (7, 8, 9) at 0.3 s."""
    goal = points([0.2, 0.3], [[4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
    report = send_goal(goal, jtc(stopped_velocity=0.0), MirrorPlant(3), goal_time=1.0)
    assert report.result.name == "SUCCESSFUL"
    assert len(report.times_s) > 1  # feedback: cycles ran before the result
    np.testing.assert_allclose(report.output[-1], [7.0, 8.0, 9.0], atol=COMMON_THRESHOLD)


def test_success_multi_point_with_velocity_sendgoal() -> None:
    """test_trajectory_actions.cpp test_success_multi_point_with_velocity_sendgoal: ending at 2 rad/s succeeds."""
    goal = points([0.2, 0.3], [[4.0, 5.0, 6.0], [7.0, 8.0, 9.0]], velocities=[[1.0] * 3, [2.0] * 3])
    report = send_goal(goal, jtc(stopped_velocity=0.0), MirrorPlant(3), goal_time=1.0)
    assert report.result.name == "SUCCESSFUL"
    np.testing.assert_allclose(report.output[-1], [7.0, 8.0, 9.0], atol=COMMON_THRESHOLD)


def test_goal_tolerances_single_point_success() -> None:
    """test_trajectory_actions.cpp test_goal_tolerances_single_point_success: goal 0.1 per joint is met."""
    report = send_goal(points([0.5], [1.0, 2.0, 3.0]), jtc(goal=0.1), MirrorPlant(3), goal_time=1.0)
    assert (report.result.code, report.result.name) == (0, "SUCCESSFUL")
    np.testing.assert_allclose(report.output[-1], [1.0, 2.0, 3.0], atol=COMMON_THRESHOLD)


def test_goal_tolerances_multi_point_success() -> None:
    """test_trajectory_actions.cpp test_goal_tolerances_multi_point_success: goal 0.1, two points, met."""
    goal = points([0.2, 0.3], [[4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
    report = send_goal(goal, jtc(goal=0.1), MirrorPlant(3), goal_time=1.0)
    assert (report.result.code, report.result.name) == (0, "SUCCESSFUL")
    np.testing.assert_allclose(report.output[-1], [7.0, 8.0, 9.0], atol=COMMON_THRESHOLD)


# The fixture's defaults for test_tolerances_via_actions and test_tolerances.cpp: goal and trajectory 0.1 per
# joint, stopped_velocity_tolerance 0.1, goal_time default_goal_time = 0.1.
TOLERANT = jtc(trajectory=0.1, goal=0.1, goal_time=0.1, stopped_velocity=0.1)


def expect_default_tolerances(active: SegmentTolerances) -> None:
    """expectDefaultTolerances: acceleration never set, goal velocity from stopped_velocity_tolerance."""
    assert active.goal_time_s == 0.1
    assert active.state == (StateTolerance(0.1, 0.0, 0.0),) * 3
    assert active.goal == (StateTolerance(0.1, 0.1, 0.0),) * 3


def test_tolerances_via_actions() -> None:
    """test_trajectory_actions.cpp test_tolerances_via_actions: a goal's tolerances apply to it, by joint name."""
    defaults = segment_tolerances(TOLERANT)
    one_point = points([0.5], [1.0, 2.0, 3.0])

    first = send_goal(one_point, TOLERANT, MirrorPlant(3), goal_time=0.0)
    assert first.result.name == "SUCCESSFUL"
    expect_default_tolerances(goal_segment_tolerances(defaults, GoalTolerances(goal_time_s=0.0)))

    path = [JointTolerance(j, 0.2, 0.3, 0.4) for j in JOINTS]
    goal = [JointTolerance("joint2", 1.2, 2.2, 3.2), JointTolerance("joint3", 1.3, 2.3, 3.3),
            JointTolerance("joint1", 1.1, 2.1, 3.1)]  # jumbled order
    second = send_goal(one_point, TOLERANT, MirrorPlant(3), goal_time=2.0, path=path, goal=goal,
                       start=first.output[-1])
    assert second.result.name == "SUCCESSFUL"
    active = goal_segment_tolerances(defaults, GoalTolerances(tuple(path), tuple(goal), 2.0))
    assert active.goal_time_s == 2.0
    assert active.state == (StateTolerance(0.2, 0.3, 0.4),) * 3
    assert active.goal == (StateTolerance(1.1, 2.1, 3.1), StateTolerance(1.2, 2.2, 3.2), StateTolerance(1.3, 2.3, 3.3))

    third = send_goal(one_point, TOLERANT, MirrorPlant(3), goal_time=0.0, start=second.output[-1])
    assert third.result.name == "SUCCESSFUL"
    expect_default_tolerances(goal_segment_tolerances(defaults, GoalTolerances(goal_time_s=0.0)))


@pytest.mark.parametrize(("commands", "states"), ACTION_INTERFACES)
def test_state_tolerances_fail(commands, states) -> None:
    """test_trajectory_actions.cpp test_state_tolerances_fail: trajectory 1e-4, frozen robot: path violated."""
    goal = points([0.0, 0.1], [[4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
    report = send_goal(goal, jtc(commands, states, trajectory=1e-4), FrozenPlant(3), goal_time=1.0)
    assert (report.result.code, report.result.name) == (-4, "PATH_TOLERANCE_VIOLATED")
    assert [(v.check, v.joint, v.time_s) for v in report.violations] == [("path", j, 0.0) for j in JOINTS]
    np.testing.assert_allclose(report.output[-1], INITIAL)  # the first command is never written
    np.testing.assert_allclose(held(report), INITIAL, atol=COMMON_THRESHOLD)


@pytest.mark.parametrize(("commands", "states"), ACTION_INTERFACES)
def test_goal_tolerances_fail(commands, states) -> None:
    """test_trajectory_actions.cpp test_goal_tolerances_fail: goal 0.1, frozen robot: goal_time runs out."""
    controller = jtc(commands, states, goal=0.1, goal_time=1e-6)
    report = send_goal(points([0.0], [4.0, 5.0, 6.0]), controller, FrozenPlant(3), goal_time=1.0)
    assert (report.result.code, report.result.name) == (-5, "GOAL_TOLERANCE_VIOLATED")
    # The goal's goal_time_tolerance (1.0 s) replaces constraints.goal_time (1e-6 s): it aborts on the first
    # cycle more than 1 s past the point at 0 s.
    assert report.result.message.startswith("Aborted due to goal_time_tolerance exceeding by 1.010000 seconds")
    assert report.duration_s == pytest.approx(1.01)
    assert [(v.check, v.joint) for v in report.violations] == [("goal_time", "")] + [("goal", j) for j in JOINTS]
    np.testing.assert_allclose(held(report), INITIAL, atol=COMMON_THRESHOLD)


@pytest.mark.parametrize(("commands", "states"), ACTION_INTERFACES)
def test_no_time_from_start_state_tolerance_fail(commands, states) -> None:
    """test_trajectory_actions.cpp test_no_time_from_start_state_tolerance_fail: one point at 0 s is path-checked."""
    report = send_goal(points([0.0], [4.0, 5.0, 6.0]), jtc(commands, states, trajectory=1e-4), FrozenPlant(3),
                       goal_time=1.0)
    assert (report.result.code, report.result.name) == (-4, "PATH_TOLERANCE_VIOLATED")
    assert report.duration_s == 0.0
    np.testing.assert_allclose(report.output[-1], INITIAL)
    np.testing.assert_allclose(held(report), INITIAL, atol=COMMON_THRESHOLD)


# test_allow_nonzero_velocity_at_trajectory_end_*: (4, 5, 6) at 0 s and (7, 8, 9) at 0.1 s, both at (4, 5, 6) rad/s.
MOVING_END = points([0.0, 0.1], [[4.0, 5.0, 6.0], [7.0, 8.0, 9.0]], velocities=[[4.0, 5.0, 6.0]] * 2)


def test_allow_nonzero_velocity_at_trajectory_end_true() -> None:
    """test_trajectory_actions.cpp test_allow_nonzero_velocity_at_trajectory_end_true: accepted and succeeds."""
    controller = jtc(stopped_velocity=0.0, allow_nonzero_velocity=True)
    report = send_goal(MOVING_END, controller, MirrorPlant(3), goal_time=1.0)
    assert report.result.name == "SUCCESSFUL"


def test_allow_nonzero_velocity_at_trajectory_end_false() -> None:
    """test_trajectory_actions.cpp test_allow_nonzero_velocity_at_trajectory_end_false: rejected; at rest, accepted."""
    controller = jtc(stopped_velocity=0.0, allow_nonzero_velocity=False)
    with pytest.raises(InputError, match="Velocity of last trajectory point of joint joint1 is not zero: 4.0000"):
        send_goal(MOVING_END, controller, MirrorPlant(3), goal_time=1.0)
    at_rest = points(MOVING_END.times_s, MOVING_END.positions, velocities=[[4.0, 5.0, 6.0], [0.0, 0.0, 0.0]])
    report = send_goal(at_rest, controller, MirrorPlant(3), goal_time=1.0)  # accepted: no InputError
    assert len(report.times_s) > 0


def test_scaling_execution_time_succeeds() -> None:
    """test_trajectory_actions.cpp test_scaling_execution_time_succeeds, factor 1.0: goal 1e-10 met twice."""
    controller = jtc(trajectory=0.3, goal=1e-10, stopped_velocity=0.01)
    goal = points([0.1, 0.2], [[4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
    first = send_goal(goal, controller, MirrorPlant(3), goal_time=0.1)
    assert first.result.name == "SUCCESSFUL"
    np.testing.assert_allclose(first.output[-1], [7.0, 8.0, 9.0], atol=COMMON_THRESHOLD)
    second = send_goal(goal, controller, MirrorPlant(3), goal_time=1.0, start=first.output[-1])
    assert second.result.name == "SUCCESSFUL"


# --- test_trajectory_controller.cpp ------------------------------------------------------------------------------


def test_update_dynamic_tolerances(tmp_path) -> None:
    """test_trajectory_controller.cpp update_dynamic_tolerances: the defaults, and constraints.* mapped to them.

    The reload of a running controller has no moveplan counterpart: its parameter file is read once.
    """
    defaults = segment_tolerances(controller_from_yaml(tmp_path, ""))
    assert defaults.goal_time_s == 0.0
    assert defaults.state == (StateTolerance(0.0),) * 3
    assert defaults.goal == (StateTolerance(0.0, 0.01),) * 3

    constraints = (
        "    constraints:\n      goal_time: 1.0\n      stopped_velocity_tolerance: 0.02\n"
        + "".join(f"      joint{i}: {{trajectory: {float(i)}, goal: {10.0 * i}}}\n" for i in (1, 2, 3)))
    updated = segment_tolerances(controller_from_yaml(tmp_path, constraints))
    assert updated.goal_time_s == 1.0
    assert updated.state == tuple(StateTolerance(float(i)) for i in (1, 2, 3))
    assert updated.goal == tuple(StateTolerance(10.0 * i, 0.02) for i in (1, 2, 3))


# velocity_error, test_state_tolerances_fail and test_goal_tolerances_fail publish three points 0.25 s (resp. 0.1 s)
# apart with velocities (cubic segments), to a robot that does not move.
def three_points(step, velocities, first=(3.3, 4.4, 5.5)):
    positions = [first, [7.7, 8.8, 9.9], [10.10, 11.11, 12.12]]
    return points(step * np.arange(1, 4), positions, velocities=[[v] * 3 for v in velocities])


@pytest.mark.parametrize(("commands", "states"), CONTROLLER_INTERFACES)
def test_velocity_error(commands, states) -> None:
    """test_trajectory_controller.cpp velocity_error: velocity errors count only with velocity state and command.

    Upstream reads state_error.velocities >= 0.1 (the first point's velocity) where they are computed; here a path
    velocity tolerance of 0.1 shows where they are: JTC's compute_error_for_joint computes them with a velocity
    state and a velocity or effort command interface, else they stay 0 and nothing is checked.
    """
    goal = three_points(0.25, (0.1, 0.2, 0.3), first=(3.3, 4.4, 6.6))
    path = [JointTolerance(j, velocity=0.1) for j in JOINTS]
    # goal_time 0 (the default): a goal outside its tolerance would wait forever; none is (see the docstring above).
    report = send_goal(goal, jtc(commands, states), FrozenPlant(3), goal_time=0.0, path=path)
    if "velocity" in states and {"velocity", "effort"} & set(commands):
        assert report.result.name == "PATH_TOLERANCE_VIOLATED"
        assert all(v.actual == 0.0 and v.error >= 0.1 for v in report.violations)
    else:
        assert report.result.name == "SUCCESSFUL"


@pytest.mark.parametrize(("commands", "states"), CONTROLLER_INTERFACES)
def test_state_tolerances_fail_topic(commands, states) -> None:
    """test_trajectory_controller.cpp test_state_tolerances_fail: trajectory 1e-4, frozen robot: aborts, holds."""
    goal = three_points(0.1, (0.01, 0.05, 0.06))
    report = send_goal(goal, jtc(commands, states, trajectory=1e-4), FrozenPlant(3), goal_time=0.0)
    assert report.result.name == "PATH_TOLERANCE_VIOLATED"
    # The first cycle samples the state it blends from (error 0); the second has moved on.
    assert [(v.joint, v.time_s) for v in report.violations] == [(j, 0.01) for j in JOINTS]
    np.testing.assert_allclose(held(report), INITIAL, atol=COMMON_THRESHOLD)


@pytest.mark.parametrize(("commands", "states"), CONTROLLER_INTERFACES)
def test_goal_tolerances_fail_topic(commands, states) -> None:
    """test_trajectory_controller.cpp test_goal_tolerances_fail: goal 0.1, goal_time 1e-6: aborts, holds, stays."""
    goal = three_points(0.1, (0.01, 0.05, 0.06))  # upstream adds efforts for effort controllers: no counterpart
    controller = jtc(commands, states, goal=0.1, goal_time=1e-6)
    report = send_goal(goal, controller, FrozenPlant(3), goal_time=0.0)
    assert report.result.name == "GOAL_TOLERANCE_VIOLATED"
    assert report.duration_s == pytest.approx(0.31)  # the first cycle more than 1e-6 s past the last point
    np.testing.assert_allclose(held(report), INITIAL, atol=COMMON_THRESHOLD)
    # Upstream then moves joint1 to -3.3 after 0.4 s: the controller is holding, nothing changes.
    bumped = send_goal(goal, controller, FrozenPlant(3), goal_time=0.0,
                       disturbances=[Disturbance(0.4, "joint1", -3.3 - INITIAL[0])])
    assert (bumped.result, bumped.duration_s) == (report.result, report.duration_s)
    np.testing.assert_allclose(held(bumped), INITIAL, atol=COMMON_THRESHOLD)


def test_invalid_message() -> None:
    """test_trajectory_controller.cpp invalid_message: malformed goals are refused, the good one accepted.

    Effort fields and header stamps (end time in the past or future) have no moveplan counterpart.
    """
    good = points([0.25], [1.0, 2.0, 3.0], velocities=[-1.0, -2.0, -3.0])
    send_goal(good, jtc(), MirrorPlant(3), goal_time=0.0)  # accepted
    with pytest.raises(UnknownName, match="joint 'bad_name' not found"):
        send_goal(points([0.25], [1.0], velocities=[-1.0], joints=("bad_name",)), jtc(), MirrorPlant(3),
                  goal_time=0.0)
    # What each malformed message breaks, as the refusal names it.
    malformed = {
        "a trajectory needs at least one point": dict(times=[], positions=np.zeros((0, 3)),  # empty message
                                                      velocities=np.zeros((0, 3))),
        r"positions: expected shape \(1, 3\), got \(1, 0\)": dict(positions=np.zeros((1, 0))),  # no positions
        r"positions: expected shape \(1, 3\), got \(1, 2\)": dict(positions=[[1.0, 2.0]]),
        r"positions: expected shape \(1, 3\), got \(1, 4\)": dict(positions=[[1.0, 2.0, 3.0, 4.0]]),
        r"velocities: expected shape \(1, 3\), got \(1, 2\)": dict(velocities=[[1.0, 2.0]]),
        r"accelerations: expected shape \(1, 3\), got \(1, 2\)": dict(accelerations=[[1.0, 2.0]]),
        "strictly increasing": dict(times=[0.25, 0.25], positions=[[1.0, 2.0, 3.0]] * 2,
                                    velocities=[[-1.0, -2.0, -3.0]] * 2),
    }
    for refusal, fields in malformed.items():
        message = dict(times=[0.25], positions=[[1.0, 2.0, 3.0]], velocities=[[-1.0, -2.0, -3.0]])
        message.update(fields)
        positions = np.asarray(message["positions"], dtype=float)
        with pytest.raises(ValueError, match=refusal):
            JointTrajectory(JOINTS, message["times"], positions, message["velocities"],
                            message.get("accelerations", np.zeros((len(positions), 3))))


def test_expect_invalid_when_message_with_nonzero_end_velocity_and_when_param_false() -> None:
    """test_trajectory_controller.cpp expect_invalid_when_message_with_nonzero_end_velocity_and_when_param_false."""
    with pytest.raises(ValueError, match="at least one point"):  # the empty message
        points([], np.zeros((0, 3)))
    moving = points([0.25], [1.0, 2.0, 3.0], velocities=[-1.0, -2.0, -3.0])
    with pytest.raises(InputError, match="joint joint1 is not zero: -1.000000000000000"):
        send_goal(moving, jtc(allow_nonzero_velocity=False), MirrorPlant(3), goal_time=0.0)


def test_jumbled_joint_order() -> None:
    """test_trajectory_controller.cpp test_jumbled_joint_order: joints (2, 3, 1) reach their own positions."""
    order = [1, 2, 0]
    dt = 0.25
    target = np.array([1.0, 2.0, 3.0])
    velocities = (target[order] - INITIAL[order]) / dt
    goal = points([dt], target[order], velocities=velocities, accelerations=velocities / dt,
                  joints=tuple(JOINTS[i] for i in order))
    report = send_goal(goal, jtc(), MirrorPlant(3), goal_time=0.0)
    assert report.joint_names == JOINTS
    np.testing.assert_allclose(report.output[-1], target, atol=COMMON_THRESHOLD)


def _partial_goal(dt=0.25):
    """joint2 to 2.0 and joint1 to 1.0 in 0.25 s, velocities and accelerations as upstream computes them."""
    velocities = (np.array([2.0, 1.0]) - INITIAL[[1, 0]]) / dt
    return points([dt], [2.0, 1.0], velocities=velocities, accelerations=velocities / dt, joints=("joint2", "joint1"))


def test_partial_joint_list(tmp_path) -> None:
    """test_trajectory_controller.cpp test_partial_joint_list: a goal for joint2, joint1 leaves joint3 in place."""
    controller = controller_from_yaml(
        tmp_path, "    allow_partial_joints_goal: true\n    allow_nonzero_velocity_at_trajectory_end: true\n")
    report = send_goal(_partial_goal(), controller, MirrorPlant(3), goal_time=0.0)
    np.testing.assert_allclose(report.output[-1], [1.0, 2.0, INITIAL[2]], atol=COMMON_THRESHOLD)


def test_partial_joint_list_not_allowed() -> None:
    """test_trajectory_controller.cpp test_partial_joint_list_not_allowed: the goal is rejected, nothing moves."""
    with pytest.raises(InputError, match="Joints on incoming trajectory don't match the controller joints"):
        send_goal(_partial_goal(), jtc(), MirrorPlant(3), goal_time=0.0)


# --- test_tolerances.cpp -----------------------------------------------------------------------------------------


def held_robot(tolerances: GoalTolerances) -> ExecutionReport:
    """The fixture's robot, held at 1.1, 2.1, 3.1, sent (4, 5, 6) at 0.5 s with TOLERANT's defaults.

    Its path error grows by 0.058 a cycle: the defaults (trajectory 0.1) abort it at 0.02 s.
    """
    return simulate(points([0.5], [4.0, 5.0, 6.0]), TOLERANT, JTC_ONLY, FrozenPlant(3), start_positions=INITIAL,
                    goal_tolerances=tolerances)


def expect_defaults_in_force(tolerances: GoalTolerances) -> None:
    expect_default_tolerances(goal_segment_tolerances(segment_tolerances(TOLERANT), tolerances))
    report = held_robot(tolerances)
    assert report.result.name == "PATH_TOLERANCE_VIOLATED"
    assert [(v.time_s, v.tolerance) for v in report.violations] == [(0.02, 0.1)] * 3


def test_get_segment_tolerances() -> None:
    """test_tolerances.cpp test_get_segment_tolerances: > 0 replaces the default, joints matched by name."""
    path = tuple(JointTolerance(j, 0.2, 0.3, 0.4) for j in JOINTS)
    goal = (JointTolerance("joint2", 1.2, 2.2, 3.2), JointTolerance("joint3", 1.3, 2.3, 3.3),
            JointTolerance("joint1", 1.1, 2.1, 3.1))
    tolerances = GoalTolerances(path, goal, 2.0)
    active = goal_segment_tolerances(segment_tolerances(TOLERANT), tolerances)
    assert active.goal_time_s == 2.0
    assert active.state == (StateTolerance(0.2, 0.3, 0.4),) * 3
    assert active.goal == (StateTolerance(1.1, 2.1, 3.1), StateTolerance(1.2, 2.2, 3.2), StateTolerance(1.3, 2.3, 3.3))
    report = held_robot(tolerances)  # the goal's path tolerance 0.2 is the one in force
    assert report.result.name == "PATH_TOLERANCE_VIOLATED"
    assert [(v.time_s, v.tolerance) for v in report.violations] == [(0.04, 0.2)] * 3


def test_deactivate_tolerances() -> None:
    """test_tolerances.cpp test_deactivate_tolerances: -1 erases every tolerance and the goal time."""
    erase = tuple(JointTolerance(j, -1.0, -1.0, -1.0) for j in JOINTS)
    tolerances = GoalTolerances(erase, erase, -1.0)
    active = goal_segment_tolerances(segment_tolerances(TOLERANT), tolerances)
    assert active.goal_time_s == 0.0
    assert active.state == active.goal == (StateTolerance(0.0, 0.0, 0.0),) * 3
    # goal_time erased to 0: JTC would wait forever for an unmet goal tolerance (moveplan: WAIT_LIMIT_S, the
    # documented difference); with nothing checked, the held robot's goal succeeds at the last point instead.
    report = held_robot(tolerances)
    assert report.result.name == "SUCCESSFUL"
    assert report.duration_s == pytest.approx(0.49)


@pytest.mark.parametrize("tolerances", [
    pytest.param(GoalTolerances((JointTolerance("joint1"),), (), -123.0), id="negative goal_time_tolerance"),
    pytest.param(GoalTolerances((JointTolerance("joint1", position=-123.0),), (), 3.0), id="negative path position"),
    pytest.param(GoalTolerances((JointTolerance("joint1", velocity=-123.0),), (), 3.0), id="negative path velocity"),
    pytest.param(GoalTolerances((JointTolerance("joint1", acceleration=-123.0),), (), 3.0),
                 id="negative path acceleration"),
    pytest.param(GoalTolerances((), (JointTolerance("joint1", position=-123.0),), 3.0), id="negative goal position"),
    pytest.param(GoalTolerances((), (JointTolerance("joint1", velocity=-123.0),), 3.0), id="negative goal velocity"),
    pytest.param(GoalTolerances((), (JointTolerance("joint1", acceleration=-123.0),), 3.0),
                 id="negative goal acceleration"),
])
def test_invalid_tolerances(tolerances) -> None:
    """test_tolerances.cpp test_invalid_tolerances: a negative value other than -1 => the whole default set."""
    expect_defaults_in_force(tolerances)


def test_invalid_joints_path_tolerance() -> None:
    """test_tolerances.cpp test_invalid_joints_path_tolerance: an unknown joint => the whole default set."""
    expect_defaults_in_force(GoalTolerances((JointTolerance("joint123"),), (), 3.0))


def test_invalid_joints_goal_tolerance() -> None:
    """test_tolerances.cpp test_invalid_joints_goal_tolerance: an unknown joint => the whole default set."""
    expect_defaults_in_force(GoalTolerances((), (JointTolerance("joint123"),), 3.0))
