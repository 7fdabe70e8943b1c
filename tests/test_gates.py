"""Regression gates: every shipped task plans, MotionBenchMaker problems solve and certify, a seed gives one file."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT, SAMPLES, Cli, run_process

from moveplan.core.pipeline.benchmark import find_problems, run_benchmark
from moveplan.core.planning import search as planning

MBM = ROOT / "tests" / "data" / "mbm"
TASKS = sorted(p for p in SAMPLES.glob("*.yaml") if "steps:" in p.read_text())


def test_every_sample_task_is_a_gate() -> None:
    assert len(TASKS) >= 8, [p.name for p in TASKS]


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("task", TASKS, ids=lambda p: p.stem)
def test_every_sample_task_plans(cli: Cli, task: Path, seed: int, tmp_path: Path) -> None:
    code, document = cli.json("plan", task, "-o", tmp_path / "plan.mcap", "--seed", seed)
    assert code == 0, document
    assert all(step["status"] == "ok" for step in document["steps"])


def test_motionbenchmaker_problems_all_solve_and_certify_exactly() -> None:
    problems = find_problems([MBM / "problems"])
    assert len(problems) == 30
    runs = run_benchmark(MBM / "panda_robot", problems, ["RRTConnect"], [0, 1], planning_time=5.0, jobs=2)
    failed = [(r.problem, r.seed, r.error) for r in runs if not (r.ok and r.exact_valid)]
    assert len(runs) == 60 and not failed


# Bookshelf 0093's goal is deep in the shelf: RRTConnect's goal tree barely grows, and with this
# budget the search is handed to LBKPIECE1, so the test covers both searches and the hand-over.
def shelf_0093(seed: int = 0, planning_time: float = 1.0) -> tuple[object, ...]:
    return ("plan", "--robot", MBM / "panda_robot", "--scene", MBM / "bookshelf_scene0093.yaml",
            "--request", MBM / "bookshelf_request0093.yaml", "--planner", "RRTConnect",
            "--planning-time", planning_time, "--seed", seed)


def test_a_seeded_plan_writes_the_same_bytes_quiet_and_with_every_core_busy(tmp_path: Path) -> None:
    quiet, loaded = tmp_path / "quiet.mcap", tmp_path / "loaded.mcap"
    run = run_process(*shelf_0093(), "-o", quiet, "--json")
    assert run.returncode == 0, run.stderr
    assert '"planner": "RRTConnect+LBKPIECE1"' in run.stdout
    burners = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(os.cpu_count() or 2)]
    try:
        run = run_process(*shelf_0093(), "-o", loaded)
    finally:
        for burner in burners:
            burner.kill()
            burner.wait()
    assert run.returncode == 0, run.stderr
    assert loaded.read_bytes() == quiet.read_bytes()


def test_a_seeded_plan_is_the_same_after_other_plans_in_one_process(cli: Cli, tmp_path: Path) -> None:
    first, other, again = (tmp_path / f"{name}.mcap" for name in ("first", "other", "again"))
    for out, seed in ((first, 0), (other, 1), (again, 0)):
        assert cli(*shelf_0093(seed), "-o", out).exit_code == 0
    assert again.read_bytes() == first.read_bytes()
    assert other.read_bytes() != first.read_bytes()



def test_a_search_cut_short_by_the_clock_fails_the_step_naming_the_cap(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(planning._Work, "out_of_time", lambda self: True)  # a machine far too busy
    out = tmp_path / "plan.mcap"
    run = cli(*shelf_0093(), "-o", out)
    assert run.exit_code == 4
    assert "step 'bookshelf_request0093'" in run.stderr and "planning time cap of 1 s" in run.stderr
    assert not out.exists()
