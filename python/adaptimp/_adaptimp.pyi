"""Type stubs of the compiled core ``adaptimp._adaptimp`` (src/python.rs).

The classes take complete parameter dicts keyed by the Python parameter names;
``adaptimp.Controller``, ``adaptimp.TwoLinkArm`` and ``adaptimp.simulate`` build
them from keywords with the paper's defaults.
"""

from collections.abc import Sequence
from typing import Any, TypedDict, final, type_check_only

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "N_JOINTS",
    "N_NODES",
    "Controller",
    "TwoLinkArm",
    "__version__",
    "core_defaults",
    "simulate",
]

__version__: str
N_JOINTS: int
N_NODES: int

_F = NDArray[np.float64]
_Joint = Sequence[float]

@type_check_only
class ControllerParams(TypedDict):
    """Controller parameters (SPEC §4–§11); per-joint values have 2 entries."""

    Ts: float
    K1: _Joint
    Kp: _Joint
    Kzeta: _Joint
    mu: float
    aux_law: str
    robust: str
    kr: _Joint
    phi: float
    kD: float
    kC: float
    kG: float
    gamma: Sequence[float]
    sigma: Sequence[float]
    eta2: float
    eps: float
    lam1: _Joint
    observer_init: str
    observer_hold: str
    tau_max: _Joint
    Dd: _Joint
    Cd: _Joint
    Gd: _Joint
    xc_offset: _Joint
    xc_sin: _Joint
    xc_cos: _Joint
    xc_omega: _Joint

@type_check_only
class ArmParams(TypedDict):
    """Arm parameters (SPEC §1), all given."""

    m1: float
    m2: float
    l1: float
    l2: float
    lc1: float
    lc2: float
    I1: float
    I2: float
    g: float

@type_check_only
class SimParams(TypedDict):
    """Run and environment parameters (SPEC §3, §11)."""

    T: float
    substeps: int
    q0: _Joint
    dq0: _Joint
    settle: float
    wall: float | None
    ke: float
    be: float

@final
class Controller:
    """One of the paper's controllers for the 2-link arm, with its state."""

    def __new__(cls, case: str, params: ControllerParams | dict[str, Any]) -> Controller: ...
    def step(self, q: ArrayLike, tau_e: ArrayLike, dq: ArrayLike | None = None) -> _F: ...
    def replay(self, q: _F, tau_e: _F, dq: _F | None = None) -> _F:
        """K steps replaying (K, 2) float64 measurement tables; applied torques (K, 2) (N m)."""
    def reset(self) -> None: ...
    @property
    def case(self) -> str: ...
    @property
    def t(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def ts(self) -> float: ...
    @property
    def zeta(self) -> _F: ...
    @property
    def dq_hat(self) -> _F: ...
    @property
    def tau(self) -> _F: ...
    @property
    def tau_sat(self) -> _F: ...
    @property
    def dtau(self) -> _F: ...
    @property
    def z1(self) -> _F: ...
    @property
    def xc(self) -> _F: ...
    @property
    def xd(self) -> _F: ...
    @property
    def weights(self) -> dict[str, _F]: ...

@final
class TwoLinkArm:
    """The paper's 2-link arm, (55)–(63)."""

    def __new__(cls, params: ArmParams | dict[str, Any]) -> TwoLinkArm: ...
    def D(self, q: ArrayLike) -> _F: ...
    def C(self, q: ArrayLike, dq: ArrayLike) -> _F: ...
    def G(self, q: ArrayLike) -> _F: ...
    def forward_dynamics(
        self, q: ArrayLike, dq: ArrayLike, tau: ArrayLike, tau_e: ArrayLike
    ) -> _F: ...
    @property
    def lumped(self) -> tuple[float, float, float, float, float]: ...

def simulate(
    controller: Controller, arm: TwoLinkArm, params: SimParams | dict[str, Any]
) -> dict[str, Any]:
    """Close the loop with the GIL released; returns the arrays and "metrics"."""

def core_defaults(scenario: str = "paper") -> dict[str, Any]:
    """The core's own defaults of ``scenario`` ("paper" or "robot"), keyed by the Python names."""
