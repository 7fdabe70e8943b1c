"""The simulated JointTrajectoryController: upstream scenarios, MoveIt's checks, plants."""

import numpy as np
import pytest

from moveplan.core.config.controllers import ControllerConfig, ExecutionConfig
from moveplan.core.control.controller import WAIT_LIMIT_S, Disturbance, simulate
from moveplan.core.control.plants import FrozenPlant, LagPlant, MirrorPlant, PidPlant, make_plant
from moveplan.core.errors import InputError, UnknownName, UsageError
from moveplan.core.types import JointTrajectory

# The upstream fixture (test_trajectory_controller_utils.hpp): three joints at 1.1, 2.1, 3.1.
JOINTS = ("joint1", "joint2", "joint3")
INITIAL = np.array([1.1, 2.1, 3.1])
NO_START_CHECK = ExecutionConfig(allowed_start_tolerance=0.0)


def jtc(joints=JOINTS, commands=("position",), states=("position", "velocity"), rate=100.0,
        goal_time=0.0, stopped_velocity=0.01, trajectory=0.0, goal=0.0, gains=None):
    return ControllerConfig(
        name="joint_trajectory_controller", joints=joints, update_rate_hz=rate,
        command_interfaces=commands, state_interfaces=states, goal_time_s=goal_time,
        stopped_velocity_tolerance=stopped_velocity,
        trajectory_tolerance={j: trajectory for j in joints},
        goal_tolerance={j: goal for j in joints},
        gains={j: dict(gains or {}) for j in joints},
    )


def points(times, positions, joints=JOINTS):
    """A goal as ros2_controllers' action tests send it: positions only (JTC interpolates linearly)."""
    positions = np.atleast_2d(np.asarray(positions, dtype=float))
    zeros = np.zeros_like(positions)
    return JointTrajectory(joints, times, positions, zeros, zeros, has_velocities=False, has_accelerations=False)


def minimum_jerk(start, delta, duration, joints, step=0.05):
    """A smooth rest-to-rest move with exact velocities and accelerations, as a retimed plan has."""
    t = np.linspace(0.0, duration, int(round(duration / step)) + 1)
    s = (t / duration)[:, None]
    return JointTrajectory(
        joints, t, start + (10 * s**3 - 15 * s**4 + 6 * s**5) * delta,
        (30 * s**2 - 60 * s**3 + 30 * s**4) / duration * delta,
        (60 * s - 180 * s**2 + 120 * s**3) / duration**2 * delta,
    )


UR_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
             "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")
UR_HOME = np.array([0.0, -np.pi / 2, -np.pi / 2, 0.0, 0.0, 0.0])
UR_MOVE = minimum_jerk(UR_HOME, np.array([1.0, 0.5, -0.8, 1.2, -1.0, 1.5]), 3.0, UR_JOINTS)


def ur_jtc(**kwargs):
    # UR's ur_controllers.yaml constraints.
    values = dict(joints=UR_JOINTS, rate=500.0, stopped_velocity=0.2, trajectory=0.2, goal=0.1)
    values.update(kwargs)
    return jtc(**values)


# --- upstream acceptance scenarios (reference 1.12) ------------------------------------------


def test_single_point_with_default_constraints_succeeds_and_commands_the_point():
    # A4: one point (1, 2, 3) at 0.5 s; all tolerances 0.
    report = simulate(points([0.5], [1.0, 2.0, 3.0]), jtc(), NO_START_CHECK, MirrorPlant(3),
                      start_positions=INITIAL)
    assert report.ok and report.result.code == 0 and report.result.name == "SUCCESSFUL"
    np.testing.assert_allclose(report.output[-1], [1.0, 2.0, 3.0], atol=1e-12)
    # Success on the cycle whose command (sampled one period ahead) reaches the last point.
    assert report.duration_s == pytest.approx(0.49)


