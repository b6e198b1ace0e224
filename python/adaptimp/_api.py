"""The public entry points: :func:`simulate`, :class:`Controller`, :class:`TwoLinkArm`,
:class:`PlanarArm`."""

from __future__ import annotations

import sys
import time
import warnings
from collections.abc import Callable, Mapping
from typing import Any, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._arms import PlanarArm, TwoLinkArm, _two_link_arm  # noqa: F401 (pickles name _api._two_link_arm)
from ._deprecated import period_alias
from ._errors import ConfigError, StabilityWarning
from ._faults import Fault
from ._params import (
    BY_NAME,
    N_JOINTS,
    _basis,
    _core_controller,
    check_case,
    check_n,
    check_scenario,
    check_settle,
    describe,
    loop_delay,
    names,
    resolve,
)
from ._result import SimResult

FloatArray = NDArray[np.float64]
Progress = Union[bool, Callable[[int, int], object], None]

STATE_FORMAT = "adaptimp.state/1"
"""The ``format`` entry of :meth:`Controller.state_dict`."""


# ---------------------------------------------------------------------------
# Helpers shared by Controller and simulate.
# ---------------------------------------------------------------------------


def _check_stability(core: _adaptimp.Controller, p: Mapping[str, Any], stacklevel: int) -> None:
    """:class:`StabilityWarning` when explicit-Euler learning is unstable at this Ts."""
    if core.case == "pd" or p["learning_step"] != "euler":
        return
    gain, kp = core.learning_gain
    if gain >= kp:
        scaled = any(d != 1.0 for d in p["inertia"])
        against = "Kp/inertia" if scaled else "Kp"
        warnings.warn(
            StabilityWarning(
                f"explicit-Euler learning is unstable at Ts = {p['Ts']:g} s: its per-step "
                f"gain Ts‖S‖²(ΓD‖ẍc‖² + ΓC‖ẋc‖² + ΓG) = {gain:.3g} exceeds "
                f"{against} = {kp:g} (the Jury condition of docs/robot.md, per unit inertia "
                "scale); use scenario='robot', or learning_step='normalized', or a smaller Ts "
                "or gamma"
            ),
            stacklevel=stacklevel + 1,
        )


class ProgressReport:
    """Progress of a long call: silent for its first ``delay`` seconds, then a tqdm
    bar if tqdm is installed, else a line on stderr rewritten in place."""

    def __init__(self, desc: str, delay: float = 2.0) -> None:
        self.desc = desc
        self.start = time.perf_counter()
        self.delay = delay
        self.bar: Any = None
        self.shown = False

    def __call__(self, done: int, total: int) -> None:
        if not self.shown and time.perf_counter() - self.start < self.delay:
            return
        self.shown = True
        if self.bar is None:
            try:
                from tqdm.auto import tqdm
            except ImportError:
                self.bar = False
            else:
                self.bar = tqdm(total=total, desc=self.desc, unit="step", unit_scale=True)
        if self.bar:
            self.bar.update(done - self.bar.n)
        else:
            print(
                f"\r{self.desc}: {100 * done / total:5.1f}% ({done}/{total} steps)",
                end="",
                file=sys.stderr,
                flush=True,
            )

    def close(self, total: int | None = None) -> None:
        if self.bar:
            if total is not None:
                self.bar.update(total - self.bar.n)
            self.bar.close()
        elif self.shown:
            print(file=sys.stderr)


def _progress(progress: Progress, desc: str) -> tuple[Callable[[int, int], object] | None, Any]:
    if progress is None or progress is False:
        return None, None
    if progress is True:
        p = ProgressReport(desc)
        return p, p
    if callable(progress):
        return progress, None
    raise TypeError(f"progress must be a bool or a callable(done, total), got {progress!r}")


