"""Arguments the Python surface refuses, by name, with the value, before anything
runs (the break-it pass's leftovers): the contact scenario's placement and
metrics, the MuJoCo run's window, the Cartesian formulation's share, a saved
result whose metrics or parameters were edited, a URDF with several legs."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import adaptimp
from adaptimp import _models
from adaptimp import contact as act

PANDA = adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip=_models.PANDA_EE)
LO, HI = np.full(7, -1.0), np.full(7, 1.0)
HOME = np.asarray(_models.PANDA_HOME)


@pytest.mark.parametrize(
    ("home", "limits", "tool_radius", "message"),
    [
        (HOME, (LO, HI), math.nan, "tool_radius must be a finite number > 0 (m), got nan"),
        (HOME, (LO, HI), -0.01, "tool_radius must be a finite number > 0 (m), got -0.01"),
        (
            HOME,
            (np.where(np.arange(7) == 2, math.nan, LO), HI),
            0.01,
            "limits[0] (lo) must be 7 finite numbers (rad) (±π for an unlimited joint); "
            "joint 2 ('panda_joint3') is nan",
        ),
        (
            HOME,
            (LO, np.where(np.arange(7) == 6, math.inf, HI)),
            0.01,
            "limits[1] (hi) must be 7 finite numbers (rad) (±π for an unlimited joint); "
            "joint 6 ('panda_joint7') is inf",
        ),
        (
            HOME,
            (HI, LO),
            0.01,
            "limits must have lo ≤ hi for every joint; joint 0 ('panda_joint1') has "
            "lo = 1.0 > hi = -1.0",
        ),
        (
            HOME,
            (LO[:3], HI),
            0.01,
            "limits[0] (lo) must be 7 finite numbers (rad) (±π for an unlimited joint), "
            "one per joint; got shape (3,)",
        ),
        (
            np.full(7, math.nan),
            (LO, HI),
            0.01,
            "home must be 7 finite numbers (rad); joint 0 ('panda_joint1') is nan",
        ),
    ],
)
def test_placement_refuses_a_quantity_that_is_not_finite_by_name(
    home: np.ndarray, limits: tuple[np.ndarray, np.ndarray], tool_radius: float, message: str
) -> None:
    with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
        act.placement(PANDA, home, limits, tool_radius=tool_radius)


def test_placement_of_finite_input_is_unchanged() -> None:
    """The checks let a finite input through to the same numbers: the centre lies
    at min(radial + OUTWARD, REACH_SHARE R) along the home tip's direction."""
    centre, top, reach = act.placement(PANDA, HOME, (LO, HI))
    p = PANDA.fk(HOME)[:3, 3]
    radial = float(np.linalg.norm(p[:2]))
    assert float(np.linalg.norm(centre)) == pytest.approx(
        min(radial + act.OUTWARD, act.REACH_SHARE * reach)
    )
    assert top == pytest.approx(p[2] - 0.01 - act.CLEARANCE)


def test_arm_table_refuses_a_home_that_is_not_finite_by_name() -> None:
    ur5 = _models.panda_urdf_path().parent.parent.parent / "ur_description/urdf/ur5_robot.urdf"
    home = [0.0, math.nan, 0.0, 0.0, 0.0, 0.0]
    message = "home must be 6 finite numbers (rad); joint 1 ('shoulder_lift_joint') is nan"
    with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
        act.arm_table(ur5, home=home)
