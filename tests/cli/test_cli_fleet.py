"""`check-tolerances --manifest`: a night's recordings checked in one command, each as a single check would."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import SAMPLES, Cli, fleet_manifest

RECORDINGS = SAMPLES / "recordings"


@pytest.fixture()
def fleet(tmp_path: Path) -> Path:
    """Return a manifest of five items: a pass, a violation, a corrupt file, a missing one and a glob's match."""
    return fleet_manifest(tmp_path, "robot", ("cell-1", "cell-2", "cell-3", "cell-4", "cell-5"))


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open() as stream:
        return list(csv.DictReader(stream))


def test_every_item_gets_the_verdict_its_single_check_gives(cli: Cli, fleet: Path) -> None:
    code, document = cli.json("check-tolerances", "--manifest", fleet)
    assert code == 3, document  # an item could not be checked: that outranks the violation
    items = document["items"]
    assert [(Path(i["recording"]).name, i["exit_code"], i["columns"]) for i in items] == [
        ("tool_up_ok.mcap", 0, {"robot": "cell-1"}), ("tool_up_path_violation.mcap", 5, {"robot": "cell-2"}),
        ("corrupt.mcap", 3, {"robot": "cell-3"}), ("missing.mcap", 3, {"robot": "cell-4"}),
        ("tool_up_goal_missed.mcap", 0, {"robot": "cell-5"})]
    for item in items:
        single_code, single = cli.json("check-tolerances", item["plan"], item["recording"])
        assert single_code == item["exit_code"]
        keep = {key: value for key, value in item.items() if key not in ("index", "plan", "recording", "columns",
                                                                         "exit_code")}
        if single_code == 3:
            assert keep["error"]["message"] == single["error"]["message"] and not keep["ok"]
        else:
            assert keep == single
    summary = document["summary"]
    assert (summary["items"], summary["passed"], summary["failed"], summary["unreadable"]) == (5, 2, 1, 2)
    assert summary["worst_margins"][0]["recording"].endswith("tool_up_path_violation.mcap")
    assert summary["worst_margins"][0]["joint"] == "wrist_1_joint" and summary["worst_margins"][0]["margin"] < 0


def test_two_workers_give_the_same_document_and_results_stream_to_csv(cli: Cli, fleet: Path, tmp_path: Path) -> None:
    one, two = tmp_path / "one.csv", tmp_path / "two.csv"
    code_one, alone = cli.json("check-tolerances", "--manifest", fleet, "--csv", one)
    code_two, together = cli.json("check-tolerances", "--manifest", fleet, "--csv", two, "--jobs", "2")
    assert code_one == code_two == 3 and alone == together
    rows = sorted(_rows(two), key=lambda row: int(row["index"]))
    assert sorted(_rows(one), key=lambda row: int(row["index"])) == rows
    assert [(row["ok"], row["exit_code"], row["result"], row["robot"]) for row in rows] == [
        ("True", "0", "SUCCESSFUL", "cell-1"), ("False", "5", "PATH_TOLERANCE_VIOLATED", "cell-2"),
        ("False", "3", "InputError", "cell-3"), ("False", "3", "InputError", "cell-4"),
        ("True", "0", "SUCCESSFUL", "cell-5")]
    assert rows[1]["worst_joint"] == "wrist_1_joint" and float(rows[1]["worst_margin"]) < 0
    assert rows[3]["recording_sha256"] == "" and "file not found" in rows[3]["error"]


def test_resume_skips_the_pairs_already_judged(cli: Cli, fleet: Path, tmp_path: Path) -> None:
    results = tmp_path / "results.csv"
    assert cli("check-tolerances", "--manifest", fleet, "--csv", results, "-q").exit_code == 3
    # It arrived since: an execution of the plan, a recording judged by no earlier run.
    assert cli("execute", tmp_path / "tool_up_plan.mcap", "--fake", "-o", tmp_path / "missing.mcap").exit_code == 0
    code, document = cli.json("check-tolerances", "--manifest", fleet, "--csv", results, "--resume")
    summary = document["summary"]
    assert (summary["checked"], summary["resumed"]) == (1, 4)  # only the pair whose file could not be read
    assert [Path(i["recording"]).name for i in document["items"]] == ["missing.mcap"]
    assert code == 3 and (summary["passed"], summary["unreadable"]) == (3, 1)  # corrupt.mcap, judged before
    assert len(_rows(results)) == 6  # the first run's five rows, and the one judged now
    replaced = ("execute", tmp_path / "tool_up_plan.mcap", "--fake", "--plant", "lag", "--plant-param", "tau=0.01")
    assert cli(*replaced, "-o", tmp_path / "tool_up_ok.mcap").exit_code == 0  # another night, the same name
    _, again = cli.json("check-tolerances", "--manifest", fleet, "--csv", results, "--resume")
    assert [Path(i["recording"]).name for i in again["items"]] == ["tool_up_ok.mcap"]  # keyed by contents


