"""`moveplan tune-pid`: the excavator notes' procedure on the pid plant, the file it writes, and its verification."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, SAMPLES, Cli

from moveplan.core.config.controllers import parse_controllers
from moveplan.core.config.controllers_write import tuned_controllers_text, yaml_float
from moveplan.core.control.tuning import BANDWIDTH_PER_RATE, Gains, JointSetup, tune_joint
from moveplan.core.errors import ConfigError

UR_PLAN = SAMPLES / "recordings" / "tool_up_plan.mcap"
DATA = ROOT / "tests" / "data" / "tuning"
UR_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
             "wrist_3_joint")
PLANT = {"inertia": 1.0, "max_effort": math.inf, "max_velocity": math.inf, "noise": 0.0, "drive_tau": 0.0, "load": 0.0}


@pytest.fixture(scope="module")
def excavator_plan(tmp_path_factory: pytest.TempPathFactory) -> Path:
    plan = tmp_path_factory.mktemp("tune") / "dig.mcap"
    result = Cli()("plan", SAMPLES / "excavator_dig_cycle.yaml", "-o", plan, "-q")
    assert result.exit_code == 0, result.stderr
    return plan


def tuned_then_executed(cli: Cli, plan: Path, controllers: Path, out: Path, *params: str) -> tuple[dict, dict]:
    """Tune, then execute the plan with the file written: both JSON documents."""
    plant = [arg for param in params for arg in ("--plant-param", param)]
    code, tuned = cli.json("tune-pid", plan, "--controllers", controllers, "-o", out, *plant)
    assert code == 0, tuned
    code, executed = cli.json("execute", plan, "--fake", "--plant", "pid", "--controllers", out, *plant)
    assert code == 0, executed["result"]
    assert not any(figures["ringing"] for figures in executed["tracking"].values())
    return tuned, executed


def changed_lines(before: Path, after: Path) -> list[tuple[str, str]]:
    old, new = before.read_text().splitlines(), after.read_text().splitlines()
    assert len(old) == len(new)
    return [(a, b) for a, b in zip(old, new, strict=True) if a != b]


# --- the samples the issue names --------------------------------------------------------------


def test_mistuned_ur10e_is_tuned_to_gains_that_pass_without_ringing(cli: Cli, tmp_path: Path) -> None:
    mistuned = SAMPLES / "ur10e_mistuned_controllers.yaml"
    assert cli("execute", UR_PLAN, "--fake", "--plant", "pid", "--controllers", mistuned).exit_code == 5
    out = tmp_path / "tuned.yaml"
    tuned, executed = tuned_then_executed(cli, UR_PLAN, mistuned, out)
    assert tuned["ok"] is True and tuned["ringing"] == []
    assert tuned["verification"]["result"]["name"] == "SUCCESSFUL"
    assert executed["margins"] == pytest.approx(tuned["verification"]["margins"])
    # Only the gains lines changed; comments, layout and every other setting are the file's.
    changed = changed_lines(mistuned, out)
    assert [a.split(":")[0] for a, _ in changed] == [f"      {j}" for j in UR_JOINTS]
    assert all("ff_velocity_scale: 0.0}" in b for _, b in changed)


def test_mistuned_excavator_is_tuned_to_gains_that_pass_without_ringing(
    cli: Cli, tmp_path: Path, excavator_plan: Path
) -> None:
    mistuned = SAMPLES / "excavator_mistuned_controllers.yaml"
    assert cli("execute", excavator_plan, "--fake", "--plant", "pid", "--controllers", mistuned).exit_code == 5
    tuned, _ = tuned_then_executed(cli, excavator_plan, mistuned, tmp_path / "tuned.yaml")
    for joint, entry in tuned["joints"].items():
        assert entry["start"]["p"] == 250.0
        assert 0.0 < entry["gains"]["p"] <= 30.0 + 1e-9  # at most the bandwidth limit of a 100 Hz loop
        assert [s["stage"] for s in entry["stages"] if s["chosen"]][:2] == ["start", "P"], joint


def test_mistuned_excavator_on_a_drive_that_cannot_accelerate_at_will(
    cli: Cli, tmp_path: Path, excavator_plan: Path
) -> None:
    tuned_then_executed(cli, excavator_plan, SAMPLES / "excavator_mistuned_controllers.yaml",
                        tmp_path / "tuned.yaml", "max_effort=3.5", "max_velocity=1.0")


@pytest.mark.parametrize("robot", ["ur10e", "excavator"])
def test_zero_gains_are_tuned_to_gains_that_pass(cli: Cli, tmp_path: Path, excavator_plan: Path, robot: str) -> None:
    plan = UR_PLAN if robot == "ur10e" else excavator_plan
    tuned, _ = tuned_then_executed(cli, plan, DATA / f"{robot}_zero_gains_controllers.yaml", tmp_path / "t.yaml")
    assert all(entry["gains"]["p"] > 0.0 for entry in tuned["joints"].values())


@pytest.mark.parametrize("p", [150, 190])
def test_ringing_effort_gains_get_d_and_stop_ringing(cli: Cli, tmp_path: Path, p: int) -> None:
    tuned, _ = tuned_then_executed(cli, UR_PLAN, DATA / f"ur10e_effort_p{p}_controllers.yaml", tmp_path / "t.yaml")
    entry = tuned["joints"]["elbow_joint"]
    chosen = [s for s in entry["stages"] if s["chosen"]]
    assert chosen[0]["response"]["decay_ratio"] >= 0.8  # the file's P alone oscillates steadily
    assert chosen[1]["stage"] == "P" and chosen[1]["note"] == "oscillates steadily"
    assert chosen[2]["stage"] == "D" and chosen[2]["gains"]["d"] > 0.0 and chosen[2]["response"]["damped"]
    assert [s["stage"] for s in chosen].count("P+D") >= 1  # more P with more D settled faster
    assert chosen[-1]["response"]["oscillations"] <= 1


def test_lagging_drive_gets_d_for_p_without_d(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "t.yaml"
    tuned, _ = tuned_then_executed(cli, UR_PLAN, DATA / "ur10e_p150_controllers.yaml", out, "drive_tau=0.02")
    gains = tuned["joints"]["elbow_joint"]["gains"]
    assert gains["d"] > 0.3
    code, bumped = cli.json("execute", UR_PLAN, "--fake", "--plant", "pid", "--controllers", out, "--plant-param",
                            "drive_tau=0.02", "--disturb", "t=1.2,joint=elbow_joint,delta=0.01")
    assert code == 0 and bumped["tracking"]["elbow_joint"]["ringing"] is False


# --- the JSON and text reports, the plot ------------------------------------------------------


def test_json_lists_every_response_tried_with_its_gains_and_figures(cli: Cli, tmp_path: Path) -> None:
    code, document = cli.json("tune-pid", UR_PLAN, "--controllers", DATA / "ur10e_p150_controllers.yaml",
                              "-o", tmp_path / "t.yaml", "--joints", "elbow_joint,wrist_1_joint",
                              "--plant-param", "drive_tau=0.02")
    assert code == 0
    assert list(document["joints"]) == ["elbow_joint", "wrist_1_joint"]
    assert document["plant"] == {"drive_tau": 0.02}
    assert document["interface"] == "velocity" and document["fit"] is None and document["error"] is None
    entry = document["joints"]["elbow_joint"]
    assert entry["bump"] == 0.1 and entry["load"] == 0.0
    assert entry["gains"] == next(s["gains"] for s in reversed(entry["stages"]) if s["stage"] == "final")
    for stage in entry["stages"]:
        assert set(stage) == {"stage", "gains", "response", "chosen", "note"}
        assert set(stage["gains"]) == {"p", "i", "d", "i_clamp", "ff_velocity_scale"}
        assert {"oscillations", "decay_ratio", "overshoot", "settling_time_s", "peak_error"} <= set(stage["response"])
    assert len(entry["stages"]) > len([s for s in entry["stages"] if s["chosen"]])  # the rungs passed are there
    # Joints not asked for keep the file's gains.
    written = parse_controllers(tmp_path / "t.yaml")["joint_trajectory_controller"].gains
    assert written["shoulder_pan_joint"]["p"] == 150.0
    for key in ("p", "i", "d"):  # the tuned joint's gains were written (to the file's precision)
        assert written["elbow_joint"][key] == pytest.approx(entry["gains"][key], rel=1e-4)
    assert written["elbow_joint"] != written["shoulder_pan_joint"]
    assert set(document["verification"]["tracking"]) == set(UR_JOINTS)


def test_text_report_is_a_table_of_stages_and_the_verification(cli: Cli, tmp_path: Path) -> None:
    result = cli("tune-pid", UR_PLAN, "--controllers", DATA / "ur10e_p150_controllers.yaml",
                 "-o", tmp_path / "t.yaml", "--joints", "elbow_joint")
    assert result.exit_code == 0
    assert "elbow_joint" in result.stdout and "critically damped" in result.stdout
    assert "verification" in result.stdout and "SUCCESSFUL" in result.stdout and "ringing: none" in result.stdout


def test_a_diverging_start_reads_diverged_not_inf_or_nan(cli: Cli, tmp_path: Path) -> None:
    result = cli("tune-pid", UR_PLAN, "--controllers", SAMPLES / "ur10e_mistuned_controllers.yaml",
                 "-o", tmp_path / "t.yaml", "--joints", "elbow_joint")
    start = next(line for line in result.stdout.splitlines() if "the file's gains" in line)
    assert "decay diverged" in start and "overshoot [rad] diverged" in start
    assert "inf" not in result.stdout and "nan" not in result.stdout


def test_tuning_from_zero_gains_keeps_the_file_s_i_clamp(cli: Cli, tmp_path: Path) -> None:
    zero = tmp_path / "zero.yaml"
    zero.write_text((DATA / "ur10e_zero_gains_controllers.yaml").read_text().replace("i_clamp: 0.0", "i_clamp: 0.05"))
    assert "i_clamp: 0.05" in zero.read_text()
    tuned, _ = tuned_then_executed(cli, UR_PLAN, zero, tmp_path / "t.yaml")
    assert all(entry["gains"]["i_clamp"] == 0.05 for entry in tuned["joints"].values())


def test_plot_is_a_png_with_a_panel_per_joint(cli: Cli, tmp_path: Path) -> None:
    plot = tmp_path / "tune.png"
    result = cli("tune-pid", UR_PLAN, "--controllers", DATA / "ur10e_p150_controllers.yaml",
                 "-o", tmp_path / "t.yaml", "--joints", "elbow_joint,wrist_1_joint", "--plot", plot, "-q")
    assert result.exit_code == 0
    data = plot.read_bytes()
    assert data.startswith(b"\x89PNG\r\n\x1a\n") and 20_000 < len(data) < 500_000


# --- the plant fitted to a recording ----------------------------------------------------------


def test_recording_fit_finds_the_drive_lag_and_says_how_well_it_reproduces(cli: Cli, tmp_path: Path) -> None:
    recording = tmp_path / "robot.mcap"
    shipped = SAMPLES / "ur10e_velocity_controllers.yaml"
    made = cli("execute", UR_PLAN, "--fake", "--plant", "pid", "--controllers", shipped,
               "--plant-param", "drive_tau=0.03", "--plant-param", "noise=2e-4", "-o", recording, "-q")
    assert made.exit_code == 0
    code, document = cli.json("tune-pid", UR_PLAN, "--controllers", SAMPLES / "ur10e_velocity_controllers.yaml",
                              "--recording", recording, "-o", tmp_path / "t.yaml")
    assert code == 0
    fit = document["fit"]
    for joint in ("elbow_joint", "wrist_1_joint"):  # the joints that move
        assert fit["joints"][joint]["params"]["drive_tau"] == pytest.approx(0.03, rel=0.35)
        assert fit["joints"][joint]["params"]["noise"] == pytest.approx(2e-4, rel=0.2)
        assert fit["joints"][joint]["fraction"] < 0.01
    assert fit["rms_error"] < 4e-4 and fit["fraction"] < 0.005 and fit["samples"] > 400
    assert document["plant"]["drive_tau.elbow_joint"] == fit["joints"]["elbow_joint"]["params"]["drive_tau"]
    text = cli("tune-pid", UR_PLAN, "--controllers", SAMPLES / "ur10e_velocity_controllers.yaml",
               "--recording", recording, "-o", tmp_path / "t2.yaml")
    assert "RMS position error" in text.stdout and "% of the largest joint travel" in text.stdout


# --- what the procedure does, on one joint ----------------------------------------------------


def test_velocity_drive_p_stops_at_the_bandwidth_limit_of_the_update_rate() -> None:
    setup = JointSetup("j", "velocity", 0.002, 0.1, PLANT)
    tuning = tune_joint(setup, Gains())
    assert tuning.gains.p == pytest.approx(BANDWIDTH_PER_RATE * 500)
    chosen = [s.stage for s in tuning.stages if s.chosen]
    assert chosen == ["start", "P", "D", "I", "final"]
    assert tuning.stages[0].response.settling_time_s is None  # zero gains never bring it back


def test_load_makes_stage_four_raise_i_until_the_setpoint_is_reached() -> None:
    # A droop P alone leaves outside the goal tolerance: load / P = 0.2 / 30 > 0.002.
    setup = JointSetup("j", "velocity", 0.01, 0.002, {**PLANT, "load": 0.2, "drive_tau": 0.02})
    tuning = tune_joint(setup, Gains(p=5.0, ff_velocity_scale=1.0))
    stage = next(s for s in tuning.stages if s.stage == "I" and s.chosen)
    assert tuning.gains.i > 0.0 and tuning.gains.i_clamp >= 0.2
    assert abs(stage.response.final_error) <= 0.002 and stage.response.oscillations == 0
    assert tuning.load == 0.2


def test_wanted_oscillations_allow_a_faster_integral() -> None:
    plant = {**PLANT, "load": 0.05, "drive_tau": 0.02}
    none = tune_joint(JointSetup("j", "velocity", 0.01, 0.002, plant), Gains(p=5.0))
    some = tune_joint(JointSetup("j", "velocity", 0.01, 0.002, plant, oscillations=3), Gains(p=5.0))
    assert some.gains.i <= none.gains.i


# --- bad input --------------------------------------------------------------------------------


def test_output_naming_an_input_is_refused_and_nothing_is_written(cli: Cli, tmp_path: Path) -> None:
    controllers = tmp_path / "c.yaml"
    controllers.write_bytes((SAMPLES / "ur10e_mistuned_controllers.yaml").read_bytes())
    before = controllers.read_bytes()
    result = cli("tune-pid", UR_PLAN, "--controllers", controllers, "-o", controllers)
    assert result.exit_code == 2 and "-o" in result.stderr and "input" in result.stderr
    assert controllers.read_bytes() == before


@pytest.mark.parametrize(("args", "code", "message"), [
    (["--joints", "elbow_joint,knee_joint"], 2, "--joints: joint 'knee_joint'"),
    (["--plant-param", "friction=1"], 2, "no parameter 'friction'"),
    (["--plant-param", "drive_tau=-1"], 2, "'drive_tau' must be >= 0"),
    (["--oscillations", "-1"], 2, "--oscillations"),
    (["--plot", "tune.svg"], 2, ".png"),
])
def test_bad_flags_exit_2_with_one_line_and_no_file(
    cli: Cli, tmp_path: Path, args: list[str], code: int, message: str
) -> None:
    args = [str(tmp_path / a) if a.endswith(".svg") else a for a in args]
    result = cli("tune-pid", UR_PLAN, "--controllers", SAMPLES / "ur10e_mistuned_controllers.yaml",
                 "-o", tmp_path / "t.yaml", *args)
    assert result.exit_code == code
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "t.yaml").exists()


def test_bad_input_files_exit_3_naming_the_file(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "t.yaml"
    missing = cli("tune-pid", UR_PLAN, "--controllers", tmp_path / "none.yaml", "-o", out)
    assert missing.exit_code == 3 and "none.yaml" in missing.stderr
    position = cli("tune-pid", UR_PLAN, "-o", out)  # the plan's own controller commands positions
    assert position.exit_code == 3
    assert "ros2_controllers.yaml" in position.stderr and "[velocity] or [effort]" in position.stderr
    unrelated = tmp_path / "rec.mcap"
    unrelated.write_bytes(b"not a bag")
    bad = cli("tune-pid", UR_PLAN, "--controllers", SAMPLES / "ur10e_mistuned_controllers.yaml",
              "--recording", unrelated, "-o", out)
    assert bad.exit_code == 3 and "rec.mcap" in bad.stderr
    no_folder = cli("tune-pid", UR_PLAN, "--controllers", SAMPLES / "ur10e_mistuned_controllers.yaml",
                    "-o", tmp_path / "nowhere" / "t.yaml")
    assert no_folder.exit_code in (2, 3) and "nowhere" in no_folder.stderr
    assert not out.exists() and not list(tmp_path.glob(".t.yaml*"))


def test_verification_that_fails_exits_5_and_still_writes_the_file(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "t.yaml"
    # A drive too slow for the plan: no gains follow it within the path tolerance.
    code, document = cli.json("tune-pid", UR_PLAN, "--controllers", SAMPLES / "ur10e_mistuned_controllers.yaml",
                              "-o", out, "--plant-param", "max_velocity=0.01")
    assert code == 5
    assert document["ok"] is False and document["verification"]["ok"] is False
    assert parse_controllers(out)["joint_trajectory_controller"].gains["elbow_joint"]["p"] < 1100.0


# --- the file written -------------------------------------------------------------------------


def test_written_numbers_are_doubles_for_ros() -> None:
    assert [yaml_float(v) for v in (50.0, 0.0, 0.865, 1e-5, 2.5e6, 1708.59375)] == [
        "50.0", "0.0", "0.865", "1.0e-05", "2.5e+06", "1708.59"]


BLOCK = """\
# my arm
controller_manager:
  ros__parameters:
    update_rate: 100  # Hz
    arm_controller:
      type: joint_trajectory_controller/JointTrajectoryController
