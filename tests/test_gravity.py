"""Gravity fed forward from the nominal model, SPEC (20.10): on request the law
adds G₀(q) of the arm's description at the measured position, so that a robot
that does not compensate gravity itself does not sag while the networks learn;
by default (the paper's law, a robot that compensates it) nothing changes."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

import adaptimp
from adaptimp import mujoco as amj

HOBBY = Path(__file__).resolve().parent / "data" / "hobby_arm.urdf"


@pytest.fixture(scope="module")
def plant() -> amj.Plant:
    with pytest.warns(UserWarning, match="effort limit"):
        return amj.Plant(HOBBY)


def _gravity_at(plant: amj.Plant, q: np.ndarray) -> np.ndarray:
    """MuJoCo's own G(q) of the plant (qfrc_bias at rest)."""
    plant.reset(q)
    return plant.bias()


def test_the_first_torque_at_rest_is_the_model_s_gravity(plant: amj.Plant) -> None:
    """At rest at the start, the first torque of SF with gravity="model" is
    G(q0) of the plant to 1e-12 of its largest entry (the core's RNEA of the
    description against MuJoCo's), joint space and Cartesian alike; without it,
    zero on every joint (the finding: the arm sags until Ĝ has learnt)."""
    task = amj.cartesian_task(plant)
    g = _gravity_at(plant, task.q0)
    assert np.max(np.abs(g)) > 0.1
    for kwargs in ({"task": task}, {}):
        off = amj.simulate("sf", plant, T=0.01, **kwargs)  # type: ignore[arg-type]
        on = amj.simulate("sf", plant, T=0.01, gravity="model", **kwargs)  # type: ignore[arg-type]
        np.testing.assert_array_equal(off.tau[0], np.zeros(5))
        q0 = on.q[0]
        np.testing.assert_allclose(
            on.tau[0], _gravity_at(plant, q0), rtol=0, atol=1e-12 * np.max(np.abs(g))
        )
    # Held at its start for 1 s, the Cartesian task's tip sags by about a
    # millimetre without the feedforward, and by nothing with it.
    off = amj.simulate("sf", plant, T=1.0, task=task)
    on = amj.simulate("sf", plant, T=1.0, task=task, gravity="model")
    assert off.pos_err is not None
    assert on.pos_err is not None
    assert np.max(off.pos_err) > 5e-4
    assert np.max(on.pos_err) < 1e-5


def test_the_default_is_the_law_as_printed(plant: amj.Plant) -> None:
    """gravity=None is the SPEC's law: the runs are those without the keyword."""
    a = amj.simulate("sf", plant, T=0.5)
    b = amj.simulate("sf", plant, T=0.5, gravity=None)
    np.testing.assert_array_equal(a.tau, b.tau)


def test_a_controller_carries_its_model_through_a_pickle(plant: amj.Plant) -> None:
    """adaptimp.Controller(gravity=...) reads the description; a copy feeds the
    same G forward and continues bit for bit."""
    ctrl = adaptimp.Controller("pd", "robot", n=5, gravity=HOBBY, tau_max=100.0)
    assert ctrl.gravity
    q = np.array([0.1, -0.4, 0.7, 0.2, 0.0])
    m = adaptimp.Measurement(q, np.zeros(5))
    copy = pickle.loads(pickle.dumps(ctrl))
    first = ctrl.step(m, xc=q)
    np.testing.assert_allclose(first, _gravity_at(plant, q), rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(copy.step(m, xc=q), first)


def test_wrong_uses_are_refused_by_name(plant: amj.Plant) -> None:
    with pytest.raises(adaptimp.ConfigError, match=r"^gravity must be None or 'model'"):
        amj.simulate("sf", plant, T=0.01, gravity="yes")
    with pytest.raises(TypeError, match=r"^gravity='model' builds a case name's controller"):
        amj.simulate(adaptimp.Controller("pd", "robot", n=5), plant, T=0.01, gravity="model")
    with pytest.raises(adaptimp.ConfigError, match=r"^gravity's model has 5 movable joints"):
        adaptimp.Controller("pd", "robot", n=3, gravity=HOBBY)
    with pytest.raises(adaptimp.ConfigError, match=r"^gravity='model' takes the plant's"):
        adaptimp.Controller("pd", "robot", n=5, gravity="model")
