"""Distance tables of link pairs: a pair they call apart never touches, and they are cached per robot."""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin
import pytest
from conftest import UR10E

from moveplan.core.collision import _pair_tables as pair_tables
from moveplan.core.collision._kernels import tabled
from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.collision.sphere_filter import CLEAR, COLLIDES, _table_arrays
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot


@pytest.fixture(scope="module")
def ur10e() -> tuple[Robot, pin.GeometryModel]:
    robot = Robot(load_robot_config(UR10E))
    return robot, CollisionChecker(robot, geometry="convex").robot_geometry


def test_a_pair_the_table_calls_apart_is_apart_one_it_calls_touching_touches_and_distant_ones_are_apart(
    ur10e: tuple[Robot, pin.GeometryModel]
) -> None:
    robot, hulls = ur10e
    tables = pair_tables.pair_tables(robot.model, hulls, robot.config.srdf.disabled_pairs, robot.config.urdf)
    assert {frozenset((t.upper, t.lower)) for t in tables} >= {frozenset(("forearm_link", "wrist_2_link"))}
    model = robot.model
    data = model.createData()
    for table in tables:
        pair = pin.GeometryModel()
        ids: dict[str, list[int]] = {table.upper: [], table.lower: []}
        for obj in hulls.geometryObjects:
            owner = str(model.frames[obj.parentFrame].name)
            if owner in ids:
                ids[owner].append(pair.addGeometryObject(obj.copy()))
        for i in ids[table.upper]:
            for j in ids[table.lower]:
                pair.addCollisionPair(pin.CollisionPair(i, j))
        pair_data = pair.createData()
        arrays = tuple(_table_arrays([table]).values())
        apart, far = 0, 0
        for _ in range(1500):
            q = pin.randomConfiguration(model)
            pin.computeDistances(model, data, pair, pair_data, q)
            distance = min(r.min_distance for r in pair_data.distanceResults)
            verdict = tabled(q, arrays)
            said_apart = verdict == CLEAR
            assert distance > 0 or not said_apart, (table.upper, table.lower, q)
            assert distance < 0 or verdict != COLLIDES, (table.upper, table.lower, q)
            if distance > 2 * table.margin:
                far += 1
                apart += said_apart
        assert apart == far


def test_a_state_off_the_grid_is_not_called_apart(ur10e: tuple[Robot, pin.GeometryModel]) -> None:
    robot, hulls = ur10e
    [table, *_] = pair_tables.pair_tables(robot.model, hulls, robot.config.srdf.disabled_pairs, robot.config.urdf)
    q = pin.neutral(robot.model)
    q[table.q_index[0]] = table.start[0] - table.step[0]
    assert tabled(q, tuple(_table_arrays([table]).values())) != CLEAR


def test_tables_are_cached_on_disk(
    ur10e: tuple[Robot, pin.GeometryModel], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    robot, hulls = ur10e
    monkeypatch.setenv("MOVEPLAN_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(pair_tables, "_MEMORY", {})
    first = pair_tables.pair_tables(robot.model, hulls, robot.config.srdf.disabled_pairs, robot.config.urdf)
    [cached] = tmp_path.glob("pairs-*.entry")
    monkeypatch.setattr(pair_tables, "_MEMORY", {})
    monkeypatch.setattr(pair_tables, "_tables", lambda *args: pytest.fail("recomputed a cached table"))
    again = pair_tables.pair_tables(robot.model, hulls, robot.config.srdf.disabled_pairs, robot.config.urdf)
    assert [t.margin for t in again] == [t.margin for t in first]
    assert cached.stat().st_size > 0
