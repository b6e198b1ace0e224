"""What the table scenario checks before a run and measures after it (SPEC
§19): a start the controller cannot hold refused by name
(:func:`refusal_of`: the velocity loop's radius, the path through the table,
the press, the sag), the rule's keywords for the scenario
(:func:`rule_keywords`, :func:`normal_inertia`), the metrics of a run
(:func:`contact_metrics`) and the rows of its table of controllers.

Re-exported by :mod:`adaptimp.scenarios.contact`. Units: m, s, rad, N, N m."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._errors import ConfigError
from ..chain import Chain
from ._contact_model import (
    ADMITTANCE_SHARE_OF_PERIOD,
    CONTACT_K1,
    TABLE_TIMECONST,
    THROUGH_TABLE,
    FloatArray,
    check_path_length,
    joint_vector,
    pair_inverse_mass,
    tool_table,
)
from .panda_table import PandaTable, table_metrics

REFUSAL_ROWS = 40
"""Rows of the scenario's joint path at which :func:`refusal_of` checks the arm
(those of the one posture check, ``adaptimp._posture.CHECKED``)."""


def refusal_of(sc: PandaTable, *, load: float = 0.5) -> str | None:
    """Why the table cannot run at the scenario's home, or None (SPEC (19.6)).

    Along the scenario's joint path (the hold, the approach, the press and one
    circle on the table's surface, as the outer loop maps it, F_e = 0): the
    one posture check of :func:`adaptimp.mujoco.cartesian_task` and
    :meth:`adaptimp.CartesianController.from_rule` (SPEC (16.9), the position
    rows: not near a singularity, inside the joint limits with margin, gravity
    at most half of every actuator, the velocity loop well-conditioned at home
    for the table's K1 = 10 s⁻¹, the path reachable within 1 mm, no collision
    of the arm with itself and the scene, the tool left out), then the table's
    own: no joint of the arm below the table top over the table, and the rule's gains' sampled
    velocity loop stable at every posture of the path (SPEC (19.10),
    :func:`velocity_loop_radius`). ``load``: the largest gravity
    load max_i |G_i|/τmax_i allowed (1 for a home the user gives: gravity
    within the actuators; the press, SPEC (19.6), is checked apart)."""
    from .. import _posture
    from .. import mujoco as amj

    start = sc.t_approach + max(sc.t_ramp, sc.t_press)
    check_path_length(start + 1.0 / sc.freq, sc.Ts)
    steps = round((start + 1.0 / sc.freq) / sc.Ts)
    q, _ = sc.outer().joint_orbit(lambda t: sc.path(t, depth=0.0), steps * sc.Ts, samples=steps)
    idx = _posture.checked_rows(steps)
    rows = np.ascontiguousarray(q[idx])
    targets = np.ascontiguousarray(
        np.array([sc.path(k * sc.Ts, depth=0.0)[0] for k in idx], dtype=np.float64)
    )
    plant = amj.Plant(sc.model, contact=False)
    # The one posture check (SPEC (16.9)), at the table's K1; the collisions of
    # the arm with itself and the rest of the scene (a pedestal, another arm),
    # the tool on the table left out: that is the task.
    a = _posture.assess(
        plant, sc.chain, sc.q0, rows, targets, orients=False, k1=CONTACT_K1, Ts=sc.Ts,
        load=load, tau_max=sc.tau_max, skip=frozenset({int(plant.ee_body)}),
    )  # fmt: skip
    if a["error"] is not None:
        return str(a["error"])
    through = _through_table(sc, plant, rows)
    if through is not None:
        return through
    return _velocity_loop_gain(sc, plant, rows)


ROBUST_SLOPE = 0.5
"""The slope of (18.4)'s robust term at z2 = 0 against Kp: kr_i/φ = Kp_i/2."""


