"""Result documents are built in core: what `--json` prints comes from a core function, the CLI adds nothing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from conftest import ROOT, SAMPLES, UR10E, Cli

from moveplan.core.config import load_robot_config, load_task
from moveplan.core.errors import NoPlan
from moveplan.core.pipeline import (
    ExecuteRequest,
    PlanExecution,
    PlanFlags,
    RobotSource,
    Run,
    StateRequest,
    TuneResult,
    benchmark_document,
    execute,
    execution_document,
    failure_document,
    inspect_document,
    inspect_file,
    plan_document,
    plan_failure_document,
    robot_document,
    state,
    state_document,
    summarize,
    tuning_document,
)
from moveplan.core.pipeline.plan import plan
from moveplan.core.pipeline.request import resolve_request


def test_the_robot_document_is_what_moveplan_robot_json_prints(cli: Cli) -> None:
    config = load_robot_config(ROOT / "configs" / "ur10e")
    code, printed = cli.json("robot", ROOT / "configs" / "ur10e")
    assert code == 0
    assert json.loads(json.dumps(robot_document(config))) == printed


def without_clock(document: dict[str, Any]) -> dict[str, Any]:
    return {**document, "steps": [{k: v for k, v in s.items() if k != "planning_time_s"} for s in document["steps"]]}


def test_the_plan_and_inspect_documents_are_what_the_commands_print(cli: Cli, tmp_path: Path) -> None:
    output = tmp_path / "plan.mcap"
    code, printed = cli.json("plan", SAMPLES / "ur10e_tool_up.yaml", "-o", output)
    assert code == 0
    result = plan(resolve_request(load_task(SAMPLES / "ur10e_tool_up.yaml"), PlanFlags()))
    built = json.loads(json.dumps(plan_document(result, output)))
    assert without_clock(built) == without_clock(printed)
    code, inspected = cli.json("inspect", output)
    assert code == 0 and json.loads(json.dumps(inspect_document(inspect_file(output)))) == inspected


def test_a_failed_plan_document_names_the_failing_step_after_those_planned() -> None:
    error = NoPlan("no path").in_step("reach")
    assert plan_failure_document(error) == {"output": None, "robot": None, "group": None,
                                            "steps": [{"name": "reach", "status": "error"}]}


# The builders alone, on values core computes: no command line involved.

RECORDINGS = SAMPLES / "recordings"


@pytest.fixture(scope="module")
def execution() -> PlanExecution:
    """The recorded tool-up plan replayed through the mirror plant."""
    return execute(ExecuteRequest(RECORDINGS / "tool_up_plan.mcap"))


def test_the_state_document_holds_the_group_joints_and_the_pose_between_ok_and_error() -> None:
    result = state(StateRequest(robot=RobotSource(UR10E), named="home"))
    document = state_document(result)
    assert list(document) == ["ok", "robot", "group", "source", "joints", "pose", "error"]
    assert document["ok"] is True and document["error"] is None
    assert (document["robot"], document["group"]) == (result.robot, result.group)
    assert document["joints"] == result.state.as_dict()["joints"]


def test_the_benchmark_document_lists_every_run_then_the_summary_rows() -> None:
    runs = [Run("s/1", "s", "RRTConnect", 0, True, search_s=0.001, simplify_s=0.001, total_s=0.002),
            Run("s/2", "s", "RRTConnect", 0, False, error="no path")]
    rows = summarize(runs)
    document = benchmark_document(runs, rows)
    assert list(document) == ["ok", "runs", "summary", "error"]
    assert document["runs"] == [run.as_dict() for run in runs] and document["summary"] == rows
    assert document["runs"][1]["search_s"] is None  # not measured: NaN in the run, null in JSON


def test_the_execution_document_names_the_executed_file_last_only_when_one_is_written(
    execution: PlanExecution,
) -> None:
    without = execution_document(execution)
    with_output = execution_document(execution, Path("run.mcap"))
    assert "output" not in without
    assert list(with_output) == [*without, "output"] and with_output["output"] == "run.mcap"


def test_the_tuning_document_names_the_plot_last_only_when_one_is_drawn(execution: PlanExecution) -> None:
    result = TuneResult(controller="joint_trajectory_controller", source="ctl.yaml", output=Path("tuned.yaml"),
                        interface="velocity", joints=(), plant_params={"drive_tau": 0.02}, fit=None,
                        verification=execution)
    without = tuning_document(result)
    assert without["output"] == "tuned.yaml" and without["verification"] == execution_document(execution)
    assert "plot" not in without
    with_plot = tuning_document(result, Path("tuning.png"))
    assert list(with_plot) == [*without, "plot"] and with_plot["plot"] == "tuning.png"


def test_a_failure_document_puts_what_the_command_adds_between_ok_and_the_error() -> None:
    document = failure_document(4, "NoPlan", "no path", {"output": None, "steps": []})
    assert document == {"ok": False, "output": None, "steps": [],
                        "error": {"exit_code": 4, "kind": "NoPlan", "message": "no path"}}
    assert list(document) == ["ok", "output", "steps", "error"]
    assert failure_document(2, "UsageError", "bad flag") == {
        "ok": False, "error": {"exit_code": 2, "kind": "UsageError", "message": "bad flag"}}
