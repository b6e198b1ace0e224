"""Controllers written in Python in the core's closed loop on MuJoCo (SPEC §13.1):
the core's loop calls such a controller back once a period, and gives the bits the
Python loop gave before it was deleted.

The digests in ``tests/data/python_loop.json`` were written by the Python loop
(``mujoco._python_loop``, the loop every controller the core could not step took
until it was deleted) with ``python tests/test_mujoco_callback.py --write`` on the
commit before the core's loop took these controllers over; those of the runs the
core stepped natively already (``NATIVE``: they must not change) by the build of
that commit, with ``--write-native``. The cases that run the core's
kinematics and dynamics (the Cartesian and computed-torque ones) were written
again by the build that rewrote them (SPEC §16, (20.2); agreeing with
Pinocchio to 1e-12): against the earlier digests their metrics moved by at
most 3e-12 relative, one run in contact by 2e-5 in a peak torque, the
rounding the contact amplifies; the two joint-space computed-torque cases
again when its reference came to advance exactly for the held acceleration
(SPEC (20.3); their RMS ‖z1‖ in contact 0.0952 and 0.1493 → 0.0952 and
0.1496 rad). Each case's arrays,
metrics and the controller left behind are compared digest by digest (bit for
bit; a NaN is any NaN). The runs on a model whose wrench comes from its contacts
(no force sensor) are compared to the recorded rows within a tolerance instead:
the Python loop summed MuJoCo's contact list in NumPy, the core reads the same
contact forces from MuJoCo's per-body external forces (``cfrc_ext``), which
round differently (the wrench agrees to 1e-14 N, docs/mujoco.md).

Two cases were recorded again since, by this loop, for a change of the
controller, not of the loop: the 2-link arm's Cartesian runs
(``cartesian_python_joint``, ``cartesian_in_python``) start nearly stretched
(σ_min(J) ≈ 0.008 m/rad), inside the singular region where the outer loop's
damping now grows (SPEC (C3')).
The native output-feedback run (``native_disturbed``, the robot preset) was
written again, ``--write-native`` by this loop's build, when output feedback
came to compare its estimate with the reference the observer's lag back (SPEC
(9.1)): its RMS ‖z1‖ 0.25495 → 0.25462 rad (a noisy, delayed, faulted 1 s run,
75 % saturated), the other native cases' digests unchanged; and again when
the lead came to extrapolate the commanded motion, not the wall's sampled
τe (SPEC (9.2)): 0.25462 → 0.25457 rad, the others unchanged.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

import adaptimp
import mujoco_probe
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

    def step(self, m: Any, **sp: Any) -> np.ndarray:
        q, tau_e, dq = m.q, m.tau_e, m.dq
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


def case_native_sf_contact() -> tuple[Any, Any, dict[str, Any]]:
    return adaptimp.Controller("sf", "robot"), "two_link", {"T": 1.0, "record_every": 3}


def case_native_disturbed() -> tuple[Any, Any, dict[str, Any]]:
    kw = {
        "T": 1.0, "noise_q": 1e-3, "seed": 2, "delay": 1, "friction_viscous": 0.3,
        "fault": adaptimp.Fault("stale", 0.4, 0.05),
    }  # fmt: skip
    return adaptimp.Controller("of", "robot"), "two_link", kw


def _first_panda_gains(sc: Any) -> dict[str, Any]:
    """The Panda scenario's joint gains as they were when the digests were
    written (the scenario's own rule, since replaced by the core's: SPEC §15's
    Kp_i = 0.25/(Ts (D⁻¹)_ii), Kζ_i = (1 + Kp_i²)/2 + 10, K1 = 20 s⁻¹, kr_i =
    φ Kp_i/2): the run this pins is the loop's, not the gain rule's."""
    from adaptimp import tuning

    d = tuning.inertia(sc.pin_model, sc.q0)
    kp = 0.25 / (sc.Ts * np.diag(np.linalg.inv(d)))
    return {
        "Kp": kp.tolist(),
        "Kzeta": ((1 + kp**2) / 2 + 10).tolist(),
        "K1": [20.0] * sc.n,
        "kr": (0.05 / 2 * kp).tolist(),
        "fallback_damping": kp.tolist(),
    }


def case_native_cartesian_panda() -> tuple[Any, Any, dict[str, Any]]:
    from adaptimp.scenarios import panda_table as apt

    sc = apt.panda_table()
    ctrl = apt.panda_controller("sf", sc, gains=_first_panda_gains(sc))
    return ctrl, amj.Plant(sc.model), {"T": 0.4, "q0": sc.q0}


def case_native_ct_cartesian() -> tuple[Any, Any, dict[str, Any]]:
    from adaptimp.scenarios import panda_table as apt

    sc = apt.panda_table()
    return apt.panda_controller("ct", sc), amj.Plant(sc.model), {"T": 0.4, "q0": sc.q0}


NATIVE: dict[str, Callable[[], tuple[Any, Any, dict[str, Any]]]] = {
    "native_sf_contact": case_native_sf_contact,
    "native_disturbed": case_native_disturbed,
    "native_cartesian_panda": case_native_cartesian_panda,
    "native_ct_cartesian": case_native_ct_cartesian,
}
"""Controllers the core stepped before: their runs must not change (digests
written by the build before this loop, ``--write-native``)."""

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


POSE = ("pos_err", "rot_err", "rms_pos", "rms_pos_after2", "max_pos_after2", "rms_rot",
        "rms_rot_after2", "max_rot_after2", "rms_pos_first2", "rms_pos_last2")  # fmt: skip
"""What a Cartesian run's result measures after the loop (its pose errors, SPEC
(16.11)): not the loop's bits (tests/test_cartesian_task.py checks them)."""


