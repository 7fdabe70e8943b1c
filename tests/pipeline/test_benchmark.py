"""`moveplan benchmark`: problems found, every planner and seed run, statistics, files, bad input."""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT, Cli

from moveplan.core.pipeline.benchmark import Run, find_problems, summarize

MBM = ROOT / "tests" / "data" / "mbm" / "problems" / "box_panda"


@pytest.fixture()
def problems(tmp_path: Path) -> Path:
    """Return a scenario folder holding the sample MotionBenchMaker problem twice."""
    folder = tmp_path / "problems" / "box_panda"
    folder.mkdir(parents=True)
    for number in ("0001", "0002"):
        shutil.copy(MBM / "scene0001.yaml", folder / f"scene{number}.yaml")
        shutil.copy(MBM / "request0001.yaml", folder / f"request{number}.yaml")
    return tmp_path / "problems"


def test_problems_are_scene_request_pairs_named_by_folder_and_number(problems: Path) -> None:
    found = find_problems([problems])
    assert [p.name for p in found] == ["box_panda/0001", "box_panda/0002"]
    assert found[0].request == problems / "box_panda" / "request0001.yaml"
    assert [p.name for p in find_problems([problems], count=1)] == ["box_panda/0001"]


def test_scenario_folders_linked_into_the_problems_folder_are_found_once(problems: Path, tmp_path: Path) -> None:
    # A dataset kept elsewhere and linked in (rglob skips links), two links to it, a link back up the tree.
    kept = tmp_path / "kept" / "cage_panda"
    kept.mkdir(parents=True)
    shutil.copy(MBM / "scene0001.yaml", kept / "scene0007.yaml")
    shutil.copy(MBM / "request0001.yaml", kept / "request0007.yaml")
    (problems / "cage_panda").symlink_to(kept)
    (problems / "again").symlink_to(kept)
    (problems / "box_panda" / "up").symlink_to(problems)
    # Of two links to one folder, the first by name counts.
    assert [p.name for p in find_problems([problems])] == ["again/0007", "box_panda/0001", "box_panda/0002"]


def test_benchmark_runs_every_problem_with_every_seed_and_writes_csv_and_plot(
    cli: Cli, problems: Path, tmp_path: Path
) -> None:
    table, plot = tmp_path / "runs.csv", tmp_path / "times.png"
    code, document = cli.json("benchmark", problems, "--robot", "panda", "--planner", "RRTConnect",
                              "--seeds", "0-1", "--csv", table, "--plot", plot)
    assert code == 0, document
    runs = document["runs"]
    assert [(r["problem"], r["seed"]) for r in runs] == [
        ("box_panda/0001", 0), ("box_panda/0002", 0), ("box_panda/0001", 1), ("box_panda/0002", 1)]
    for run in runs:
        assert run["ok"] and run["exact_valid"], run
        stages = [run[f"{stage}_s"] for stage in ("search", "simplify", "certify", "timing")]
        assert run["total_s"] == pytest.approx(sum(stages)) and run["search_s"] > 0 and run["certify_s"] > 0
        assert run["total_s"] <= run["planning_time_s"] and run["checks"] > 0
        assert run["duration_s"] > 0 and run["path_length"] > 0
    overall = next(r for r in document["summary"] if r["scenario"] == "all")
    assert overall["runs"] == 4 and overall["success_rate"] == 1.0 and overall["exact_valid"] == 4
    with table.open() as stream:
        assert len(list(csv.DictReader(stream))) == 4
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_failed_runs_count_against_success_and_not_in_times() -> None:
    runs = [Run("s/1", "s", "RRTConnect", 0, True, search_s=0.001, simplify_s=0.001, total_s=0.002),
            Run("s/2", "s", "RRTConnect", 0, False, error="no path")]
    [row, _] = summarize(runs)
    assert row["success_rate"] == 0.5 and row["total_median_s"] == pytest.approx(0.002)


@pytest.mark.parametrize(("args", "code", "message"), [
    (["--seeds", "3-1"], 2, "--seeds"),
    (["--seeds", "a"], 2, "--seeds"),
    (["--planning-time", "0"], 2, "planning-time"),
])
def test_bad_flags_are_usage_errors(cli: Cli, problems: Path, args: list[str], code: int, message: str) -> None:
    result = cli("benchmark", problems, "--robot", "panda", *args)
    assert result.exit_code == code and message in result.output


def test_bad_problem_folders_name_the_file(cli: Cli, problems: Path, tmp_path: Path) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    (problems / "box_panda" / "request0002.yaml").unlink()
    for folder, message in ((tmp_path / "missing", "no such problem folder"), (empty, "no sceneNNNN.yaml"),
                            (problems, "no matching request0002.yaml")):
        code, document = cli.json("benchmark", folder, "--robot", "panda")
        assert code == 3 and message in document["error"]["message"], document


def test_a_malformed_request_stops_the_benchmark_with_exit_3_naming_it(cli: Cli, problems: Path) -> None:
    (problems / "box_panda" / "request0002.yaml").write_text("group_name: [unclosed\n")
    code, document = cli.json("benchmark", problems, "--robot", "panda", "--planner", "RRTConnect")
    assert code == 3 and "request0002.yaml" in document["error"]["message"], document


