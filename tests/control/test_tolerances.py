"""JTC tolerance rules and MoveIt's execution checks, applied to hand-built time series."""

import numpy as np
import pytest

from moveplan.core.config.controllers import ControllerConfig, ExecutionConfig
from moveplan.core.control._judging import judge, judge_spans
from moveplan.core.control._moveit_checks import Timeout, check_start_state, expected_duration_s
from moveplan.core.control.results import (
    GOAL_TOLERANCE_VIOLATED,
    PATH_TOLERANCE_VIOLATED,
    START_STATE_INVALID,
    SUCCESSFUL,
    TIMED_OUT,
)
from moveplan.core.control.tolerances import (
    SegmentTolerances,
    StateTolerance,
    check_state_tolerance_per_joint,
    position_error,
    segment_tolerances,
    velocity_error_computable,
)

JOINTS = ("joint1", "joint2")


def controller(commands=("position",), states=("position", "velocity"), **overrides):
    values = dict(
        name="jtc", joints=JOINTS, update_rate_hz=100.0, command_interfaces=commands,
        state_interfaces=states, goal_time_s=0.5, stopped_velocity_tolerance=0.2,
        trajectory_tolerance={"joint1": 0.1}, goal_tolerance={"joint1": 0.05, "joint2": 0.02},
        gains={},
    )
    values.update(overrides)
    return ControllerConfig(**values)


def tolerances(path=(0.1, 0.1), goal=(0.05, 0.05), goal_time=0.0, stopped=0.0):
    return SegmentTolerances(
        JOINTS,
        tuple(StateTolerance(position=p) for p in path),
        tuple(StateTolerance(position=g, velocity=stopped) for g in goal),
        goal_time,
    )


def test_segment_tolerances_follow_jtc_parameters_with_zero_for_missing_joints():
    result = segment_tolerances(controller())
    assert result.joint_names == JOINTS
    assert result.state == (StateTolerance(position=0.1), StateTolerance())
    assert result.goal == (StateTolerance(0.05, 0.2), StateTolerance(0.02, 0.2))
    assert result.goal_time_s == 0.5


def test_error_exactly_equal_to_tolerance_passes():
    assert check_state_tolerance_per_joint(0.5, 0.0, 0.0, StateTolerance(position=0.5))
    assert check_state_tolerance_per_joint(-0.25, 0.0, 0.0, StateTolerance(position=0.25))


def test_error_above_tolerance_fails_in_each_field():
    assert not check_state_tolerance_per_joint(0.5000001, 0.0, 0.0, StateTolerance(position=0.5))
    assert not check_state_tolerance_per_joint(0.0, -0.3, 0.0, StateTolerance(velocity=0.2))
    assert not check_state_tolerance_per_joint(0.0, 0.0, 2.0, StateTolerance(acceleration=1.0))


def test_zero_tolerance_is_not_checked():
    assert check_state_tolerance_per_joint(1e9, 1e9, 1e9, StateTolerance())


def test_position_error_wraps_only_continuous_joints():
    # A16: joint at 3.1, reference 6.6.
    error = position_error([6.6, 6.6], [3.1, 3.1], continuous=[True, False])
    np.testing.assert_allclose(error, [6.6 - 3.1 - 2 * np.pi, 3.5], atol=1e-12)
    assert error[0] == pytest.approx(-2.783, abs=1e-3)


@pytest.mark.parametrize(("commands", "states", "computable"), [
    (("position",), ("position", "velocity"), False),
    (("position", "velocity"), ("position",), False),
    (("position", "velocity"), ("position", "velocity"), True),
    (("velocity",), ("position", "velocity"), True),
    (("effort",), ("position", "velocity"), True),
])
def test_velocity_error_needs_velocity_state_and_velocity_or_effort_command(
    commands, states, computable
):
    assert velocity_error_computable(controller(commands, states)) is computable


def test_expected_duration_is_scaled_duration_plus_margin():
    execution = ExecutionConfig(allowed_execution_duration_scaling=1.2,
                                allowed_goal_duration_margin=0.5)
    assert expected_duration_s(2.0, execution) == pytest.approx(2.9)


def test_start_deviation_names_each_joint_outside_allowed_start_tolerance():
    report = check_start_state(JOINTS, [0.0, 1.0], [0.0, 1.05], 0.01)
    assert report is not None
    assert report.result.code == START_STATE_INVALID
    assert report.result.name == "START_STATE_INVALID"
    assert "joint2" in report.result.message and "deviates" in report.result.message
    (violation,) = report.violations
    assert (violation.check, violation.joint, violation.reference, violation.actual) == (
        "start_tolerance", "joint2", 1.05, 1.0)
    assert violation.error == pytest.approx(0.05)


