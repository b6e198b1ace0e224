"""A break-it probe of the public Python API: state restore (bit flips,
edits, truncations), the fault semantics, the n-joint API, sweeps and their
cache, chains, the Cartesian front, formulations, the dynamics and computed
torque, saved results (atomic, concurrent, forged formats), MuJoCo runs,
robot descriptions (URDF text and files through read_arm, Chain.from_urdf,
ComputedTorque and MuJoCo runs), callbacks reading the object that calls them
(each in a process with a time limit), and wrong inputs refused by the name
the user wrote. Every case is classified:

- accepted: it succeeded and every invariant checked held;
- clear error: it was refused by an adaptimp error (or a TypeError,
  ValueError or OSError) with a message, and changed nothing it must not;
- crash: any other exception (a panic, KeyError, OverflowError, ...), or the
  category's process died;
- hang: a case ran past its time limit, or the category's process did;
- silent wrong: it succeeded where it must not (an edited snapshot accepted,
  a torque beyond τmax, a step accepted while a fault is latched, a cached
  result that differs from the run, a controller that never steps again);
- false refusal: it was refused where it must succeed.

    python scripts/breakit.py           # the full probe (a few minutes)
    python scripts/breakit.py --quick   # fewer cases (tests/test_breakit.py)
    python scripts/breakit.py --json    # the counts as JSON

Each category runs in its own process, so a crash or a hang of one is counted
and the others still run. Deterministic: every draw comes from a seeded
generator.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import warnings
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

COLUMNS = ("cases", "accepted", "clear", "crash", "hang", "wrong", "false_refusal")
CASE_SECONDS = 60


class Wrong(Exception):
    """An invariant that does not hold: a silent wrong result."""


class Hang(BaseException):
    """A case ran past its time limit."""


@dataclass
class Tally:
    name: str
    cases: int = 0
    accepted: int = 0
    clear: int = 0
    crash: int = 0
    hang: int = 0
    wrong: int = 0
    false_refusal: int = 0
    notes: list[str] = field(default_factory=list)

    def note(self, what: str) -> None:
        if len(self.notes) < 20:
            self.notes.append(what)


def _clear(e: BaseException) -> bool:
    """An error a user can act on: adaptimp's, or a TypeError/ValueError/
    OSError with a message that is not an internal one."""
    import adaptimp

    if not isinstance(e, (adaptimp.AdaptimpError, TypeError, ValueError, OSError)):
        return False
    if isinstance(e, (KeyError, IndexError, UnicodeError, json.JSONDecodeError)):
        return False
    msg = str(e)
    return bool(msg) and not any(w in msg for w in ("panicked", "unwrap", "internal"))


@contextlib.contextmanager
def _alarm(seconds: int) -> Iterator[None]:
    def ring(*_: Any) -> None:
        raise Hang

    old = signal.signal(signal.SIGALRM, ring)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def case(t: Tally, name: str, fn: Callable[[], object], expect: str) -> None:
    """Run ``fn`` as case ``name`` of ``t``; ``expect`` is "accept", "refuse"
    or "either". ``fn`` raises :class:`Wrong` for a broken invariant."""
    t.cases += 1
    try:
        with _alarm(CASE_SECONDS), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fn()
    except Hang:
        t.hang += 1
        t.note(f"hang: {name}")
    except Wrong as w:
        t.wrong += 1
        t.note(f"wrong: {name}: {w}")
    except BaseException as e:
        if isinstance(e, KeyboardInterrupt):
            raise
        if not _clear(e):
            t.crash += 1
            t.note(f"crash: {name}: {type(e).__name__}: {e}")
        elif expect == "accept":
            t.false_refusal += 1
            t.note(f"false refusal: {name}: {type(e).__name__}: {e}")
        else:
            t.clear += 1
    else:
        if expect == "refuse":
            t.wrong += 1
            t.note(f"wrong: {name}: accepted")
        else:
            t.accepted += 1


def check(cond: bool, what: str) -> None:
    if not cond:
        raise Wrong(what)


# ---------------------------------------------------------------------------
# Helpers.
# ---------------------------------------------------------------------------


def _inputs(k: int, n: int = 2) -> tuple[list[float], list[float], list[float]]:
    s = k * 1e-3
    q = [0.2 + 0.1 * math.sin(s + i) for i in range(n)]
    dq = [0.1 * math.cos(s + i) for i in range(n)]
    return q, [0.0] * n, dq


def _meas(k: int, n: int = 2) -> Any:
    """The measurement of step k (``_inputs``)."""
    import adaptimp

    q, te, dq = _inputs(k, n)
    return adaptimp.Measurement(q, dq, tau_e=te)


def _controller(case_: str, scenario: str, n: int = 2, **kw: Any) -> Any:
    import adaptimp

    if n <= 3:
        return adaptimp.Controller(case_, scenario=scenario, n=n, **kw)
    rng = np.random.default_rng(n)
    centers = rng.uniform(-1.0, 1.0, (32, 4 * n))
    return adaptimp.Controller(
        case_, scenario=scenario, n=n, centers=centers, widths=np.ones(4 * n), **kw
    )


def _trained(case_: str, scenario: str, n: int = 2, steps: int = 200, **kw: Any) -> Any:
    ctrl = _controller(case_, scenario, n, **kw)
    for k in range(steps):
        ctrl.step(_meas(k, n))
    return ctrl


def _refused(dst: Any, data: Any, unchanged: Callable[[], None]) -> None:
    """``dst.restore(data)`` must raise and change nothing; if it accepts,
    ``dst`` is put back (for the next case) and the case is wrong."""
    before = dst.snapshot()
    try:
        dst.restore(data)
    except BaseException:
        unchanged()
        raise
    dst.restore(before)
    raise Wrong("a corrupt or edited snapshot was accepted")


def _tau_max(ctrl: Any) -> np.ndarray:
    return np.asarray(ctrl.params["tau_max"], dtype=float)


def _torque_ok(ctrl: Any, tau: Any) -> None:
    tau = np.asarray(tau)
    check(tau.shape == (ctrl.n,), f"torque of shape {tau.shape}")
    check(bool(np.all(np.isfinite(tau))), f"non-finite torque {tau}")
    check(bool(np.all(np.abs(tau) <= _tau_max(ctrl) + 1e-12)), f"torque {tau} beyond τmax")


# ---------------------------------------------------------------------------
# Categories.
# ---------------------------------------------------------------------------


def restore(t: Tally, quick: bool) -> None:
    """Snapshots: bit flips, edits, truncations; state dicts: edited keys."""
    import adaptimp

    rng = np.random.default_rng(20)
    flips = 60 if quick else 700
    setups = [("sf", "robot", 2), ("of", "paper", 2), ("pd", "robot", 1), ("sf", "robot", 3)]
    if not quick:
        setups += [("sf", "robot", 7), ("of", "robot", 4)]
    for case_, scenario, n in setups:
        src = _trained(case_, scenario, n)
        snap = src.snapshot()
        dst = _controller(case_, scenario, n)
        before = dst.snapshot()

        def unchanged(dst: Any = dst, before: np.ndarray = before) -> None:
            check(np.array_equal(dst.snapshot(), before), "a refused restore changed the state")

        per = flips // len(setups)
        for _ in range(per):
            i, bit = int(rng.integers(len(snap))), int(rng.integers(64))
            bad = snap.copy()
            bad.view(np.uint64)[i] ^= np.uint64(1) << np.uint64(bit)

            def flip(
                bad: np.ndarray = bad, dst: Any = dst, unchanged: Callable[[], None] = unchanged
            ) -> None:
                _refused(dst, bad, unchanged)

            case(t, f"{case_}/{scenario}/n={n}: flip bit {bit} of value {i}", flip, "refuse")
        edits: list[tuple[str, Any]] = [
            ("empty", np.zeros(0)),
            ("truncated", snap[:-1]),
            ("extended", np.concatenate([snap, [0.0]])),
            ("2-D", snap.reshape(1, -1)),
            ("NaN", np.where(np.arange(len(snap)) == 7, np.nan, snap)),
            ("all zero", np.zeros_like(snap)),
            ("float32", snap.astype(np.float32)),
            ("list", list(snap)),
            ("int array", snap.astype(np.int64)),
            ("another n", _trained(case_, scenario, 2 if n != 2 else 1, 5).snapshot()),
            ("a weight 1e200", np.where(np.arange(len(snap)) == len(snap) - 3 * n, 1e200, snap)),
            ("the reference 1e99", np.where(np.arange(len(snap)) == 5, 1e99, snap)),
        ]
        for what, data in edits:

            def edit(
                data: Any = data, dst: Any = dst, unchanged: Callable[[], None] = unchanged
            ) -> None:
                _refused(dst, data, unchanged)

            case(t, f"{case_}/n={n}: restore {what}", edit, "refuse")

        def good(snap: np.ndarray = snap, src: Any = src, dst: Any = dst, n: int = n) -> None:
            dst.restore(snap)
            for k in range(200, 230):
                a, b = src.step(_meas(k, n)), dst.step(_meas(k, n))
                check(np.array_equal(a, b), "a restored state does not continue identically")

        case(t, f"{case_}/n={n}: restore its own snapshot", good, "accept")

    # State dicts.
    src = _trained("sf", "robot")
    state = src.state_dict()
    for key, value in [
        ("W_D", state["W_D"] * 2),
        ("W_C", state["W_C"] + 1e-12),
        ("W_G", np.zeros_like(state["W_G"])),
        ("zeta", state["zeta"] + 1),
        ("steps", state["steps"] + 1),
        ("t", state["t"] * 2),
        ("case", "of"),
        ("n", 3),
        ("nodes", 64),
        ("format", "adaptimp.state/0"),
        ("snapshot", state["snapshot"][:-5]),
        ("W_D", state["W_D"][..., :10]),
        ("W_D", np.full_like(state["W_D"], np.nan)),
    ]:

        def load(key: str = key, value: Any = value) -> None:
            dst = adaptimp.Controller("sf", scenario="robot")
            before = dst.snapshot()
            try:
                dst.load_state_dict({**state, key: value})
            finally:
                check(np.array_equal(dst.snapshot(), before), "a refused load changed the state")

        case(t, f"load_state_dict with {key} edited", load, "refuse")
    for scale in (1e200, 1e3, np.inf):
        w = {k: v * scale for k, v in src.weights.items()}

        def weights(w: dict[str, np.ndarray] = w) -> None:
            adaptimp.Controller("sf", scenario="robot").load_weights(w)

        case(t, f"load_weights × {scale}", weights, "refuse")

    def whole() -> None:
        dst = adaptimp.Controller("sf", scenario="robot")
        dst.load_state_dict(state)
        check(np.array_equal(dst.snapshot(), src.snapshot()), "load_state_dict is not exact")

    case(t, "load_state_dict unedited", whole, "accept")


def faults(t: Tally, quick: bool) -> None:
    """Random sequences of good and bad samples under every fault policy and
    fallback: torques within τmax, the latch holds, the rate limit holds from
    the torque applied, and no single bad sample bricks the controller."""
    rng = np.random.default_rng(21)
    runs = 24 if quick else 160
    kinds = [
        "nan_q", "inf_tau_e", "huge_q", "huge_tau_e", "dxc_1e99", "xc_1e50", "ddxc",
        "jump", "nan_dq", "shape", "type", "tau_e_1e8", "negative_inf_dq", "xc_nan",
    ]  # fmt: skip
    for r in range(runs):
        case_ = ["pd", "sf", "of"][r % 3]
        policy = ["report", "latch"][(r // 3) % 2]
        fallback = ["hold", "zero", "damping"][(r // 6) % 3]
        kw: dict[str, Any] = {
            "fault_policy": policy,
            "fallback": fallback,
            "fallback_damping": 2.0,
            "tau_rate_max": [None, 0.5][(r // 18) % 2],
            "q_jump_max": [None, 0.05][(r // 36) % 2],
        }
        if r % 5 == 0:
            kw.update(q_max=3.0, dq_max=10.0, tau_e_max=100.0)
        scenario = "robot" if r % 4 else "paper"
        bad_kinds = list(rng.choice(kinds, size=3))

        def run(
            case_: str = case_, scenario: str = scenario, kw: dict[str, Any] = kw,
            bad_kinds: list[str] = bad_kinds, policy: str = policy, fallback: str = fallback,
        ) -> None:  # fmt: skip
            import adaptimp

            ctrl = adaptimp.Controller(case_, scenario=scenario, **kw)
            rate = kw["tau_rate_max"]
            applied = np.zeros(2)
            k = 0

            def good() -> tuple[np.ndarray, str | None]:
                nonlocal k, applied
                tau, err = ctrl.step_or_fallback(_meas(k))
                _torque_ok(ctrl, tau)
                if err is None and rate is not None:
                    check(
                        bool(np.all(np.abs(tau - applied) <= rate + 1e-9)),
                        f"rate limit broken: {applied} → {tau}",
                    )
                applied = np.asarray(tau)
                k += 1
                return tau, err

            for _ in range(30):
                good()
            for kind in bad_kinds:
                q, te, dq = _inputs(k)
                sp: dict[str, Any] = {}
                if kind == "nan_q":
                    q[0] = math.nan
                elif kind == "inf_tau_e":
                    te[1] = math.inf
                elif kind == "huge_q":
                    q[1] = 1e40
                elif kind == "huge_tau_e":
                    te[0] = 1e99
                elif kind == "tau_e_1e8":
                    te[0] = 1e8
                elif kind == "dxc_1e99":
                    sp = {"xc": q, "dxc": [1e99, 0.0]}
                elif kind == "xc_1e50":
                    sp = {"xc": [1e50, 0.0]}
                elif kind == "xc_nan":
                    sp = {"xc": [math.nan, 0.0]}
                elif kind == "ddxc":
                    sp = {"xc": q, "ddxc": [0.0, 1e7]}
                elif kind == "jump":
                    q[0] += 0.5
                elif kind == "nan_dq":
                    dq[0] = math.nan
                elif kind == "negative_inf_dq":
                    dq[1] = -math.inf
                refused_by_shape = False
                before_steps = ctrl.steps
                if kind == "shape":
                    q = [0.0, 0.0, 0.0]
                if kind == "type":
                    q = "x"  # type: ignore[assignment]
                try:
                    tau, err = ctrl.step_or_fallback(q, te, dq, **sp)
                except (TypeError, adaptimp.MeasurementError):
                    refused_by_shape = True
                    err = "raised"
                    tau = None
                if tau is not None:
                    _torque_ok(ctrl, tau)
                if err is None and tau is not None:  # accepted: a plausible sample
                    if rate is not None:
                        check(
                            bool(np.all(np.abs(tau - applied) <= rate + 1e-9)),
                            f"{kind}: rate limit broken: {applied} → {tau}",
                        )
                    applied = np.asarray(tau)
                    k += 1
                if err is not None:
                    check(ctrl.fault is not None, f"{kind}: a refusal recorded no fault")
                    check(ctrl.steps == before_steps, f"{kind}: a refused step advanced the clock")
                    if tau is not None and fallback == "zero":
                        check(bool(np.all(np.asarray(tau) == 0.0)), f"{kind}: zero fallback {tau}")
                    if tau is not None and fallback == "hold":
                        check(bool(np.array_equal(tau, applied)), f"{kind}: hold gave {tau}")
                    if tau is None:  # raised: the torque to apply is ctrl.applied
                        tau = getattr(ctrl, "applied", None)
                        check(tau is not None, f"{kind}: no torque to apply after a refusal")
                        _torque_ok(ctrl, tau)
                        if fallback == "zero":
                            check(bool(np.all(tau == 0.0)), f"{kind}: zero fallback {tau}")
                    applied = np.asarray(tau)
                    if policy == "latch":
                        tau2, err2 = ctrl.step_or_fallback(_meas(k))
                        check(err2 is not None and "latched" in err2, f"{kind}: latch did not hold")
                        _torque_ok(ctrl, tau2)
                        applied = np.asarray(tau2)
                        ctrl.clear_fault()
                del refused_by_shape
                # No brick: normal samples are accepted again within 2 steps
                # (a jump re-anchors after one).
                errors = []
                for _ in range(40):
                    _, e = good()
                    errors.append(e)
                    if policy == "latch" and e is not None:
                        ctrl.clear_fault()
                check(
                    all(e is None for e in errors[2:]),
                    f"{kind}: still refused after the bad sample: {errors[-1]}",
                )

        case(t, f"{case_}/{scenario} {kw} {bad_kinds}", run, "accept")


def njoint(t: Tally, quick: bool) -> None:
    """The n-joint API: every n, arguments of every shape and type."""
    import adaptimp

    ns = [1, 2, 3, 7] if quick else [1, 2, 3, 4, 5, 6, 7]
    for n in ns:
        for case_ in ("pd", "sf", "of"):
            ctrl = _trained(case_, "robot", n, steps=20)
            q, te, dq = _inputs(20, n)
            variants: list[tuple[str, dict[str, Any], str]] = [
                ("lists", {"q": q, "tau_e": te, "dq": dq}, "accept"),
                ("float32", {"q": np.float32(q), "tau_e": te, "dq": dq}, "accept"),
                ("int64 tau_e", {"q": q, "tau_e": np.zeros(n, np.int64), "dq": dq}, "accept"),
                ("tuple", {"q": tuple(q), "tau_e": te, "dq": dq}, "accept"),
                ("strided", {"q": np.repeat(q, 2)[::2], "tau_e": te, "dq": dq}, "accept"),
                ("too short", {"q": q[:-1], "tau_e": te, "dq": dq}, "refuse"),
                ("too long", {"q": [*q, 0.0], "tau_e": te, "dq": dq}, "refuse"),
                ("2-D", {"q": np.array([q]), "tau_e": te, "dq": dq}, "refuse"),
                ("scalar", {"q": 0.1, "tau_e": te, "dq": dq}, "refuse"),
                ("string", {"q": "0.1", "tau_e": te, "dq": dq}, "refuse"),
                ("None q", {"q": None, "tau_e": te, "dq": dq}, "refuse"),
                ("complex", {"q": np.array(q, complex), "tau_e": te, "dq": dq}, "refuse"),
                ("object", {"q": np.array(q, object), "tau_e": te, "dq": dq}, "either"),
                ("bool", {"q": [True] * n, "tau_e": te, "dq": dq}, "either"),
                ("huge int", {"q": [10**400, *q[1:]], "tau_e": te, "dq": dq}, "refuse"),
                ("NaN", {"q": [math.nan, *q[1:]], "tau_e": te, "dq": dq}, "refuse"),
                ("dxc without xc", {"q": q, "tau_e": te, "dq": dq, "dxc": dq}, "refuse"),
                ("setpoint", {"q": q, "tau_e": te, "dq": dq, "xc": q, "dxc": dq}, "accept"),
            ]
            if case_ != "of":
                variants.append(("no dq", {"q": q, "tau_e": te}, "refuse"))
            for what, args, expect in variants:

                def one(
                    ctrl: Any = ctrl, args: dict[str, Any] = args, expect: str = expect
                ) -> None:
                    before = ctrl.steps
                    try:
                        sp = {k: v for k, v in args.items() if k in ("xc", "dxc", "ddxc")}
                        m = adaptimp.Measurement(args["q"], args.get("dq"), tau_e=args["tau_e"])
                        tau = ctrl.step(m, **sp)
                    finally:
                        if expect == "refuse":
                            check(ctrl.steps == before, "a refused step advanced the clock")
                        ctrl.clear_fault()
                    _torque_ok(ctrl, tau)

                case(t, f"n={n} {case_}: step with {what}", one, expect)
            # replay with tables of the wrong shape.
            for what, table in [
                ("(K, n+1)", np.zeros((3, n + 1))),
                ("(K,)", np.zeros(3)),
                ("(3, n) and (4, n)", np.zeros((4, n))),
            ]:

                def rep(ctrl: Any = ctrl, table: np.ndarray = table, n: int = n) -> None:
                    ctrl.replay(np.zeros((3, n)), table, np.zeros((3, n)))

                case(t, f"n={n} {case_}: replay {what}", rep, "refuse")

            def rep32(ctrl: Any = ctrl, n: int = n) -> None:
                q = np.tile(np.float32(_inputs(0, n)[0]), (3, 1))
                out = ctrl.replay(q, np.zeros((3, n)), np.zeros((3, n), np.float32))
                check(out.shape == (3, n), f"replay gave shape {out.shape}")
                for row in out:
                    _torque_ok(ctrl, row)

            case(t, f"n={n} {case_}: replay float32 tables", rep32, "accept")
            # weights of the wrong shapes.
            w = ctrl.weights
            for what, bad in [
                ("D transposed", {**w, "D": np.swapaxes(w["D"], 0, 2)}),
                ("no G", {"D": w["D"], "C": w["C"]}),
                ("G NaN", {**w, "G": np.full_like(w["G"], np.nan)}),
            ]:

                def lw(ctrl: Any = ctrl, bad: dict[str, Any] = bad) -> None:
                    ctrl.load_weights(bad)

                case(t, f"n={n} {case_}: load_weights {what}", lw, "refuse")
    for kw in [
        {"q_jump_max": math.inf},
        {"q_jump_max": [0.05, math.inf]},
        {"q_max": [math.inf, math.inf]},
    ]:
        case(t, f"Controller({kw})", lambda kw=kw: adaptimp.Controller("sf", **kw), "accept")
    for kw in [
        {"q_jump_max": math.nan},
        {"q_max": -math.inf},
        {"dq_max": 0.0},
        {"tau_rate_max": [-1.0, 1.0]},
        {"n": 8},
        {"n": 0},
        {"fault_policy": "ignore"},
        {"fallback": 3},
    ]:
        case(t, f"Controller({kw})", lambda kw=kw: adaptimp.Controller("sf", **kw), "refuse")


def sweeps(t: Tally, quick: bool) -> None:
    """Sweeps and their cache: bad values are error rows; a damaged cache is
    recomputed; cached results equal fresh ones; arms and models are keyed."""
    import adaptimp

    fixed = {"T": 0.2, "substeps": 1, "scenario": "robot"}
    root = Path(tempfile.mkdtemp(prefix="breakit-"))
    try:
        bad_values: list[tuple[str, list[Any]]] = [
            ("m2", [1.0, -1.0]),
            ("m2", [0.0]),
            ("m2", [math.nan]),
            ("l1", [1e300]),
            ("Kp", ["x"]),
            ("Kp", [None]),
            ("Kp", [np.float32(9.5), np.int64(10)]),
            ("Kp", [[9.0, 10.0], [9.0]]),
            ("tau_max", [[17.0, -15.0]]),
            ("q_jump_max", [math.inf, 0.0]),
            ("Ts", [0.0, 1e-3]),
            ("delay", [np.int64(1), 65]),
        ]
        for name, values in bad_values:

            def grid(name: str = name, values: list[Any] = values) -> None:
                df = adaptimp.sweep("pd", vary={name: values}, **fixed)
                check(len(df) == len(values), "a row is missing")
                for i, row in df.iterrows():
                    if row["error"] is None:
                        alone = adaptimp.simulate("pd", **{**fixed, name: values[int(i)]})  # type: ignore[arg-type]
                        check(row["rms_z1"] == alone.metrics["rms_z1"], "a row is not its run")

            case(t, f"sweep vary {name}={values}", grid, "accept")
        draws = 4 if quick else 12
        for seed in range(draws):

            def normal(seed: int = seed) -> None:
                vary = {"m2": adaptimp.Normal(0.3, 0.6), "Kp": adaptimp.LogUniform(5.0, 20.0)}
                cache = root / f"normal{seed}"
                a = adaptimp.sweep("pd", vary=vary, samples=5, seed=seed, cache=cache, **fixed)
                b = adaptimp.sweep("pd", vary=vary, samples=5, seed=seed, cache=cache, **fixed)
                c = adaptimp.sweep("pd", vary=vary, samples=5, seed=seed, **fixed)
                check(a.equals(b) and a.equals(c), "a cached rerun differs")

            case(t, f"sweep Normal draws seed {seed}", normal, "accept")
        arms = [adaptimp.TwoLinkArm(), adaptimp.TwoLinkArm(m2=2.0), adaptimp.TwoLinkArm(l1=0.5)]
        for i, arm in enumerate(arms):

            def keyed(arm: Any = arm, i: int = i) -> None:
                cache = root / "arms"
                a = adaptimp.sweep("pd", vary={"Kp": [10.0]}, arm=arm, cache=cache, **fixed)
                b = adaptimp.sweep("pd", vary={"Kp": [10.0]}, arm=arm, **fixed)
                check(a.equals(b), f"arm {i}: the cache returned another arm's result")

            case(t, f"sweep arm {i} through a shared cache", keyed, "accept")
        damages: list[tuple[str, Callable[[Path], None]]] = [
            ("truncated", lambda p: p.write_bytes(p.read_bytes()[:40])),
            ("empty", lambda p: p.write_bytes(b"")),
            ("non-UTF-8", lambda p: p.write_bytes(b"\xff\xfe\xfa")),
            ("a list", lambda p: p.write_text("[]")),
            ("null", lambda p: p.write_text("null")),
            ("no result", lambda p: p.write_text('{"key": 1}')),
            ("missing metric", lambda p: p.write_text('{"result": {"rms_z1": 1.0}}')),
            ("string metric", lambda p: p.write_text(_with(p, "rms_z1", "x"))),
            ("short joint metric", lambda p: p.write_text(_with(p, "peak_abs_tau", "x"))),
            ("another key", lambda p: p.write_text(_rekey(p))),
            ("a directory", lambda p: (p.unlink(), p.mkdir())),
        ]
        for what, damage in damages:

            def damaged(what: str = what, damage: Callable[[Path], None] = damage) -> None:
                cache = root / f"damage-{what}"
                vary = {"Kp": [9.0, 10.0]}
                fresh = adaptimp.sweep("pd", vary=vary, cache=cache, **fixed)
                damage(sorted(cache.glob("*.json"))[0])
                again = adaptimp.sweep("pd", vary=vary, cache=cache, **fixed)
                check(fresh.equals(again), f"{what}: the rerun differs from the run")

            case(t, f"sweep cache entry {what}", damaged, "accept")
        not_dir = root / "file"
        not_dir.write_text("x")
        for cache in (not_dir, not_dir / "sub"):

            def unwritable(cache: Path = cache) -> None:
                adaptimp.sweep("pd", vary={"Kp": [9.0]}, cache=cache, **fixed)

            case(t, f"sweep cache {cache.name} unwritable", unwritable, "refuse")

        def concurrent() -> None:
            from concurrent.futures import ThreadPoolExecutor

            cache = root / "concurrent"
            kw = {"vary": {"Kp": [8.0, 9.0, 10.0]}, "cache": cache, "batch_size": 1, **fixed}
            with ThreadPoolExecutor(4) as ex:
                frames = list(ex.map(lambda _: adaptimp.sweep("pd", **kw), range(8)))  # type: ignore[arg-type]
            check(all(f.equals(frames[0]) for f in frames), "concurrent sweeps differ")
            check(not list(cache.glob("*.tmp")), "a temporary file was left")

        case(t, "sweep 8 concurrent writers", concurrent, "accept")
        broken = root / "broken.urdf"
        broken.write_text("<robot name='x'><link name='a'>")
        for model in (str(broken), str(root / "missing.xml"), "no_such_model"):

            def mj(model: str = model) -> None:
                df = adaptimp.sweep("pd", vary={"Kp": [10.0]}, plant="mujoco", model=model, T=0.02)
                check(bool(df["error"].notna().all()), "a broken model gave a result")

            case(t, f"sweep mujoco model {Path(model).name}", mj, "accept")
        for T in (math.inf, math.nan, -1.0, 1e300):

            def mjT(T: float = T) -> None:
                from adaptimp import mujoco as amj

                amj.simulate("pd", "two_link", T=T)

            case(t, f"mujoco.simulate(T={T})", mjT, "refuse")
    finally:
        shutil.rmtree(root, ignore_errors=True)


def _with(p: Path, metric: str, value: Any) -> str:
    data = json.loads(p.read_text())
    data["result"][metric] = value
    return json.dumps(data)


def _rekey(p: Path) -> str:
    data = json.loads(p.read_text())
    data["key"] = "0" * 24
    return json.dumps(data)


# ---------------------------------------------------------------------------
# The surfaces of issue 33: chains, the Cartesian front, formulations, the
# dynamics and computed torque, saves, MuJoCo runs.
# ---------------------------------------------------------------------------

BAD = (math.nan, math.inf, -math.inf, 1e300, -1e300, 1e200, 1e151, 1e50, 1e7, 1e-320, 0.0, -1.0)


def _arm3() -> Any:
    import adaptimp

    return adaptimp.Chain(
        [
            {"kind": "revolute", "axis": [0, 0, 1]},
            {"kind": "revolute", "xyz": [0.3, 0, 0], "axis": [0, 1, 0]},
            {"kind": "revolute", "xyz": [0.3, 0, 0], "axis": [1, 0, 0]},
        ],
        tip={"xyz": [0.2, 0, 0]},
    )


def _finite(*arrays: Any) -> None:
    for a in arrays:
        check(bool(np.all(np.isfinite(np.asarray(a, dtype=float)))), f"not finite: {a}")


def chains(t: Tally, quick: bool) -> None:
    """Chains from joint data: every field of a joint with every bad value, the
    origin conventions, names, sites; fk, Jacobian, J̇q̇ and motion with bad
    rates and shapes. Accepted: finite outputs, and a movable joint that moves
    the tip (no zero axis)."""
    import adaptimp

    base = [
        {"kind": "revolute", "axis": [0, 0, 1]},
        {"kind": "prismatic", "xyz": [0.3, 0, 0], "rpy": [0.1, 0.2, 0.3], "axis": [1, 0, 0]},
        {"kind": "revolute", "pos": [0.1, 0, 0], "quat": [1, 0, 0, 0], "axis": [0, 1, 0]},
    ]
    fields = [("axis", 3), ("xyz", 3), ("rpy", 3), ("quat", 4), ("offset", 1)]
    values = BAD if not quick else BAD[::2]
    for j in range(3):
        for key, size in fields:
            if key not in base[j] and key != "offset":
                continue
            for i in range(size):
                for v in values:

                    def one(j: int = j, field: str = key, i: int = i, v: float = v) -> None:
                        joints = [dict(x) for x in base]
                        if field == "offset":
                            joints[j]["offset"] = v
                        else:
                            joints[j][field] = list(joints[j][field])
                            joints[j][field][i] = v
                        arm = adaptimp.Chain(joints, tip={"xyz": [0.2, 0, 0]})
                        q = [0.1, 0.05, -0.2]
                        _finite(arm.fk(q), arm.jacobian(q), arm.jdot_qdot(q, [0.1] * 3))
                        # Every movable joint moves the tip or turns it.
                        col = np.abs(arm.jacobian(q)).max(axis=0)
                        check(bool(np.all(col > 0)), f"a joint that moves nothing: {col}")

                    axis = list(base[j]["axis"])
                    if field == "axis":
                        axis[i] = v
                    zero_axis = field == "axis" and float(np.linalg.norm(axis)) <= 1e-12
                    bad_value = not math.isfinite(v) or zero_axis
                    case(
                        t,
                        f"joint {j} {field}[{i}] = {v:g}",
                        one,
                        "refuse" if bad_value else "either",
                    )
    extra: list[tuple[str, dict[str, Any], str]] = [
        ("quat with rpy", {"quat": [1, 0, 0, 0], "rpy": [0, 0, 1]}, "refuse"),
        ("xyz with pos", {"xyz": [0, 0, 1], "pos": [0, 0, 1]}, "refuse"),
        ("rotation with rpy", {"rotation": np.eye(3).tolist(), "rpy": [0, 0, 1]}, "refuse"),
        ("a reflection", {"rotation": np.diag([1.0, 1.0, -1.0]).tolist()}, "refuse"),
        ("a sloppy rotation", {"rotation": (np.eye(3) * (1 + 4e-7)).tolist()}, "accept"),
        ("R × 1.1", {"rotation": (np.eye(3) * 1.1).tolist()}, "refuse"),
        ("axis [0, 0, 1e200]", {"axis": [0, 0, 1e200]}, "accept"),
        ("axis [1e308, 1e308, 0]", {"axis": [1e308, 1e308, 0]}, "accept"),
        ("axis of 2 values", {"axis": [0, 1]}, "refuse"),
        ("axis as a string", {"axis": "z"}, "refuse"),
        ("kind 'ball'", {"kind": "ball"}, "refuse"),
        ("kind 3", {"kind": 3}, "refuse"),
        ("no axis", {"axis": None}, "refuse"),
    ]
    for what, patch, expect in extra:

        def mixed(patch: dict[str, Any] = patch) -> None:
            j = {"kind": "revolute", "axis": [0, 0, 1], **patch}
            if j.get("axis") is None:
                j.pop("axis")
            arm = adaptimp.Chain([j], tip={"xyz": [0.3, 0, 0]})
            _finite(arm.fk([0.2]), arm.jacobian([0.2]))
            check(float(np.abs(arm.jacobian([0.2])).max()) > 0.1, "a zero axis")
            r = arm.fk([0.2])[:3, :3]
            check(abs(np.linalg.det(r) - 1.0) < 1e-12, f"det R = {np.linalg.det(r)}")

        case(t, f"Chain with {what}", mixed, expect)
    for what, names, expect in [
        ("two names for one joint", ["a", "b"], "refuse"),
        ("a string", "ab", "refuse"),
        ("one name", ["a"], "accept"),
    ]:
        case(
            t,
            f"names: {what}",
            lambda names=names: adaptimp.Chain(  # type: ignore[misc]
                [{"kind": "revolute", "axis": [0, 0, 1]}], names=names
            ),
            expect,
        )
    arm = _arm3()
    q = [0.3, 0.6, 0.2]
    z23 = np.zeros((2, 3))
    calls: list[tuple[str, Callable[[], object], str]] = []
    for v in values:
        either = "refuse" if not math.isfinite(v) or abs(v) > 1e6 else "either"
        calls += [
            (f"fk q[1] = {v:g}", lambda v=v: arm.fk([0.3, v, 0.2]), either),
            (f"jacobian q[0] = {v:g}", lambda v=v: arm.jacobian([v, 0.6, 0.2]), either),
            (f"jdot_qdot dq[2] = {v:g}", lambda v=v: arm.jdot_qdot(q, [0.1, 0.1, v]), either),
            (f"motion dq = {v:g}", lambda v=v: arm.motion(z23, np.full((2, 3), v), z23), either),
        ]
    calls += [
        ("fk of 2 values", lambda: arm.fk([0.1, 0.2]), "refuse"),
        ("fk of a string", lambda: arm.fk("q"), "refuse"),
        (
            "motion of a 1-D array",
            lambda: arm.motion(np.zeros(3), np.zeros(3), np.zeros(3)),
            "refuse",
        ),
        ("motion of other lengths", lambda: arm.motion(z23, np.zeros((3, 3)), z23), "refuse"),
        (
            "motion of lists",
            lambda: arm.motion([[0.1, 0.2, 0.3]], [[0, 0, 1]], [[0, 0, 0]]),
            "accept",
        ),
    ]
    for what, fn, expect in calls:

        def out(fn: Callable[[], object] = fn) -> None:
            r = fn()
            _finite(*(r if isinstance(r, tuple) else (r,)))

        case(t, what, out, expect)
    try:
        import mujoco
    except ImportError:
        return
    m = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><joint type="hinge"/><geom size=".1"/>'
        '<site name="s"/><site name="t"/></body></worldbody></mujoco>'
    )
    for site, expect in [(1.5, "refuse"), (True, "refuse"), (-1, "refuse"), (2, "refuse"),
                         ("nope", "refuse"), (1, "accept"), (np.int64(0), "accept")]:  # fmt: skip
        case(
            t,
            f"from_mujoco site {site!r}",
            lambda site=site: adaptimp.Chain.from_mujoco(m, site),
            expect,
        )


TURN = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
"""A quarter turn about z."""


def _refused_step(c: Any, q: Any) -> bool:
    """One step of a Cartesian controller: whether it was refused."""
    import adaptimp

    try:
        c.step(adaptimp.Measurement(q, np.zeros(3), wrench=np.zeros(6)))
    except (adaptimp.MeasurementError, ValueError, TypeError):
        return True
    return False


def _cart(**kw: Any) -> Any:
    import adaptimp

    return adaptimp.CartesianController(
        _arm3(), "pd", q0=[0.3, 0.6, 0.2], tau_max=20.0, Kp=5.0, Kzeta=25.0, **kw
    )


def _cart_meas(q: Any, w: Any = None) -> Any:
    """A Cartesian step's measurement of the 3-joint arm at rest: q, the wrench ``w``."""
    import adaptimp

    return adaptimp.Measurement(q, np.zeros(3), wrench=np.zeros(6) if w is None else w)