def _record_every(k: object) -> int:
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
        raise TypeError(f"record_every must be an integer ≥ 1, got {type(k).__name__}")
    if not 1 <= int(k) < 2**63:
        raise ConfigError(f"record_every must be an integer ≥ 1, got {k}")
    return int(k)


def _table(name: str, value: ArrayLike, n: int) -> FloatArray:
    """``value`` as a C-contiguous float64 array of shape (K, n), or an error naming ``name``."""
    from ._errors import MeasurementError

    arr = np.asarray(value)
    if arr.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be an array of real numbers, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != n:
        raise MeasurementError(f"{name} must have shape (K, {n}), got shape {arr.shape}")
    return np.ascontiguousarray(arr, dtype=np.float64)


# ---------------------------------------------------------------------------
# simulate.
# ---------------------------------------------------------------------------


def simulate(
    case: str = "sf",
    scenario: str = "paper",
    *,
    n: int = N_JOINTS,
    arm: TwoLinkArm | PlanarArm | None = None,
    centers: ArrayLike | None = None,
    widths: ArrayLike | None = None,
    weights: Mapping[str, ArrayLike] | None = None,
    record_every: int = 1,
    progress: Progress = False,
    fault: Fault | None = None,
    **params: Any,
) -> SimResult:
    """Simulate one of the paper's controllers on an arm against the wall.

    The controller runs at the period ``Ts``; the plant is integrated by RK4 with
    the applied torque held for the period (``substeps`` RK4 steps), and the wall
    force recomputed at every stage (SPEC §11). The compiled core runs with the
    GIL released, checks for Ctrl-C every 50 ms (``KeyboardInterrupt``) and can
    report progress.

    Parameters
    ----------
    case : {"pd", "sf", "of"}
        PD (Case 1), adaptive neural state feedback (14) or output feedback (35).
    scenario : {"paper", "robot"}
        The table of defaults: ``"paper"`` is SPEC §11 (T = 20 s, Ts = 50 µs,
        one RK4 substep: 400 000 steps, the printed laws); ``"robot"`` is the
        same at a robot's Ts = 1 ms with 10 RK4 substeps and the hardened
        options of SPEC §13 (see ``docs/robot.md``).
    n : int
        Joints, 1 … 7 (default 2, the paper's arm). Per-joint defaults are the
        paper's first joint's value for every joint.
    arm : TwoLinkArm or PlanarArm, optional
        The plant. Default: the paper's arm for n = 2 (from the arm keywords),
        else ``PlanarArm(n)``. The controller is model-free and never reads it.
    centers : array_like, shape (L, 4n), optional
        RBF centres (rows of x, v, α1, α̇1; rad, rad/s, rad/s, rad/s²) instead
        of the paper's vertex grid (which exists for n ≤ 3). Without them for
        n > 3: the rule's centres along one period of the commanded trajectory
        (``xc_*``), or, if it does not move, 2n + 1 centres about its offset
        (SPEC §18).
    widths : float or array_like, shape (4n,), optional
        The centres' widths η_d per input dimension (units of that input):
        S_i = exp(−Σ_d (Z_d − μ_id)² / η_d²); ``np.inf`` leaves input d out
        (SPEC §15). Default √eta2.
    weights : dict, optional
        Initial network weights ("D" (n, n, L), "C" (n, n, L), "G" (n, L)),
        e.g. ``Controller.state_dict()`` or ``SimResult`` of a previous run's
        controller: a warm start. Default zero, as in the paper.
    record_every : int
        Keep every k-th row (k ≥ 1); the metrics still see every step.
    progress : bool or callable
        ``True``: a progress bar (tqdm if installed, else a line on stderr)
        for runs longer than 2 s; a callable is called as ``progress(done,
        total)`` about every 50 ms, and once with ``done == total`` when
        the run ends.
    fault : Fault, optional
        A fault injected over a window (:class:`adaptimp.Fault`: stale or NaN
        sensors, a force bias, weak actuators, skipped steps); refused steps
        apply the fallback and are marked in ``refused``.
    **params
        Any parameter below by name. Per-joint values take a number (for every
        joint) or one value per joint; ``gamma`` and ``sigma`` a number or one
        value per network (D̂, Ĉ, Ĝ).

    Returns
    -------
    SimResult
        The recorded arrays, the SPEC §12 metrics and every parameter that ran.

    Raises
    ------
    TypeError
        An unknown keyword (the message lists the valid names) or a value of the
        wrong type.
    ConfigError
        (a ``ValueError``) a wrong shape, a non-finite number, an unknown case or
        choice, or a violated condition of SPEC §10 (the message names the
        condition, the value and what to change).
    DivergedError
        The closed loop left the finite range.
    KeyboardInterrupt
        Ctrl-C during the run (within 0.1 s).

    Warns
    -----
    StabilityWarning
        Explicit-Euler learning unstable at this Ts (per-step gain ≥ Kp).

    Examples
    --------
    >>> import adaptimp
    >>> res = adaptimp.simulate("pd", T=0.5)
    >>> res.q.shape
    (10000, 2)
    """
    check_case(case)
    n = check_n(n)
    every = _record_every(record_every)
    if arm is not None and arm.n != n:
        raise ConfigError(f"arm has {arm.n} joints but n = {n}")
    if isinstance(arm, (TwoLinkArm, PlanarArm)) and any(
        BY_NAME[k].group == "arm" for k in params if k in BY_NAME
    ):
        raise TypeError("give the arm's parameters to the arm, not to simulate(), with arm=")
    params = dict(params)
    # SPEC (18.11): the loop's delay is the plant's and the controller's alike.
    params["delay"] = loop_delay(params)
    p = resolve(params, scenario=scenario, caller="simulate()", n=n)
    if "settle" in params:
        check_settle(p["settle"], p["T"], p["Ts"])
    c, eta = _basis(n, centers, widths, p)
    core = _core_controller(case, p, n, c, None if eta is None else eta**2)
    _check_stability(core, p, stacklevel=2)
    if arm is None:
        arm = TwoLinkArm(**{k: p[k] for k in names("arm")}) if n == N_JOINTS else PlanarArm(n)
    # What the core derived: the arm's parameters, the weight bounds of "auto".
    if isinstance(arm, TwoLinkArm):
        p.update(arm.params)
    else:
        p["arm"] = arm.params
    p["weight_bound"] = core.weight_bound
    if c is not None:
        p["nodes"] = int(c.shape[0])
    callback, bar = _progress(progress, f"simulate({case!r})")
    try:
        core_params = {k: v for k, v in p.items() if k in BY_NAME}
        out = _adaptimp.simulate(
            core,
            arm.core,
            core_params,
            every,
            callback,
            _weights_or_none(weights),
            None if fault is None else fault.core(n),
        )
    finally:
        if bar is not None:
            bar.close()
    metrics = out.pop("metrics")
    return SimResult(
        case=case,
        scenario=scenario,
        params=p,
        metrics=metrics,
        record_every=every,
        centers=c,
        widths=eta,
        **out,
    )


