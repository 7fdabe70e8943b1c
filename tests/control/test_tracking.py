"""Execution quality in every execution report: tracking figures per joint, and ringing joints named."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, SAMPLES, Cli
from rosbags.highlevel import AnyReader

from moveplan.core.bag.execution_file import EXECUTION_RESULT_TOPIC
from moveplan.core.control.quality import BAND_FLOOR, RINGING_OSCILLATIONS, crossings, noise_level, tracking

PLAN = SAMPLES / "recordings" / "tool_up_plan.mcap"  # one 1.05 s step: elbow and wrist_1 move
DATA = ROOT / "tests" / "data" / "tuning"
SHIPPED_GAINS = SAMPLES / "ur10e_velocity_controllers.yaml"
MOVING = ("shoulder_lift_joint", "elbow_joint", "wrist_1_joint")
KEYS = {"peak_error", "overshoot", "settling_time_s", "oscillations", "final_error", "band", "observed_s", "ringing"}


def ringing(document: dict) -> set[str]:
    return {joint for joint, figures in document["tracking"].items() if figures["ringing"]}


# --- the acceptance check: P = 150 and P = 190, no D ---------------------------------


@pytest.mark.parametrize("p", [150, 190])
def test_effort_p_without_d_passes_its_tolerances_but_its_ringing_joints_are_named(cli: Cli, p: int) -> None:
    controllers = DATA / f"ur10e_effort_p{p}_controllers.yaml"
    code, document = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers", controllers)
    assert code == 0 and document["result"]["name"] == "SUCCESSFUL"
    assert ringing(document) == set(MOVING)
    for joint in MOVING:
        figures = document["tracking"][joint]
        assert figures["oscillations"] >= RINGING_OSCILLATIONS
        assert figures["overshoot"] > 1e-4  # past the goal, beyond the band
    text = cli("execute", PLAN, "--fake", "--plant", "pid", "--controllers", controllers)
    assert text.exit_code == 0 and "SUCCESSFUL" in text.stdout
    named = text.stdout.split("ringing (error sign changes after the stop):", 1)[1]
    assert all(joint in named for joint in MOVING) and "wrist_3_joint" not in named


@pytest.mark.parametrize("p", [150, 190])
def test_velocity_p_without_d_rings_after_a_bump_on_a_lagging_drive(cli: Cli, p: int) -> None:
    # A bump after the step's end lands in the observed hold; a 20 ms drive lag leaves P alone underdamped.
    code, document = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers",
                              DATA / f"ur10e_p{p}_controllers.yaml", "--plant-param", "drive_tau=0.02",
                              "--disturb", "t=1.2,joint=elbow_joint,delta=0.01")
    assert code == 0
    assert ringing(document) == {"elbow_joint"}
    shipped = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers", SHIPPED_GAINS,
                       "--plant-param", "drive_tau=0.02", "--disturb", "t=1.2,joint=elbow_joint,delta=0.01")[1]
    assert ringing(shipped) == set()
    assert shipped["tracking"]["elbow_joint"]["oscillations"] <= 1


@pytest.mark.parametrize("p", [150, 190])
def test_velocity_p_without_d_on_the_ideal_drive_is_well_damped(cli: Cli, p: int) -> None:
    code, document = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers",
                              DATA / f"ur10e_p{p}_controllers.yaml", "--disturb", "t=1.2,joint=elbow_joint,delta=0.01")
    assert code == 0
    assert ringing(document) == set()


# --- noise ------------------------------------------------------------------------------------


@pytest.mark.parametrize("noise", ["1e-4", "1e-3"])
def test_a_noisy_but_well_damped_joint_is_not_ringing(cli: Cli, noise: str) -> None:
    code, document = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers", SHIPPED_GAINS,
                              "--plant-param", f"noise={noise}", "--seed", "3")
    assert code == 0
    assert ringing(document) == set()
    for figures in document["tracking"].values():
        assert figures["band"] >= 3.0 * float(noise)  # the hysteresis band grew with the noise
        assert figures["overshoot"] < float(noise)  # noise is no overshoot


def test_a_ringing_joint_is_still_named_under_noise(cli: Cli) -> None:
    code, document = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers",
                              DATA / "ur10e_effort_p150_controllers.yaml", "--plant-param", "noise=1e-4")
    assert code == 0
    assert {"elbow_joint", "wrist_1_joint"} <= ringing(document)


# --- the documents ----------------------------------------------------------------------------


def test_execute_json_has_tracking_per_joint_overall_and_per_step(cli: Cli) -> None:
    code, document = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers", SHIPPED_GAINS)
    assert code == 0
    assert set(document["tracking"]) == set(document["margins"])
    for figures in document["tracking"].values():
        assert set(figures) == KEYS
        assert figures["observed_s"] == pytest.approx(2.0, abs=0.01)  # held 2 s past the verdict
        assert figures["settling_time_s"] == 0.0 and figures["ringing"] is False
    [step] = document["steps"]
    assert step["tracking"] == document["tracking"]
    assert document["tracking"]["elbow_joint"]["peak_error"] < 1e-5  # feed-forward carries the motion


def test_mirror_execution_tracks_perfectly(cli: Cli) -> None:
    code, document = cli.json("execute", PLAN, "--fake")
    assert code == 0
    for figures in document["tracking"].values():
        assert figures["peak_error"] == 0.0 and figures["oscillations"] == 0 and figures["final_error"] == 0.0


def test_executed_file_result_carries_the_tracking(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "executed.mcap"
    code, document = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers",
                              DATA / "ur10e_effort_p150_controllers.yaml", "-o", out)
    assert code == 0
    with AnyReader([out]) as reader:
        [(connection, _, raw)] = [m for m in reader.messages() if m[0].topic == EXECUTION_RESULT_TOPIC]
        stored = json.loads(reader.deserialize(raw, connection.msgtype).data)
    assert stored["tracking"] == document["tracking"]
    assert stored["tracking"]["elbow_joint"]["ringing"] is True


def test_failed_step_has_no_stop_to_observe(cli: Cli) -> None:
    code, document = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers", SHIPPED_GAINS,
                              "--disturb", "t=0.5,joint=elbow_joint,delta=0.3")
    assert code == 5
    figures = document["tracking"]["elbow_joint"]
    assert figures["peak_error"] == pytest.approx(0.3, abs=0.01)
    assert figures["oscillations"] == 0 and figures["observed_s"] == 0.0 and figures["settling_time_s"] is None


def test_check_tolerances_reports_tracking_of_a_recording_step_by_step(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "executed.mcap"
    executed = cli.json("execute", PLAN, "--fake", "--plant", "pid", "--controllers",
                        DATA / "ur10e_effort_p150_controllers.yaml", "-o", out)[1]
    code, document = cli.json("check-tolerances", PLAN, out, "--start", "0", "--controllers",
                              DATA / "ur10e_effort_p150_controllers.yaml")
    assert code == 0
    [step] = document["steps"]
    assert step["tracking"] == document["tracking"]
    for joint, figures in document["tracking"].items():
        assert set(figures) == KEYS
        # The same samples up to the verdict; the file ends there, so nothing after the stop is seen.
        assert figures["peak_error"] == pytest.approx(executed["tracking"][joint]["peak_error"], abs=1e-7)
        assert figures["observed_s"] < 0.01


def test_check_tolerances_of_a_shipped_recording_has_tracking(cli: Cli) -> None:
    code, document = cli.json("check-tolerances", PLAN, SAMPLES / "recordings" / "tool_up_ok.mcap")
    assert code == 0
    assert set(document["tracking"]) == set(document["margins"])
    text = cli("check-tolerances", PLAN, SAMPLES / "recordings" / "tool_up_ok.mcap")
    assert "tracking [rad]" in text.stdout and "ringing" not in text.stdout


def test_check_tolerances_start_all_names_the_cycle_its_tracking_comes_from(cli: Cli) -> None:
    code, document = cli.json("check-tolerances", PLAN, SAMPLES / "recordings" / "tool_up_ok.mcap", "--start", "all")
    assert code == 0
    assert document["tracking_cycle"] == 0
    assert set(document["tracking"]) == set(document["margins"])


def test_slow_drive_mistuned_excavator_names_its_ringing_joints(cli: Cli, tmp_path: Path) -> None:
    plan = tmp_path / "demo.mcap"
    assert cli("plan", SAMPLES / "excavator_demo.yaml", "-o", plan, "-q").exit_code == 0
    # The excavator config's hydraulic plant, without its lag, droop and noise: the slow drive alone.
    ideal = ("--plant-param", "drive_tau=0", "--plant-param", "load=0", "--plant-param", "noise=0")
    code, document = cli.json("execute", plan, "--fake", "--plant", "pid", "--controllers",
                              SAMPLES / "excavator_mistuned_controllers.yaml", "--plant-param", "max_effort=3.5",
                              "--plant-param", "max_velocity=1.0", *ideal)
    assert code == 5
    assert ringing(document)
    assert all(document["tracking"][j]["oscillations"] >= RINGING_OSCILLATIONS for j in ringing(document))


# --- the figures on hand-made signals ---------------------------------------------------------


def test_crossings_count_only_swings_through_the_band() -> None:
    values = np.array([0.0, 2.0, 0.5, -0.5, 0.5, -2.0, -0.5, 2.0, 0.9])
    assert crossings(values, 1.0).tolist() == [5, 7]
    assert len(crossings(np.zeros(10), 1e-4)) == 0


def test_noise_level_estimates_white_noise_on_a_smooth_motion() -> None:
    rng = np.random.default_rng(0)
    times = np.linspace(0.0, 2.0, 2001)
    values = 0.3 * np.sin(2.0 * times) + rng.normal(0.0, 1e-3, len(times))
    assert noise_level(values)[0] == pytest.approx(1e-3, rel=0.1)
    assert noise_level(0.3 * np.sin(2.0 * times))[0] < 1e-6


def test_tracking_of_a_decaying_oscillation_after_the_stop() -> None:
    times = np.arange(0.0, 3.0, 0.002)
    reference = np.where(times < 1.0, times * 0.5, 0.5)
    after = times >= 1.0
    # Past the goal first: actual - goal = 0.01 e^-t sin(...), error = -(that).
    error = np.where(after, -0.01 * np.exp(-(times - 1.0)) * np.sin(2 * np.pi * 3.0 * (times - 1.0)), 0.0)
    [(joint, figures)] = tracking(["j"], times, reference[:, None], error[:, None], 1.0, [0.002]).items()
    assert joint == "j"
    assert figures.ringing and figures.oscillations >= 10
    assert figures.overshoot == pytest.approx(0.01 * np.exp(-1 / 12), abs=2e-4)  # the first peak
    assert figures.peak_error == pytest.approx(figures.overshoot, abs=1e-5)
    assert 1.0 < figures.settling_time_s < 2.0
    assert figures.band == BAND_FLOOR


def test_tracking_of_a_joint_that_never_settles_and_of_a_diverged_one() -> None:
    times = np.arange(0.0, 1.0, 0.01)
    still = np.zeros((len(times), 1))
    figures = tracking(["j"], times, still, np.full_like(still, 0.5), 0.5, [0.1])["j"]
    assert figures.settling_time_s is None and figures.final_error == 0.5
    broken = np.where(times[:, None] > 0.3, np.nan, 0.0)
    figures = tracking(["j"], times, still, broken, 0.5, [0.1])["j"]
    assert figures.peak_error == 0.0 and np.isnan(figures.final_error) and not figures.ringing


def test_a_step_aborted_in_motion_counts_its_oscillation_over_the_step(cli: Cli) -> None:
    """The mistuned UR10e aborts on a path violation while its error oscillates to the limit: the report shows it."""
    code, document = cli.json("execute", SAMPLES / "recordings" / "tool_up_plan.mcap", "--fake", "--plant", "pid",
                              "--controllers", SAMPLES / "ur10e_mistuned_controllers.yaml")
    assert code == 5 and document["result"]["name"] == "PATH_TOLERANCE_VIOLATED"
    violation = document["violations"][0]["joint"]
    assert document["tracking"][violation]["oscillations"] >= RINGING_OSCILLATIONS
    assert violation in ringing(document)
