"""adaptimp.franka's loop against a Franka of the test's own (tests/franka_fake.py):
pylibfranka's calls in order, in the test's time. What the loop must do, exactly:
the rule's controller, the start at rest where the arm stands, libfranka's
torque rate, the clock of a missed cycle, the clean stop, and every way a
motion ends early, named."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

# pylibfranka has wheels for Python ≥ 3.10 (scripts/test.sh checks it is installed).
pylibfranka = pytest.importorskip("pylibfranka")

import adaptimp  # noqa: E402
from adaptimp import SimResult, _models, franka  # noqa: E402
from adaptimp import mujoco as amj  # noqa: E402
from adaptimp._cartesian_task import chain_of  # noqa: E402
from franka_fake import FR3, FakeRobot, State  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent

READY = np.array(franka.READY)


def rate_steps(sent: list[tuple[list[float], bool]]) -> np.ndarray:
    """The change of every torque sent from the one before (N m)."""
    tau = np.array([s[0] for s in sent])
    return np.abs(np.diff(tau, axis=0))


def test_the_arm_is_the_urdfs_without_gravity() -> None:
    p = franka.plant(FR3)
    assert p.n == 7
    assert p.model.opt.gravity.tolist() == [0.0, 0.0, 0.0]
    assert p.tau_max.tolist() == list(franka.TAU_MAX)
    ur5 = Path(_models.panda_urdf_path()).parents[2] / "ur_description" / "urdf" / "ur5_robot.urdf"
    with pytest.raises(
        adaptimp.ConfigError, match=r"a Franka arm has 7 joints; the arm of .* has 6"
    ):
        franka.plant(str(ur5))


def test_the_controller_is_the_rule_a_simulate_user_gets() -> None:
    """One truth: setup() is amj.rule_keywords / amj.cartesian_task on the arm
    without gravity, plus the Franka's limits."""
    plant = franka.plant(FR3)
    limits = {"tau_max": list(franka.TAU_MAX), "tau_rate_max": 1.0}
    s = franka.setup("sf", plant, READY)
    task = amj.default_task(plant, READY)
    kw = amj.rule_keywords(plant, task, Ts=1e-3, case="sf", delay=franka.DELAY)
    kw.pop("n")
    same = adaptimp.Controller("sf", scenario="robot", n=7, **{**kw, **limits})
    assert s.controller.params == same.params
    assert s.controller.params["tau_rate_max"] == [1.0] * 7
    np.testing.assert_array_equal(s.task.home, READY)
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^the arm stands at q = \[0\.0, 0\.0, 0\.0, -1\.57, 0\.0, 1\.57, 0\.785\] rad, "
        r"where q0 cannot run the task: condition velocity-loop conditioning .* move it first "
        r"\(run\(\.\.\., start=franka\.READY\), or franka\.move_to\)$",
    ):
        franka.setup("sf", plant, [0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785], task="cartesian")
    c = franka.setup("sf", plant, READY, task="cartesian")
    ctask = amj.cartesian_task(plant, q0=READY)
    assert c.controller.params == ctask.controller("sf", plant, delay=franka.DELAY, **limits).params
    # The Cartesian task's orbit takes the shaped gains too (SPEC (18.12)).
    assert c.controller.inner.params.get("inertia_matrix") is not None
    assert s.controller.params["delay"] == 1
    # SPEC (18.12): the rule's default for libfranka's delay, the same on
    # the robot as in simulate; coupled=False the diagonal rule's.
    assert s.controller.params["inertia_matrix"] is not None
    diagonal = franka.setup("sf", plant, READY, coupled=False)
    assert diagonal.controller.params["inertia_matrix"] is None
    kw = amj.rule_keywords(plant, task, Ts=1e-3, case="sf", delay=franka.DELAY, coupled=False)
    kw.pop("n")
    same = adaptimp.Controller("sf", scenario="robot", n=7, **{**kw, **limits})
    assert diagonal.controller.params == same.params
    c = franka.setup("sf", plant, READY, task="cartesian", coupled=True)
    want = ctask.controller("sf", plant, delay=franka.DELAY, coupled=True, **limits)
    assert c.controller.params == want.params
    assert c.controller.inner.params == want.inner.params
    assert want.inner.params["inertia_matrix"] is not None


