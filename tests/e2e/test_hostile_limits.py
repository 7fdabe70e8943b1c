"""Hostile limits: input that never ends, and output that cannot be written.

A device, a FIFO or a folder given where a file is read is refused before it is read, with one
line naming it (exit 3), and no output is written (docs/formats.md, Limits). A stdout that cannot
be written, a file-size limit, a full disk or a signal while a command writes its second output
leave one line, the documented exit code, and no output (docs/cli.md, Output files).
"""

from __future__ import annotations

import os
import resource
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT, SAMPLES, UR10E, Cli

from moveplan.core.bag import read_plan
from moveplan.core.config.fields import read_input
from moveplan.core.errors import ConfigError, InputError
from moveplan.core.pipeline import benchmark as bench

SHIPPED_PLAN = SAMPLES / "recordings" / "tool_up_plan.mcap"
QUICK_PLAN = ("--robot", UR10E, "--start-joints", "0,-1,-1,0,0,0", "--named", "home", "--seed", "0")
NOT_FILES = ["/dev/zero", "/dev/urandom", "FIFO", "FOLDER"]


@pytest.fixture()
def not_a_file(tmp_path: Path, request: pytest.FixtureRequest) -> str:
    """Return the path of what the test's parameter names: a device, or a FIFO or folder made in tmp_path."""
    kind = request.param
    if kind == "FIFO":
        os.mkfifo(tmp_path / "fifo.yaml")  # no writer: reading it would wait forever
        return str(tmp_path / "fifo.yaml")
    if kind == "FOLDER":
        (tmp_path / "folder.yaml").mkdir()
        return str(tmp_path / "folder.yaml")
    return kind


def _command(kind: str, path: str, tmp_path: Path) -> list[object]:
    """Return the command line reading `path` as the input `kind`."""
    shutil.copy(SHIPPED_PLAN, tmp_path / "p.mcap")
    out = tmp_path / "out"
    return {
        "scene": ["plan", "--robot", UR10E, "--scene", path, "--named", "home", "-o", out],
        "request": ["plan", "--robot", UR10E, "--request", path, "-o", out],
        "task": ["plan", path, "-o", out],
        "controllers": ["execute", tmp_path / "p.mcap", "--fake", "--controllers", path, "-o", out],
        "tune-pid controllers": ["tune-pid", tmp_path / "p.mcap", "--controllers", path, "-o", out],
        "state scene": ["state", "--robot", UR10E, "--scene", path],
    }[kind]


@pytest.mark.parametrize("not_a_file", NOT_FILES, indirect=True)
@pytest.mark.parametrize("kind", ["scene", "request", "task", "controllers", "tune-pid controllers", "state scene"])
def test_a_device_fifo_or_folder_given_as_an_input_file_is_refused_at_once(
    cli: Cli, tmp_path: Path, not_a_file: str, kind: str
) -> None:
    result = cli(*_command(kind, not_a_file, tmp_path), "-q")
    assert result.exit_code == 3, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"moveplan: error: {not_a_file}"), result.stderr
    assert "not a regular file" in lines[0] or "a folder, not a file" in lines[0]
    assert not (tmp_path / "out").exists()


def test_a_file_is_read_no_further_than_the_limit_whatever_it_claims(tmp_path: Path) -> None:
    big = tmp_path / "big.yaml"
    big.write_bytes(b"a: 1\n" * 100)
    assert read_input(big, limit=500) == b"a: 1\n" * 100
    with pytest.raises(ConfigError, match=r"big.yaml: more than 499 bytes; moveplan reads files of at most 499"):
        read_input(big, limit=499)


