"""`moveplan execute --fake -o` on plans of many steps: every step's cycles reach the file, written as they run."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import UR10E, Cli
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader

from moveplan.core.bag.execution_file import EXECUTION_RESULT_TOPIC
from moveplan.core.control.controller import Disturbance
from moveplan.core.control.results import ExecutionSummary
from moveplan.core.errors import UsageError
from moveplan.core.pipeline.execution import ExecuteRequest, execute
from moveplan.core.pipeline.report import execute_to_file, write_execution

STEPS = 120
RATE_HZ = 500.0  # the UR10e config's update_rate
GOALS = ("[0.3, -1.4, -1.6, 0.0, 1.57, 0.0]", "[-0.3, -1.7, -1.4, 0.2, 1.57, 0.3]")
STATE_TOPIC = "/joint_trajectory_controller/controller_state"


@pytest.fixture(scope="module")
def many_steps(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A UR10e plan of STEPS steps, alternating two joint goals at full speed."""
    folder = tmp_path_factory.mktemp("many_steps")
    lines = [f"robot: {UR10E}", "start: {named: home}",
             "defaults: {velocity_scaling: 1.0, acceleration_scaling: 1.0}", "steps:"]
    lines += [f"  - {{name: s{i}, joints: {GOALS[i % 2]}}}" for i in range(STEPS)]
    task = folder / "task.yaml"
    task.write_text("\n".join(lines) + "\n")
    plan = folder / "plan.mcap"
    result = Cli()("plan", task, "-o", plan, "--seed", "0", "--quiet")
    assert result.exit_code == 0, result.stderr
    return plan


def log_times(path: Path) -> dict[str, list[int]]:
    """Per topic, the log times [ns] of its messages, read back by rosbags."""
    times: dict[str, list[int]] = {}
    with AnyReader([path]) as reader:
        for connection, log_time, _ in reader.messages():
            times.setdefault(connection.topic, []).append(log_time)
    return times


def file_order(path: Path) -> list[tuple[str, int]]:
    """(topic, log time [ns]) of every message in the order the file holds them."""
    with path.open("rb") as stream:
        return [(channel.topic, message.log_time)
                for _, channel, message in make_reader(stream).iter_messages(log_time_order=False)]


def test_every_step_of_a_many_step_plan_is_in_the_executed_file_in_order(
    cli: Cli, many_steps: Path, tmp_path: Path
) -> None:
    executed = tmp_path / "executed.mcap"
    code, document = cli.json("execute", many_steps, "--fake", "-o", executed)
    assert code == 0
    assert len(document["steps"]) == STEPS and all(s["result"] == "SUCCESSFUL" for s in document["steps"])
    times = log_times(executed)
    # Each step runs its cycles 0 .. duration * rate, the first at its start on the execution's timeline.
    cycles = sum(round(s["duration_s"] * RATE_HZ) + 1 for s in document["steps"])
    assert len(times["/joint_states"]) == len(times[STATE_TOPIC]) == cycles
    stamps = np.array(times["/joint_states"])
    assert np.all(np.diff(stamps) >= 0)
    assert {round(s["start_s"] * 1e9) for s in document["steps"]} <= set(stamps.tolist())
    assert stamps[-1] == round(document["duration_s"] * 1e9)
    assert times[EXECUTION_RESULT_TOPIC] == [stamps[-1]]
    assert times["/tf"][0] == 0 and times["/tf"][-1] == stamps[-1]
    # Written as they ran, yet in log-time order, as `ros2 bag record` writes: the result last.
    order = file_order(executed)
    assert [t for _, t in order] == sorted(t for _, t in order) and order[-1][0] == EXECUTION_RESULT_TOPIC
    checked_code, checked = cli.json("check-tolerances", many_steps, executed, "--start", "0")
    assert checked_code == 0 and len(checked["steps"]) == STEPS


def test_writing_while_executing_gives_the_file_written_afterwards(many_steps: Path, tmp_path: Path) -> None:
    request = ExecuteRequest(many_steps, plant="lag", plant_params={"tau": 0.02})
    streamed = execute_to_file(request, tmp_path / "streamed.mcap", "humble")
    outcome = execute(request)
    assert all(isinstance(step.report, ExecutionSummary) for step in outcome.steps)  # no samples kept
    write_execution(tmp_path / "afterwards.mcap", outcome, "humble")
    assert (tmp_path / "streamed.mcap").read_bytes() == (tmp_path / "afterwards.mcap").read_bytes()
    assert streamed.steps == outcome.steps and streamed.result == outcome.result


def test_an_error_in_a_late_step_leaves_no_output_file(cli: Cli, many_steps: Path, tmp_path: Path) -> None:
    executed = tmp_path / "executed.mcap"
    # Earlier steps have already been written when the step holding this disturbance refuses it.
    result = cli("execute", many_steps, "--fake", "-o", executed, "--disturb", "t=60,joint=nope,delta=0.1")
    assert result.exit_code == 2
    assert "joint 'nope'" in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []
    request = ExecuteRequest(many_steps, disturbances=(Disturbance(60.0, "nope", 0.1),))
    with pytest.raises(UsageError, match="nope"):
        execute_to_file(request, executed)
    assert list(tmp_path.iterdir()) == []  # nor the temporary file the earlier steps went to


def test_a_plan_refused_at_its_start_writes_a_file_with_only_the_result(
    cli: Cli, many_steps: Path, tmp_path: Path
) -> None:
    executed = tmp_path / "executed.mcap"
    code, document = cli.json("execute", many_steps, "--fake", "-o", executed, "--start-joints", "elbow_joint=-1.0")
    assert code == 5 and document["result"]["name"] == "START_STATE_INVALID" and len(document["steps"]) == 1
    with AnyReader([executed]) as reader:
        assert "/tf" not in reader.topics
    times = log_times(executed)
    assert "/joint_states" not in times and times[EXECUTION_RESULT_TOPIC] == [0]