@pytest.mark.parametrize("task", ["joint", "cartesian"])
def test_gravity_fed_forward_is_refused_on_a_franka(task: str) -> None:
    """The robot adds its own model's gravity torque (docs/franka.md): the
    Cartesian task took gravity="model" without a word, the joint task named
    another reason."""
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^gravity='model': the Franka adds its own model's gravity torque to every "
        r"command \(libfranka\), so the controller never commands gravity; fed forward again "
        r"it would count twice: keep the default \(docs/franka\.md, SPEC \(20\.10\)\)$",
    ):
        franka.setup("sf", franka.plant(FR3), READY, task=task, gravity="model")
    robot = FakeRobot(FR3)
    with pytest.raises(adaptimp.ConfigError, match=r"^gravity='model': the Franka adds"):
        franka.run("sf", FR3, robot, T=1.0, task=task, start=READY, gravity="model")
    assert robot.sent == []  # refused before the robot moved
    assert robot.collision is None


def test_the_joint_task_starts_at_rest_where_the_arm_stands() -> None:
    """The reference: at the standing posture, at rest, at t = 0; the path
    itself from t = blend on; its rates the derivatives of its position."""
    s = franka.setup("pd", FR3, READY)
    steps = 3000
    xc, dxc, ddxc = s.reference(steps)
    np.testing.assert_array_equal(xc[0], READY)
    np.testing.assert_array_equal(dxc[0], np.zeros(7))
    np.testing.assert_array_equal(ddxc[0], np.zeros(7))
    t = np.arange(steps)[:, None] * 1e-3
    path = [np.asarray(a) for a in s.task.reference(t)]
    after = round(s.blend / 1e-3) + 1
    for got, want in zip((xc, dxc, ddxc), path):
        np.testing.assert_allclose(got[after:], want[after:], rtol=0, atol=1e-15)
    # The rates are the position's derivatives (central differences; the
    # acceleration has a corner where the blend ends: its jerk stops there).
    smooth = np.r_[1 : after - 3, after + 2 : steps - 1]
    np.testing.assert_allclose(np.gradient(xc, 1e-3, axis=0)[smooth], dxc[smooth], atol=1e-5)
    np.testing.assert_allclose(np.gradient(dxc, 1e-3, axis=0)[smooth], ddxc[smooth], atol=1e-4)
    # A home far away: a longer blend, no joint faster than BLEND_SPEED from it.
    far = franka.setup("pd", FR3, READY, home=READY + 0.6)
    # The path starts at home − 0.2 rad, 0.4 rad from where the arm stands.
    assert far.blend == pytest.approx(1.875 * 0.4 / franka.BLEND_SPEED, rel=1e-12)


def test_a_run_starts_without_a_step_and_ends_with_motion_finished() -> None:
    robot = FakeRobot(FR3)
    res = franka.run("sf", FR3, robot, T=1.0)
    assert res.rows == 1000
    assert robot.collision is not None
    assert [tuple(c) for c in robot.collision] == list(franka.COLLISION)
    # The first torque holds the arm where it stands (the robot compensates
    # gravity exactly here: nothing else holds it).
    assert np.max(np.abs(robot.sent[0][0])) < 0.05
    # libfranka's rate: at most 1 N m from one command to the next.
    assert np.max(rate_steps(robot.sent)) <= 1.0 + 1e-12
    # The last command: the last torque again, with motion_finished.
    assert robot.sent[-1] == (robot.sent[-2][0], True)
    assert [s[1] for s in robot.sent[:-1]] == [False] * 1000
    np.testing.assert_array_equal(res.tau_sat[-1], robot.sent[-2][0])
    assert res.params["loop"] == "libfranka"
    assert res.params["cycles"] == {"total": 1000, "missed": 0, "longest": 0.001}