def record(make: Callable[[], tuple[Any, Any, dict[str, Any]]]) -> dict[str, Any]:
    """A case's run: digests of its arrays, task rows, metrics and controller."""
    ctrl, model, kw = make()
    res = amj.simulate(ctrl, model, **kw)
    arrays = {name: digest(getattr(res, name)) for name in ARRAYS}
    task = {name: digest(v) for name, v in (res.task or {}).items() if name not in POSE}
    metrics = {key: _exact(value) for key, value in res.metrics.items() if key not in POSE}
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


@pytest.mark.parametrize("name", sorted(NATIVE))
def test_a_native_run_gives_the_bits_it_gave(name: str, frozen: dict[str, Any]) -> None:
    got, want = record(NATIVE[name]), frozen[name]
    assert got["arrays"] == want["arrays"]
    assert got["task"] == want["task"]
    assert got["metrics"] == want["metrics"]
    assert got["left"] == want["left"]


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
if __name__ == "__main__" and sys.argv[1:] == ["--write-native"]:
    # Run with the build before the change on PYTHONPATH: the native runs' digests.
    with DATA.open(encoding="utf-8") as f:
        out = json.load(f)
    out.update({name: record(make) for name, make in NATIVE.items()})
    DATA.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    print(f"wrote {DATA}")


# ---------------------------------------------------------------------------
# What the core's loop brings to a controller written in Python.
# ---------------------------------------------------------------------------


def _same(got: amj.MujocoResult, want: amj.MujocoResult, names: tuple[str, ...] = ARRAYS) -> None:
    for name in names:
        if name != "w_norms":
            np.testing.assert_array_equal(getattr(got, name), getattr(want, name), err_msg=name)
    assert set(got.metrics) == set(want.metrics)
    for key, value in want.metrics.items():
        np.testing.assert_array_equal(got.metrics[key], value, err_msg=key)