def _weights_dict(weights: Mapping[str, ArrayLike]) -> dict[str, FloatArray]:
    """The "D", "C", "G" arrays of a weights dict or a state dict."""
    if not isinstance(weights, Mapping):
        raise TypeError(f"weights must be a dict of arrays, got {type(weights).__name__}")
    keys = ("W_D", "W_C", "W_G") if "W_D" in weights else ("D", "C", "G")
    out = {}
    for name, key in zip(("D", "C", "G"), keys):
        if key not in weights:
            raise ConfigError(f"weights has no {key!r} (need D, C and G)")
        out[name] = np.ascontiguousarray(weights[key], dtype=np.float64)
    return out


def _weights_or_none(weights: Mapping[str, ArrayLike] | None) -> dict[str, FloatArray] | None:
    return None if weights is None else _weights_dict(weights)


_PARAMS_DOC = (
    "\n    Parameters by name (unit; paper default)\n    ----------------------------------------\n"
)
simulate.__doc__ = (simulate.__doc__ or "") + _PARAMS_DOC + describe()


# ---------------------------------------------------------------------------
# Controller.
# ---------------------------------------------------------------------------


Gravity = tuple[list[dict[str, Any]], list[dict[str, Any]], list[float]]
"""A nominal model as the core takes it for (20.10): the chain's joints, their
inertials and the gravity vector (m/s²)."""