def _cart_steps(c: Any, k: int) -> np.ndarray:
    q0 = np.array([0.3, 0.6, 0.2])
    return np.array([c.step(_cart_meas(q0 + 1e-3 * np.sin(i + np.arange(3)))) for i in range(k)])


def cartesian(t: Tally, quick: bool) -> None:
    """The Python Cartesian front: bad targets (each part, each bad value, R that
    is no rotation or of the wrong shape), wrenches, postures, starts, resets,
    stiffnesses, orbits and paths. A refused call keeps nothing: the controller
    then steps bit-identically to a twin that never saw it; an accepted step's
    torque is finite and within τmax."""
    import adaptimp
    from adaptimp.cartesian import CartesianImpedance

    arm = _arm3()
    q0 = np.array([0.3, 0.6, 0.2])
    p0, R0 = arm.fk(q0)[:3, 3], arm.fk(q0)[:3, :3]
    z3 = np.zeros(3)

    def twin(call: Callable[[Any], object], expect: str, name: str) -> None:
        def run() -> None:
            a, b = _cart(), _cart()
            _cart_steps(a, 3)
            _cart_steps(b, 3)
            try:
                out = call(a)
            except BaseException:
                check(
                    np.array_equal(_cart_steps(a, 10), _cart_steps(b, 10)),
                    "a refused call changed what the controller does",
                )
                raise
            if out is not None and np.ndim(out) == 1 and len(out) == 3:
                _finite(out)
                check(bool(np.all(np.abs(out) <= 20.0 + 1e-12)), f"torque {out} beyond τmax")
            tau = _cart_steps(a, 10)
            _finite(tau)

        case(t, name, run, expect)

    values = BAD if not quick else BAD[::2]
    parts = [("xc", 3), ("dxc", 3), ("ddxc", 3), ("w", 3), ("dw", 3)]
    for part, size in parts:
        for i in range(size) if not quick else (0,):
            for v in values:
                bad = not math.isfinite(v) or abs(v) > 1e6

                def target(c: Any, part: str = part, i: int = i, v: float = v) -> object:
                    kw: dict[str, Any] = {"xc": p0.copy(), "R": R0}
                    kw[part] = kw.get(part, z3).copy() if part in kw else z3.copy()
                    kw[part][i] = v
                    return c.step(_cart_meas(q0), **kw)

                twin(target, "refuse" if bad else "either", f"step {part}[{i}] = {v:g}")
    for what, R, expect in [
        ("R0", R0, "accept"),
        ("1.1·R0", 1.1 * R0, "refuse"),
        ("a reflection", R0 @ np.diag([1.0, 1.0, -1.0]), "refuse"),
        ("R0 + 1e-9", R0 + 1e-9, "accept"),
        ("R0 + 1e-5", R0 + 1e-5, "refuse"),
        ("NaN in R", np.where(np.eye(3) > 0, math.nan, 0.0), "refuse"),
        ("flat (9,)", R0.ravel(), "refuse"),
        ("4 values", [1, 0, 0, 1], "refuse"),
        ("a string", "R", "refuse"),
    ]:
        twin(lambda c, R=R: c.step(_cart_meas(q0), xc=p0, R=R), expect, f"step R = {what}")
        twin(lambda c, R=R: c.outer.target(p0, R=R), expect, f"target(R = {what})")
    for what, w, expect in [
        ("(6,)", np.zeros(6), "accept"),
        ("(3,)", np.ones(3), "accept"),
        ("(2, 3)", np.zeros((2, 3)), "refuse"),
        ("(5,)", np.zeros(5), "refuse"),
        ("NaN", [math.nan, 0, 0, 0, 0, 0], "refuse"),
        ("1e10", [1e10, 0, 0, 0, 0, 0], "refuse"),
        ("strings", ["a"] * 6, "refuse"),
    ]:
        twin(lambda c, w=w: c.step(_cart_meas(q0, w)), expect, f"wrench {what}")

    def started(v: float) -> None:
        c = adaptimp.CartesianController(_arm3(), "pd", q0=[v, 0.6, 0.2], tau_max=20.0)
        _finite(_cart_steps(c, 2))

    for v in values:
        far = "refuse" if not math.isfinite(v) or abs(v) > 1e6 else "either"
        pull = "refuse" if not math.isfinite(v) or abs(v) > 4e4 else "either"  # null_k = 25
        stiff = "refuse" if not math.isfinite(v) or v < 0 or v > 1e9 else "either"
        twin(lambda c, v=v: c.outer.set_posture([0.3, v, 0.2]), pull, f"set_posture[1] = {v:g}")
        twin(lambda c, v=v: c.outer.set_stiffness([v, 100.0, 100.0]), stiff, f"Kd[0] = {v:g}")
        twin(lambda c, v=v: c.outer.reset([0.3, v, 0.2]), far, f"outer.reset q0[1] = {v:g}")
        case(t, f"CartesianController q0[0] = {v:g}", lambda v=v: started(v), far)
    for what, call, expect in [
        ("set_stiffness of 2", lambda c: c.outer.set_stiffness([1, 2]), "refuse"),
        ("set_stiffness (1, 1) rot", lambda c: c.outer.set_stiffness(100.0, [[1.0]]), "refuse"),
        ("set_posture of 6", lambda c: c.outer.set_posture(np.zeros(6)), "refuse"),
        ("reset(np.zeros(6))", lambda c: c.outer.reset(np.zeros(6)), "refuse"),
        ("xc of 2", lambda c: c.step(_cart_meas(q0), xc=[0.3, 0.0]), "refuse"),
        ("q of 2", lambda c: c.step(adaptimp.Measurement([0.3, 0.6], [0.0] * 2)), "refuse"),
        ("q NaN", lambda c: c.step(_cart_meas([0.3, math.nan, 0.2])), "refuse"),
        ("q NaN with a new R", lambda c: c.step(_cart_meas([math.nan, 0.6, 0.2]), xc=p0,
                                                R=R0 @ TURN), "refuse"),
    ]:  # fmt: skip
        twin(call, expect, what)
    ci = CartesianImpedance(arm, Ts=1e-3, q0=q0)
    calls = [0]

    def path(tt: float) -> Any:
        calls[0] += 1
        return (p0, z3, z3)

    for what, kw, expect in [
        ("T = 1e9", {"T": 1e9}, "refuse"),
        ("T = NaN", {"T": math.nan}, "refuse"),
        ("T = -1", {"T": -1.0}, "refuse"),
        ("T = '1.0'", {"T": "1.0"}, "refuse"),
        ("T = True", {"T": True}, "refuse"),
        ("nodes = -5", {"T": 0.05, "nodes": -5}, "refuse"),
        ("nodes = 0", {"T": 0.05, "nodes": 0}, "refuse"),
        ("nodes = 2.5", {"T": 0.05, "nodes": 2.5}, "refuse"),
        ("nodes = True", {"T": 0.05, "nodes": True}, "refuse"),
        ("nodes = 10**12", {"T": 0.01, "nodes": 10**12}, "accept"),
        ("nodes = 4", {"T": 0.05, "nodes": 4}, "accept"),
    ]:

        def orbit(kw: dict[str, Any] = kw, expect: str = expect) -> None:
            calls[0] = 0
            args = dict(kw)
            try:
                c, _ = ci.orbit_centres(path, args.pop("T"), **args)
            finally:
                if expect == "refuse":
                    check(calls[0] == 0, "the path was tabulated before the refusal")
            _finite(c)

        case(t, f"orbit_centres {what}", orbit, expect)
    # A path that returns one bad R, then good ones: that step is refused, no more.
    for what, bad_value in [
        ("1.1·R", lambda: 1.1 * R0),
        ("a 2-tuple", None),
        ("R of 4", lambda: [1, 0, 0, 1]),
    ]:

        def pathed(bad_value: Any = bad_value) -> None:
            k = [0]

            def pth(tt: float) -> Any:
                k[0] += 1
                if k[0] == 3:
                    return (p0, z3) if bad_value is None else (p0, z3, z3, bad_value(), z3, z3)
                return (p0, z3, z3, R0, z3, z3)

            c = _cart(path=pth)
            refused = sum(_refused_step(c, q0) for _ in range(8))
            check(refused == 1, f"{refused} steps refused after one bad path value")

        case(t, f"a path that returns {what} once", pathed, "accept")  # fmt: skip


