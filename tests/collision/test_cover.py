"""The clearances of a motion's states must cover the motion between them: graze found, near miss passed, a bound.

A robot point moving along a line (travel = its position [m]) past an obstacle point: the distance
at each state is known exactly, so the states the cover walk adds and its verdict can be checked.
"""

from __future__ import annotations

import numpy as np
import pytest

from moveplan.core.collision import _cover as cover
from moveplan.core.collision._certify import MAX_STATES
from moveplan.core.collision.checker import CONTACT_M
from moveplan.core.errors import InputError

STEP_M = 0.005


class _Line:
    """A point moving along x past an obstacle `clearance` [m] from its path at x = `at` (negative: into it)."""

    def __init__(self, clearance: float, at: float = 0.5012345) -> None:
        self.clearance, self.at = clearance, at
        self.judged = 0

    def distance(self, travel: np.ndarray) -> np.ndarray:
        return np.asarray(np.hypot(travel - self.at, 0.01 + self.clearance) - 0.01)

    def judge(self, states: np.ndarray, travel: np.ndarray, margin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self.judged += len(states)
        distance = self.distance(states[:, 0])
        free = distance > CONTACT_M
        return free, np.where(free, CONTACT_M, 0.0)  # as coal answers: free, and 1 um apart

    def within(self, states: np.ndarray, margin: np.ndarray) -> np.ndarray:
        return np.asarray(self.distance(states[:, 0]) >= margin)


def _walk(line: _Line, length: float = 1.0) -> np.ndarray | None:
    travel = np.linspace(0.0, length, int(np.ceil(length / STEP_M)) + 1)
    states = travel[:, None]
    free, radius = line.judge(states, travel, np.zeros(len(states)))
    assert free.all(), "the states themselves are clear: only what lies between them can collide"
    return cover.uncovered_collision(states, travel, radius, lambda t: np.asarray(t)[:, None], line.judge, line.within)


def test_a_graze_between_two_states_is_found_and_the_state_returned_collides() -> None:
    line = _Line(-20e-6)
    hit = _walk(line)
    assert hit is not None and line.distance(hit)[0] <= CONTACT_M
    assert line.judged < 250 + 201  # the states, and a few dozen more near the grain


def test_a_near_miss_of_twenty_micrometres_is_certified_free() -> None:
    assert _walk(_Line(20e-6)) is None


def test_shapes_that_touch_between_two_states_count_as_colliding() -> None:
    assert _walk(_Line(0.0)) is not None


def test_a_motion_far_from_everything_adds_no_state() -> None:
    line = _Line(0.05)
    assert _walk(line) is None
    assert line.judged == 201


def test_a_motion_that_would_need_more_than_max_states_is_refused() -> None:
    line = _Line(0.0)
    line.distance = lambda travel: np.full(len(travel), 1.5 * CONTACT_M)  # type: ignore[method-assign]
    # 1.5 um from a surface for a kilometre: states 3 um apart, hundreds of millions of them.
    length = 1_000.0
    assert length / (3 * CONTACT_M) > MAX_STATES
    with pytest.raises(InputError, match="more than moveplan's 2,000,000 collision checks"):
        _walk(line, length)
