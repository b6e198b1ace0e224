"""Every entry point refuses a wrong input by the name the user wrote: a walk
over the public API with a table of wrong values per kind of argument (text
for numbers, bools for numbers, NaN, wrong shapes, complex numbers, numbers
for paths). Each call must raise (``TypeError``, ``ValueError`` or an adaptimp
error, never accept), and the message must name the argument as it was
written (``q``, not the core's ``x``; ``span``, not Python's "must be real
number, not str")."""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement, tuning
from adaptimp import mujoco as amj
from adaptimp.baselines import ComputedTorque

HOBBY = Path(__file__).parent / "data" / "hobby_arm.urdf"

# Wrong values by kind of argument (each a list of (label, value)).
NAN = math.nan
SCALAR = [("text", "2"), ("bool", True), ("NaN", NAN), ("list", [1.0, 2.0]), ("complex", 1j)]
# A number or one per joint (n = 2 here).
PER_JOINT = [("text", "2"), ("bool", True), ("NaN", NAN), ("3 values", [1.0, 2.0, 3.0]),
             ("complex", 1j)]  # fmt: skip
POSITIVE = [*SCALAR, ("zero", 0.0), ("negative", -1.0), ("infinite", math.inf)]
COUNT = [("text", "2"), ("bool", True), ("float", 2.5), ("zero", 0), ("NaN", NAN)]
TEXT = [("number", 3), ("None", None), ("list", ["a"]), ("bytes", b"sf")]
PATH = [("number", 3), ("list", [1, 2]), ("dict", {"a": 1})]


def vector(n: int) -> list[tuple[str, Any]]:
    """Wrong values for an (n,) array of reals."""
    return [
        ("text", "abc"),
        ("bools", [True] * n),
        ("NaN", [NAN] * n),
        ("short", [0.1] * (n - 1)),
        ("long", [0.1] * (n + 1)),
        ("2-D", [[0.1] * n]),
        ("complex", [1j] * n),
        ("strings", ["0.1"] * n),
    ]


def table(k: int, n: int) -> list[tuple[str, Any]]:
    """Wrong values for a (k, n) table of reals."""
    return [
        ("text", "abc"),
        ("NaN", np.full((k, n), NAN)),
        ("1-D", np.zeros(n)),
        ("wide", np.zeros((k, n + 1))),
        ("complex", np.full((k, n), 1j)),
    ]


def _no_nan(values: list[tuple[str, Any]]) -> list[tuple[str, Any]]:
    return [(label, v) for label, v in values if label != "NaN"]


def _controller() -> adaptimp.Controller:
    return adaptimp.Controller("sf", scenario="robot")


def _chain() -> adaptimp.Chain:
    return adaptimp.Chain.from_urdf(HOBBY)


def _cart(**kw: Any) -> adaptimp.CartesianController:
    chain = adaptimp.Chain.from_mujoco(amj.two_link(), "ee")
    return adaptimp.CartesianController(
        chain, "pd", q0=[0.25, -0.05], Kd_rot=0.0, tau_max=[17.0, 15.0], **kw
    )


Q2 = [0.25, -0.05]
M2 = Measurement(Q2, [0.0, 0.0])