def test_exit_codes_all_pass_and_any_violation(cli: Cli, fleet: Path) -> None:
    passing, failing = fleet.parent / "passing.csv", fleet.parent / "failing.csv"
    passing.write_text("plan,recording\ntool_up_plan.mcap,tool_up_ok.mcap\n")
    failing.write_text("plan,recording\ntool_up_plan.mcap,tool_up_ok.mcap\ntool_up_plan.mcap,tool_up_path_violation.mcap\n")
    assert cli("check-tolerances", "--manifest", passing).exit_code == 0
    result = cli("check-tolerances", "--manifest", failing)
    assert result.exit_code == 5
    last = result.stdout.splitlines()[-1]
    assert last.startswith("2 items: 1 passed, 1 failed, 0 not checked; smallest margin -0.05 (wrist_1_joint")


@pytest.mark.parametrize(("text", "message"), [
    ("plan,bag\na.mcap,b.mcap\n", "a manifest needs the columns plan and recording (its header: plan, bag)"),
    ("plan,recording\n", "the manifest lists no (plan, recording) pair"),
    ("plan,recording\na.mcap,\n", "row 2: plan and recording are both needed"),
    ("plan,recording\na.mcap,b.mcap,c\n", "row 2: more cells than the header names"),
])
def test_a_bad_manifest_exits_3_naming_it(cli: Cli, tmp_path: Path, text: str, message: str) -> None:
    manifest = tmp_path / "fleet.csv"
    manifest.write_text(text)
    code, document = cli.json("check-tolerances", "--manifest", manifest)
    assert code == 3 and document["error"]["message"] == f"{manifest}: {message}", document


@pytest.mark.parametrize(("args", "message"), [
    (["--manifest", "M", "--plot", "p.png"], "give no PLAN, RECORDING or --plot with it"),
    (["--manifest", "M", "--resume"], "--resume reads and extends the results of --csv"),
    (["PLAN", "REC", "--csv", "r.csv"], "--ray-address and --html go with --manifest"),
    ([], "needs PLAN and RECORDING, or --manifest FLEET.csv"),
])
def test_flags_that_do_not_go_together_exit_2(cli: Cli, fleet: Path, args: list[str], message: str) -> None:
    swapped = [str(fleet) if a == "M" else str(RECORDINGS / "tool_up_plan.mcap") if a == "PLAN"
               else str(RECORDINGS / "tool_up_ok.mcap") if a == "REC" else a for a in args]
    result = cli("check-tolerances", *swapped)
    assert result.exit_code == 2 and message in result.stderr, result.stderr
    assert not (fleet.parent / "p.png").exists()


def test_the_json_document_is_one_strict_document(cli: Cli, fleet: Path) -> None:
    result = cli("check-tolerances", "--manifest", fleet, "--json")
    document = json.loads(result.stdout, parse_constant=lambda name: pytest.fail(f"non-JSON {name}"))
    assert set(document) == {"items", "summary"}


def test_a_plan_rewritten_between_batches_is_read_anew(cli: Cli, fleet: Path, tmp_path: Path) -> None:
    """A worker keeps the plans it read while their files stay the same; a rewritten plan is read again."""
    passing = tmp_path / "passing.csv"
    passing.write_text("plan,recording\ntool_up_plan.mcap,tool_up_ok.mcap\n")
    assert cli("check-tolerances", "--manifest", passing).exit_code == 0
    assert cli("plan", SAMPLES / "ur10e_joint_goals.yaml", "-o", tmp_path / "tool_up_plan.mcap").exit_code == 0
    code, document = cli.json("check-tolerances", "--manifest", passing)
    single_code, single = cli.json("check-tolerances", tmp_path / "tool_up_plan.mcap", tmp_path / "tool_up_ok.mcap")
    assert code == single_code != 0
    assert document["items"][0]["result"] == single["result"]


# --- the Ray engine -------------------------------------------------------------------------------------------------


