"""Python for real work: n joints, user centres, external setpoints, state that
travels, threads, signals, decimated records, the ecosystem, errors by kind."""

from __future__ import annotations

import copy
import os
import pickle
import signal
import subprocess
import sys
import textwrap
import threading
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement


def _centers(n: int, nodes: int, seed: int = 0) -> np.ndarray:
    """A fixed set of user centres over x, v, α1, α̇1 for n joints."""
    rng = np.random.default_rng(seed)
    scale = np.concatenate([np.full(n, 0.5), np.full(n, 1.0), np.full(n, 1.0), np.full(n, 4.0)])
    return rng.uniform(-1.0, 1.0, size=(nodes, 4 * n)) * scale


# ---------------------------------------------------------------------------
# Any n, any basis.
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6, 7])
def test_planar_arm_dynamics_are_consistent_for_every_n(n: int) -> None:
    arm = adaptimp.PlanarArm(n, masses=np.linspace(2.0, 0.5, n), lengths=0.3)
    rng = np.random.default_rng(n)
    q, dq = rng.normal(size=n), rng.normal(size=n)
    d = arm.D(q)
    assert d.shape == (n, n)
    np.testing.assert_allclose(d, d.T, rtol=0, atol=1e-14)
    assert np.all(np.linalg.eigvalsh(d) > 0)
    tau, tau_e = rng.normal(size=n), rng.normal(size=n)
    acc = arm.forward_dynamics(q, dq, tau, tau_e)
    # (4): D q̈ = τ − τe − C q̇ − G.
    np.testing.assert_allclose(
        d @ acc, tau - tau_e - arm.C(q, dq) @ dq - arm.G(q), rtol=0, atol=1e-12
    )


def test_planar_arm_of_two_links_is_the_papers_arm() -> None:
    two = adaptimp.TwoLinkArm()
    p = two.params
    arm = adaptimp.PlanarArm(
        2,
        masses=[p["m1"], p["m2"]],
        lengths=[p["l1"], p["l2"]],
        coms=[p["lc1"], p["lc2"]],
        inertias=[p["I1"], p["I2"]],
        g=p["g"],
    )
    q, dq = np.array([0.3, -0.7]), np.array([1.1, 0.4])
    np.testing.assert_allclose(arm.D(q), two.D(q), rtol=0, atol=1e-14)
    np.testing.assert_allclose(arm.C(q, dq), two.C(q, dq), rtol=0, atol=1e-14)
    np.testing.assert_allclose(arm.G(q), two.G(q), rtol=0, atol=1e-13)


def _user_loop(case: str, n: int, g: float, centers: int | None) -> tuple[float, float]:
    """A user's own loop: an n-link arm of 1 kg, 0.25 m links integrated with
    semi-implicit Euler at 1 ms, the controller (robot scenario, Kp = 2 for
    these light links) tracking a slow sinusoid. Returns the initial ‖z1‖ and
    the RMS ‖z1‖ over the last 2 s (rad)."""
    arm = adaptimp.PlanarArm(n, masses=1.0, lengths=0.25, g=g)
    kw: dict[str, object] = {}
    if centers is not None:
        kw = {"centers": _centers(n, centers), "widths": 2.0}
    ctrl = adaptimp.Controller(
        case,
        "robot",
        n=n,
        Kp=2.0,
        Kzeta=10.0,
        K1=10.0,
        tau_max=40.0,
        xc_offset=0.2,
        xc_sin=0.1,
        xc_cos=0.0,
        xc_omega=1.0,
        **kw,
    )
    assert ctrl.n == n
    assert ctrl.nodes == (2 ** (4 * n) if centers is None else centers)
    q, dq = np.zeros(n), np.zeros(n)
    h = ctrl.Ts
    errors = []
    for _ in range(4000):
        tau = ctrl.step(Measurement(q, dq, tau_e=np.zeros(n)))
        assert tau.shape == (n,)
        assert np.all(np.abs(tau) <= 40.0)
        dq = dq + h * arm.forward_dynamics(q, dq, tau, np.zeros(n))
        q = q + h * dq
        errors.append(np.linalg.norm(ctrl.z1))
    assert np.all(np.isfinite(q))
    return float(errors[0]), float(np.sqrt(np.mean(np.square(errors[2000:]))))