def formulations(t: Tally, quick: bool) -> None:
    """The formulations (SPEC §19) and their share: by name, every bad value;
    accepted ones step with finite torques within τmax."""

    for form in ("admittance", "impedance", "unified", "Unified", "", None, 3):
        for share in (None, 0.0, 0.3, 1.0, -0.1, 1.5, math.nan, True):
            kw: dict[str, Any] = {"formulation": form}
            if share is not None:
                kw["admittance_share"] = share
            ok_form = form in ("admittance", "impedance", "unified")
            ok_share = share is None or (
                form == "unified" and not isinstance(share, bool) and 0.0 <= share <= 1.0
            )
            expect = "either" if ok_form and ok_share else "refuse"

            def run(kw: dict[str, Any] = kw) -> None:
                c = _cart(**kw)
                tau = _cart_steps(c, 20)
                _finite(tau)
                check(bool(np.all(np.abs(tau) <= 20.0 + 1e-12)), "torque beyond τmax")

            case(t, f"formulation={form!r} share={share!r}", run, expect)


def dynamics(t: Tally, quick: bool) -> None:
    """Computed torque and its model (RNEA): construction with every bad value
    of every scalar; the model's queries with bad rates; accepted: finite."""
    try:
        from adaptimp import Measurement
        from adaptimp.baselines import ComputedTorque
    except ImportError:
        return
    values = BAD if not quick else BAD[::2]
    positive = ("Ts", "Kp", "mass_scale", "tau_max", "Dd")  # > 0; the others ≥ 0
    for name in ("Ts", "Kp", "Kd", "mass_scale", "payload", "tau_max", "armature", "damping",
                 "friction", "Dd", "Gd"):  # fmt: skip
        for v in values:
            bad = (
                not math.isfinite(v)
                or v < 0
                or (v == 0.0 and name in positive)
                or abs(v) > 1e9
                or (name == "Ts" and v > 1.0)
            )

            def make(name: str = name, v: float = v) -> None:
                ct = ComputedTorque(**{name: v})
                for _ in range(5):
                    _finite(ct.step(Measurement([0.1, 0.2], [0.0, 0.0])))

            case(t, f"ComputedTorque({name}={v:g})", make, "refuse" if bad else "either")
    ct = ComputedTorque()
    for v in values:
        bad = not math.isfinite(v) or abs(v) > 1e6
        for what, args in [
            ("q", ([v, 0.0], [0.0, 0.0], [0.0, 0.0])),
            ("dq", ([0.0, 0.0], [v, 0.0], [0.0, 0.0])),
            ("ddq", ([0.0, 0.0], [0.0, 0.0], [0.0, v])),
        ]:
            rnea = lambda args=args: _finite(ct.inverse_dynamics(*args))  # noqa: E731
            case(t, f"inverse_dynamics {what} = {v:g}", rnea, "refuse" if bad else "either")
        case(t, f"mass_matrix q = {v:g}", lambda v=v: _finite(ct.mass_matrix([v, 0.0])),
             "refuse" if bad else "either")  # fmt: skip
    for name in ("payload", "mass_scale", "Ts"):  # a bool was taken as 1
        case(t, f"ComputedTorque({name}=True)", lambda n=name: ComputedTorque(**{n: True}),
             "refuse")  # fmt: skip
    _gravcomp(t)


