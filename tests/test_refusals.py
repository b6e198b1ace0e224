"""Arguments the Python surface refuses, by name, with the value, before anything
runs (the break-it pass's leftovers): the contact scenario's placement and
metrics, the MuJoCo run's window, the Cartesian formulation's share, a saved
result whose metrics or parameters were edited, a URDF with several legs."""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

import adaptimp
from adaptimp import _models
from adaptimp._description import read_arm
from adaptimp.scenarios import contact as act

PANDA = adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip=_models.PANDA_EE)
LO, HI = np.full(7, -1.0), np.full(7, 1.0)
HOME = np.asarray(_models.PANDA_HOME)


@pytest.mark.parametrize(
    ("home", "limits", "tool_radius", "message"),
    [
        (HOME, (LO, HI), math.nan, "tool_radius must be a finite number > 0 (m), got nan"),
        (HOME, (LO, HI), -0.01, "tool_radius must be a finite number > 0 (m), got -0.01"),
        (
            HOME,
            (np.where(np.arange(7) == 2, math.nan, LO), HI),
            0.01,
            "limits[0] (lo) must be 7 finite numbers (rad) (±π for an unlimited joint); "
            "joint 2 ('panda_joint3') is nan",
        ),
        (
            HOME,
            (LO, np.where(np.arange(7) == 6, math.inf, HI)),
            0.01,
            "limits[1] (hi) must be 7 finite numbers (rad) (±π for an unlimited joint); "
            "joint 6 ('panda_joint7') is inf",
        ),
        (
            HOME,
            (HI, LO),
            0.01,
            "limits must have lo ≤ hi for every joint; joint 0 ('panda_joint1') has "
            "lo = 1.0 > hi = -1.0",
        ),
        (
            HOME,
            (LO[:3], HI),
            0.01,
            "limits[0] (lo) must be 7 finite numbers (rad) (±π for an unlimited joint), "
            "one per joint; got shape (3,)",
        ),
        (
            np.full(7, math.nan),
            (LO, HI),
            0.01,
            "home must be 7 finite numbers (rad); joint 0 ('panda_joint1') is nan",
        ),
    ],
)
def test_placement_refuses_a_quantity_that_is_not_finite_by_name(
    home: np.ndarray, limits: tuple[np.ndarray, np.ndarray], tool_radius: float, message: str
) -> None:
    with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
        act.placement(PANDA, home, limits, tool_radius=tool_radius)


def test_placement_of_finite_input_is_unchanged() -> None:
    """The checks let a finite input through to the same numbers: the centre lies
    at min(radial + OUTWARD, REACH_SHARE R) along the home tip's direction."""
    centre, top, reach = act.placement(PANDA, HOME, (LO, HI))
    p = PANDA.fk(HOME)[:3, 3]
    radial = float(np.linalg.norm(p[:2]))
    assert float(np.linalg.norm(centre)) == pytest.approx(
        min(radial + act.OUTWARD, act.REACH_SHARE * reach)
    )
    assert top == pytest.approx(p[2] - 0.01 - act.CLEARANCE)


def test_arm_table_refuses_a_home_that_is_not_finite_by_name() -> None:
    ur5 = _models.panda_urdf_path().parent.parent.parent / "ur_description/urdf/ur5_robot.urdf"
    home = [0.0, math.nan, 0.0, 0.0, 0.0, 0.0]
    message = "home must be 6 finite numbers (rad); joint 1 ('shoulder_lift_joint') is nan"
    with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
        act.arm_table(ur5, home=home)