def test_disturbances_act_on_a_controller_called_back() -> None:
    """SPEC §17 on a controller written in Python: the same bits as the same
    controller stepped natively, under noise, delay, friction and weak motors."""
    kw: dict[str, Any] = {
        "T": 1.0, "noise_q": 1e-3, "noise_dq": 1e-2, "seed": 4, "delay": 2,
        "friction_viscous": 0.5, "friction_coulomb": 0.2, "actuator_fraction": 0.8,
    }  # fmt: skip
    native = amj.simulate(adaptimp.Controller("sf", "robot", delay=2), "two_link", **kw)
    # SPEC (17.1): the loop gives the setpoint of the delayed sample's instant; a
    # controller called back with its own clock would sample t_k instead, so the
    # run hands it the same trajectory as a reference (the native run's rows).
    called = amj.simulate(
        InPython(adaptimp.Controller("sf", "robot", delay=2)), "two_link", reference=native, **kw
    )
    assert (native.params["loop"], called.params["loop"]) == ("native", "callback")
    _same(called, native)
    clean = amj.simulate(InPython(adaptimp.Controller("sf", "robot")), "two_link", T=1.0)
    assert not np.array_equal(called.tau, clean.tau)
    assert called.metrics["steps_in_contact"] > 100


@pytest.mark.parametrize(
    "fault",
    [
        adaptimp.Fault("stale", 0.3, 0.05),
        adaptimp.Fault("actuator_drop", 0.3, 0.1, fraction=0.2),
        adaptimp.Fault("force_bias", 0.3, 0.1, bias=[2.0, -1.0]),
    ],
    ids=["stale", "actuator_drop", "force_bias"],
)
def test_a_fault_acts_on_a_controller_called_back(fault: adaptimp.Fault) -> None:
    native = amj.simulate(adaptimp.Controller("sf", "robot"), "two_link", T=0.6, fault=fault)
    called = amj.simulate(
        InPython(adaptimp.Controller("sf", "robot")), "two_link", T=0.6, fault=fault
    )
    _same(called, native)
    base = amj.simulate(adaptimp.Controller("sf", "robot"), "two_link", T=0.6)
    assert not np.array_equal(called.tau_sat, base.tau_sat)


def test_skipped_steps_and_a_torque_that_is_not_finite_are_refused() -> None:
    """A fault's skipped steps are not called; with a fault, a non-finite torque
    is a refused step (zero torque, the run goes on); without one it ends the
    run, as a ValueError naming it."""
    skip = adaptimp.Fault("skipped", 0.1, 0.01)
    ctrl = PythonPD()
    res = amj.simulate(ctrl, "two_link", T=0.2, reference=amj.paper_circle(), fault=skip)
    assert res.refused is not None
    assert int(np.sum(res.refused)) == 10
    assert ctrl.calls == 190
    native = amj.simulate(
        adaptimp.Controller("pd", "robot"), "two_link", T=0.2, reference=amj.paper_circle(),
        fault=skip,
    )  # fmt: skip
    np.testing.assert_array_equal(res.refused, native.refused)

    class Blows(PythonPD):
        def step(self, m: Any, **sp: Any) -> np.ndarray:
            tau = super().step(m, **sp)
            return np.array([math.nan, 1.0]) if 50 <= self.calls < 55 else tau

    burst = adaptimp.Fault("nan_burst", 1.0, 0.01)  # a window after the run: refusals allowed
    # ... and said: refused steps outside the fault's window (they were silent).
    with pytest.warns(adaptimp.PlantWarning, match=r"^5 of 200 recorded steps were refused "):
        res = amj.simulate(Blows(), "two_link", T=0.2, reference=amj.paper_circle(), fault=burst)
    assert res.refused is not None
    assert np.flatnonzero(res.refused).tolist() == [49, 50, 51, 52, 53]
    np.testing.assert_array_equal(res.tau_sat[49:54], np.zeros((5, 2)))
    with pytest.raises(ValueError, match=r"^tau must be finite, got ") as e:
        amj.simulate(Blows(), "two_link", T=0.2, reference=amj.paper_circle())
    # The words of the loop written in Python, which NumPy's printing gave.
    assert str(e.value) == f"tau must be finite, got {np.array([math.nan, 1.0])}"