def test_start_check_is_skipped_when_allowed_start_tolerance_is_zero():
    assert check_start_state(JOINTS, [0.0, 0.0], [5.0, 5.0], 0.0) is None


def test_start_check_normalises_continuous_joints():
    start, first = [np.pi - 0.001, 0.0], [-np.pi + 0.001, 0.0]
    assert check_start_state(JOINTS, start, first, 0.01, continuous=[True, False]) is None
    assert check_start_state(JOINTS, start, first, 0.01, continuous=[False, False]) is not None


def series(errors_joint1, dt=0.1):
    """A recorded-looking series: reference 0, actual = -error on joint1, joint2 exact."""
    errors = np.asarray(errors_joint1, dtype=float)
    times = np.arange(len(errors)) * dt
    reference = np.zeros((len(errors), 2))
    actual = np.c_[-errors, np.zeros(len(errors))]
    return times, reference, actual


FAR = Timeout(100.0, "too long")


def test_recorded_series_path_violation_names_joint_time_and_values():
    times, reference, actual = series([0.0, 0.05, 0.12, 0.0, 0.0])
    before = times < 0.35
    report = judge(tolerances(), times, reference, actual, before, 0.4, FAR)
    assert report.result.code == PATH_TOLERANCE_VIOLATED
    assert report.end_index == 2
    (violation,) = report.violations
    assert (violation.check, violation.joint) == ("path", "joint1")
    assert violation.time_s == pytest.approx(0.2)
    values = (violation.reference, violation.actual, violation.error, violation.tolerance)
    assert values == pytest.approx((0.0, -0.12, 0.12, 0.1))
    assert report.margins["joint1"] == pytest.approx(-0.02)


def test_success_on_first_cycle_inside_goal_reports_margins():
    times, reference, actual = series([0.0, 0.05, 0.08, 0.03, 0.0])
    report = judge(tolerances(), times, reference, actual, times < 0.25, 0.3, FAR)
    assert report.ok and report.result.code == SUCCESSFUL
    assert report.end_index == 3
    # joint1: path margin 0.1 - 0.08; goal margin at the end 0.05 - 0.03.
    assert report.margins == pytest.approx({"joint1": 0.02, "joint2": 0.05})


def test_first_cycle_is_path_checked_even_when_past_the_last_point():
    times, reference, actual = series([0.5, 0.0])
    report = judge(tolerances(), times, reference, actual, [False, False], 0.0, FAR)
    assert report.result.code == PATH_TOLERANCE_VIOLATED
    assert report.end_index == 0


def test_goal_not_reached_within_goal_time_aborts_with_goal_tolerance_violated():
    times, reference, actual = series([0.0, 0.2, 0.2, 0.2, 0.2, 0.2])
    report = judge(tolerances(path=(0.0, 0.0), goal_time=0.25), times, reference, actual,
                   times < 0.1, 0.1, FAR)
    assert report.result.code == GOAL_TOLERANCE_VIOLATED
    assert report.end_index == 4  # 0.4 - 0.1 > 0.25
    late, goal = report.violations
    assert (late.check, late.joint, late.tolerance) == ("goal_time", "", 0.25)
    assert late.error == pytest.approx(-0.3)
    assert (goal.check, goal.joint, goal.error) == ("goal", "joint1", pytest.approx(0.2))


def test_stopped_velocity_is_checked_only_with_velocity_errors_given():
    times, reference, actual = series([0.0, 0.0, 0.0])
    moving = np.c_[np.full(3, 0.5), np.zeros(3)]
    kwargs = dict(times_s=times, reference_positions=reference, actual_positions=actual,
                  before_last_point=[True, False, False], last_point_s=0.1,
                  timeout=Timeout(0.15, "late"))
    checked = judge(tolerances(stopped=0.2), **kwargs, reference_velocities=np.zeros((3, 2)),
                    actual_velocities=moving)
    ignored = judge(tolerances(stopped=0.2), **kwargs)
    assert ignored.ok
    assert checked.result.code == TIMED_OUT
    checks = [(v.check, v.joint) for v in checked.violations]
    assert checks == [("timeout", ""), ("stopped_velocity", "joint1")]


