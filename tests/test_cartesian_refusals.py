"""The Python Cartesian front keeps no refused value (issue 33 B), refuses a
posture or start far out of range when given (C), an axis whose norm
overflows (F), unbounded orbit work (G) and malformed arguments by name; each
refused call leaves the controller stepping as a twin that never saw it."""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement, _models
from adaptimp.cartesian import CartesianImpedance

ARM = adaptimp.Chain(
    [
        {"kind": "revolute", "axis": [0, 0, 1]},
        {"kind": "revolute", "xyz": [0.3, 0, 0], "axis": [0, 1, 0]},
        {"kind": "revolute", "xyz": [0.3, 0, 0], "axis": [1, 0, 0]},
    ],
    tip={"xyz": [0.2, 0, 0]},
)
Q0 = np.array([0.3, 0.6, 0.2])
P0 = ARM.fk(Q0)[:3, 3]
R0 = ARM.fk(Q0)[:3, :3]
#: The measurement at rest at Q0, without contact (immutable: shared by the tests).
M0 = Measurement(Q0, np.zeros(3), wrench=np.zeros(6))
PANDA_Q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8])


def _ctrl(**kw: Any) -> adaptimp.CartesianController:
    return adaptimp.CartesianController(ARM, "pd", q0=Q0, tau_max=20.0, Kp=5.0, Kzeta=25.0, **kw)


def _panda(**kw: Any) -> adaptimp.CartesianController:
    chain = adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip="panda_link8")
    return adaptimp.CartesianController(chain, "pd", q0=PANDA_Q0, tau_max=50.0, **kw)


def _steps(c: adaptimp.CartesianController, q0: np.ndarray, k: int, **kw: Any) -> np.ndarray:
    """k steps near q0, each commanding the start pose moved a little."""
    out = []
    for i in range(k):
        q = q0 + 1e-3 * np.sin(i + np.arange(len(q0)))
        out.append(c.step(Measurement(q, np.zeros(len(q0)), wrench=np.zeros(6)), **kw))
    return np.array(out)


def _twins(refuse: Callable[[adaptimp.CartesianController], None], make: Any = _ctrl) -> None:
    """A controller that saw the refused call steps bit-identically to a twin
    that never saw it."""
    a, b = make(), make()
    q0 = Q0 if a.n == 3 else PANDA_Q0
    _steps(a, q0, 3)
    _steps(b, q0, 3)
    refuse(a)
    np.testing.assert_array_equal(_steps(a, q0, 20), _steps(b, q0, 20))


# The deviation named as what it is (it read "R_c = 0.21", as if it were R_c),
# of R_c (a path's rotation, the core's name) or of R (the keyword given).
ORTHONORMAL = re.escape(
    "condition RᵀR = I (an orthonormal rotation matrix, to 1e-6) is violated: "
    "max |R_cᵀR_c − I| of R_c = 0.2100000000000004 (SPEC §10)"
)
ORTHONORMAL_R = re.escape(
    "condition RᵀR = I (an orthonormal rotation matrix, to 1e-6) is violated: "
    "max |RᵀR − I| of R = 0.2100000000000004 (SPEC §10)"
)


def test_a_refused_rotation_is_not_kept_as_the_last_commanded_one() -> None:
    c = _ctrl()
    c.step(M0, xc=P0, R=R0)
    with pytest.raises(adaptimp.MeasurementError, match=ORTHONORMAL_R):
        c.step(M0, xc=P0, R=1.1 * R0)
    np.testing.assert_array_equal(c.outer.held_rotation, R0)
    # The next step without R holds the last good one (it was bricked).
    c.step(M0, xc=P0)
    with pytest.raises(adaptimp.MeasurementError, match=ORTHONORMAL_R):
        c.outer.target(P0, R=1.1 * R0)
    np.testing.assert_array_equal(c.outer.held_rotation, R0)
    c.step(M0, xc=P0)

    def refuse(c: adaptimp.CartesianController) -> None:
        with pytest.raises(adaptimp.MeasurementError):
            c.step(M0, xc=P0, R=1.1 * R0)

    _twins(refuse)


def test_a_good_rotation_of_a_refused_step_is_not_kept_either() -> None:
    c = _ctrl()
    c.step(M0, xc=P0, R=R0)
    turned = R0 @ np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(adaptimp.MeasurementError, match=r"^q\[1\] is not finite"):
        c.step(Measurement([0.3, math.nan, 0.2], np.zeros(3), wrench=np.zeros(6)), xc=P0, R=turned)
    np.testing.assert_array_equal(c.outer.held_rotation, R0)
    c.step(M0, xc=P0, R=turned)
    np.testing.assert_array_equal(c.outer.held_rotation, turned)