def test_contact_metrics_of_a_run_without_rows_in_its_windows_is_refused() -> None:
    """A 0.05 s run: no row at t ≥ settle (default 2 s), and none at t ≥ 0.1 s
    (peak_tau_ratio's window): each is named with the run's last row."""
    from adaptimp import mujoco as amj
    from adaptimp.scenarios import panda_table as apt

    sc = act.arm_table(friction=0.0)
    ctrl = apt.panda_controller("ct", sc, formulation="impedance")
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=0.05, q0=sc.q0)
    message = (
        "the metrics' window t ≥ settle = 2 s holds no row of the run (50 rows, its last "
        "row at t = 0.049 s): run for longer than 2 s (or give a smaller settle)"
    )
    with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
        act.contact_metrics(res, ctrl, sc)
    message = (
        "the metrics' window t ≥ windup_after = 0.1 s holds no row of the run (50 rows, its "
        "last row at t = 0.049 s): run for longer than 0.1 s (peak_tau_ratio leaves out the "
        "start-up transient)"
    )
    with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
        act.contact_metrics(res, ctrl, sc, settle=0.0)
    for settle in (math.nan, -1.0):
        with pytest.raises(
            adaptimp.ConfigError,
            match=f"^{re.escape(f'settle must be a finite number ≥ 0 (s), got {settle!r}')}$",
        ):
            act.contact_metrics(res, ctrl, sc, settle=settle)
    # Long enough for both windows: every metric is a number, but for the time
    # off the table after the approach, which this run never reaches: NaN.
    longer = amj.simulate(ctrl, amj.Plant(sc.model), T=0.2, q0=sc.q0)
    m = act.contact_metrics(longer, ctrl, sc, settle=0.1)
    assert math.isnan(m.pop("contact_lost_s"))
    assert all(math.isfinite(v) for v in m.values()), m
    # A run recorded every other period: the chatter is per sample, so refused.
    sparse = amj.simulate(ctrl, amj.Plant(sc.model), T=0.4, q0=sc.q0, record_every=2)
    with pytest.raises(adaptimp.ConfigError, match=r"record_every=1$"):
        act.contact_metrics(sparse, ctrl, sc, settle=0.1)


def _erd(*parts: str) -> str:
    return str(_models.panda_urdf_path().parent.parent.parent.joinpath(*parts))


SOLO = _erd("solo_description", "robots", "solo12.urdf")
LEGS = "'FL_LOWER_LEG', 'FR_LOWER_LEG', 'HL_LOWER_LEG', 'HR_LOWER_LEG'"


def test_a_quadruped_is_refused_unless_the_leg_is_named() -> None:
    """Solo's four legs tie for the longest chain: the arm loaders (MuJoCo's,
    Pinocchio's, the contact scenario's) and the kinematic chain each refuse to
    pick one, listing the candidates; tip= picks it."""
    from adaptimp import mujoco as amj
    from adaptimp.baselines import pinocchio_model

    message = (
        f"URDF 'solo12.urdf': 4 serial chains of 3 joints from the root tie for the arm (legs, "
        f"or two arms), ending at the links {LEGS}: name one with tip= or hold the others' "
        "joints with fix="
    )
    for load in (
        amj.from_urdf,
        amj.Plant,
        pinocchio_model,
        act.arm_table,
        adaptimp.Chain.from_urdf,
    ):
        with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
            load(SOLO)
    with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
        amj.simulate("sf", SOLO, T=0.01)
    # Named: that leg, the others fixed, the same in every loader.
    leg = ("HR_HAA", "HR_HFE", "HR_KFE")
    arm = read_arm(SOLO, tip="HR_LOWER_LEG")
    assert arm.joints == leg
    assert sorted(arm.fixed) == sorted(
        f"{side}_{j}" for side in ("FL", "FR", "HL") for j in ("HAA", "HFE", "KFE")
    )
    plant = amj.Plant(amj.from_urdf(SOLO, tip="HR_LOWER_LEG"))
    joint = amj.mujoco.mjtObj.mjOBJ_JOINT
    assert tuple(amj.mujoco.mj_id2name(plant.model, joint, j) for j in plant._joints) == leg
    assert adaptimp.Chain.from_urdf(SOLO, tip="HR_LOWER_LEG").joint_names == list(leg)
    paw = (
        "URDF 'solo12.urdf': tip= 'paw' is neither a link nor a frame of it: name the link "
        "(a MuJoCo body) or the frame (a site) that ends the arm; its 17 links and 0 frames, "
        "closest first: ['base_link', 'FL_UPPER_LEG', 'FL_LOWER_LEG', 'FR_UPPER_LEG', "
        "'FR_LOWER_LEG', 'HL_UPPER_LEG', 'HL_LOWER_LEG', 'HR_UPPER_LEG', 'HR_LOWER_LEG', "
        "'FL_FOOT', 'FR_FOOT', 'HL_FOOT', 'HR_FOOT', 'FL_SHOULDER', 'FR_SHOULDER', "
        "'HL_SHOULDER', 'HR_SHOULDER']"
    )
    with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(paw)}$"):
        read_arm(SOLO, tip="paw")
    # A misspelt tip: the link meant leads the list (issue 45).
    with pytest.raises(adaptimp.ConfigError) as e:
        amj.Plant(str(_models.panda_urdf_path()), tip="panda_tcp")
    assert str(e.value).startswith(
        "URDF 'panda.urdf': tip= 'panda_tcp' is neither a link nor a frame of it: name the "
        "link (a MuJoCo body) or the frame (a site) that ends the arm; its 13 links and 0 "
        "frames, closest first: ['panda_hand_tcp', "
    )


