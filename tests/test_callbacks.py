"""Python code a call runs can read the object that called it: a progress
callback its controller, a joint controller written in Python the Cartesian
controller in front of it, a path its controller. Each kind reads every public
property of its owner; each case runs in a process of its own with a time
limit, so that a deadlock fails the test instead of hanging it (they hung
before: the call held its object's lock while the Python code ran).

Run as a script (``python tests/test_callbacks.py CASE``), a case prints what
each read gave, as JSON.
"""

from __future__ import annotations

import inspect
import json
import subprocess
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def public_properties(obj: Any) -> list[str]:
    """The names of the public properties of ``obj``'s class (Python
    properties and the compiled classes' getters)."""
    names = []
    for name in dir(type(obj)):
        if name.startswith("_"):
            continue
        attr = inspect.getattr_static(type(obj), name)
        if isinstance(attr, property) or type(attr).__name__ == "getset_descriptor":
            names.append(name)
    return names


class Reads:
    """What each read of an object's properties gave: its type, or the
    exception, by property; and how many times it read."""

    def __init__(self) -> None:
        self.calls = 0
        self.failed: dict[str, str] = {}
        self.steps: list[int] = []

    def read(self, *objects: Any) -> None:
        self.calls += 1
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            for obj in objects:
                for name in public_properties(obj):
                    error = self._error(obj, name)
                    if error is not None:
                        self.failed[f"{type(obj).__name__}.{name}"] = error

    @staticmethod
    def _error(obj: Any, name: str) -> str | None:
        """What reading ``obj.name`` raised (None: nothing, or the
        AttributeError of a property the object does not have)."""
        try:
            getattr(obj, name)
        except AttributeError as e:
            return None if "has no" in str(e) or "does not say" in str(e) else repr(e)
        except Exception as e:
            return repr(e)
        return None


def _two_link_chain() -> Any:
    import adaptimp
    from adaptimp import mujoco as amj

    return adaptimp.Chain.from_mujoco(amj.two_link(), "ee")


Q0 = np.array([0.25, -0.05])


def _cartesian(joint: Any, **kw: Any) -> Any:
    import adaptimp

    chain = _two_link_chain()
    if isinstance(joint, str):
        return adaptimp.CartesianController(
            chain, joint, q0=Q0, Kd_rot=0.0, tau_max=[17.0, 15.0], **kw
        )
    return adaptimp.CartesianController(chain, joint, q0=Q0, Kd_rot=0.0, **kw)


def case_replay_progress(reads: Reads) -> None:
    import adaptimp

    c = adaptimp.Controller("sf")
    rows = 20_000
    q = np.full((rows, 2), 0.2)
    zero = np.zeros((rows, 2))

    def progress(done: int, total: int) -> None:
        reads.read(c)
        reads.steps.append(c.steps - done)

    c.replay(q, zero, zero, progress=progress)


def case_mujoco_progress(reads: Reads) -> None:
    import adaptimp
    from adaptimp import mujoco as amj

    c = adaptimp.Controller("sf", scenario="robot")

    def progress(done: int, total: int) -> None:
        reads.read(c)
        reads.steps.append(c.steps - done)

    amj.simulate(c, "two_link", T=0.3, progress=progress)


def case_computed_torque_progress(reads: Reads) -> None:
    from adaptimp import mujoco as amj
    from adaptimp.baselines import ComputedTorque

    ct = ComputedTorque("two_link")

    def progress(done: int, total: int) -> None:
        reads.read(ct)
        reads.steps.append(round(ct.t / ct.Ts) - done)

    amj.simulate(ct, "two_link", T=0.3, progress=progress, contact=False)


def case_cartesian_progress(reads: Reads) -> None:
    from adaptimp import mujoco as amj

    cart = _cartesian("sf")
    p0 = _two_link_chain().pose(Q0)[0]

    def progress(done: int, total: int) -> None:
        reads.read(cart, cart.inner)
        reads.steps.append(cart.inner.steps - done)

    path = lambda t: (p0, np.zeros(3), np.zeros(3))  # noqa: E731
    amj.simulate(cart, amj.two_link(), T=0.3, q0=Q0, reference=path, progress=progress)