class Raises(PythonPD):
    """Raises at its call number ``at``."""

    def __init__(self, at: int) -> None:
        super().__init__()
        self.at = at

    def step(self, m: Any, **sp: Any) -> np.ndarray:
        if self.calls + 1 == self.at:
            raise RuntimeError(f"the controller gave up at call {self.at}")
        return super().step(m, **sp)


def test_an_exception_ends_the_run_with_it_and_the_plant_where_it_was() -> None:
    """An exception of the controller ends the run with that exception (also
    with a fault injected, which refuses only what the core refuses); the
    plant is left at the start of the period that raised, so a run with
    reset=False goes on from there."""
    plant = amj.Plant("two_link")
    ctrl = Raises(at=6)
    with pytest.raises(RuntimeError, match=r"^the controller gave up at call 6$"):
        amj.simulate(ctrl, plant, T=0.2, reference=amj.paper_circle())
    assert ctrl.calls == 5
    assert plant.data.time == pytest.approx(5 * ctrl.Ts, abs=1e-12)
    ctrl.at = 0
    on = amj.simulate(ctrl, plant, T=0.01, reference=amj.paper_circle(), reset=False)
    assert on.rows == 10
    assert plant.data.time == pytest.approx(15 * ctrl.Ts, abs=1e-12)
    with pytest.raises(RuntimeError, match="at call 3"):
        amj.simulate(
            Raises(at=3), "two_link", T=0.2, reference=amj.paper_circle(),
            fault=adaptimp.Fault("stale", 0.0, 0.1),
        )  # fmt: skip


def test_what_a_controller_returns_and_says_is_checked_by_name() -> None:
    class Wide(PythonPD):
        def step(self, m: Any, **sp: Any) -> np.ndarray:
            return np.zeros(3)

    with pytest.raises(ValueError, match=r"^tau must have shape \(2,\), got \(3,\)$"):
        amj.simulate(Wide(), "two_link", T=0.01, reference=amj.paper_circle())

    class Scalar(PythonPD):
        def step(self, m: Any, **sp: Any) -> float:
            return 0.5

    res = amj.simulate(Scalar(), "two_link", T=0.01, reference=amj.paper_circle())
    np.testing.assert_array_equal(res.tau_sat, np.full((10, 2), 0.5))

    class BadXd(PythonPD):
        xd = np.zeros(3)

    with pytest.raises(ValueError, match=r"^the controller's xd must have 2 values, got shape"):
        amj.simulate(BadXd(), "two_link", T=0.01, reference=amj.paper_circle())

    class Word(PythonPD):
        def step(self, m: Any, **sp: Any) -> str:
            return "torque"

    # Text is not a torque ("3.5" was taken as 3.5 N m), nor None (it became
    # NaN: "tau must be finite"), nor a dict: refused naming tau.
    returned = (
        ("torque", "a str of dtype <U6"), (["3.5", "0"], "a list of dtype <U3"),
        (None, "None"), ({"tau": [0, 0]}, "a dict of dtype object"),
    )  # fmt: skip
    for value, what in returned:
        Word.step = lambda self, m, _v=value, **sp: _v  # type: ignore[method-assign,misc]
        with pytest.raises(
            TypeError, match=re.escape(f"the controller's step returned {what} for its torque")
        ):
            amj.simulate(Word(), "two_link", T=0.01, reference=amj.paper_circle())


def test_a_task_space_controller_called_back_refuses_what_acts_on_tau_e() -> None:
    ctrl, model, kw = case_cartesian_in_python()
    with pytest.raises(adaptimp.ConfigError, match="noise_tau_e: a Cartesian controller reads"):
        amj.simulate(ctrl, model, noise_tau_e=0.1, **kw)
    bias = adaptimp.Fault("force_bias", 0.1, 0.1, bias=[1.0, 1.0])
    with pytest.raises(adaptimp.ConfigError, match="force_bias: a Cartesian controller reads"):
        amj.simulate(ctrl, model, fault=bias, **kw)