_GRAVCOMP = """<mujoco><option gravity='0.3 -0.2 -9.81'/><worldbody>
<body name='a' pos='0 0 0.1'><joint name='j1' axis='0 0 1'/><geom size='0.05' mass='1'/>
 <body name='b' pos='0.3 0 0' gravcomp='{b}'><joint name='j2' axis='0 1 0'/>
  <geom type='capsule' fromto='0 0 0 0.25 0 0' size='0.03' mass='2'/>
  <body name='held' pos='0.25 0 0' gravcomp='{held}'>
   <geom size='0.04' pos='0.02 0.01 0' mass='0.5'/></body>
  <body name='c' pos='0.25 0 0' gravcomp='{c}'><joint name='j3' axis='0 1 0'/>
   <geom type='box' size='0.1 0.02 0.02' pos='0.1 0 0' mass='0.7'/><site name='tip' pos='0.2 0 0'/>
  </body></body></body></worldbody>
<actuator><motor joint='j1' ctrlrange='-50 50'/><motor joint='j2' ctrlrange='-50 50'/>
<motor joint='j3' ctrlrange='-50 50'/></actuator></mujoco>"""


def _gravcomp(t: Tally) -> None:
    """Computed torque's inverse dynamics against MuJoCo's with gravity
    compensation on some bodies (``gravcomp``: it was off by exactly
    ``qfrc_gravcomp``): to 1e-12 of its scale."""
    try:
        import mujoco

        from adaptimp.baselines import ComputedTorque
    except ImportError:
        return
    for shares in ((0.5, 1.0, 0.2), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (-0.5, 2.0, 0.3)):

        def exact(shares: tuple[float, ...] = shares) -> None:
            b, held, c = shares
            m = mujoco.MjModel.from_xml_string(_GRAVCOMP.format(b=b, held=held, c=c))
            d = mujoco.MjData(m)
            ct = ComputedTorque(m, tip="tip")
            rng = np.random.default_rng(3)
            for _ in range(5):
                q, dq, ddq = rng.uniform(-2, 2, 3), rng.normal(size=3), rng.normal(size=3)
                d.qpos[:], d.qvel[:], d.qacc[:] = q, dq, ddq
                mujoco.mj_inverse(m, d)
                err = np.abs(ct.inverse_dynamics(q, dq, ddq) - d.qfrc_inverse).max()
                check(err <= 1e-12 * max(1.0, np.abs(d.qfrc_inverse).max()), f"off by {err:g}")

        case(t, f"computed torque with gravcomp {shares} = mj_inverse", exact, "accept")


