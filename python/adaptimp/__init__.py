"""adaptimp: adaptive neural impedance control of a robot arm with input saturation.

A faithful implementation of W. He, Y. Dong, C. Sun, "Adaptive Neural Impedance
Control of a Robotic Manipulator With Input Saturation", IEEE Trans. SMC: Systems
46(3), 2016, with a Rust core (``adaptimp._adaptimp``) and this NumPy front.
Units: rad, rad/s, rad/s², N m, s. The equations, errata and decisions are in
the project's SPEC (docs/SPEC.md).

- :func:`simulate` runs one of the paper's controllers ("pd", "sf", "of") on an
  arm of 1–7 joints (the paper's 2-link arm by default) against the wall and
  returns a :class:`SimResult` (arrays, SPEC §12 metrics, ``.plot(kind)``,
  ``.save(path)``, ``.to_pandas()``).
- :class:`Controller` is the controller alone, for your own loop; it pickles.
- :class:`TwoLinkArm` is the paper's arm, :class:`PlanarArm` an arm of n links:
  D(q), C(q, q̇), G(q), forward dynamics.
- :class:`Chain` is any arm's kinematics (from a URDF or a MuJoCo model), and
  :class:`CartesianController` the 6-D Cartesian impedance over it (SPEC §16).
- :func:`sweep` runs many simulations (a grid or random samples) on every core
  or on a Dask cluster and returns a pandas DataFrame.
- Errors by kind: :class:`ConfigError`, :class:`MeasurementError`,
  :class:`DivergedError`, :class:`FaultError`, :class:`SaveError`;
  :class:`StabilityWarning`, :class:`PlantWarning`.

Every SPEC quantity is a keyword parameter with the paper's default
(:data:`PARAMS`, :data:`SCENARIOS`)::

    import adaptimp

    res = adaptimp.simulate("sf", T=5.0, Kp=10.5)
    print(res.metrics["rms_z1_after2"])
    res.plot("tracking").savefig("tracking.png")
"""

from ._adaptimp import Measurement, __version__
from ._api import Controller, simulate
from ._arms import PlanarArm, TwoLinkArm
from ._errors import (
    AdaptimpError,
    ConfigError,
    DivergedError,
    FaultError,
    MeasurementError,
    PlantWarning,
    SaveError,
    StabilityWarning,
    XacroError,
)
from ._faults import Fault
from ._params import CASES, MAX_JOINTS, PARAMS, SCENARIOS, Param, defaults
from ._plot import PLOT_KINDS
from ._plot import compare as plot_compare
from ._result import RESULT_KINDS, SimResult, metrics_table
from ._sweep import Choice, LogUniform, Normal, Uniform, sweep
from .cartesian import CartesianController, CartesianStep, PoseTarget
from .chain import Chain


def _mujoco_result() -> type[SimResult] | None:
    """:class:`adaptimp.mujoco.MujocoResult`, for ``SimResult.load`` of its
    files; None without the mujoco extra."""
    try:
        from .mujoco import MujocoResult
    except ImportError:
        return None
    return MujocoResult


RESULT_KINDS["MujocoResult"] = _mujoco_result

__all__ = [
    "CASES",
    "MAX_JOINTS",
    "PARAMS",
    "PLOT_KINDS",
    "SCENARIOS",
    "AdaptimpError",
    "CartesianController",
    "CartesianStep",
    "Chain",
    "Choice",
    "ConfigError",
    "Controller",
    "DivergedError",
    "Fault",
    "FaultError",
    "LogUniform",
    "Measurement",
    "MeasurementError",
    "Normal",
    "Param",
    "PlanarArm",
    "PlantWarning",
    "PoseTarget",
    "SaveError",
    "SimResult",
    "StabilityWarning",
    "TwoLinkArm",
    "Uniform",
    "XacroError",
    "__version__",
    "defaults",
    "metrics_table",
    "plot_compare",
    "simulate",
    "sweep",
]