def test_ctrl_c_in_the_controller_ends_the_run() -> None:
    """SIGINT while the controller's step runs: KeyboardInterrupt, at once."""
    import os
    import signal

    class Interrupted(PythonPD):
        def step(self, m: Any, **sp: Any) -> np.ndarray:
            if self.calls == 20:
                os.kill(os.getpid(), signal.SIGINT)
            return super().step(m, **sp)

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        ctrl = Interrupted()
        with pytest.raises(KeyboardInterrupt):
            amj.simulate(ctrl, "two_link", T=10.0, reference=amj.paper_circle())
        assert 20 <= ctrl.calls < 40
    finally:
        signal.signal(signal.SIGINT, previous)


def test_many_substeps_are_interrupted() -> None:
    """A progress callback that raises ends a run of 10 000 MuJoCo steps per
    period with its exception; the plant and controller run again after."""
    plant = amj.Plant("two_link")
    ctrl = adaptimp.Controller("sf", "robot")

    def interrupt(done: int, total: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        amj.simulate(ctrl, plant, T=5.0, substeps=10_000, progress=interrupt)
    assert plant.data.time < 5.0
    res = amj.simulate(PythonPD(), plant, T=0.05, reference=amj.paper_circle())
    assert res.rows == 50


_SUBSTEPS = "substeps must be an integer (MuJoCo steps per period), got "
_BOUND = "condition 1 ≤ substeps ≤ 10 000 is violated: substeps = {} (MuJoCo steps per period)"


@pytest.mark.parametrize(
    ("kw", "error", "message"),
    [
        ({"substeps": 2.5}, TypeError, _SUBSTEPS + "float"),
        ({"substeps": True}, TypeError, _SUBSTEPS + "bool"),
        ({"substeps": "3"}, TypeError, _SUBSTEPS + "str"),
        ({"substeps": 0}, adaptimp.ConfigError, _BOUND.format(0)),
        ({"substeps": -2}, adaptimp.ConfigError, _BOUND.format(-2)),
        ({"substeps": 10_001}, adaptimp.ConfigError, _BOUND.format(10001)),
        ({"substeps": 10**8}, adaptimp.ConfigError, _BOUND.format(100000000)),
        ({"T": "1.0"}, TypeError, "T must be a real number (s), got str"),
        ({"T": True}, TypeError, "T must be a real number (s), got bool"),
        ({"T": [1.0]}, TypeError, "T must be a real number (s), got list"),
        ({"Ts": True}, TypeError, "Ts must be a real number (s), got bool"),
        ({"Ts": "1e-3"}, TypeError, "Ts must be a real number (s), got str"),
    ],
)
def test_the_run_arguments_are_refused_by_name_before_any_work(
    kw: dict[str, Any], error: type[Exception], message: str
) -> None:
    """Issue 33 D: before the model is even read (here a file that is not there)."""
    with pytest.raises(error) as e:
        amj.simulate("sf", "nowhere.xml", **kw)
    assert str(e.value) == message


def test_numpy_numbers_are_run_arguments() -> None:
    res = amj.simulate("pd", "two_link", T=np.float64(0.01), substeps=np.int64(3), contact=False)
    assert (res.rows, res.params["substeps"]) == (10, 3)
    assert res.params["timestep"] == pytest.approx(1e-3 / 3)
    res = amj.simulate("pd", "two_link", T=0.01, Ts=np.float32(1e-3), substeps=10_000)
    assert res.params["substeps"] == 10_000
    slow = mujoco_probe.Hold([0.0, 0.0], Ts=1.0)  # 20 000 of the model's 50 µs
    with pytest.raises(adaptimp.ConfigError) as e:
        amj.simulate(slow, "two_link", T=1.0)
    assert str(e.value) == (
        "condition 1 ≤ substeps ≤ 10 000 is violated: substeps = round(Ts / the model's "
        "timestep) = 20000: give substeps"
    )