def test_a_path_that_returns_one_bad_rotation_costs_one_step() -> None:
    bad_at = 2

    def path(t: float) -> tuple[Any, ...]:
        k = round(t / 1e-3)
        R = 1.1 * R0 if k == bad_at else R0
        return (P0, np.zeros(3), np.zeros(3), R, np.zeros(3), np.zeros(3))

    c = _ctrl(path=path)
    for _ in range(bad_at):
        c.step(M0)
    with pytest.raises(adaptimp.MeasurementError, match=ORTHONORMAL):
        c.step(M0)
    np.testing.assert_array_equal(c.outer.held_rotation, R0)
    # The refused step did not advance the clock: the path is asked for the
    # same t again, still bad, until the caller gives a target.
    c.step(M0, xc=P0, R=R0)
    np.testing.assert_array_equal(c.outer.held_rotation, R0)


def test_a_refused_reset_keeps_the_start() -> None:
    ci = CartesianImpedance(ARM, Ts=1e-3, q0=Q0)
    with pytest.raises(
        adaptimp.MeasurementError,
        match=r"^q0 must have shape \(3,\) \(one value per joint\), got shape \(6,\)$",
    ):
        ci.reset(np.zeros(6))
    np.testing.assert_array_equal(ci.q0, Q0)
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^q0\[0\] = 1e7 is beyond its limit ±1e6; the state was left unchanged$",
    ):
        ci.reset(np.full(3, 1e7))
    np.testing.assert_array_equal(ci.q0, Q0)
    ci.reset()  # it was bricked: every later reset() failed
    ci.reset(Q0 + 0.1)
    np.testing.assert_array_equal(ci.q0, Q0 + 0.1)


def test_a_posture_far_out_of_range_is_refused_when_given() -> None:
    # The Panda: seven joints, a null space the posture acts in.
    c = _panda()
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^posture\[0\] = 1e7 is beyond its limit ±1e6; the state was left unchanged$",
    ):
        c.outer.set_posture(np.full(7, 1e7))
    # Within 1e6 rad, but the posture task would ask beyond the ceiling of
    # q̈_d: every step after it was refused (DivergedError on ddxc).
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^condition null_k·\|posture − q_d\| ≤ 1e6 rad/s² \(the ceiling of q̈_d\) is "
        r"violated: null_k·\|posture − q_d\|\[0\] = 2500000 ",
    ):
        c.outer.set_posture(np.full(7, 1e5))
    with pytest.raises(adaptimp.MeasurementError, match=r"^posture\[2\] is not finite"):
        c.outer.set_posture([0, 0, math.nan, 0, 0, 0, 0])
    _steps(c, PANDA_Q0, 20)
    c.outer.set_posture(PANDA_Q0 + 0.1)
    np.testing.assert_array_equal(c.outer.core.state("posture"), PANDA_Q0 + 0.1)

    def refuse(c: adaptimp.CartesianController) -> None:
        for bad in (np.full(7, 1e7), np.full(7, 1e5)):
            with pytest.raises(adaptimp.ConfigError):
                c.outer.set_posture(bad)

    _twins(refuse, _panda)


def test_a_start_far_out_of_range_is_refused_at_construction() -> None:
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^q0\[0\] = 1e7 is beyond its limit ±1e6; the state was left unchanged$",
    ):
        adaptimp.CartesianController(ARM, "pd", q0=[1e7, 0.0, 0.0])
    with pytest.raises(adaptimp.ConfigError, match=r"^posture\[1\] = 1e7 is beyond"):
        adaptimp.CartesianController(ARM, "pd", q0=Q0, posture=[0.0, 1e7, 0.0])


def test_an_axis_whose_norm_overflows_is_an_axis() -> None:
    unit = adaptimp.Chain([{"kind": "revolute", "axis": [0, 0, 1]}], tip={"xyz": [0.3, 0, 0]})
    for axis in ([0, 0, 1e200], [0, 0, 1.7e308]):
        big = adaptimp.Chain([{"kind": "revolute", "axis": axis}], tip={"xyz": [0.3, 0, 0]})
        for q in ([0.0], [0.7]):
            np.testing.assert_array_equal(big.jacobian(q), unit.jacobian(q))
            np.testing.assert_array_equal(big.fk(q), unit.fk(q))
        assert np.abs(big.jacobian([0.7])).max() > 0.1


