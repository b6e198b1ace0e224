"""PlanarArm and TwoLinkArm against Pinocchio (an independent rigid-body library):
the same arm built as a Pinocchio model of revolute-z joints; D by CRBA, C by
Pinocchio's Coriolis matrix, G by its generalized gravity, q̈ by ABA, the tip's
position and Jacobian by its frame kinematics, for N = 2 … 5 at random states."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import adaptimp


def planar_model(masses, lengths, coms, inertias, g: float):  # type: ignore[no-untyped-def]
    """Links along their local x, joints about z, gravity along −y (PlanarArm's plane)."""
    model = pin.Model()
    model.gravity = pin.Motion(np.array([0.0, -g, 0.0, 0.0, 0.0, 0.0]))
    parent, placement = 0, pin.SE3.Identity()
    for i, (m, length, c, inertia) in enumerate(zip(masses, lengths, coms, inertias)):
        jid = model.addJoint(parent, pin.JointModelRZ(), placement, f"joint{i + 1}")
        body = pin.Inertia(m, np.array([c, 0.0, 0.0]), np.diag([inertia] * 3))
        model.appendBodyToJoint(jid, body, pin.SE3.Identity())
        parent, placement = jid, pin.SE3(np.eye(3), np.array([length, 0.0, 0.0]))
    model.addFrame(pin.Frame("tip", parent, 0, placement, pin.FrameType.OP_FRAME))
    return model


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_planar_arm_dynamics_equal_pinocchio(n: int) -> None:
    rng = np.random.default_rng(100 + n)
    m = rng.uniform(0.5, 3.0, n)
    length = rng.uniform(0.2, 0.5, n)
    com = length * rng.uniform(0.2, 0.8, n)
    inertia = rng.uniform(1e-3, 5e-2, n)
    arm = adaptimp.PlanarArm(n, m, length, com, inertia, g=9.81)
    model = planar_model(m, length, com, inertia, 9.81)
    data = model.createData()
    for _ in range(20):
        q, v = rng.uniform(-np.pi, np.pi, n), rng.normal(size=n)
        d = pin.crba(model, data, q)
        d = np.triu(d) + np.triu(d, 1).T  # CRBA fills the upper triangle
        np.testing.assert_allclose(arm.D(q), d, rtol=0, atol=1e-12)
        c = pin.computeCoriolisMatrix(model, data, q, v)
        np.testing.assert_allclose(arm.C(q, v), c, rtol=0, atol=1e-12)
        g = pin.computeGeneralizedGravity(model, data, q)
        np.testing.assert_allclose(arm.G(q), g, rtol=0, atol=1e-12)
        # And the forward dynamics against ABA.
        tau = rng.normal(size=n)
        a = pin.aba(model, data, q, v, tau)
        np.testing.assert_allclose(arm.forward_dynamics(q, v, tau, np.zeros(n)), a, atol=1e-10)


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_planar_arm_kinematics_equal_pinocchio(n: int) -> None:
    rng = np.random.default_rng(200 + n)
    length = rng.uniform(0.2, 0.5, n)
    arm = adaptimp.PlanarArm(n, 1.0, length)
    model = planar_model(np.ones(n), length, length / 2, np.full(n, 0.01), 9.81)
    data = model.createData()
    tip = model.getFrameId("tip")
    for _ in range(20):
        q = rng.uniform(-np.pi, np.pi, n)
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        np.testing.assert_allclose(arm.fk(q), data.oMf[tip].translation, rtol=0, atol=1e-12)
        j = pin.computeFrameJacobian(model, data, q, tip, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(arm.jacobian(q), j[:3], rtol=0, atol=1e-12)


def test_two_link_arm_kinematics_equal_pinocchio() -> None:
    two = adaptimp.TwoLinkArm()
    p = two.params
    model = planar_model(
        [p["m1"], p["m2"]], [p["l1"], p["l2"]], [p["lc1"], p["lc2"]], [p["I1"], p["I2"]], p["g"]
    )
    data = model.createData()
    tip = model.getFrameId("tip")
    q = np.array([0.3, -1.1])
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    np.testing.assert_allclose(two.fk(q), data.oMf[tip].translation, rtol=0, atol=1e-12)
    j = pin.computeFrameJacobian(model, data, q, tip, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    np.testing.assert_allclose(two.jacobian(q), j[:3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(two.D(q), pin.crba(model, data, q), rtol=0, atol=1e-12)
