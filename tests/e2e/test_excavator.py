"""The shipped excavator: config, demo and dig cycle plans, the deposition bucket, PID tuning."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, SAMPLES, Cli

from moveplan.core.bag.plan_file import PlanFile, read_plan
from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene
from moveplan.core.trajectory import sample

EXCAVATOR = ROOT / "configs" / "excavator"
SCENE = SAMPLES / "excavator_scene.yaml"
MISTUNED = SAMPLES / "excavator_mistuned_controllers.yaml"
JOINTS = ["turret_joint", "shoulder_joint", "elbow_joint", "wrist_joint"]
BODY_UNDERSIDE_Z = -0.125  # base_link is the body box's centre; the box is 0.25 m high
GROUND_Z = -0.35  # where the wheels stand
REALISTIC_DRIVE = ["--plant-param", "max_velocity=1.0", "--plant-param", "max_effort=3.5"]


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot(load_robot_config(EXCAVATOR))


@pytest.fixture(scope="module")
def checker(robot: Robot) -> CollisionChecker:
    return CollisionChecker(robot, load_scene(SCENE, robot).objects)


@pytest.fixture(scope="module")
def dig_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("excavator") / "dig.mcap"
    result = Cli()("plan", SAMPLES / "excavator_dig_cycle.yaml", "-o", out)
    assert result.exit_code == 0, result.stderr
    return out


@pytest.fixture(scope="module")
def dig(dig_file: Path) -> PlanFile:
    return read_plan(dig_file)


def dense(plan: PlanFile, step: str, period_s: float = 0.002) -> np.ndarray:
    """Positions of one step every `period_s` (at most 0.8 rad/s x 2 ms = 1.6 mrad apart)."""
    trajectory = next(s.trajectory for s in plan.steps if s.name == step)
    times = np.append(np.arange(0.0, trajectory.duration_s, period_s), trajectory.duration_s)
    positions, _, _ = sample(trajectory, times)
    return positions


def test_config_has_group_arm_with_the_four_joints_limits_and_controller(cli: Cli) -> None:
    code, document = cli.json("robot", EXCAVATOR)
    assert code == 0
    assert document["groups"]["Arm"]["joints"] == JOINTS
    assert document["groups"]["Arm"]["tip"] == "bucket_tip"
    assert document["joints"]["turret_joint"]["lower"] < -3.2 and document["joints"]["turret_joint"]["upper"] > 3.2
    for joint in JOINTS:
        assert 0.3 <= document["joints"][joint]["max_velocity"] <= 1.0
        assert document["joints"][joint]["source"]["acceleration"] == "joint_limits.yaml"
    assert set(document["named_states"]["Arm"]) == {"stowed", "ready", "dump"}
    assert document["controllers"]["excavation_controller"]["joints"] == JOINTS


def test_controller_commands_velocity_with_the_issues_constraints_and_per_joint_gains(robot: Robot) -> None:
    controller = robot.config.controllers["excavation_controller"]
    assert controller.update_rate_hz == 100
    assert controller.command_interfaces == ("velocity",)
    assert controller.state_interfaces == ("position", "velocity")
    assert controller.stopped_velocity_tolerance == 0.1 and controller.goal_time_s == 5.0
    for joint in ("shoulder_joint", "elbow_joint", "wrist_joint"):
        assert controller.trajectory_tolerance[joint] > 0 and controller.goal_tolerance[joint] > 0
    assert set(controller.gains) == set(JOINTS)
    assert all(gains["p"] > 0 and gains["ff_velocity_scale"] == 1.0 for gains in controller.gains.values())


def test_named_states_and_initial_positions_are_free_in_the_digging_site(robot: Robot,
                                                                         checker: CollisionChecker) -> None:
    states = robot.config.srdf.group_states["Arm"]
    for name, values in [*states.items(), ("initial_positions", robot.config.initial_positions)]:
        q = robot.configuration([values[j] for j in JOINTS])
        assert checker.colliding_pair(q) is None, name
    np.testing.assert_allclose([robot.config.initial_positions[j] for j in JOINTS],
                               [states["stowed"][j] for j in JOINTS])


def stowed(robot: Robot, turret: float) -> np.ndarray:
    """The stowed pose's joint values (the SRDF's, equal to the initial positions) at a turret angle."""
    values = robot.config.srdf.group_states["Arm"]["stowed"]
    return np.array([turret, *(values[j] for j in JOINTS[1:])])


def test_stowed_arm_clears_the_body_at_every_turret_angle_and_meets_only_the_deposition_bucket(
    robot: Robot, checker: CollisionChecker
) -> None:
    limit = robot.config.limits["turret_joint"]
    angles = np.linspace(limit.lower, limit.upper, 73)  # every 5.2 deg over the turret's range
    poses = robot.configurations(np.array([stowed(robot, a) for a in angles]))
    arm = ("turret_link", "boom_link", "stick_link", "bucket_link")
    body_only = CollisionChecker(robot, load_scene(SCENE, robot).objects,
                                 allowed=frozenset(frozenset(("deposition_bucket", link)) for link in arm))
    assert body_only.free_batch(poses).all()  # body, wheels, turret, the arm itself, the ground
    hits = {round(float(a), 3): checker.colliding_pair(robot.configuration(stowed(robot, a))) for a in angles}
    blocked = [a for a, pair in hits.items() if pair is not None]
    assert all(set(hits[a] or ()) == {"bucket_link", "deposition_bucket"} for a in blocked)
    # only on the way round, where the digging bucket would cut through the deposition bucket's
    # front corner and side wall: free ahead, to the sides and turned round (inside its opening)
    assert blocked and all(2.0 < abs(a) < 3.0 for a in blocked)
    for angle in (0.0, np.pi / 2, -np.pi / 2, np.pi, -np.pi, 3.2):
        assert checker.colliding_pair(robot.configuration(stowed(robot, angle))) is None, angle


def test_straight_slew_of_the_stowed_arm_to_3_2_rad_sweeps_the_bucket_through_the_deposition_bucket(
    robot: Robot, checker: CollisionChecker
) -> None:
    straight = np.linspace(stowed(robot, 0.0), stowed(robot, 3.2), 2001)
    free = checker.free_batch(robot.configurations(straight))
    assert free[0] and free[-1] and not free.all()
    hit = {checker.colliding_pair(robot.configuration(v)) for v in straight[~free]}
    assert hit and all(pair is not None and set(pair) == {"bucket_link", "deposition_bucket"} for pair in hit)


@pytest.mark.parametrize("seed", range(5))
def test_turret_to_3_2_rad_from_the_initial_state_goes_around_the_deposition_bucket_and_executes(
    cli: Cli, tmp_path: Path, robot: Robot, seed: int
) -> None:
    """The seed exercise as a user types it: no task file, no scene, start where the hardware is."""
    out = tmp_path / "slew.mcap"
    code, document = cli.json("plan", "--robot", EXCAVATOR, "--joints", "turret_joint=3.2", "-o", out,
                              "--seed", seed)
    assert code == 0, document
    plan = read_plan(out)
    initial = [robot.config.initial_positions[j] for j in JOINTS]
    np.testing.assert_allclose(plan.steps[0].trajectory.positions[0], initial, atol=1e-9)
    np.testing.assert_allclose(plan.steps[0].trajectory.positions[-1], stowed(robot, 3.2), atol=1e-9)
    path = dense(plan, "goal")
    assert CollisionChecker(robot).free_batch(robot.configurations(path)).all()
    # not the straight slew of the turret alone (that is in collision): the arm lifts the bucket
    assert np.abs(path[:, 1:] - path[0, 1:]).max() > 0.2
    code, document = cli.json("execute", out, "--fake", "--plant", "pid")
    assert code == 0 and document["result"]["name"] == "SUCCESSFUL", document["violations"]


def test_demo_sample_is_the_seed_exercise_around_the_deposition_bucket_and_executes_under_pid(
    cli: Cli, tmp_path: Path, robot: Robot, checker: CollisionChecker
) -> None:
    out = tmp_path / "demo.mcap"
    code, document = cli.json("plan", SAMPLES / "excavator_demo.yaml", "-o", out)
    assert code == 0, document
    plan = read_plan(out)
    trajectory = plan.steps[0].trajectory
    np.testing.assert_allclose(trajectory.positions[0], stowed(robot, 0.0), atol=1e-9)
    assert trajectory.positions[-1][0] == pytest.approx(3.2, abs=1e-9)
    np.testing.assert_allclose(trajectory.positions[-1][1:], trajectory.positions[0][1:], atol=1e-9)
    path = dense(plan, "slew")
    assert checker.free_batch(robot.configurations(path)).all()
    assert np.abs(path[:, 1:] - path[0, 1:]).max() > 0.2
    for drive in ([], REALISTIC_DRIVE):
        code, document = cli.json("execute", out, "--fake", "--plant", "pid", *drive)
        assert code == 0 and document["result"]["name"] == "SUCCESSFUL", document["violations"]
    code, document = cli.json("execute", out, "--fake", "--plant", "pid", "--controllers", MISTUNED)
    assert code == 5


def test_from_ready_the_slew_to_3_2_rad_is_one_straight_move_of_the_turret(cli: Cli, tmp_path: Path) -> None:
    """Ready holds the digging bucket high enough to pass over the deposition bucket."""
    out = tmp_path / "ready.mcap"
    code, document = cli.json("plan", SAMPLES / "excavator_demo.yaml", "--start-named", "ready", "-o", out)
    assert code == 0, document
    trajectory = read_plan(out).steps[0].trajectory
    assert trajectory.positions[-1][0] == pytest.approx(3.2, abs=1e-9)
    unchanged = trajectory.positions[:, 1:] - trajectory.positions[0, 1:]
    assert np.abs(unchanged).max() < 1e-9
    code, document = cli.json("execute", out, "--fake", "--plant", "pid")
    assert code == 0 and document["result"]["name"] == "SUCCESSFUL"


def test_dig_cycle_plans_every_step(dig: PlanFile) -> None:
    assert [s.name for s in dig.steps] == ["into_trench", "drag", "scoop", "to_dump", "dump", "back"]
    assert all(s.trajectory.duration_s > 0 for s in dig.steps)


def test_bucket_tip_digs_below_the_bodys_underside_and_the_ground(dig: PlanFile, robot: Robot) -> None:
    for step in ("into_trench", "drag"):
        end = next(s.trajectory for s in dig.steps if s.name == step).positions[-1]
        tip = robot.frame_pose(robot.configuration(end), "bucket_tip")[:3, 3]
        assert tip[2] < GROUND_Z < BODY_UNDERSIDE_Z
        assert tip[0] > 0.62  # in the trench in front of the rover


def test_drag_is_a_level_15_cm_pull_towards_the_rover(dig: PlanFile, robot: Robot) -> None:
    tips = np.array([robot.frame_pose(robot.configuration(q), "bucket_tip")[:3, 3] for q in dense(dig, "drag", 0.05)])
    np.testing.assert_allclose(tips[-1] - tips[0], [-0.15, 0.0, 0.0], atol=1e-4)
    assert np.abs(tips[:, 1:] - tips[0, 1:]).max() < 1e-3  # no sideways or vertical wander


def test_straight_move_from_dig_to_dump_hits_the_deposition_bucket_but_the_plan_goes_around(
    dig: PlanFile, robot: Robot, checker: CollisionChecker
) -> None:
    planned = dense(dig, "to_dump")
    start, goal = planned[0], planned[-1]
    assert goal[0] == pytest.approx(np.pi)  # turned round to the rear, over the deposition bucket
    straight = start + np.linspace(0.0, 1.0, 2001)[:, None] * (goal - start)
    free = checker.free_batch(robot.configurations(straight))
    hit = [checker.colliding_pair(robot.configuration(v)) for v in straight[~free]]
    assert hit and all(pair is not None and "deposition_bucket" in pair for pair in hit)
    for step in ("into_trench", "drag", "scoop", "to_dump", "dump", "back"):
        assert checker.free_batch(robot.configurations(dense(dig, step))).all(), step


def test_tuned_gains_track_the_dig_cycle_within_tolerances_under_the_pid_plant(cli: Cli, dig_file: Path) -> None:
    for drive in ([], REALISTIC_DRIVE):
        code, document = cli.json("execute", dig_file, "--fake", "--plant", "pid", *drive)
        assert code == 0, document["violations"]
        assert document["violations"] == [] and len(document["steps"]) == 6
        assert all(margin > 0 for margin in document["margins"].values())


def test_mistuned_gains_fail_the_same_plan_with_a_path_violation_naming_a_joint(cli: Cli, dig_file: Path) -> None:
    code, document = cli.json("execute", dig_file, "--fake", "--plant", "pid", "--controllers", MISTUNED)
    assert code == 5
    assert document["result"]["name"] == "PATH_TOLERANCE_VIOLATED"
    violation = document["violations"][0]
    assert violation["check"] == "path" and violation["joint"] in JOINTS and violation["step"] == "into_trench"
    assert abs(violation["error"]) > violation["tolerance"]
    assert document["margins"][violation["joint"]] < 0


def test_mistuned_gains_on_a_slower_drive_never_settle_and_fail_the_goal_tolerance(cli: Cli, dig_file: Path) -> None:
    # The slow drive alone: the config's hydraulic lag and droop make the same gains fail sooner, on the path.
    ideal = ["--plant-param", "drive_tau=0", "--plant-param", "load=0", "--plant-param", "noise=0"]
    code, document = cli.json("execute", dig_file, "--fake", "--plant", "pid", "--controllers", MISTUNED,
                              *REALISTIC_DRIVE, *ideal)
    assert code == 5
    assert document["result"]["name"] == "GOAL_TOLERANCE_VIOLATED"
    goal = [v for v in document["violations"] if v["check"] == "goal"]
    assert goal and goal[0]["joint"] in JOINTS and abs(goal[0]["error"]) > goal[0]["tolerance"]


def test_the_excavators_hydraulic_plant_shows_the_pid_effect_by_default(
        cli: Cli, dig_file: Path, tmp_path: Path) -> None:
    """configs/excavator's `plant`: with the shipped gains every motion tracks; with zero gains the droop and
    the drive's lag take a joint out of its path tolerance; tune-pid from zero raises P, then D."""
    import yaml

    code, document = cli.json("execute", dig_file, "--fake")
    assert code == 0, document["violations"]
    controllers = yaml.safe_load((ROOT / "configs" / "excavator" / "ros2_controllers.yaml").read_text())
    for gains in controllers["excavation_controller"]["ros__parameters"]["gains"].values():
        gains.update(p=0.0, i=0.0, d=0.0)
    zero = tmp_path / "zero.yaml"
    zero.write_text(yaml.safe_dump(controllers))
    code, document = cli.json("execute", dig_file, "--fake", "--controllers", zero)
    assert code == 5 and document["result"]["name"] == "PATH_TOLERANCE_VIOLATED"
    code, tuned = cli.json("tune-pid", dig_file, "--controllers", zero, "-o", tmp_path / "tuned.yaml")
    assert code == 0 and tuned["verification"]["ok"] is True
    assert tuned["plant"]["drive_tau"] == 0.06  # the config's plant
    for joint in tuned["joints"].values():
        stages = [s for s in joint["stages"] if s["stage"] in ("P", "D") and s["chosen"]]
        assert [s["stage"] for s in stages] == ["P", "D"]
        assert stages[0]["gains"]["p"] > 0 and stages[1]["gains"]["d"] > 0


@pytest.mark.parametrize("lag", [0.02, 0.15])
def test_tune_pid_gains_pass_their_own_verification_on_slow_and_fast_drives(
        cli: Cli, dig_file: Path, tmp_path: Path, lag: float) -> None:
    """From zero gains, on drives lagging 20 to 150 ms under the excavator's droop: P, then D, verified."""
    import yaml

    controllers = yaml.safe_load((ROOT / "configs" / "excavator" / "ros2_controllers.yaml").read_text())
    for gains in controllers["excavation_controller"]["ros__parameters"]["gains"].values():
        gains.update(p=0.0, i=0.0, d=0.0)
    zero = tmp_path / "zero.yaml"
    zero.write_text(yaml.safe_dump(controllers))
    code, tuned = cli.json("tune-pid", dig_file, "--controllers", zero, "--plant-param", f"drive_tau={lag}",
                           "-o", tmp_path / "tuned.yaml")
    assert code == 0 and tuned["verification"]["result"]["name"] == "SUCCESSFUL", tuned["verification"]["result"]
