"""The result of a MuJoCo run (:class:`MujocoResult`): a
:class:`adaptimp.SimResult` with the plant's arrays, figures and save.

Re-exported by :mod:`adaptimp.mujoco`. Units: rad, rad/s, N, N m, m, s."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ._plot import MUJOCO_FIGURES, MUJOCO_PLOT_KINDS
from ._result import SimResult

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

FloatArray = NDArray[np.float64]


# ---------------------------------------------------------------------------

PLOT_KINDS = MUJOCO_PLOT_KINDS
"""Kinds of :meth:`MujocoResult.plot`."""

ARRAYS = (
    "t", "q", "dq", "ddq", "xc", "dxc", "ddxc", "xd", "dq_hat", "tau", "tau_sat", "tau_e",
    "zeta", "z1", "x_ee", "wrench_ee",
)  # fmt: skip
"""Names of the recorded arrays of :class:`MujocoResult`."""


@dataclass(frozen=True, repr=False, eq=False)
class MujocoResult(SimResult):
    """A closed-loop run on a MuJoCo plant: one row k = 0 … K − 1 per controller
    step at t_k = k·Ts. A :class:`adaptimp.SimResult` (the same metrics,
    ``to_pandas``, ``save``), with the end effector's position and wrench, and
    the plot kinds of a MuJoCo run ("contact" besides SimResult's); ``w_norms``
    is NaN (the plant does not see the weights) and ``case`` is the
    controller's, or "custom".

    Per-joint arrays have shape (K, n); the reference arrays (K, m), m the
    dimension of the controller's xc (n in joint space).

    Attributes
    ----------
    t : (K,)
        Time t_k (s).
    q, dq, ddq : (K, n)
        Joint positions (rad), velocities (rad/s), and accelerations (rad/s²)
        at the row's state and applied torque (MuJoCo's q̈, contact included).
    xc, dxc, ddxc : (K, m)
        Commanded trajectory and its derivatives (NaN where unknown).
    xd : (K, m)
        Compliant reference (the controller's ``xd``; xc if it has none).
    dq_hat : (K, n)
        Velocity the controller used (its ``dq_hat``; dq if it has none).
    tau, tau_sat : (K, n)
        Commanded torque τ and the torque applied to the plant (N m).
    tau_e : (K, n)
        τe = Jᵀ F_e given to the controller (N m).
    zeta : (K, n)
        Auxiliary state ζ (N m; zero for controllers without one).
    z1 : (K, m)
        Tracking error xd − x (the controller's ``z1``, else xd − q).
    x_ee : (K, 3)
        End-effector position (m), world frame.
    wrench_ee : (K, 6)
        F_e: force (N) and moment (N m) the end effector exerts, world frame.
    task : dict or None
        A Cartesian controller's task-space rows (:class:`adaptimp.CartesianController`,
        the keys of its ``arrays()``): "pc", "dpc", "ddpc" (the commanded position
        and rates, = ``xc``, ``dxc``, ``ddxc``), "pd", "dpd", "ddpd" (the compliant
        reference, ``xd`` = pd), "qd" (the joint reference, (K, n)), "wrench" (the
        F_e it was given, (K, 6)), "error" (the impedance's [e_p; e_o], (K, 6)).
        None for a joint-space controller (and for a Cartesian one called back
        with ``record=False``).
    metrics : dict
        The SPEC §12 metrics, with the keys of :attr:`adaptimp.SimResult.metrics`
        (NaN where they do not apply: ``imp_err_rms_after2`` needs a joint-space
        reference).
    params : dict
        The run: ``Ts``, ``substeps``, ``timestep``, ``T``, ``settle``,
        ``contact``, ``tau_max``, ``wrench_source``, ``model``, ``joints``
        (the arm's joint names, base to tip), ``controller``,
        ``loop`` (``"native"``: the core stepped the controller;
        ``"callback"``: the core's loop called a controller written in Python).
    """

    x_ee: FloatArray | None = None
    wrench_ee: FloatArray | None = None
    task: dict[str, FloatArray] | None = None

    _own_params = ("controller", "model", "Ts", "substeps", "contact", "settle")

    def _own_arrays(self) -> dict[str, FloatArray]:
        out = {n: a for n in ("x_ee", "wrench_ee") if (a := getattr(self, n)) is not None}
        out.update({f"task.{k}": v for k, v in (self.task or {}).items()})
        return out

    @classmethod
    def _own_fields(cls, arrays: Mapping[str, Any]) -> dict[str, Any]:
        fields: dict[str, Any] = {n: arrays[n] for n in ("x_ee", "wrench_ee") if n in arrays}
        task = {k[len("task.") :]: v for k, v in arrays.items() if k.startswith("task.")}
        if task:
            fields["task"] = task
        return fields

    @property
    def rows(self) -> int:
        """Number of recorded rows K."""
        return int(self.t.shape[0])

    @property
    def pos_err(self) -> FloatArray | None:
        """A Cartesian task's position error ‖p_c − p‖ per row (m), (K,) (None for
        a run without a ``task``)."""
        return None if self.task is None else self.task.get("pos_err")

    @property
    def rot_err(self) -> FloatArray | None:
        """A Cartesian task's orientation error ‖Log(R_c Rᵀ)‖ per row (rad), (K,)
        (None for a run without a ``task``)."""
        return None if self.task is None else self.task.get("rot_err")

    @property
    def dtau(self) -> FloatArray:
        """sat(τ) − τ (N m), (K, n)."""
        return self.tau_sat - self.tau

    def plot(self, kind: str = "tracking", ax: Axes | Sequence[Axes] | None = None) -> Figure:
        """A matplotlib figure of the run, one panel per joint (or per force axis).

        kind : {"tracking", "errors", "torques", "contact"}
            q against xc and xd; z1; τ and sat(τ) with ±τmax; the end-effector
            force F_e (N) and ‖τe‖ (N m).
        ax : Axes or sequence of Axes, optional
            Draw "tracking", "errors" or "torques" into these axes, as
            :meth:`adaptimp.SimResult.plot` does.
        """
        if ax is not None:
            return super().plot(kind, ax)
        if kind not in PLOT_KINDS:
            raise ValueError(f"kind must be one of {PLOT_KINDS}, got {kind!r}")
        return MUJOCO_FIGURES[kind](self)

    def __repr__(self) -> str:
        m, p = self.metrics, self.params
        return (
            f"MujocoResult({p['controller']} on {p['model']}: {self.rows} steps of Ts = "
            f"{p['Ts']:g} s, {p['substeps']} MuJoCo steps each; contact "
            f"{'on' if p['contact'] else 'off'})\n"
            f"  RMS ‖z1‖ = {m['rms_z1']:.4g}, over t ≥ {p['settle']:g} s: "
            f"{m['rms_z1_after2']:.4g}; saturated {100 * m['sat_duty']:.1f}% of steps; "
            f"{m['steps_in_contact']} steps in contact"
        )


# ---------------------------------------------------------------------------
# The closed loop.
# ---------------------------------------------------------------------------