def test_a_trajectory_beyond_the_control_cycle_limit_is_refused_before_it_is_simulated(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A plan of hours at a kHz rate would take gigabytes: the limit is stated, and raised by the variable."""
    monkeypatch.setenv("MOVEPLAN_MAX_CONTROL_CYCLES", "100")
    result = cli("execute", SHIPPED_PLAN, "--fake", "-o", tmp_path / "e.mcap")
    assert result.exit_code == 3
    line = result.stderr.strip()
    assert line.startswith(f"moveplan: error: {SHIPPED_PLAN}: step 'up': a ") and "\n" not in line
    assert "control cycles; moveplan simulates at most 100 per trajectory (MOVEPLAN_MAX_CONTROL_CYCLES" in line
    assert not (tmp_path / "e.mcap").exists()
    monkeypatch.setenv("MOVEPLAN_MAX_CONTROL_CYCLES", "10000000")
    assert cli("execute", SHIPPED_PLAN, "--fake", "-o", tmp_path / "e.mcap", "-q").exit_code == 0


def test_a_control_cycle_limit_that_is_no_number_is_a_usage_error(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("MOVEPLAN_MAX_CONTROL_CYCLES", "lots")
    result = cli("execute", SHIPPED_PLAN, "--fake", "-o", tmp_path / "e.mcap")
    assert result.exit_code == 2
    assert result.stderr == ("moveplan: error: MOVEPLAN_MAX_CONTROL_CYCLES='lots': expected a positive number of "
                             "control cycles\n")


@pytest.mark.parametrize("kind", ["--robot", "inspect", "task robot", "--scene"])
def test_a_name_too_long_for_the_system_is_bad_input_naming_it_shortened(cli: Cli, tmp_path: Path, kind: str) -> None:
    name = "x" * 300  # beyond NAME_MAX (255): the system refuses to look it up
    if kind == "task robot":
        (tmp_path / "task.yaml").write_text(f"robot: {name}\nsteps:\n  - {{name: home, named: home}}\n")
        args: list[object] = ["plan", tmp_path / "task.yaml", "-o", tmp_path / "out"]
    elif kind == "inspect":
        args = ["inspect", name]
    else:
        args = ["plan", "--robot", UR10E if kind == "--scene" else name, *([kind, name] if kind == "--scene" else []),
                "--named", "home", "-o", tmp_path / "out"]
    result = cli(*args)
    assert result.exit_code == 3, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "internal error" not in lines[0] and len(lines[0]) < 400, result.stderr
    assert lines[0].endswith("File name too long")


def test_control_characters_from_a_file_reach_the_terminal_escaped(cli: Cli, tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text('"\\x1b[31mred\\x07": 1\nsteps: []\n')  # an escape sequence and a bell as a key
    result = cli("plan", task, "-o", tmp_path / "out")
    assert result.exit_code == 3
    assert r"unknown key '\x1b[31mred\x07'" in result.stderr and "\x1b" not in result.stderr


def test_a_scene_coordinate_beyond_the_bound_is_refused_naming_it(cli: Cli, tmp_path: Path) -> None:
    """A box at 1e18 m broke coal's bounding volumes (an internal error); 1e300 was called a collision."""
    scene = tmp_path / "scene.yaml"
    scene.write_text("objects:\n  - {name: box, frame: base_link, xyz: [0.6, 1.0e18, 0.2], box: [0.1, 0.1, 0.1]}\n")
    result = cli("plan", "--robot", UR10E, "--scene", scene, "--named", "home", "-o", tmp_path / "out")
    assert result.exit_code == 3
    assert "scene.yaml: objects[0].xyz[1]: 1e+18 is out of range; values are limited to |value| <= 1,000,000" \
        in result.stderr


@pytest.mark.parametrize("group", ["{manipulator: 1}", "[manipulator]"])
def test_a_planning_group_that_is_no_name_is_refused(cli: Cli, tmp_path: Path, group: str) -> None:
    config = tmp_path / "ur10e"
    shutil.copytree(UR10E, config)
    manifest = config / "moveplan.yaml"
    manifest.write_text(manifest.read_text().replace("group: manipulator", f"group: {group}"))
    result = cli("robot", config)
    assert result.exit_code == 3
    assert "moveplan.yaml: planning.group: expected a name, got" in result.stderr


def test_a_huge_goal_duration_margin_is_refused_before_memory_is_spent(cli: Cli, tmp_path: Path) -> None:
    """MoveIt's duration monitor waits the margin out: 1e12 s asked for terabytes of control cycles."""
    controllers = tmp_path / "moveit_controllers.yaml"
    controllers.write_text("trajectory_execution: {allowed_goal_duration_margin: 1.0e12}\n")
    config = tmp_path / "ur10e"
    shutil.copytree(UR10E, config)
    shutil.copy(controllers, config / "moveit_controllers.yaml")
    plan = tmp_path / "plan.mcap"
    assert cli("plan", "--robot", config, "--start-joints", "0,-1,-1,0,0,0", "--named", "home", "-o", plan,
               "-q").exit_code == 0
    result = cli("execute", plan, "--fake", "-o", tmp_path / "e.mcap")
    assert result.exit_code == 3
    assert "control cycles; moveplan simulates at most 1,000,000 per trajectory" in result.stderr


# -- stdout that cannot be written: exit 3 and one line, or 141 and nothing, whatever prints ---------------------


@pytest.mark.parametrize("args", [["--help"], ["--version"], ["plan", "--help"]])
def test_help_or_version_into_a_full_stdout_is_one_line_and_exit_3(args: list[str]) -> None:
    with open("/dev/full", "w") as full:  # every write fails with ENOSPC, as a full disk under `> file`
        result = subprocess.run([sys.executable, "-m", "moveplan.cli.app", *args], stdout=full,
                                stderr=subprocess.PIPE, text=True, timeout=120)
    assert result.returncode == 3
    assert result.stderr == "moveplan: error: cannot write to standard output: No space left on device\n"


@pytest.mark.parametrize("args", [["--help"], ["--version"]])
def test_help_or_version_into_a_closed_pipe_exits_141_quietly(args: list[str]) -> None:
    reading, writing = os.pipe()
    os.close(reading)
    try:
        result = subprocess.run([sys.executable, "-m", "moveplan.cli.app", *args], stdout=writing,
                                stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(writing)
    assert result.returncode == 141 and result.stderr == ""


@pytest.mark.parametrize(("args", "code"), [(["inspect", "missing.mcap"], 3), (["plan", "--robot"], 2)])
def test_an_error_that_cannot_be_said_on_a_full_stderr_still_exits_with_its_code(args: list[str], code: int) -> None:
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-m", "moveplan.cli.app", *args], stdout=subprocess.PIPE,
                                stderr=full, text=True, timeout=120)
    assert result.returncode == code and result.stdout == ""


def test_output_and_errors_both_unwritable_exit_3(tmp_path: Path) -> None:
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-m", "moveplan.cli.app", "robot", UR10E], stdout=full, stderr=full,
                                timeout=120)
    assert result.returncode == 3