# (entry point, the argument's name as written, its wrong values, the call).
CASES: list[tuple[str, str, list[tuple[str, Any]], Callable[[Any], Any]]] = [
    ("simulate", "case", TEXT, lambda v: adaptimp.simulate(v, T=0.01)),
    ("simulate", "T", POSITIVE, lambda v: adaptimp.simulate("pd", T=v)),
    ("simulate", "Kp", PER_JOINT, lambda v: adaptimp.simulate("pd", T=0.01, Kp=v)),
    ("simulate", "record_every", COUNT, lambda v: adaptimp.simulate("pd", T=0.01, record_every=v)),
    ("Controller", "case", TEXT, lambda v: adaptimp.Controller(v)),
    ("Controller", "n", COUNT, lambda v: adaptimp.Controller("pd", n=v)),
    ("Controller", "Ts", POSITIVE, lambda v: adaptimp.Controller("pd", Ts=v)),
    ("Controller", "tau_max", PER_JOINT, lambda v: adaptimp.Controller("pd", tau_max=v)),
    # A measurement's values are the controller's to judge (NaN: a refused step).
    ("Measurement", "q", _no_nan(vector(2)), lambda v: Measurement(v, [0.0, 0.0])),
    ("Measurement", "dq", _no_nan(vector(2)), lambda v: Measurement(Q2, v)),
    ("Measurement", "tau_e", _no_nan(vector(2)), lambda v: Measurement(Q2, [0.0, 0.0], tau_e=v)),
    ("Controller.step", "q", vector(2), lambda v: _controller().step(Measurement(v, [0, 0]))),
    ("Controller.step", "xc", vector(2), lambda v: _controller().step(M2, xc=v)),
    ("Controller.replay", "q", table(3, 2),
     lambda v: _controller().replay(v, np.zeros((3, 2)), np.zeros((3, 2)))),
    ("Controller.replay", "tau_e", table(3, 2),
     lambda v: _controller().replay(np.zeros((3, 2)), v, np.zeros((3, 2)))),
    ("TwoLinkArm.D", "q", vector(2), lambda v: adaptimp.TwoLinkArm().D(v)),
    ("PlanarArm", "n", COUNT, lambda v: adaptimp.PlanarArm(v)),
    ("Chain.fk", "q", vector(5), lambda v: _chain().fk(v)),
    ("Chain.jacobian", "q", vector(5), lambda v: _chain().jacobian(v)),
    ("Chain.jdot_qdot", "dq", vector(5), lambda v: _chain().jdot_qdot([0.0] * 5, v)),
    ("Chain.motion", "q", table(2, 5),
     lambda v: _chain().motion(v, np.zeros((2, 5)), np.zeros((2, 5)))),
    ("Chain.from_urdf", "source", PATH, lambda v: adaptimp.Chain.from_urdf(v)),
    ("Chain.from_urdf", "tip", [("number", 3), ("list", ["a"])],
     lambda v: adaptimp.Chain.from_urdf(HOBBY, tip=v)),
    ("Chain.from_urdf", "fix", [("text", "base_yaw"), ("number", 3)],
     lambda v: adaptimp.Chain.from_urdf(HOBBY, fix=v)),
    ("Chain.from_mujoco", "model", [*PATH, ("None", None)],
     lambda v: adaptimp.Chain.from_mujoco(v)),
    ("Chain.from_mujoco", "fix", [("text", "joint1"), ("number", 3)],
     lambda v: adaptimp.Chain.from_mujoco(amj.two_link(), fix=v)),
    ("CartesianController", "q0", vector(2),
     lambda v: adaptimp.CartesianController(
         adaptimp.Chain.from_mujoco(amj.two_link(), "ee"), "pd", q0=v, Kd_rot=0.0)),
    ("CartesianController.step", "xc", vector(3), lambda v: _cart().step(M2, xc=v)),
    # (A position-only controller reads no R: one that is not a rotation is
    # the 6-D controller's to refuse, test_cartesian_refusals.py.)
    ("CartesianController.step", "R", [("text", "abc"), ("NaN", np.full((3, 3), NAN)),
                                       ("2-D", np.eye(2))],
     lambda v: _cart().step(M2, xc=[0.3, 0.0, 0.2], R=v)),
    ("PoseTarget", "p", vector(3), lambda v: adaptimp.PoseTarget(p=v)),
    ("PoseTarget.at", "R", [("text", "abc"), ("NaN", np.full((3, 3), NAN)), ("2-D", np.eye(2))],
     lambda v: adaptimp.PoseTarget.at([0.1, 0.0, 0.2], v)),
    ("Fault", "start", SCALAR, lambda v: adaptimp.Fault("nan_burst", v, 0.1)),
    ("Fault", "duration", POSITIVE, lambda v: adaptimp.Fault("nan_burst", 0.1, v)),
    ("Fault", "kind", TEXT, lambda v: adaptimp.Fault(v, 0.1, 0.1)),
    ("SimResult.save", "path", PATH, lambda v: _RUN.save(v)),
    ("SimResult.save", "every", COUNT, lambda v: _RUN.save("/dev/null/x", every=v)),
    ("SimResult.load", "path", PATH, lambda v: adaptimp.SimResult.load(v)),
    ("ComputedTorque", "Ts", POSITIVE, lambda v: ComputedTorque(Ts=v)),
    ("ComputedTorque", "mass_scale", POSITIVE, lambda v: ComputedTorque(mass_scale=v)),
    ("ComputedTorque", "payload", SCALAR, lambda v: ComputedTorque(payload=v)),
    ("ComputedTorque", "Kp", vector(2)[:-1], lambda v: ComputedTorque(Kp=v)),
    ("ComputedTorque", "tau_max", vector(2)[:-1], lambda v: ComputedTorque(tau_max=v)),
    ("ComputedTorque.step", "q", vector(2),
     lambda v: ComputedTorque().step(Measurement(v, [0, 0]))),
    ("ComputedTorque.inverse_dynamics", "ddq", vector(2),
     lambda v: ComputedTorque().inverse_dynamics(Q2, [0.0, 0.0], v)),
    ("ComputedTorque.mass_matrix", "q", vector(2), lambda v: ComputedTorque().mass_matrix(v)),
    ("mujoco.simulate", "T", POSITIVE, lambda v: amj.simulate("pd", "two_link", T=v)),
    ("mujoco.simulate", "Ts", POSITIVE, lambda v: amj.simulate("pd", "two_link", T=0.01, Ts=v)),
    ("mujoco.simulate", "substeps", COUNT,
     lambda v: amj.simulate("pd", "two_link", T=0.01, substeps=v)),
    ("mujoco.simulate", "q0", vector(2), lambda v: amj.simulate("pd", "two_link", T=0.01, q0=v)),
    ("mujoco.simulate", "record_every", COUNT,
     lambda v: amj.simulate("pd", "two_link", T=0.01, record_every=v)),
    ("mujoco.simulate", "payload", SCALAR,
     lambda v: amj.simulate("pd", "two_link", T=0.01, payload=v)),
    ("mujoco.simulate", "task", [("text", "abc"), ("number", 3)],
     lambda v: amj.simulate("pd", "two_link", T=0.01, task=v)),
    ("mujoco.Plant", "model", PATH, lambda v: amj.Plant(v)),
    ("mujoco.cartesian_task", "Ts", POSITIVE, lambda v: amj.cartesian_task(HOBBY, Ts=v)),
    ("mujoco.cartesian_task", "span", POSITIVE, lambda v: amj.cartesian_task(HOBBY, span=v)),
    ("mujoco.cartesian_task", "pose", [("text", "abc"), ("number", 3)],
     lambda v: amj.cartesian_task(HOBBY, pose=v)),
    ("mujoco.cartesian_task", "q0", vector(5)[:-2], lambda v: amj.cartesian_task(HOBBY, q0=v)),
    ("tuning.suggest", "q0", vector(2),
     lambda v: tuning.suggest(adaptimp.TwoLinkArm(), v, [17.0, 15.0])),
    ("tuning.suggest", "tau_max", vector(2)[:-1],
     lambda v: tuning.suggest(adaptimp.TwoLinkArm(), Q2, v)),
    ("tuning.suggest", "Ts", POSITIVE,
     lambda v: tuning.suggest(adaptimp.TwoLinkArm(), Q2, [17.0, 15.0], Ts=v)),
]  # fmt: skip

_RUN = adaptimp.simulate("pd", T=0.01)


def _names(message: str, name: str) -> bool:
    """Whether ``message`` names ``name`` as a word (``q`` in "q[0]", not in "quat")."""
    return re.search(rf"(?<![A-Za-z_]){re.escape(name)}(?![A-Za-z_])", message) is not None


@pytest.mark.parametrize(
    ("entry", "name", "wrong", "call"), CASES, ids=[f"{e}:{n}" for e, n, _, _ in CASES]
)
def test_a_wrong_input_is_refused_by_its_name(
    entry: str, name: str, wrong: list[tuple[str, Any]], call: Callable[[Any], Any]
) -> None:
    unnamed = []
    for label, value in wrong:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                call(value)
            except (TypeError, ValueError, adaptimp.AdaptimpError) as e:
                if not _names(str(e), name):
                    unnamed.append(f"{label} {value!r:.30}: {type(e).__name__}: {str(e)[:160]}")
            else:
                unnamed.append(f"{label} {value!r:.30}: accepted")
    assert unnamed == [], f"{entry}({name}=…)"
