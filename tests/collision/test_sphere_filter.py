"""The sphere filter: spheres enclose the real geometry, and a state it clears never collides."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT, UR10E

from moveplan.core.collision import _sphere_fit as sphere_model
from moveplan.core.collision._sphere_fit import fit_geometry, robot_spheres
from moveplan.core.collision.checker import CollisionChecker, GeometryMode
from moveplan.core.collision.motion import MotionChecker
from moveplan.core.collision.sphere_filter import CLEAR, COLLIDES, SphereFilter
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene
from moveplan.core.types import CollisionObject, Shape

PANDA = ROOT / "configs" / "panda"
MBM = ROOT / "tests" / "data" / "mbm"


def _surface_points(obj: pin.GeometryObject, rng: np.random.Generator) -> np.ndarray:
    """Return vertices and random points on the triangles of a shape's surface, in its joint's frame."""
    vertices, triangles = sphere_model._surface(obj.geometry)
    corners = vertices[triangles]
    weights = rng.dirichlet(np.ones(3), size=(len(triangles), 20))
    inside = np.einsum("tkc,tcx->tkx", weights, corners).reshape(-1, 3)
    points = np.vstack([vertices, inside])
    return points @ np.asarray(obj.placement.rotation).T + np.asarray(obj.placement.translation)


@pytest.mark.parametrize(("config", "mode"), [(PANDA, "exact"), (PANDA, "convex"), (UR10E, "exact")],
                         ids=["panda meshes", "panda hulls", "ur10e cylinders"])
def test_every_point_of_every_shape_lies_inside_its_spheres(config: Path, mode: GeometryMode) -> None:
    robot = Robot(load_robot_config(config))
    geometry = CollisionChecker(robot, geometry=mode).robot_geometry
    rng = np.random.default_rng(0)
    for obj in geometry.geometryObjects:
        centres, radii = fit_geometry(obj)
        points = _surface_points(obj, rng)
        gaps = np.linalg.norm(points[:, None, :] - centres[None], axis=2) - radii[None]
        assert np.all(gaps.min(axis=1) <= 0.0), obj.name


@pytest.fixture(scope="module")
def panda_in_box() -> tuple[Robot, CollisionChecker, CollisionChecker, SphereFilter]:
    robot = Robot(load_robot_config(PANDA))
    scene = load_scene(MBM / "problems" / "box_panda" / "scene0001.yaml", robot)
    checker = CollisionChecker(robot, scene.objects, scene.source, geometry="exact", allowed=scene.allowed)
    hulls = CollisionChecker(robot, scene.objects, scene.source, geometry="convex", allowed=scene.allowed)
    spheres = SphereFilter(robot, checker.robot_geometry, scene.objects, scene.allowed, hulls=hulls.robot_geometry)
    return robot, checker, hulls, spheres


def test_no_state_the_filter_clears_collides_even_under_the_hulls_and_most_free_states_are_cleared(
    panda_in_box: tuple[Robot, CollisionChecker, CollisionChecker, SphereFilter]
) -> None:
    # Free under the hulls, not only the meshes: the search stops at the hulls, and must answer alike
    # with the filter and without it (tests/pipeline/test_filter_rule.py).
    robot, checker, hulls, spheres = panda_in_box
    rng = np.random.default_rng(1)
    values = rng.uniform(robot.lower, robot.upper, size=(3000, robot.dof))
    # States near the box's walls too: small moves from a known free state.
    values = np.vstack([values, robot.values(robot.neutral()) + rng.normal(scale=0.3, size=(1000, robot.dof))])
    values = np.clip(values, robot.lower, robot.upper)
    q = robot.configurations(values, robot.neutral())
    free = checker.free_batch(q)
    verdict, configurations = spheres.classify(values)
    np.testing.assert_allclose(configurations, q.T)
    cleared = verdict == CLEAR
    assert not np.any(cleared & ~hulls.free_batch(q))
    assert cleared[free].mean() > 0.6


def test_most_free_states_a_tenth_of_a_radian_from_contact_are_cleared(
    panda_in_box: tuple[Robot, CollisionChecker, CollisionChecker, SphereFilter]
) -> None:
    robot, checker, _, spheres = panda_in_box
    rng = np.random.default_rng(2)
    values = rng.uniform(robot.lower, robot.upper, size=(2000, robot.dof))
    free = checker.free_batch(robot.configurations(values))
    count = min(free.sum(), (~free).sum(), 500)
    start, end = values[free][:count], values[~free][:count]
    # Bisect each free-to-colliding segment to its first contact, then step back 0.1 rad.
    lo, hi = np.zeros(count), np.ones(count)
    for _ in range(10):
        middle = (lo + hi) / 2
        ok = checker.free_batch(robot.configurations(start + middle[:, None] * (end - start)))
        lo, hi = np.where(ok, middle, lo), np.where(ok, hi, middle)
    direction = (end - start) / np.linalg.norm(end - start, axis=1)[:, None]
    near = np.clip(start + lo[:, None] * (end - start) - 0.1 * direction, robot.lower, robot.upper)
    near_free = checker.free_batch(robot.configurations(near))
    cleared = spheres.classify(near)[0] == CLEAR
    assert not np.any(cleared & ~near_free)
    # The clustering fit this replaced cleared 39% of them; the hull-hugging one 75%.
    assert cleared[near_free].mean() > 0.6


@pytest.mark.parametrize("resolution", [0.5, 0.05, 0.01], ids=["few states", "search", "fine"])
def test_an_edge_is_judged_at_every_state_between_its_ends_once(
    panda_in_box: tuple[Robot, CollisionChecker, CollisionChecker, SphereFilter], resolution: float
) -> None:
    robot, _, _, spheres = panda_in_box
    rng = np.random.default_rng(4)
    for a, b in rng.uniform(robot.lower, robot.upper, size=(20, 2, robot.dof)):
        count = max(1, int(np.ceil(np.abs(b - a).max() / resolution)))
        verdict, q = spheres.classify(a + (b - a) * (np.arange(1, count + 1) / count)[:, None])
        worst, unclear, unclear_q = spheres.edge(a, b, resolution)
        assert worst == verdict.min()
        assert sorted(unclear) == sorted(verdict[verdict != CLEAR])
        order = np.lexsort(unclear_q.T)
        np.testing.assert_allclose(unclear_q[order], q[verdict != CLEAR][np.lexsort(q[verdict != CLEAR].T)])
        stopped = spheres.edge(a, b, resolution, stop=True)
        assert stopped[0] == worst and (worst != COLLIDES or stopped[1][-1] == COLLIDES)


def test_read_only_states_are_judged_without_compiling_the_kernels_again(
    panda_in_box: tuple[Robot, CollisionChecker, CollisionChecker, SphereFilter],
) -> None:
    from moveplan.core.collision import _kernels as sphere_kernels

    robot, _, _, spheres = panda_in_box
    before = len(sphere_kernels.edge.signatures), len(sphere_kernels.classify.signatures)
    path = np.array([robot.values(robot.neutral()), robot.upper * 0.5])
    writable = [(worst, verdicts.copy(), unclear.copy()) for worst, verdicts, unclear in
                [spheres.edge(path[0], path[1], 0.05)]], spheres.classify(path)
    path.setflags(write=False)  # as a planned path's frozen waypoints
    worst, verdicts, unclear = spheres.edge(path[0], path[1], 0.05)
    judged = spheres.classify(path)
    # Compiling another version takes seconds on a fresh machine, inside a clocked search.
    assert (len(sphere_kernels.edge.signatures), len(sphere_kernels.classify.signatures)) == before
    assert worst == writable[0][0][0]
    np.testing.assert_array_equal(verdicts, writable[0][0][1])
    np.testing.assert_array_equal(unclear, writable[0][0][2])
    for got, want in zip(judged, writable[1], strict=True):
        np.testing.assert_array_equal(got, want)


def test_edges_and_states_are_judged_alike_with_and_without_the_spheres_and_hulls(
    panda_in_box: tuple[Robot, CollisionChecker, CollisionChecker, SphereFilter]
) -> None:
    robot, checker, hulls, spheres = panda_in_box
    staged = MotionChecker(robot, checker, robot.neutral(), spheres, hulls)
    meshes_only = MotionChecker(robot, checker, robot.neutral())
    rng = np.random.default_rng(5)
    starts = rng.uniform(robot.lower, robot.upper, size=(60, robot.dof))
    ends = np.clip(starts + rng.normal(scale=0.3, size=starts.shape), robot.lower, robot.upper)
    for a, b in zip(starts, ends, strict=True):
        assert staged.edge_free(a, b, 0.05) == meshes_only.edge_free(a, b, 0.05)
        assert staged.state_free(b) == meshes_only.state_free(b)


def test_fitted_spheres_are_cached_on_disk_and_a_corrupt_cache_is_rebuilt(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("MOVEPLAN_CACHE_DIR", str(tmp_path))
    robot = Robot(load_robot_config(UR10E))
    geometry = CollisionChecker(robot).robot_geometry
    monkeypatch.setattr(sphere_model, "_CACHE", {})
    first = robot_spheres(robot.model, geometry, robot.config.urdf)
    [cached] = tmp_path.glob("spheres-*.entry")
    cached.write_bytes(b"not a cache entry")
    monkeypatch.setattr(sphere_model, "_CACHE", {})
    again = robot_spheres(robot.model, geometry, robot.config.urdf)
    np.testing.assert_array_equal(first.radii, again.radii)
    assert cached.read_bytes() != b"not a cache entry"


def test_a_state_the_filter_finds_colliding_collides_under_the_hulls_and_most_hull_collisions_are_found(
    panda_in_box: tuple[Robot, CollisionChecker, CollisionChecker, SphereFilter]
) -> None:
    robot, _, hulls, spheres = panda_in_box
    rng = np.random.default_rng(2)
    values = rng.uniform(robot.lower, robot.upper, size=(4000, robot.dof))
    verdict, q = spheres.classify(values)
    hull_free = hulls.free_batch(q.T)
    surely = verdict == COLLIDES
    assert not np.any(surely & hull_free)
    assert surely[~hull_free].mean() > 0.3


def test_a_base_resting_on_a_table_leaves_the_other_links_to_decide() -> None:
    robot = Robot(load_robot_config(UR10E))
    scene = load_scene(ROOT / "samples" / "ur10e_table_scene.yaml", robot)
    checker = CollisionChecker(robot, scene.objects, scene.source, allowed=scene.allowed)
    spheres = SphereFilter(robot, checker.robot_geometry, scene.objects, scene.allowed)
    values = np.random.default_rng(3).uniform(robot.lower, robot.upper, size=(2000, robot.dof))
    free = checker.free_batch(robot.configurations(values))
    cleared = spheres.classify(values)[0] == CLEAR
    assert not np.any(cleared & ~free)
    assert cleared[free].mean() > 0.5


def test_a_filter_for_the_next_scene_of_a_robot_judges_as_one_built_from_nothing() -> None:
    # A benchmark's process builds the robot's part of a filter once and reuses it for every
    # scene with nothing attached; a scene that attaches an object, or allows other pairs, gets its own.
    from moveplan.core.collision import sphere_filter

    robot = Robot(load_robot_config(PANDA))
    first, second = (load_scene(MBM / "problems" / "box_panda" / f"scene000{k}.yaml", robot) for k in (1, 2))
    held = CollisionObject("tray", Shape("box", (0.3, 0.3, 0.02)), np.eye(4), link="panda_hand",
                           touch_links=("panda_hand", "panda_leftfinger", "panda_rightfinger"))
    checker = CollisionChecker(robot)
    scenes = [(first.objects, first.allowed), (second.objects, second.allowed),
              ((*second.objects, held), second.allowed),
              (second.objects, second.allowed | {frozenset(("panda_link5", "panda_link7"))}),
              (first.objects, first.allowed)]
    values = np.random.default_rng(5).uniform(robot.lower, robot.upper, size=(3000, robot.dof))
    reused = [SphereFilter(robot, checker.robot_geometry, objects, allowed).classify(values)[0]
              for objects, allowed in scenes]
    for (objects, allowed), verdicts in zip(scenes, reused, strict=True):
        sphere_filter._ROBOT_PARTS.clear()
        fresh = SphereFilter(robot, checker.robot_geometry, objects, allowed).classify(values)[0]
        np.testing.assert_array_equal(verdicts, fresh)
    # Each scene judged as itself: the walls moved, the tray held; the first scene again as the first time.
    assert not np.array_equal(reused[0], reused[1]) and not np.array_equal(reused[1], reused[2])
    np.testing.assert_array_equal(reused[0], reused[4])


def test_the_robot_packed_once_and_a_world_added_are_the_arrays_packed_at_once() -> None:
    # The kernels read every array where LAYOUT puts it: the robot's two pieces and a scene's obstacles,
    # packed apart, must give the very arrays and head that packing all of them together gives.
    from moveplan.core.collision import _packing, sphere_filter

    robot = Robot(load_robot_config(PANDA))
    scene = load_scene(MBM / "problems" / "box_panda" / "scene0001.yaml", robot)
    checker = CollisionChecker(robot, scene.objects, scene.source, "convex", scene.allowed)
    built = SphereFilter(robot, checker.robot_geometry, scene.objects, scene.allowed)
    part = next(iter(sphere_filter._ROBOT_PARTS.values()))
    arrays = {name: np.arange(7 * (k + 1)).reshape((-1, 7) if ndim == 2 else (-1, 1, 7) if ndim == 3 else (-1,))
              for k, (name, ndim, _) in enumerate(_packing.LAYOUT)}
    robot_arrays = {name: value for name, value in arrays.items() if name not in _packing.WORLD}
    world = {name: arrays[name] for name in _packing.WORLD}
    together = _packing._piece(arrays, range(len(_packing.LAYOUT)))
    for got, want in zip(_packing.pack(_packing.pack_robot(robot_arrays), world), together, strict=True):
        np.testing.assert_array_equal(got, want)
        assert got.dtype == want.dtype
    # And a real filter's: the scene's obstacles sit where unpack reads them.
    floats, _, head = built._packed
    obstacles = sphere_filter._obstacles([obj for obj in scene.objects if not obj.link], {})
    k = [name for name, _, _ in _packing.LAYOUT].index("osize")
    at, rows, columns = head[k, :3]
    assert len(part.packed) == 2 and rows == len(obstacles["osize"]) > 0
    np.testing.assert_array_equal(floats[at:at + rows * columns].reshape(rows, columns), obstacles["osize"])


def test_a_state_where_a_links_hull_reaches_into_a_shelf_and_its_mesh_does_not_is_left_to_the_hulls() -> None:
    # From a MotionBenchMaker search (bookshelf_small 0005, seed 0): panda_link6's hull 25 mm into the shelf's
    # top, its mesh clear of it. Spheres fitted to the mesh cleared this state, which the search, stopping at
    # the hulls, refuses without them: it then checked 1,022 motions with the filter and 1,019 without.
    robot = Robot(load_robot_config(MBM / "panda_robot"))
    scene = load_scene(MBM / "problems" / "bookshelf_small_panda" / "scene0005.yaml", robot)
    checker = CollisionChecker(robot, scene.objects, scene.source, geometry="exact", allowed=scene.allowed)
    hulls = CollisionChecker(robot, scene.objects, scene.source, geometry="convex", allowed=scene.allowed)
    spheres = SphereFilter(robot, checker.robot_geometry, scene.objects, scene.allowed, hulls=hulls.robot_geometry)
    values = np.array([[2.16431345839404, -0.9577543007378085, -1.6230182492307321, -1.0571055375308713,
                        2.544895648219603, 2.62899724058303, 0.0240692558119896]])
    q = robot.configurations(values, robot.neutral())
    assert checker.free_batch(q)[0] and not hulls.free_batch(q)[0]
    assert hulls.colliding_pair(q[:, 0]) == ("panda_link6", "shelf_top")
    assert spheres.classify(values)[0][0] != CLEAR