def gravity_model(source: Any, n: int) -> Gravity | None:
    """The nominal model whose gravity a controller of ``n`` joints feeds
    forward, SPEC (20.10), from ``source``: None (none); a URDF, xacro or MJCF
    path, a ``mujoco.MjModel`` or an ``adaptimp.mujoco.Plant`` (its model),
    read by the core (SPEC §21); or the (joints, inertials, gravity) triple
    itself. A ``ConfigError`` if its arm has not n movable joints; a path
    that is no file, ``FileNotFoundError``."""
    if source is None:
        return None
    if isinstance(source, tuple) and len(source) == 3:
        joints, inertials, g = source
        return list(joints), list(inertials), [float(x) for x in g]
    if isinstance(source, str) and source == "model":
        raise ConfigError(
            "gravity='model' takes the plant's own model: give it to adaptimp.mujoco.simulate "
            "or CartesianController.from_rule; adaptimp.Controller takes the model itself "
            "(gravity=PATH, a mujoco.MjModel or an adaptimp.mujoco.Plant)"
        )
    from ._description import read_arm

    plant_model = getattr(source, "model", None)
    arm = read_arm(plant_model if hasattr(source, "qpos_adr") else source)
    if arm.n != n:
        raise ConfigError(
            f"gravity's model has {arm.n} movable joints ({', '.join(arm.joints)}), the "
            f"controller {n}"
        )
    return list(arm.chain), list(arm.inertials), [float(x) for x in arm.gravity]


