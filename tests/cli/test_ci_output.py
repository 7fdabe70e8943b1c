"""What a CI job sees: one line on stderr for a failure under --quiet, nothing for a success, benchmark's progress."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from conftest import ROOT, SAMPLES, Cli

from moveplan.cli import render

RECORDINGS = SAMPLES / "recordings"
PLAN = RECORDINGS / "tool_up_plan.mcap"
MBM = ROOT / "tests" / "data" / "mbm" / "problems" / "box_panda"


def test_quiet_execute_that_violates_prints_one_line_naming_the_result_and_worst_violation(cli: Cli) -> None:
    result = cli("execute", PLAN, "--fake", "--plant", "pid", "--controllers",
                 SAMPLES / "ur10e_mistuned_controllers.yaml", "--quiet")
    assert result.exit_code == 5
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1
    # The controller aborts with elbow_joint and wrist_1_joint both out; wrist_1_joint is further beyond.
    assert re.fullmatch(r"moveplan: execute: PATH_TOLERANCE_VIOLATED: wrist_1_joint at 0\.\d{3} s in step 'up': "
                        r"path error -0\.2\d*, tolerance 0\.2 \(2 violations\)", lines[0]), lines[0]


def test_quiet_check_that_violates_prints_one_line_naming_the_result_and_the_violation(cli: Cli) -> None:
    result = cli("check-tolerances", PLAN, RECORDINGS / "tool_up_path_violation.mcap", "-q")
    assert result.exit_code == 5
    assert result.stdout == ""
    assert result.stderr.splitlines() == [
        "moveplan: check-tolerances: PATH_TOLERANCE_VIOLATED: wrist_1_joint at 0.500 s in step 'up': "
        "path error -0.25, tolerance 0.2 (1 violation)"]


def test_quiet_success_prints_nothing(cli: Cli) -> None:
    result = cli("check-tolerances", PLAN, RECORDINGS / "tool_up_ok.mcap", "--quiet")
    assert result.exit_code == 0
    assert (result.stdout, result.stderr) == ("", "")


@pytest.mark.parametrize(("args", "code"), [
    (["plan", "--robot", "ur10e", "--joints", "0,0,0,0,0,0", "--seed", "-1"], 2),  # refused by the flag parser
    (["plan", "--robot", "ur10e", "--bogus"], 2),
    (["execute", PLAN], 2),  # no --fake
    (["inspect", ROOT / "no_such_file.mcap"], 3),
    (["plan", "--robot", "ur10e", "--pose", "5,0,0"], 4),
], ids=["bad-value", "unknown-option", "no-fake", "missing-file", "unreachable"])
def test_quiet_error_is_one_line_on_stderr(cli: Cli, tmp_path: Path, args: list[object], code: int) -> None:
    result = cli(*args, *(["-o", tmp_path / "out.mcap"] if args[0] == "plan" else []), "--quiet")
    assert result.exit_code == code
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("moveplan: error: "), result.stderr


def test_benchmark_on_a_pipe_prints_progress_lines(cli: Cli, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(render, "PROGRESS_EVERY_S", 0.0)  # a line for every run
    result = cli("benchmark", MBM, "--robot", "panda", "--count", "1", "--seeds", "0-1")
    assert result.exit_code == 0, result.stderr
    progress = [line for line in result.stderr.splitlines() if line.startswith("benchmark:")]
    assert [re.sub(r"\d+ s$", "N s", line) for line in progress] == [
        "benchmark: 1/2 runs, 1 solved, N s", "benchmark: 2/2 runs, 2 solved, N s"]


def test_quiet_benchmark_prints_no_progress(cli: Cli, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(render, "PROGRESS_EVERY_S", 0.0)
    result = cli("benchmark", MBM, "--robot", "panda", "--count", "1", "--quiet")
    assert result.exit_code == 0, result.stderr
    assert (result.stdout, result.stderr) == ("", "")
