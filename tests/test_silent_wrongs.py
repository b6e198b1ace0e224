"""Issue 41's silently wrong results and unnamed errors, one test each (the
hangs are tests/test_callbacks.py and test_reliability.py, the saves
test_save_atomic.py, the wrong types and values of every entry point
test_wrong_inputs.py; gravity compensation test_dynamics.py, the inertia
test_model_refusals.py, the mimic and floating joints tests/description.rs).
Each failed before: a result accepted that was wrong, or a message that did
not name what was wrong."""

from __future__ import annotations

import copy
import importlib.util
import pickle
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement
from adaptimp import mujoco as amj
from adaptimp.baselines import ComputedTorque

ROOT = Path(__file__).resolve().parent.parent
HOBBY = ROOT / "tests" / "data" / "hobby_arm.urdf"


# --- Silently wrong -------------------------------------------------------


def test_a_task_made_on_another_arm_is_refused() -> None:
    """A task made on one arm and run on another measured its errors with the
    first arm's kinematics (0.2 mm reported, the tip 219 mm off)."""
    task = amj.cartesian_task("panda")
    other = amj.panda()
    other.body_pos[3, 2] += 0.2  # a link 20 cm longer
    with pytest.raises(adaptimp.ConfigError, match=r"^the task was made on another arm: "):
        amj.simulate("pd", other, T=0.05, task=task)


def test_a_task_and_a_reference_are_not_both_taken() -> None:
    """The arm tracked the reference, the metrics measured the task's path."""
    task = amj.cartesian_task("panda")
    with pytest.raises(ValueError, match=r"^give the task or a reference, not both"):
        amj.simulate("pd", "panda", T=0.05, task=task, reference=amj.paper_circle())


def test_a_controller_for_another_count_of_joints_is_named(tmp_path: Path) -> None:
    """Any count mismatch said "noise_q: wrong length" (never given); and a
    slide joint on the way made the default chain 3 joints where the plant
    drives 2 (the plant holds it): the chain now holds it too."""
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^the controller \(Controller\) has 3 joints, the plant 2 \(joint1, joint2\)",
    ):
        amj.simulate(adaptimp.Controller("pd", n=3), "two_link", T=0.01)
    path = tmp_path / "slide.xml"
    path.write_text(
        "<mujoco><worldbody><body name='a' pos='0 0 0.1'><joint name='j1' axis='0 0 1'/>"
        "<geom size='0.05' mass='1'/><body name='b' pos='0.3 0 0'>"
        "<joint name='s' type='slide' axis='1 0 0' range='-0.1 0.1'/>"
        "<geom size='0.03' mass='0.5'/><body name='c' pos='0.25 0 0'>"
        "<joint name='j3' axis='0 1 0'/><geom type='box' size='0.1 0.02 0.02' pos='0.1 0 0' "
        "mass='0.7'/><site name='tip' pos='0.2 0 0'/></body></body></body></worldbody>"
        "<actuator><motor joint='j1'/><motor joint='s'/><motor joint='j3'/></actuator></mujoco>"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", adaptimp.PlantWarning)
        plant = amj.Plant(path)
        chain = adaptimp.Chain.from_mujoco(path)
    assert plant.n == chain.n == 2
    assert chain.joint_names == ["j1", "j3"]
    assert chain.fixed["s"].startswith("prismatic")
    # A tip given beyond it drives it, as the plant's tip would.
    assert adaptimp.Chain.from_mujoco(path, tip="tip").n == 3


class _Stepper:
    """A joint controller written in Python (the protocol)."""

    n = 2
    Ts = 1e-3
    impedance = "external"

    def step(self, m: Any, **setpoint: Any) -> Any:
        return np.zeros(2)


def test_a_path_that_returns_none_is_refused_with_a_python_controller() -> None:
    """Refused with a named joint controller, the last target held silently
    with one written in Python."""
    chain = adaptimp.Chain.from_mujoco(amj.two_link(), "ee")
    calls = []

    def path(t: float) -> Any:
        calls.append(t)
        return None if len(calls) > 1 else (np.array([0.3, 0.0, 0.2]), np.zeros(3), np.zeros(3))

    for inner, kw in ((_Stepper(), {}), ("pd", {"tau_max": [17.0, 15.0]})):
        calls.clear()
        cart = adaptimp.CartesianController(
            chain, inner, q0=[0.25, -0.05], Kd_rot=0.0, path=path, **kw
        )
        m = Measurement([0.25, -0.05], [0.0, 0.0])
        cart.step(m)
        with pytest.raises(TypeError, match=r"a path returns \(p, dp, ddp\).*got NoneType"):
            cart.step(m)


def test_an_old_style_step_is_called_as_such_and_deprecated() -> None:
    """``def step(self, q, tau_e=None, dq=None)`` was given a Measurement as q,
    with no DeprecationWarning, and failed in the user's own code."""
    seen = []

    class Old:
        n = 2
        Ts = 1e-3

        def step(self, q: Any, tau_e: Any = None, dq: Any = None) -> Any:
            seen.append(type(q))
            return np.zeros(2)

    with pytest.warns(DeprecationWarning, match=r"Old\.step\(q, tau_e, dq\) is deprecated"):
        amj.simulate(Old(), "two_link", T=0.01)
    assert seen
    assert all(t is np.ndarray for t in seen)


def test_a_deprecated_call_under_warnings_as_errors_is_not_a_refused_step() -> None:
    """With warnings turned into errors the deprecated ``c.step(q, tau_e, dq)``
    was recorded as a refused step: under ``fault_policy="latch"`` the next
    valid step raised FaultError."""
    c = adaptimp.Controller("sf", fault_policy="latch")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DeprecationWarning):
            c.step([0.1, 0.2], [0.0, 0.0], [0.0, 0.0])  # type: ignore[call-overload]
    assert c.fault is None
    assert np.isfinite(c.step(Measurement([0.1, 0.2], [0.0, 0.0]))).all()


