"""A user's script that hands adaptimp's own controllers, and controllers
written the two ways the protocol documents, to ``adaptimp.mujoco.simulate``
type-checks under ``mypy --strict`` (the ``ControllerLike`` protocol once
refused every one of adaptimp's controllers: their steps take the setpoint
keywords by name, not as ``**setpoint``)."""

from __future__ import annotations

from pathlib import Path

import pytest

api = pytest.importorskip("mypy.api")

USER = """
from typing import Any

import numpy as np

import adaptimp
from adaptimp import mujoco as amj
from adaptimp.baselines import ComputedTorque


class Keywords:
    Ts = 1e-3

    def step(self, m: adaptimp.Measurement, **setpoint: Any) -> np.ndarray:
        return np.zeros(m.n)


class Plain:
    Ts = 1e-3

    def step(self, m: adaptimp.Measurement) -> list[float]:
        return [0.0] * m.n


def run(c: adaptimp.Controller, ct: ComputedTorque, cc: adaptimp.CartesianController) -> None:
    for ctrl in (c, ct, cc, Keywords(), Plain()):
        amj.simulate(ctrl, "panda", T=0.1)
"""

NOT_A_CONTROLLER = """
from adaptimp import mujoco as amj


class NoStep:
    Ts = 1e-3


amj.simulate(NoStep(), "panda", T=0.1)
"""


def check(tmp_path: Path, text: str) -> tuple[str, int]:
    path = tmp_path / "user.py"
    path.write_text(text)
    out, err, status = api.run(["--strict", "--no-error-summary", str(path)])
    return out + err, status


def test_the_controllers_type_check_with_simulate(tmp_path: Path) -> None:
    out, status = check(tmp_path, USER)
    assert status == 0, out


def test_an_object_without_a_step_does_not(tmp_path: Path) -> None:
    out, status = check(tmp_path, NOT_A_CONTROLLER)
    assert status == 1
    assert 'Argument 1 to "simulate" has incompatible type "NoStep"' in out
