"""Executed files from report.write_execution, checked by rosbags and the reference encoder (mcap_ros2)."""

from __future__ import annotations

import json
import re
import time
from dataclasses import replace
from importlib.resources import files
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from mcap.reader import make_reader
from reference_cdr import reference_cdr
from rosbags.highlevel import AnyReader
from rosbags.interfaces import ConnectionExtRosbag2, QosDurability

from moveplan.core.bag.cdr import messages as msgs
from moveplan.core.bag.cdr.bulk import controller_states_cdr
from moveplan.core.bag.cdr.joint_state import encode_joint_states
from moveplan.core.bag.container._mcap_writer import McapWriter
from moveplan.core.bag.container.summary import summarize
from moveplan.core.bag.execution_file import EXECUTION_RESULT_TOPIC
from moveplan.core.bag.plan_file import PlanFile, read_plan
from moveplan.core.bag.plan_writer import write_plan
from moveplan.core.config.controllers import ControllerConfig, ExecutionConfig
from moveplan.core.control.controller import ExecutionReport, simulate
from moveplan.core.control.plants import FrozenPlant, MirrorPlant, make_plant
from moveplan.core.control.published import controller_states
from moveplan.core.control.results import Violation
from moveplan.core.errors import InputError, UsageError
from moveplan.core.pipeline.execution import PlanExecution, StepExecution
from moveplan.core.pipeline.report import execution_document, write_execution
from moveplan.core.types import ControllerStates, JointTrajectory, Plan, PointSeries, StepResult, TfSamples

DISTROS = sorted(
    entry.name
    for entry in files("moveplan.core.bag.cdr.msgs").iterdir()
    if entry.is_dir() and entry.name.isalpha()
)
JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint")
STATE_TOPIC = "/joint_trajectory_controller/controller_state"
RESULT_TOPIC = EXECUTION_RESULT_TOPIC
JOINT_STATE = "sensor_msgs/msg/JointState"
CONTROLLER_STATE = "control_msgs/msg/JointTrajectoryControllerState"
URDF = "<robot name='threelink'><link name='base_link'/></robot>"
# Names of every length mod 8, so strings leave every possible padding before what follows.
ODD_NAMES = ("j", "jo", "joi", "join", "joint", "joint_", "joint_1", "joint_12", "joint_123")


def jtc(
    joints: tuple[str, ...] = JOINTS,
    rate: float = 100.0,
    commands: tuple[str, ...] = ("position",),
    states: tuple[str, ...] = ("position", "velocity"),
    name: str = "joint_trajectory_controller",
) -> ControllerConfig:
    return ControllerConfig(
        name=name, joints=joints, update_rate_hz=rate, command_interfaces=commands,
        state_interfaces=states, goal_time_s=0.0, stopped_velocity_tolerance=0.01,
        trajectory_tolerance={j: 0.2 for j in joints}, goal_tolerance={j: 0.1 for j in joints},
        gains={j: {"p": 5.0} for j in joints},
    )


def minimum_jerk(
    start: np.ndarray, delta: np.ndarray, duration: float, joints: tuple[str, ...] = JOINTS
) -> JointTrajectory:
    t = np.linspace(0.0, duration, 11)
    s = (t / duration)[:, None]
    return JointTrajectory(
        joints, t, start + (10 * s**3 - 15 * s**4 + 6 * s**5) * delta,
        (30 * s**2 - 60 * s**3 + 30 * s**4) / duration * delta,
        (60 * s - 180 * s**2 + 120 * s**3) / duration**2 * delta,
    )


def plan_file(urdf: str = URDF, attachments: dict[str, bytes] | None = None) -> PlanFile:
    return PlanFile(
        robot_name="threelink", group="arm", planning_frame="base_link", distro="jazzy", steps=(),
        attachments=attachments or {}, metadata={}, limits={}, urdf=urdf,
    )


def execution_of(
    reports: list[tuple[str, ExecutionReport]],
    controller: ControllerConfig,
    plan: PlanFile | None = None,
) -> PlanExecution:
    steps = tuple(StepExecution(name, report) for name, report in reports)
    last = steps[-1].report
    return PlanExecution(last.ok, last.result, steps, controller, plan or plan_file())