def velocity_loop_radius(
    inertia: ArrayLike, gain: ArrayLike, damping: ArrayLike | None, Ts: float
) -> float:
    """The spectral radius of the sampled velocity loop, SPEC (19.10): a joint
    law whose torque τ_k = −K_v v_k is held over a period Ts (s) on an arm of
    inertia D (kg m², (n, n)) with viscous damping B = diag(``damping``)
    (N m s/rad, MuJoCo integrates it within the period; None: none) moves the
    velocity by v_(k+1) = (E − F D⁻¹ K_v) v_k, E = e^(−Ts D⁻¹B), F = ∫₀^Ts
    e^(−s D⁻¹B) ds; K_v = diag(``gain``) (N m s/rad). Stable below 1; without
    damping ρ = max_i |1 − Ts λ_i(D⁻¹ K_v)|, i.e. Ts λmax < 2."""
    d = np.asarray(inertia, dtype=np.float64)
    n = d.shape[0]
    b = np.zeros(n) if damping is None else np.asarray(damping, dtype=np.float64)
    w, u = np.linalg.eigh(d)
    half, inv_half = (u * np.sqrt(w)) @ u.T, (u / np.sqrt(w)) @ u.T
    # D⁻¹B = D^(−½) S D^(½), S = D^(−½) B D^(−½) symmetric ≥ 0.
    lam, v = np.linalg.eigh(inv_half @ np.diag(b) @ inv_half)
    lam = np.maximum(lam, 0.0)
    x = lam * Ts
    share = np.where(x > 1e-12, -np.expm1(-x) / np.where(x > 1e-12, lam, 1.0), Ts)
    e = inv_half @ (v * np.exp(-x)) @ v.T @ half
    f = inv_half @ (v * share) @ v.T @ half
    loop = e - f @ np.linalg.solve(d, np.diag(np.asarray(gain, dtype=np.float64)))
    return float(np.max(np.abs(np.linalg.eigvals(loop))))


def _velocity_loop_gain(sc: PandaTable, plant: Any, rows: FloatArray) -> str | None:
    """SPEC (19.10): the rule's joint gains (:func:`rule_keywords`: the
    inertia scales along the path) close a sampled velocity loop
    (:func:`velocity_loop_radius`, K_v = Kp (1 + :data:`ROBUST_SLOPE`), the
    plant's own damping) that must stay stable (ρ < 1) at every posture of
    ``rows``; the first posture where it is not, named with ρ, or None."""
    from .. import tuning

    kv = np.asarray(rule_keywords(sc)["gains"]["Kp"], dtype=np.float64) * (1.0 + ROBUST_SLOPE)
    damping = tuning.joint_damping(plant)
    for k, q in enumerate(rows):
        rho = velocity_loop_radius(tuning.inertia(plant, q), kv, damping, sc.Ts)
        if not rho < 1.0:
            return (
                f"{RINGING}: at row {k} of the path the sampled velocity loop's spectral "
                f"radius ρ(E − F D⁻¹ K_v) = {rho:.3g} ≥ 1 (K_v = Kp + kr/φ of the rule's "
                "gains: joints whose axes line up along the path share a light inertia)"
            )
    return None


RINGING = "the velocity loop stable along the path"
"""How :func:`refusal_of` begins the refusal of a path on which the rule's
gains would ring at half the sampling rate (SPEC (19.10))."""


def _through_table(sc: PandaTable, plant: Any, rows: FloatArray) -> str | None:
    """A joint of the arm (its anchor) below the table top over the table, at a
    posture of ``rows``, named; None if none."""
    import mujoco

    m = plant.model
    tool, g = tool_table(m)
    if g < 0:
        return None
    d = mujoco.MjData(m)
    top = sc.surface_z - float(m.geom_size[tool, 0])
    for k, q in enumerate(rows):
        d.qpos[plant.qpos_adr] = q
        mujoco.mj_kinematics(m, d)
        centre, half = d.geom_xpos[g], m.geom_size[g]
        axes = d.geom_xmat[g].reshape(3, 3)  # the table's axes (turned if it faces the base)
        for i, j in enumerate(plant.joint_ids):
            a = axes.T @ (d.xanchor[j] - centre)
            over = abs(a[0]) <= half[0] and abs(a[1]) <= half[1]
            if over and d.xanchor[j][2] < top:
                return (
                    f"{THROUGH_TABLE}: at row {k} of the path joint {i} "
                    f"({sc.chain.joint_names[i]!r}) is {top - d.xanchor[j][2]:.3g} m below the "
                    "table top"
                )
    return None