def saves(t: Tally, quick: bool) -> None:
    """SimResult and MujocoResult files: bit flips in every stored entry, arrays
    swapped or scaled, truncations, JSON edits of every record. A damaged file
    is a SaveError naming it; nothing damaged loads; an intact one loads bit
    for bit."""
    import adaptimp

    root = Path(tempfile.mkdtemp(prefix="breakit-saves-"))
    try:
        fault = adaptimp.Fault("nan_burst", 0.01, 0.01)
        runs: dict[str, Any] = {
            "fault run": adaptimp.simulate("sf", T=0.05, fault=fault),
            "rerun": adaptimp.simulate("pd", T=0.05),
        }
        try:
            from adaptimp import mujoco as amj

            runs["MuJoCo run"] = amj.simulate("pd", "two_link", T=0.05)
        except ImportError:
            pass
        rng = np.random.default_rng(33)
        for label, res in runs.items():
            for compress in (True, False):
                path = res.save(root / f"{label}-{compress}", compress=compress)
                _save_cases(t, f"{label} compress={compress}", res, path, rng, quick)
        _save_writes(t, root, runs["rerun"], runs["fault run"], quick)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def _same_run(a: Any, b: Any) -> bool:
    return a.case == b.case and all(np.array_equal(getattr(a, k), getattr(b, k)) for k in _ROWS)


def _save_writes(t: Tally, root: Path, a: Any, b: Any, quick: bool) -> None:
    """How a save is written and what a file says it is: saves from several
    threads to one path (one of them whole, every load meanwhile good), a save
    that fails partway (the old file intact), a folder as the path, a numpy
    integer ``every``, a format-4 file declared format 2 or 3 (its record
    dropped and q and tau swapped, or its record kept), a MuJoCo result's load
    of another kind's file."""
    import threading

    import adaptimp

    path = root / "shared.npz"

    def concurrent() -> None:
        a.save(path, recompute=False)
        failures: list[str] = []
        done = threading.Event()

        def save(r: Any) -> None:
            for _ in range(3 if quick else 10):
                r.save(path, recompute=False)

        def load_once() -> None:
            try:
                adaptimp.SimResult.load(path)
            except Exception as e:  # the failure is the result
                failures.append(repr(e))

        def load() -> None:
            while not done.is_set():
                load_once()

        reader = threading.Thread(target=load)
        reader.start()
        savers = [threading.Thread(target=save, args=(r,)) for r in (a, b, a, b)]
        for th in savers:
            th.start()
        for th in savers:
            th.join()
        done.set()
        reader.join()
        check(not failures, f"a load failed while others saved: {failures[:1]}")
        left = adaptimp.SimResult.load(path)
        check(_same_run(left, a) or _same_run(left, b), "the file left is neither save")
        check(sorted(p.name for p in root.glob("*shared*")) == ["shared.npz"], "a part left")

    case(t, "saves: 4 threads save to one path, a fifth loads", concurrent, "accept")

    def failed_save() -> None:
        a.save(path, recompute=False)
        before = path.read_bytes()
        code = (
            "import resource, signal, adaptimp\n"
            "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
            "res = adaptimp.simulate('sf', T=0.05)\n"
            "resource.setrlimit(resource.RLIMIT_FSIZE, (2048, 2048))\n"
            f"try:\n    res.save({str(path)!r}, recompute=False)\n"
            "except OSError:\n    print('refused')\n"
        )
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        check(out.stdout.strip() == "refused", f"the failing save did not fail: {out.stderr}")
        check(path.read_bytes() == before, "a failed save changed the file that was there")

    case(t, "saves: a save that fails partway over a good one", failed_save, "accept")
    (root / "folder").mkdir(exist_ok=True)
    for what in (f"{root / 'folder'}/", str(root / "folder"), f"{root / 'new'}/"):
        case(t, f"saves: save({what!r}) (a folder)", lambda w=what: a.save(w), "refuse")
    case(t, "saves: every=np.int64(2)",
         lambda: check(adaptimp.SimResult.load(a.save(root / "half", every=np.int64(2)))
                       .record_every == 2, "record_every"), "accept")  # fmt: skip
    saved = b.save(root / "v4", recompute=False)
    with np.load(saved, allow_pickle=False) as f:
        content = {k: f[k] for k in f}
    for version in (2, 3):
        for swap, keep in ((True, False), (False, True), (False, False)):
            fmt = json.loads(str(content["format"]))
            fmt["version"] = version
            if not keep:
                for key in ("arrays", "inputs", "metrics", "result"):
                    fmt.pop(key)
                if version < 3:
                    fmt.pop("simulated")
                    fmt.pop("n")
            edited = dict(content)
            if swap:
                edited["q"], edited["tau"] = content["tau"], content["q"]
                d = fmt["differences"]
                d["q"], d["tau"] = d["tau"], d["q"]
            edited["format"] = np.array(json.dumps(fmt))
            label = (f"saves: format 4 declared {version}, record {'kept' if keep else 'dropped'}"
                     f"{', q and tau swapped' if swap else ''}")  # fmt: skip

            def declared(e: dict[str, Any] = edited, honest: bool = not (swap or keep)) -> None:
                out = root / "declared.npz"
                np.savez(out, **e)
                back = adaptimp.SimResult.load(out)
                check(honest, "an edited file loaded")
                check(_same_run(back, b), "not bit for bit")

            case(t, label, declared, "accept" if not (swap or keep) else "refuse")
    try:
        from adaptimp import mujoco as amj
    except ImportError:
        return
    plain = a.save(root / "plain", compress=False)
    case(t, "saves: MujocoResult.load of a SimResult's file",
         lambda: repr(amj.MujocoResult.load(plain)), "refuse")  # fmt: skip


_ROWS = ("t", "q", "dq", "xc", "xd", "tau", "tau_sat", "tau_e", "zeta", "z1")


def _save_cases(
    t: Tally, label: str, res: Any, path: Path, rng: np.random.Generator, quick: bool
) -> None:
    """The damages of one saved file (see :func:`saves`)."""
    import json as _json

    with np.load(path, allow_pickle=False) as f:
        content = {k: f[k] for k in f}
    bad = path.with_name("bad.npz")

    def intact(p: Path = path) -> None:
        back = type(res).load(p)
        for name in _ROWS:
            same = np.array_equal(getattr(back, name), getattr(res, name), equal_nan=True)
            check(same, f"{name} not bit for bit")
        repr(back)

    def refused(edited: dict[str, Any]) -> None:
        np.savez(bad, **edited)
        loaded = type(res).load(bad)
        check(False, f"a damaged file loaded ({loaded.rows} rows)")

    case(t, f"{label}: load intact", intact, "accept")
    arrays = [k for k, v in content.items() if v.dtype.kind in "fu" and v.ndim >= 1]
    for _ in range((6 if quick else 30) if arrays else 0):
        name = arrays[int(rng.integers(len(arrays)))]
        a = content[name].copy()
        flat = a.reshape(-1).view(np.uint8)
        i, bit = int(rng.integers(flat.size)), int(rng.integers(8))
        flat[i] ^= np.uint8(1 << bit)
        edited = {**content, name: a}
        case(
            t,
            f"{label}: flip bit {bit} of byte {i} of {name}",
            lambda e=edited: refused(e),
            "refuse",
        )
    m = _json.loads(str(content["format"]))
    for a, b in [("q", "dq"), ("q", "tau"), ("xc", "xd"), ("tau_e", "zeta")]:
        if a in content and b in content and content[a].shape == content[b].shape:
            mm = _json.loads(str(content["format"]))
            d = mm.get("differences", {})
            if a in d and b in d:
                d[a], d[b] = d[b], d[a]
            edited = {**content, a: content[b], b: content[a], "format": np.array(_json.dumps(mm))}
            case(t, f"{label}: swap {a} and {b}", lambda e=edited: refused(e), "refuse")
    if m.get("plain"):
        edited = {**content, "q": content["q"] * 1.5}
        case(t, f"{label}: q × 1.5", lambda e=edited: refused(e), "refuse")
    data = path.read_bytes()
    for frac in (0.0, 0.3, 0.9, 0.999) if quick else np.linspace(0, 0.999, 12):

        def truncated(frac: float = float(frac)) -> None:
            bad.write_bytes(data[: int(len(data) * frac)])
            type(res).load(bad)
            check(False, "a truncated file loaded")

        case(t, f"{label}: truncated to {frac:.1%}", truncated, "refuse")
    for key in [*m, "version"]:
        informative = key in ("adaptimp", "result")  # what saved it: not checked
        mm = dict(m)
        if key == "version":
            mm["version"] = 99
        else:
            del mm[key]
        edited = {**content, "format": np.array(_json.dumps(mm))}

        def dropped(edited: dict[str, Any] = edited, informative: bool = informative) -> None:
            if not informative:
                refused(edited)
            np.savez(bad, **edited)
            intact(bad)

        expect = "accept" if informative else "refuse"
        case(t, f"{label}: format record without {key}", dropped, expect)
    for entry, value in [("params", "{"), ("metrics", "[]"), ("case", 3.0), ("record_every", 0)]:
        edited = {**content, entry: np.array(value)}
        case(t, f"{label}: {entry} = {value!r}", lambda e=edited: refused(e), "refuse")
    params = _json.loads(str(content["params"]))
    if "T" in params:
        edited = {**content, "params": np.array(_json.dumps({**params, "T": 1e5}))}
        case(t, f"{label}: params T edited", lambda e=edited: refused(e), "refuse")


