"""Checks of the shipped UR10e config: kinematics, limits, SRDF consistency, self-collision."""

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml

CONFIG = Path(__file__).parents[2] / "configs/ur10e"
URDF = CONFIG / "ur10e.urdf"
SRDF = CONFIG / "ur10e.srdf"
JOINTS = [
    "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
    "wrist_1_joint", "wrist_2_joint", "wrist_3_joint",
]
TWO_PI = 2 * np.pi


@pytest.fixture(scope="module")
def model():
    return pin.buildModelFromUrdf(str(URDF))


def ur_dh_forward_kinematics(q):
    # UR's published UR10e DH table: T = prod Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i).
    d = [0.1807, 0.0, 0.0, 0.17415, 0.11985, 0.11655]
    a = [0.0, -0.6127, -0.57155, 0.0, 0.0, 0.0]
    alpha = [np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0]
    pose = np.eye(4)
    for theta, di, ai, al in zip(q, d, a, alpha, strict=True):
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(al), np.sin(al)
        pose = pose @ np.array([
            [ct, -st * ca, st * sa, ai * ct],
            [st, ct * ca, -ct * sa, ai * st],
            [0.0, sa, ca, di],
            [0.0, 0.0, 0.0, 1.0],
        ])
    return pose


def test_tool0_in_base_frame_matches_ur_dh_kinematics(model):
    data = model.createData()
    base, tool0 = model.getFrameId("base"), model.getFrameId("tool0")
    rng = np.random.default_rng(0)
    for _ in range(1000):
        q = rng.uniform(model.lowerPositionLimit, model.upperPositionLimit)
        pin.framesForwardKinematics(model, data, q)
        pose = (data.oMf[base].inverse() * data.oMf[tool0]).homogeneous
        np.testing.assert_allclose(pose, ur_dh_forward_kinematics(q), rtol=0, atol=1e-9)


def named_configurations(model):
    q_of = {}
    for state in ET.parse(SRDF).getroot().findall("group_state"):
        values = {j.get("name"): float(j.get("value")) for j in state.findall("joint")}
        q_of[f"group_state {state.get('name')}"] = values
    initial = yaml.safe_load((CONFIG / "initial_positions.yaml").read_text())["initial_positions"]
    q_of["initial_positions"] = initial
    return {
        name: np.array([values[model.names[j]] for j in range(1, model.njoints)])
        for name, values in q_of.items()
    }


def test_named_states_and_initial_positions_are_free_of_self_collision(model):
    geom = pin.buildGeomFromUrdf(model, str(URDF), pin.GeometryType.COLLISION)
    geom.addAllCollisionPairs()
    pin.removeCollisionPairs(model, geom, str(SRDF))
    geom_data = pin.GeometryData(geom)
    data = model.createData()
    configurations = named_configurations(model)
    assert {"group_state home", "initial_positions"} <= set(configurations)
    home = [0, -np.pi / 2, -np.pi / 2, 0, 0, 0]
    np.testing.assert_allclose(configurations["group_state home"], home)
    for name, q in configurations.items():
        pin.computeCollisions(model, data, geom, geom_data, q, False)
        hits = [
            (geom.geometryObjects[cp.first].name, geom.geometryObjects[cp.second].name)
            for k, cp in enumerate(geom.collisionPairs)
            if geom_data.collisionResults[k].isCollision()
        ]
        assert not hits, f"{name} is in self-collision: {hits}"


def test_urdf_limits_match_the_ur10e_datasheet(model):
    assert [model.names[j] for j in range(1, model.njoints)] == JOINTS
    lower = [-TWO_PI, -TWO_PI, -np.pi, -TWO_PI, -TWO_PI, -TWO_PI]
    np.testing.assert_allclose(model.lowerPositionLimit, lower)
    np.testing.assert_allclose(model.upperPositionLimit, np.negative(lower))
    np.testing.assert_allclose(model.velocityLimit, [2.094, 2.094, 3.142, 3.142, 3.142, 3.142])
    np.testing.assert_allclose(model.effortLimit, [330, 330, 150, 56, 56, 56])


def test_every_link_named_in_the_srdf_exists_in_the_urdf():
    urdf_links = {link.get("name") for link in ET.parse(URDF).getroot().findall("link")}
    srdf = ET.parse(SRDF).getroot()
    named = set()
    for chain in srdf.iter("chain"):
        named |= {chain.get("base_link"), chain.get("tip_link")}
    for link in srdf.iter("link"):
        named.add(link.get("name"))
    for pair in srdf.findall("disable_collisions"):
        named |= {pair.get("link1"), pair.get("link2")}
    assert named - urdf_links == set()
    assert srdf.get("name") == "ur10e"
