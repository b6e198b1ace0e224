"""Cartesian impedance (SPEC §16): the compiled core's 6-D outer loop in front of a
joint controller, for any arm given as a :class:`~adaptimp.Chain`.

- :class:`CartesianController`: the controller a robot engineer specifies on
  the tip's pose: stiffness, damping and inertia for the translation and the
  rotation (per axis, world frame), a null-space posture, error clipping,
  filters on the target, the stiffness and the measured wrench. Its ``step(q,
  dq, wrench, …) -> tau`` runs the core's outer loop and, for a case name
  (``"pd"``, ``"sf"``, ``"of"``), the core's joint step with no Python in
  between; a joint controller written in Python (e.g.
  :class:`adaptimp.baselines.ComputedTorque`) can take its place, the outer
  loop still running in the core. It is a controller of
  :func:`adaptimp.mujoco.simulate`.
- :class:`CartesianImpedance`: the core's outer loop alone: commanded pose and
  measured wrench in, the joint reference (q_d, q̇_d, q̈_d) out; and the
  orbit-centre rule of SPEC §15 for a Cartesian path (:meth:`~CartesianImpedance.orbit_centres`).

Every parameter is declared once, in the core's schema (group ``"cartesian"``:
``Md``, ``Bd``, ``Kd``, ``Md_rot``, ``Bd_rot``, ``Kd_rot``, ``clik_kp``,
``clik_kd``, ``clik_lambda``, ``clik_lambda_rot``, ``null_k``, ``null_d``,
``pos_error_max``, ``rot_error_max``, ``target_filter``, ``force_filter``,
``force_feedforward``; ``adaptimp params`` lists them with units and defaults).
``Kd_rot = 0`` makes the loop position-only.

The scenarios over this API (the Panda drawing a circle on a table, the same
table for any arm) live in :mod:`adaptimp.scenarios`; this module imports none.

Sign convention (SPEC §4, §16): the wrench F_e = [f; m] (N, N m) is what the
tip exerts on the environment, world frame, the moment about the tip (pressing
down on a table: f_z < 0). Units: m, m/s, m/s², rad, rad/s, rad/s², N, N m, kg,
kg m², s.
"""

from __future__ import annotations

import contextlib
import math
import types
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import _adaptimp
from ._adaptimp import Measurement
from ._cartesian_impedance import (
    CartesianImpedance,
    FloatArray,
    Path,
    as_given,
    commit_rotation,
    finite_pose,
    flat_target,
    measured_of,
    pose_of,
    wrench_of,
)
from ._cartesian_impedance import pose_target as pose_target
from ._cartesian_impedance import tabulate as tabulate
from ._deprecated import period_alias
from ._errors import ConfigError, MeasurementError
from ._inputs import reals as reals  # (importable from here before the split)
from ._params import BY_NAME, check_scenario, describe
from ._params import resolve as resolve  # (importable from here before the split)
from ._pose import CartesianStep, PoseTarget, call_shape
from .chain import Chain

__all__ = [
    "CartesianController",
    "CartesianImpedance",
    "CartesianStep",
    "Chain",
    "Path",
    "PoseTarget",
    "pose_target",
]