def mujoco_runs(t: Tally, quick: bool) -> None:
    """adaptimp.mujoco.simulate's arguments: durations, periods, substeps,
    payloads, references of the wrong shape, models without actuators."""
    try:
        from adaptimp import mujoco as amj
    except ImportError:
        return
    root = Path(tempfile.mkdtemp(prefix="breakit-mujoco-"))
    try:
        noact = root / "noact.xml"
        noact.write_text('<mujoco><worldbody><body><joint type="hinge"/><geom size=".1" mass="1"/>'
                         "</body></worldbody></mujoco>")  # fmt: skip
        z2, z3 = np.zeros(2), np.zeros(3)
        cases_: list[tuple[str, dict[str, Any], str]] = [
            ("payload=1e300", {"payload": 1e300}, "refuse"),
            ("payload=-1", {"payload": -1.0}, "refuse"),
            ("payload=True", {"payload": True}, "refuse"),
            ("payload=0.5", {"payload": 0.5}, "accept"),
            ("a reference of 2 values", {"reference": lambda tt: (z2, z2)}, "refuse"),
            ("a reference of 3 joints", {"reference": lambda tt: (z3, z3, z3)}, "refuse"),
            ("a reference of strings", {"reference": lambda tt: ("a", "b", "c")}, "refuse"),
            ("q0 of 3", {"q0": [0.0, 0.0, 0.0]}, "refuse"),
            ("q0 NaN", {"q0": [math.nan, 0.0]}, "refuse"),
            ("T = NaN", {"T": math.nan}, "refuse"),
            ("T = -1", {"T": -1.0}, "refuse"),
        ]  # fmt: skip
        cases_ += [  # issue 33 D (the loop's arguments)
            ("substeps=2.5", {"substeps": 2.5}, "refuse"),
            ("substeps=True", {"substeps": True}, "refuse"),
            ("substeps=10**9", {"substeps": 10**9}, "refuse"),
            ("substeps=0", {"substeps": 0}, "refuse"),
            ("substeps=2", {"substeps": 2}, "accept"),
            ("T='1.0'", {"T": "1.0"}, "refuse"),
            ("T=True", {"T": True}, "refuse"),
            ("Ts=-1e-3", {"Ts": -1e-3}, "refuse"),
            ("Ts=NaN", {"Ts": math.nan}, "refuse"),
        ]
        for what, kw, expect in cases_:

            def run(kw: dict[str, Any] = kw) -> None:
                res = amj.simulate("pd", "two_link", **{"T": 0.02, **kw})
                _finite(res.tau_sat)

            case(t, f"mujoco.simulate {what}", run, expect)

        # Files as a user has them: broken, foreign, of the wrong kind, a tip or
        # fix that is not there, too many joints, a joint with two motors.
        def body(i: int, inner: str = "") -> str:
            return (f'<body name="b{i}" pos="0 0 .1"><joint name="j{i}" type="hinge" '
                    f'axis="0 1 0"/><geom size=".05" mass="1"/>{inner}</body>')  # fmt: skip

        chain9 = ""
        for i in reversed(range(9)):
            chain9 = body(i, chain9)
        motors9 = "".join(f'<motor joint="j{i}" ctrlrange="-5 5"/>' for i in range(9))
        files = {
            "missing.xml": None,
            "broken.xml": "<mujoco><worldbody><body>",
            "not_xml.xml": "\x00\x01 binary",
            "a_free_body.xml": '<mujoco><worldbody><body><freejoint/><geom size=".1"/>'
            "</body></worldbody></mujoco>",
            "nine_joints.xml": f"<mujoco><worldbody>{chain9}</worldbody>"
            f"<actuator>{motors9}</actuator></mujoco>",
            "two_motors.xml": f"<mujoco><worldbody>{body(0)}</worldbody><actuator>"
            '<motor joint="j0"/><motor joint="j0"/></actuator></mujoco>',
            "arm.xml": f"<mujoco><worldbody>{body(0, body(1))}</worldbody><actuator>"
            '<motor joint="j0" ctrlrange="-5 5"/><motor joint="j1" ctrlrange="-5 5"/>'
            "</actuator></mujoco>",
        }
        for name, text in files.items():
            if text is not None:
                (root / name).write_text(text)
        for name, kw, expect in [
            ("missing.xml", {}, "refuse"),
            ("broken.xml", {}, "refuse"),
            ("not_xml.xml", {}, "refuse"),
            ("a_free_body.xml", {}, "refuse"),
            ("nine_joints.xml", {}, "refuse"),
            ("two_motors.xml", {}, "refuse"),
            ("arm.xml", {}, "accept"),
            ("arm.xml", {"tip": "nowhere"}, "refuse"),
            ("arm.xml", {"fix": ("j9",)}, "refuse"),
            ("arm.xml", {"fix": "j0"}, "refuse"),
            ("arm.xml", {"fix": ("j0",)}, "either"),
            ("arm.xml", {"tip": "b0"}, "either"),
        ]:

            def plant(name: str = name, kw: dict[str, Any] = kw) -> None:
                res = amj.simulate("pd", str(root / name), T=0.05, **kw)
                _finite(res.tau_sat, res.q)

            case(t, f"MJCF {name} {kw}", plant, expect)
        # The plant adds a motor where a joint has none (unnamed joints too).
        case(t, "a model without actuators",
             lambda: _finite(amj.simulate("pd", str(noact), T=0.05).tau_sat), "accept")  # fmt: skip
        _controllers_said(t, amj)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def _controllers_said(t: Tally, amj: Any) -> None:
    """What a run was given that it cannot honour, said or refused (it ran
    silently): a task from another arm, a task and a reference, a controller
    of another joint count, a controller written in Python that returns None,
    text or a dict, or whose every torque is refused with a fault configured
    elsewhere, or that takes the old call."""
    import adaptimp

    class Returns:
        Ts = 1e-3

        def __init__(self, value: Any) -> None:
            self.value = value

        def step(self, m: Any, **sp: Any) -> Any:
            return self.value

    for what, value in [("None", None), ("the text '3.5'", "3.5"), ("['3.5', '0']", ["3.5", "0"]),
                        ("a dict", {"tau": [0.0, 0.0]})]:  # fmt: skip
        case(t, f"a Python step returns {what}",
             lambda v=value: amj.simulate(Returns(v), "two_link", T=0.01), "refuse")  # fmt: skip

    def nan_with_fault() -> None:
        res = amj.simulate(Returns([math.nan, 0.0]), "two_link", T=0.05,
                           fault=adaptimp.Fault("nan_burst", 5.0, 0.1))  # fmt: skip
        check(int(res.refused.sum()) == res.rows, "not every row refused")
        check(any("were refused" in w for w in res.params["warnings"]), "no warning")

    case(t, "every torque NaN, a fault configured after the run", nan_with_fault, "accept")

    class Old:
        Ts = 1e-3

        def step(self, q: Any, tau_e: Any = None, dq: Any = None) -> Any:
            return -1.0 * np.asarray(q)  # a Measurement here would raise

    case(t, "an old-style step(q, tau_e=None, dq=None)",
         lambda: _finite(amj.simulate(Old(), "two_link", T=0.01).tau_sat), "accept")  # fmt: skip

    def other_count() -> None:
        try:
            amj.simulate(adaptimp.Controller("pd", n=3), "two_link", T=0.01)
        except adaptimp.ConfigError as e:
            check("3 joints, the plant 2" in str(e), f"not named: {e}")
            raise

    case(t, "a controller of 3 joints on 2", other_count, "refuse")
    try:
        from adaptimp import _models

        robots = _models.panda_urdf_path().parents[2]
        ur5, ur10 = (robots / f"ur_description/urdf/{a}_robot.urdf" for a in ("ur5", "ur10"))
        if not (ur5.is_file() and ur10.is_file()):
            return
        task = amj.cartesian_task(ur5)
    except (ImportError, OSError, adaptimp.ConfigError):
        return
    case(t, "a UR5's task run on a UR10",
         lambda: amj.simulate("sf", ur10, T=0.01, task=task), "refuse")  # fmt: skip
    case(t, "a task and a reference",
         lambda: amj.simulate("sf", ur5, T=0.01, task=task,
                              reference=lambda tt: (np.zeros(6),) * 3), "refuse")  # fmt: skip
    case(t, "the UR5's task on the UR5",
         lambda: _finite(amj.simulate("sf", ur5, T=0.01, task=task).tau_sat), "accept")  # fmt: skip


_URDF_FIELDS = {
    "origin xyz": "0 0 0.1", "origin rpy": "0 0 0", "axis xyz": "0 1 0", "mass": "0.5",
    "inertia ixx": "0.01", "limit lower": "-2", "limit upper": "2", "limit effort": "10",
    "limit velocity": "3", "dynamics damping": "0.1", "dynamics friction": "0.05",
    "mimic multiplier": "1",
}  # fmt: skip
_URDF_VALUES = ("nan", "inf", "-inf", "1e400", "1e200", "-1", "0", "1e-320", "abc", "",
                "1 2", "0 0 0", "1e9 0 0", "0 0 1e200", "-0", "1e308 1e308 1e308")  # fmt: skip


def _urdf(field: str | None = None, value: str = "") -> str:
    """breakit.c's probe arm: three revolute joints and a prismatic jaw that
    mimics the third (the rule holds both), ``field`` replaced by ``value``."""
    v = {k: (value if k == field else d) for k, d in _URDF_FIELDS.items()}
    links = ["base", "l1", "l2", "l3", "jaw"]
    text = "<robot name='probe'><link name='base'/>"
    for j in range(4):
        mimic = f"<mimic joint='j3' multiplier='{v['mimic multiplier']}'/>" if j == 3 else ""
        text += (
            f"<link name='{links[j + 1]}'><inertial><origin xyz='0 0 0.05'/>"
            f"<mass value='{v['mass']}'/><inertia ixx='{v['inertia ixx']}' ixy='0' ixz='0' "
            "iyy='0.01' iyz='0' izz='0.01'/></inertial></link>"
            f"<joint name='j{j + 1}' type='{'prismatic' if j == 3 else 'revolute'}'>"
            f"<parent link='{links[j]}'/><child link='{links[j + 1]}'/>"
            f"<origin xyz='{v['origin xyz']}' rpy='{v['origin rpy']}'/>"
            f"<axis xyz='{v['axis xyz']}'/><limit lower='{v['limit lower']}' "
            f"upper='{v['limit upper']}' effort='{v['limit effort']}' "
            f"velocity='{v['limit velocity']}'/><dynamics damping='{v['dynamics damping']}' "
            f"friction='{v['dynamics friction']}'/>{mimic}</joint>"
        )
    return text + "</robot>"


def _arm_ok(arm: Any) -> None:
    """What a read arm must be: limits numbers with lower ≤ upper, an effort
    and a speed positive or NaN (none stated), drive terms finite ≥ 0; its
    chain moves its tip with every joint, finitely."""
    import adaptimp

    n = len(arm.joints)
    check(1 <= n <= 7, f"{n} joints")
    lo, hi = np.asarray(arm.lower), np.asarray(arm.upper)
    check(not np.isnan(lo).any() and not np.isnan(hi).any() and bool(np.all(lo <= hi)),
          f"limits {lo}, {hi}")  # fmt: skip
    for what in ("effort", "velocity"):
        x = np.asarray(getattr(arm, what))
        check(bool(np.all(np.isnan(x) | (x > 0))), f"{what} {x}")
    for what in ("armature", "damping", "friction"):
        x = np.asarray(getattr(arm, what))
        check(bool(np.all(np.isfinite(x) & (x >= 0))), f"{what} {x}")
    chain = adaptimp.Chain(arm.chain, tip=arm.tip_origin)
    q = 0.1 * np.arange(1, n + 1)
    _finite(chain.fk(q))
    jac = np.asarray(chain.jacobian(q))
    _finite(jac)
    check(bool(np.all(np.linalg.norm(jac, axis=0) > 0)), f"a joint moves nothing: {jac}")