def test_sloppy_rotations_within_the_tolerance_multiply_into_a_rotation() -> None:
    rpy = [0.3, -0.2, 0.5]
    R = adaptimp.Chain([{"kind": "revolute", "rpy": rpy, "axis": [0, 0, 1]}]).fk([0.0])[:3, :3]
    sloppy = (R * (1 + 2.5e-7)).tolist()  # |RᵀR − I| = 5e-7: accepted
    joints = [{"kind": "revolute", "translation": [0, 0, 0.1], "rotation": sloppy,
               "axis": [0, 0, 1]}] * 7  # fmt: skip
    chain = adaptimp.Chain(joints)
    M = chain.fk(np.full(7, 0.2))[:3, :3]
    assert abs(np.linalg.det(M) - 1.0) < 1e-14  # was 1.0000084
    np.testing.assert_allclose(M.T @ M, np.eye(3), atol=1e-14)


def _counting_path() -> tuple[Callable[[float], Any], list[int]]:
    calls = [0]

    def path(t: float) -> Any:
        calls[0] += 1
        return (P0, np.zeros(3), np.zeros(3))

    return path, calls


@pytest.mark.parametrize(
    ("kw", "error", "message"),
    [
        (
            {"T": 1e9},
            adaptimp.ConfigError,
            "condition 1 ≤ round(T/Ts) ≤ 1e6 steps (an orbit is sampled once a period) is "
            "violated: T/Ts = 1000000000000 (SPEC §10)",
        ),
        ({"T": math.nan}, adaptimp.ConfigError, "T[0] is not finite (NaN or infinite)"),
        ({"T": -1.0}, adaptimp.ConfigError, "condition T > 0 is violated: T = -1 (SPEC §10)"),
        ({"T": "1.0"}, TypeError, "T must be a real number, got '1.0'"),
        ({"T": True}, TypeError, "T must be a real number, got True"),
        ({"nodes": -5}, adaptimp.ConfigError, "nodes must be an integer ≥ 1, got -5"),
        ({"nodes": 0}, adaptimp.ConfigError, "nodes must be an integer ≥ 1, got 0"),
        ({"nodes": 2.5}, TypeError, "nodes must be an integer ≥ 1, got 2.5"),
        ({"nodes": True}, TypeError, "nodes must be an integer ≥ 1, got True"),
    ],
)
def test_unbounded_orbit_work_is_refused_by_name_before_any(
    kw: dict[str, Any], error: type[Exception], message: str
) -> None:
    ci = CartesianImpedance(ARM, Ts=1e-3, q0=Q0)
    path, calls = _counting_path()
    args = {"T": 0.05, **kw}
    with pytest.raises(error) as e:
        ci.orbit_centres(path, args.pop("T"), **args)
    assert str(e.value) == message
    assert calls[0] == 0, "the path was tabulated before the refusal"