def _outcomes(path: Path) -> dict[tuple[str, str, str], tuple[str, ...]]:
    """Return per (problem, planner, seed) what a run found: success, checks, path, duration, validity."""
    with path.open() as stream:
        return {(r["problem"], r["planner"], r["seed"]): (r["ok"], r["checks"], r["path_length"], r["duration_s"],
                                                          r["exact_valid"]) for r in csv.DictReader(stream)}


def test_shards_merged_give_the_runs_of_the_whole_benchmark(cli: Cli, problems: Path, tmp_path: Path) -> None:
    """Two processes, or two shards on two machines, find what one process finds: each run is seeded anew."""
    common = ("benchmark", problems, "--robot", "panda", "--planner", "RRTConnect", "--seeds", "0-1", "-q")
    whole, first, second, merged = (tmp_path / f"{name}.csv" for name in ("whole", "first", "second", "merged"))
    assert cli(*common, "--jobs", "2", "--csv", whole).exit_code == 0
    assert cli(*common, "--shard", "1/2", "--csv", first).exit_code == 0
    assert cli(*common, "--shard", "2/2", "--csv", second, "--no-exact-check").exit_code == 0
    assert {key[0] for key in _outcomes(first)} == {"box_panda/0001"}  # every second problem from the first
    code, document = cli.json("benchmark-merge", first, second, "--csv", merged)
    assert code == 0, document
    overall = next(r for r in document["summary"] if r["scenario"] == "all")
    assert overall["runs"] == 4 and overall["succeeded"] == 4 and overall["exact_valid"] == 2  # shard 2 unchecked
    together, alone = _outcomes(merged), _outcomes(whole)
    assert together.keys() == alone.keys()
    for key, found in together.items():
        assert found[:4] == alone[key][:4], key
        assert found[4] == ("True" if key[0] == "box_panda/0001" else "")


def test_merging_overlapping_or_foreign_files_is_refused_naming_them(cli: Cli, problems: Path, tmp_path: Path) -> None:
    runs = tmp_path / "runs.csv"
    assert cli("benchmark", problems, "--robot", "panda", "--planner", "RRTConnect", "--csv", runs, "-q").exit_code == 0
    code, document = cli.json("benchmark-merge", runs, runs)
    assert code == 3 and f"{runs}: row 2: problem box_panda/0001, planner RRTConnect, seed 0 is also in {runs}: " \
        "row 2: shards overlap" == document["error"]["message"], document
    other = tmp_path / "other.csv"
    other.write_text("a,b\n1,2\n")
    code, document = cli.json("benchmark-merge", other)
    assert code == 3 and document["error"]["message"].startswith(f"{other}: not a benchmark CSV"), document
    broken = tmp_path / "broken.csv"
    broken.write_text(runs.read_text().replace(",True,", ",yes,", 1))
    code, document = cli.json("benchmark-merge", broken)
    assert code == 3 and document["error"]["message"].startswith(f"{broken}: row 2: expected True or False"), document
    code, document = cli.json("benchmark-merge", tmp_path / "missing.csv")
    assert code == 3 and "missing.csv: cannot read" in document["error"]["message"], document


@pytest.mark.parametrize(("shard", "message"), [("3/2", "1 <= K <= N"), ("1-2", "expected K/N"), ("3/5", "no problem")])
def test_a_bad_shard_is_a_usage_error(cli: Cli, problems: Path, shard: str, message: str) -> None:
    result = cli("benchmark", problems, "--robot", "panda", "--shard", shard)
    assert result.exit_code == 2 and message in result.stderr, result.stderr


def test_the_ray_engine_finds_what_local_processes_find(problems: Path, tmp_path: Path, ray_address: str) -> None:
    """Runs on a Ray cluster (a head and a worker node) are the runs two local processes make."""
    common = ["benchmark", str(problems), "--robot", "panda", "--planner", "RRTConnect", "--seeds", "0-1", "-q"]
    local, on_ray = tmp_path / "local.csv", tmp_path / "ray.csv"
    for extra in (["--jobs", "2", "--csv", str(local)], ["--engine", "ray", "--ray-address", ray_address,
                                                         "--csv", str(on_ray)]):
        result = subprocess.run([sys.executable, "-m", "moveplan.cli.app", *common, *extra], capture_output=True,
                                text=True, timeout=600, check=False,
                                env={**os.environ, "RAY_USAGE_STATS_ENABLED": "0"})
        assert result.returncode == 0, result.stderr
    assert _outcomes(on_ray) == _outcomes(local) and len(_outcomes(local)) == 4


def test_merged_shards_write_their_page_and_an_unknown_engine_is_refused(
    cli: Cli, problems: Path, tmp_path: Path
) -> None:
    runs, page = tmp_path / "runs.csv", tmp_path / "runs.html"
    assert cli("benchmark", problems, "--robot", "panda", "--planner", "RRTConnect", "--csv", runs, "-q").exit_code == 0
    assert cli("benchmark-merge", runs, "--html", page, "-q").exit_code == 0
    assert page.read_text().count('"box_panda/000') == 2  # a row per run in the page's data
    refused = cli("benchmark", problems, "--robot", "panda", "--engine", "spark")
    assert refused.exit_code == 2 and "--engine: expected local or ray, got 'spark'" in refused.stderr