def _rebuild_controller(state: dict[str, Any]) -> Controller:
    """Unpickle: a controller from the state :meth:`Controller.__reduce__` wrote."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StabilityWarning)
        ctrl = Controller._make(
            state["case"],
            state["scenario"],
            state["n"],
            state["params"],
            state["centers"],
            state["widths"],
            state.get("gravity"),
        )
    ctrl.restore(np.asarray(state["snapshot"], dtype=np.float64))
    return ctrl


class Controller(_adaptimp.Controller):
    """One of the paper's controllers for an arm of n joints, for your own loop.

    The controller keeps its own clock: step k happens at t_k = k·Ts, counted
    from construction or :meth:`reset`, and tracks the commanded trajectory
    ``xc`` of its parameters, or a setpoint you give at each step (``xc=``).
    It never reads a model of the arm.

    Parameters
    ----------
    case : {"pd", "sf", "of"}
        PD (Case 1), adaptive neural state feedback (14) or output feedback (35).
    scenario : {"paper", "robot"}
        The table of defaults (see :func:`simulate`).
    n : int
        Joints, 1 … 7 (default 2).
    centers, widths : array_like, optional
        RBF centres (L, 4n) and widths (4n,) instead of the vertex grid (see
        :func:`simulate`); for n > 3 without them, the rule's default basis
        along the commanded trajectory (SPEC §18).
    gravity : path, MjModel or Plant, optional
        Feed the nominal model's gravity forward, SPEC (20.10): the law adds
        G₀(q) (N m) at the measured position, the arm's description read by
        the core (a URDF, xacro or MJCF path, a ``mujoco.MjModel`` or an
        ``adaptimp.mujoco.Plant``; its movable joints must be the n of this
        controller). For a robot that does not compensate gravity itself;
        None (default, the paper's law) for one that does (Franka's torque
        interface adds its own model's gravity: feeding it again counts it
        twice).
    **params
        Controller parameters by name, as for :func:`simulate` (``Ts``, ``Kp``,
        ``K1``, ``Kzeta``, ``gamma``, ``tau_max``, ``xc_offset``, …). The run's,
        the wall's and the arm's parameters (``T``, ``q0``, ``wall``, ``m1``, …)
        are rejected with ``TypeError``.

    Notes
    -----
    **Methods from the compiled core.** ``step(m, *, xc=None, dxc=None,
    ddxc=None)`` takes an :class:`adaptimp.Measurement` ``m``: positions q
    (rad), for "pd"/"sf" velocities dq (rad/s), and the measured force on the
    environment τe (N m; none: zeros), each of shape (n,); it returns the
    applied torque sat(τ) (N m), (n,). ``xc``, ``dxc``, ``ddxc`` (rad, rad/s,
    rad/s²; the last two zero if omitted) replace the trajectory's setpoint.
    Every controller takes the same call (``CartesianController`` reads the
    measurement's wrench instead of τe); the old ``step(q, tau_e, dq)`` works,
    with a ``DeprecationWarning``. ``step_or_fallback`` never raises for a refused
    measurement and returns (torque, error message or None). ``replay`` runs K
    steps from (K, n) tables without the GIL. ``reset()``, ``snapshot()``,
    ``restore(data)``, ``load_weights(dict)``, ``take_over(tau)`` (before the
    first step: the torque a robot's own controller held the arm with, from
    which the first step's rate limit moves, SPEC (22.4)); the read-only ``t``, ``steps``,
    ``Ts``, ``n``, ``nodes``, ``zeta``, ``tau``, ``tau_sat``, ``applied`` (the
    torque to apply now: after a refused step, the fallback), ``dtau``, ``z1``,
    ``xc``, ``xd``, ``dq_hat``, ``weights``, ``weight_bound``, ``fault``.

    **Faults.** Every refused step, whichever method refused it, records the
    fault (``fault``; with ``fault_policy="latch"`` later steps raise
    ``FaultError`` until ``clear_fault()``) and takes the fallback as the
    torque applied, from which the next step's ``tau_rate_max`` is measured.
    ``restore``, ``load_state_dict`` and ``load_weights`` refuse a state this
    controller could never step. The table is in docs/reliability.md.

    **Threads.** Each call is atomic: a controller is guarded by a lock, and a
    thread that finds it in use waits (with the GIL released) until the other
    call ends; steps from several threads are applied one after another in
    the order the threads get the lock. Give each thread its own controller
    (``copy.deepcopy``) unless that is what you want. Distinct controllers run
    in parallel: ``simulate`` and ``replay`` release the GIL.

    **Copies and pickles.** ``copy.copy``, ``copy.deepcopy`` and ``pickle``
    make independent controllers that continue bit-identically (a recorded
    fault is not carried over).

    Examples
    --------
    >>> import adaptimp
    >>> ctrl = adaptimp.Controller("sf", scenario="robot")
    >>> m = adaptimp.Measurement([0.25, -0.05], [0.0, 0.0], tau_e=[0.0, 0.0])
    >>> tau = ctrl.step(m)
    >>> tau.shape, ctrl.t
    ((2,), 0.001)
    """

    _params: dict[str, Any]
    _scenario: str
    _centers: FloatArray | None
    _widths: FloatArray | None
    _gravity: Gravity | None

    def __new__(
        cls,
        case: str,
        scenario: str = "paper",
        *,
        n: int = N_JOINTS,
        centers: ArrayLike | None = None,
        widths: ArrayLike | None = None,
        gravity: Any = None,
        **params: Any,
    ) -> Controller:
        check_case(case)
        check_scenario(scenario)
        n = check_n(n)
        p = resolve(params, scenario=scenario, groups=("controller",), caller="Controller()", n=n)
        c, eta = _basis(n, centers, widths, p)
        self = cls._make(case, scenario, n, p, c, eta, gravity_model(gravity, n))
        _check_stability(self, p, stacklevel=2)
        return self

    @classmethod
    def _make(
        cls,
        case: str,
        scenario: str,
        n: int,
        p: dict[str, Any],
        centers: FloatArray | None,
        widths: FloatArray | None,
        gravity: Gravity | None = None,
    ) -> Controller:
        w2 = None if widths is None else np.ascontiguousarray(np.asarray(widths) ** 2)
        self = _core_controller(case, p, n, centers, w2, cls, gravity)
        assert isinstance(self, Controller)
        self._params = dict(p)
        self._params["weight_bound"] = self.weight_bound
        self._scenario = scenario
        self._centers = centers
        self._widths = widths
        self._gravity = gravity
        return self

    @property
    def gravity(self) -> bool:
        """Whether the law feeds a nominal model's gravity forward (SPEC (20.10))."""
        return self._gravity is not None

    def __init__(
        self,
        case: str,
        scenario: str = "paper",
        *,
        n: int = N_JOINTS,
        centers: ArrayLike | None = None,
        widths: ArrayLike | None = None,
        gravity: Any = None,
        **params: Any,
    ) -> None:
        """Everything happens in ``__new__`` (the compiled core is immutable); the
        signature is ``__new__``'s, for help() and the documentation."""

    # -- state that travels -------------------------------------------------

    def __reduce__(self) -> tuple[Any, ...]:
        state = {
            "case": self.case,
            "scenario": self._scenario,
            "n": self.n,
            "params": self._params,
            "centers": self._centers,
            "widths": self._widths,
            "gravity": self._gravity,
            "snapshot": self.snapshot(),
        }
        return (_rebuild_controller, (state,))

    def __copy__(self) -> Controller:
        """An independent copy: stepping it never changes this controller."""
        return _rebuild_controller(self.__reduce__()[1][0])

    def __deepcopy__(self, memo: dict[int, Any]) -> Controller:
        return self.__copy__()

    def state_dict(self) -> dict[str, Any]:
        """Everything learned and the whole state, as plain NumPy arrays and numbers.

        Keys: ``format`` (``"adaptimp.state/1"``), ``case``, ``n``, ``nodes``,
        ``steps``, ``t`` (s), ``zeta`` (N m, (n,)), ``W_D`` (n, n, L) kg m²,
        ``W_C`` (n, n, L) kg m²/s, ``W_G`` (n, L) N m, and ``snapshot`` (the
        flat state of :meth:`restore`). Save it with ``np.savez``.
        """
        w = self.weights
        return {
            "format": STATE_FORMAT,
            "case": self.case,
            "n": self.n,
            "nodes": self.nodes,
            "steps": self.steps,
            "t": self.t,
            "zeta": self.zeta,
            "W_D": w["D"],
            "W_C": w["C"],
            "W_G": w["G"],
            "snapshot": self.snapshot(),
        }

    def load_state_dict(self, state: Mapping[str, Any], *, weights_only: bool = False) -> None:
        """Load a :meth:`state_dict` of a controller with the same n and L.

        With ``weights_only=False`` (default) the whole state is restored and the
        controller continues exactly where the saved one stopped. With
        ``weights_only=True`` only the weights are loaded, into the current
        state (call :meth:`reset` first to start a new run from t = 0 with
        them: a warm start). Checked before anything changes: a state this
        controller could never step is refused (see :meth:`restore`), and so
        are keys that disagree with the ``snapshot`` they travel with (edited
        ``W_D``, ``steps``, …: load edited weights with ``weights_only=True``),
        and a snapshot of another case.
        """
        if not isinstance(state, Mapping):
            raise TypeError(f"state must be a dict, got {type(state).__name__}")
        fmt = state.get("format")
        if fmt is not None and str(fmt) != STATE_FORMAT:
            raise ConfigError(f"state has format {fmt!r}, expected {STATE_FORMAT!r}")
        for key, mine in (("n", self.n), ("nodes", self.nodes)):
            if key in state and int(state[key]) != mine:
                raise ConfigError(f"state has {key} = {int(state[key])}, this controller {mine}")
        if weights_only or "snapshot" not in state:
            self.load_weights(_weights_dict(state))
            return
        if "case" in state and str(state["case"]) != self.case:
            raise ConfigError(
                f"state is of case {str(state['case'])!r}, this controller {self.case!r} "
                "(load its weights with weights_only=True)"
            )
        snapshot = np.ascontiguousarray(state["snapshot"], dtype=np.float64)
        # What the snapshot holds, read by the core on a scratch copy: every
        # other key given must agree with it.
        scratch = self.__copy__()
        scratch.restore(snapshot)
        restored = scratch.state_dict()
        for key in ("W_D", "W_C", "W_G", "zeta", "steps", "t"):
            if key in state and not np.array_equal(np.asarray(state[key]), restored[key]):
                raise ConfigError(
                    f"state[{key!r}] disagrees with state['snapshot']: drop the snapshot "
                    "to load edited weights (load_state_dict(state, weights_only=True))"
                )
        self.restore(snapshot)

    # -- conveniences -------------------------------------------------------

    def replay(
        self,
        q: ArrayLike,
        tau_e: ArrayLike,
        dq: ArrayLike | None = None,
        *,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
        progress: Progress = False,
    ) -> FloatArray:
        """K steps in one call, e.g. to replay logged measurements; returns the
        applied torques (N m), shape (K, n).

        Equivalent to calling :meth:`step` on each row in turn, but the loop runs
        in the compiled core without the GIL (Ctrl-C is honoured within 0.1 s).

        Parameters
        ----------
        q : array_like, shape (K, n)
            Measured joint positions (rad), one row per step.
        tau_e : array_like, shape (K, n)
            Measured force on the environment (N m).
        dq : array_like, shape (K, n), optional
            Measured joint velocities (rad/s): required by "pd" and "sf".
        xc, dxc, ddxc : array_like, shape (K, n), optional
            External setpoints (rad, rad/s, rad/s²) instead of the trajectory.
        progress : bool or callable
            As for :func:`simulate`.

        Raises
        ------
        MeasurementError
            A wrong shape, or an error at some row (named in the message; the
            rows before it have been stepped).
        """
        n = self.n
        tables = [
            None if a is None else _table(name, a, n)
            for name, a in (("dq", dq), ("xc", xc), ("dxc", dxc), ("ddxc", ddxc))
        ]
        callback, bar = _progress(progress, "replay")
        try:
            return super().replay(
                _table("q", q, n),
                _table("tau_e", tau_e, n),
                tables[0],
                xc=tables[1],
                dxc=tables[2],
                ddxc=tables[3],
                progress=callback,
            )
        finally:
            if bar is not None:
                bar.close()

    @property
    def scenario(self) -> str:
        """The scenario whose defaults were used."""
        return self._scenario

    @property
    def params(self) -> dict[str, Any]:
        """Every controller parameter (a copy), as for :attr:`SimResult.params`."""
        return dict(self._params)

    @property
    def ts(self) -> float:
        """Deprecated: the period is :attr:`Ts` (s)."""
        return period_alias(self)

    def __repr__(self) -> str:
        if self._centers is not None:
            basis = "user centres"
        else:
            basis = "vertex grid" if self.n <= 3 else "centres along the trajectory"
        return (
            f"adaptimp.Controller({self.case!r}, scenario={self._scenario!r}, n={self.n}): "
            f"{self.nodes} RBF nodes ({basis}), Ts = {self.Ts:g} s, "
            f"t = {self.t:g} s after {self.steps} steps"
        )