@pytest.fixture(scope="module")
def two_steps() -> PlanExecution:
    """Two steps through a lagging plant at 100 Hz; 0.537 s makes a duration off the grid."""
    controller = jtc()
    home = np.array([0.0, -1.5, 1.2])
    first = minimum_jerk(home, np.array([0.5, 0.3, -0.4]), 0.537)
    second = minimum_jerk(first.positions[-1], np.array([-0.2, 0.1, 0.6]), 0.3)
    reports = []
    start = None
    for name, trajectory in (("approach", first), ("retreat", second)):
        plant = make_plant("lag", {"tau": 0.02}, controller)
        report = simulate(trajectory, controller, ExecutionConfig(), plant, start_positions=start)
        assert report.ok and np.abs(report.error).max() > 1e-3  # errors to see in the file
        reports.append((name, report))
        start = report.actual_positions[-1]
    return execution_of(reports, controller)


def write(tmp_path: Path, execution: PlanExecution, distro: str = "jazzy", **kwargs: Any) -> Path:
    path = tmp_path / f"executed_{distro}.mcap"
    write_execution(path, execution, distro, **kwargs)
    return path


def read_all(path: Path) -> list[tuple[str, int, Any]]:
    """(topic, log time [ns], message) decoded by rosbags with the file's own schemas."""
    with AnyReader([path]) as reader:
        return [(c.topic, t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages()]


def on(messages: list[tuple[str, int, Any]], topic: str) -> list[tuple[int, Any]]:
    return [(t, m) for name, t, m in messages if name == topic]


def ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def cycle_stamps(execution: PlanExecution) -> list[int]:
    """Every cycle's time on the execution's timeline, steps one after the other, in [ns]."""
    stamps, start = [], 0
    for step in execution.steps:
        stamps += [start + round(t * 1e9) for t in step.report.times_s]
        start += round(step.report.duration_s * 1e9)
    return stamps


def metadata_records(path: Path) -> dict[str, dict[str, str]]:
    with path.open("rb") as stream:
        records = make_reader(stream).iter_metadata()
        return {record.name: dict(record.metadata) for record in records}


# --- the file is a rosbag2 bag with the expected topics ------------------------------------------


@pytest.mark.parametrize("distro", DISTROS)
def test_executed_file_has_the_topics_types_counts_and_schemas_of_its_distro(
    tmp_path: Path, two_steps: PlanExecution, distro: str
) -> None:
    path = write(tmp_path, two_steps, distro)
    cycles = sum(len(s.report.times_s) for s in two_steps.steps)
    shipped = files("moveplan.core.bag.cdr.msgs").joinpath(distro)
    with AnyReader([path]) as reader:
        counts = {topic: info.msgcount for topic, info in reader.topics.items()}
        types = {c.topic: c.msgtype for c in reader.connections}
        for connection in reader.connections:
            ext = connection.ext
            assert isinstance(ext, ConnectionExtRosbag2) and ext.serialization_format == "cdr"
            want = shipped.joinpath(connection.msgtype.replace("/", "__") + ".msg").read_text()
            assert connection.msgdef.data == want, connection.topic
            durability = ext.offered_qos_profiles[0].durability
            latched = connection.topic in ("/robot_description", RESULT_TOPIC)
            assert durability == (
                QosDurability.TRANSIENT_LOCAL if latched else QosDurability.VOLATILE
            ), connection.topic
    assert types == {
        "/robot_description": "std_msgs/msg/String",
        "/joint_states": JOINT_STATE,
        STATE_TOPIC: CONTROLLER_STATE,
        RESULT_TOPIC: "std_msgs/msg/String",
    }
    assert counts == {"/robot_description": 1, "/joint_states": cycles, STATE_TOPIC: cycles,
                      RESULT_TOPIC: 1}
    assert metadata_records(path)["rosbag2"] == {"ROS_DISTRO": distro}
    summary = summarize(path)
    assert summary.profile == "ros2" and summary.start_ns == 0
    assert summary.end_ns == cycle_stamps(two_steps)[-1]


def test_controller_state_topic_is_named_after_the_controller(
    tmp_path: Path, two_steps: PlanExecution
) -> None:
    execution = replace(two_steps, controller=replace(two_steps.controller, name="arm_controller"))
    with AnyReader([write(tmp_path, execution)]) as reader:
        assert "/arm_controller/controller_state" in reader.topics
        assert STATE_TOPIC not in reader.topics


# --- message contents ----------------------------------------------------------------------------


def test_joint_states_hold_the_measured_state_of_every_cycle_steps_one_after_the_other(
    tmp_path: Path, two_steps: PlanExecution
) -> None:
    messages = on(read_all(write(tmp_path, two_steps)), "/joint_states")
    stamps = cycle_stamps(two_steps)
    assert [t for t, _ in messages] == stamps
    assert [ns(m.header.stamp) for _, m in messages] == stamps
    # The second step starts at the first one's duration, off the 10 ms grid's integer ms.
    first = len(two_steps.steps[0].report.times_s)
    assert stamps[first] == round(two_steps.steps[0].report.duration_s * 1e9) == stamps[first - 1]
    for _, message in messages:
        assert list(message.name) == list(JOINTS) and message.header.frame_id == ""
        assert len(message.effort) == 0
    positions = np.concatenate([s.report.actual_positions for s in two_steps.steps])
    velocities = np.concatenate([s.report.actual_velocities for s in two_steps.steps])
    np.testing.assert_array_equal([m.position for _, m in messages], positions)
    np.testing.assert_array_equal([m.velocity for _, m in messages], velocities)


@pytest.mark.parametrize("distro", DISTROS)
def test_controller_state_decodes_with_the_files_schema_and_holds_the_report(
    tmp_path: Path, two_steps: PlanExecution, distro: str
) -> None:
    messages = on(read_all(write(tmp_path, two_steps, distro)), STATE_TOPIC)
    assert [t for t, _ in messages] == cycle_stamps(two_steps)
    index = 0
    for step in two_steps.steps:
        report = step.report
        for k, time_s in enumerate(report.times_s):
            _, message = messages[index]
            index += 1
            assert ns(message.header.stamp) == messages[index - 1][0]
            assert list(message.joint_names) == list(JOINTS)
            reference, feedback = message.reference, message.feedback
            np.testing.assert_array_equal(reference.positions, report.reference_positions[k])
            np.testing.assert_array_equal(reference.velocities, report.reference_velocities[k])
            np.testing.assert_array_equal(
                reference.accelerations, report.reference_accelerations[k]
            )
            np.testing.assert_array_equal(feedback.positions, report.actual_positions[k])
            np.testing.assert_array_equal(feedback.velocities, report.actual_velocities[k])
            assert len(feedback.accelerations) == 0  # no acceleration state interface
            np.testing.assert_array_equal(message.error.positions, report.error[k])
            # Position command only: JTC leaves the velocity error at 0.
            np.testing.assert_array_equal(message.error.velocities, np.zeros(3))
            np.testing.assert_array_equal(message.output.positions, report.output[k])
            assert len(message.output.velocities) == len(message.output.effort) == 0
            points = [reference, feedback, message.error, message.output]
            if distro == "humble":
                # Deprecated fields, filled as Humble's JTC fills them since ros2_controllers#1985.
                for new, old in ((reference, message.desired), (feedback, message.actual)):
                    for field in ("positions", "velocities", "accelerations", "effort"):
                        np.testing.assert_array_equal(getattr(old, field), getattr(new, field))
                points += [message.desired, message.actual]
                assert not hasattr(message, "speed_scaling_factor")
            else:
                assert message.speed_scaling_factor == 1.0
                assert not hasattr(message, "desired")
            assert {ns(p.time_from_start) for p in points} == {round(time_s * 1e9)}
            assert list(message.multi_dof_joint_names) == []
            assert message.multi_dof_reference.transforms == []
    assert index == len(messages)


def test_velocity_command_fills_velocity_output_and_velocity_error(tmp_path: Path) -> None:
    controller = jtc(commands=("velocity",))
    plant = make_plant("pid", {}, controller)
    trajectory = minimum_jerk(np.zeros(3), np.array([0.2, -0.1, 0.3]), 0.4)
    report = simulate(trajectory, controller, ExecutionConfig(), plant)
    assert report.output_interface == "velocity"
    messages = on(read_all(write(tmp_path, execution_of([("move", report)], controller))),
                  STATE_TOPIC)
    assert len(messages) == len(report.times_s)
    for k, (_, message) in enumerate(messages):
        assert len(message.output.positions) == 0
        np.testing.assert_array_equal(message.output.velocities, report.output[k])
        np.testing.assert_array_equal(
            message.error.velocities,
            report.reference_velocities[k] - report.actual_velocities[k],
        )


def test_without_velocity_state_interface_feedback_and_error_have_no_velocities(
    tmp_path: Path,
) -> None:
    controller = jtc(states=("position",))
    trajectory = minimum_jerk(np.zeros(3), np.array([0.2, -0.1, 0.3]), 0.2)
    report = simulate(trajectory, controller, ExecutionConfig(), MirrorPlant(3))
    path = write(tmp_path, execution_of([("move", report)], controller))
    for _, message in on(read_all(path), STATE_TOPIC):
        assert len(message.feedback.velocities) == len(message.error.velocities) == 0
        assert len(message.reference.velocities) == 3
    # /joint_states still carries what the hardware measures.
    for _, message in on(read_all(path), "/joint_states"):
        assert len(message.velocity) == 3


def test_acceleration_state_interface_reads_zero_acceleration(tmp_path: Path) -> None:
    controller = jtc(states=("position", "velocity", "acceleration"))
    trajectory = minimum_jerk(np.zeros(3), np.array([0.2, -0.1, 0.3]), 0.2)
    report = simulate(trajectory, controller, ExecutionConfig(), MirrorPlant(3))
    path = write(tmp_path, execution_of([("move", report)], controller))
    for _, message in on(read_all(path), STATE_TOPIC):
        np.testing.assert_array_equal(message.feedback.accelerations, np.zeros(3))
        # No acceleration command interface: JTC leaves the acceleration error at 0.
        np.testing.assert_array_equal(message.error.accelerations, np.zeros(3))


# --- the result ----------------------------------------------------------------------------------


def test_result_json_is_on_its_latched_topic_and_in_the_metadata(
    tmp_path: Path, two_steps: PlanExecution
) -> None:
    path = write(tmp_path, two_steps)
    [(log_time, message)] = on(read_all(path), RESULT_TOPIC)
    document = json.loads(message.data)
    assert log_time == sum(round(s.report.duration_s * 1e9) for s in two_steps.steps)
    assert list(document)[:4] == ["ok", "result", "violations", "margins"]
    assert document["ok"] is True
    assert document["result"] == {"code": 0, "name": "SUCCESSFUL",
                                  "message": two_steps.result.message}
    assert document["violations"] == []
    assert document["margins"] == pytest.approx(two_steps.margins)
    assert document["controller"] == "joint_trajectory_controller"
    assert [(s["name"], s["ok"]) for s in document["steps"]] == [
        ("approach", True), ("retreat", True)
    ]
    assert document["steps"][1]["start_s"] == pytest.approx(two_steps.steps[0].report.duration_s)
    record = metadata_records(path)["moveplan_execution"]
    assert {key: json.loads(value) for key, value in record.items()} == document


def test_failed_execution_reports_its_violations_with_their_step(tmp_path: Path) -> None:
    controller = replace(jtc(), trajectory_tolerance={j: 1e-3 for j in JOINTS})
    trajectory = minimum_jerk(np.zeros(3), np.array([0.5, 0.0, 0.0]), 0.5)
    report = simulate(trajectory, controller, ExecutionConfig(), FrozenPlant(3))
    assert report.result.name == "PATH_TOLERANCE_VIOLATED"
    path = write(tmp_path, execution_of([("stuck", report)], controller))
    [(_, message)] = on(read_all(path), RESULT_TOPIC)
    document = json.loads(message.data)
    assert document["ok"] is False and document["result"]["code"] == -4
    assert {v["step"] for v in document["violations"]} == {"stuck"}
    assert {v["check"] for v in document["violations"]} == {"path"}
    assert len(on(read_all(path), "/joint_states")) == len(report.times_s)


def test_non_finite_numbers_become_json_null(tmp_path: Path, two_steps: PlanExecution) -> None:
    report = two_steps.steps[0].report
    diverged = replace(
        report,
        margins={"elbow_joint": float("-inf")},
        violations=(Violation("path", "elbow_joint", 0.1, 1.0, float("nan"), float("nan"), 0.2),),
    )
    execution = execution_of([("diverged", diverged)], two_steps.controller)
    [(_, message)] = on(read_all(write(tmp_path, execution)), RESULT_TOPIC)
    document = json.loads(message.data)  # strict JSON: no NaN or Infinity
    assert document["margins"] == {"elbow_joint": None}
    assert document["violations"][0]["actual"] is None
    assert "NaN" not in message.data and "Infinity" not in message.data


def test_execution_document_is_strict_json_however_the_plant_diverged(two_steps: PlanExecution) -> None:
    report = two_steps.steps[0].report
    nan = float("nan")
    diverged = replace(report, margins={"elbow_joint": nan},
                       violations=(Violation("goal", "elbow_joint", nan, 1.0, float("inf"), float("-inf"), 0.2),))
    document = execution_document(execution_of([("diverged", diverged)], two_steps.controller))
    json.dumps(document, allow_nan=False)
    assert document["margins"] == {"elbow_joint": None}
    assert [document["violations"][0][k] for k in ("time_s", "reference", "actual", "error")] == [None, 1.0, None, None]


def test_execution_that_never_started_writes_channels_and_result_but_no_cycles(
    tmp_path: Path,
) -> None:
    controller = jtc()
    trajectory = minimum_jerk(np.zeros(3), np.array([0.2, -0.1, 0.3]), 0.4)
    report = simulate(trajectory, controller, ExecutionConfig(), MirrorPlant(3),
                      start_positions=[0.5, 0.0, 0.0])
    assert report.result.name == "START_STATE_INVALID" and len(report.times_s) == 0
    path = write(tmp_path, execution_of([("refused", report)], controller))
    with AnyReader([path]) as reader:
        counts = {topic: info.msgcount for topic, info in reader.topics.items()}
    assert counts == {"/robot_description": 1, "/joint_states": 0, STATE_TOPIC: 0,
                      RESULT_TOPIC: 1}
    [(log_time, message)] = on(read_all(path), RESULT_TOPIC)
    assert log_time == 0 and json.loads(message.data)["result"]["code"] == -26


# --- /robot_description and /tf ------------------------------------------------------------------


def test_robot_description_comes_from_the_plan_and_is_latched_at_time_zero(
    tmp_path: Path, two_steps: PlanExecution
) -> None:
    [(log_time, message)] = on(read_all(write(tmp_path, two_steps)), "/robot_description")
    assert log_time == 0 and message.data == URDF


def test_robot_description_falls_back_to_the_plans_urdf_attachment(
    tmp_path: Path, two_steps: PlanExecution
) -> None:
    plan = plan_file(urdf="", attachments={"arm.urdf": b"<robot name='arm'/>", "a.srdf": b"x"})
    execution = replace(two_steps, plan=plan)
    [(_, message)] = on(read_all(write(tmp_path, execution)), "/robot_description")
    assert message.data == "<robot name='arm'/>"


def test_plan_without_urdf_writes_no_robot_description(
    tmp_path: Path, two_steps: PlanExecution
) -> None:
    execution = replace(two_steps, plan=plan_file(urdf=""))
    with AnyReader([write(tmp_path, execution)]) as reader:
        assert "/robot_description" not in reader.topics


def test_tf_samples_are_written_at_their_times(tmp_path: Path, two_steps: PlanExecution) -> None:
    times = np.array([0.0, 0.25, 0.537, 0.837])
    poses = np.tile([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], (4, 2, 1))
    poses[:, 1, 0] = times  # link_2 moves along x
    tf = TfSamples(times, ("base_link", "link_1"), ("link_1", "link_2"), poses)
    path = write(tmp_path, two_steps, tf=tf)
    messages = on(read_all(path), "/tf")
    assert [t for t, _ in messages] == [0, 250_000_000, 537_000_000, 837_000_000]
    for (log_time, message), x in zip(messages, times, strict=True):
        assert {ns(t.header.stamp) for t in message.transforms} == {log_time}
        assert message.transforms[1].child_frame_id == "link_2"
        assert message.transforms[1].transform.translation.x == x
    with AnyReader([path]) as reader:
        tf_connection = next(c for c in reader.connections if c.topic == "/tf")
        assert isinstance(tf_connection.ext, ConnectionExtRosbag2)
        assert tf_connection.ext.offered_qos_profiles[0].durability == QosDurability.VOLATILE


# --- read_plan gives the URDF back ---------------------------------------------------------------


def test_read_plan_returns_the_plans_robot_description(tmp_path: Path) -> None:
    trajectory = minimum_jerk(np.zeros(3), np.array([0.2, -0.1, 0.3]), 0.4)
    step = StepResult("move", {}, "RRTConnect", 0.01, trajectory)
    plan = Plan("threelink", "arm", "base_link", (step,), URDF)
    write_plan(tmp_path / "plan.mcap", plan)
    plan_read = read_plan(tmp_path / "plan.mcap")
    assert plan_read.urdf == URDF
    assert plan_read.steps[0].name == "move"


def test_plan_file_without_urdf_argument_still_builds() -> None:
    plan = PlanFile("r", "g", "f", "jazzy", (), {}, {}, {})
    assert plan.urdf == ""


# --- writes are atomic and reproducible ----------------------------------------------------------


def test_same_execution_written_twice_gives_identical_bytes(
    tmp_path: Path, two_steps: PlanExecution
) -> None:
    write_execution(tmp_path / "a.mcap", two_steps, "humble")
    write_execution(tmp_path / "b.mcap", two_steps, "humble")
    assert (tmp_path / "a.mcap").read_bytes() == (tmp_path / "b.mcap").read_bytes()


def test_failed_write_leaves_no_file_behind(
    tmp_path: Path, two_steps: PlanExecution, monkeypatch: pytest.MonkeyPatch
) -> None:
    def fail(*args: Any, **kwargs: Any) -> None:
        raise RuntimeError("disk on fire")

    monkeypatch.setattr(McapWriter, "add_metadata", fail)
    with pytest.raises(RuntimeError, match="disk on fire"):
        write_execution(tmp_path / "executed.mcap", two_steps)
    assert list(tmp_path.iterdir()) == []


def test_failed_write_keeps_the_previous_file(
    tmp_path: Path, two_steps: PlanExecution, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "executed.mcap"
    path.write_bytes(b"previous run")
    monkeypatch.setattr(McapWriter, "finish", lambda self: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        write_execution(path, two_steps)
    assert [p.name for p in tmp_path.iterdir()] == ["executed.mcap"]
    assert path.read_bytes() == b"previous run"


def test_write_into_a_missing_folder_raises_input_error_naming_it(
    tmp_path: Path, two_steps: PlanExecution
) -> None:
    path = tmp_path / "no" / "executed.mcap"
    with pytest.raises(InputError, match=re.escape(str(path)) + ".*cannot write"):
        write_execution(path, two_steps)


def test_unknown_distro_raises_usage_error_and_writes_nothing(
    tmp_path: Path, two_steps: PlanExecution
) -> None:
    with pytest.raises(UsageError, match="rolling.*humble, jazzy"):
        write_execution(tmp_path / "executed.mcap", two_steps, "rolling")
    assert list(tmp_path.iterdir()) == []


# --- the fast CDR encoders write what the reference encoder writes -------------------------------


def random_states(
    joints: int, count: int, seed: int, empty: tuple[str, ...] = ()
) -> ControllerStates:
    """Random series; `empty` names point fields ("feedback.velocities") left empty."""
    rng = np.random.default_rng(seed)
    shape = (count, joints)

    def series(name: str) -> PointSeries:
        fields = ("positions", "velocities", "accelerations", "effort")
        return PointSeries(**{
            field: rng.normal(size=shape) for field in fields if f"{name}.{field}" not in empty
        })

    stamps = np.cumsum(rng.integers(1, 1_500_000_000, count))  # some past a second
    return ControllerStates(
        joint_names=ODD_NAMES[:joints],
        stamps_ns=stamps,
        times_from_start_ns=stamps - stamps[:1] if count else stamps,
        reference=series("reference"),
        feedback=series("feedback"),
        error=series("error"),
        output=series("output"),
    )


STATE_CASES = [
    (6, 50, ()),
    (1, 1, ()),
    (1, 3, ("feedback.velocities", "output.positions")),
    (3, 1, ("reference.effort", "feedback.effort", "error.effort", "output.effort")),
    (7, 5, ("feedback.positions", "output.velocities", "output.accelerations")),
    (9, 4, ("error.velocities", "error.accelerations", "error.effort")),
    (2, 0, ()),
    (0, 2, ()),
]


@pytest.mark.parametrize("distro", DISTROS)
@pytest.mark.parametrize(("joints", "count", "empty"), STATE_CASES)
def test_fast_controller_states_match_the_generic_encoder(
    distro: str, joints: int, count: int, empty: tuple[str, ...]
) -> None:
    states = random_states(joints, count, seed=joints * 10 + count, empty=empty)
    encoded = controller_states_cdr(states, distro)
    assert len(encoded) == count
    messages = [msgs.controller_state(states, index, distro) for index in range(count)]
    assert encoded == reference_cdr(CONTROLLER_STATE, distro, messages)


@pytest.mark.parametrize("distro", DISTROS)
@pytest.mark.parametrize("frame_id", ["", "w", "base_link"])
@pytest.mark.parametrize(("joints", "count"), [(1, 1), (2, 0), (3, 3), (6, 40), (7, 2), (9, 5),
                                               (0, 2)])
def test_fast_joint_states_match_the_generic_encoder(
    distro: str, frame_id: str, joints: int, count: int
) -> None:
    rng = np.random.default_rng(joints + count)
    names = ODD_NAMES[:joints]
    stamps = np.cumsum(rng.integers(1, 1_500_000_000, count))
    positions, velocities = rng.normal(size=(count, joints)), rng.normal(size=(count, joints))
    encoded = encode_joint_states(names, stamps, positions, velocities, frame_id=frame_id)
    assert len(encoded) == count
    messages = [
        msgs.joint_state(names, stamp, q, v, frame_id)
        for stamp, q, v in zip(stamps.tolist(), positions, velocities, strict=True)
    ]
    assert encoded == reference_cdr(JOINT_STATE, distro, messages)


@pytest.mark.parametrize("distro", DISTROS)
def test_every_written_message_is_what_the_generic_encoder_writes(
    tmp_path: Path, two_steps: PlanExecution, distro: str
) -> None:
    # Odd joint names and a single-cycle step on top of the two-step execution.
    names = ("a", "bcd", "efghi")
    controller = replace(two_steps.controller, joints=names)
    hold = JointTrajectory(
        names, np.zeros(1), np.array([[0.1, 0.2, 0.3]]), np.zeros((1, 3)), np.zeros((1, 3))
    )
    single = simulate(hold, controller, ExecutionConfig(), MirrorPlant(3))
    assert len(single.times_s) >= 1
    renamed = [(s.name, replace(s.report, joint_names=names)) for s in two_steps.steps]
    execution = execution_of([*renamed, ("hold", single)], controller)
    path = write(tmp_path, execution, distro)
    written: dict[str, list[bytes]] = {}
    with path.open("rb") as stream:
        for _, channel, message in make_reader(stream).iter_messages(log_time_order=False):
            written.setdefault(channel.topic, []).append(message.data)
    stamps = cycle_stamps(execution)
    reports = [s.report for s in execution.steps]
    positions = np.concatenate([r.actual_positions for r in reports])
    velocities = np.concatenate([r.actual_velocities for r in reports])
    assert written["/joint_states"] == reference_cdr(JOINT_STATE, distro, [
        msgs.joint_state(names, stamp, q, v) for stamp, q, v in zip(stamps, positions, velocities, strict=True)
    ])
    expected_states = []
    start = 0
    for report in reports:
        times = np.rint(report.times_s * 1e9).astype(np.int64)
        states = controller_states(report, controller, start + times, times)
        expected_states += reference_cdr(
            CONTROLLER_STATE, distro, [msgs.controller_state(states, k, distro) for k in range(len(times))]
        )
        start += round(report.duration_s * 1e9)
    assert written[STATE_TOPIC] == expected_states
    assert len(read_all(path)) == sum(len(v) for v in written.values())


# --- speed ---------------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("distro", DISTROS)
def test_ten_seconds_at_one_kilohertz_are_written_in_well_under_half_a_second(
    tmp_path: Path, distro: str
) -> None:
    joints = tuple(f"joint_{i}" for i in range(1, 7))
    controller = jtc(joints=joints, rate=1000.0)
    trajectory = minimum_jerk(np.zeros(6), np.linspace(0.5, 1.5, 6), 10.0, joints)
    report = simulate(trajectory, controller, ExecutionConfig(), MirrorPlant(6))
    assert len(report.times_s) >= 10_000
    execution = execution_of([("move", report)], controller)
    write_execution(tmp_path / "warm.mcap", execution, distro)
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        write_execution(tmp_path / "executed.mcap", execution, distro)
        best = min(best, time.perf_counter() - start)
    assert best < 0.5