def case_cartesian_replay_progress(reads: Reads) -> None:
    cart = _cartesian("sf")
    rows = 2_000
    q = np.tile(Q0, (rows, 1))

    def progress(done: int, total: int) -> None:
        reads.read(cart, cart.inner, cart.outer)
        reads.steps.append(cart.outer.core.steps - done)

    cart.outer.core.replay(cart.inner, q, np.zeros_like(q), np.zeros((rows, 6)), None, progress)


class ReadingJoint:
    """A joint controller written in Python (PD) that reads the Cartesian
    controller in front of it at every step."""

    impedance = "external"
    Ts = 1e-3

    def __init__(self, reads: Reads) -> None:
        self.reads = reads
        self.cart: Any = None

    def step(self, m: Any, **sp: Any) -> np.ndarray:
        self.reads.read(self.cart, self.cart.outer)
        return np.asarray(50.0 * (sp["xc"] - m.q) + 5.0 * (sp["dxc"] - m.dq))


def case_python_joint_step(reads: Reads) -> None:
    import adaptimp

    joint = ReadingJoint(reads)
    cart = _cartesian(joint)
    joint.cart = cart
    for _ in range(3):
        cart.step(adaptimp.Measurement(Q0, np.zeros(2)))


def case_python_joint_in_mujoco(reads: Reads) -> None:
    from adaptimp import mujoco as amj

    joint = ReadingJoint(reads)
    cart = _cartesian(joint)
    joint.cart = cart
    p0 = _two_link_chain().pose(Q0)[0]
    path = lambda t: (p0, np.zeros(3), np.zeros(3))  # noqa: E731
    amj.simulate(cart, amj.two_link(), T=0.05, q0=Q0, reference=path)


def case_cartesian_path(reads: Reads) -> None:
    import adaptimp

    p0 = _two_link_chain().pose(Q0)[0]
    holder: list[Any] = []

    def path(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if holder:
            reads.read(holder[0], holder[0].inner)
        return p0, np.zeros(3), np.zeros(3)

    cart = _cartesian("pd", path=path)
    holder.append(cart)
    for _ in range(3):
        cart.step(adaptimp.Measurement(Q0, np.zeros(2)))


def case_computed_torque_path(reads: Reads) -> None:
    import adaptimp
    from adaptimp.baselines import ComputedTorque

    holder: list[Any] = []

    def trajectory(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        reads.read(holder[0])
        return Q0, np.zeros(2), np.zeros(2)

    ct = ComputedTorque("two_link", trajectory=trajectory)
    holder.append(ct)
    for _ in range(3):
        ct.step(adaptimp.Measurement(Q0, np.zeros(2)))


class InPython:
    """A controller of the core behind a Python ``step``."""

    def __init__(self, inner: Any, reads: Reads) -> None:
        self.inner, self.reads = inner, reads

    def step(self, *args: Any, **kwargs: Any) -> Any:
        self.reads.read(self.inner)
        return self.inner.step(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


def case_python_controller_in_mujoco(reads: Reads) -> None:
    import adaptimp
    from adaptimp import mujoco as amj

    inner = adaptimp.Controller("sf", scenario="robot")
    amj.simulate(
        InPython(inner, reads), "two_link", T=0.05, progress=lambda d, t: reads.read(inner)
    )


CASES: dict[str, Callable[[Reads], None]] = {
    name[len("case_") :]: fn for name, fn in globals().items() if name.startswith("case_")
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_callback_reads_every_property_of_its_owner(case: str) -> None:
    proc = subprocess.run(
        [sys.executable, __file__, case], capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.splitlines()[-1])
    assert out["calls"] > 0
    assert out["failed"] == {}
    # A progress callback reads the controller as it is after `done` steps.
    assert set(out["steps"]) <= {0}


def test_a_callback_cannot_change_the_controller_it_reads() -> None:
    """A progress callback that steps or resets its own controller is
    refused by name (the run goes on from the state it holds), not a
    deadlock; the run ends with that error."""
    import adaptimp

    c = adaptimp.Controller("sf")
    q = np.full((200, 2), 0.2)
    zero = np.zeros((200, 2))
    with pytest.raises(RuntimeError, match="can read the Controller, not change it"):
        c.replay(q, zero, zero, progress=lambda done, total: c.reset())
    assert c.steps == 200


if __name__ == "__main__":
    reads = Reads()
    CASES[sys.argv[1]](reads)
    print(json.dumps({"calls": reads.calls, "failed": reads.failed, "steps": reads.steps}))
