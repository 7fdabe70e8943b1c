"""Result documents are built in core: what `--json` prints comes from a core function, the CLI adds nothing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from conftest import ROOT, SAMPLES, Cli

from moveplan.core.config import load_robot_config, load_task
from moveplan.core.errors import NoPlan
from moveplan.core.pipeline import (
    PlanFlags,
    inspect_document,
    inspect_file,
    plan_document,
    plan_failure_document,
    robot_document,
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