class CartesianController:
    """SPEC §16's 6-D Cartesian impedance: the core's outer loop and a joint controller.

    Parameters
    ----------
    chain : Chain
        The arm's kinematics (:meth:`Chain.from_urdf`, :meth:`Chain.from_mujoco`).
    controller : {"pd", "sf", "of"} or joint controller
        A case name builds ``adaptimp.Controller(controller, scenario, n=chain.n,
        impedance="external", centers=, widths=, **controller parameters)``, and
        each step is the core's (outer loop and joint step in one call). Or a
        joint controller written in Python with ``step(q, tau_e, dq, *, xc, dxc,
        ddxc)``, ``impedance = "external"`` and the period ``ts``/``Ts`` (e.g.
        ``ComputedTorque(..., impedance="external")``): the core's outer loop
        hands it its reference.
    scenario : {"robot", "paper"}
        The defaults of a case name's controller.
    q0 : (n,)
        The start (rad): the outer loop's q_d(0) and (default) posture.
    posture : (n,), optional
        The null-space posture (rad); default q0.
    path : callable, optional
        :data:`Path`, the commanded pose when a step is given none; without it a
        step without a target holds the last one (at first the start pose).
    centers, widths : array_like, optional
        RBF centres and widths of a case name's controller (see
        :meth:`CartesianImpedance.orbit_centres`).
    record : bool
        Keep every step's p_c, ṗ_c, p̈_c, p_d, ṗ_d, p̈_d, q_d, F_e (:meth:`arrays`).
    **params
        The Cartesian parameters (group "cartesian": ``Kd``, ``Kd_rot``,
        ``force_feedforward``, …) and, for a case name, the joint controller's
        (``Ts``, ``Kp``, ``tau_max``, ``gamma``, …).

    Notes
    -----
    The :func:`adaptimp.mujoco.simulate` protocol: ``task_space = True``, so it
    reads the measurement's wrench; ``step(m, xc=, dxc=, ddxc=)``; ``.Ts``; after a step
    ``xc``, ``dxc``, ``ddxc`` = p_c, ṗ_c, p̈_c (the commanded position and its
    rates; when no target is given, the held target after its filter, p_t, at
    rest), ``xd`` = p_d (the compliant reference), ``z1`` = p_d − p(q) (m,
    (3,)), ``tau`` (the joint controller's commanded τ, N m), ``q_d``,
    ``force`` (f, N); ``zeta`` and ``dq_hat`` are the joint controller's (if it
    has them). With a case name's joint controller, :func:`adaptimp.mujoco.simulate`
    runs the whole loop in the core (the path or the reference tabulated
    first, at the loop's t_k); afterwards the controller is as after the same
    steps taken one by one (its log holds the run's kept rows).

    Examples
    --------
    >>> import adaptimp
    >>> arm = adaptimp.Chain(
    ...     [
    ...         {"kind": "revolute", "axis": [0, 0, 1]},
    ...         {"kind": "revolute", "xyz": [0.3, 0, 0], "axis": [0, 0, 1]},
    ...     ],
    ...     tip={"xyz": [0.2, 0, 0]},
    ... )
    >>> ctrl = adaptimp.CartesianController(
    ...     arm, "pd", q0=[0.3, 0.6], Kd_rot=0.0, tau_max=20.0, Kp=5.0, Kzeta=25.0
    ... )
    >>> tau = ctrl.step(adaptimp.Measurement([0.3, 0.6], [0.0, 0.0]))
    >>> tau.shape
    (2,)
    """

    task_space = True

    def __init__(
        self,
        chain: Chain,
        controller: Any = "sf",
        scenario: str = "robot",
        *,
        q0: ArrayLike,
        posture: ArrayLike | None = None,
        path: Path | None = None,
        centers: ArrayLike | None = None,
        widths: ArrayLike | None = None,
        record: bool = True,
        **params: Any,
    ) -> None:
        from ._api import Controller

        check_scenario(scenario)
        cart = {k: v for k, v in params.items() if k in BY_NAME and BY_NAME[k].group == "cartesian"}
        joint = {k: v for k, v in params.items() if k not in cart}
        if isinstance(controller, str):
            if joint.get("impedance", "external") != "external":
                raise ConfigError(
                    "the joint controller of a Cartesian impedance has impedance='external' "
                    "(the Cartesian impedance is the only one, SPEC §16)"
                )
            joint["impedance"] = "external"
            # The chain fixes n; an n given too (e.g. in tuning.suggest's keywords) must agree.
            n = joint.pop("n", chain.n)
            if n != chain.n:
                raise ConfigError(f"n = {n!r}, but the chain has {chain.n} joints")
            inner: Any = Controller(
                controller,
                scenario,
                n=chain.n,
                centers=centers,
                widths=widths,
                **joint,
            )
            self._core: Any = inner
        else:
            if joint or centers is not None or widths is not None:
                raise TypeError(
                    f"parameters {sorted(joint)} of a joint controller apply to a case name "
                    "only; configure the controller object itself"
                )
            mode = getattr(controller, "impedance", None) or inner_params(controller).get(
                "impedance"
            )
            if mode != "external":
                raise ConfigError(
                    f"the joint controller must have impedance='external' (SPEC §16), got {mode!r}"
                )
            inner = controller
            # A joint controller the core steps (computed torque, SPEC §20).
            core_joint = getattr(controller, "core_joint", None)
            self._core = core_joint if isinstance(core_joint, _adaptimp.ComputedTorque) else None
            # A joint controller written in Python: called as the protocol says.
            self._inner_measurement = (
                self._core is not None or call_shape(controller) == "measurement"
            )
        Ts = getattr(inner, "Ts", None)
        if Ts is None:
            raise TypeError(f"the joint controller {inner!r} has no period .Ts (s)")
        self.inner = inner
        self.outer = CartesianImpedance(chain, Ts=float(Ts), q0=q0, posture=posture, **cart)
        self.chain = chain
        self._path, self._record = path, bool(record)
        self._Ts = float(Ts)
        self._tau = np.full(chain.n, math.nan)
        self._log: dict[str, list[FloatArray]] = {k: [] for k in _LOG}
        self._bind()

    def _bind(self) -> None:
        """The per-sample step as the core's own method (docs/performance.md):
        ``step(m)`` goes from the call to the core with no Python frame
        between; any other call is :meth:`step`'s. A subclass's own ``step``
        is left as it is."""
        if type(self).step is not CartesianController.step:
            return
        joint = self._core
        # Any call but step(m) goes on to the method below, as written in Python.
        other = types.MethodType(CartesianController.step, self)
        bound = _adaptimp.CartesianStep(self.outer.core, joint, self._path, other, self._record)
        self.step = bound.step  # type: ignore[method-assign]

    @property
    def path(self) -> Path | None:
        """The commanded pose's path ``path(t) -> (p, ṗ, p̈[, R, ω, ω̇])``, called
        at t_k by a step given no pose (None: the last target held)."""
        return self._path

    @path.setter
    def path(self, path: Path | None) -> None:
        self._path = path
        self._bind()

    @property
    def record(self) -> bool:
        """Whether each step's row is kept for :attr:`log` and :meth:`arrays`."""
        return self._record

    @record.setter
    def record(self, record: bool) -> None:
        self._record = bool(record)
        self._bind()

    @property
    def _k(self) -> int:
        """Steps taken: the outer loop's clock, t_k = k·Ts."""
        return int(self.outer.core.steps)

    @classmethod
    def from_rule(
        cls,
        chain: Chain,
        controller: str,
        path: Path,
        q0: ArrayLike,
        *,
        model: Any,
        tau_max: ArrayLike | None = None,
        span: float | None = None,
        Ts: float = 1e-3,
        delay: int = 0,
        coupled: bool | None = None,
        **params: Any,
    ) -> CartesianController:
        """The Cartesian controller of a case name built by the core's rule
        (SPEC §16 (16.10), §18): nothing set per arm.

        The outer loop (the schema's Cartesian defaults; position-only for an
        arm of fewer than six joints, which cannot hold an orientation) runs
        kinematically from ``q0`` along ``path`` over its ``span`` (the
        hold, the ramp and one period of a periodic path); the joint rule
        then takes D and G from ``model``, the actuators' ``tau_max`` and that
        joint path (q_d, q̇_d, q̈_d of every step): the gains (18.1)–(18.4)
        with the inertia scales the smallest along the path (16.12), the
        centres along the joint orbit with the tube narrowed to the orbit
        (16.10), the learning (18.6)–(18.8).

        The start must pass the posture rule along that joint path, the one
        check :func:`adaptimp.mujoco.cartesian_task` and the table scenario
        apply (SPEC (16.9): σmin(J), the joint limits with their margin,
        gravity within the actuators, the velocity loop's conditioning at
        K1·Ts/m of the controller built, the path within 1 mm; for an
        ``adaptimp.mujoco.Plant`` the arm free of collisions), or a
        ``ConfigError`` names the condition, its bound and the value.

        Parameters
        ----------
        chain : Chain
            The arm's kinematics, to the point the task moves.
        controller : {"pd", "sf", "of"}
            The joint controller's case.
        path : callable
            :data:`Path`, the commanded pose (m, rad; world frame).
        q0 : (n,)
            The start posture (rad), an inverse-kinematics solution of
            ``path(0)``.
        model
            What gives D(q) and G(q): an ``adaptimp.mujoco.Plant``, a
            Pinocchio ``Model``, an object with ``D(q)`` and ``G(q)``
            (:func:`adaptimp.tuning.inertia`, :func:`adaptimp.tuning.gravity`).
        tau_max : (n,), optional
            Actuator limits (N m); default ``model.tau_max``.
        span : float, optional
            The part of the path the rule samples (s); default ``path.span``
            (the default task's: hold + ramp + one period).
        Ts : float
            The period (s).
        delay : int
            The loop's delay (periods) the rule sizes the joint gains for,
            SPEC (18.11) (libfranka: 1); the joint controller's ``delay``.
        coupled : bool or None
            The joint controller's inertia-shaped gains, SPEC (18.12)
            (:func:`adaptimp.tuning.suggest`'s ``coupled``; default: the
            shaped gains for a ``delay`` ≥ 1, with Ĝ learning at least at
            (m/Ts) K1 on the orbit, the diagonal ones of (18.1) without a
            delay; False: the diagonal ones at any delay).
        **params
            Replace the rule's keywords (Cartesian parameters, e.g. ``Kd``,
            and the joint controller's, e.g. ``gamma``). ``gravity="model"``:
            the joint controller feeds ``model``'s gravity forward, SPEC
            (20.10) (an ``adaptimp.mujoco.Plant``; or give the description
            itself, ``gravity=PATH``), for a robot that does not compensate it.

        Raises
        ------
        ConfigError
            ``q0`` cannot run the path (the condition with its bound and the
            value measured), or a keyword is refused.
        """
        from . import _posture, tuning

        if params.get("gravity") == "model":
            if not hasattr(model, "qpos_adr"):
                raise ConfigError(
                    "gravity='model' reads the model's description from an "
                    "adaptimp.mujoco.Plant: give the arm's file itself, gravity=PATH"
                )
            params = {**params, "gravity": model}
        if not isinstance(controller, str):
            raise TypeError(
                f"from_rule builds a case name's controller ('pd', 'sf', 'of'), got {controller!r}"
            )
        q0 = np.asarray(q0, dtype=np.float64)
        span = getattr(path, "span", None) if span is None else span
        if (
            span is None
            or isinstance(span, bool)
            or not (
                isinstance(span, (int, float, np.floating)) and math.isfinite(span) and span > 0
            )
        ):
            raise ConfigError(
                f"span must be a finite number > 0 (s): the part of the path the rule samples "
                f"(the path has no .span); got {span!r}"
            )
        limits = getattr(model, "tau_max", None) if tau_max is None else tau_max
        if limits is None:
            raise ConfigError("tau_max (N m) is needed: the model has no .tau_max")
        cart = {k: v for k, v in params.items() if k in BY_NAME and BY_NAME[k].group == "cartesian"}
        if chain.n < 6:
            cart.setdefault("Kd_rot", 0.0)
        outer = CartesianImpedance(chain, Ts=Ts, q0=q0, **cart)
        steps = round(float(span) / Ts)
        q, dq, ddq = outer.joint_path(path, steps * Ts, samples=steps)
        # A Plant's state as the caller left it, whatever the check and the rule
        # read D and G at.
        kept = getattr(model, "state_kept", None)
        with kept() if callable(kept) else contextlib.nullcontext():
            # The one posture check (SPEC (16.9)) along the joint path, at the K1
            # of the controller built (the rule's, or the one given); a start
            # given: gravity within the actuators.
            idx = _posture.checked_rows(q.shape[0])
            targets = tabulate(path, steps, Ts, chain.pose(q0)[1])[idx, 0:3]
            k1 = params.get("K1")
            a = _posture.assess(
                model, chain, q0, q[idx], targets, orients=outer.orients,
                k1=None if k1 is None else float(np.min(np.asarray(k1, dtype=np.float64))),
                Ts=Ts, load=_posture.GIVEN_LOAD, tau_max=limits,
            )  # fmt: skip
            if a["error"] is not None:
                raise ConfigError(f"q0 cannot run the path: {a['error']}")
            kw = tuning.suggest(
                model, q0, limits, Ts=Ts, path=np.hstack([q, dq, ddq]), period=steps * Ts,
                case=controller, resolve=True, delay=delay, coupled=coupled,
            )  # fmt: skip
        kw.pop("n")
        joint = {k: v for k, v in params.items() if k not in cart}
        centres, widths = (
            joint.pop("centers", kw.pop("centers")),
            joint.pop("widths", kw.pop("widths")),
        )
        kw.update(joint)
        return cls(
            chain, controller, "robot", q0=q0, path=path, centers=centres, widths=widths,
            **cart, **kw,
        )  # fmt: skip

    @property
    def Ts(self) -> float:
        """Period Ts (s)."""
        return self._Ts

    @property
    def ts(self) -> float:
        """Deprecated name of :attr:`Ts`."""
        return period_alias(self)

    @property
    def zeta(self) -> FloatArray:
        """The joint controller's auxiliary state ζ now (N m), (n,) (AttributeError
        if it has none)."""
        return np.asarray(self.inner.zeta, dtype=np.float64)

    @property
    def dq_hat(self) -> FloatArray:
        """The velocity the joint controller used in the last step (rad/s), (n,)
        (AttributeError if it does not say)."""
        return np.asarray(self.inner.dq_hat, dtype=np.float64)

    @property
    def n(self) -> int:
        """Joints."""
        return self.chain.n

    def _last(self, what: str) -> FloatArray:
        return np.asarray(self.outer.core.last(what), dtype=np.float64)

    @property
    def output(self) -> CartesianStep:
        """Every quantity of the last step by name, with its unit
        (:class:`CartesianStep`; NaN before a first step)."""
        return CartesianStep.of(self.outer.core)

    @property
    def xc(self) -> FloatArray:
        """The last step's commanded position p_c (m), (3,) (NaN before a step)."""
        return self._last("p_c")

    @property
    def dxc(self) -> FloatArray:
        """The last step's ṗ_c (m/s), (3,)."""
        return self._last("dp_c")

    @property
    def ddxc(self) -> FloatArray:
        """The last step's p̈_c (m/s²), (3,)."""
        return self._last("ddp_c")

    @property
    def xd(self) -> FloatArray:
        """The last step's compliant reference p_d (m), (3,)."""
        return self._last("p_d")

    @property
    def z1(self) -> FloatArray:
        """The last step's p_d − p(q) (m), (3,)."""
        return self._last("p_d") - self._last("p")

    @property
    def force(self) -> FloatArray:
        """The last step's measured force f (N), (3,)."""
        return self._last("wrench")[:3]

    @property
    def q_d(self) -> FloatArray:
        """The joint reference q_d of the last step (rad), (n,) (q0 before one)."""
        q = self._last("q_d")
        return self.outer.q0.copy() if np.isnan(q).all() else q

    @property
    def core_joint(self) -> Any:
        """The joint controller the core steps itself behind this one (an
        :class:`adaptimp.Controller`, or the core's computed torque of an
        :class:`adaptimp.baselines.ComputedTorque`); None for a joint controller
        written in Python, which each step calls."""
        return self._core

    @property
    def tau(self) -> FloatArray:
        """The last step's commanded τ of the joint controller (N m), (n,)."""
        return self._last("tau") if self._core is not None else self._tau

    @property
    def log(self) -> dict[str, list[FloatArray]]:
        """The kept rows, per quantity (see :meth:`arrays`): lists of rows or blocks."""
        rows = self.outer.core.take_log()
        if len(rows):
            n = self.chain.n
            cuts = np.cumsum([3, 3, 3, 3, 3, 3, n, 6])
            for key, block in zip(_LOG, np.split(rows, cuts, axis=1)):
                self._log[key].append(block)
        return self._log

    @property
    def params(self) -> dict[str, Any]:
        """The Cartesian parameters, and the joint controller's under ``"inner"``."""
        p = inner_params(self.inner)
        return {**self.outer.params, "inner": dict(p)}

    def take_over(self, tau: ArrayLike) -> None:
        """The joint controller takes over from a controller that was applying
        ``tau`` (n,) (N m) until now (:meth:`adaptimp.Controller.take_over`:
        the first step's torque rate limit moves from it). TypeError if the
        joint controller has no ``take_over``."""
        joint = self.inner if self._core is None else self._core
        take = getattr(joint, "take_over", None)
        if not callable(take):
            raise TypeError(
                f"the joint controller {type(joint).__name__} cannot take over a torque"
            )
        take(tau)

    def reset(self) -> None:
        """Back to t = 0: the outer loop at its start, the joint controller reset
        (if it has ``reset``), the log emptied."""
        self.outer.reset()
        reset = getattr(self.inner, "reset", None)
        if callable(reset):
            reset()
        for v in self.log.values():
            v.clear()

    def step(
        self,
        m: Measurement | ArrayLike | None = None,
        dq: ArrayLike | None = None,
        wrench: ArrayLike | None = None,
        *,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
        R: ArrayLike | None = None,
        w: ArrayLike | None = None,
        dw: ArrayLike | None = None,
        target: PoseTarget | None = None,
        q: ArrayLike | None = None,
    ) -> FloatArray:
        """One step at t_k = k·Ts; returns the torque to apply (N m), (n,).

        ``m`` is an :class:`adaptimp.Measurement`: q (rad), dq (rad/s) (n,),
        and the wrench F_e = [f; m] (N, N m), (6,) (f (3,) alone: no moment;
        None: no contact); its tau_e is not read (the step maps the wrench to
        the joints itself). The commanded pose: ``xc`` = p_c (m), ``dxc``,
        ``ddxc`` (m/s, m/s²), ``R`` (3, 3), ``w``, ``dw`` (rad/s, rad/s²),
        each optional (R: the last commanded rotation), or all of it as a
        :class:`PoseTarget` ``target``; without either the ``path`` at t_k,
        or the last target held. The rest of the step by name:
        :attr:`output`. ``step(q, dq, wrench)`` works, with a
        ``DeprecationWarning``.
        """
        measured: Any
        if self._core is not None and type(m) is Measurement and dq is wrench is q is None:
            measured = m  # the core reads it itself: no arrays made here
        else:
            q, dq, wrench = measured_of(self.chain.n, m, dq, wrench, q)
            measured = q
        names = ("xc", "dxc", "ddxc", "R", "w", "dw")
        if target is not None:
            if xc is not None:
                raise TypeError("give the commanded pose as xc=… or as target=…, not both")
            if not isinstance(target, PoseTarget):
                raise TypeError(f"target must be a PoseTarget, got {type(target).__name__}")
            xc, dxc, ddxc, R, w, dw = target.p, target.dp, target.ddp, target.R, target.w, target.dw
            names = ("target.p", "target.dp", "target.ddp", "target.R", "target.w", "target.dw")
        given: FloatArray | None = None
        if xc is not None:
            # Read here, each part named as given (the core reads p_c, R_c, …).
            given = flat_target(self.outer, (xc, dxc, ddxc, R, w, dw), names)
            finite_pose(given, names)
            sample: Any = given
        elif self.path is not None:
            sample = self.path(self._k * self._Ts)
            if sample is None:  # held silently before (the core's step refuses it too)
                raise TypeError(
                    "a path returns (p, dp, ddp) or (p, dp, ddp, R, w, dw) (a tuple of arrays), "
                    "got NoneType"
                )
        else:
            sample = None
        if self._core is not None:
            # One call of the core: the pose and wrench read, the step, the row kept.
            core = self.outer.core
            try:
                out: FloatArray = core.step_sample(
                    self._core, measured, dq, wrench, sample, self.record
                )
            except MeasurementError as e:
                if given is None:
                    raise
                raise as_given(e, names) from None
            return out
        f = wrench_of(wrench)
        # The rotation a target sets is kept only once the core accepted the step.
        flat: FloatArray | None = None
        turned: object = None
        if given is not None:
            flat, turned = given, R
        elif sample is not None:
            flat = pose_of(sample, self.outer.held_rotation)
            turned = True
        core = self.outer.core
        try:
            out = core.step_python(self.inner, q, dq, f, flat, measurement=self._inner_measurement)
        except MeasurementError as e:
            if given is None:
                raise
            raise as_given(e, names) from None
        self._tau = np.asarray(getattr(self.inner, "tau", out), dtype=np.float64)
        commit_rotation(self.outer, flat, turned)
        if self.record:
            for key, v in zip(
                _LOG,
                (
                    self.xc,
                    self.dxc,
                    self.ddxc,
                    self.xd,
                    core.last("dp_d"),
                    core.last("ddp_d"),
                    self.q_d,
                    f,
                    core.last("error"),
                ),
            ):
                self._log[key].append(np.array(v, dtype=np.float64))
        return np.asarray(out)

    def arrays(self) -> dict[str, FloatArray]:
        """The log as (K, ·) arrays: pc, dpc, ddpc (the commanded position and its
        rates, as ``xc``, ``dxc``, ``ddxc``), pd, dpd, ddpd (K, 3); qd (K, n);
        wrench, error (K, 6)."""
        n = self.chain.n
        width = {"qd": n, "wrench": 6, "error": 6}
        # Each entry of the log is a step's row, or a block of rows (a run of the core's loop).
        return {
            k: np.vstack(v) if v else np.zeros((0, width.get(k, 3))) for k, v in self.log.items()
        }

    def run_core(
        self,
        steps: int,
        reference: Callable[[float], Sequence[ArrayLike]] | Sequence[FloatArray] | None,
        loop: Callable[[Any, FloatArray | None], dict[str, Any]],
    ) -> tuple[dict[str, Any], FloatArray | None]:
        """``steps`` steps of the core's closed loop from this controller's state
        (:func:`adaptimp.mujoco.simulate`'s): its commanded pose tabulated for
        every row (``reference`` at t_k, or its rows (xc, dxc, ddxc), else the
        path on this controller's clock), then ``loop(core_joint, targets)``,
        which runs the core's loop and returns its dict; the controller brought
        up to date (clock, held rotation, log) whatever happens. Returns that
        dict and the targets (steps, 24), or None where the last target is held."""
        if self._core is None or type(self).step is not CartesianController.step:
            raise TypeError(
                "run_core: the core runs a CartesianController whose step is its own and whose "
                "joint controller it steps (an adaptimp.Controller or a baselines.ComputedTorque); "
                f"this one's joint controller is a {type(self.inner).__name__}"
                + ("" if type(self).step is CartesianController.step else ", its step overridden")
            )
        targets = self.commanded_poses(steps, reference)
        k0 = self._k
        task: dict[str, Any] | None = None
        try:
            out = loop(self._core, targets)
            task = out["task"]
        except BaseException as e:
            # Stopped (Ctrl-C, a diverged plant): the rows of the steps it took
            # (the exception's `partial`), which the log keeps as the clock does.
            task = getattr(e, "partial", None)
            raise
        finally:
            self._ran(targets, task, k0)
        return out, targets

    def commanded_poses(
        self,
        steps: int,
        reference: Callable[[float], Sequence[ArrayLike]] | Sequence[FloatArray] | None = None,
    ) -> FloatArray | None:
        """The commanded pose of the next ``steps`` steps at t_k = k·Ts of a loop,
        (steps, 24) (p (m), ṗ (m/s), p̈ (m/s²), R row-major, ω (rad/s), ω̇
        (rad/s²)), as :meth:`step` would take them one by one: ``reference(t_k)``
        or the row k of a tabulated reference (xc, dxc, ddxc) (position, rates;
        the rotation held), else the path on this controller's clock, else None
        (the last target held)."""
        path = self.path
        if reference is None and path is None:
            return None
        if reference is not None and not callable(reference):
            out = np.zeros((steps, 24))
            out[:, 9:18] = self.outer.held_rotation.ravel()
            for i in range(3):
                out[:, 3 * i : 3 * i + 3] = reference[i][:steps]
            return out
        if reference is not None:
            return tabulate(
                reference, steps, self.Ts, self.outer.held_rotation, what="reference(t)"
            )
        assert path is not None
        return tabulate(path, steps, self.Ts, self.outer.held_rotation, start=self._k)

    def _ran(self, targets: FloatArray | None, task: dict[str, FloatArray] | None, k0: int) -> None:
        """After a run of the core's loop (:func:`adaptimp.mujoco.simulate`) along
        ``targets`` (of :meth:`commanded_poses`), whole or stopped by an error: the clock,
        the held rotation and the attributes as after the steps it took; the log
        extended by the run's kept rows ``task`` (None: none); ``k0`` the steps
        taken before it."""
        if self._k > k0 and targets is not None and self.path is not None:
            self.outer.held_rotation = targets[self._k - k0 - 1, 9:18].reshape(3, 3).copy()
        if self.record and task is not None and len(task["pc"]):
            log = self.log
            for key in _LOG:
                log[key].append(task[key])

    def __repr__(self) -> str:
        kind = "position-only" if not self.outer.orients else "6-D"
        inner = getattr(self.inner, "case", type(self.inner).__name__)
        return (
            f"adaptimp.CartesianController({self.chain.source}, {inner!r}): {kind}, "
            f"Ts = {self.Ts:g} s, {self._k} steps"
        )


_LOG = ("pc", "dpc", "ddpc", "pd", "dpd", "ddpd", "qd", "wrench", "error")

_PARAMS_DOC = (
    "\n    Cartesian parameters by name (unit; default)\n"
    "    --------------------------------------------\n"
)
CartesianController.__doc__ = (
    (CartesianController.__doc__ or "") + _PARAMS_DOC + describe("cartesian", scenario="robot")
)


def inner_params(inner: Any) -> dict[str, Any]:
    """A joint controller's ``params`` dict (empty if it has none)."""
    p = getattr(inner, "params", None)
    return dict(p) if isinstance(p, dict) else {}