def test_a_plan_whose_json_meets_a_full_stdout_exits_3_and_its_file_stays_complete(tmp_path: Path) -> None:
    """The file is written before anything is printed (docs/cli.md, Signals and pipes)."""
    out = tmp_path / "plan.mcap"
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-m", "moveplan.cli.app", "plan", *QUICK_PLAN, "-o", out, "--json"],
                                stdout=full, stderr=subprocess.PIPE, text=True, timeout=300)
    assert result.returncode == 3
    assert result.stderr == "moveplan: error: cannot write to standard output: No space left on device\n"
    assert [step.name for step in read_plan(out).steps] == ["home"]


# -- a file-size limit (ulimit -f) or a full disk while writing: one line, exit 3, nothing left --------------------


def _outputs(kind: str, folder: Path) -> tuple[list[object], list[Path]]:
    """Return the command line of `kind` writing two outputs into `folder`, and those outputs."""
    if kind == "execute":
        outputs = [folder / "executed.mcap", folder / "executed.png"]
        return ["execute", SHIPPED_PLAN, "--fake", "-o", outputs[0], "--plot", outputs[1], "-q"], outputs
    outputs = [folder / "tuned.yaml", folder / "tuned.png"]
    return ["tune-pid", SHIPPED_PLAN, "--controllers", SAMPLES / "ur10e_velocity_controllers.yaml",
            "-o", outputs[0], "--plot", outputs[1], "-q"], outputs