def test_user_loop_controls_a_3_joint_arm_under_gravity_better_than_pd() -> None:
    _, pd = _user_loop("pd", 3, 9.81, None)
    _, sf = _user_loop("sf", 3, 9.81, None)
    # The networks learn the gravity PD leaves as a steady error.
    assert sf < 0.5 * pd


def test_user_loop_controls_a_5_joint_arm_with_user_centres() -> None:
    first, last = _user_loop("sf", 5, 0.0, 96)
    assert last < 0.3 * first


def test_simulate_runs_n_joints_with_a_planar_arm() -> None:
    arm = adaptimp.PlanarArm(3, masses=[1.5, 1.0, 0.5], lengths=0.3)
    res = adaptimp.simulate("pd", n=3, arm=arm, T=0.5, Ts=1e-3, substeps=4, wall=None)
    assert res.q.shape == (500, 3)
    assert res.n == 3
    assert res.params["arm"]["masses"] == [1.5, 1.0, 0.5]
    assert len(res.metrics["peak_abs_tau"]) == 3


def test_n_beyond_the_grid_gets_centres_along_its_trajectory() -> None:
    # SPEC §18: the default trajectory (0.2 − 0.2 cos πt on each joint) is
    # 1.6 rad long per period in q for n = 4: L = ⌈2 · 1.6 / 0.2⌉ = 16.
    ctrl = adaptimp.Controller("sf", n=4)
    assert ctrl.nodes == 16
    assert "centres along the trajectory" in repr(ctrl)
    # A trajectory that does not move: 2n + 1 centres about its offset.
    assert adaptimp.Controller("sf", n=5, xc_sin=0.0, xc_cos=0.0).nodes == 11
    with pytest.raises(adaptimp.ConfigError, match="n must be between 1 and 7"):
        adaptimp.Controller("sf", n=8)
    with pytest.raises(adaptimp.ConfigError, match=r"centers must have shape \(L, 12\)"):
        adaptimp.Controller("sf", n=3, centers=np.zeros((5, 8)))
    with pytest.raises(TypeError, match="paper's 2-link arm, with n = 3"):
        adaptimp.simulate("sf", n=3, m1=2.0)
    with pytest.raises(adaptimp.ConfigError, match="arm has 3 joints but n = 2"):
        adaptimp.simulate("sf", arm=adaptimp.PlanarArm(3))


def test_centres_per_dimension_widths_reach_the_basis() -> None:
    """Two controllers that differ only in one input dimension's width learn differently."""
    c = _centers(2, 32)
    a = adaptimp.Controller("sf", "robot", centers=c, widths=1.0)
    w = np.ones(8)
    w[0] = 0.1
    b = adaptimp.Controller("sf", "robot", centers=c, widths=w)
    for ctrl in (a, b):
        for _ in range(5):
            ctrl.step(Measurement([0.1, 0.2], [0.3, -0.2], tau_e=[0.0, 0.0]))
    assert not np.array_equal(a.weights["G"], b.weights["G"])
    with pytest.raises(adaptimp.ConfigError, match=r"widths must be a number or have shape \(8,\)"):
        adaptimp.Controller("sf", centers=c, widths=[1.0, 2.0])


# ---------------------------------------------------------------------------
# Your own reference.
# ---------------------------------------------------------------------------


def test_external_setpoints_streamed_from_a_file_equal_the_trajectory(tmp_path: Path) -> None:
    """The setpoints of a run written to a file and streamed back with xc, dxc,
    ddxc give the run's torques exactly, step by step and through replay."""
    res = adaptimp.simulate("sf", "robot", T=0.3, substeps=2)
    path = tmp_path / "setpoints.csv"
    np.savetxt(path, np.hstack([res.xc, res.dxc, res.ddxc]), delimiter=",", fmt="%.17g")
    table = np.loadtxt(path, delimiter=",")
    xc, dxc, ddxc = table[:, :2], table[:, 2:4], table[:, 4:]
    # Same parameters (the "auto" weight bound derives from the trajectory);
    # its own trajectory is not used.
    ctrl = adaptimp.Controller("sf", "robot")
    for k in range(res.rows):
        tau = ctrl.step(
            Measurement(res.q[k], res.dq[k], tau_e=res.tau_e[k]), xc=xc[k], dxc=dxc[k], ddxc=ddxc[k]
        )
        assert np.array_equal(tau, res.tau_sat[k]), k
    again = adaptimp.Controller("sf", "robot")
    out = again.replay(res.q, res.tau_e, res.dq, xc=xc, dxc=dxc, ddxc=ddxc)
    assert np.array_equal(out, res.tau_sat)
    # And another setpoint is really used: a shifted one changes the torques.
    other = adaptimp.Controller("sf", "robot")
    shifted = other.replay(res.q, res.tau_e, res.dq, xc=xc + 0.01, dxc=dxc, ddxc=ddxc)
    assert not np.array_equal(shifted, res.tau_sat)


