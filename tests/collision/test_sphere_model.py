"""The sphere fit: spheres hold every point of a shape's surface and reach little past its convex hull."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from conftest import ROOT, SAMPLES
from scipy.spatial import ConvexHull

from moveplan.core.collision import _sphere_fit as sphere_model
from moveplan.core.collision._sphere_fit import fit_shape, robot_spheres
from moveplan.core.collision.checker import CollisionChecker, coal_geometry
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot
from moveplan.core.types import Shape

PANDA = ROOT / "configs" / "panda"


def _surface_points(vertices: np.ndarray, triangles: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Return the vertices and random points on every triangle."""
    weights = rng.dirichlet(np.ones(3), size=(len(triangles), 20))
    return np.vstack([vertices, np.einsum("tkc,tcx->tkx", weights, vertices[triangles]).reshape(-1, 3)])


def _reach_past_hull(points: np.ndarray, centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Return per sphere how far it reaches past the planes of the convex hull of `points` [m]."""
    equations = ConvexHull(points).equations
    return radii + (centres @ equations[:, :3].T + equations[:, 3]).max(axis=1)


def test_panda_spheres_reach_at_most_three_centimetres_past_each_link_hull() -> None:
    # The clustering fit this replaced reached up to 7 cm past the hulls (3.8 cm for the median sphere).
    # The filter fits its spheres to the links' hulls (core/collision/sphere_filter.py).
    robot = Robot(load_robot_config(PANDA))
    geometry = CollisionChecker(robot, geometry="convex").robot_geometry
    spheres = robot_spheres(robot.model, geometry, robot.config.urdf)
    owners = np.array(spheres.owners)
    reach = []
    for link in dict.fromkeys(spheres.owners):
        shapes = [obj for obj in geometry.geometryObjects if robot.model.frames[obj.parentFrame].name == link]
        points = np.vstack([sphere_model._surface(obj.geometry)[0] @ np.asarray(obj.placement.rotation).T
                            + np.asarray(obj.placement.translation) for obj in shapes])
        mine = owners == link
        reach.append(_reach_past_hull(points, spheres.centres[mine], spheres.radii[mine]))
    reach_m = np.concatenate(reach)
    assert reach_m.max() <= 0.03
    assert np.median(reach_m) <= 0.02
    assert max(Counter(spheres.owners).values()) <= 30  # about 24 a link: the kernel's cost grows with them


@pytest.mark.parametrize("shape", [
    Shape("box", (0.3, 0.2, 0.1)),
    Shape("box", (0.6, 0.4, 0.005)),
    Shape("cylinder", (0.05, 0.4)),
    Shape("mesh", vertices=np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.3, 0.3, 0.0], [0.0, 0.3, 0.0]]),
          triangles=np.array([[0, 1, 2], [0, 2, 3]])),
    Shape("mesh", mesh_path=str(SAMPLES / "panda_tray.obj")),
], ids=["box", "thin plate", "cylinder", "flat square mesh", "tray mesh"])
def test_every_point_of_an_attached_shape_lies_inside_its_spheres(shape: Shape) -> None:
    rotation = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    transform = np.eye(4)
    transform[:3, :3], transform[:3, 3] = rotation, (0.2, -0.1, 0.5)
    centres, radii = fit_shape(shape, transform)
    points = _surface_points(*sphere_model._surface(coal_geometry(shape)), np.random.default_rng(0))
    points = points @ rotation.T + transform[:3, 3]
    gaps = np.linalg.norm(points[:, None, :] - centres[None], axis=2) - radii[None]
    assert np.all(gaps.min(axis=1) <= 0.0)


@pytest.mark.parametrize("shape", [Shape("box", (0.2, 0.15, 0.1)), Shape("cylinder", (0.06, 0.3))],
                         ids=["box", "cylinder"])
def test_with_balls_to_spare_no_ball_reaches_more_than_the_excess_past_the_shape(shape: Shape) -> None:
    geometry = coal_geometry(shape)
    centres, radii = sphere_model._fit_coal(geometry, most=1000)
    reach = _reach_past_hull(sphere_model._surface(geometry)[0], centres, radii)
    assert reach.max() <= sphere_model._EXCESS_M + 1e-9


def test_a_large_shape_is_fitted_coarser_and_stays_within_its_ball_budget() -> None:
    shape = Shape("box", (20.0, 10.0, 0.5))
    centres, radii = fit_shape(shape, np.eye(4))
    assert len(radii) <= sphere_model._MOST
    points = _surface_points(*sphere_model._surface(coal_geometry(shape)), np.random.default_rng(0))
    gaps = np.linalg.norm(points[:, None, :] - centres[None], axis=2) - radii[None]
    assert np.all(gaps.min(axis=1) <= 0.0)
