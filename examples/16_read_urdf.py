"""Read an arm from a URDF in Python (SPEC §21), the same in Rust
(``examples/16_read_urdf.rs``) and C (``ffi/examples/16_read_urdf.c``): the
core reads the file, finds the arm by its one rule (which chain, which
joints, the tip, what is held and why) and builds its chain.

    python examples/16_read_urdf.py [PATH] [--tip LINK] [--fix JOINT]...

Without PATH, the URDF text of the Rust example: a 3-joint arm holding a
gripper whose jaw a finger mimics (the jaw is held: a gripper's drive). A
``.xacro`` path is expanded with the extra ``xacro``; an MJCF path is
compiled by MuJoCo (the extra ``mujoco``).
"""

from __future__ import annotations

import argparse
import textwrap
from typing import NoReturn

import adaptimp
from adaptimp._description import read_arm

URDF = (
    "<robot name='demo'>"
    "<link name='base'/>"
    "<link name='upper'><inertial><origin xyz='0.15 0 0'/><mass value='2'/>"
    "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.02' iyz='0' izz='0.02'/></inertial></link>"
    "<link name='fore'><inertial><origin xyz='0.1 0 0'/><mass value='1'/>"
    "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link>"
    "<link name='hand'><inertial><mass value='0.3'/>"
    "<inertia ixx='1e-4' ixy='0' ixz='0' iyy='1e-4' iyz='0' izz='1e-4'/></inertial></link>"
    "<link name='tool'/><link name='jaw'/><link name='finger'/>"
    "<joint name='shoulder' type='revolute'><parent link='base'/><child link='upper'/>"
    "<origin xyz='0 0 0.1'/><axis xyz='0 0 1'/>"
    "<limit lower='-3' upper='3' effort='20' velocity='2'/><dynamics damping='0.5'/></joint>"
    "<joint name='elbow' type='revolute'><parent link='upper'/><child link='fore'/>"
    "<origin xyz='0.3 0 0'/><axis xyz='0 1 0'/>"
    "<limit lower='-2' upper='2' effort='10' velocity='2'/></joint>"
    "<joint name='wrist' type='continuous'><parent link='fore'/><child link='hand'/>"
    "<origin xyz='0.2 0 0'/><axis xyz='1 0 0'/></joint>"
    "<joint name='flange' type='fixed'><parent link='hand'/><child link='tool'/>"
    "<origin xyz='0.05 0 0'/></joint>"
    "<joint name='jaw_joint' type='revolute'><parent link='hand'/><child link='jaw'/>"
    "<axis xyz='0 0 1'/><limit lower='0' upper='1' effort='1' velocity='1'/></joint>"
    "<joint name='finger_joint' type='revolute'><parent link='hand'/><child link='finger'/>"
    "<axis xyz='0 0 1'/><limit lower='-1' upper='0' effort='1' velocity='1'/>"
    "<mimic joint='jaw_joint' multiplier='-1'/></joint>"
    "</robot>"
)


class Parser(argparse.ArgumentParser):
    """A usage error is one line (``prog: error: …``), exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


def main() -> None:
    doc = (__doc__ or "").split("\n\n")
    parser = Parser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(doc[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("path", nargs="?", help="a URDF, xacro or MJCF file (default: the text)")
    parser.add_argument("--tip", help="the link (or site) that ends the arm")
    parser.add_argument("--fix", action="append", default=[], help="a joint to hold")
    args = parser.parse_args()
    source = args.path if args.path else URDF
    try:
        arm = read_arm(source, tip=args.tip, fix=tuple(args.fix))
    except (OSError, ValueError, ImportError) as e:  # a path, tip or joint it does not have
        parser.error(str(e))
    print(f"{arm.source}: n = {arm.n}, tip {arm.tip!r}")
    for name, lo, hi, effort, damping, friction in zip(
        arm.joints, arm.lower, arm.upper, arm.effort, arm.damping, arm.friction
    ):
        print(
            f"  {name}: limits [{lo:g}, {hi:g}], effort {effort:g}, damping {damping:g}, "
            f"friction {friction:g}"
        )
    for name, why in arm.fixed.items():
        print(f"  held {name} = {arm.held[name]:g}: {why}")
    chain = adaptimp.Chain(arm.chain, arm.tip_origin, names=arm.joints)
    p = chain.fk([0.0] * arm.n)[:3, 3]
    print(f"tip at q = 0: {p[0]:.17g} {p[1]:.17g} {p[2]:.17g}")


if __name__ == "__main__":
    main()