def check_press(
    chain: Chain,
    plant: Any,
    q0: FloatArray,
    tau_max: FloatArray,
    force: float,
    friction: float,
    tool_radius: float,
) -> None:
    """Refuse an arm that cannot hold the press at its home posture: joint i
    takes |G_i(q0)| + F (|J_c,z,i| + μ ‖J_c,xy,i‖) (N m), gravity and the
    prescribed normal force F (N) with its sliding friction μF in the worst
    horizontal direction, acting at the contact point (the tool's centre less
    ``tool_radius`` along z, J_c its position Jacobian); beyond τmax_i no
    controller can press (an estimated effort limit of a light wrist, say)."""
    from .. import tuning

    j = np.asarray(chain.jacobian(q0), dtype=np.float64)
    o = np.array([0.0, 0.0, -tool_radius])
    skew = np.array([[0.0, -o[2], o[1]], [o[2], 0.0, -o[0]], [-o[1], o[0], 0.0]])
    jc = j[:3] - skew @ j[3:]  # v + ω × o
    g = tuning.gravity(plant, q0)
    load = np.abs(g if g is not None else 0.0) + force * (
        np.abs(jc[2]) + friction * np.linalg.norm(jc[:2], axis=0)
    )
    over = np.flatnonzero(load > tau_max)
    if over.size:
        i = int(over[0])
        raise ConfigError(
            f"the arm cannot press on the table: at its home posture joint {i} "
            f"({chain.joint_names[i]!r}) takes {load[i]:.4g} N m (gravity and the "
            f"prescribed {force:.4g} N with friction {friction:g}) but its effort limit is "
            f"{tau_max[i]:.4g} N m; give the URDF a larger <limit effort> for it, or a "
            "smaller depth or friction"
        )


def sag(chain: Chain, model: Any, q0: ArrayLike, tau_max: ArrayLike, *, Ts: float = 1e-3) -> float:
    """How far (m) the tip hangs below its path at ``q0`` (rad) under the joint
    feedback alone, before the networks have learnt gravity: |(J Δq)_z| with
    Δq_i = G_i/(Kp_i K1) (SPEC (18.5)'s sag, in the task), Kp from the rule
    (:func:`adaptimp.tuning.suggest` with ``model``'s D(q0), ``tau_max`` (N m),
    ``Ts`` (s)), K1 = min(:data:`CONTACT_K1`, the rule's), G(q0) and J the tip's position
    Jacobian from ``chain``. ``model``: what :func:`adaptimp.tuning.gravity`
    takes (here the arm's ``adaptimp.mujoco.Plant``)."""

    q = joint_vector("q0", q0, chain)
    data: Any = getattr(model, "data", None)
    if data is None:
        return _sag(chain, model, q, tau_max, Ts)
    saved = (data.qpos.copy(), data.qvel.copy())
    try:
        return _sag(chain, model, q, tau_max, Ts)
    finally:  # a Plant's state as the caller left it
        import mujoco

        data.qpos[:], data.qvel[:] = saved
        mujoco.mj_forward(model.model, data)