def test_setpoint_arguments_are_checked() -> None:
    ctrl = adaptimp.Controller("sf", "robot")
    with pytest.raises(TypeError, match="dxc and ddxc need xc"):
        ctrl.step(Measurement([0.0, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]), dxc=[0.0, 0.0])
    with pytest.raises(adaptimp.MeasurementError, match=r"xc\[1\] is not finite"):
        ctrl.step(Measurement([0.0, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]), xc=[0.0, np.inf])
    with pytest.raises(adaptimp.MeasurementError, match=r"xc must have shape \(2,\)"):
        ctrl.step(Measurement([0.0, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]), xc=[0.0])
    assert ctrl.steps == 0


# ---------------------------------------------------------------------------
# State that travels.
# ---------------------------------------------------------------------------


def _drive(ctrl: adaptimp.Controller, k0: int, k1: int) -> np.ndarray:
    out = []
    for k in range(k0, k1):
        t = 1e-3 * k
        q = np.array([0.25 + 0.1 * np.sin(t), -0.05 + 0.1 * np.cos(t)])
        out.append(
            ctrl.step(
                Measurement(
                    q, [0.1 * np.cos(t), -0.1 * np.sin(t)], tau_e=[0.5 * np.sin(3 * t), 0.0]
                )
            )
        )
    return np.array(out)


@pytest.mark.parametrize("case", ["pd", "sf", "of"])
def test_pickle_mid_run_continues_bit_identically(case: str) -> None:
    a = adaptimp.Controller(case, "robot")
    _drive(a, 0, 200)
    b = pickle.loads(pickle.dumps(a))
    c = copy.deepcopy(a)
    d = copy.copy(a)
    assert (b.steps, b.t, b.case, b.params) == (a.steps, a.t, a.case, a.params)
    tail = _drive(a, 200, 400)
    for other in (b, c, d):
        assert np.array_equal(_drive(other, 200, 400), tail)
        for key, w in a.weights.items():
            assert np.array_equal(other.weights[key], w)


def test_copies_are_independent() -> None:
    a = adaptimp.Controller("sf", "robot")
    b = copy.copy(a)
    _drive(b, 0, 10)
    assert (a.steps, b.steps) == (0, 10)
    assert not np.any(a.weights["G"])


def test_pickle_keeps_user_centres() -> None:
    a = adaptimp.Controller("sf", "robot", n=4, centers=_centers(4, 20), widths=1.5)
    a.step(Measurement(np.zeros(4), np.ones(4), tau_e=np.zeros(4)))
    b = pickle.loads(pickle.dumps(a))
    assert (b.n, b.nodes) == (4, 20)
    x = np.full(4, 0.1)
    assert np.array_equal(a.step(Measurement(x, x, tau_e=x)), b.step(Measurement(x, x, tau_e=x)))