def test_spans_judged_together_get_the_verdicts_they_get_alone():
    spans = [series([0.0, 0.05, 0.12, 0.0, 0.0]), series([0.0, 0.05, 0.08, 0.03, 0.0]),
             series([0.0, 0.08, 0.08])]
    timeouts = [FAR, FAR, Timeout(0.15, "late")]
    stacked = [np.concatenate(arrays) for arrays in zip(*spans, strict=True)]
    times = stacked[0]
    together = judge_spans(tolerances(), *stacked, times < 0.25, 0.3, [0, 5, 10], timeouts)
    alone = [judge(tolerances(), t, r, a, t < 0.25, 0.3, timeout)
             for (t, r, a), timeout in zip(spans, timeouts, strict=True)]
    assert together == alone
    assert [r.result.code for r in together] == [PATH_TOLERANCE_VIOLATED, SUCCESSFUL, TIMED_OUT]


def test_series_ending_without_verdict_times_out_at_its_last_cycle():
    times, reference, actual = series([0.0, 0.2, 0.2])
    report = judge(tolerances(path=(0.0, 0.0)), times, reference, actual, [True, False, False], 0.1,
                   Timeout(60.0, "recording ended"))
    assert report.result.code == TIMED_OUT
    assert report.result.message.startswith("recording ended")
    assert report.end_index == 2


# --- tolerances a FollowJointTrajectory goal carries (test_tolerances.cpp) ------------------------

THREE = ("joint1", "joint2", "joint3")


def _defaults():
    # test_tolerances.cpp's fixture: goal 0.1, trajectory 0.1, stopped_velocity 0.1, goal_time 0.1.
    config = controller(joints=THREE, goal_time_s=0.1, stopped_velocity_tolerance=0.1,
                        trajectory_tolerance=dict.fromkeys(THREE, 0.1), goal_tolerance=dict.fromkeys(THREE, 0.1))
    return segment_tolerances(config)


def test_get_segment_tolerances_from_goal_maps_them_by_joint_name():
    """test_tolerances.cpp test_get_segment_tolerances_from_goal: path (0.2, 0.3, 0.4) for every joint, goal
    tolerances in jumbled order, goal_time 2.0."""
    from moveplan.core.control.tolerances import goal_segment_tolerances
    from moveplan.core.types import GoalTolerances, JointTolerance

    goal = GoalTolerances(
        path=tuple(JointTolerance(j, 0.2, 0.3, 0.4) for j in THREE),
        goal=(JointTolerance("joint2", 1.2, 2.2, 3.2), JointTolerance("joint3", 1.3, 2.3, 3.3),
              JointTolerance("joint1", 1.1, 2.1, 3.1)),
        goal_time_s=2.0)
    active = goal_segment_tolerances(_defaults(), goal)
    assert active.goal_time_s == 2.0
    assert active.state == (StateTolerance(0.2, 0.3, 0.4),) * 3
    assert active.goal == (StateTolerance(1.1, 2.1, 3.1), StateTolerance(1.2, 2.2, 3.2), StateTolerance(1.3, 2.3, 3.3))
    assert goal_segment_tolerances(_defaults(), None) == _defaults()  # the next goal without: the defaults


def test_deactivate_tolerances_with_minus_one_erases_them():
    """test_tolerances.cpp test_deactivate_tolerances: -1 everywhere leaves nothing checked, goal_time 0."""
    from moveplan.core.control.tolerances import goal_segment_tolerances
    from moveplan.core.types import GoalTolerances, JointTolerance

    erase = tuple(JointTolerance(j, -1.0, -1.0, -1.0) for j in THREE)
    active = goal_segment_tolerances(_defaults(), GoalTolerances(erase, erase, -1.0))
    assert active.goal_time_s == 0.0
    assert active.state == active.goal == (StateTolerance(0.0, 0.0, 0.0),) * 3


@pytest.mark.parametrize("goal", ["invalid", "unknown_path_joint", "unknown_goal_joint"])
def test_invalid_tolerances_or_joints_fall_back_to_the_controllers(goal, caplog):
    """test_tolerances.cpp test_invalid_tolerances, test_invalid_joints_path_tolerance,
    test_invalid_joints_goal_tolerance: the whole default set applies."""
    from moveplan.core.control.tolerances import goal_segment_tolerances
    from moveplan.core.types import GoalTolerances, JointTolerance

    goals = {
        "invalid": GoalTolerances(tuple(JointTolerance(j, -123.0) for j in THREE), (), 2.0),
        "unknown_path_joint": GoalTolerances((JointTolerance("joint123", 0.2),), (), 2.0),
        "unknown_goal_joint": GoalTolerances((), (JointTolerance("joint123", 0.2),), 2.0),
    }
    assert goal_segment_tolerances(_defaults(), goals[goal]) == _defaults()
    assert "the controller's tolerances apply to this goal" in caplog.text
