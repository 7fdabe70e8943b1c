"""`--plot FILE.png` on inspect, execute and check-tolerances: one PNG per command, exit codes unchanged."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, SAMPLES, Cli, write_bag
from PIL import Image

from moveplan.core.bag.jointstates import encode_joint_states, read_joint_states
from moveplan.core.pipeline.plots._figures import POINTS_PER_SERIES
from moveplan.core.pipeline.plots.commands import thinned

RECORDINGS = SAMPLES / "recordings"
PLAN = RECORDINGS / "tool_up_plan.mcap"
MISTUNED = SAMPLES / "ur10e_mistuned_controllers.yaml"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _png(path: Path) -> Image.Image:
    """Return the PNG at `path`, checked to be one of a size fit for a CI artifact."""
    assert path.read_bytes()[:8] == PNG_SIGNATURE
    assert 20_000 < path.stat().st_size < 600_000
    return Image.open(path)


def _red_pixels(image: Image.Image) -> int:
    """Return how many pixels above the legend are pure red: the violation marks (nothing else is drawn in it)."""
    pixels = np.asarray(image.convert("RGB"))[:-80]
    return int(np.sum(np.all(pixels == (255, 0, 0), axis=-1)))


@pytest.fixture(scope="module")
def cycle_plan(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """Return the joint-goals plan (home, two goals, home) and a file of its execution."""
    folder = tmp_path_factory.mktemp("cycle")
    plan, executed = folder / "cycle.mcap", folder / "executed.mcap"
    cli = Cli()
    assert cli("plan", SAMPLES / "ur10e_joint_goals.yaml", "-o", plan, "-q").exit_code == 0
    assert cli("execute", plan, "--fake", "-o", executed, "-q").exit_code == 0
    return plan, executed


def test_inspect_plot_draws_a_plan_one_row_per_joint(cli: Cli, tmp_path: Path) -> None:
    plot = tmp_path / "plan.png"
    result = cli("inspect", PLAN, "--plot", plot)
    assert result.exit_code == 0, result.stderr
    image = _png(plot)
    assert image.size == (1200, round(100 * (1.4 + 1.9 * 6)))  # 12 in wide at 100 dpi; 6 joints of the UR10e
    assert image.text["Title"].startswith("moveplan inspect tool_up_plan.mcap: ur10e / manipulator, 1 steps")
    peaks = json.loads(cli("inspect", PLAN, "--json").stdout)["plan"]["steps"][0]
    assert (f"peak velocity {peaks['peak_velocity_fraction']:.0%}, acceleration "
            f"{peaks['peak_acceleration_fraction']:.0%} of the limits") in image.text["Title"]


def test_inspect_plot_of_a_recording_is_refused(cli: Cli, tmp_path: Path) -> None:
    plot = tmp_path / "recording.png"
    result = cli("inspect", RECORDINGS / "tool_up_ok.mcap", "--plot", plot)
    assert result.exit_code == 2
    assert result.stderr.strip() == (f"moveplan: error: --plot: {RECORDINGS / 'tool_up_ok.mcap'} is not a moveplan "
                                     "plan file; --plot draws the joints of a plan")
    assert not plot.exists()


def test_execute_plot_keeps_exit_code_and_report_and_marks_the_violation(cli: Cli, tmp_path: Path) -> None:
    plot = tmp_path / "mistuned.png"
    args = ("execute", PLAN, "--fake", "--plant", "pid", "--controllers", MISTUNED)
    plain_code, plain = cli.json(*args)
    code, document = cli.json(*args, "--plot", plot)
    assert (code, document) == (plain_code, plain) == (5, plain)
    assert document["result"]["name"] == "PATH_TOLERANCE_VIOLATED"
    image = _png(plot)
    assert "PATH_TOLERANCE_VIOLATED" in image.text["Title"]
    assert _red_pixels(image) > 50


def test_execute_plot_of_a_success_has_no_violation_marks(cli: Cli, tmp_path: Path) -> None:
    plot = tmp_path / "ok.png"
    result = cli("execute", PLAN, "--fake", "--plot", plot)
    assert result.exit_code == 0, result.stderr
    image = _png(plot)
    assert image.text["Title"].startswith("moveplan execute tool_up_plan.mcap: SUCCESSFUL - executed 1 of 1 steps")
    assert _red_pixels(image) == 0


def test_execute_plot_and_output_write_both_files(cli: Cli, tmp_path: Path) -> None:
    plot, executed = tmp_path / "run.png", tmp_path / "run.mcap"
    code, document = cli.json("execute", PLAN, "--fake", "-o", executed, "--plot", plot)
    assert code == 0 and document["output"] == str(executed)
    _png(plot)
    assert len(read_joint_states(executed).times_s) > 100
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.mcap", "run.png"]  # no temporary file left


@pytest.mark.parametrize(
    ("recording", "extra", "code", "verdict"),
    [
        ("tool_up_ok.mcap", [], 0, "within tolerances"),
        ("tool_up_path_violation.mcap", [], 5, "PATH_TOLERANCE_VIOLATED"),
        ("tool_up_goal_missed.mcap", ["--controllers", RECORDINGS / "ur10e_goal_time_controllers.yaml",
                                      "--start", "0"], 5, "GOAL_TOLERANCE_VIOLATED"),
    ],
)
def test_check_plot_keeps_exit_code_and_draws_the_verdict(
    cli: Cli, tmp_path: Path, recording: str, extra: list[object], code: int, verdict: str
) -> None:
    plot = tmp_path / "check.png"
    args = ("check-tolerances", PLAN, RECORDINGS / recording, *extra)
    plain = cli.json(*args)
    assert cli.json(*args, "--plot", plot) == plain
    assert plain[0] == code
    image = _png(plot)
    assert image.text["Title"].startswith(f"moveplan check-tolerances tool_up_plan.mcap {recording}: {verdict}")
    assert (_red_pixels(image) > 50) == (code == 5)


def test_check_plot_of_many_cycles_draws_the_first_failing_one(
    cli: Cli, tmp_path: Path, cycle_plan: tuple[Path, Path]
) -> None:
    plan, executed = cycle_plan
    one = read_joint_states(executed)
    period = float(np.median(np.diff(one.times_s)))
    pause = np.repeat(one.positions[-1:], int(1.0 / period), axis=0)  # a second at rest between cycles
    cycle = np.concatenate([one.positions, pause])
    positions = np.concatenate([cycle] * 4)
    bump = 2 * len(cycle) + len(one.positions) // 3
    positions[bump : bump + 5, 2] += 0.3
    recording = _bag(tmp_path / "shift.mcap", one.names, positions, period)
    plot = tmp_path / "shift.png"
    code, document = cli.json("check-tolerances", plan, recording, "--start", "all", "--plot", plot)
    assert code == 5 and document["failing_cycles"] == [2]
    title = _png(plot).text["Title"]
    assert "cycle 2 of 4 drawn (the first that failed)" in title
    start = document["cycles"][2]["start_s"]
    assert f"t = 0 is {start:.3f} s into the recording" in title


def test_check_plot_of_passing_cycles_draws_the_first(
    cli: Cli, tmp_path: Path, cycle_plan: tuple[Path, Path]
) -> None:
    plan, executed = cycle_plan
    one = read_joint_states(executed)
    period = float(np.median(np.diff(one.times_s)))
    pause = np.repeat(one.positions[-1:], int(1.0 / period), axis=0)
    recording = _bag(tmp_path / "two.mcap", one.names, np.concatenate([one.positions, pause] * 2), period)
    plot = tmp_path / "two.png"
    code, _ = cli.json("check-tolerances", plan, recording, "--start", "all", "--plot", plot)
    assert code == 0
    assert "cycle 0 of 2 drawn (none failed: the first)" in _png(plot).text["Title"]


def test_check_of_a_recording_cut_off_writes_no_plot(cli: Cli, tmp_path: Path) -> None:
    whole = read_joint_states(RECORDINGS / "tool_up_ok.mcap")
    period = float(np.median(np.diff(whole.times_s)))
    half = _bag(tmp_path / "half.mcap", whole.names, whole.positions[: len(whole.positions) // 2], period)
    plot = tmp_path / "half.png"
    result = cli("check-tolerances", PLAN, half, "--start", "0", "--plot", plot)
    assert result.exit_code == 3, result.stderr
    assert not plot.exists()


def _bag(path: Path, names: tuple[str, ...], positions: np.ndarray, period: float) -> Path:
    """Write joint states one `period` [s] apart as a ROS 2 bag; return its path."""
    stamps = (np.arange(len(positions)) * period * 1e9).astype(np.int64) + 1_700_000_000_000_000_000
    payloads = encode_joint_states(names, stamps, positions)
    return write_bag(path, [("/joint_states", "sensor_msgs/msg/JointState", int(s), p)
                            for s, p in zip(stamps, payloads, strict=True)])


@pytest.mark.parametrize(
    ("command", "plot", "code", "message"),
    [
        ("execute", "missing/plot.png", 3, "--plot '{tmp}/missing/plot.png': cannot write: folder "
                                           "'{tmp}/missing' does not exist"),
        ("execute", "plot.svg", 2, "--plot '{tmp}/plot.svg': expected a file name ending in .png"),
        ("execute", "folder.png", 2, "--plot '{tmp}/folder.png': is a directory; name a file"),
        ("execute", "{plan}", 2, "is also PLAN, read by this command"),
        ("execute", "{tmp}/out.mcap", 2, "is also -o; name two different files"),
        ("check-tolerances", "{recording}", 2, "is also RECORDING, read by this command"),
        ("check-tolerances", "missing/plot.png", 3, "folder '{tmp}/missing' does not exist"),
        ("inspect", "{plan}", 2, "is also FILE, read by this command"),
        ("inspect", "plot.PNG.txt", 2, "expected a file name ending in .png"),
    ],
)
def test_bad_plot_path_is_refused_before_any_work(
    cli: Cli, tmp_path: Path, command: str, plot: str, code: int, message: str
) -> None:
    (tmp_path / "folder.png").mkdir()
    names = {"tmp": tmp_path, "plan": PLAN, "recording": RECORDINGS / "tool_up_ok.mcap"}
    target = Path(plot.format(**names))
    target = target if target.is_absolute() else tmp_path / target
    output = tmp_path / "out.mcap"
    args = {
        "execute": ["execute", PLAN, "--fake", "-o", output],
        "check-tolerances": ["check-tolerances", PLAN, RECORDINGS / "tool_up_ok.mcap"],
        "inspect": ["inspect", PLAN],
    }[command]
    result = cli(*args, "--plot", target)
    assert result.exit_code == code
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and message.format(**names) in lines[0], result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder.png"]  # no -o written: refused before the work


def test_plan_that_cannot_be_read_leaves_no_plot(cli: Cli, tmp_path: Path) -> None:
    plot = tmp_path / "plot.png"
    result = cli("execute", RECORDINGS / "tool_up_ok.mcap", "--fake", "--plot", plot)
    assert result.exit_code == 3
    assert "not a moveplan plan file" in result.stderr and "Traceback" not in result.stderr
    assert not plot.exists()


def test_matplotlib_is_imported_only_for_a_plot(tmp_path: Path) -> None:
    code = f"""
