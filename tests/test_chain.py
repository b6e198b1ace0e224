"""adaptimp.Chain (SPEC §16): serial-chain kinematics from a URDF or a MuJoCo model,
against Pinocchio and MuJoCo, on every arm of example-robot-data; bad input."""

from __future__ import annotations

import importlib.metadata
import warnings
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pinocchio as pin
import pytest

import adaptimp
from adaptimp import _models
from adaptimp import mujoco as amj
from adaptimp._description import read_arm

ROBOTS = Path(
    str(
        importlib.metadata.distribution("example-robot-data").locate_file(
            "cmeel.prefix/share/example-robot-data/robots"
        )
    )
)
URDFS = sorted(ROBOTS.rglob("*.urdf"))
MOVABLE = ("revolute", "continuous", "prismatic")


def _chains(path: Path) -> list[tuple[str, list[str]]]:
    """Every leaf link of the URDF whose way from the root has 1 … 7 joints, all
    revolute, continuous, prismatic or fixed: (tip, movable joint names)."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    parent: dict[str, tuple[str, str, str]] = {}
    for j in root.findall("joint"):
        p, c = j.find("parent"), j.find("child")
        assert p is not None
        assert c is not None
        parent[c.get("link", "")] = (j.get("name", ""), j.get("type", ""), p.get("link", ""))
    parents = {v[2] for v in parent.values()}
    out = []
    for leaf in sorted(set(parent) - parents):
        names, link, ok = [], leaf, True
        while link in parent:
            name, kind, link = parent[link]
            if kind in MOVABLE:
                names.append(name)
            elif kind != "fixed":
                ok = False
        if ok and 1 <= len(names) <= 7:
            out.append((leaf, names[::-1]))
    return out


def _pinocchio(path: Path) -> Any:
    try:
        return pin.buildModelFromUrdf(str(path))
    except Exception:  # "every arm that loads": URDFs Pinocchio refuses are not arms here
        return None


CASES = [
    (path, tip, names)
    for path in URDFS
    if _pinocchio(path) is not None
    for tip, names in _chains(path)
]


def _pin_state(
    model: Any, names: list[str], q: np.ndarray, v: np.ndarray, held: dict[str, float]
) -> tuple[Any, Any]:
    """Pinocchio's q, v with the chain's joints set (continuous: cos, sin), the
    joints the reduction holds at their held values, the rest 0."""
    qf, vf = pin.neutral(model), np.zeros(model.nv)
    values = [*zip(names, q, v), *((name, x, 0.0) for name, x in held.items())]
    for name, x, dx in values:
        j = model.joints[model.getJointId(name)]
        if j.nq == 2:  # an unbounded revolute joint: (cos θ, sin θ)
            qf[j.idx_q : j.idx_q + 2] = np.cos(x), np.sin(x)
        else:
            qf[j.idx_q] = x
        vf[j.idx_v] = dx
    return qf, vf


def test_the_arms_of_example_robot_data_are_all_there() -> None:
    """The parametrised test below covers every chain of every URDF that loads:
    at least the Panda, the UR5, the xArm7, the Kinova and the Z1 arms."""
    joints = {(p.name, tip): len(n) for p, tip, n in CASES}
    assert joints[("panda.urdf", "panda_hand_tcp")] == 7
    assert joints[("ur5_robot.urdf", "tool0")] == 6
    for urdf, n in (("xarm7.urdf", 7), ("kinova.urdf", 6), ("z1.urdf", 6)):
        assert max(k for (p, _), k in joints.items() if p == urdf) >= n, urdf
    assert len({p for p, _ in joints}) >= 60
    assert len(CASES) >= 400


@pytest.mark.parametrize(
    ("path", "tip", "names"), CASES, ids=[f"{p.stem}:{t}" for p, t, _ in CASES]
)
def test_chain_equals_pinocchio(path: Path, tip: str, names: list[str]) -> None:
    """Pose and Jacobian to 1e-12, J̇ q̇ to 1e-12 of its scale (Pinocchio's
    classical acceleration of the frame, LOCAL_WORLD_ALIGNED, at q̈ = 0), random
    q, q̇."""
    model = _pinocchio(path)
    data = model.createData()
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always", adaptimp.PlantWarning)
        chain = adaptimp.Chain.from_urdf(path, tip=tip)
        # The one reduction (SPEC (21.2)): a mimic joint on the way moves with its
        # master, so the chain holds it (Pinocchio, without its mimic option,
        # counts it as a joint): compared at its held value.
        held = {n: read_arm(path, tip).held[n] for n in names if n in chain.fixed}
    # Said, not silent: a file's mimic of a joint it does not have, off the
    # arm (alex_psyonic_hands' fingers name their masters without the side).
    assert all("which is not a joint of it: held" in str(w.message) for w in seen)
    assert all(chain.fixed[n].startswith("mimics") for n in held), chain.fixed
    assert chain.joint_names == [n for n in names if n not in held]
    names = chain.joint_names
    fid = model.getFrameId(tip, pin.BODY)
    rng = np.random.default_rng(abs(hash((path.name, tip))) % 2**32)
    prismatic = np.array(chain.prismatic)
    for _ in range(3):
        q = np.where(
            prismatic, rng.uniform(-0.3, 0.3, chain.n), rng.uniform(-np.pi, np.pi, chain.n)
        )
        v = rng.normal(size=chain.n)
        qf, vf = _pin_state(model, names, q, v, held)
        pin.forwardKinematics(model, data, qf, vf, np.zeros(model.nv))
        pin.updateFramePlacements(model, data)
        frame = data.oMf[fid]
        acc = pin.getFrameClassicalAcceleration(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        jac = pin.computeFrameJacobian(model, data, qf, fid, pin.LOCAL_WORLD_ALIGNED)
        cols = [model.joints[model.getJointId(n)].idx_v for n in names]
        t = chain.fk(q)
        np.testing.assert_allclose(t[:3, 3], frame.translation, rtol=0, atol=1e-12)
        np.testing.assert_allclose(t[:3, :3], frame.rotation, rtol=0, atol=1e-12)
        np.testing.assert_allclose(chain.jacobian(q), jac[:, cols], rtol=0, atol=1e-12)
        bias = np.concatenate([acc.linear, acc.angular])
        scale = max(1.0, float(np.abs(bias).max()))
        np.testing.assert_allclose(chain.jdot_qdot(q, v), bias, rtol=0, atol=1e-12 * scale)


def test_mujoco_chain_equals_mujoco_and_the_urdf() -> None:
    """The Panda's MuJoCo model to its site: pose and Jacobian equal MuJoCo's own
    (mj_kinematics, mj_jacSite) and the URDF chain's, J̇ q̇ the URDF chain's."""
    model = amj.panda(table_height=None)
    data = mujoco.MjData(model)
    chain = adaptimp.Chain.from_mujoco(model, "ee")
    urdf = adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip=_models.PANDA_EE)
    assert chain.n == 7
    assert chain.joint_names == list(_models.PANDA_JOINTS)
    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "ee")
    rng = np.random.default_rng(7)
    jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    for _ in range(5):
        q, v = rng.uniform(-2, 2, 7), rng.normal(size=7)
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_jacSite(model, data, jp, jr, sid)
        t = chain.fk(q)
        np.testing.assert_allclose(t[:3, 3], data.site_xpos[sid], rtol=0, atol=1e-12)
        np.testing.assert_allclose(t[:3, :3], data.site_xmat[sid].reshape(3, 3), atol=1e-12)
        np.testing.assert_allclose(chain.jacobian(q), np.vstack([jp, jr]), rtol=0, atol=1e-12)
        np.testing.assert_allclose(t, urdf.fk(q), rtol=0, atol=1e-12)
        np.testing.assert_allclose(chain.jdot_qdot(q, v), urdf.jdot_qdot(q, v), atol=1e-10)


MJCF = """
<mujoco>
  <worldbody>
    <body name="a" pos="0.1 0 0.2" euler="0.2 0 0.3">
      <joint name="j1" type="hinge" axis="0 0 1" pos="0.05 0 0" ref="0.4"/>
      <body name="b" pos="0.3 0 0" quat="0.9 0.1 0.3 0">
        <joint name="j2" type="slide" axis="1 1 0" ref="0.1"/>
        <joint name="j3" type="hinge" axis="0 1 0" pos="0 0.02 0.1"/>
        <body name="c" pos="0 0 0.25">
          <site name="tip" pos="0.05 0.01 0" euler="0 0.5 0"/>
          <geom size="0.01" mass="0.1"/>
        </body>
        <geom size="0.01" mass="0.1"/>
      </body>
      <geom size="0.01" mass="0.1"/>
    </body>
  </worldbody>