def test_a_missed_cycle_advances_the_clock_by_its_duration() -> None:
    """After a 3 ms cycle the next row is the state 3 ms later and its
    setpoint the reference's at that time: rows 101, 102 are skipped."""
    robot = FakeRobot(FR3, stretch={100: 3})
    res = franka.run("sf", FR3, robot, T=0.5)
    assert res.params["cycles"] == {"total": 498, "missed": 1, "longest": 0.003}
    assert res.t[101] - res.t[100] == pytest.approx(0.003, abs=1e-12)
    xc, dxc, _ddxc = franka.setup("sf", FR3, READY).reference(500)
    np.testing.assert_array_equal(res.xc[101], xc[103])
    np.testing.assert_array_equal(res.dxc[101], dxc[103])
    np.testing.assert_array_equal(res.xc[:101], xc[:101])


def test_ctrl_c_ends_the_motion_first() -> None:
    robot = FakeRobot(FR3)

    def interrupt(k: int, t: float, state: object) -> None:
        if k == 50:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as err:
        franka.run("sf", FR3, robot, T=1.0, on_cycle=interrupt)
    assert str(err.value) == "Ctrl-C at t = 0.050 s: the motion was ended (motion_finished)"
    assert robot.sent[-1] == (robot.sent[-2][0], True)
    partial = err.value.partial  # type: ignore[attr-defined]
    assert partial.rows == 51


def test_a_hook_ends_the_motion_cleanly() -> None:
    robot = FakeRobot(FR3)
    res = franka.run("pd", FR3, robot, T=1.0, on_cycle=lambda k, t, s: k == 99)
    assert res.rows == 100
    assert robot.sent[-1] == (robot.sent[-2][0], True)


def test_a_libfranka_exception_is_named_and_recovery_waits_for_a_request() -> None:
    reflex = pylibfranka.ControlException(
        "libfranka: Move command aborted: motion aborted by reflex!"
    )
    for recover, recoveries in ((False, 0), (True, 1)):
        robot = FakeRobot(FR3, fail={30: reflex}, fail_errors=["joint_reflex"])
        with pytest.raises(franka.RobotError) as err:
            franka.run("sf", FR3, robot, T=1.0, recover=recover)
        assert str(err.value) == (
            "libfranka raised ControlException at t = 0.029 s: libfranka: Move command "
            "aborted: motion aborted by reflex!; the robot's errors: ['joint_reflex']; the "
            "robot ended the motion"
        )
        assert err.value.cause is reflex
        assert err.value.errors == ["joint_reflex"]
        assert err.value.partial is not None
        assert err.value.partial.rows == 30
        assert robot.recoveries == recoveries
        # Nothing written after libfranka raised.
        assert len(robot.sent) == 30
        assert not robot.sent[-1][1]


def test_a_refused_step_ends_the_motion_with_the_last_torque() -> None:
    def glitch(cycle: int, state: State) -> None:
        if cycle == 40:
            state.dq[3] = math.nan

    robot = FakeRobot(FR3, state_hook=glitch)
    with pytest.raises(franka.RobotError) as err:
        franka.run("sf", FR3, robot, T=1.0)
    assert str(err.value).startswith(
        "the controller refused the step at t = 0.040 s (row 40): MeasurementError: "
    )
    assert str(err.value).endswith("the motion was ended (motion_finished, the last torque held)")
    assert "dq" in str(err.value)
    assert isinstance(err.value.cause, adaptimp.MeasurementError)
    assert robot.sent[-1] == (robot.sent[-2][0], True)
    assert err.value.partial is not None
    assert err.value.partial.rows == 40


def test_errors_before_the_start_are_cleared_only_on_request() -> None:
    robot = FakeRobot(FR3, errors=["cartesian_reflex"])
    with pytest.raises(franka.RobotError, match=r"the robot reports errors \['cartesian_reflex'\]"):
        franka.run("pd", FR3, robot, T=0.1)
    assert robot.recoveries == 0
    assert robot.sent == []
    res = franka.run("pd", FR3, robot, T=0.1, recover=True)
    assert robot.recoveries == 1
    assert res.rows == 100