import sys
from typer.testing import CliRunner
from moveplan.cli.app import app
runner = CliRunner()
plan, recording = {str(PLAN)!r}, {str(RECORDINGS / 'tool_up_ok.mcap')!r}
for args in (["--help"], ["inspect", plan], ["execute", plan, "--fake"], ["execute", plan, "--fake", "-o",
             {str(tmp_path / 'e.mcap')!r}], ["check-tolerances", plan, recording]):
    assert runner.invoke(app, args).exit_code == 0, args
before = "matplotlib" in sys.modules
assert runner.invoke(app, ["inspect", plan, "--plot", {str(tmp_path / 'p.png')!r}]).exit_code == 0
print(before, "matplotlib" in sys.modules)
"""
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["False", "True"]


def test_thinning_keeps_a_bounded_number_of_rows_and_every_peak() -> None:
    count = 60_000  # a minute at 1 kHz
    times = np.arange(count) / 1000.0
    positions = np.column_stack([np.sin(times), np.cos(times)])
    error = np.zeros((count, 2))
    error[12_345, 1] = 0.3  # a one-cycle spike between kept rows
    every = -(-count // POINTS_PER_SERIES)
    kept_times, reference, actual, kept_error, low, high = thinned(times, positions, positions, error, every,
                                                                   last=True)
    assert len(kept_times) <= POINTS_PER_SERIES + 1
    assert kept_times[-1] == times[-1]
    assert reference.shape == actual.shape == kept_error.shape == low.shape == (len(kept_times), 2)
    assert not np.any(kept_error[:, 1])  # the spike falls between kept rows...
    assert high[:, 1].max() == 0.3 and low.min() == 0.0  # ...and still shows in the envelope


def test_json_documents_stay_strict_with_a_plot(cli: Cli, tmp_path: Path) -> None:
    result = cli("check-tolerances", PLAN, RECORDINGS / "tool_up_ok.mcap", "--plot", tmp_path / "c.png", "--json")
    assert result.exit_code == 0
    assert json.loads(result.stdout)["ok"] is True