def _run_limited(args: list[object], limit: int | None) -> subprocess.CompletedProcess[str]:
    """Run moveplan as its own process, its files limited to `limit` bytes (None: unlimited), as `ulimit -f` does."""

    def apply() -> None:
        if limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return subprocess.run([sys.executable, "-m", "moveplan.cli.app", *map(str, args)], preexec_fn=apply,
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("kind", ["execute", "tune-pid"])
def test_a_file_size_limit_on_the_second_output_leaves_neither_and_names_it(tmp_path: Path, kind: str) -> None:
    """The limit lies between the two outputs' sizes: the larger one fails (EFBIG; SIGXFSZ is ignored)."""
    whole, limited = tmp_path / "whole", tmp_path / "limited"
    whole.mkdir()
    limited.mkdir()
    args, outputs = _outputs(kind, whole)
    assert _run_limited(args, None).returncode == 0
    sizes = sorted((p.stat().st_size, p.name) for p in outputs)
    args, _ = _outputs(kind, limited)
    result = _run_limited(args, (sizes[0][0] + sizes[1][0]) // 2)
    assert result.returncode == 3, result.stderr
    assert result.stderr == f"moveplan: error: {limited / sizes[1][1]}: cannot write: File too large\n"
    assert list(limited.iterdir()) == []


@pytest.fixture()
def problems(tmp_path: Path) -> Path:
    """A folder of one MotionBenchMaker problem for the panda."""
    folder = tmp_path / "problems" / "box_panda"
    folder.mkdir(parents=True)
    for name in ("scene0001.yaml", "request0001.yaml"):
        shutil.copy(ROOT / "tests" / "data" / "mbm" / "problems" / "box_panda" / name, folder / name)
    return tmp_path / "problems"


def test_a_benchmark_plot_that_fails_takes_its_csv_with_it(
    cli: Cli, problems: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def full_disk(runs: object, path: Path) -> None:
        raise InputError(f"{path}: cannot write: No space left on device")

    monkeypatch.setattr(bench, "plot_benchmark", full_disk)
    out = tmp_path / "out"
    out.mkdir()
    result = cli("benchmark", problems, "--robot", "panda", "--planner", "RRTConnect", "--csv", out / "runs.csv",
                 "--plot", out / "times.png", "-q")
    assert result.exit_code == 3
    assert result.stderr == f"moveplan: error: {out / 'times.png'}: cannot write: No space left on device\n"
    assert list(out.iterdir()) == []


def test_a_benchmark_plot_in_a_missing_folder_is_refused_before_any_run(
    cli: Cli, problems: Path, tmp_path: Path
) -> None:
    plot = tmp_path / "missing" / "times.png"
    result = cli("benchmark", problems, "--robot", "panda", "--csv", tmp_path / "runs.csv", "--plot", plot)
    assert result.exit_code == 3
    assert result.stderr == (f"moveplan: error: --plot '{plot}': cannot write: folder '{plot.parent}' does not "
                             "exist\n")
    assert not (tmp_path / "runs.csv").exists()


# -- a signal while a second output is written: 128 + signal, nothing left ------------------------------------------

# moveplan's entry point with the plot slowed down: it announces that it has started drawing (the
# first output is written or staged then) and waits there to be signalled.
_SLOW_PLOT = """
import importlib, sys, time
from pathlib import Path
from moveplan.cli.app import main

started, module, function = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
def slow_plot(*args, **kwargs):
    started.touch()
    time.sleep(120)
setattr(importlib.import_module(module), function, slow_plot)
sys.argv = ["moveplan", *sys.argv[4:]]
main()
"""


def _signals_by_default() -> None:
    """Give the child the default SIGINT and SIGHUP: a suite run under nohup or in the background ignores them."""
    for signum in (signal.SIGINT, signal.SIGHUP):
        signal.signal(signum, signal.SIG_DFL)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
@pytest.mark.parametrize("command", ["tune-pid", "benchmark"])
def test_a_signal_while_the_plot_is_drawn_leaves_no_output_and_exits_128_plus_signal(
    problems: Path, tmp_path: Path, signum: int, command: str
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    if command == "tune-pid":
        hook = ["moveplan.core.pipeline.plots.tuning", "write_tuning_plot"]
        args: list[object] = ["tune-pid", SHIPPED_PLAN, "--controllers", SAMPLES / "ur10e_velocity_controllers.yaml",
                              "-o", out / "tuned.yaml", "--plot", out / "tuned.png"]
    else:
        hook = ["moveplan.core.pipeline.benchmark", "plot_benchmark"]
        args = ["benchmark", problems, "--robot", "panda", "--planner", "RRTConnect", "--csv", out / "runs.csv",
                "--plot", out / "times.png"]
    started = tmp_path / "started"
    process = subprocess.Popen([sys.executable, "-c", _SLOW_PLOT, started, *hook, *map(str, args), "-q"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               preexec_fn=_signals_by_default)
    try:
        deadline = time.monotonic() + 120
        while not started.exists():
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, "the plot was never drawn"
            time.sleep(0.05)
        assert list(out.iterdir()), "the first output is there (staged or written) while the plot is drawn"
        process.send_signal(signum)
        _, stderr = process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == 128 + signum, stderr
    assert stderr == f"moveplan: error: interrupted ({signal.Signals(signum).name})\n"
    assert list(out.iterdir()) == []