def test_the_wrench_estimate_reaches_the_controller() -> None:
    """O_F_ext_hat_K (what the robot exerts, base frame, about K = the tip
    here): τe = Jᵀ F_e for the joint controller, F_e itself for the Cartesian."""
    f = np.array([0.0, 2.0, -5.0, 0.1, 0.0, 0.0])
    robot = FakeRobot(FR3, wrench=f)
    res = franka.run("pd", FR3, robot, T=0.05)
    chain = chain_of(franka.plant(FR3))
    for k in (0, 10, 49):
        np.testing.assert_allclose(res.tau_e[k], chain.jacobian(res.q[k]).T @ f, atol=1e-12)
    np.testing.assert_array_equal(res.wrench_ee, np.tile(f, (50, 1)))
    cart = franka.run("pd", FR3, FakeRobot(FR3, wrench=f), T=0.05, task="cartesian")
    assert cart.task is not None
    np.testing.assert_allclose(cart.task["wrench"], np.tile(f, (50, 1)), atol=1e-12)
    quiet = franka.run("pd", FR3, FakeRobot(FR3, wrench=f), T=0.05, wrench=False)
    np.testing.assert_array_equal(quiet.tau_e, np.zeros((50, 7)))


def test_the_result_has_simulates_metrics_plots_and_save(
    tmp_path: Path, close_figures: None
) -> None:
    res = franka.run("sf", FR3, FakeRobot(FR3), T=2.5)
    sim = amj.simulate("pd", "two_link", T=0.01, contact=False)
    assert set(res.metrics) == set(sim.metrics)
    assert res.metrics["rms_z1_after2"] > 0
    for kind in amj.PLOT_KINDS:
        res.plot(kind)
    back = SimResult.load(res.save(tmp_path / "run"))
    assert isinstance(back, amj.MujocoResult)
    assert back.params == res.params
    assert back.metrics == res.metrics
    np.testing.assert_array_equal(back.q, res.q)
    cart = franka.run("sf", FR3, FakeRobot(FR3), T=2.5, task="cartesian")
    assert {"rms_pos_after2", "rms_rot_after2"} <= set(cart.metrics)
    assert cart.pos_err is not None
    assert cart.pos_err.shape == (2500,)


def test_move_to_uses_the_robots_own_controller() -> None:
    robot = FakeRobot(FR3, q0=READY + 0.1)
    franka.move_to(robot, READY, speed=0.5)
    assert robot.position_mode == pylibfranka.ControllerMode.JointImpedance  # type: ignore[attr-defined]
    assert robot.sent[-1] == (READY.tolist(), True)
    steps = np.abs(np.diff(np.array([s[0] for s in robot.sent]), axis=0))
    assert np.max(steps) <= 0.5 * 1e-3 + 1e-12
    # 375 ms from rest to rest (1.875 × 0.1 rad / 0.5 rad/s), at least 0.5 s.
    assert len(robot.sent) == 501


@pytest.mark.parametrize("task", ["joint", "cartesian"])
def test_the_robots_torque_is_taken_over_before_anything_moves(task: str) -> None:
    """SPEC (22.4): the torque the robot holds the arm with when the loop
    starts (tau_J_d) is the one the first command moves from, at most 1 N m
    a cycle; one beyond the controller's τmax is refused before the motion,
    by name, and nothing is sent."""
    held = [0.0, -4.0, 0.0, 6.5, 0.0, 1.0, 0.0]
    robot = FakeRobot(FR3)
    robot.applied = np.array(held)
    res = franka.run("sf", FR3, robot, T=0.02, task=task)
    assert res.params["taken_over"] == held
    first = np.asarray(robot.sent[0][0])
    assert np.max(np.abs(first - held)) <= 1.0 + 1e-9
    assert np.max(np.abs(first - held)) > 0.0
    beyond = FakeRobot(FR3)
    beyond.applied = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 20.0])
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^the torque the robot holds the arm with, \[0\.0, 0\.0, 0\.0, 0\.0, 0\.0, 0\.0, "
        r"20\.0\] N m, cannot be taken over: torque taken over\[6\] = 2e1 is beyond its limit "
        r"±1\.2e1; the state was left unchanged$",
    ):
        franka.run("sf", FR3, beyond, T=0.02, task=task)
    assert beyond.sent == []
