"""Controllers written in Python in the core's closed loop on MuJoCo (SPEC §13.1):
the core's loop calls such a controller back once a period, and gives the bits the
Python loop gave before it was deleted.

The digests in ``tests/data/python_loop.json`` were written by the Python loop
(``mujoco._python_loop``, the loop every controller the core could not step took
until it was deleted) with ``python tests/test_mujoco_callback.py --write`` on the
commit before the core's loop took these controllers over. Each case's arrays,
metrics and the controller left behind are compared digest by digest (bit for
bit; a NaN is any NaN). The runs on a model whose wrench comes from its contacts
(no force sensor) are compared to the recorded rows within a tolerance instead:
the Python loop summed MuJoCo's contact list in NumPy, the core reads the same
contact forces from MuJoCo's per-body external forces (``cfrc_ext``), which
round differently (the wrench agrees to 1e-14 N, docs/mujoco.md).
"""

from __future__ import annotations

import hashlib
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

import adaptimp
from adaptimp import _models
from adaptimp import mujoco as amj
from adaptimp.baselines import ComputedTorque

DATA = Path(__file__).parent / "data" / "python_loop.json"

ARRAYS = (
    "t", "q", "dq", "ddq", "xc", "dxc", "ddxc", "xd", "dq_hat", "tau", "tau_sat", "tau_e",
    "zeta", "z1", "x_ee", "wrench_ee", "w_norms",
)  # fmt: skip


def digest(value: Any) -> str:
    """The shape and the SHA-256 of a float64 array's bytes (NaN made one NaN)."""
    a = np.ascontiguousarray(np.asarray(value, dtype=np.float64))
    a = np.where(np.isnan(a), math.nan, a)
    return f"{a.shape}:{hashlib.sha256(a.astype('<f8').tobytes()).hexdigest()[:32]}"


def _exact(value: Any) -> Any:
    """A metric value as exact text (float.hex; NaN as 'nan')."""
    if isinstance(value, list):
        return [_exact(v) for v in value]
    if isinstance(value, float):
        return "nan" if math.isnan(value) else value.hex()
    return value


# ---------------------------------------------------------------------------
# Controllers written in Python.
# ---------------------------------------------------------------------------


class PythonPD:
    """Joint PD with gravity compensation written in Python, on a reference."""

    Ts = 1e-3

    def __init__(self) -> None:
        self.arm = adaptimp.TwoLinkArm()
        self.Kp, self.Kd = np.array([60.0, 40.0]), np.array([8.0, 5.0])
        self.tau = np.zeros(2)
        self.z1 = np.zeros(2)
        self.calls = 0

    def step(self, q: Any, tau_e: Any, dq: Any = None, **sp: Any) -> np.ndarray:
        q, dq = np.asarray(q), np.asarray(dq)
        self.z1 = sp["xc"] - q
        self.tau = self.arm.G(q) + self.Kp * self.z1 + self.Kd * (sp["dxc"] - dq) - tau_e
        self.calls += 1
        return self.tau * 1.2  # beyond what it says it commands: the loop saturates


