"""Distance tables of link pairs: a pair they call apart never touches, and they are cached per robot."""

from __future__ import annotations

from pathlib import Path

import numpy as np
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


def _shoulder(folder: Path) -> Robot:
    """Return an arm whose upper arm's hub sits 25 mm over its base however its two joints (two full turns each) turn.

    As a UR5's upper arm passes ~13 mm over its base: a 20,000-point grid over two full turns
    of each joint has a margin of tens of millimetres, more than the pair's distance.
    """
    (folder / "arm.urdf").write_text("""<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
  <link name="shoulder"/>
  <link name="upper_arm">
    <collision><geometry><sphere radius="0.05"/></geometry></collision>
    <collision><origin xyz="0.2 0 0"/><geometry><box size="0.3 0.04 0.04"/></geometry></collision>
  </link>
  <joint name="pan" type="revolute"><parent link="base"/><child link="shoulder"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-6.283185307179586" upper="6.283185307179586" velocity="2" effort="1"/></joint>
  <joint name="lift" type="revolute"><parent link="shoulder"/><child link="upper_arm"/><origin xyz="0 0 0.075"/>
    <axis xyz="0 1 0"/><limit lower="-6.283185307179586" upper="6.283185307179586" velocity="2" effort="1"/></joint>
</robot>
""")
    (folder / "arm.srdf").write_text(
        '<robot name="arm"><group name="arm"><joint name="pan"/><joint name="lift"/></group></robot>')
    return Robot(load_robot_config(folder))


def test_a_pair_nearer_than_the_grids_margin_almost_everywhere_is_tabulated_finer_and_called_apart_where_apart(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    robot = _shoulder(tmp_path)
    hulls = CollisionChecker(robot, geometry="convex").robot_geometry
    monkeypatch.setenv("MOVEPLAN_CACHE_DIR", str(tmp_path / "cache"))

    def tabulated() -> pair_tables.PairTable:
        monkeypatch.setattr(pair_tables, "_MEMORY", {})
        for cached in (tmp_path / "cache").glob("pairs-*.entry"):
            cached.unlink()
        [table] = pair_tables.pair_tables(robot.model, hulls, robot.config.srdf.disabled_pairs, robot.config.urdf)
        return table

    with monkeypatch.context() as grid:
        grid.setattr(pair_tables, "_FINE_GRID_POINTS", pair_tables._GRID_POINTS)
        coarse = tabulated()
    assert np.mean(coarse.distances > coarse.margin) == 0  # that grid calls the pair apart nowhere
    table = tabulated()
    assert table.distances.size > pair_tables._GRID_POINTS
    assert table.margin < 0.51 * np.median(table.distances)  # half, to the grid's rounding
    assert np.mean(table.distances > table.margin) > 0.5
    model, data = robot.model, robot.model.createData()
    pair = pin.GeometryModel()
    for obj in hulls.geometryObjects:
        pair.addGeometryObject(obj.copy())
    base = [k for k, g in enumerate(hulls.geometryObjects) if g.parentJoint == 0]
    arm = [k for k, g in enumerate(hulls.geometryObjects) if g.parentJoint != 0]
    for i in base:
        for j in arm:
            pair.addCollisionPair(pin.CollisionPair(i, j))
    pair_data = pair.createData()
    arrays = tuple(_table_arrays([table]).values())
    said_apart = 0
    for q in np.random.default_rng(0).uniform(-2 * np.pi, 2 * np.pi, size=(1500, 2)):
        pin.computeDistances(model, data, pair, pair_data, q)
        distance = min(r.min_distance for r in pair_data.distanceResults)
        verdict = tabled(q, arrays)
        assert distance > 0 or verdict != CLEAR, q
        assert distance < 0 or verdict != COLLIDES, q
        said_apart += verdict == CLEAR
    assert said_apart > 500
