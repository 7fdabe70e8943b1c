"""Joint-space search: bounded by work, seeded, RRTConnect's fallback, and a crossed thin obstacle repaired."""

from __future__ import annotations

import time

import numpy as np
import pytest

from moveplan.core.errors import PlanningFailed, PlanningTimeExceeded
from moveplan.core.planning import search as planning
from moveplan.core.planning.search import Validity, plan_path, repair_path
from moveplan.core.trajectory import interpolate

LOWER, UPPER = np.array([-1.0, -1.0]), np.array([2.0, 2.0])


@pytest.fixture(autouse=True)
def _seeded() -> None:
    """Seed every search: unseeded, a test draws whatever the tests before it left in OMPL's generator."""
    planning.seed_planner(0)


def _wall(resolution: float) -> Validity:
    """Return checks in a plane with a wall 1 cm thick at x = 0.51, open above y = 0.8."""

    def state_free(q: np.ndarray) -> bool:
        return not (0.51 <= q[0] <= 0.52 and q[1] < 0.8)

    def edge_free(a: np.ndarray, b: np.ndarray) -> bool:
        return all(state_free(q) for q in interpolate(a, b, resolution)[1:])

    return Validity(state_free, edge_free)


def test_only_the_segment_through_the_wall_is_planned_again() -> None:
    waypoints = np.array([[0.0, 0.0], [0.3, 0.1], [1.0, 0.0]])
    coarse, fine = _wall(0.05), _wall(0.005)
    assert all(coarse.edge_free(a, b) for a, b in zip(waypoints[:-1], waypoints[1:], strict=True))

    repaired = repair_path(waypoints, LOWER, UPPER, fine, "RRTConnect", 1.0).waypoints

    np.testing.assert_array_equal(repaired[:2], waypoints[:2])
    np.testing.assert_array_equal(repaired[-1], waypoints[-1])
    assert len(repaired) > 3
    assert all(fine.edge_free(a, b) for a, b in zip(repaired[:-1], repaired[1:], strict=True))


def test_a_waypoint_inside_the_wall_cannot_be_repaired() -> None:
    waypoints = np.array([[0.0, 0.0], [0.515, 0.0], [1.0, 0.0]])
    with pytest.raises(PlanningFailed, match="waypoint"):
        repair_path(waypoints, LOWER, UPPER, _wall(0.005), "RRTConnect", 1.0)


def test_rrtconnect_hands_what_it_has_not_solved_to_its_fallback(monkeypatch: pytest.MonkeyPatch) -> None:
    def free(q: np.ndarray) -> bool:  # a wall at x = 0 with a gap at |y| < 0.1
        return bool(abs(q[0]) > 0.05 or abs(q[1]) < 0.1)

    def edge(a: np.ndarray, b: np.ndarray) -> bool:
        return all(free(q) for q in interpolate(a, b, 0.01))

    validity = Validity(free, edge)
    start, goal = np.array([-0.5, 0.8]), np.array([0.5, 0.8])
    lower, upper = np.array([-1.0, -1.0]), np.array([1.0, 1.0])
    monkeypatch.setattr(planning, "_FALLBACK_AFTER", 1e-6)  # RRTConnect stops at once, unsolved
    path = plan_path(start, goal, lower, upper, validity, "RRTConnect", 1.0)
    assert path.planner == "RRTConnect+LBKPIECE1"
    np.testing.assert_array_equal(path.waypoints[[0, -1]], [start, goal])
    assert all(edge(a, b) for a, b in zip(path.waypoints[:-1], path.waypoints[1:], strict=True))
    monkeypatch.setattr(planning, "_FALLBACK", {})
    with pytest.raises(PlanningFailed):
        plan_path(start, goal, lower, upper, validity, "RRTConnect", 0.0)


def _boxed_in(delay_s: float = 0.0) -> Validity:
    """Return checks with the goal (0.5, 0.5) walled in; each check takes at least `delay_s`."""

    def free(q: np.ndarray) -> bool:
        time.sleep(delay_s)
        distance = np.max(np.abs(np.atleast_2d(q) - 0.5), axis=1)
        return bool(((distance < 0.3) | (distance > 0.35)).all())

    return Validity(free, lambda a, b: free(interpolate(a, b, 0.01)[1:]))


def test_a_search_stops_after_its_budget_of_checked_motions(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(planning, "_CHECKS_PER_S", 2000)  # 100 checks: well within the clock's cap
    with pytest.raises(PlanningFailed, match="found no path within 100 checked motions"):
        plan_path(np.array([-0.5, -0.5]), np.array([0.5, 0.5]), LOWER, UPPER, _boxed_in(), "RRTConnect", 0.05)


def test_a_slow_search_stops_at_the_wall_clock_safety_limit_and_says_so() -> None:
    limit = r"timed out: 0.05 s of wall time passed after \d+ of its 20000 checked motions \(1 s of planning time\)"
    with pytest.raises(PlanningTimeExceeded, match=limit):
        plan_path(np.array([-0.5, -0.5]), np.array([0.5, 0.5]), LOWER, UPPER, _boxed_in(0.002), "RRTConnect", 1.0,
                  timeout_s=0.05)


def test_a_slow_search_spends_its_whole_budget_past_its_planning_time_in_wall_time() -> None:
    # 0.05 s of planning time is 1000 checked motions, whatever they cost: the clock does not cut the search.
    with pytest.raises(PlanningFailed, match="found no path within 1000 checked motions") as failed:
        plan_path(np.array([-0.5, -0.5]), np.array([0.5, 0.5]), LOWER, UPPER, _boxed_in(0.0002), "RRTConnect", 0.05)
    assert not isinstance(failed.value, PlanningTimeExceeded)


def test_the_same_seed_gives_the_same_path_whatever_ran_before() -> None:
    start, goal = np.array([0.0, 0.0]), np.array([1.0, 0.0])
    paths = []
    for seed in (3, 4, 3):
        planning.seed_planner(seed)
        paths.append(plan_path(start, goal, LOWER, UPPER, _wall(0.005), "RRTConnect", 1.0))
    np.testing.assert_array_equal(paths[0].waypoints, paths[2].waypoints)
    assert paths[0].checks == paths[2].checks > 1
    assert not np.array_equal(paths[0].waypoints, paths[1].waypoints)


def test_the_planners_known_without_ompl_are_the_ompl_packages_own() -> None:
    from ompl import base as ob
    from ompl import geometric as og

    found = {name for name in dir(og)
             if name[0].isupper() and isinstance(getattr(og, name), type) and issubclass(getattr(og, name), ob.Planner)}
    assert set(planning.PLANNERS) == found