def _sag(chain: Chain, model: Any, q: FloatArray, tau_max: ArrayLike, Ts: float) -> float:
    """:func:`sag` without keeping ``model``'s state."""
    from .. import tuning

    g = tuning.gravity(model, q)
    if g is None:
        raise ConfigError(f"sag needs a model that gives G(q); got {type(model).__name__}")
    kw = tuning.suggest(model, q, tau_max, Ts=Ts)
    kp = np.asarray(kw["Kp"], dtype=np.float64)
    dq = g / (kp * min(CONTACT_K1, float(kw["K1"][0])))
    return float(abs(np.asarray(chain.jacobian(q))[2] @ dq))


def rule_keywords(sc: PandaTable, case: str = "sf") -> dict[str, Any]:
    """Keywords of :func:`adaptimp.scenarios.panda_table.panda_controller` for the joint
    controller ``case`` on the scenario ``sc``, from the core's rule (SPEC §18,
    :func:`adaptimp.tuning.suggest`): gains (18.1)–(18.4) from D(q0), the RBF
    centres (18.5) and the learning (18.6)–(18.8) along the scenario's whole
    joint path (the hold, the approach, the press and one period of the circle,
    as the outer loop maps the path on the table's surface into the joints,
    F_e = 0, taken as one period of that length), the inertia scales the
    smallest along it (16.12), Ĝ's learning near the velocity loop's critical
    bandwidth (``tuning.suggest(critical=True)``) and K1 = min(:data:`CONTACT_K1`,
    the rule's (18.2)) (SPEC (19.6)), the centres' widths in q at least the
    diameter of the circle's joint orbit, one period after the approach (SPEC
    (19.11)). Returns ``gains`` (Kp, Kzeta, K1), ``basis`` (centres,
    widths) and the rest (gamma, sigma, weight_bound, kr, …) as keywords."""
    from .. import mujoco as amj
    from .. import tuning

    start = sc.t_approach + max(sc.t_ramp, sc.t_press)
    check_path_length(start + 1.0 / sc.freq, sc.Ts)
    steps = round((start + 1.0 / sc.freq) / sc.Ts)
    q, dq = sc.outer().joint_orbit(lambda t: sc.path(t, depth=0.0), steps * sc.Ts, samples=steps)
    ddq = np.gradient(dq, sc.Ts, axis=0)

    def path(t: float) -> tuple[Any, Any, Any]:
        k = min(round(t / sc.Ts), steps - 1)
        return q[k], dq[k], ddq[k]

    # (19.11): the circle repeats, the hold and the approach do not; the
    # centres' widths in q span the circle's joint orbit.
    circle = q[min(round(start / sc.Ts), steps - 1) :]
    kw = tuning.suggest(
        amj.Plant(sc.model), sc.q0, sc.tau_max, Ts=sc.Ts, path=path, period=steps * sc.Ts,
        case=case, critical=True, orbit=circle,
    )  # fmt: skip
    kw["K1"] = [min(CONTACT_K1, float(kw["K1"][0]))] * sc.n  # never above (18.2)
    out: dict[str, Any] = {
        "gains": {k: kw[k] for k in ("Kp", "Kzeta", "K1")},
        "basis": (kw["centers"], kw["widths"]),
    }
    md = normal_inertia(sc, q)
    if md > DEFAULT_MD:  # (19.8); the default target inertia otherwise, as before
        out["Md"] = [DEFAULT_MD, DEFAULT_MD, md]
    skip = {"n", "Kp", "Kzeta", "K1", "centers", "widths", "Ts", "tau_max"}
    out.update({k: v for k, v in kw.items() if k not in skip})
    return out


DEFAULT_MD = 2.0
"""The target inertia M_d (kg) of SPEC §16's defaults, per axis."""

NORMAL_SAMPLES = 50
"""Postures of the scenario's joint path at which :func:`normal_inertia` takes
the tool's Cartesian inertia along the normal."""