def test_from_rule_leaves_the_plant_where_it_was() -> None:
    """``from_rule(..., model=Plant(...))`` moved ``plant.data.qpos`` to the
    task's q0 and left it there."""
    plant = amj.Plant("panda")
    before = (plant.data.qpos.copy(), plant.data.qvel.copy())
    task = amj.cartesian_task(plant)
    adaptimp.CartesianController.from_rule(task.chain, "pd", task.path, task.q0, model=plant)
    np.testing.assert_array_equal(plant.data.qpos, before[0])
    np.testing.assert_array_equal(plant.data.qvel, before[1])


def test_copies_of_a_pose_target_are_immutable() -> None:
    """``copy.deepcopy`` and a pickled copy had writable arrays."""
    target = adaptimp.PoseTarget(p=[0.1, 0.0, 0.2], dp=[0.0, 0.1, 0.0])
    for other in (
        copy.copy(target),
        copy.deepcopy(target),
        pickle.loads(pickle.dumps(target)),
    ):
        assert other == target
        for name in ("p", "dp", "ddp", "R", "w", "dw"):
            a = getattr(other, name)
            assert not a.flags.writeable, name
            with pytest.raises(ValueError, match="read-only"):
                a[0] = 1.0


def test_arm_targets_refuses_a_part_or_an_arm_it_does_not_know() -> None:
    """``--only nonsense`` ran nothing and exited 0."""
    for args, said in (
        (["--only", "nonsense"], "--only: unknown part(s) nonsense"),
        (["--arms", "nonsense"], "--arms nonsense: no arm's label contains it"),
    ):
        out = subprocess.run(
            [sys.executable, str(ROOT / "scripts" / "arm_targets.py"), *args],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        assert out.returncode == 2, out
        assert said in out.stderr


# --- Errors that did not name what is wrong -------------------------------


def test_computed_torques_step_names_q_and_dq() -> None:
    """It said ``x[0]`` and ``dx[0]`` (the core's names)."""
    ct = ComputedTorque()
    with pytest.raises(adaptimp.MeasurementError, match=r"^q\[0\] is not finite"):
        ct.step(Measurement([np.nan, 0.2], [0.0, 0.0]))
    with pytest.raises(adaptimp.MeasurementError, match=r"^dq\[0\] = 1e200 is beyond"):
        ct.step(Measurement([0.1, 0.2], [1e200, 0.0]))


def test_a_pose_out_of_reach_is_named_by_the_inverse_kinematics() -> None:
    """Without q0, a path 1 m away raised DivergedError "ddqd[0] = −2.97e138"."""

    def far(t: float) -> tuple[Any, ...]:
        return np.array([0.3, 0.0, 1.5]), np.zeros(3), np.zeros(3)

    with pytest.raises(adaptimp.ConfigError) as e:
        amj.cartesian_task("panda", pose=far)
    assert "the inverse kinematics of the pose path's first pose diverged" in str(e.value)
    assert "is the pose within the arm's reach?" in str(e.value)
    # Not "the path reachable … (best 0)": a start screened alone measures no reach.
    assert "the inverse kinematics within 0.001 m of it (best 0.2575)" in str(e.value)


def test_a_task_with_no_start_names_the_condition_that_failed() -> None:
    """``tip="panda_link1"`` said "none passed the rule at its start", not why."""
    from adaptimp import _models

    with pytest.raises(adaptimp.ConfigError) as e:
        amj.cartesian_task(_models.panda_urdf_path(), tip="panda_link1")
    assert (
        "none passed the rule at its start (the condition σmin(J) ≥ 0.05 m/rad along the task "
        "(not near a singularity) failed at 2050 of them)" in str(e.value)
    )


ONE_JOINT = (
    "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
    "<parent link='a'/><child link='b'/><axis xyz='0 0 1'/>"
    "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>"
)


def test_urdf_text_after_a_byte_order_mark_is_text() -> None:
    """It was taken for a path, the whole text printed as the file's name."""
    assert adaptimp.Chain.from_urdf("\ufeff" + ONE_JOINT).n == 1


def test_a_urdf_axis_of_two_numbers_is_named() -> None:
    """The joint was named, not the axis."""
    text = ONE_JOINT.replace("xyz='0 0 1'", "xyz='0 1'")
    with pytest.raises(adaptimp.ConfigError, match=r'<axis xyz="0 1"> \(three numbers, x y z\)'):
        adaptimp.Chain.from_urdf(text)


def test_a_tiny_quaternion_is_normalised_as_documented() -> None:
    """A body quaternion of norm 1e-200 (MuJoCo keeps it as given) was refused
    as zero, though the docs say a non-zero one is normalised."""
    import mujoco

    xml = (
        "<mujoco><worldbody><body name='a'><joint name='j1' axis='0 0 1'/>"
        "<geom size='0.05' mass='1'/><body name='b' pos='0.3 0 0' quat='1e-200 0 0 0'>"
        "<joint name='j2' axis='0 1 0'/><geom size='0.05' mass='1'/>"
        "<site name='tip' pos='0.2 0 0'/></body></body></worldbody></mujoco>"
    )
    model = mujoco.MjModel.from_xml_string(xml)
    assert model.body_quat[2, 0] == 1e-200
    chain = adaptimp.Chain.from_mujoco(model, "tip")
    np.testing.assert_allclose(chain.fk([0.0, 0.0])[:3, 3], [0.5, 0.0, 0.0], atol=1e-15)


def test_the_cli_refuses_a_figure_format_and_an_output_that_is_no_folder(
    tmp_path: Path,
) -> None:
    """``--plot x.unknownext`` and ``reproduce --out /dev/null`` ended in
    tracebacks; ``--save dir/`` wrote ``dir.npz`` beside the folder."""
    cases = (
        (["simulate", "--case", "pd", "--T", "0.01", "--plot", str(tmp_path / "x.unknownext")],
         ".unknownext is not a figure format"),
        (["reproduce", "--out", "/dev/null"], "--out /dev/null: not a folder"),
        (["simulate", "--case", "pd", "--T", "0.01", "--save", f"{tmp_path}/"], "is a folder"),
    )  # fmt: skip
    for argv, said in cases:
        out = subprocess.run(
            [sys.executable, "-m", "adaptimp", *argv],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        assert out.returncode in (1, 2), (argv, out)
        assert "Traceback" not in out.stderr, out.stderr
        assert said in out.stderr, out.stderr
    assert not (tmp_path.parent / f"{tmp_path.name}.npz").exists()


def test_peers_refuses_a_frame_the_file_lacks_before_it_builds() -> None:
    """``benches/peers.py --urdf FILE:nope`` raised IndexError, after building
    the C++ peer."""
    pytest.importorskip("pinocchio")
    spec = importlib.util.spec_from_file_location("peers", ROOT / "benches" / "peers.py")
    assert spec is not None
    assert spec.loader is not None
    peers = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(peers)
    with pytest.raises(SystemExit, match=r"the file has no link or frame 'nope'"):
        peers.arm_files([], [f"{HOBBY}:nope"])