def _moveplan(*args: object, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """Run moveplan in a process of its own: Ray's driver state stays out of the test process."""
    return subprocess.run([sys.executable, "-m", "moveplan.cli.app", *map(str, args)], capture_output=True, text=True,
                          env={**os.environ, "RAY_USAGE_STATS_ENABLED": "0", **(env or {})}, timeout=600, check=False)


def test_the_ray_engine_gives_the_local_engine_s_verdicts(fleet: Path, tmp_path: Path, ray_address: str) -> None:
    local = _moveplan("check-tolerances", "--manifest", fleet, "--json", "--csv", tmp_path / "local.csv")
    on_ray = _moveplan("check-tolerances", "--manifest", fleet, "--json", "--csv", tmp_path / "ray.csv",
                       "--engine", "ray", env={"RAY_ADDRESS": ray_address})
    assert local.returncode == on_ray.returncode == 3, on_ray.stderr
    assert json.loads(on_ray.stdout) == json.loads(local.stdout)
    assert sorted(_rows(tmp_path / "ray.csv"), key=lambda r: int(r["index"])) == \
        sorted(_rows(tmp_path / "local.csv"), key=lambda r: int(r["index"]))


def test_the_ray_engine_says_what_it_lacks(fleet: Path, tmp_path: Path) -> None:
    blocked = tmp_path / "no_ray" / "ray"
    blocked.mkdir(parents=True)
    (blocked / "__init__.py").write_text("raise ImportError('No module named ray')\n")
    missing = _moveplan("check-tolerances", "--manifest", fleet, "--engine", "ray", "--ray-address", "127.0.0.1:1",
                        env={"PYTHONPATH": str(blocked.parent)})
    assert missing.returncode == 2
    assert missing.stderr.strip() == ("moveplan: error: --engine ray needs Ray, an optional extra: "
                                      "pip install 'moveplan[ray]'")
    environment = {key: value for key, value in os.environ.items() if key != "RAY_ADDRESS"}
    nowhere = subprocess.run([sys.executable, "-m", "moveplan.cli.app", "check-tolerances", "--manifest", str(fleet),
                              "--engine", "ray"], capture_output=True, text=True, env=environment, timeout=600,
                             check=False)
    assert nowhere.returncode == 2 and "give --ray-address HOST:PORT or set RAY_ADDRESS" in nowhere.stderr
    refused = _moveplan("check-tolerances", "--manifest", fleet, "--engine", "ray", "--ray-address", "127.0.0.1:1")
    assert refused.returncode == 3
    assert refused.stderr.strip().startswith("moveplan: error: --ray-address 127.0.0.1:1: cannot connect to a Ray "
                                             "cluster there")


def test_unreadable_manifests_and_results_exit_3_naming_the_file(cli: Cli, fleet: Path, tmp_path: Path) -> None:
    binary = tmp_path / "binary.csv"
    binary.write_bytes(b"\xff\xfe\x00plan,recording\n")
    folder = tmp_path / "folder.csv"
    folder.mkdir()
    for manifest, message in ((binary, "cannot read"), (folder, "cannot read: Is a directory"),
                              (tmp_path / "missing.csv", "cannot read: No such file or directory")):
        code, document = cli.json("check-tolerances", "--manifest", manifest)
        assert code == 3 and document["error"]["message"].startswith(f"{manifest}: {message}"), document
    foreign = tmp_path / "foreign.csv"
    foreign.write_text("a,b\n1,2\n")
    code, document = cli.json("check-tolerances", "--manifest", fleet, "--csv", foreign, "--resume")
    assert code == 3 and document["error"]["message"] == (
        f"{foreign}: not the results of a batch check (--resume reads the --csv a batch wrote)"), document
    assert foreign.read_text() == "a,b\n1,2\n"  # left as it was


def test_a_results_file_that_is_an_input_is_refused_before_any_work(cli: Cli, fleet: Path) -> None:
    recording = fleet.parent / "tool_up_ok.mcap"
    before = recording.read_bytes()
    result = cli("check-tolerances", "--manifest", fleet, "--csv", recording)
    assert result.exit_code == 2 and "--csv" in result.stderr, result.stderr
    assert recording.read_bytes() == before


def test_an_unknown_engine_or_a_report_in_no_folder_is_refused_before_any_work(cli: Cli, fleet: Path) -> None:
    engine = cli("check-tolerances", "--manifest", fleet, "--engine", "spark")
    assert engine.exit_code == 2
    assert engine.stderr.strip() == "moveplan: error: --engine: expected local or ray, got 'spark'"
    nowhere = fleet.parent / "out" / "night.html"
    report = cli("check-tolerances", "--manifest", fleet, "--html", nowhere, "--csv", fleet.parent / "r.csv")
    assert report.exit_code == 3 and "cannot write: folder" in report.stderr, report.stderr
    assert not (fleet.parent / "r.csv").exists() and not nowhere.parent.exists()
