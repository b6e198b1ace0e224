"""franky-sim's FR3 (MuJoCo) served on one loopback address, in a process of its own.

Run as a script by :class:`adaptimp.franka.Simulator` (``python _franky_server.py
--ip 127.0.0.2 [--load KG] [--q0 Q1 … Q7]``), by the interpreter that has
franky-sim: it imports franky-sim and MuJoCo only, never adaptimp, so it runs
from a virtual environment of its own as well. pylibfranka's blocking calls
hold the GIL, so the server cannot share the client's process.

franky-sim's embedded mode: the scene is built, a body of ``--load`` kg is
added to the hand (the robot is not told of it), then the server starts. It
prints ``ready <ip>`` once it listens, and stops on SIGINT or SIGTERM.
"""

from __future__ import annotations

import argparse
import contextlib
import signal
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

LOAD_OFFSET = 0.1
"""Where the load sits: this far (m) along the hand's z axis, between the fingers."""

LOAD_RADIUS = 0.03
"""The load is a solid sphere of this radius (m), for its inertia."""


def add_load(sim: Any, mass: float) -> None:
    """A rigid body of ``mass`` kg welded to the hand of the first robot of
    franky-sim's scene (before the simulator starts)."""
    hands = [b for b in sim.worldbody.iter("body") if b.get("name") == "robot0_hand"]
    if not hands:
        raise SystemExit("franky-sim's scene has no body 'robot0_hand' to add a load to")
    load = ET.SubElement(hands[0], "body", name="adaptimp_load", pos=f"0 0 {LOAD_OFFSET}")
    inertia = 0.4 * mass * LOAD_RADIUS**2
    ET.SubElement(
        load, "inertial", pos="0 0 0", mass=repr(mass), diaginertia=f"{inertia} {inertia} {inertia}"
    )


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--ip", required=True, help="the loopback address to serve on")
    parser.add_argument("--load", type=float, default=0.0, help="a body on the hand (kg)")
    parser.add_argument("--q0", type=float, nargs=7, help="the posture it starts in (rad)")
    args = parser.parse_args(argv)
    # Run as a script, this file's folder is first on the path: it holds
    # adaptimp's own mujoco.py, which must not stand in for MuJoCo.
    here = Path(__file__).resolve().parent
    sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() != here]

    import franky_sim
    from franky_sim.mujoco_simulator import MujocoSimulator

    def stop(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, stop)
    with MujocoSimulator() as sim:
        robot = sim.add_robot() if args.q0 is None else sim.add_robot(initial_q=tuple(args.q0))
        if args.load > 0:
            add_load(sim, args.load)
        with franky_sim.SimulationServer(sim, hostname_candidates=[args.ip]) as server:
            print(f"ready {robot.hostname}", flush=True)
            with contextlib.suppress(KeyboardInterrupt):
                server.run_forever()
    sys.stdout.flush()


if __name__ == "__main__":
    main()