def test_an_orbit_with_more_nodes_than_steps_samples_every_step() -> None:
    ci = CartesianImpedance(ARM, Ts=1e-3, q0=Q0)
    path, calls = _counting_path()
    centres, _ = ci.orbit_centres(path, 0.005, nodes=10**12)
    assert centres.shape == (5, 12)
    assert calls[0] == 5


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda c: c.outer.set_stiffness([1, 2]), adaptimp.ConfigError,
         "Kd must be a scalar or have shape (3,) (x, y, z), got shape (2,)"),
        (lambda c: c.outer.set_stiffness(100.0, [[1.0]]), adaptimp.ConfigError,
         "Kd_rot must be a scalar or have shape (3,) (x, y, z), got shape (1, 1)"),
        # Named as the step's keywords (the core's p_c, R_c, … are its own).
        (lambda c: c.step(M0, xc=[0.3, 0]), adaptimp.MeasurementError,
         "xc must have shape (3,), got shape (2,)"),
        (lambda c: c.step(M0, xc=P0, R=[1, 0, 0, 1]),
         adaptimp.MeasurementError, "R must have shape (3, 3), got shape (4,)"),
        (lambda c: c.step(M0, xc=P0, R=R0.ravel()),
         adaptimp.MeasurementError, "R must have shape (3, 3), got shape (9,)"),
        (lambda c: c.step(M0, xc=P0, dw=["x", 0, 0]), TypeError,
         "dw must hold real numbers, got an array of dtype <U21"),
        (lambda c: c.step(Measurement(Q0, np.zeros(3), wrench=np.zeros((2, 3)))),
         adaptimp.MeasurementError,
         "wrench must have shape (6,) ([f; m], N and N m) or (3,) (f alone), got shape (2, 3)"),
        (lambda c: c.step(M0, xc=P0, w=[math.nan, 0, 0]),
         adaptimp.MeasurementError, "w[0] is not finite (NaN or infinite)"),
        (lambda c: c.step(M0, xc=P0, R=np.diag([1.0, math.nan, 1.0])),
         adaptimp.MeasurementError, "R[4] is not finite (NaN or infinite)"),
        (lambda c: c.step(M0, xc=[0, 0, 2e6]),
         adaptimp.MeasurementError,
         "xc[2] = 2e6 is beyond its limit ±1e6; the state was left unchanged"),
    ],
)  # fmt: skip
def test_malformed_arguments_are_refused_by_name_and_change_nothing(
    call: Callable[[adaptimp.CartesianController], object], error: type[Exception], message: str
) -> None:
    c = _ctrl()
    with pytest.raises(error) as e:
        call(c)
    assert str(e.value) == message

    def refuse(c: adaptimp.CartesianController) -> None:
        with pytest.raises(error):
            call(c)

    _twins(refuse)


def test_a_stiffness_beyond_its_bound_is_reported_as_its_value() -> None:
    with pytest.raises(adaptimp.ConfigError) as e:
        _ctrl(Kd=1e10)
    assert str(e.value).endswith(
        "condition |value| ≤ 1e9 is violated: Kd[0] = 10000000000 (SPEC §10)"
    )
    with pytest.raises(adaptimp.ConfigError, match=r"tau_max\[1\] = 10000000000 "):
        adaptimp.Controller("pd", tau_max=[17.0, 1e10])


def test_the_chain_refuses_rates_whose_outputs_would_not_be_finite() -> None:
    with pytest.raises(adaptimp.MeasurementError) as e:
        ARM.jdot_qdot(Q0, [1e200, 0.0, 0.0])  # was −inf with no error
    assert str(e.value) == "dq[0] = 1e200 is beyond its limit ±1e6; the state was left unchanged"
    with pytest.raises(adaptimp.MeasurementError) as e:
        ARM.jacobian([0.0, -3e6, 0.0])
    assert str(e.value) == "q[1] = -3e6 is beyond its limit ±1e6; the state was left unchanged"
    assert np.isfinite(ARM.jdot_qdot(Q0, np.full(3, 1e6))).all()
    with pytest.raises(adaptimp.MeasurementError) as e:
        ARM.motion(np.zeros(3), np.zeros(3), np.zeros(3))
    assert str(e.value) == "q must have shape (K, 3), got shape (3,)"
    with pytest.raises(adaptimp.MeasurementError) as e:
        ARM.motion(np.zeros((2, 3)), np.zeros((3, 3)), np.zeros((2, 3)))
    assert str(e.value) == "dq must have shape (2, 3) like q, got shape (3, 3)"
    with pytest.raises(adaptimp.MeasurementError) as e:
        ARM.motion(np.zeros((2, 3)), np.full((2, 3), 1e200), np.zeros((2, 3)))
    assert str(e.value) == (
        "row 0: dq[0] = 1e200 is beyond its limit ±1e6; the state was left unchanged"
    )
    v, a = ARM.motion([[0.1, 0.2, 0.3]], [[0.0, 0.0, 1.0]], [[0, 0, 0]])  # lists, ints
    assert v.shape == a.shape == (1, 6)


@pytest.mark.parametrize(
    ("origin", "got"),
    [
        ({"quat": [1, 0, 0, 0], "rpy": [0, 0, 1]}, "rpy and quat"),
        ({"xyz": [0, 0, 1], "pos": [0, 0, 1]}, "xyz and pos"),
        ({"rotation": np.eye(3).tolist(), "rpy": [0, 0, 1]}, "rpy and rotation"),
        ({"translation": [0, 0, 1], "quat": [1, 0, 0, 0]}, "quat and translation"),
    ],
)
def test_an_origin_in_two_conventions_is_refused(origin: dict[str, Any], got: str) -> None:
    # quat together with rpy: the rpy was ignored.
    with pytest.raises(adaptimp.ConfigError) as e:
        adaptimp.Chain([{"kind": "revolute", "axis": [0, 0, 1], **origin}])
    assert str(e.value) == (
        "joints: an origin is given by xyz and rpy (URDF), pos and quat (MuJoCo) or "
        f"translation and rotation, one convention at a time; got {got}"
    )