arm_controller:
  ros__parameters:
    joints: [$(var prefix)a, $(var prefix)b, c]
    command_interfaces: [velocity]
    state_interfaces: [position, velocity]
    gains:
      $(var prefix)a:
        p: 1.0  # too soft
        ff_velocity_scale: 1.0
      $(var prefix)b: {p: 2.0}
    constraints:
      goal_time: 1.0
"""


def test_gains_are_written_where_they_stand_and_added_where_missing(tmp_path: Path) -> None:
    gains = {name: {"p": 10.0, "i": 0.5, "d": 0.25, "i_clamp": 0.1} for name in ("left_a", "left_b", "c")}
    text = tuned_controllers_text(BLOCK, "arm.yaml", "arm_controller", gains, {"prefix": "left_"})
    assert text.startswith("# my arm\n") and "p: 10.0  # too soft" in text and "update_rate: 100  # Hz" in text
    assert "$(var prefix)b: {p: 10.0, i: 0.5, d: 0.25, i_clamp: 0.1}" in text
    assert "      c: {p: 10.0, i: 0.5, d: 0.25, i_clamp: 0.1}" in text
    path = tmp_path / "arm.yaml"
    path.write_text(text)
    written = parse_controllers(path, {"prefix": "left_"})["arm_controller"].gains
    assert written["left_a"] == {"p": 10.0, "i": 0.5, "d": 0.25, "i_clamp": 0.1, "ff_velocity_scale": 1.0}
    assert written["c"] == gains["c"]


def test_a_controller_without_gains_gets_a_gains_section(tmp_path: Path) -> None:
    source = (ROOT / "configs" / "ur10e" / "ros2_controllers.yaml").read_text()
    gains = {j: {"p": 5.0, "d": 0.1} for j in UR_JOINTS}
    path = tmp_path / "c.yaml"
    path.write_text(tuned_controllers_text(source, "c.yaml", "joint_trajectory_controller", gains))
    written = parse_controllers(path)["joint_trajectory_controller"].gains
    assert all(written[j] == {"p": 5.0, "d": 0.1} for j in UR_JOINTS)
    assert path.read_text().startswith(source.rstrip("\n").split("\n")[0])


def test_a_file_without_the_controller_is_refused() -> None:
    with pytest.raises(ConfigError, match="no 'other_controller: ros__parameters' section"):
        tuned_controllers_text(BLOCK, "arm.yaml", "other_controller", {"a": {"p": 1.0}})


def test_responses_of_a_ladder_are_simulated_in_one_pass_and_agree_with_one_by_one() -> None:
    from moveplan.core.control.plants.responses import measure, simulate_responses

    gains = {"p": np.array([20.0, 60.0]), "i": 0.0, "d": 0.0, "i_clamp": 0.0, "ff_velocity_scale": 1.0}
    both = simulate_responses("velocity", 0.002, gains, {**PLANT, "drive_tau": 0.02}, 1.0, bump=0.01)
    one = simulate_responses("velocity", 0.002, {**gains, "p": 60.0}, {**PLANT, "drive_tau": 0.02}, 1.0, bump=0.01)
    np.testing.assert_allclose(both[:, 1], one[:, 0], atol=1e-15)
    slow, fast = measure(both, 0.002, 0.01)
    assert slow.oscillations <= 1 and fast.oscillations >= 2 and fast.overshoot > slow.overshoot
