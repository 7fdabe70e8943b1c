"""What a person reads off a plot at a glance: panels scaled to what they show, limits as planned, names apart.

The figures are built from a real plan and from executions drawn as execute and
check-tolerances draw them, then rendered with matplotlib's Agg canvas to measure text.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import SAMPLES, Cli
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.text import Text

from moveplan.core.bag import read_plan
from moveplan.core.pipeline.plots._plan import plan_curves, plan_figure
from moveplan.core.pipeline.plots._tracking import TrackedStep, Tracking, ViolationMark, tracking_figure

JOINTS = ("shoulder_pan_joint", "elbow_joint")


@pytest.fixture(scope="module")
def pick_and_place(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Return the pick-and-place plan: five steps, two of them (push, lift) a tenth of a second apart."""
    path = tmp_path_factory.mktemp("pick") / "pick.mcap"
    assert Cli()("plan", SAMPLES / "ur10e_pick_and_place.yaml", "-o", path, "-q").exit_code == 0
    return path


def _texts(axis: Any) -> list[str]:
    return [text.get_text() for text in axis.texts]


def _note(axis: Any) -> str:
    return next(text for text in _texts(axis) if text.startswith("largest |error|"))


def test_step_names_of_steps_closer_than_a_name_do_not_overlap(pick_and_place: Path) -> None:
    figure = plan_figure(plan_curves(read_plan(pick_and_place), pick_and_place))
    canvas = FigureCanvasAgg(figure)
    canvas.draw()  # places the names
    renderer = canvas.get_renderer()
    names = [text for text in figure.axes[0].texts if text.get_rotation() == 90]
    assert [n.get_text() for n in names] == ["approach", "reach", "push", "lift", "home"]
    boxes = [Text.get_window_extent(n, renderer) for n in names]  # the name alone, without its tie to the line
    assert not any(a.overlaps(b) for a, b in itertools.combinations(boxes, 2))


def test_velocity_and_acceleration_are_drawn_against_the_limits_as_planned(pick_and_place: Path) -> None:
    plan = read_plan(pick_and_place)
    scaling = [step.scaling for step in plan.steps]
    assert scaling == [(0.5, 0.5)] * 5  # the task's velocity_scaling and acceleration_scaling
    figure = plan_figure(plan_curves(plan, pick_and_place))
    axes = np.array(figure.axes).reshape(-1, 3)
    for row, joint in enumerate(plan.steps[0].trajectory.joint_names):
        for column, key in ((1, "max_velocity"), (2, "max_acceleration")):
            planned = next(c for c in axes[row, column].collections if isinstance(c, LineCollection))
            levels = {round(float(segment[0][1]), 9) for segment in planned.get_segments()}
            limit = plan.limits[joint][key]
            assert levels == {round(0.5 * limit, 9), round(-0.5 * limit, 9)}
            assert axes[row, column].get_ylim()[1] >= 0.5 * limit


def test_position_panels_span_the_motion_and_name_limits_far_outside_it(pick_and_place: Path) -> None:
    plan = read_plan(pick_and_place)
    figure = plan_figure(plan_curves(plan, pick_and_place))
    pan = figure.axes[0]  # shoulder_pan_joint: 0.83 rad of travel within limits of +-2 pi
    low, high = pan.get_ylim()
    assert high - low < 1.0
    assert any("-6.28 and 6.28 rad: off-scale" in text for text in _texts(pan))


def test_a_plan_without_recorded_scaling_draws_the_joint_limits() -> None:
    """A plan file of an earlier moveplan has no step_scaling: its limits are drawn as the joint's."""
    path = SAMPLES / "recordings" / "tool_up_plan.mcap"
    plan = read_plan(path)
    assert [step.scaling for step in plan.steps] == [None]
    figure = plan_figure(plan_curves(plan, path))
    labels = [text.get_text() for text in figure.legends[0].get_texts()]
    assert "joint limits" in labels and not any("as planned" in label for label in labels)


def _tracking(error: float, path: float = 0.2, goal: float = 0.1, marks: tuple[ViolationMark, ...] = ()) -> Tracking:
    """Return one 1 s step of two joints whose error swings up to `error` [rad], under these tolerances."""
    times = np.linspace(0.0, 1.0, 201)
    swing = error * np.sin(2 * np.pi * 3 * times)[:, None] * np.ones((1, 2))
    reference = np.outer(times, (0.5, -0.3))
    step = TrackedStep("up", 0.0, 0.95, 1.0, times, reference, reference - swing, swing, swing, swing, marks)
    return Tracking("test", JOINTS, ("rad", "rad"), (step,), np.array([path, path]), np.array([goal, goal]), 1.0,
                    0.002)


def _error_panel(figure: Any, row: int) -> Any:
    return figure.axes[3 * row + 1]


def test_a_passing_run_draws_its_errors_to_their_scale_and_names_the_tolerance_off_scale() -> None:
    figure = tracking_figure(_tracking(4e-6))
    error = _error_panel(figure, 0)
    assert error.get_ylabel() == "[µrad]"
    low, high = error.get_ylim()
    assert 4.0 < high < 8.0 and low == -high  # the swing fills most of the panel, in µrad
    note = _note(error)
    assert "largest |error| 4e-06 rad" in note and "path ±0.2 (off-scale), goal ±0.1 (off-scale)" in note


def test_an_error_near_its_tolerance_draws_the_tolerance_to_scale() -> None:
    mark = ViolationMark(0.4, "elbow_joint", "path", -0.5, 0.21)
    figure = tracking_figure(_tracking(0.15, marks=(mark,)))
    error = _error_panel(figure, 1)
    assert error.get_ylabel() == "[rad]"
    assert error.get_ylim()[1] >= 0.21  # the violation and the path tolerance are in the panel
    assert "(off-scale)" not in _note(error)


def test_rounding_error_reads_as_nanoradians_not_as_an_exponent() -> None:
    figure = tracking_figure(_tracking(1e-13))
    error = _error_panel(figure, 0)
    assert error.get_ylabel() == "[nrad]"
    assert error.get_ylim()[1] == pytest.approx(1.15)


def test_unchecked_tolerances_are_said_in_the_note() -> None:
    figure = tracking_figure(_tracking(0.01, path=0.0, goal=0.0))
    assert "path 0: not checked, goal 0: not checked" in _note(_error_panel(figure, 0))