def normal_inertia(sc: PandaTable, q: ArrayLike) -> float:
    """The target inertia M_d,n (kg) along the table's normal by SPEC (19.8):
    max(M_d, k Λ_c (Ts/m)²), k = 1/τ_n² the table contact's stiffness per
    unit apparent mass (τ_n = :data:`TABLE_TIMECONST`), Λ_c the
    larger of the tool's Cartesian inertia along the normal, 1/(nᵀ J D⁻¹ Jᵀ
    n), over :data:`NORMAL_SAMPLES` postures of the joint path ``q`` (K, n)
    (rad; D the plant's, armature included) and
    MuJoCo's own estimate of it (1/``body_invweight0`` of the tool and the
    table), m = :data:`ADMITTANCE_SHARE_OF_PERIOD`: the admittance's mode on
    the table's stiffness takes at most m of a period."""
    from .. import mujoco as amj
    from .. import tuning

    model = sc.model
    tool, table = tool_table(model)
    if tool < 0 or table < 0:
        return DEFAULT_MD
    rows = np.asarray(q, dtype=np.float64)
    plant = amj.Plant(model, contact=False)
    idx = np.unique(np.linspace(0, rows.shape[0] - 1, NORMAL_SAMPLES).round().astype(int))
    lam = 0.0
    for k in idx:
        d = tuning.inertia(plant, rows[k])
        jz = np.asarray(sc.chain.jacobian(rows[k]), dtype=np.float64)[2]
        lam = max(lam, 1.0 / float(jz @ np.linalg.solve(d, jz)))
    inv_mass = pair_inverse_mass(model, tool, table)
    if inv_mass > 0:
        lam = max(lam, 1.0 / inv_mass)
    stiffness = 1.0 / TABLE_TIMECONST**2  # 1/s², per kg of apparent mass
    return max(DEFAULT_MD, stiffness * lam * (sc.Ts / ADMITTANCE_SHARE_OF_PERIOD) ** 2)


def contact_metrics(
    res: Any, ctrl: Any, sc: PandaTable, *, settle: float = 2.0
) -> dict[str, float]:
    """The scenario's table of a run (``res`` from :func:`adaptimp.mujoco.simulate`),
    over t ≥ ``settle`` (s) unless said:

    - ``track_mm``: RMS ‖p_d − p‖ (mm), the compliant reference against the tip;
    - ``track_along_mm``: RMS ‖(p_d − p)_xy‖ (mm), its part along the table
      (the table's plane; the normal part is the force error over K_d,z);
    - ``force_target_N``: K_d,z δ_c, or for a spring table of k_e (16.1)'s
      K_d k_e/(K_d + k_e) δ_c (N);
    - ``force_rms_err_N``: RMS (F_n − target) (N), F_n = −F_e,z;
    - ``force_chatter_N``: RMS (F_n,k+1 − F_n,k) (N), the sample-to-sample change;
    - ``force_mean_N``: the mean of F_n (N);
    - ``force_16_1_N``: what (16.1) prescribes with the measured mean n·e,
      K_d k_e/(K_d + k_e)(δ_c + n·e) (K_d (δ_c + n·e) for a rigid table), n = −z,
      e = p − p_d (N);
    - ``contact_lost_s``: time (s) with F_n ≤ 0 after the first contact at or
      after the end of the approach, when the commanded point has reached δ_c
      into the table (``t_approach + t_press``; all the time after it, if
      none; NaN for a run that ends before it);
    - ``peak_force_N``: max F_n over the whole run (N), the approach's impact
      included;
    - ``peak_tau_ratio``: max_i max_{t ≥ 0.1 s} |τ_i|/τmax_i, commanded;
    - ``sat_duty``: fraction of all rows with sat(τ_i) ≠ τ_i on some joint.
    """
    m = table_metrics(res, ctrl, sc, settle=settle)
    t = np.asarray(res.t)
    if t.size > 1 and not np.allclose(np.diff(t), sc.Ts, rtol=1e-9, atol=0.0):
        raise ConfigError(
            f"contact_metrics needs every period's row (Ts = {sc.Ts:g} s; the chatter is "
            "sample to sample): run simulate with record_every=1"
        )
    return {
        "track_mm": m["rms_track"] * 1e3,
        "track_along_mm": m["rms_track_along"] * 1e3,
        "peak_force_N": m["peak_force"],
        "force_rms_err_N": m["force_rms_err"],
        "force_target_N": m["force_target"],
        "force_chatter_N": m["force_chatter"],
        "force_mean_N": m["force_mean"],
        "force_16_1_N": m["force_16_1"],
        "contact_lost_s": m["contact_lost"],
        "peak_tau_ratio": m["peak_tau_ratio"],
        "sat_duty": m["sat_duty"],
        "applied_ratio": m["applied_ratio"],
    }