def _chain_ok(chain: Any) -> None:
    q = np.full(chain.n, 0.1)
    _finite(chain.fk(q), chain.jacobian(q))


def descriptions(t: Tally, quick: bool) -> None:
    """Robot descriptions (SPEC §21) through every Python front that reads one:
    read_arm, Chain.from_urdf, ComputedTorque(PATH, tip=, fix=) and
    mujoco.from_urdf, with sources no arm is read from, every field of the
    probe arm's URDF replaced by a bad value, and tips, fixes and drive= of
    every wrong kind. Accepted: the arm's numbers are what a user can use."""
    from adaptimp import Chain, Measurement
    from adaptimp._description import read_arm

    root = Path(tempfile.mkdtemp(prefix="breakit-urdf-"))
    try:
        deep = "<robot name='r'>" + "<a>" * 100_000 + "</a>" * 100_000 + "</robot>"
        files = {
            "probe.urdf": _urdf(),
            "broken.urdf": "<robot name='x'><link name='a'>",
            "mjcf.urdf": "<mujoco><worldbody/></mujoco>",
            "urdf.xml": _urdf(),
            "empty.urdf": "",
            "binary.urdf": "\x00\x01\x02",
            "deep.urdf": deep,
            "a_dir.urdf": None,
        }
        for name, text in files.items():
            if text is None:
                (root / name).mkdir()
            else:
                (root / name).write_text(text)
        probe = root / "probe.urdf"
        sources: list[tuple[str, Any, str]] = [
            ("None", None, "refuse"),
            ("1.5", 1.5, "refuse"),
            ("bytes", _urdf().encode(), "refuse"),
            ("''", "", "refuse"),
            ("'/'", "/", "refuse"),
            ("/dev/zero", "/dev/zero", "refuse"),
            ("a missing file", root / "missing.urdf", "refuse"),
            ("100 000 nested elements (text)", deep, "refuse"),
            ("'<'", "<", "refuse"),
            ("MJCF text", "<mujoco><worldbody/></mujoco>", "refuse"),
            ("xacro text", "<robot name='x' xmlns:xacro='http://www.ros.org/wiki/xacro'>"
             "<xacro:property name='l' value='1'/><link name='a'/></robot>", "refuse"),
            ("the probe arm (text)", _urdf(), "accept"),
        ]  # fmt: skip
        sources += [(f"file {n}", root / n, "accept" if n in ("probe.urdf", "urdf.xml")
                     else "refuse") for n in files]  # fmt: skip
        for what, source, expect in sources:
            case(t, f"read_arm {what}", lambda s=source: _arm_ok(read_arm(s)), expect)
        values = _URDF_VALUES if not quick else _URDF_VALUES[::3]
        for fld in _URDF_FIELDS:
            for v in values:
                text = _urdf(fld, v)
                case(t, f"read_arm {fld} = {v!r}", lambda s=text: _arm_ok(read_arm(s)), "either")
        # Tips and fixes of every kind, through every front.
        args: list[tuple[str, dict[str, Any], str]] = [
            ("tip=None", {}, "accept"),
            ("tip='l2'", {"tip": "l2"}, "accept"),
            ("tip=''", {"tip": ""}, "refuse"),
            ("tip=1", {"tip": 1}, "refuse"),
            ("tip='base'", {"tip": "base"}, "refuse"),
            ("tip='j1' (a joint)", {"tip": "j1"}, "refuse"),
            ("tip='nowhere'", {"tip": "nowhere"}, "refuse"),
            ("fix=('j2',)", {"fix": ("j2",)}, "accept"),
            ("fix='j2' (a string)", {"fix": "j2"}, "refuse"),
            ("fix=('nope',)", {"fix": ("nope",)}, "refuse"),
            ("fix=(1,)", {"fix": (1,)}, "refuse"),
            ("fix=None", {"fix": None}, "either"),
            ("fix=every joint", {"fix": ("j1", "j2", "j3", "j4")}, "refuse"),
        ]
        fronts: list[tuple[str, Callable[..., None]]] = [
            ("read_arm", lambda **kw: _arm_ok(read_arm(probe, **kw))),
            ("Chain.from_urdf", lambda **kw: _chain_ok(Chain.from_urdf(probe, **kw))),
        ]
        try:
            from adaptimp.baselines import ComputedTorque

            def ct(**kw: Any) -> None:
                c = ComputedTorque(str(probe), **kw)
                q = [0.1] * c.n
                for _ in range(3):
                    _finite(c.step(Measurement(q, [0.0] * c.n), xc=q))

            fronts.append(("ComputedTorque", ct))
        except ImportError:
            pass
        try:
            from adaptimp import mujoco as amj

            def plant(**kw: Any) -> None:
                _finite(amj.simulate("pd", str(probe), T=0.02, **kw).tau_sat)

            fronts.append(("mujoco.simulate", plant))
        except ImportError:
            pass
        for front, fn in fronts:
            for what, kw, expect in args:
                case(t, f"{front} {what}", lambda fn=fn, kw=kw: fn(**kw), expect)
        drives = [("True", True, "accept"), ("None", None, "accept"),
                  ("'yes'", "yes", "refuse"), ("1.5", 1.5, "refuse")]  # fmt: skip
        for what, drive, expect in drives:
            if any(f == "ComputedTorque" for f, _ in fronts):
                case(t, f"ComputedTorque drive={what}", lambda d=drive: ct(drive=d), expect)
        # The inertials a computed torque would use: unphysical ones.
        for fld, v in [("mass", "1e200"), ("mass", "1e-320"), ("inertia ixx", "-1"),
                       ("inertia ixx", "1e200"), ("mass", "0")]:  # fmt: skip
            path = root / f"inertial_{fld.replace(' ', '_')}_{v}.urdf"
            path.write_text(_urdf(fld, v))
            if any(f == "ComputedTorque" for f, _ in fronts):

                def model(p: Path = path) -> None:
                    c = ComputedTorque(str(p))
                    _finite(c.inverse_dynamics([0.1, 0.2], [0.3, 0.0], [0.0, 1.0]))
                    _finite(c.mass_matrix([0.1, 0.2]))
                    check(bool(np.all(np.linalg.eigvalsh(c.mass_matrix([0.1, 0.2])) > 0)),
                          "a mass matrix that is not positive definite")  # fmt: skip

                case(t, f"ComputedTorque of a URDF with {fld} = {v}", model, "either")
        _descriptions_said(t, root)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def _descriptions_said(t: Tally, root: Path) -> None:
    """A description's mistakes the reader held or took silently: text after a
    byte-order mark (taken for a path, the whole text printed as its name), a
    mimic of a joint the file lacks or of itself (on the arm's way: refused;
    off it: held and warned), a floating joint on the way to the arm the rule
    finds, an inertia no rigid body has (its dynamics refused, by link)."""
    from adaptimp import Chain
    from adaptimp._description import read_arm

    case(t, "URDF text after a byte-order mark",
         lambda: _arm_ok(read_arm("\ufeff" + _urdf())), "accept")  # fmt: skip
    for master in ("nope", "j2"):
        text = _urdf().replace("<limit lower='-2' upper='2' effort='10' velocity='3'/>"
                               "<dynamics damping='0.1' friction='0.05'/></joint>"
                               "<link name='l3'>",
                               "<limit lower='-2' upper='2' effort='10' velocity='3'/>"
                               f"<dynamics damping='0.1' friction='0.05'/><mimic joint='{master}'/>"
                               "</joint><link name='l3'>", 1)  # fmt: skip
        check(text != _urdf(), "the probe arm changed")
        case(t, f"j2 mimics {master!r} (on the way)", lambda s=text: read_arm(s), "refuse")

        def off_the_way(s: str = text) -> None:
            with warnings.catch_warnings(record=True) as seen:
                warnings.simplefilter("always")
                arm = read_arm(s, "l1")
            check(bool(arm.warnings) and bool(seen), "the mistake was not said")

        case(t, f"j2 mimics {master!r} (off the way to l1)", off_the_way, "accept")
    floating = _urdf().replace("type='revolute'", "type='floating'", 1)
    case(t, "a floating joint on the rule's way", lambda: read_arm(floating), "refuse")
    path = root / "ixy5.urdf"
    path.write_text(_urdf().replace("ixy='0'", "ixy='5'", 1))
    case(t, "an inertia with ixy = 5: its chain", lambda: _chain_ok(Chain.from_urdf(path)),
         "accept")  # fmt: skip
    try:
        from adaptimp import mujoco as amj
        from adaptimp.baselines import ComputedTorque
    except ImportError:
        return
    case(t, "an inertia with ixy = 5: ComputedTorque", lambda: ComputedTorque(path), "refuse")
    slide = root / "slide.xml"
    slide.write_text(
        "<mujoco><worldbody><body name='a' pos='0 0 0.1'><joint name='j1' axis='0 0 1'/>"
        "<geom size='0.05' mass='1'/><body name='b' pos='0.3 0 0'>"
        "<joint name='s' type='slide' axis='1 0 0' range='-0.1 0.1'/>"
        "<geom size='0.03' mass='0.5'/><body name='c' pos='0.25 0 0'>"
        "<joint name='j3' axis='0 1 0'/><geom size='0.05' pos='0.1 0 0' mass='0.7'/>"
        "<site name='tip' pos='0.2 0 0'/></body></body></body></worldbody></mujoco>"
    )

    def same_count() -> None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            plant, chain = amj.Plant(slide), Chain.from_mujoco(slide)
        check(plant.n == chain.n, f"the plant drives {plant.n} joints, the chain has {chain.n}")

    case(t, "a slide on the default way: the chain's joints are the plant's", same_count,
         "accept")  # fmt: skip
    case(t, "an inertia with ixy = 5: mujoco.simulate",
         lambda: amj.simulate("pd", path, T=0.02), "refuse")  # fmt: skip


# ---------------------------------------------------------------------------
# Callbacks that read the object that called them (each in a process of its
# own with a time limit: a deadlock holds the GIL-less thread that SIGALRM
# cannot interrupt).
# ---------------------------------------------------------------------------


def _properties(obj: Any) -> list[str]:
    """The public properties of ``obj``'s class (Python ones and getters)."""
    import inspect

    out = []
    for name in dir(type(obj)):
        attr = inspect.getattr_static(type(obj), name)
        if not name.startswith("_") and (
            isinstance(attr, property) or type(attr).__name__ == "getset_descriptor"
        ):
            out.append(name)
    return out


def _read_all(*objects: Any) -> None:
    """Read every public property of ``objects``: an AttributeError of a
    property the object does not have is fine, anything else is not."""
    for obj in objects:
        for name in _properties(obj):
            _read_one(obj, name)


def _read_one(obj: Any, name: str) -> None:
    try:
        getattr(obj, name)
    except AttributeError as e:
        if "has no" not in str(e) and "does not say" not in str(e):
            raise
    except DeprecationWarning:
        pass


