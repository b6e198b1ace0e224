"""franky-sim's MuJoCo FR3 as a libfranka server (:class:`Simulator`): a
process of its own on a loopback address, with a load on the hand the
controller is not told of (:mod:`adaptimp._franky_server`).

Re-exported by :mod:`adaptimp.franka`. Units: kg, m, s."""

from __future__ import annotations

import math
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from numpy.typing import ArrayLike

from ._errors import ConfigError
from ._franka_loop import posture_of

# ---------------------------------------------------------------------------
# The simulator.
# ---------------------------------------------------------------------------

SERVER = Path(__file__).with_name("_franky_server.py")
"""The script that serves franky-sim's FR3 (run by :class:`Simulator`)."""


def _free_address() -> str:
    """A loopback address on which libfranka's command port (1337) is free."""
    base = 2 + os.getpid() % 200
    for i in range(250):
        ip = f"127.0.{1 + (base + i) // 250}.{2 + (base + i) % 250}"
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            try:
                s.bind((ip, 1337))
            except OSError:
                continue
            return ip
    raise OSError("no loopback address with port 1337 free (127.0.x.y)")


class Simulator:
    """franky-sim's MuJoCo FR3 (a server of libfranka's network protocol) in a
    process of its own, on a loopback address; a context manager::

        with franka.Simulator(load=1.6) as sim:
            res = franka.run("sf", urdf, sim.ip)

    Parameters
    ----------
    ip : str, optional
        The loopback address to serve on; default one whose port 1337 is free.
    load : float
        A body of this mass (kg) welded to the hand, 0.1 m along its axis,
        before the simulation starts: the robot (and the controller) are not
        told of it.
    q0 : array_like, optional
        The posture the arm starts in (rad); default franky-sim's.
    python : str, optional
        The interpreter that has franky-sim (default this one; franky-sim
        may live in a virtual environment of its own).
    timeout : float
        How long (s) the server may take to start.

    What the simulator does: each 1 ms of wall time it applies the last torque
    received (clipped to ±87/12 N m) plus its own gravity model's torque
    (Pinocchio on its FR3 URDF, hand included), steps MuJoCo, and sends the
    state. ``tau_ext_hat_filtered`` is the applied torque, not an estimate,
    and ``O_F_ext_hat_K`` is zero: the controller gets no wrench in simulation.
    """

    def __init__(
        self,
        ip: str | None = None,
        *,
        load: float = 0.0,
        q0: ArrayLike | None = None,
        python: str | None = None,
        timeout: float = 60.0,
    ) -> None:
        if not (math.isfinite(load) and load >= 0):
            raise ConfigError(f"load must be a finite mass ≥ 0 (kg), got {load!r}")
        self.ip = ip
        self.load = float(load)
        self.q0 = None if q0 is None else posture_of("q0", q0)
        self.python = python or sys.executable
        self.timeout = float(timeout)
        self.process: subprocess.Popen[str] | None = None

    def __enter__(self) -> Simulator:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def start(self) -> None:
        """Start the server and wait until it listens."""
        ip = self.ip or _free_address()
        args = [self.python, str(SERVER), "--ip", ip, "--load", repr(self.load)]
        if self.q0 is not None:
            args += ["--q0", *map(repr, self.q0.tolist())]
        self.process = subprocess.Popen(
            args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        deadline = time.monotonic() + self.timeout
        assert self.process.stdout is not None
        while time.monotonic() < deadline:
            line = self.process.stdout.readline()
            if line.startswith("ready "):
                self.ip = line.split()[1]
                return
            if not line and self.process.poll() is not None:
                break
        err = "" if self.process.stderr is None else self.process.stderr.read()[-2000:]
        self.stop()
        raise RuntimeError(f"franky-sim did not start on {ip} ({' '.join(args)}): {err}")

    def stop(self) -> None:
        """Stop the server (SIGINT, then SIGKILL after 5 s)."""
        p, self.process = self.process, None
        if p is None:
            return
        if p.poll() is None:
            p.send_signal(signal.SIGINT)
            try:
                p.wait(5.0)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        for stream in (p.stdout, p.stderr):
            if stream is not None:
                stream.close()
