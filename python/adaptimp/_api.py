"""The public entry points: :func:`simulate`, :class:`Controller`, :class:`TwoLinkArm`."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._params import check_case, describe, resolve
from ._result import SimResult

FloatArray = NDArray[np.float64]


def simulate(case: str = "sf", scenario: str = "paper", **params: Any) -> SimResult:
    """Simulate one of the paper's controllers on the 2-link arm against the wall.

    The controller runs at the period ``Ts``; the plant is integrated by RK4 with
    the applied torque held for the period (``substeps`` RK4 steps), and the wall
    force recomputed at every stage (SPEC §11). The compiled core runs with the
    GIL released.

    Parameters
    ----------
    case : {"pd", "sf", "of"}
        PD (Case 1), adaptive neural state feedback (14) or output feedback (35).
    scenario : {"paper", "robot"}
        The table of defaults: ``"paper"`` is SPEC §11 (T = 20 s, Ts = 50 µs,
        one RK4 substep: 400 000 steps, the printed laws); ``"robot"`` is the
        same at a robot's Ts = 1 ms with 10 RK4 substeps and the hardened
        options of SPEC §13 (normalised learning step, conditional integration,
        weight projection, tanh robust term, triangle-hold observer started at
        the first measurement; see ``docs/robot.md``).
    **params
        Any parameter below by name. Per-joint values take a number (for every
        joint) or one value per joint; ``gamma`` and ``sigma`` a number or one
        value per network (D̂, Ĉ, Ĝ). The arm parameters define the plant only:
        the controller is model-free and never reads them.

    Returns
    -------
    SimResult
        The recorded arrays, the SPEC §12 metrics and every parameter that ran.

    Raises
    ------
    TypeError
        An unknown keyword (the message lists the valid names) or a value of the
        wrong type.
    ValueError
        A wrong shape, a non-finite number, an unknown case or choice, or a
        violated condition of SPEC §10 (the message names the condition and the
        value, e.g. ``condition 2Kζ − I − KpᵀKp > 0 is violated: 2·Kzeta − 1 −
        Kp²[0] = -1 (SPEC §10)``).

    Examples
    --------
    >>> import adaptimp
    >>> res = adaptimp.simulate("pd", T=0.5)
    >>> res.q.shape
    (10000, 2)
    """
    check_case(case)
    p = resolve(params, scenario=scenario, caller="simulate()")
    ctrl = _adaptimp.Controller(case, p)
    arm = _adaptimp.TwoLinkArm(p)
    # What the core derived: the arm's centres of mass and inertias, the
    # weight bounds of "auto".
    p.update(arm.params)
    p["weight_bound"] = ctrl.weight_bound
    out = _adaptimp.simulate(ctrl, arm, p)
    metrics = out.pop("metrics")
    return SimResult(case=case, scenario=scenario, params=p, metrics=metrics, **out)


_PARAMS_DOC = (
    "\n    Parameters by name (unit; paper default)\n    ----------------------------------------\n"
)
simulate.__doc__ = (simulate.__doc__ or "") + _PARAMS_DOC + describe()


def _table(name: str, value: ArrayLike) -> FloatArray:
    """``value`` as a C-contiguous float64 array of shape (K, 2), or an error naming ``name``."""
    arr = np.asarray(value)
    if arr.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be an array of real numbers, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"{name} must have shape (K, 2), got shape {arr.shape}")
    return np.ascontiguousarray(arr, dtype=np.float64)


class Controller:
    """One of the paper's controllers, for your own control loop.

    The controller keeps its own clock: step k happens at t_k = k·Ts, counted
    from construction or :meth:`reset`, and tracks the commanded trajectory
    ``xc`` of its parameters. It never reads a model of the arm.

    Parameters
    ----------
    case : {"pd", "sf", "of"}
        PD (Case 1), adaptive neural state feedback (14) or output feedback (35).
    scenario : {"paper", "robot"}
        The table of defaults (see :func:`simulate`).
    **params
        Controller parameters by name, as for :func:`simulate` (``Ts``, ``Kp``,
        ``K1``, ``Kzeta``, ``gamma``, ``tau_max``, ``xc_offset``, …). The run's,
        the wall's and the arm's parameters (``T``, ``q0``, ``wall``, ``m1``, …)
        are rejected with ``TypeError``.

    Examples
    --------
    >>> import adaptimp
    >>> ctrl = adaptimp.Controller("sf", Ts=1e-3)
    >>> tau = ctrl.step(q=[0.25, -0.05], tau_e=[0.0, 0.0], dq=[0.0, 0.0])
    >>> tau.shape, ctrl.t
    ((2,), 0.001)
    """

    __slots__ = ("_core", "_params", "_scenario")

    def __init__(self, case: str, scenario: str = "paper", **params: Any) -> None:
        check_case(case)
        self._params = resolve(
            params, scenario=scenario, groups=("controller",), caller="Controller()"
        )
        self._scenario = scenario
        self._core = _adaptimp.Controller(case, self._params)
        self._params["weight_bound"] = self._core.weight_bound

    def step(self, q: ArrayLike, tau_e: ArrayLike, dq: ArrayLike | None = None) -> FloatArray:
        """One controller step at t_k = k·Ts; returns the applied torque sat(τ) (N m), (2,).

        Parameters
        ----------
        q : array_like, shape (2,)
            Measured joint positions (rad).
        tau_e : array_like, shape (2,)
            Measured force the robot exerts on the environment (N m).
        dq : array_like, shape (2,), optional
            Measured joint velocities (rad/s): required by "pd" and "sf",
            ignored by "of" (which estimates them with its observer).

        Raises
        ------
        ValueError
            A wrong shape, a non-finite input (the state is left untouched), a
            missing ``dq`` for "pd"/"sf", or a diverged state (then :meth:`reset`).
        TypeError
            An input that is not a sequence of numbers.
        """
        return self._core.step(q, tau_e, dq)

    def step_or_fallback(
        self, q: ArrayLike, tau_e: ArrayLike, dq: ArrayLike | None = None
    ) -> tuple[FloatArray, str | None]:
        """One step that never raises for a refused measurement: for a real loop.

        Returns the torque to apply (N m), (2,), and None, or, when the
        controller refuses the step (a non-finite or implausible measurement,
        a latched fault), the configured fallback torque (``fallback``:
        "hold" the last applied torque, "zero", or "damping" −Kd q̇; saturated)
        and the error message. A refused step changes nothing but the
        recorded :attr:`fault`. Inputs of the wrong shape or type still raise.

        Examples
        --------
        >>> import adaptimp
        >>> ctrl = adaptimp.Controller("sf", scenario="robot", fallback="zero")
        >>> tau, error = ctrl.step_or_fallback([float("nan"), 0.0], [0.0, 0.0], [0.0, 0.0])
        >>> tau.tolist(), error
        ([0.0, 0.0], 'q[0] is not finite (NaN or infinite)')
        """
        return self._core.step_or_fallback(q, tau_e, dq)

    @property
    def fault(self) -> tuple[str, int] | None:
        """The fault recorded by the last refused step: (message, step k), or None."""
        return self._core.fault

    def clear_fault(self) -> None:
        """Clear the recorded fault. With ``fault_policy="latch"`` every step is
        refused until this is called; the controller then continues from the
        state it had before the fault (nothing learned is lost)."""
        self._core.clear_fault()

    def replay(self, q: ArrayLike, tau_e: ArrayLike, dq: ArrayLike | None = None) -> FloatArray:
        """K steps in one call, e.g. to replay logged measurements; returns the
        applied torques (N m), shape (K, 2).

        Equivalent to calling :meth:`step` on each row in turn, but the loop runs
        in the compiled core without the GIL.

        Parameters
        ----------
        q : array_like, shape (K, 2)
            Measured joint positions (rad), one row per step.
        tau_e : array_like, shape (K, 2)
            Measured force on the environment (N m).
        dq : array_like, shape (K, 2), optional
            Measured joint velocities (rad/s): required by "pd" and "sf".

        Raises
        ------
        ValueError
            A wrong shape, or an error at some row (named in the message; the
            rows before it have been stepped).
        TypeError
            An input that is not an array of real numbers.
        """
        dq_table = None if dq is None else _table("dq", dq)
        return self._core.replay(_table("q", q), _table("tau_e", tau_e), dq_table)

    def reset(self) -> None:
        """Back to t = 0: weights, ζ, observer and reference as at construction."""
        self._core.reset()

    @property
    def case(self) -> str:
        """The controller: "pd", "sf" or "of"."""
        return self._core.case

    @property
    def scenario(self) -> str:
        """The scenario whose defaults were used."""
        return self._scenario

    @property
    def params(self) -> dict[str, Any]:
        """Every controller parameter (a copy), as for :attr:`SimResult.params`."""
        return dict(self._params)

    @property
    def Ts(self) -> float:
        """Sampling period Ts (s)."""
        return self._core.ts

    @property
    def t(self) -> float:
        """Time of the next step t_k = k·Ts (s)."""
        return self._core.t

    @property
    def steps(self) -> int:
        """Steps taken since construction or :meth:`reset`."""
        return self._core.steps

    @property
    def zeta(self) -> FloatArray:
        """Auxiliary state ζ (N m), (2,), now: the value the next step uses, (11)."""
        return self._core.zeta

    @property
    def weights(self) -> dict[str, FloatArray]:
        """Network weights now (a copy), SPEC §6, indexed [k][j][i] (output row,
        column, node): "D" (2, 2, 256) kg m², "C" (2, 2, 256) kg m²/s, "G" (2, 256) N m."""
        return self._core.weights

    @property
    def dq_hat(self) -> FloatArray:
        """Velocity the last step used (rad/s), (2,): the measured dq, or the
        observer's estimate for "of"."""
        return self._core.dq_hat

    @property
    def tau(self) -> FloatArray:
        """The last step's commanded torque τ before saturation (N m), (2,)."""
        return self._core.tau

    @property
    def tau_sat(self) -> FloatArray:
        """The last step's applied torque sat(τ) (N m), (2,)."""
        return self._core.tau_sat

    @property
    def dtau(self) -> FloatArray:
        """The last step's Δτ = sat(τ) − τ (N m), (2,)."""
        return self._core.dtau

    @property
    def z1(self) -> FloatArray:
        """The last step's tracking error z1 = xd − q (rad), (2,)."""
        return self._core.z1

    @property
    def xc(self) -> FloatArray:
        """The last step's commanded position xc (rad), (2,)."""
        return self._core.xc

    @property
    def xd(self) -> FloatArray:
        """The last step's compliant reference xd (rad), (2,)."""
        return self._core.xd

    def __repr__(self) -> str:
        return (
            f"adaptimp.Controller({self.case!r}, scenario={self._scenario!r}): "
            f"Ts = {self.Ts:g} s, t = {self.t:g} s after {self.steps} steps"
        )


