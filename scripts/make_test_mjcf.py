"""Writes tests/data/ur5_gripper.xml: an MJCF arm as Menagerie-style files ship.

The UR5 of example-robot-data (its URDF's kinematics and inertias, compiled by
MuJoCo), then what such files have and a URDF has not:

- position actuators (kp, kv, a forcerange of the URDF's effort limits, the
  joint range as ctrlrange) in place of torque motors;
- the end effector as a body (``tool0``), with no site;
- collision geometry: a capsule along each link (its ends a radius short of
  the joints), as MuJoCo checks contacts with;
- a gripper on ``tool0``: a 0.3 kg palm, two fingers on hinges named
  ``…knuckle…`` (one driven by a position actuator, the other coupled to it
  by a joint equality);
- a keyframe ``home`` with the servos' targets.

    python scripts/make_test_mjcf.py        # rewrites the file

Needs MuJoCo and example-robot-data (the test extras).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from adaptimp import _description, _models

OUT = Path(__file__).resolve().parents[1] / "tests" / "data" / "ur5_gripper.xml"
UR5 = _models.panda_urdf_path().parents[2] / "ur_description" / "urdf" / "ur5_robot.urdf"
EFFORT = {"shoulder": 150.0, "elbow": 150.0, "wrist": 28.0}
RADIUS = {"shoulder": 0.06, "upper": 0.05, "forearm": 0.04, "wrist": 0.035}


def main() -> None:
    arm = _description.read_arm(UR5)  # the core's reduction (SPEC §21)
    assert arm.urdf is not None
    spec = mujoco.MjSpec.from_string(arm.urdf)
    spec.compiler.fusestatic = False
    spec.modelname = "ur5_gripper"
    model = spec.compile()
    # Capsules from each body's origin to its child's, a radius short of each end.
    for b in range(1, model.nbody):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b)
        children = [c for c in range(model.nbody) if model.body_parentid[c] == b and c != b]
        r = next((v for k, v in RADIUS.items() if k in name), 0.03)
        for c in children:
            end = np.array(model.body_pos[c])
            length = float(np.linalg.norm(end))
            if length < 3 * r:
                continue
            u = end / length
            spec.body(name).add_geom(
                type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                size=[r, 0, 0],
                fromto=[*(r * u), *(end - r * u)],
                mass=0.0,
                density=0.0,
                rgba=[0.6, 0.6, 0.7, 1.0],
            )
    for j in arm.joints:  # the URDF importer's limits: the servos' forcerange says it
        spec.joint(j).actfrclimited = mujoco.mjtLimited.mjLIMITED_FALSE
        spec.joint(j).actfrcrange = [0.0, 0.0]
    palm = spec.body("tool0").add_body(name="palm", pos=[0, 0, 0.03])
    palm.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.04, 0.02, 0.03], mass=0.3)
    for side, y in (("left", 0.025), ("right", -0.025)):
        finger = palm.add_body(name=f"{side}_finger", pos=[0, y, 0.03])
        finger.add_joint(
            name=f"{side}_knuckle_joint",
            type=mujoco.mjtJoint.mjJNT_HINGE,
            axis=[1, 0, 0] if side == "left" else [-1, 0, 0],
            range=[0, 0.8],
        )
        finger.add_geom(
            type=mujoco.mjtGeom.mjGEOM_CAPSULE,
            size=[0.008, 0, 0],
            fromto=[0, 0, 0.01, 0, 0, 0.05],
            mass=0.05,
        )
    spec.compile()
    # Actuators, coupling and keyframe as text a MuJoCo 3 reads too: <position>
    # servos on the big joints, Menagerie's <general> form on the wrists.
    lines = ["  <actuator>"]
    for j in arm.joints:
        effort = next(v for k, v in EFFORT.items() if k in j)
        lo, hi = (float(x) for x in model.jnt_range[mujoco.mj_name2id(model, 3, j)])
        kp, kv = 20 * effort, 2 * effort
        name = j.replace("_joint", "")
        common = (
            f'name="{name}" joint="{j}" ctrlrange="{lo:g} {hi:g}" '
            f'forcerange="{-effort:g} {effort:g}"'
        )
        if "wrist" in j:
            bias = f'biastype="affine" biasprm="0 {-kp:g} {-kv:g}"'
            lines.append(f'    <general {common} gainprm="{kp:g}" {bias}/>')
        else:
            lines.append(f'    <position {common} kp="{kp:g}" kv="{kv:g}"/>')
    lines.append(
        '    <position name="gripper" joint="left_knuckle_joint" ctrlrange="0 0.8" '
        'forcerange="-5 5" kp="20" kv="0.5"/>'
    )
    lines.append("  </actuator>")
    lines.append("  <equality>")
    lines.append('    <joint joint1="right_knuckle_joint" joint2="left_knuckle_joint"/>')
    lines.append("  </equality>")
    home = "0 -1.2 1.4 -1.8 -1.57 0"
    lines.append("  <keyframe>")
    lines.append(f'    <key name="home" qpos="{home} 0.2 0.2" ctrl="{home} 0.2"/>')
    lines.append("  </keyframe>")
    xml = spec.to_xml().replace("</mujoco>", "\n".join(lines) + "\n</mujoco>")
    header = (
        "<!-- An MJCF arm as Menagerie-style files ship (position servos, the end effector\n"
        "     as a body, collision capsules, a gripper with a coupled finger): the UR5 of\n"
        "     example-robot-data. Written by scripts/make_test_mjcf.py; do not edit. -->\n"
    )
    OUT.write_text(header + xml)
    mujoco.MjModel.from_xml_path(str(OUT))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