def test_the_contact_scenario_drives_the_joints_simulate_drives() -> None:
    """The so100 arm ends in a gripper joint (named "gripper"): the contact
    scenario and adaptimp.mujoco.simulate take the same arm, by the core's one
    rule (SPEC (21.2): the gripper's joint fixed, the tool on the wrist's link)."""
    from adaptimp import mujoco as amj

    so100 = _erd("so_arm_description", "urdf", "so100.urdf")
    arm = ("shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll")
    rule = read_arm(so100)
    assert rule.joints == arm
    assert rule.fixed == {"gripper": "a gripper's (its name contains 'gripper')"}
    sc = act.arm_table(so100)
    assert sc.n == len(arm)
    assert tuple(sc.chain.joint_names) == arm
    plant = amj.Plant(sc.model)
    joint = amj.mujoco.mjtObj.mjOBJ_JOINT
    assert tuple(amj.mujoco.mj_id2name(plant.model, joint, j) for j in plant._joints) == arm
    res = amj.simulate("sf", so100, T=0.01)
    assert res.q.shape == (10, len(arm))
    alone = amj.Plant(so100)
    assert tuple(amj.mujoco.mj_id2name(alone.model, joint, j) for j in alone._joints) == arm


def test_a_tip_beyond_a_fixed_joint_holds_it_on_the_chain_too() -> None:
    """Given tip= and fix= that leave a fixed joint on the chain, the chain holds
    it as the model does (one reduction, SPEC (21.2)): the tool rides on the jaw,
    the gripper's joint held closed."""
    so100 = _erd("so_arm_description", "urdf", "so100.urdf")
    arm = ["shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll"]
    sc = act.arm_table(so100, tip="jaw", fix=("gripper",))
    assert sc.chain.joint_names == arm
    assert sc.chain.fixed == {"gripper": "asked (fix=)"}


@pytest.mark.parametrize("formulation", [None, "admittance", "impedance"])
def test_an_admittance_share_without_the_unified_formulation_is_refused(
    formulation: str | None,
) -> None:
    """admittance_share acts in formulation='unified' only; given with another
    (or the default, 'admittance') it would be ignored: refused, naming both."""
    from adaptimp import cartesian as ac

    chosen = {} if formulation is None else {"formulation": formulation}
    message = (
        f"admittance_share = 0.5 has no effect with formulation={formulation or 'admittance'!r}: "
        "it is the admittance's share of the torque for formulation='unified' only (give "
        "formulation='unified', or leave admittance_share out)"
    )
    for make in (
        lambda: ac.CartesianImpedance(PANDA, Ts=1e-3, q0=HOME, admittance_share=0.5, **chosen),
        lambda: ac.CartesianController(PANDA, "sf", q0=HOME, admittance_share=0.5, **chosen),
    ):
        with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
            make()
    # Unified takes it; the other formulations take their defaults' dict.
    unified = ac.CartesianImpedance(
        PANDA, Ts=1e-3, q0=HOME, formulation="unified", admittance_share=0.5
    )
    assert unified.params["admittance_share"] == 0.5
    other = ac.CartesianImpedance(PANDA, Ts=1e-3, q0=HOME, **chosen)
    assert other.params["formulation"] == (formulation or "admittance")