def test_state_dict_round_trip_and_warm_start(tmp_path: Path) -> None:
    a = adaptimp.Controller("sf", "robot")
    _drive(a, 0, 300)
    sd = a.state_dict()
    assert sd["format"] == "adaptimp.state/1"
    assert sd["W_D"].shape == (2, 2, 256)
    assert sd["W_G"].shape == (2, 256)
    np.savez(tmp_path / "state.npz", **sd)
    loaded = dict(np.load(tmp_path / "state.npz"))
    # Whole state: continues exactly.
    b = adaptimp.Controller("sf", "robot")
    b.load_state_dict(loaded)
    assert b.steps == 300
    assert np.array_equal(_drive(b, 300, 350), _drive(a, 300, 350))
    # Weights only: a warm start from t = 0.
    c = adaptimp.Controller("sf", "robot")
    c.load_state_dict(loaded, weights_only=True)
    assert c.steps == 0
    assert np.array_equal(c.weights["G"], sd["W_G"])
    # A simulation warm-started with them learns less from scratch.
    cold = adaptimp.simulate("sf", "robot", T=0.5)
    warm = adaptimp.simulate("sf", "robot", T=0.5, weights=sd)
    assert warm.w_norms[0, 2] == pytest.approx(np.linalg.norm(sd["W_G"]))
    assert cold.w_norms[0, 2] == 0.0
    with pytest.raises(adaptimp.ConfigError, match="state has n = 2, this controller 3"):
        adaptimp.Controller("sf", "robot", n=3).load_state_dict(sd)
    bad = dict(sd, W_G=np.zeros((2, 255)))
    with pytest.raises(adaptimp.ConfigError, match=r"weights\[\"G\"\] must have shape \(2, 256\)"):
        c.load_state_dict(bad, weights_only=True)


def test_arms_and_results_pickle() -> None:
    arm = adaptimp.PlanarArm(3, masses=[1.0, 2.0, 3.0])
    arm2 = pickle.loads(pickle.dumps(arm))
    assert np.array_equal(arm.D([0.1, 0.2, 0.3]), arm2.D([0.1, 0.2, 0.3]))
    two = copy.deepcopy(adaptimp.TwoLinkArm(m2=1.3))
    assert two.params["m2"] == 1.3
    res = adaptimp.simulate("pd", T=0.05)
    res2 = pickle.loads(pickle.dumps(res))
    assert np.array_equal(res2.q, res.q)
    np.testing.assert_equal(res2.metrics, res.metrics)


# ---------------------------------------------------------------------------
# Threads.
# ---------------------------------------------------------------------------


def test_two_threads_stepping_one_controller_never_collide() -> None:
    """Every call is atomic: no 'Already borrowed', no lost step."""
    ctrl = adaptimp.Controller("sf", "robot")
    errors: list[BaseException] = []

    def work() -> None:
        try:
            for _ in range(500):
                ctrl.step(Measurement([0.1, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]))
            ctrl.replay(np.zeros((2000, 2)), np.zeros((2000, 2)), np.zeros((2000, 2)))
        except BaseException as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=work) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert ctrl.steps == 2 * (500 + 2000)


def test_distinct_controllers_in_threads_give_the_serial_results() -> None:
    serial = [adaptimp.simulate(c, "robot", T=0.5).metrics for c in ("pd", "sf", "of")]
    out: dict[str, dict[str, object]] = {}

    def run(case: str) -> None:
        out[case] = adaptimp.simulate(case, "robot", T=0.5).metrics

    threads = [threading.Thread(target=run, args=(c,)) for c in ("pd", "sf", "of")]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    np.testing.assert_equal([out[c] for c in ("pd", "sf", "of")], serial)


# ---------------------------------------------------------------------------
# Runs you can stop and watch.
# ---------------------------------------------------------------------------