def _callback_case(name: str) -> None:
    """One callback case, run in a child process (``--callback NAME``)."""
    import adaptimp
    from adaptimp import mujoco as amj
    from adaptimp.baselines import ComputedTorque

    warnings.simplefilter("ignore")
    q0 = np.array([0.25, -0.05])
    chain = adaptimp.Chain.from_mujoco(amj.two_link(), "ee")
    p0 = chain.pose(q0)[0]

    def hold(tt: float) -> tuple[np.ndarray, ...]:
        return p0, np.zeros(3), np.zeros(3)

    def cart(joint: Any = "sf", **kw: Any) -> Any:
        extra = {"tau_max": [17.0, 15.0]} if isinstance(joint, str) else {}
        return adaptimp.CartesianController(chain, joint, q0=q0, Kd_rot=0.0, **extra, **kw)

    calls = [0]

    def reading(*objects: Any) -> Callable[..., None]:
        def read(*_: Any, **__: Any) -> None:
            calls[0] += 1
            _read_all(*objects)

        return read

    if name == "replay progress":
        c = adaptimp.Controller("sf")
        z = np.zeros((5000, 2))
        c.replay(z + 0.2, z, z, progress=reading(c))
    elif name == "replay progress resets":
        c = adaptimp.Controller("sf")
        z = np.zeros((500, 2))
        try:
            c.replay(z + 0.2, z, z, progress=lambda d, t: c.reset())
        except RuntimeError as e:
            check("can read the Controller, not change it" in str(e), str(e))
            calls[0] += 1
    elif name == "MuJoCo run progress":
        c = adaptimp.Controller("sf", scenario="robot")
        amj.simulate(c, "two_link", T=0.2, progress=reading(c))
    elif name == "computed torque progress":
        ct = ComputedTorque("two_link")
        amj.simulate(ct, "two_link", T=0.2, contact=False, progress=reading(ct))
    elif name == "Cartesian run progress":
        k = cart()
        amj.simulate(k, amj.two_link(), T=0.2, q0=q0, reference=hold, progress=reading(k, k.inner))
    elif name == "Cartesian replay progress":
        k = cart()
        q = np.tile(q0, (500, 1))
        k.outer.core.replay(k.inner, q, 0 * q, np.zeros((500, 6)), None, reading(k, k.outer))
    elif name == "a Python joint controller reads its Cartesian controller":

        class Joint:
            impedance, Ts = "external", 1e-3

            def step(self, m: Any, **sp: Any) -> Any:
                read()
                return 50.0 * (sp["xc"] - m.q)

        j = Joint()
        k = cart(j)
        read = reading(k, k.outer)
        for _ in range(3):
            k.step(adaptimp.Measurement(q0, [0.0, 0.0]))
        amj.simulate(k, amj.two_link(), T=0.02, q0=q0, reference=hold)
    elif name == "a path reads its Cartesian controller":
        holder: list[Any] = []

        def path(tt: float) -> tuple[np.ndarray, ...]:
            if holder:
                reading(holder[0], holder[0].inner)()
            return hold(tt)

        k = cart("pd", path=path)
        holder.append(k)
        for _ in range(3):
            k.step(adaptimp.Measurement(q0, [0.0, 0.0]))
    elif name == "a Python controller in a MuJoCo run reads the one it wraps":
        inner = adaptimp.Controller("sf", scenario="robot")

        class InPython:
            Ts = inner.Ts

            def step(self, m: Any, **sp: Any) -> Any:
                reading(inner)()
                return inner.step(m, **sp)

        amj.simulate(InPython(), "two_link", T=0.02, progress=reading(inner))
    elif name == "a trajectory reads its computed torque":
        holder = []

        def traj(tt: float) -> tuple[np.ndarray, ...]:
            reading(holder[0])()
            return q0, np.zeros(2), np.zeros(2)

        ct = ComputedTorque("two_link", trajectory=traj)
        holder.append(ct)
        for _ in range(3):
            ct.step(adaptimp.Measurement(q0, [0.0, 0.0]))
    assert calls[0] > 0, "the callback was not called"
    print("done")


CALLBACK_CASES = (
    "replay progress",
    "replay progress resets",
    "MuJoCo run progress",
    "computed torque progress",
    "Cartesian run progress",
    "Cartesian replay progress",
    "a Python joint controller reads its Cartesian controller",
    "a path reads its Cartesian controller",
    "a Python controller in a MuJoCo run reads the one it wraps",
    "a trajectory reads its computed torque",
)


def callbacks(t: Tally, quick: bool) -> None:
    """Each kind of callback (progress of a replay, a MuJoCo run, computed
    torque, a Cartesian run and replay; a joint controller written in Python;
    a path; a trajectory) reads every public property of the object that
    called it, and one that resets it is refused by name: each in a process of
    its own, 120 s at most (they deadlocked: the call held its object's lock
    while the Python code ran)."""
    for name in CALLBACK_CASES:
        t.cases += 1
        cmd = [sys.executable, __file__, "--callback", name]
        try:
            out = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        except subprocess.TimeoutExpired:
            t.hang += 1
            t.note(f"hang: {name}")
            continue
        if out.returncode == 0 and out.stdout.strip().endswith("done"):
            t.accepted += 1
        else:
            t.crash += 1
            t.note(f"crash: {name}: {out.stderr.strip()[-300:]}")


# ---------------------------------------------------------------------------
# Wrong inputs, refused by the name written.
# ---------------------------------------------------------------------------


def _named(message: str, name: str) -> bool:
    import re

    return re.search(rf"(?<![A-Za-z_]){re.escape(name)}(?![A-Za-z_])", message) is not None


def named_inputs(t: Tally, quick: bool) -> None:
    """Entry points given a wrong type or value (text, bools, NaN, wrong
    shapes, complex numbers, numbers for paths): each refused, the message
    naming the argument as written."""
    import adaptimp
    from adaptimp import Measurement, tuning

    nan = math.nan
    scalar = [("text", "2"), ("bool", True), ("NaN", nan), ("complex", 1j)]
    positive = [*scalar, ("zero", 0.0), ("negative", -1.0)]
    count = [("text", "2"), ("bool", True), ("float", 2.5), ("zero", 0)]

    def vector(n: int, nan_ok: bool = False) -> list[tuple[str, Any]]:
        out = [("text", "abc"), ("bools", [True] * n), ("short", [0.1] * (n - 1)),
               ("2-D", [[0.1] * n]), ("complex", [1j] * n), ("strings", ["0.1"] * n)]  # fmt: skip
        return out if nan_ok else [*out, ("NaN", [nan] * n)]

    q2 = [0.25, -0.05]
    m2 = Measurement(q2, [0.0, 0.0])
    table: list[tuple[str, str, list[tuple[str, Any]], Callable[[Any], Any]]] = [
        ("simulate", "T", positive, lambda v: adaptimp.simulate("pd", T=v)),
        ("simulate", "record_every", count,
         lambda v: adaptimp.simulate("pd", T=0.01, record_every=v)),
        ("Controller", "Ts", positive, lambda v: adaptimp.Controller("pd", Ts=v)),
        ("Measurement", "q", vector(2, nan_ok=True), lambda v: Measurement(v, [0.0, 0.0])),
        ("Measurement", "dq", vector(2, nan_ok=True), lambda v: Measurement(q2, v)),
        ("Controller.step", "xc", vector(2), lambda v: adaptimp.Controller("sf").step(m2, xc=v)),
        ("Chain.from_urdf", "source", [("number", 3), ("list", [1])],
         lambda v: adaptimp.Chain.from_urdf(v)),
        ("PoseTarget", "p", vector(3), lambda v: adaptimp.PoseTarget(p=v)),
        ("Fault", "start", scalar, lambda v: adaptimp.Fault("nan_burst", v, 0.1)),
        ("Fault", "duration", positive, lambda v: adaptimp.Fault("nan_burst", 0.1, v)),
        ("SimResult.load", "path", [("number", 3), ("list", [1])],
         lambda v: adaptimp.SimResult.load(v)),
        ("tuning.suggest", "q0", vector(2),
         lambda v: tuning.suggest(adaptimp.TwoLinkArm(), v, [17.0, 15.0])),
        ("tuning.suggest", "Ts", positive,
         lambda v: tuning.suggest(adaptimp.TwoLinkArm(), q2, [17.0, 15.0], Ts=v)),
    ]  # fmt: skip
    try:
        from adaptimp import mujoco as amj
        from adaptimp.baselines import ComputedTorque

        chain = adaptimp.Chain.from_mujoco(amj.two_link(), "ee")
        table += [
            ("ComputedTorque", "payload", scalar, lambda v: ComputedTorque(payload=v)),
            ("ComputedTorque", "mass_scale", positive, lambda v: ComputedTorque(mass_scale=v)),
            ("ComputedTorque.mass_matrix", "q", vector(2),
             lambda v: ComputedTorque().mass_matrix(v)),
            ("Chain.from_mujoco", "model", [("number", 3), ("None", None)],
             lambda v: adaptimp.Chain.from_mujoco(v)),
            ("Chain.from_mujoco", "fix", [("text", "joint1")],
             lambda v: adaptimp.Chain.from_mujoco(amj.two_link(), fix=v)),
            ("CartesianController", "q0", vector(2),
             lambda v: adaptimp.CartesianController(chain, "pd", q0=v, Kd_rot=0.0)),
            ("CartesianController.step", "xc", vector(3),
             lambda v: adaptimp.CartesianController(
                 chain, "pd", q0=q2, Kd_rot=0.0, tau_max=[17.0, 15.0]).step(m2, xc=v)),
            ("mujoco.simulate", "q0", vector(2),
             lambda v: amj.simulate("pd", "two_link", T=0.01, q0=v)),
            ("mujoco.simulate", "task", [("text", "abc")],
             lambda v: amj.simulate("pd", "two_link", T=0.01, task=v)),
            ("mujoco.Plant", "model", [("number", 3)], lambda v: amj.Plant(v)),
        ]  # fmt: skip
    except ImportError:
        pass
    for entry, name, wrong, call in table:
        for label, value in wrong:

            def refused(call: Callable[[Any], Any] = call, value: Any = value,
                        name: str = name) -> None:  # fmt: skip
                try:
                    call(value)
                except (TypeError, ValueError) as e:
                    check(_named(str(e), name), f"the refusal does not name {name}: {e}")
                    raise
                check(False, "accepted")

            case(t, f"{entry}({name}=) {label}", refused, "refuse")


CATEGORIES: dict[str, Callable[[Tally, bool], None]] = {
    "state restore": restore,
    "fault semantics": faults,
    "n-joint API": njoint,
    "sweeps and cache": sweeps,
    "chains": chains,
    "Cartesian front": cartesian,
    "formulations": formulations,
    "dynamics": dynamics,
    "saves": saves,
    "MuJoCo runs": mujoco_runs,
    "robot descriptions": descriptions,
    "callbacks": callbacks,
    "named inputs": named_inputs,
}


# ---------------------------------------------------------------------------
# Driver: each category in its own process.
# ---------------------------------------------------------------------------


def _child(name: str, quick: bool) -> None:
    t = Tally(name)
    CATEGORIES[name](t, quick)
    print(json.dumps(asdict(t)))


def _run(name: str, quick: bool, timeout: float) -> Tally:
    cmd = [sys.executable, __file__, "--child", name] + (["--quick"] if quick else [])
    env = {**os.environ, "PYTHONHASHSEED": "0"}
    try:
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        return Tally(name, cases=1, hang=1, notes=[f"the category ran past {timeout} s"])
    if out.returncode != 0:
        return Tally(name, cases=1, crash=1, notes=[f"exit {out.returncode}: {out.stderr[-400:]}"])
    data = json.loads(out.stdout.strip().splitlines()[-1])
    return Tally(**data)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer cases")
    ap.add_argument("--json", action="store_true", help="print the counts as JSON")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    ap.add_argument("--callback", help=argparse.SUPPRESS)
    ap.add_argument("--timeout", type=float, default=1800.0, help="per category (s)")
    args = ap.parse_args()
    if args.callback:
        _callback_case(args.callback)
        return 0
    if args.child:
        _child(args.child, args.quick)
        return 0
    tallies = [_run(name, args.quick, args.timeout) for name in CATEGORIES]
    if args.json:
        print(json.dumps([asdict(t) for t in tallies]))
    else:
        print("| surface | " + " | ".join(COLUMNS) + " |")
        print("|---|" + "---:|" * len(COLUMNS))
        for t in tallies:
            print(f"| {t.name} | " + " | ".join(str(getattr(t, c)) for c in COLUMNS) + " |")
        total = {c: sum(getattr(t, c) for t in tallies) for c in COLUMNS}
        print("| **all** | " + " | ".join(f"**{total[c]}**" for c in COLUMNS) + " |")
        for t in tallies:
            for note in t.notes:
                print(f"- {t.name}: {note}")
    bad = sum(t.crash + t.hang + t.wrong + t.false_refusal for t in tallies)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