def test_multi_point_goal_within_goal_tolerance_succeeds_and_holds_last_point():
    # A5: goal 0.1; (4, 5, 6) at 0.2 s, (7, 8, 9) at 0.3 s.
    trajectory = points([0.2, 0.3], [[4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
    report = simulate(trajectory, jtc(goal=0.1), NO_START_CHECK, MirrorPlant(3),
                      start_positions=INITIAL)
    assert report.ok
    np.testing.assert_allclose(report.output[-1], [7.0, 8.0, 9.0], atol=1e-12)
    np.testing.assert_allclose(report.actual_positions[-1], report.reference_positions[-1],
                               atol=1e-12)


def test_frozen_robot_violates_path_tolerance_and_keeps_last_written_command():
    # A6: trajectory tolerance 1e-4, robot frozen; (4, 5, 6) at 0.0 s, (7, 8, 9) at 0.1 s.
    trajectory = points([0.0, 0.1], [[4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
    report = simulate(trajectory, jtc(trajectory=1e-4), NO_START_CHECK, FrozenPlant(3),
                      start_positions=INITIAL)
    assert report.result.code == -4 and report.result.name == "PATH_TOLERANCE_VIOLATED"
    assert report.duration_s == 0.0
    assert [v.joint for v in report.violations] == list(JOINTS)
    assert all(v.check == "path" and v.tolerance == 1e-4 for v in report.violations)
    np.testing.assert_allclose(report.output[-1], INITIAL)  # the violating command is never written


def test_frozen_robot_outside_goal_tolerance_aborts_after_goal_time():
    # A7: goal 0.1, goal_time 1e-6, robot frozen; single point (4, 5, 6) at 0.0 s.
    report = simulate(points([0.0], [4.0, 5.0, 6.0]), jtc(goal=0.1, goal_time=1e-6), NO_START_CHECK,
                      FrozenPlant(3), start_positions=INITIAL)
    assert report.result.code == -5 and report.result.name == "GOAL_TOLERANCE_VIOLATED"
    assert "goal_time_tolerance exceeding by" in report.result.message
    assert report.duration_s == pytest.approx(0.01)
    checks = [(v.check, v.joint) for v in report.violations]
    assert checks == [("goal_time", ""), ("goal", "joint1"), ("goal", "joint2"), ("goal", "joint3")]
    goal = report.violations[1]
    assert (goal.reference, goal.actual, goal.tolerance) == pytest.approx((4.0, 1.1, 0.1))
    assert goal.error == pytest.approx(2.9)


def test_single_point_at_time_zero_is_path_checked_on_first_sample():
    # A8: trajectory tolerance 1e-4, robot frozen, single point (4, 5, 6) at 0.0 s.
    report = simulate(points([0.0], [4.0, 5.0, 6.0]), jtc(trajectory=1e-4), NO_START_CHECK,
                      FrozenPlant(3), start_positions=INITIAL)
    assert report.result.name == "PATH_TOLERANCE_VIOLATED"
    assert report.violations[0].time_s == 0.0


def test_continuous_joint_error_wraps_and_pid_output_turns_the_short_way():
    # A16: joint3 continuous at 3.1, first point 6.6 at 0.25 s; through velocity with a P gain.
    controller = jtc(commands=("velocity",), gains={"p": 1.0})
    trajectory = points([0.25], [1.1, 2.1, 6.6])

    def run(continuous):
        plant = make_plant("pid", {}, controller, continuous_joints=continuous)
        return simulate(trajectory, controller, NO_START_CHECK, plant, continuous_joints=continuous,
                        start_positions=INITIAL)

    wrapped, plain = run({"joint3"}), run(set())
    assert np.all(wrapped.output[1:, 2] < 0.0) and np.all(wrapped.error[:, 2] <= 1e-12)
    assert np.all(plain.output[1:, 2] > 0.0) and np.all(plain.error[1:, 2] > 0.0)


# --- tolerance semantics -------------------------------------------------------------------


def test_zero_tolerance_leaves_a_frozen_robot_unchecked():
    report = simulate(points([0.0, 0.5], [INITIAL, [4.0, 5.0, 6.0]]), jtc(), NO_START_CHECK,
                      FrozenPlant(3), start_positions=INITIAL)
    assert report.ok
    assert report.margins == {}


def test_error_exactly_at_tolerance_passes_and_just_above_fails():
    at = simulate(points([0.0], [1.5, 2.1, 3.1]), jtc(trajectory=0.5, goal=0.5), NO_START_CHECK,
                  FrozenPlant(3), start_positions=[1.0, 2.1, 3.1])
    above = simulate(points([0.0], [1.5, 2.1, 3.1]), jtc(trajectory=0.4999, goal=0.5),
                     NO_START_CHECK, FrozenPlant(3), start_positions=[1.0, 2.1, 3.1])
    assert at.ok and at.margins["joint1"] == pytest.approx(0.0, abs=1e-12)
    assert above.result.name == "PATH_TOLERANCE_VIOLATED"


def test_mirror_plant_tracks_the_reference_exactly_after_the_first_cycle():
    report = simulate(UR_MOVE, ur_jtc(), ExecutionConfig(), MirrorPlant(6))
    assert report.ok
    np.testing.assert_allclose(report.error, 0.0, atol=1e-12)
    assert report.margins == pytest.approx({j: 0.1 for j in UR_JOINTS})


def test_margins_report_smallest_distance_to_tolerance_on_success():
    plant = make_plant("lag", {"tau": 0.02}, ur_jtc())
    report = simulate(UR_MOVE, ur_jtc(), ExecutionConfig(), plant)
    assert report.ok
    worst_path = 0.2 - np.abs(report.error[:-1]).max(axis=0)
    for j, joint in enumerate(UR_JOINTS):
        assert 0.0 < report.margins[joint] <= worst_path[j] + 1e-12


def test_slow_robot_reaching_goal_after_goal_time_fails_goal_tolerance():
    report = simulate(UR_MOVE, ur_jtc(trajectory=0.0, goal_time=0.05), ExecutionConfig(),
                      make_plant("lag", {"tau": 0.5}, ur_jtc()))
    assert report.result.name == "GOAL_TOLERANCE_VIOLATED"
    assert report.duration_s == pytest.approx(3.0 + 0.05, abs=0.003)
    assert report.violations[0].check == "goal_time"
    assert {v.check for v in report.violations[1:]} == {"goal"}


@pytest.mark.parametrize(("commands", "succeeds"), [
    (("position",), True), (("position", "velocity"), False),
])
def test_stopped_velocity_counts_only_with_velocity_command_interface(commands, succeeds):
    # A lagging robot arrives inside the goal position tolerance while still moving.
    controller = ur_jtc(commands=commands, stopped_velocity=1e-3, goal=0.5, goal_time=0.01)
    report = simulate(UR_MOVE, controller, ExecutionConfig(), LagPlant(np.full(6, 0.05)))
    assert report.ok is succeeds
    if not succeeds:
        assert "stopped_velocity" in {v.check for v in report.violations}


# --- MoveIt's execution checks ---------------------------------------------------------------


def test_goal_time_zero_and_unreachable_goal_end_by_moveit_duration_monitor():
    execution = ExecutionConfig(allowed_execution_duration_scaling=1.2,
                                allowed_goal_duration_margin=0.5)
    plant = make_plant("lag", {"tau": 2.0}, ur_jtc())
    report = simulate(UR_MOVE, ur_jtc(trajectory=0.0), execution, plant)
    assert report.result.code == -6 and report.result.name == "TIMED_OUT"
    assert "expected upper bound" in report.result.message
    assert report.duration_s == pytest.approx(3.0 * 1.2 + 0.5, abs=0.003)
    timeout = report.violations[0]
    assert (timeout.check, timeout.joint, timeout.reference) == ("timeout", "", 3.0)
    assert timeout.tolerance == pytest.approx(1.1)
    assert {v.check for v in report.violations[1:]} <= {"goal", "stopped_velocity"}


def test_without_duration_monitoring_the_simulation_still_stops():
    execution = ExecutionConfig(execution_duration_monitoring=False)
    report = simulate(UR_MOVE, ur_jtc(trajectory=0.0), execution, FrozenPlant(6))
    assert report.result.name == "TIMED_OUT"
    assert "wait" in report.result.message and "forever" in report.result.message
    assert report.duration_s == pytest.approx(3.0 + WAIT_LIMIT_S, abs=0.003)


def test_start_deviation_fails_before_execution_naming_the_joint():
    start = UR_HOME + np.array([0.0, 0.0, 0.05, 0.0, 0.0, 0.0])
    report = simulate(UR_MOVE, ur_jtc(), ExecutionConfig(), MirrorPlant(6), start_positions=start)
    assert report.result.name == "START_STATE_INVALID" and not report.ok
    assert "elbow_joint" in report.result.message
    (violation,) = report.violations
    assert (violation.check, violation.joint) == ("start_tolerance", "elbow_joint")
    assert violation.time_s == 0.0
    assert violation.error == pytest.approx(-0.05)
    assert report.times_s.shape == (0,) and report.actual_positions.shape == (0, 6)


def test_start_deviation_without_moveit_check_is_caught_by_first_sample_path_check():
    start = UR_HOME + np.array([0.0, 0.0, 0.3, 0.0, 0.0, 0.0])
    report = simulate(UR_MOVE, ur_jtc(), NO_START_CHECK, MirrorPlant(6), start_positions=start)
    assert report.result.name == "PATH_TOLERANCE_VIOLATED"
    assert [(v.joint, v.time_s) for v in report.violations] == [("elbow_joint", 0.0)]


# --- disturbances, plants --------------------------------------------------------------------


def test_disturbance_produces_path_violation_naming_joint_and_time():
    report = simulate(UR_MOVE, ur_jtc(), ExecutionConfig(), MirrorPlant(6),
                      disturbances=[Disturbance(1.2, "elbow_joint", 0.3)])
    assert report.result.name == "PATH_TOLERANCE_VIOLATED"
    (violation,) = report.violations
    assert (violation.check, violation.joint) == ("path", "elbow_joint")
    assert violation.time_s == pytest.approx(1.2)
    assert violation.error == pytest.approx(-0.3)
    assert violation.actual == pytest.approx(violation.reference + 0.3)
    assert report.margins["elbow_joint"] == pytest.approx(-0.1)


def test_lag_plant_recovers_from_small_disturbance():
    plant = make_plant("lag", {"tau": 0.01}, ur_jtc())
    report = simulate(UR_MOVE, ur_jtc(), ExecutionConfig(), plant,
                      disturbances=[Disturbance(1.0, "wrist_1_joint", 0.1)])
    assert report.ok
    assert report.margins["wrist_1_joint"] < 0.2 - 0.09


def test_pid_plant_with_sane_gains_follows_six_joint_trajectory():
    controller = ur_jtc(commands=("effort",), gains={"p": 400.0, "d": 40.0})
    report = simulate(UR_MOVE, controller, ExecutionConfig(), make_plant("pid", {}, controller))
    assert report.ok
    assert report.output_interface == "effort"
    assert min(report.margins.values()) > 0.05


@pytest.mark.parametrize("gains", [{"p": 4e4}, {"p": 1e6, "d": 10.0}])
def test_pid_plant_with_p_too_high_or_no_d_violates_path_tolerance(gains):
    controller = ur_jtc(commands=("effort",), gains=gains)
    report = simulate(UR_MOVE, controller, ExecutionConfig(), make_plant("pid", {}, controller))
    assert report.result.name == "PATH_TOLERANCE_VIOLATED"
    assert report.duration_s < UR_MOVE.duration_s


def test_pid_plant_measurement_noise_is_reproducible_by_seed():
    controller = ur_jtc(commands=("velocity",), gains={"p": 50.0, "ff_velocity_scale": 1.0})
    plant = make_plant("pid", {"noise": 1e-3}, controller)
    first = simulate(UR_MOVE, controller, ExecutionConfig(), plant, seed=7)
    again = simulate(UR_MOVE, controller, ExecutionConfig(), plant, seed=7)
    other = simulate(UR_MOVE, controller, ExecutionConfig(), plant, seed=8)
    np.testing.assert_array_equal(first.actual_positions, again.actual_positions)
    assert not np.array_equal(first.actual_positions, other.actual_positions)


def test_pid_plant_velocity_saturation_makes_robot_fall_behind():
    controller = ur_jtc(commands=("velocity",), gains={"p": 50.0, "ff_velocity_scale": 1.0})
    report = simulate(UR_MOVE, controller, ExecutionConfig(),
                      make_plant("pid", {"max_velocity": 0.3}, controller))
    assert report.result.name == "PATH_TOLERANCE_VIOLATED"
    assert np.abs(report.actual_velocities).max() <= 0.3 + 1e-12


def test_make_plant_rejects_unknown_plant_listing_known_ones():
    with pytest.raises(UsageError, match="unknown plant 'pdi'; known: lag, mirror, pid"):
        make_plant("pdi", {}, ur_jtc())


def test_make_plant_rejects_unknown_parameter_listing_valid_ones():
    with pytest.raises(UsageError, match=r"no parameter 'tua'; known: tau, tau\.elbow_joint"):
        make_plant("lag", {"tua": 0.1}, ur_jtc())
    with pytest.raises(UsageError, match="must be positive"):
        make_plant("lag", {"tau": 0.0}, ur_jtc())


def test_lag_time_constant_can_be_set_per_joint():
    plant = make_plant("lag", {"tau": 0.01, "tau.elbow_joint": 1.0}, ur_jtc())
    report = simulate(UR_MOVE, ur_jtc(trajectory=0.0, goal=0.0), ExecutionConfig(), plant)
    lag = np.abs(report.error).max(axis=0)
    assert lag[2] > 10 * lag[0]


def test_pid_plant_needs_velocity_or_effort_as_only_command_interface():
    with pytest.raises(UsageError, match=r"\[velocity\] or \[effort\].*\[position\]"):
        make_plant("pid", {}, ur_jtc())


# --- inputs --------------------------------------------------------------------------------


def test_trajectory_in_other_joint_order_is_sorted_to_controller_order():
    reversed_move = JointTrajectory(UR_JOINTS[::-1], UR_MOVE.times_s, UR_MOVE.positions[:, ::-1],
                                    UR_MOVE.velocities[:, ::-1], UR_MOVE.accelerations[:, ::-1])
    report = simulate(reversed_move, ur_jtc(), ExecutionConfig(), MirrorPlant(6))
    assert report.ok and report.joint_names == UR_JOINTS
    np.testing.assert_allclose(report.reference_positions[0], UR_HOME)


def test_trajectory_joint_unknown_to_controller_is_rejected():
    with pytest.raises(UnknownName, match="joint 'elbow' not found in controller"):
        simulate(points([0.0], [0.0], joints=("elbow",)), jtc(), ExecutionConfig(), MirrorPlant(3))


def test_partial_trajectory_is_rejected_like_jtc_without_partial_goals():
    with pytest.raises(InputError, match="don't match the controller joints.*joint3"):
        simulate(points([0.0], [0.0, 0.0], joints=JOINTS[:2]), jtc(), ExecutionConfig(),
                 MirrorPlant(3))


def test_disturbance_of_unknown_joint_lists_known_joints():
    with pytest.raises(UsageError, match="'elbow'.*known: elbow_joint"):
        simulate(UR_MOVE, ur_jtc(), ExecutionConfig(), MirrorPlant(6),
                 disturbances=[Disturbance(1.0, "elbow", 0.1)])


def test_report_series_share_one_time_base_and_are_read_only():
    plant = make_plant("lag", {"tau": 0.01}, ur_jtc())
    report = simulate(UR_MOVE, ur_jtc(), ExecutionConfig(), plant)
    k = len(report.times_s)
    for series in (report.reference_positions, report.reference_velocities,
                   report.reference_accelerations, report.actual_positions,
                   report.actual_velocities, report.output, report.error):
        assert series.shape == (k, 6)
        assert not series.flags.writeable
    assert report.duration_s == report.times_s[-1]
    np.testing.assert_allclose(np.diff(report.times_s), 1 / 500.0)


def test_plant_classes_start_at_rest_where_reset():
    no_gains = {g: np.zeros(2) for g in ("p", "i", "d", "i_clamp", "ff_velocity_scale")}
    plants = (MirrorPlant(2), FrozenPlant(2), LagPlant([0.1, 0.1]), PidPlant(no_gains, "effort"))
    for plant in plants:
        positions, velocities = plant.reset([0.5, -0.5])
        np.testing.assert_array_equal(positions, [0.5, -0.5])
        np.testing.assert_array_equal(velocities, [0.0, 0.0])


def test_a_last_point_that_still_moves_is_refused_unless_the_controller_allows_it(tmp_path) -> None:
    """A12 (test_trajectory_actions.cpp test_allow_nonzero_velocity_at_trajectory_end_{false,true})."""
    from dataclasses import replace

    from moveplan.core.control import validate_goal_end

    moving = JointTrajectory(JOINTS, [0.25, 0.5], [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
                             [[0.0] * 3, [4.0, 5.0, 6.0]], np.zeros((2, 3)))
    with pytest.raises(InputError, match=r"invalid goal, the controller would reject it: Velocity of last trajectory "
                                         r"point of joint joint1 is not zero: 4.000000000000000"):
        validate_goal_end(moving, jtc().allow_nonzero_velocity_at_trajectory_end, "goal")
    stopped = replace(moving, velocities=np.zeros((2, 3)))
    validate_goal_end(stopped, False, "goal")  # the same trajectory ending at rest is accepted
    validate_goal_end(moving, True, "goal")
    report = simulate(moving, replace(jtc(stopped_velocity=0.0), allow_nonzero_velocity_at_trajectory_end=True),
                      NO_START_CHECK, MirrorPlant(3), start_positions=INITIAL)
    assert report.ok and report.result.name == "SUCCESSFUL"


def test_a_positions_only_goal_is_interpolated_linearly_from_the_state_read() -> None:
    """Every goal of test_trajectory_actions.cpp carries positions only; JTC interpolates linearly (A1)."""
    report = simulate(points([1.0], [2.1, 3.1, 4.1]), jtc(), NO_START_CHECK, MirrorPlant(3), start_positions=INITIAL)
    assert report.ok
    middle = int(np.searchsorted(report.times_s, 0.5))
    np.testing.assert_allclose(report.reference_velocities[middle], [1.0, 1.0, 1.0], atol=1e-9)
    np.testing.assert_allclose(report.reference_positions[middle], INITIAL + report.times_s[middle], atol=1e-9)


@pytest.mark.parametrize(("release", "velocity"), [("jazzy", 1.875), ("4.35.0", 1.0)])
def test_the_blend_before_a_late_first_point_has_the_trajectorys_degree_since_4_36(release, velocity) -> None:
    """test_trajectory.cpp fill_point_before_with_same_degree_as_traj (PR #2043): a position-only state gets zero
    velocity and acceleration, so the blend to a first point at 1 s is quintic; before 4.36.0 it was linear."""
    from moveplan.core.control import fills_point_before

    trajectory = JointTrajectory(("joint1",), [1.0, 2.0], [[1.0], [2.0]], np.zeros((2, 1)), np.zeros((2, 1)))
    controller = jtc(joints=("joint1",), states=("position",))
    report = simulate(trajectory, controller, NO_START_CHECK, MirrorPlant(1), start_positions=[0.0],
                      fill_point_before=fills_point_before(release))
    first = 0
    np.testing.assert_allclose(report.reference_positions[first], [0.0], atol=1e-12)
    middle = int(np.searchsorted(report.times_s, 0.5))
    assert report.times_s[middle] == pytest.approx(0.5)
    np.testing.assert_allclose(report.reference_positions[middle], [0.5], atol=1e-9)
    np.testing.assert_allclose(report.reference_velocities[middle], [velocity], atol=1e-9)


def test_ros2_controllers_releases_are_named_by_distro_or_version() -> None:
    from moveplan.core.control import fills_point_before

    assert fills_point_before("humble") and fills_point_before("Jazzy") and fills_point_before("2.52.0")
    assert not fills_point_before("2.51.3") and not fills_point_before("4.35") and not fills_point_before("3.29.0")
    assert fills_point_before("4.36.0") and fills_point_before("5.11.0") and not fills_point_before("5.10.0")
    with pytest.raises(UsageError, match=r"--ros2-controllers 'iron-ish': expected a distro \(humble, jazzy"):
        fills_point_before("iron-ish")
