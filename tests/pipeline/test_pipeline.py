"""What the plan pipeline guarantees beyond one command: last-resort timing stays on the path; errors name steps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import UR10E, dense_peaks

from moveplan.core.config.tasks import load_task
from moveplan.core.errors import ConfigError, GoalOutsideLimits, GoalUnreachable, MoveplanError, UnknownName
from moveplan.core.pipeline.plan import PlanFlags, plan, resolve_request
from moveplan.core.timing import rest_to_rest
from moveplan.core.trajectory import sample


def test_rest_to_rest_timing_keeps_every_joint_on_the_checked_segments() -> None:
    waypoints = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [1.0, 1.0, 1.0], [0.2, 1.0, 1.0]])
    limits_v, limits_a = np.array([1.0, 1.0, 1.0]), np.array([2.0, 2.0, 2.0])
    trajectory = rest_to_rest(("a", "b", "c"), waypoints, limits_v, limits_a)
    positions, _, _ = sample(trajectory, np.linspace(0.0, trajectory.duration_s, 5000))

    def distance_to_path(q: np.ndarray) -> float:
        best = np.inf
        for a, b in zip(waypoints[:-1], waypoints[1:], strict=True):
            s = np.clip((q - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
            best = min(best, float(np.linalg.norm(q - (a + s * (b - a)))))
        return best

    assert max(distance_to_path(q) for q in positions) < 1e-12
    peak_v, peak_a = dense_peaks(trajectory)
    assert np.all(peak_v <= limits_v) and np.all(peak_a <= limits_a)
    np.testing.assert_allclose(trajectory.positions[[0, -1]], waypoints[[0, -1]], atol=1e-12)
    assert np.all(np.diff(trajectory.times_s) > 0)


def step_error(tmp_path: Path, steps: str) -> MoveplanError:
    task = tmp_path / "task.yaml"
    task.write_text(f"robot: {UR10E}\nstart: {{named: home}}\nsteps:\n{steps}")
    with pytest.raises(MoveplanError) as caught:
        plan(resolve_request(load_task(task), PlanFlags()))
    return caught.value


@pytest.mark.parametrize(("steps", "kind", "message"), [
    ("  - {name: first, named: ready}\n  - {name: second, named: nope}\n", UnknownName, "named state 'nope'"),
    ("  - {name: bent, joints: {elbow_joint: 4}}\n", GoalOutsideLimits, "goal for joint 'elbow_joint'"),
    ("  - {name: short, joints: [0, 0]}\n", ConfigError, "joint goal has 2 values"),
    ("  - {name: far, pose: {xyz: [5, 0, 0]}}\n", GoalUnreachable, ""),
])
def test_any_error_while_planning_a_step_names_the_step(
    tmp_path: Path, steps: str, kind: type[MoveplanError], message: str
) -> None:
    error = step_error(tmp_path, steps)
    name = steps.rsplit("name: ", 1)[1].split(",")[0]
    assert isinstance(error, kind) and error.step == name
    assert str(error).startswith(f"step '{name}': ") and message in str(error)


def test_an_error_before_the_first_step_names_no_step(tmp_path: Path) -> None:
    with pytest.raises(UnknownName) as caught:
        plan(resolve_request(None, PlanFlags(robot=UR10E, start_named="nope", named="home")))
    assert caught.value.step is None