def test_names_of_another_length_and_a_site_that_is_no_id_are_refused() -> None:
    with pytest.raises(adaptimp.ConfigError) as e:
        adaptimp.Chain([{"kind": "revolute", "axis": [0, 0, 1]}], names=["a", "b"])
    assert str(e.value) == (
        "joints: names must give one name per movable joint (1), got ['a', 'b']"
    )
    with pytest.raises(adaptimp.ConfigError):
        adaptimp.Chain([{"kind": "revolute", "axis": [0, 0, 1]}], names="ab")
    import mujoco

    m = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><joint type="hinge"/><geom size=".1"/>'
        '<site name="s"/><site name="t"/></body></worldbody></mujoco>'
    )
    for site in (1.5, True):  # taken as site 1
        with pytest.raises(TypeError) as e:
            adaptimp.Chain.from_mujoco(m, site)  # type: ignore[arg-type]
        assert str(e.value) == f"tip must be a site's or body's name or a site id, got {site!r}"
    assert adaptimp.Chain.from_mujoco(m, np.int64(1)).source == "MuJoCo model to site 't'"


def test_an_interrupted_native_cartesian_run_keeps_its_rows_in_the_log() -> None:
    """Ctrl-C (here from the progress callback) in a Cartesian run of the core's
    loop: the rows of the steps it took are in ctrl.log, as its clock says
    (they were missing: the log lost the interrupted run)."""
    from adaptimp import mujoco as amj
    from adaptimp import tuning

    chain = adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip="panda_link8")
    plant = amj.Plant(amj.panda(table_height=None))
    p0, R0 = chain.pose(PANDA_Q0)
    ctrl = adaptimp.CartesianController(
        chain, "sf", "robot", q0=PANDA_Q0, Kd_rot=30.0,
        **tuning.suggest(plant, PANDA_Q0, plant.tau_max),
    )  # fmt: skip
    plant.reset(PANDA_Q0)
    ctrl.step(
        Measurement(PANDA_Q0, np.zeros(7), wrench=np.zeros(6)), xc=p0, R=R0
    )  # a row before the run

    def stop(done: int, total: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        amj.simulate(ctrl, plant, T=60.0, reset=False, progress=stop)
    k = int(ctrl.outer.core.steps)
    assert 1 < k < 60_001
    rows = ctrl.arrays()
    assert {len(v) for v in rows.values()} == {k}, {n: len(v) for n, v in rows.items()}
    np.testing.assert_array_equal(rows["qd"][-1], ctrl.q_d)


def test_a_step_the_outer_loop_refuses_falls_back_on_its_own_measurement() -> None:
    """A step the outer loop refuses before the joint step runs (a rotation
    that is not one) is recorded with its measurement, as the core's and C's
    Cartesian steps record it: the damping fallback is −Kd q̇ of that step's
    q̇, for a single step and within a run (a replay) alike."""
    dq = np.array([0.5, -0.4, 0.3])
    bad = R0.copy()
    bad[0, 0] += 0.21
    alone = _ctrl(fallback="damping", fallback_damping=3.0)
    _steps(alone, Q0, 3)
    with pytest.raises(adaptimp.MeasurementError, match="orthonormal"):
        alone.step(Measurement(Q0, dq, wrench=np.zeros(6)), xc=P0, R=bad)
    np.testing.assert_array_equal(alone.inner.applied, -3.0 * dq)

    run = _ctrl(fallback="damping", fallback_damping=3.0)
    good = np.concatenate([P0, np.zeros(6), R0.ravel(), np.zeros(6)])
    targets = np.tile(good, (4, 1))
    targets[3, 9:18] = bad.ravel()
    q = np.tile(Q0, (4, 1))
    dqs = np.zeros((4, 3))
    dqs[3] = dq
    with pytest.raises(adaptimp.ConfigError, match=r"^row 3: condition RᵀR = I"):
        run.outer.core.replay(run.inner, q, dqs, np.zeros((4, 6)), targets, None)
    np.testing.assert_array_equal(run.inner.applied, -3.0 * dq)
