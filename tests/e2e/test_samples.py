"""The MoveIt workshop exercises as shipped samples: each plans, and its geometry is what was asked."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import SAMPLES, Cli

from moveplan.core.bag import PlanFile, read_plan
from moveplan.core.model.robot import Robot
from moveplan.core.trajectory import sample

WORKSHOP = {
    "target_1": (np.array([0.6, 0.2, 0.4]), np.diag([1.0, -1.0, -1.0])),
    "target_2": (np.array([0.7, -0.2, 0.3]), np.array([[np.cos(0.7330383), 0, np.sin(0.7330383)], [0, 1, 0],
                                                       [-np.sin(0.7330383), 0, np.cos(0.7330383)]])),
    "object": (np.array([0.6, -0.4, 0.1]), np.eye(3)),
}
DOWN = np.diag([1.0, -1.0, -1.0])  # tool z pointing down (rpy pi, 0, 0)


@pytest.fixture(scope="module")
def plans(tmp_path_factory: pytest.TempPathFactory) -> dict[str, PlanFile]:
    folder = tmp_path_factory.mktemp("samples")
    result = {}
    for task in ("ur10e_tool_up", "ur10e_to_target", "ur10e_tilted_approach", "ur10e_tool_x_shift",
                 "ur10e_pick_and_place"):
        out = folder / f"{task}.mcap"
        run = Cli()("plan", SAMPLES / f"{task}.yaml", "-o", out)
        assert run.exit_code == 0, f"{task}: {run.stderr}"
        result[task] = read_plan(out)
    return result


def tip(robot: Robot, values: np.ndarray) -> np.ndarray:
    return robot.frame_pose(robot.configuration(values), "tool0")


def assert_on_line(robot: Robot, plan: PlanFile, step: int, tolerance_m: float = 0.001) -> None:
    trajectory = plan.steps[step].trajectory
    start, end = tip(robot, trajectory.positions[0])[:3, 3], tip(robot, trajectory.positions[-1])[:3, 3]
    direction = (end - start) / np.linalg.norm(end - start)
    positions, _, _ = sample(trajectory, np.linspace(0, trajectory.duration_s, 200))
    for values in positions:
        offset = tip(robot, values)[:3, 3] - start
        assert np.linalg.norm(offset - direction * (offset @ direction)) < tolerance_m


def test_tool_up_moves_10_cm_along_base_z_in_a_straight_line(plans: dict[str, PlanFile], ur10e: Robot) -> None:
    trajectory = plans["ur10e_tool_up"].steps[0].trajectory
    before, after = tip(ur10e, trajectory.positions[0]), tip(ur10e, trajectory.positions[-1])
    np.testing.assert_allclose(after[:3, 3] - before[:3, 3], [0, 0, 0.1], atol=1e-4)
    np.testing.assert_allclose(after[:3, :3], before[:3, :3], atol=1e-3)
    assert_on_line(ur10e, plans["ur10e_tool_up"], 0)


def test_to_target_reaches_the_static_frame(plans: dict[str, PlanFile], ur10e: Robot) -> None:
    reached = tip(ur10e, plans["ur10e_to_target"].steps[0].trajectory.positions[-1])
    position, rotation = WORKSHOP["target_1"]
    np.testing.assert_allclose(reached[:3, 3], position, atol=1e-4)
    np.testing.assert_allclose(reached[:3, :3], rotation, atol=1e-3)


def test_tilted_approach_puts_the_tip_on_the_targets_own_z_axis(plans: dict[str, PlanFile], ur10e: Robot) -> None:
    reached = tip(ur10e, plans["ur10e_tilted_approach"].steps[0].trajectory.positions[-1])
    position, rotation = WORKSHOP["target_2"]
    z_axis = rotation[:, 2]
    np.testing.assert_allclose(reached[:3, 3], position + 0.1 * z_axis, atol=1e-4)
    np.testing.assert_allclose(reached[:3, 2], -z_axis, atol=1e-3)  # the tool points at the target


def test_tool_x_shift_moves_along_the_tools_own_x_axis(plans: dict[str, PlanFile], ur10e: Robot) -> None:
    trajectory = plans["ur10e_tool_x_shift"].steps[0].trajectory
    before, after = tip(ur10e, trajectory.positions[0]), tip(ur10e, trajectory.positions[-1])
    np.testing.assert_allclose(after[:3, 3], before[:3, 3] + 0.1 * before[:3, 0], atol=1e-4)
    assert_on_line(ur10e, plans["ur10e_tool_x_shift"], 0)


def test_pick_and_place_tip_ends_where_each_step_asks(plans: dict[str, PlanFile], ur10e: Robot) -> None:
    plan = plans["ur10e_pick_and_place"]
    assert [s.name for s in plan.steps] == ["approach", "reach", "push", "lift", "home"]
    obj = WORKSHOP["object"][0]
    expected = {"approach": obj + [0, 0, 0.15], "reach": obj, "push": obj - [0, 0, 0.005], "lift": obj + [0, 0, 0.2]}
    for step in plan.steps[:4]:
        reached = tip(ur10e, step.trajectory.positions[-1])
        np.testing.assert_allclose(reached[:3, 3], expected[step.name], atol=1e-3)
        np.testing.assert_allclose(reached[:3, :3], DOWN, atol=1e-3)
    np.testing.assert_allclose(plan.steps[-1].trajectory.positions[-1], [0, -np.pi / 2, -np.pi / 2, 0, 0, 0],
                               atol=1e-9)
    for index in (1, 2, 3):
        assert_on_line(ur10e, plan, index)


def test_pose_flag_in_a_scene_frame_matches_the_task(cli: Cli, tmp_path: Path, ur10e: Robot) -> None:
    out = tmp_path / "p.mcap"
    result = cli("plan", "--robot", SAMPLES.parent / "configs/ur10e", "--scene", SAMPLES / "ur10e_workshop_scene.yaml",
                 "--start-named", "ready", "--pose", "0,0,0.15,pi,0,0", "--frame", "object", "-o", out)
    assert result.exit_code == 0, result.stderr
    reached = tip(ur10e, read_plan(out).steps[0].trajectory.positions[-1])
    np.testing.assert_allclose(reached[:3, 3], WORKSHOP["object"][0] + [0, 0, 0.15], atol=1e-4)


def test_pose_goal_solution_is_nearest_to_start(cli: Cli, tmp_path: Path, ur10e: Robot) -> None:
    ready = np.array([0, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0])
    here = tip(ur10e, ready)[:3, 3]
    out = tmp_path / "p.mcap"
    result = cli("plan", "--robot", SAMPLES.parent / "configs/ur10e", "--start-named", "ready",
                 "--pose", ",".join(map(str, here + [0.05, 0.0, -0.05])) + ",pi,0,-pi/2", "-o", out)
    assert result.exit_code == 0, result.stderr
    end = read_plan(out).steps[0].trajectory.positions[-1]
    assert np.max(np.abs(end - ready)) < 0.5  # no wrist or elbow flip for a 7 cm move


def test_moveit_shift_frame_reproduces_shift_pose_target(cli: Cli, tmp_path: Path, ur10e: Robot) -> None:
    import pinocchio as pin

    out = tmp_path / "p.mcap"
    result = cli("plan", "--robot", SAMPLES.parent / "configs/ur10e", "--start-named", "ready",
                 "--shift", "x=0.05,yaw=0.3", "--shift-frame", "moveit", "-o", out)
    assert result.exit_code == 0, result.stderr
    trajectory = read_plan(out).steps[0].trajectory
    before, after = tip(ur10e, trajectory.positions[0]), tip(ur10e, trajectory.positions[-1])
    expected = before[:3, 3] + [0.05, 0, 0]
    rpy = pin.rpy.matrixToRpy(before[:3, :3]) + [0, 0, 0.3]
    np.testing.assert_allclose(after[:3, 3], expected, atol=1e-4)
    np.testing.assert_allclose(after[:3, :3], pin.rpy.rpyToMatrix(*rpy), atol=1e-3)


BAD_POSES = [
    (["--pose", "0,0"], 2, "x,y,z"),
    (["--pose", "0.5,0,0.5,0,0,0,0"], 2, "zero norm"),
    (["--pose", "0.5,0,nan"], 2, "expected a number"),
    (["--pose", "0,0,0.1", "--frame", "tol0"], 3, "known: base"),
    (["--pose", "3,0,0.5"], 4, "closest"),
    (["--shift", "q=1"], 2, "axis=value"),
    (["--frame", "object", "--named", "home"], 2, "--frame goes with --pose"),
]


@pytest.mark.parametrize(("args", "code", "message"), BAD_POSES)
def test_bad_pose_input_exits_with_code_and_one_line(
    cli: Cli, tmp_path: Path, args: list[str], code: int, message: str
) -> None:
    out = tmp_path / "o.mcap"
    result = cli("plan", "--robot", SAMPLES.parent / "configs/ur10e", "--scene",
                 SAMPLES / "ur10e_workshop_scene.yaml", "--start-named", "ready", *args, "-o", out)
    assert result.exit_code == code, result.stderr
    assert message in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_straight_line_blocked_by_an_obstacle_reports_fraction_pair_and_where(cli: Cli, tmp_path: Path) -> None:
    scene = tmp_path / "wall.yaml"
    scene.write_text("objects:\n  - {name: wall, frame: base_link, box: [0.6, 0.6, 0.02], xyz: [0.69, 0.17, 0.58]}\n")
    out = tmp_path / "o.mcap"
    code, document = cli.json("plan", "--robot", SAMPLES.parent / "configs/ur10e", "--scene", scene,
                              "--start-named", "ready", "--shift", "z=-0.2", "--shift-frame", "base", "--linear",
                              "-o", out)
    assert code == 4
    message = document["error"]["message"]
    assert "straight line achieved" in message and "wall" in message and "stopped at" in message
    assert not out.exists()


def test_zero_quaternion_in_a_task_is_a_file_error(cli: Cli, tmp_path: Path) -> None:
    task = tmp_path / "t.yaml"
    task.write_text(f"robot: {SAMPLES.parent / 'configs/ur10e'}\nsteps:\n"
                    "  - {name: a, pose: {xyz: [0.5, 0, 0.5], quat: [0, 0, 0, 0]}}\n")
    result = cli("plan", task, "-o", tmp_path / "o.mcap")
    assert result.exit_code == 3
    assert "t.yaml" in result.stderr and "zero norm" in result.stderr