</mujoco>
"""


def test_mujoco_chain_has_anchors_references_slides_and_bodies_of_two_joints() -> None:
    model = mujoco.MjModel.from_xml_string(MJCF)
    data = mujoco.MjData(model)
    chain = adaptimp.Chain.from_mujoco(model, "tip")
    assert chain.joint_names == ["j1", "j2", "j3"]
    assert chain.prismatic == [False, True, False]
    jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-1, 1, 3)
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_jacSite(model, data, jp, jr, 0)
        t = chain.fk(q)
        np.testing.assert_allclose(t[:3, 3], data.site_xpos[0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(t[:3, :3], data.site_xmat[0].reshape(3, 3), atol=1e-12)
        np.testing.assert_allclose(chain.jacobian(q), np.vstack([jp, jr]), rtol=0, atol=1e-12)


URDF = """<robot name="r">
  <link name="base"/><link name="l1"/><link name="l2"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/></joint>
</robot>"""


def _urdf(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (URDF.replace('<child link="l2"/>', '<child link="l3"/>'), "missing link"),
        (
            URDF.replace(
                "</robot>",
                '<joint name="j3" type="fixed"><parent link="l2"/><child link="l1"/></joint>'
                "</robot>",
            ),
            "kinematic loop",
        ),
        (
            URDF.replace(
                'type="revolute"><parent link="l1"/>', 'type="floating"><parent link="l1"/>'
            ),
            "joint 'j2' on the way to 'l2' is floating",
        ),
        (URDF.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 0 0"/>'), "‖axis‖ > 0"),
        (
            URDF.replace('<origin xyz="0.3 0 0"/>', '<origin xyz="0.3 0"/>'),
            r'<joint name="j2">: .*expected 3 found 2',
        ),
        ("<robot", "robot.urdf as a URDF: it is not XML"),
    ],
)
def test_bad_urdf_is_refused_by_name(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        adaptimp.Chain.from_urdf(_urdf(tmp_path, text), tip="l2")


def test_a_cycle_of_joints_is_a_loop(tmp_path: Path) -> None:
    text = URDF.replace(
        '<parent link="base"/><child link="l1"/>', '<parent link="l2"/><child link="l1"/>'
    )
    with pytest.raises(ValueError, match="loop"):
        adaptimp.Chain.from_urdf(_urdf(tmp_path, text), tip="l2")


def test_tip_must_be_a_link_and_the_default_is_the_arm() -> None:
    with pytest.raises(ValueError, match="tip= 'hand' is neither a link nor a frame"):
        adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip="hand")
    # The fingers are the hand's, not the arm's (SPEC (21.2)): the chain is the
    # arm the plant drives, to its last joint's link.
    chain = adaptimp.Chain.from_urdf(_models.panda_urdf_path())
    assert chain.joint_names == list(_models.PANDA_JOINTS)
    assert chain.source == "URDF 'panda.urdf' to 'panda_link7'"
    assert set(chain.fixed) == set(_models.PANDA_FINGERS)


def test_more_than_seven_joints_is_refused(tmp_path: Path) -> None:
    links = "".join(f'<link name="l{i}"/>' for i in range(9))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        '<origin xyz="0.1 0 0"/><axis xyz="0 0 1"/></joint>'
        for i in range(8)
    )
    path = _urdf(tmp_path, f'<robot name="long">{links}{joints}</robot>')
    with pytest.raises(ValueError, match=r"has 8 joints \(j0, .*, j7\); a chain has at most 7"):
        adaptimp.Chain.from_urdf(path)


def test_joint_data_is_validated() -> None:
    skew = {"kind": "revolute", "translation": [0, 0, 0], "rotation": np.eye(3) * 1.1}
    with pytest.raises(ValueError, match="orthonormal"):
        adaptimp.Chain([{**skew, "axis": [0, 0, 1]}])
    mirror = {"kind": "revolute", "rotation": np.diag([1.0, 1.0, -1.0]), "axis": [0, 0, 1]}
    with pytest.raises(ValueError, match="det R = \\+1"):
        adaptimp.Chain([mirror])
    with pytest.raises(ValueError, match="‖axis‖ > 0"):
        adaptimp.Chain([{"kind": "revolute", "axis": [0.0, 0.0, 0.0]}])
    with pytest.raises(ValueError, match="'fixed', 'revolute' or 'prismatic'"):
        adaptimp.Chain([{"kind": "ball", "axis": [0, 0, 1]}])
    with pytest.raises(ValueError, match="1 ≤ n ≤ 7"):
        adaptimp.Chain([{"kind": "fixed"}])


def test_default_tip_is_the_end_of_the_single_chain_of_movable_joints(tmp_path: Path) -> None:
    text = URDF.replace(
        "</robot>",
        '<link name="tool"/><joint name="t" type="fixed"><parent link="l2"/>'
        '<child link="tool"/><origin xyz="0 0 0.1"/></joint></robot>',
    )
    chain = adaptimp.Chain.from_urdf(_urdf(tmp_path, text))
    assert chain.joint_names == ["j1", "j2"]
    np.testing.assert_allclose(chain.fk([0.0, 0.0])[:3, 3], [0.3, 0.0, 0.1], atol=1e-15)
    tool = adaptimp.Chain.from_urdf(_urdf(tmp_path, text), tip="tool")
    np.testing.assert_allclose(tool.fk([0.0, 0.0])[:3, 3], [0.3, 0.0, 0.2], atol=1e-15)


def test_motion_along_rows_is_the_jacobian_and_its_derivative() -> None:
    """Chain.motion: [ṗ; ω] = J q̇ and [p̈; ω̇] = J q̈ + J̇ q̇ per row, as the
    single-row methods give them; a table of the wrong width is refused."""
    chain = adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip=_models.PANDA_EE)
    rng = np.random.default_rng(3)
    q, dq, ddq = (rng.uniform(-2, 2, (50, 7)) for _ in range(3))
    v, a = chain.motion(q, dq, ddq)
    assert v.shape == a.shape == (50, 6)
    for k in range(50):
        jac = chain.jacobian(q[k])
        np.testing.assert_allclose(v[k], jac @ dq[k], rtol=0, atol=1e-12)
        want = jac @ ddq[k] + chain.jdot_qdot(q[k], dq[k])
        np.testing.assert_allclose(a[k], want, rtol=0, atol=1e-11)
    with pytest.raises(ValueError, match="dq"):
        chain.motion(q, dq[:, :6], ddq)