class TwoLinkArm:
    """The paper's 2-link arm in a vertical plane, (55)–(63), SPEC §1.

    ``D(q) q̈ + C(q, q̇) q̇ + G(q) = τ − τe``, with τ the applied (saturated)
    torque and τe the force the arm exerts on the environment.

    Parameters
    ----------
    **params
        ``m1``, ``m2`` (kg), ``l1``, ``l2`` (m), ``lc1``, ``lc2`` (m; default
        half the given lengths), ``I1``, ``I2`` (kg m²; default m l²/4 of the
        given masses and lengths), ``g`` (m/s²). Defaults: SPEC §1.

    Examples
    --------
    >>> import adaptimp
    >>> arm = adaptimp.TwoLinkArm(m2=1.0)
    >>> arm.D([0.0, 0.0]).shape
    (2, 2)
    """

    __slots__ = ("_core", "_params")

    def __init__(self, **params: Any) -> None:
        self._params = resolve(params, groups=("arm",), caller="TwoLinkArm()")
        self._core = _adaptimp.TwoLinkArm(self._params)
        self._params.update(self._core.params)

    @property
    def params(self) -> dict[str, Any]:
        """The arm's parameters (a copy), derived ones included."""
        return dict(self._params)

    @property
    def lumped(self) -> tuple[float, float, float, float, float]:
        """p1 … p5 of (59)–(63) (kg m², kg m², kg m², kg m, kg m), p4 with the erratum."""
        p1, p2, p3, p4, p5 = self._core.lumped
        return (p1, p2, p3, p4, p5)

    def D(self, q: ArrayLike) -> FloatArray:
        """Inertia matrix D(q) (kg m²), (2, 2), at joint positions ``q`` (rad), (56)."""
        return self._core.D(q)

    def C(self, q: ArrayLike, dq: ArrayLike) -> FloatArray:
        """Coriolis and centripetal matrix C(q, q̇) (kg m²/s), (2, 2), (57)."""
        return self._core.C(q, dq)

    def G(self, q: ArrayLike) -> FloatArray:
        """Gravity torque G(q) (N m), (2,), (58)."""
        return self._core.G(q)

    def forward_dynamics(
        self, q: ArrayLike, dq: ArrayLike, tau: ArrayLike, tau_e: ArrayLike
    ) -> FloatArray:
        """Joint acceleration q̈ (rad/s²), (2,), from (4).

        Parameters
        ----------
        q, dq : array_like, shape (2,)
            Joint positions (rad) and velocities (rad/s).
        tau : array_like, shape (2,)
            Applied (already saturated) torque (N m).
        tau_e : array_like, shape (2,)
            Force the arm exerts on the environment (N m).
        """
        return self._core.forward_dynamics(q, dq, tau, tau_e)

    def __repr__(self) -> str:
        p = self._params
        return (
            f"adaptimp.TwoLinkArm(m1={p['m1']:g}, m2={p['m2']:g}, l1={p['l1']:g}, "
            f"l2={p['l2']:g}, lc1={p['lc1']:g}, lc2={p['lc2']:g}, I1={p['I1']:g}, "
            f"I2={p['I2']:g}, g={p['g']:g})"
        )