@pytest.fixture
def sigint() -> Iterator[None]:
    """Python's SIGINT handler (KeyboardInterrupt) for the test, whatever the
    suite was started with: under ``nohup … &`` SIGINT is ignored, Python then
    installs no handler, and a Ctrl-C test would wait for a run of minutes."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def test_sigint_during_simulate_raises_keyboard_interrupt_and_leaves_objects_usable(
    sigint: None,
) -> None:
    """SIGINT from the outside (as Ctrl-C) while the core runs without the GIL."""
    ctrl = adaptimp.Controller("sf")
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            # 2e7 steps: many minutes if not stopped.
            adaptimp.simulate("sf", T=1000.0, record_every=1000)
    finally:
        timer.cancel()
    # Everything still works.
    assert adaptimp.simulate("sf", T=0.05).rows == 1000
    assert ctrl.step(Measurement([0.0, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0])).shape == (2,)


def test_an_exception_in_the_progress_callback_stops_the_run() -> None:
    calls: list[int] = []

    def progress(done: int, total: int) -> None:
        calls.append(done)
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        adaptimp.simulate("sf", T=1000.0, record_every=1000, progress=progress)
    assert len(calls) == 1
    assert 0 < calls[0] < 20_000_000


def test_sigint_during_replay(sigint: None) -> None:
    ctrl = adaptimp.Controller("sf", "robot")
    seen: list[int] = []

    def progress(done: int, total: int) -> None:
        seen.append(done)
        signal.raise_signal(signal.SIGINT)  # Python runs its handler here, in the callback

    rows = 3_000_000
    z = np.zeros((rows, 2))
    with pytest.raises(KeyboardInterrupt):
        ctrl.replay(z, z, z, progress=progress)
    assert 0 < ctrl.steps < rows
    assert ctrl.step(Measurement([0.0, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0])).shape == (2,)


def test_ctrl_c_in_a_fresh_process_is_a_keyboard_interrupt_not_a_panic() -> None:
    # The child sets the handler: it inherits an ignored SIGINT under nohup.
    script = textwrap.dedent(
        """
        import signal, sys, adaptimp
        signal.signal(signal.SIGINT, signal.default_int_handler)
        print("ready", flush=True)
        adaptimp.simulate("sf", T=1000.0)
        """
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", script],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None
    assert proc.stdout.readline().strip() == "ready"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert "KeyboardInterrupt" in err
    assert "PanicException" not in err
    assert proc.returncode != 0


def test_progress_callback_sees_the_run_advance() -> None:
    seen: list[tuple[int, int]] = []
    adaptimp.simulate("sf", T=4.0, progress=lambda d, t: seen.append((d, t)))
    assert seen, "a 80 000-step run reports progress"
    assert all(t == 80_000 for _, t in seen)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)


def test_progress_true_prints_on_long_runs(capsys: pytest.CaptureFixture[str]) -> None:
    # A run shorter than the 2 s delay prints nothing.
    adaptimp.simulate("pd", T=0.2, progress=True)
    assert capsys.readouterr().err == ""


def test_record_every_keeps_every_kth_row_and_the_metrics_of_every_step() -> None:
    full = adaptimp.simulate("sf", T=0.3)
    thin = adaptimp.simulate("sf", T=0.3, record_every=7)
    assert thin.rows == -(-full.rows // 7)
    assert np.array_equal(thin.q, full.q[::7])
    assert np.array_equal(thin.t, full.t[::7])
    np.testing.assert_equal(thin.metrics, full.metrics)
    assert thin.record_every == 7
    with pytest.raises(adaptimp.ConfigError, match="record_every must be an integer ≥ 1"):
        adaptimp.simulate("sf", T=0.1, record_every=0)


# ---------------------------------------------------------------------------
# Results that fit the ecosystem.
# ---------------------------------------------------------------------------


def test_to_pandas_is_tidy_with_units() -> None:
    res = adaptimp.simulate("sf", T=0.1, record_every=10)
    df = res.to_pandas()
    assert df.shape[0] == res.rows
    assert df.index.name == "t [s]"
    assert "q1 [rad]" in df.columns
    assert "tau_sat2 [N m]" in df.columns
    assert "ddq1 [rad/s^2]" in df.columns
    np.testing.assert_array_equal(df["q2 [rad]"].to_numpy(), res.q[:, 1])
    assert df.attrs["metrics"] == res.metrics
    assert df.attrs["units"]["dq1 [rad/s]"] == "rad/s"


def test_to_xarray_has_dimensions_and_units() -> None:
    res = adaptimp.simulate("pd", n=3, T=0.05, Ts=1e-3, wall=None)
    ds = res.to_xarray()
    assert ds["q"].dims == ("t", "joint")
    assert ds["q"].shape == (50, 3)
    assert ds["tau"].attrs["units"] == "N m"
    assert list(ds["joint"].values) == [1, 2, 3]


def test_save_is_compressed_and_loads_back(tmp_path: Path) -> None:
    res = adaptimp.simulate("sf", T=0.5)
    path = res.save(tmp_path / "run")
    raw = sum(
        getattr(res, name).nbytes
        for name in (*adaptimp._result.ARRAYS, *adaptimp._result.EXTRA_ARRAYS)
    )
    assert path.stat().st_size < raw
    back = adaptimp.SimResult.load(path)
    assert np.array_equal(back.ddq, res.ddq)
    assert np.array_equal(back.refused, res.refused)
    np.testing.assert_equal(back.metrics, res.metrics)


def test_plots_overlay_runs_in_given_axes() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1)
    for case in ("pd", "sf"):
        out = adaptimp.simulate(case, T=0.1).plot("errors", ax=axes)
        assert out is fig
    assert len(axes[0].lines) == 2
    assert len(axes[1].lines) == 2
    fig2 = adaptimp.plot_compare([adaptimp.simulate("pd", T=0.1)])
    assert fig2.axes
    plt.close("all")


# ---------------------------------------------------------------------------
# Errors you can catch by kind.
# ---------------------------------------------------------------------------


def test_config_error_says_what_to_change() -> None:
    with pytest.raises(adaptimp.ConfigError, match=r"raise Kzeta above 72\.5 for Kp = 12"):
        adaptimp.Controller("sf", Kp=12.0)
    with pytest.raises(ValueError, match=r"raise Kzeta above 72\.5 for Kp = 12"):
        adaptimp.simulate("sf", Kp=12.0)


def test_measurement_error_names_the_argument_as_given() -> None:
    ctrl = adaptimp.Controller("sf", "robot")
    with pytest.raises(adaptimp.MeasurementError, match=r"q\[0\] is not finite"):
        ctrl.step(Measurement([np.nan, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]))
    with pytest.raises(adaptimp.MeasurementError, match=r"dq\[1\] is not finite"):
        ctrl.step(Measurement([0.0, 0.0], [0.0, np.inf], tau_e=[0.0, 0.0]))
    with pytest.raises(
        adaptimp.MeasurementError, match=r"tau_e has 3 values and q 2: one value per joint each"
    ):
        ctrl.step(Measurement([0.0, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0, 0.0]))
    with pytest.raises(adaptimp.MeasurementError, match="q holds a number too large"):
        ctrl.step(Measurement([10**400, 0], [0.0, 0.0], tau_e=[0.0, 0.0]))
    assert ctrl.steps == 0


def test_huge_integers_are_value_errors_not_overflow_errors() -> None:
    with pytest.raises(ValueError, match="T is too large for a float"):
        adaptimp.simulate("sf", T=10**400)
    with pytest.raises(ValueError, match="Kp holds a number too large"):
        adaptimp.Controller("sf", Kp=[10**400, 1])
    with pytest.raises(ValueError, match="substeps is out of range"):
        adaptimp.simulate("sf", substeps=2**70)


def test_diverged_error() -> None:
    # The unstable loop's plant leaves the ceilings of SPEC §14 (1e6 rad) at
    # once: the run stops there, naming it, rather than at an overflow.
    with pytest.raises(adaptimp.DivergedError, match=r"plant state q\[0\] = .* beyond .*±1e6"):
        adaptimp.simulate("pd", Ts=1e-2, Kp=1e4, Kzeta=1e9, tau_max=1e9, T=5.0)


def test_fault_error_is_raised_while_a_fault_is_latched() -> None:
    ctrl = adaptimp.Controller("sf", "robot", fault_policy="latch")
    _, error = ctrl.step_or_fallback(Measurement([np.nan, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]))
    assert error is not None
    with pytest.raises(adaptimp.FaultError, match="latched"):
        ctrl.step(Measurement([0.0, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]))
    ctrl.clear_fault()
    ctrl.step(Measurement([0.0, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]))


def test_stability_warning_for_euler_learning_at_1khz() -> None:
    with pytest.warns(adaptimp.StabilityWarning, match="learning_step='normalized'"):
        adaptimp.Controller("of", Ts=1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        adaptimp.Controller("of")  # the paper's 50 µs: stable
        adaptimp.Controller("of", "robot")  # normalised step
        adaptimp.Controller("pd", Ts=1e-3)  # PD does not learn


def test_the_ctrl_c_tests_pass_when_the_suite_starts_with_sigint_ignored() -> None:
    """As under ``nohup pytest … &``: SIGINT ignored from the start (they failed)."""
    tests = [
        f"{__file__}::{name}"
        for name in (
            "test_sigint_during_simulate_raises_keyboard_interrupt_and_leaves_objects_usable",
            "test_sigint_during_replay",
            "test_ctrl_c_in_a_fresh_process_is_a_keyboard_interrupt_not_a_panic",
        )
    ]
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *tests],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "3 passed" in proc.stdout
