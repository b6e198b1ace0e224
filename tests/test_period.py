"""One name for the sampling period: ``Ts`` (s). ``.ts`` is still read, with a
DeprecationWarning, on adaptimp's objects and in the controller protocol of
``adaptimp.mujoco.simulate``."""

from __future__ import annotations

import numpy as np
import pytest

import adaptimp
from adaptimp import mujoco as amj
from adaptimp.baselines import ComputedTorque
from adaptimp.cartesian import CartesianImpedance
from adaptimp.chain import Chain


def test_controller_period_is_Ts_and_ts_is_deprecated() -> None:
    ctrl = adaptimp.Controller("sf", "robot")
    assert ctrl.Ts == 1e-3
    with pytest.warns(
        DeprecationWarning, match=r"^Controller\.ts is deprecated: the period is \.Ts \(s\)$"
    ):
        assert ctrl.ts == 1e-3


def test_computed_torque_and_outer_loop_take_Ts() -> None:
    ct = ComputedTorque(Ts=2e-3)
    assert ct.Ts == 2e-3
    with pytest.warns(DeprecationWarning, match=r"^ComputedTorque\.ts is deprecated"):
        assert ct.ts == 2e-3
    chain = Chain.from_mujoco(amj.two_link(), "ee")
    outer = CartesianImpedance(chain, Ts=1e-3, q0=np.array([0.5, 1.0]))
    assert outer.Ts == 1e-3
    with pytest.warns(DeprecationWarning, match=r"^CartesianImpedance\.ts is deprecated"):
        assert outer.ts == 1e-3


class _Old:
    """A controller written for the protocol's earlier name of the period."""

    ts = 1e-3

    def step(self, m: object, **setpoint: object) -> np.ndarray:
        return np.zeros(2)


def test_mujoco_reads_Ts_and_the_deprecated_ts() -> None:
    with pytest.warns(
        DeprecationWarning, match=r"period \.ts is deprecated: name it \.Ts \(_Old\)"
    ):
        res = amj.simulate(_Old(), "two_link", T=0.003)
    assert res.rows == 3
    assert res.params["Ts"] == 1e-3

    class NoPeriod:
        def step(self, *args: object, **kw: object) -> np.ndarray:
            return np.zeros(2)

    with pytest.raises(TypeError, match=r"has no period: give it a \.Ts \(s\)"):
        amj.simulate(NoPeriod(), "two_link", T=0.003)