class InPython:
    """A controller of the core behind a Python object: its ``step`` in Python."""

    def __init__(self, inner: Any) -> None:
        self.inner = inner

    def step(self, *args: Any, **kwargs: Any) -> Any:
        return self.inner.step(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


class OwnComputedTorque(ComputedTorque):
    """Computed torque with a ``step`` of its own (Python)."""

    def step(self, *args: Any, **kwargs: Any) -> Any:
        return super().step(*args, **kwargs)


def bare_two_link() -> mujoco.MjModel:
    """The paper's arm with its ceiling and no sensor: the wrench from the contacts."""
    spec = mujoco.MjSpec.from_file(str(_models.TWO_LINK_XML))
    for sensor in list(spec.sensors):
        spec.delete(sensor)
    return spec.compile()


def _up(p0: np.ndarray) -> Callable[[float], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The tip up at 0.1 m/s for 1 s, then held: into the ceiling."""

    def path(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = min(t, 1.0)
        v = 0.1 if t < 1.0 else 0.0
        return p0 + np.array([0.0, 0.0, 0.1 * s]), np.array([0.0, 0.0, v]), np.zeros(3)

    return path


def _cartesian(joint: Any) -> adaptimp.CartesianController:
    model = amj.two_link()
    chain = adaptimp.Chain.from_mujoco(model, "ee")
    q0 = np.array([0.25, -0.05])
    if joint == "sf":
        return adaptimp.CartesianController(chain, "sf", q0=q0, Kd_rot=0.0, tau_max=[17.0, 15.0])
    return adaptimp.CartesianController(chain, joint, q0=q0, Kd_rot=0.0, force_feedforward=True)


def _cartesian_reference() -> Any:
    chain = adaptimp.Chain.from_mujoco(amj.two_link(), "ee")
    return _up(chain.pose(np.array([0.25, -0.05]))[0])


def case_pd_reference() -> tuple[Any, Any, dict[str, Any]]:
    return PythonPD(), "two_link", {"T": 1.0, "reference": amj.paper_circle()}


def case_sf_own_trajectory() -> tuple[Any, Any, dict[str, Any]]:
    ctrl = InPython(adaptimp.Controller("sf", "robot"))
    return ctrl, "two_link", {"T": 1.0, "record_every": 2}


def case_ct_own_trajectory() -> tuple[Any, Any, dict[str, Any]]:
    return ComputedTorque(mass_scale=1.3), "two_link", {"T": 1.0, "contact": False}


def case_ct_reference() -> tuple[Any, Any, dict[str, Any]]:
    kw = {"T": 1.0, "reference": amj.paper_circle(), "q0": [0.1, 0.3]}
    return ComputedTorque(), "two_link", kw


def case_cartesian_python_joint() -> tuple[Any, Any, dict[str, Any]]:
    joint = OwnComputedTorque("two_link", Ts=1e-3, tau_max=[17.0, 15.0], impedance="external")
    kw = {"T": 0.6, "reference": _cartesian_reference(), "q0": [0.25, -0.05]}
    return _cartesian(joint), amj.two_link(), kw


def case_cartesian_in_python() -> tuple[Any, Any, dict[str, Any]]:
    kw = {"T": 1.2, "reference": _cartesian_reference(), "q0": [0.25, -0.05], "record_every": 3}
    return InPython(_cartesian("sf")), amj.two_link(), kw


def case_contact_list_sf() -> tuple[Any, Any, dict[str, Any]]:
    return "sf", bare_two_link(), {"T": 2.0}


def case_contact_list_pd() -> tuple[Any, Any, dict[str, Any]]:
    return PythonPD(), bare_two_link(), {"T": 1.5, "reference": amj.paper_circle()}


CASES: dict[str, Callable[[], tuple[Any, Any, dict[str, Any]]]] = {
    "pd_reference": case_pd_reference,
    "sf_own_trajectory": case_sf_own_trajectory,
    "ct_own_trajectory": case_ct_own_trajectory,
    "ct_reference": case_ct_reference,
    "cartesian_python_joint": case_cartesian_python_joint,
    "cartesian_in_python": case_cartesian_in_python,
}
"""Cases compared bit for bit."""

CONTACT_LIST: dict[str, Callable[[], tuple[Any, Any, dict[str, Any]]]] = {
    "contact_list_sf": case_contact_list_sf,
    "contact_list_pd": case_contact_list_pd,
}
"""Cases on a model measured through its contacts, compared within a tolerance."""


def _left_behind(ctrl: Any) -> dict[str, str]:
    """Digests of what the controller holds after the run."""
    out: dict[str, str] = {}
    if isinstance(ctrl, InPython):
        ctrl = ctrl.inner
    if isinstance(ctrl, adaptimp.CartesianController):
        for name in ("xc", "dxc", "ddxc", "xd", "z1", "force", "tau", "q_d"):
            out[name] = digest(getattr(ctrl, name))
        out["_k"] = str(ctrl._k)
        for name, rows in ctrl.arrays().items():
            out[f"log.{name}"] = digest(rows)
        ctrl = ctrl.inner
    if isinstance(ctrl, adaptimp.Controller):
        out["steps"] = str(ctrl.steps)
        out["zeta"] = digest(ctrl.zeta)
        out["weights.G"] = digest(ctrl.weights["G"])
    if isinstance(ctrl, ComputedTorque):
        out["t"] = float(ctrl.t).hex()
        for name in ("tau", "tau_sat", "xc", "xd", "z1"):
            out[name] = digest(getattr(ctrl, name))
    if isinstance(ctrl, PythonPD):
        out["calls"] = str(ctrl.calls)
        out["tau"] = digest(ctrl.tau)
    return out


def record(make: Callable[[], tuple[Any, Any, dict[str, Any]]]) -> dict[str, Any]:
    """A case's run: digests of its arrays, task rows, metrics and controller."""
    ctrl, model, kw = make()
    res = amj.simulate(ctrl, model, **kw)
    arrays = {name: digest(getattr(res, name)) for name in ARRAYS}
    task = {name: digest(v) for name, v in (res.task or {}).items()}
    metrics = {key: _exact(value) for key, value in res.metrics.items()}
    return {"arrays": arrays, "task": task, "metrics": metrics, "left": _left_behind(ctrl)}


def record_rows(make: Callable[[], tuple[Any, Any, dict[str, Any]]]) -> dict[str, Any]:
    """A contact-list case's rows (every 25th) and metrics, as exact text."""
    ctrl, model, kw = make()
    res = amj.simulate(ctrl, model, **kw)
    rows = {
        name: [[v.hex() for v in row] for row in getattr(res, name)[::25]]
        for name in ("q", "tau_sat", "wrench_ee", "tau_e")
    }
    return {"rows": rows, "metrics": {k: _exact(v) for k, v in res.metrics.items()}}


@pytest.fixture(scope="module")
def frozen() -> dict[str, Any]:
    with DATA.open(encoding="utf-8") as f:
        return dict(json.load(f))


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_python_controller_gives_the_python_loops_bits(name: str, frozen: dict[str, Any]) -> None:
    got, want = record(CASES[name]), frozen[name]
    assert got["arrays"] == want["arrays"]
    assert got["task"] == want["task"]
    assert got["metrics"] == want["metrics"]
    assert got["left"] == want["left"]


def _floats(rows: list[list[str]]) -> np.ndarray:
    return np.array([[float.fromhex(v) for v in row] for row in rows])


@pytest.mark.parametrize("name", sorted(CONTACT_LIST))
def test_a_contact_measured_model_gives_the_python_loops_run(
    name: str, frozen: dict[str, Any]
) -> None:
    ctrl, model, kw = CONTACT_LIST[name]()
    res = amj.simulate(ctrl, model, **kw)
    want = frozen[name]
    assert res.params["wrench_source"] == "contact"
    for field, atol in (("q", 1e-12), ("tau_sat", 1e-9), ("wrench_ee", 1e-9), ("tau_e", 1e-9)):
        rows = np.asarray(getattr(res, field))[::25]
        np.testing.assert_allclose(rows, _floats(want["rows"][field]), rtol=0, atol=atol)
    assert res.metrics["steps_in_contact"] == want["metrics"]["steps_in_contact"] > 100


if __name__ == "__main__" and sys.argv[1:] == ["--write"]:
    out = {name: record(make) for name, make in CASES.items()}
    out.update({name: record_rows(make) for name, make in CONTACT_LIST.items()})
    DATA.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    print(f"wrote {DATA}")