def _edited(src: Path, dst: Path, **edits: object) -> Path:
    """A copy of the saved file ``src`` with entries replaced: a callable edits
    the entry's JSON, anything else replaces the entry."""
    import json

    with np.load(src, allow_pickle=False) as f:
        content = {k: f[k] for k in f}
    for key, edit in edits.items():
        if callable(edit):
            content[key] = np.array(json.dumps(edit(json.loads(str(content[key])))))
        else:
            content[key] = np.array(edit)
    np.savez_compressed(dst, **content)
    return dst


def _set(key: str, value: object) -> object:
    def edit(d: dict[str, object]) -> dict[str, object]:
        d[key] = value
        return d

    return edit


def _as_format_3(m: dict[str, object]) -> dict[str, object]:
    """A record of format 3 (before the digests of the arrays, inputs and
    metrics and the class were recorded: a file of format 3 holds none of
    them, and one that declares 3 with any of them is refused)."""
    m["version"] = 3
    for key in ("arrays", "result", "inputs", "metrics"):
        m.pop(key, None)
    return m


def _without_inputs(m: dict[str, object]) -> dict[str, object]:
    return _as_format_3(m)


def test_a_load_names_the_parameters_edited_after_the_save(tmp_path: Path) -> None:
    """The save records the SHA-256 of the case, scenario, rows kept and each
    parameter; a load names each that differs, instead of blaming the platform."""
    path = adaptimp.simulate("sf", T=0.05).save(tmp_path / "run")
    edited = _edited(path, tmp_path / "k1.npz", params=_set("K1", [7.0, 6.0]))
    message = (
        f"{edited}: the file was edited after it was saved: the parameter 'K1' (now [7.0, "
        "6.0]) is not what the save recorded (its SHA-256 differs), so its arrays and metrics "
        "are not those of a run with it"
    )
    with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
        adaptimp.SimResult.load(edited)
    both = _edited(path, tmp_path / "both.npz", case="pd", params=_set("T", 0.06))
    message = (
        f"{both}: the file was edited after it was saved: the case ('pd'), the parameter 'T' "
        "(now 0.06) are not what the save recorded"
    )
    with pytest.raises(ValueError, match=f"^{re.escape(message)}"):
        adaptimp.SimResult.load(both)
    # A MuJoCo run keeps its arrays: an edited Ts would re-derive t unseen.
    from adaptimp import mujoco as amj

    saved = amj.simulate("sf", "two_link", T=0.02).save(tmp_path / "mj")
    ts = _edited(saved, tmp_path / "ts.npz", params=_set("Ts", 2e-3))
    with pytest.raises(ValueError, match=re.escape("the parameter 'Ts' (now 0.002) is not")):
        amj.MujocoResult.load(ts)