SHARE = 0.3
"""The admittance's share n of the table's unified rows (docs/contact.md)."""

LEARN_KEYS = ("gamma", "sigma", "weight_bound")
"""The rule's learning keywords; the rows without learning (PD, SF with +τe and
Γ = 1) leave them out."""

TABLE_ROWS: dict[str, tuple[str, str, str, bool, bool]] = {
    "pd": ("PD, admittance", "pd", "admittance", False, False),
    "sf-printed": ("SF with +τe, Γ = 1, admittance", "sf", "admittance", True, False),
    "sf-admittance": ("SF, admittance, no τe feedforward", "sf", "admittance", False, True),
    "sf": (f"SF, unified n = {SHARE}", "sf", "unified", False, True),
    "of": (f"OF, unified n = {SHARE}", "of", "unified", False, True),
    "sf-ff": (f"SF with +τe, unified n = {SHARE}", "sf", "unified", True, True),
    "sf-impedance": ("SF, impedance", "sf", "impedance", False, True),
    "ct-admittance": ("CT exact, admittance (+τe)", "ct", "admittance", True, False),
    "ct": ("CT exact, impedance", "ct", "impedance", False, False),
    "ct+30": ("CT +30 % mass, impedance", "ct+30", "impedance", False, False),
}
"""The table's rows (docs/contact.md): name: (label, joint controller, the
impedance's formulation (SPEC §19), the +τe feedforward, the rule's learning).
Computed torque's rows ("ct…") need a URDF arm (Pinocchio's model)."""


def row_controller(name: str, sc: PandaTable, rule: dict[str, Any]) -> Any:
    """The controller of the table's row ``name`` (:data:`TABLE_ROWS`) on the
    scenario ``sc``, with the scenario's rule keywords ``rule``
    (:func:`rule_keywords`)."""
    from .panda_table import panda_controller

    if name not in TABLE_ROWS:
        raise ConfigError(f"no row {name!r}; the rows are {list(TABLE_ROWS)}")
    _, kind, formulation, ff, learn = TABLE_ROWS[name]
    extra: dict[str, Any] = {}
    if formulation == "unified":
        extra["admittance_share"] = SHARE
    if kind in ("pd", "sf", "of"):
        extra.update({k: v for k, v in rule.items() if learn or k not in LEARN_KEYS})
    elif "Md" in rule:  # the scenario's target inertia (SPEC (19.8)), whatever the joint law
        extra["Md"] = rule["Md"]
    return panda_controller(kind, sc, force_feedforward=ff, formulation=formulation, **extra)


def run_row(
    name: str,
    sc: PandaTable,
    rule: dict[str, Any],
    T: float,
    *,
    progress: Callable[[int, int], object] | None = None,
) -> tuple[Any, Any, dict[str, float]]:
    """One row of the table on the scenario: (result, controller, metrics of
    :func:`contact_metrics` over t ≥ min(2 s, T/2)); ``progress(done,
    total)`` as :func:`adaptimp.mujoco.simulate` calls it."""
    from .. import mujoco as amj

    ctrl = row_controller(name, sc, rule)
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=T, q0=sc.q0, progress=progress or False)
    return res, ctrl, contact_metrics(res, ctrl, sc, settle=min(2.0, T / 2))
