"""A break-it probe of the public Python API: state restore (bit flips,
edits, truncations), the fault semantics, the n-joint API, sweeps and their
cache. Every case is classified:

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
        ctrl.step(*_inputs(k, n))
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
                a, b = src.step(*_inputs(k, n)), dst.step(*_inputs(k, n))
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
                tau, err = ctrl.step_or_fallback(*_inputs(k))
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
                        tau2, err2 = ctrl.step_or_fallback(*_inputs(k))
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
                        tau = ctrl.step(**args)
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


CATEGORIES: dict[str, Callable[[Tally, bool], None]] = {
    "state restore": restore,
    "fault semantics": faults,
    "n-joint API": njoint,
    "sweeps and cache": sweeps,
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
    ap.add_argument("--timeout", type=float, default=1800.0, help="per category (s)")
    args = ap.parse_args()
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
