"""Recorded executions judged against plans with the controller's tolerance rules."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from mcap.writer import Writer

from moveplan.core.bag.jointstates import (
    JOINT_STATE_TYPE,
    JointStateSeries,
    encode_joint_states,
    read_joint_states,
)
from moveplan.core.bag.plan_file import PlanStepRecord
from moveplan.core.config.controllers import ControllerConfig, ExecutionConfig
from moveplan.core.control.check.recording import check_recording, uses_velocities
from moveplan.core.control.check.report import CheckReport
from moveplan.core.control.controller import WAIT_LIMIT_S, Disturbance, simulate
from moveplan.core.control.plants import MirrorPlant
from moveplan.core.control.results import INCOMPLETE
from moveplan.core.errors import InputError, UsageError
from moveplan.core.trajectory import sample
from moveplan.core.types import JointTrajectory

JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
          "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")
HOME = np.array([0.0, -np.pi / 2, -np.pi / 2, 0.0, 0.0, 0.0])
PICK = HOME + np.array([1.0, 0.5, -0.8, 1.2, -1.0, 1.5])
RATE = 250.0
EXECUTION = ExecutionConfig()
SCHEMA = (Path(__file__).resolve().parents[2] / "core/bag/cdr/msgs/jazzy/sensor_msgs__msg__JointState.msg")


@dataclass(frozen=True)
class Plan:
    steps: tuple[PlanStepRecord, ...]


def minimum_jerk(start, goal, duration: float) -> JointTrajectory:
    t = np.linspace(0.0, duration, int(round(duration / 0.1)) + 1)
    s = (t / duration)[:, None]
    delta = np.asarray(goal) - np.asarray(start)
    return JointTrajectory(
        JOINTS, t, start + (10 * s**3 - 15 * s**4 + 6 * s**5) * delta,
        (30 * s**2 - 60 * s**3 + 30 * s**4) / duration * delta,
        (60 * s - 180 * s**2 + 120 * s**3) / duration**2 * delta,
    )


OUT = minimum_jerk(HOME, PICK, 2.0)
BACK = minimum_jerk(PICK, HOME, 2.0)
ONE_STEP = Plan((PlanStepRecord("out", 0.0, OUT),))
CYCLE = Plan((PlanStepRecord("out", 0.0, OUT), PlanStepRecord("back", 2.0, BACK)))


def jtc(commands=("position",), goal_time: float = 0.5, joints=JOINTS) -> ControllerConfig:
    return ControllerConfig(
        name="joint_trajectory_controller", joints=joints, update_rate_hz=500.0,
        command_interfaces=commands, state_interfaces=("position", "velocity"),
        goal_time_s=goal_time, stopped_velocity_tolerance=0.2,
        trajectory_tolerance={j: 0.2 for j in joints}, goal_tolerance={j: 0.1 for j in joints},
        gains={},
    )


def follow(times, starts_and_trajectories, delay: float = 0.0):
    """Positions and velocities of a robot executing each trajectory from its start time."""
    first = starts_and_trajectories[0][1]
    positions = np.tile(first.positions[0], (len(times), 1))
    velocities = np.zeros_like(positions)
    for start, trajectory in starts_and_trajectories:
        mask = times >= start + delay
        p, v, _ = sample(trajectory, times[mask] - start - delay)
        positions[mask], velocities[mask] = p, v
    return positions, velocities


def series(times, positions, velocities=None) -> JointStateSeries:
    return JointStateSeries(JOINTS, times, positions, velocities, 1_700_000_000 * 10**9)


def grid(duration: float, rate: float = RATE):
    return np.arange(int(duration * rate)) / rate


def check(plan, recorded, controller=None, **options) -> CheckReport:
    return check_recording(plan, recorded, controller or jtc(), EXECUTION, **options)


# --- one execution --------------------------------------------------------------------------


def test_recording_that_follows_the_plan_passes_and_is_aligned() -> None:
    times = grid(4.0)
    positions, velocities = follow(times, [(0.73, OUT)], delay=0.003)
    report = check(ONE_STEP, series(times, positions, velocities))
    assert report.ok and report.result.name == "SUCCESSFUL" and report.violations == ()
    assert report.start_s == pytest.approx(0.733, abs=1e-3)
    assert report.steps[0].aligned_by == "departure"
    assert report.duration_s == pytest.approx(2.0, abs=0.01)
    assert min(report.margins.values()) > 0.09


def test_spike_beyond_path_tolerance_names_joint_and_time() -> None:
    times = grid(4.0)
    positions, _ = follow(times, [(0.5, OUT)])
    positions[(times >= 1.7) & (times < 1.72), 2] += 0.3
    report = check(ONE_STEP, series(times, positions))
    assert not report.ok and report.result.name == "PATH_TOLERANCE_VIOLATED"
    (step, violation), = report.violations
    assert step == "out" and violation.check == "path" and violation.joint == "elbow_joint"
    assert violation.time_s == pytest.approx(1.2, abs=0.005)
    assert report.steps[0].start_s + violation.time_s == pytest.approx(1.7, abs=0.005)
    assert abs(violation.error) > 0.2 and violation.tolerance == 0.2
    assert report.margins["elbow_joint"] < 0


def test_robot_that_arrives_late_misses_the_goal_within_goal_time() -> None:
    times = grid(5.0)
    positions, _ = follow(times, [(0.5, OUT)])
    # The last 0.15 rad of shoulder_pan_joint come a second late: inside the path
    # tolerance, outside the goal tolerance for longer than goal_time.
    positions[:, 0] -= np.interp(times, [1.5, 2.5, 3.5, 4.0], [0.0, 0.15, 0.15, 0.0])
    report = check(ONE_STEP, series(times, positions))
    assert report.result.name == "GOAL_TOLERANCE_VIOLATED"
    checks = [(v.check, v.joint) for _, v in report.violations]
    assert checks == [("goal_time", ""), ("goal", "shoulder_pan_joint")]
    assert report.steps[0].duration_s == pytest.approx(2.5, abs=0.01)


def test_continuous_joint_errors_wrap_around() -> None:
    times = grid(3.5)
    positions, _ = follow(times, [(0.5, OUT)])
    positions[:, 5] += 2 * np.pi  # wrist_3_joint recorded one turn off
    assert check(ONE_STEP, series(times, positions), continuous_joints=["wrist_3_joint"]).ok
    wrapped_not = check(ONE_STEP, series(times, positions))
    assert wrapped_not.result.name == "START_STATE_INVALID"


def test_given_start_time_is_used_as_is() -> None:
    times = grid(4.0)
    positions, _ = follow(times, [(0.5, OUT)])
    assert check(ONE_STEP, series(times, positions), start=0.5).ok
    late = check(ONE_STEP, series(times, positions), start=0.3)
    assert late.result.name == "PATH_TOLERANCE_VIOLATED" and late.steps[0].aligned_by == "given"


def test_start_far_from_the_plan_is_refused_as_moveit_does() -> None:
    times = grid(3.5)
    positions, _ = follow(times, [(0.5, OUT)])
    positions[:, 1] += 0.015
    report = check(ONE_STEP, series(times, positions))
    assert report.result.name == "START_STATE_INVALID"
    assert report.violations[0][1].joint == "shoulder_lift_joint"


def test_recording_that_ends_early_is_incomplete_not_timed_out() -> None:
    times = grid(1.5)
    positions, _ = follow(times, [(0.5, OUT)])
    report = check(ONE_STEP, series(times, positions))
    assert report.result.code == INCOMPLETE and report.result.name == "INCOMPLETE"
    assert not report.ok and not report.complete and report.violations == ()
    assert "recording ends 1.004 s before the plan's execution could finish" in report.result.message
    assert not report.steps[0].complete


def test_recording_that_ends_inside_goal_time_is_incomplete_without_a_goal_margin() -> None:
    times = grid(2.8)  # ends 0.3 s after the last point, inside goal_time 0.5 s
    positions, _ = follow(times, [(0.5, OUT)])
    positions[:, 0] -= np.interp(times, [1.5, 2.5], [0.0, 0.15])  # 0.15 short: outside the goal
    report = check(ONE_STEP, series(times, positions))
    assert report.result.name == "INCOMPLETE" and report.violations == ()
    assert "before the controller decided step 'out'" in report.result.message
    # The path margin 0.2 - 0.15 counts; the goal margin 0.1 - 0.15 at the cut does not.
    assert report.margins["shoulder_pan_joint"] == pytest.approx(0.05, abs=0.005)


def test_without_any_time_limit_a_robot_stuck_short_times_out_where_execute_gives_up() -> None:
    # goal_time 0 and no duration monitor: nothing ever stops the wait, so the check stops
    # where `execute --fake` does, WAIT_LIMIT_S after the last point.
    unmonitored = ExecutionConfig(execution_duration_monitoring=False)
    for length, verdict in ((6.0, "INCOMPLETE"), (13.0, "TIMED_OUT")):
        times = grid(length)
        positions, _ = follow(times, [(0.5, OUT)])
        positions[:, 0] -= np.interp(times, [1.5, 2.5], [0.0, 0.15])  # never within the goal
        report = check_recording(ONE_STEP, series(times, positions), jtc(goal_time=0.0), unmonitored)
        assert report.result.name == verdict
    assert report.steps[0].duration_s == pytest.approx(2.0 + WAIT_LIMIT_S, abs=0.01)


def test_violation_before_the_recording_ends_still_fails() -> None:
    times = grid(1.5)
    positions, _ = follow(times, [(0.5, OUT)])
    positions[(times >= 1.2) & (times < 1.22), 2] += 0.3
    report = check(ONE_STEP, series(times, positions))
    assert report.result.name == "PATH_TOLERANCE_VIOLATED" and report.complete
    assert report.violations[0][1].joint == "elbow_joint"


def test_recording_that_begins_after_the_goal_was_sent_is_incomplete() -> None:
    times = grid(3.5)
    positions, _ = follow(times, [(-0.2, OUT)])  # 12 mrad from the first point at the first sample
    report = check(ONE_STEP, series(times, positions))
    assert report.result.name == "INCOMPLETE" and "recording begins" in report.result.message
    assert report.start_s == pytest.approx(-0.2, abs=5e-3)  # aligned by where it leaves the zone
    assert report.steps[0].ok  # judged, but MoveIt's start check has no state to check


def test_recording_from_the_send_time_is_complete() -> None:
    times = grid(3.0)
    positions, _ = follow(times, [(0.0, OUT)])
    report = check(ONE_STEP, series(times, positions))
    assert report.ok and report.complete and report.start_s == pytest.approx(0.0, abs=1e-3)


def test_execution_longer_than_moveit_allows_times_out() -> None:
    times = grid(6.0)
    positions, _ = follow(times, [(0.5, minimum_jerk(HOME, PICK, 4.0))])
    # No path tolerance and goal_time 0: only MoveIt's duration monitor stops the wait.
    tolerant = jtc(goal_time=0.0)
    tolerant = ControllerConfig(**{**tolerant.__dict__,
                                   "trajectory_tolerance": {j: 0.0 for j in JOINTS}})
    report = check(ONE_STEP, series(times, positions), tolerant)
    assert report.result.name == "TIMED_OUT"
    assert "taking too long" in report.result.message
    assert report.steps[0].duration_s == pytest.approx(2.0 * 1.1 + 0.5, abs=0.01)


def test_stopped_velocity_is_checked_only_where_jtc_computes_velocity_errors() -> None:
    times = grid(4.0)
    positions, velocities = follow(times, [(0.5, OUT)])
    velocities[(times > 2.4) & (times < 3.3)] = 0.5  # still moving after arriving
    recorded = series(times, positions, velocities)
    assert check(ONE_STEP, recorded, jtc(commands=("position",))).ok
    report = check(ONE_STEP, recorded, jtc(commands=("velocity",)))
    assert report.result.name == "GOAL_TOLERANCE_VIOLATED"
    assert {v.check for _, v in report.violations} == {"goal_time", "stopped_velocity"}


def test_velocities_are_read_only_where_jtc_computes_velocity_errors_or_blends_from_them() -> None:
    assert not uses_velocities(CYCLE, jtc())
    assert uses_velocities(CYCLE, jtc(commands=("velocity",)))
    later = JointTrajectory(JOINTS, OUT.times_s + 0.1, OUT.positions, OUT.velocities,
                            OUT.accelerations)
    assert uses_velocities(Plan((PlanStepRecord("out", 0.0, later),)), jtc())


def test_steps_are_separate_goals_started_by_their_departures() -> None:
    times = grid(7.0)
    # MoveIt sends "back" 0.8 s after "out" ended: the plan's timeline says 0 s.
    positions, _ = follow(times, [(0.5, OUT), (3.3, BACK)])
    report = check(CYCLE, series(times, positions))
    assert report.ok and [s.name for s in report.steps] == ["out", "back"]
    assert report.steps[1].start_s == pytest.approx(3.3, abs=2e-3)
    given = check(CYCLE, series(times, positions), start=0.5)
    assert given.ok and given.steps[1].aligned_by == "departure"  # it places the first step only


def test_gaps_are_reported() -> None:
    times = grid(4.0)
    keep = (times < 1.0) | (times > 1.3)
    positions, _ = follow(times[keep], [(0.5, OUT)])
    report = check(ONE_STEP, series(times[keep], positions))
    (start, length), = report.gaps
    assert start == pytest.approx(1.0, abs=0.005) and length == pytest.approx(0.3, abs=0.01)
    assert any("gap" in w for w in report.warnings)


def test_same_verdict_as_the_simulated_controller() -> None:
    controller = jtc()
    for disturbances in ((), (Disturbance(1.2, "elbow_joint", 0.3),)):
        simulated = simulate(OUT, controller, EXECUTION, MirrorPlant(6),
                             disturbances=disturbances)
        recorded = series(simulated.times_s, simulated.actual_positions)
        report = check(ONE_STEP, recorded, controller, start=0.0)
        assert report.result.code == simulated.result.code
        assert report.steps[0].duration_s == pytest.approx(simulated.duration_s)
        assert [(v.check, v.joint, v.time_s) for _, v in report.violations] == \
            [(v.check, v.joint, v.time_s) for v in simulated.violations]


def test_missing_controller_joint_is_an_input_error() -> None:
    times = grid(1.0)
    recorded = JointStateSeries(JOINTS[:5], times, np.zeros((len(times), 5)), None, 0)
    with pytest.raises(InputError, match="no joint wrist_3_joint"):
        check(ONE_STEP, recorded)


def test_unknown_start_is_a_usage_error() -> None:
    times = grid(1.0)
    with pytest.raises(UsageError, match="start"):
        check(ONE_STEP, series(times, np.tile(HOME, (len(times), 1))), start="first")


# --- every execution in a long recording ------------------------------------------------------


def cycles_recording(starts, bad: int | None = None):
    times = grid(starts[-1] + 6.0)
    pieces = []
    for start in starts:
        pieces += [(start, OUT), (start + 2.3, BACK)]
    positions, velocities = follow(times, pieces, delay=0.002)
    if bad is not None:
        spike = (times >= starts[bad] + 3.0) & (times < starts[bad] + 3.02)
        positions[spike, 3] -= 0.25
    return times, positions, velocities


def test_start_all_reports_exactly_the_bad_cycle() -> None:
    starts = [0.6, 6.61, 12.6, 18.59]
    times, positions, velocities = cycles_recording(starts, bad=2)
    report = check(CYCLE, series(times, positions, velocities), start="all")
    assert [c.index for c in report.cycles] == [0, 1, 2, 3]
    np.testing.assert_allclose([c.start_s for c in report.cycles], np.add(starts, 0.002), atol=2e-3)
    assert report.failing_cycles == (2,) and not report.ok
    assert [c.ok for c in report.cycles] == [True, True, False, True]
    bad = report.cycles[2]
    assert bad.result.name == "PATH_TOLERANCE_VIOLATED"
    assert [s.name for s in bad.steps] == ["out", "back"] and bad.worst_margin < 0
    assert report.result.name == "PATH_TOLERANCE_VIOLATED" and "cycle 2" in report.result.message
    assert report.violations[0][0] == "back" and report.violations[0][1].joint == "wrist_1_joint"
    assert all(c.worst_margin > 0.09 for c in report.cycles if c.ok)


def cut(times, positions, velocities, begin: float, end: float):
    keep = (times >= begin) & (times < end)
    return series(times[keep] - begin, positions[keep], velocities[keep])


def test_start_all_counts_a_last_cycle_cut_by_the_end_as_incomplete_not_failing() -> None:
    starts = [0.6, 6.61, 12.6]
    recorded = cut(*cycles_recording(starts), 0.0, starts[2] + 1.0)  # ends in step out
    report = check(CYCLE, recorded, start="all")
    assert report.ok and report.complete and report.result.name == "SUCCESSFUL"
    assert report.failing_cycles == () and report.incomplete_cycles == (2,)
    last = report.cycles[2]
    assert not last.ok and not last.complete and last.result.code == INCOMPLETE
    assert "before the plan's execution could finish" in last.result.message
    assert [s.name for s in last.steps] == ["out"] and last.worst_margin > 0.09
    assert "2 complete executions within tolerances; 1 incomplete" in report.result.message


def test_start_all_counts_a_first_cycle_begun_before_the_recording_as_incomplete() -> None:
    starts = [0.6, 6.61, 12.6]
    recorded = cut(*cycles_recording(starts), 0.8, 20.0)  # 0.2 s into cycle 0, near its start
    report = check(CYCLE, recorded, start="all")
    assert report.ok and report.failing_cycles == () and report.incomplete_cycles == (0,)
    first = report.cycles[0]
    assert first.result.name == "INCOMPLETE" and "recording begins about 0.198 s" in first.result.message
    assert first.start_s == pytest.approx(-0.198, abs=2e-3)  # the robot lags its command by 2 ms
    assert [s.ok for s in first.steps] == [True, True]  # judged, as far as recorded
    assert [c.ok for c in report.cycles[1:]] == [True, True]


def test_start_all_lists_a_cycle_already_running_at_the_first_sample_as_incomplete() -> None:
    starts = [0.6, 6.61, 12.6]
    recorded = cut(*cycles_recording(starts), 2.0, 20.0)  # mid step out: no departure recorded
    report = check(CYCLE, recorded, start="all")
    assert report.ok and report.incomplete_cycles == (0,)
    assert [c.index for c in report.cycles] == [0, 1, 2]
    running = report.cycles[0]
    assert running.steps == () and running.start_s == 0.0 and running.worst_margin is None
    assert "already running" in running.result.message
    np.testing.assert_allclose([c.start_s for c in report.cycles[1:]],
                               np.subtract(starts[1:], 2.0 - 0.002), atol=2e-3)
    auto = check(CYCLE, recorded)
    assert auto.ok and any("already running" in w for w in auto.warnings)


def test_start_all_fails_a_cut_cycle_that_violated_before_the_cut() -> None:
    starts = [0.6, 6.61, 12.6]
    times, positions, velocities = cycles_recording(starts, bad=2)  # spike 3.0 s into cycle 2
    report = check(CYCLE, cut(times, positions, velocities, 0.0, starts[2] + 3.5), start="all")
    assert not report.ok and report.failing_cycles == (2,) and report.incomplete_cycles == ()
    assert report.cycles[2].result.name == "PATH_TOLERANCE_VIOLATED"


def test_start_all_with_no_complete_cycle_is_incomplete() -> None:
    starts = [0.6]
    report = check(CYCLE, cut(*cycles_recording(starts), 0.0, 2.0), start="all")
    assert not report.ok and not report.complete and report.incomplete_cycles == (0,)
    assert report.result.name == "INCOMPLETE" and "no complete execution" in report.result.message


def test_start_all_without_any_execution_is_an_input_error() -> None:
    times = grid(3.0)
    with pytest.raises(InputError, match="no execution of the plan"):
        check(CYCLE, series(times, np.tile(PICK, (len(times), 1))), start="all")


def test_file_written_at_1khz_read_and_checked(tmp_path: Path) -> None:
    starts = [0.5, 6.5, 12.5]
    times, positions, velocities = cycles_recording(starts, bad=1)
    stamps = 1_700_000_000 * 10**9 + np.round(times * 1e9).astype(np.int64)
    path = tmp_path / "cycles.mcap"
    with path.open("wb") as stream:
        writer = Writer(stream, chunk_size=64 * 1024)
        writer.start("ros2", "test")
        schema = writer.register_schema(JOINT_STATE_TYPE, "ros2msg", SCHEMA.read_bytes())
        channel = writer.register_channel("/joint_states", "cdr", schema)
        for stamp, data in zip(stamps.tolist(), encode_joint_states(JOINTS, stamps, positions,
                                                                    velocities), strict=True):
            writer.add_message(channel, stamp, data, stamp)
        writer.finish()
    recorded = read_joint_states(path, joints=JOINTS)
    report = check(CYCLE, recorded, start="all")
    assert report.failing_cycles == (1,) and len(report.cycles) == 3