def test_a_file_without_recorded_inputs_names_what_differs_and_both_causes(
    tmp_path: Path,
) -> None:
    """A file saved before the inputs were recorded: the rerun's bits differ; the
    message names the array, both digests, the versions and both causes."""
    path = adaptimp.simulate("sf", T=0.05).save(tmp_path / "run")
    old = _edited(path, tmp_path / "old.npz", format=_without_inputs)
    assert adaptimp.SimResult.load(old).metrics == adaptimp.SimResult.load(path).metrics
    edited = _edited(old, tmp_path / "edited.npz", params=_set("K1", [7.0, 6.0]))
    message = (
        r"^.*edited\.npz: \w+ was left to the simulation to recompute, but running the file's "
        r"case 'sf', scenario 'paper' and parameters again does not give the same bits "
        r"\(SHA-256 [0-9a-f]{12}…, the save recorded [0-9a-f]{12}…; saved by adaptimp "
        + re.escape(adaptimp.__version__)
        + r", which this is\): the file's case, scenario or parameters were edited after it "
        r"was saved, or this platform's floating point differs from the one that saved it$"
    )
    with pytest.raises(ValueError, match=message):
        adaptimp.SimResult.load(edited)
    broken = _edited(old, tmp_path / "broken.npz", params=_set("K1", [-1.0, 6.0]))
    message = (
        "t was left to the simulation to recompute, but the file's case 'sf', scenario "
        "'paper' and parameters do not describe a run the core can repeat (ConfigError: "
        "condition K1 > 0 is violated: K1[0] = -1 (SPEC §10)); saved by adaptimp "
        f"{adaptimp.__version__}, which this is"
    )
    with pytest.raises(ValueError, match=f"{re.escape(message)}$"):
        adaptimp.SimResult.load(broken)


def test_metrics_edited_after_the_save_are_refused_or_recomputed(tmp_path: Path) -> None:
    """A save records each metric's SHA-256: an edited one is refused by name. A
    file of format 2 or 3 saved the metrics of the rows it holds: one that
    disagrees with its rows is refused too. A file of format 1 (no record)
    has its metrics recomputed from its rows by the core's accumulator (bit
    for bit the run's), with a warning naming each that differed."""
    res = adaptimp.simulate("sf", T=2.05)
    path = res.save(tmp_path / "run")
    edited = _edited(path, tmp_path / "m.npz", metrics=_set("rms_z1", 0.001))
    message = (
        f"{edited}: the file was edited after it was saved: the metric 'rms_z1' (now 0.001) "
        "is not what the save recorded (its SHA-256 differs)"
    )
    with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
        adaptimp.SimResult.load(edited)
    # compress=False records them too (format 4): refused the same way.
    plain = _edited(
        res.save(tmp_path / "plain", compress=False), tmp_path / "plain_m.npz",
        metrics=_set("rms_z1", 0.001),
    )  # fmt: skip
    with pytest.raises(ValueError, match=re.escape(f"{plain}: the file was edited")):
        adaptimp.SimResult.load(plain)
    true = res.metrics["rms_z1_after2"]
    old = _edited(path, tmp_path / "old.npz", format=_without_metrics)
    bad = _edited(old, tmp_path / "old_m.npz", metrics=_set("rms_z1_after2", 0.5))
    message = (
        f"{bad}: the file was edited after it was saved: its metrics are not those of its rows "
        f"(rms_z1_after2 = 0.5 stored, {true!r} from the rows; format 3 saved them together)"
    )
    with pytest.raises(adaptimp.SaveError, match=f"^{re.escape(message)}$"):
        adaptimp.SimResult.load(bad)
    with np.load(res.save(tmp_path / "plain1", compress=False), allow_pickle=False) as f:
        first = {k: f[k] for k in f if k != "format"}  # format 1: plain arrays, no record
    np.savez(tmp_path / "v1.npz", **first)
    for name, source in (("v1", tmp_path / "v1.npz"),):
        bad = _edited(source, tmp_path / f"{name}_m.npz", metrics=_set("rms_z1_after2", 0.5))
        warning = (
            f"{bad}: the stored metrics disagree with what its rows give (rms_z1_after2 = 0.5 "
            f"stored, {true!r} from the rows); the file records no digest of them (saved with "
            "compress=False, or by an earlier version): the metrics are recomputed from the rows"
        )
        with pytest.warns(UserWarning, match=f"^{re.escape(warning)}$"):
            back = adaptimp.SimResult.load(bad)
        assert back.metrics == res.metrics
    # An edited result, saved: the file is faithful to it and loads as saved.
    odd = dataclasses.replace(res, metrics={**res.metrics, "rms_z1": 1.0})
    assert adaptimp.SimResult.load(odd.save(tmp_path / "odd")).metrics["rms_z1"] == 1.0


