"""One error hierarchy: exit codes by kind, collision errors under one base, the step an error happened in."""

from __future__ import annotations

import inspect

import pytest

from moveplan.core import errors
from moveplan.core.errors import (
    ConfigError,
    CorruptData,
    GoalInCollision,
    InCollision,
    InputError,
    MoveplanError,
    NoPlan,
    PlanningFailed,
    StartInCollision,
    UnknownName,
    UnsupportedJoint,
)


def test_every_error_class_is_a_moveplan_error_with_a_documented_exit_code() -> None:
    classes = [value for value in vars(errors).values() if inspect.isclass(value) and issubclass(value, Exception)]
    assert {c.__name__ for c in classes} >= {"CorruptData", "UnsupportedJoint", "InCollision"}
    for cls in classes:
        assert issubclass(cls, MoveplanError), cls
        assert cls.exit_code in (1, 2, 3, 4), cls


def test_errors_raised_outside_the_hierarchy_before_are_bad_input_now() -> None:
    for cls in (CorruptData, UnsupportedJoint):
        assert issubclass(cls, InputError) and not issubclass(cls, ValueError)
        assert cls("x").exit_code == 3


def test_start_and_goal_collisions_share_a_base_but_do_not_catch_each_other() -> None:
    goal, start = GoalInCollision(("a", "b")), StartInCollision(("c", "d"))
    assert isinstance(goal, InCollision) and isinstance(start, InCollision) and isinstance(goal, NoPlan)
    assert not isinstance(goal, StartInCollision) and not isinstance(start, GoalInCollision)
    assert str(goal) == "goal state is in collision: a touches b" and goal.where == "goal state"
    assert str(StartInCollision(("c", "d"), where="every state")).startswith("every state is in collision")
    assert start.pair == ("c", "d")


def test_an_error_marked_with_its_step_names_it_in_front_of_the_message() -> None:
    error = UnknownName("named state", "nope", "group 'arm'", ["home"])
    assert error.step is None and str(error).startswith("named state 'nope'")
    assert error.in_step("approach") is error
    assert error.step == "approach"
    assert str(error) == "step 'approach': named state 'nope' not found in group 'arm'; known: home"
    assert error.in_step("other").step == "approach"


def test_a_step_marked_error_keeps_its_kind_and_exit_code() -> None:
    with pytest.raises(PlanningFailed, match="^step 'lift': no path$") as caught:
        raise PlanningFailed("no path").in_step("lift")
    assert caught.value.kind == "PlanningFailed" and caught.value.exit_code == 4
    assert ConfigError("bad").in_step("s").exit_code == 3