def _without_metrics(m: dict[str, object]) -> dict[str, object]:
    return _as_format_3(m)


def test_a_settle_below_zero_or_beyond_the_run_is_refused_by_both_plants() -> None:
    """settle ≥ 0 is the core's condition, on the rigid plant and on MuJoCo (either
    loop); a settle given beyond the run's last step would leave the 'after'
    metrics NaN: refused, naming the last step. The last step itself is fine."""
    from adaptimp import mujoco as amj
    from adaptimp.baselines import ComputedTorque

    below = "condition settle ≥ 0 is violated: settle = -1 (SPEC §10)"
    beyond = (
        "settle = {s:g} s starts the metrics' window t ≥ settle after the run's last step "
        "(t = {last:g} s; T = 0.2 s at Ts = {Ts:g} s), so its metrics would be NaN: give "
        "settle ≤ {last:g} s, or a longer T"
    )
    runs = (
        (lambda s: adaptimp.simulate("sf", T=0.2, settle=s), 5e-5),
        (lambda s: amj.simulate("sf", "panda", T=0.2, settle=s), 1e-3),  # the core's loop
        (  # a loop in Python (a Python controller)
            lambda s: amj.simulate(
                ComputedTorque(Ts=1e-3), "two_link",
                T=0.2, settle=s,
            ),
            1e-3,
        ),
    )  # fmt: skip
    for run, ts in runs:
        with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(below)}$"):
            run(-1.0)
        last = 0.2 - ts
        for s in (5.0, 0.2):
            message = beyond.format(s=s, last=last, Ts=ts)
            with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
                run(s)
        res = run(last)
        assert math.isfinite(res.metrics["rms_z1_after2"])
    # The default settle (2 s) on a shorter run keeps its documented NaN.
    assert math.isnan(adaptimp.simulate("sf", T=0.2).metrics["rms_z1_after2"])


def test_the_panda_s_scenario_refuses_a_urdf_s_keywords() -> None:
    """arm_table(urdf=None) is the Panda's own scenario: tip, fix and home would
    be ignored; refused, naming them."""
    message = (
        "tip, home apply to the arm of a URDF; the Panda's scenario (urdf=None) has its own "
        "tool body, fixed fingers and home posture: give the Panda's URDF path to set them"
    )
    with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
        act.arm_table(tip="panda_link8", home=HOME)
    with pytest.raises(adaptimp.ConfigError, match=r"^fix applies to the arm of a URDF"):
        act.arm_table(fix=("panda_joint7",))


def test_a_path_that_is_no_file_is_file_not_found_everywhere() -> None:
    """Every entry point that reads an arm's file raises FileNotFoundError for a
    path that is not there, naming it (issue 45, finding 10: simulate raised
    ValueError, Chain FileNotFoundError)."""
    from adaptimp import mujoco as amj
    from adaptimp.baselines import ComputedTorque
    from adaptimp.scenarios import contact as act

    for call in (
        lambda: amj.simulate("sf", "nowhere.urdf", T=0.1),
        lambda: amj.Plant("nowhere.xml"),
        lambda: amj.cartesian_task("nowhere.urdf"),
        lambda: amj.from_urdf("nowhere.urdf"),
        lambda: adaptimp.Chain.from_urdf("nowhere.urdf"),
        lambda: adaptimp.Chain.from_mujoco("nowhere.xml"),
        lambda: ComputedTorque("nowhere.urdf"),
        lambda: act.arm_table("nowhere.urdf"),
        lambda: adaptimp.Controller("sf", gravity="nowhere.urdf"),
        lambda: read_arm("nowhere.urdf"),
    ):
        with pytest.raises(FileNotFoundError, match=r"'nowhere\.(urdf|xml)'"):
            call()
