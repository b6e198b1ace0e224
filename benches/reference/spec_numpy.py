"""Plain NumPy reference implementation of the adaptimp SPEC, §1-§12.

Written the way a competent Python user would write it from ``SPEC.md``:
readable, vectorised within a controller step, and a Python ``for`` loop over
time steps.  It is an independent cross-check for the Rust crate and the
"what a Python user would write" baseline for speed comparisons.

Units: angles (joint positions) in rad, velocities in rad/s, accelerations in
rad/s², torques in N m, time in s.  n = 2 joints (the paper's arm).

Conventions shared with ``spec_numba.py`` (and expected of the Rust crate):

* network input ``Z = [x, v, alpha1, dalpha1]`` (length 4n), with ``v`` the
  measured velocity (``"pd"``, ``"sf"``) or the observer estimate ``pi2/eps``
  (``"of"``);
* node ``j`` (0-based) has centre ``mu_j[d] = +1`` if ``(j >> d) & 1`` else
  ``-1``; ``S_j = exp(-||Z - mu_j||² / eta2)``;
* weights ``WD[k, j, i]``, ``WC[k, j, i]`` (shape (n, n, l)) and ``WG[k, i]``
  (shape (n, l)), updated by explicit Euler after the step's output has been
  computed with the old weights.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

CASES = ("pd", "sf", "of")
AUX_LAWS = ("default", "printed")
N_JOINTS = 2

# Keys whose value is one number per joint (scalars are broadcast).
_PER_JOINT = ("q0", "dq0", "Kp", "K1", "Kzeta", "lam1", "tau_max", "Dd", "Cd", "Gd")
# Keys whose value is one number per network, ordered (D, C, G).
_PER_NETWORK = ("gamma", "sigma")


# --------------------------------------------------------------------------
# Parameters, SPEC §1-§11 defaults and §10 validation
# --------------------------------------------------------------------------
def default_params(case: str = "sf") -> dict:
    """Paper-scenario defaults of SPEC §11 for ``case`` in ``("pd", "sf", "of")``.

    Keys and units:

    * ``T`` run length (s); ``Ts`` controller period (s); ``substeps`` RK4
      substeps per period (-);
    * ``q0`` (rad), ``dq0`` (rad/s): initial joint state, shape (n,);
    * ``Kp`` (N m s/rad), ``K1`` (1/s), ``Kzeta`` (1/s): diagonal gains, (n,);
    * ``mu`` auxiliary-law threshold on ||ζ|| (N m);
    * ``gamma`` adaptation gains Γ and ``sigma`` σ-modification (-), a scalar
      or one value per network in the order (D, C, G);
    * ``eta2`` RBF width η² (-); ``kr`` robust gain (N m);
    * ``eps`` observer ε (s); ``lam1`` observer λ1 (-), (n,);
    * ``tau_max`` actuator limits (N m), (n,);
    * ``Dd`` (kg m², i.e. N m s²/rad), ``Cd`` (N m s/rad), ``Gd`` (N m/rad):
      target impedance, (n,);
    * ``wall`` wall position on joint 1 (rad), ``ke`` stiffness (N m/rad),
      ``be`` damping (N m s/rad);
    * ``m1``, ``m2`` (kg), ``l1``, ``l2`` (m), ``g`` (m/s²): the arm of SPEC §1;
    * ``aux_law``: ``"default"`` (ζ̇ = -Kζ ζ + Δτ when ||ζ|| < μ) or
      ``"printed"`` (ζ̇ = 0 when ||ζ|| < μ).
    """
    if case not in CASES:
        raise ValueError(f"case must be one of {CASES}, got {case!r}")
    return {
        "T": 20.0,
        "Ts": 50e-6,
        "substeps": 1,
        "q0": np.array([0.25, -0.05]),
        "dq0": np.array([0.0, 0.0]),
        "Kp": np.array([10.0, 10.0]),
        "K1": np.array([6.0, 6.0]),
        "Kzeta": np.array([60.0, 60.0]),
        "mu": 0.01,
        "gamma": 100.0,
        "sigma": 0.01,
        "eta2": 25.0,
        "kr": 0.5,
        "eps": 1e-4,
        "lam1": np.array([3.0, 3.0]),
        "tau_max": np.array([17.0, 15.0]),
        "Dd": np.array([1.0, 1.0]),
        "Cd": np.array([10.0, 10.0]),
        "Gd": np.array([60.0, 60.0]),
        "wall": 0.2,
        "ke": 1000.0,
        "be": 10.0,
        "m1": 2.0,
        "m2": 0.85,
        "l1": 0.35,
        "l2": 0.31,
        "g": 9.81,
        "aux_law": "default",
    }


def make_params(case: str, **overrides) -> dict:
    """Defaults of ``case`` updated with ``overrides``, normalised and validated (SPEC §10).

    Per-joint quantities become float arrays of shape (n,), ``gamma`` and
    ``sigma`` arrays of shape (3,) in the order (D, C, G).  Raises
    ``TypeError`` on an unknown key and ``ValueError`` naming the violated
    condition otherwise.
    """
    p = default_params(case)
    unknown = set(overrides) - set(p)
    if unknown:
        raise TypeError(f"unknown parameter(s): {sorted(unknown)}")
    p.update(overrides)
    for key in _PER_JOINT:
        p[key] = np.array(np.broadcast_to(np.asarray(p[key], dtype=float), (N_JOINTS,)))
    for key in _PER_NETWORK:
        p[key] = np.array(np.broadcast_to(np.asarray(p[key], dtype=float), (3,)))
    for key, value in p.items():
        if key in ("aux_law", "substeps"):
            continue
        if key not in _PER_JOINT and key not in _PER_NETWORK:
            p[key] = float(value)
        if not np.all(np.isfinite(p[key])):
            raise ValueError(f"{key} must be finite, got {p[key]}")
    p["substeps"] = int(p["substeps"])
    _validate(p)
    return p


def _validate(p: dict) -> None:
    """SPEC §10 stability conditions (all gains diagonal)."""
    checks = [
        ("K1 > 0", p["K1"]),
        ("2Kp - I > 0", 2.0 * p["Kp"] - 1.0),
        ("2Kzeta - I - Kp^T Kp > 0", 2.0 * p["Kzeta"] - 1.0 - p["Kp"] ** 2),
        ("gamma > 0", p["gamma"]),
        ("sigma > 0", p["sigma"]),
        ("eta2 > 0", p["eta2"]),
        ("eps > 0", p["eps"]),
        ("lam1 > 0", p["lam1"]),
        ("mu > 0", p["mu"]),
        ("tau_max > 0", p["tau_max"]),
        ("Dd > 0", p["Dd"]),
        ("Ts > 0", p["Ts"]),
        ("T > 0", p["T"]),
    ]
    for condition, value in checks:
        if not np.all(np.asarray(value) > 0.0):
            raise ValueError(f"stability condition violated: {condition} (value {value})")
    if p["substeps"] < 1:
        raise ValueError(f"substeps must be >= 1, got {p['substeps']}")
    if p["aux_law"] not in AUX_LAWS:
        raise ValueError(f"aux_law must be one of {AUX_LAWS}, got {p['aux_law']!r}")


# --------------------------------------------------------------------------
# Plant (SPEC §1), wall (§3), commanded trajectory (§4)
# --------------------------------------------------------------------------
def arm_coefficients(p: dict) -> np.ndarray:
    """p1..p5 of SPEC §1 (kg m², kg m², kg m², kg m, kg m), with the (62) erratum."""
    m1, m2, l1, l2 = p["m1"], p["m2"], p["l1"], p["l2"]
    lc1, lc2 = l1 / 2.0, l2 / 2.0
    i1, i2 = m1 * l1**2 / 4.0, m2 * l2**2 / 4.0
    return np.array(
        [
            m1 * lc1**2 + m2 * l1**2 + i1,
            m2 * lc2**2 + i2,
            m2 * l1 * lc2,
            m1 * lc1 + m2 * l1,
            m2 * lc2,
        ]
    )


def arm_matrices(q: np.ndarray, dq: np.ndarray, pc: np.ndarray, g: float):
    """D(q) (kg m²), C(q, q̇) (kg m²/s) and G(q) (N m) of SPEC §1."""
    p1, p2, p3, p4, p5 = pc
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    D = np.array([[p1 + p2 + 2.0 * p3 * c2, p2 + p3 * c2], [p2 + p3 * c2, p2]])
    C = np.array([[-p3 * dq[1] * s2, -p3 * (dq[0] + dq[1]) * s2], [p3 * dq[0] * s2, 0.0]])
    c12 = np.cos(q[0] + q[1])
    G = np.array([p4 * g * np.cos(q[0]) + p5 * g * c12, p5 * g * c12])
    return D, C, G


def plant_accel(q, dq, tau_s, tau_e, pc, g) -> np.ndarray:
    """Joint acceleration (rad/s²) from D q̈ + C q̇ + G = sat(τ) - τe (SPEC §1)."""
    D, C, G = arm_matrices(q, dq, pc, g)
    return np.linalg.solve(D, tau_s - tau_e - C @ dq - G)


def wall_force(q, dq, wall: float, ke: float, be: float) -> np.ndarray:
    """τe (N m) of the penalty wall on joint 1 (SPEC §3): [f, 0]."""
    tau_e = np.zeros(N_JOINTS)
    delta = q[0] - wall
    if delta > 0.0:
        tau_e[0] = max(0.0, ke * delta + be * dq[0])
    return tau_e


def commanded(t):
    """xc (rad), ẋc (rad/s), ẍc (rad/s²) of (64) at time ``t`` (s; scalar or array)."""
    a, w = 0.2, np.pi
    s, c = np.sin(w * t), np.cos(w * t)
    xc = np.array([a - a * c, a + a * s])
    dxc = np.array([a * w * s, a * w * c])
    ddxc = np.array([a * w * w * c, -(a * w * w) * s])
    return xc, dxc, ddxc


def rk4_step(q, dq, tau_s, h, p, pc):
    """One classical RK4 step of length ``h`` (s) with τs held and τe recomputed per stage."""

    def f(qq, vv):
        tau_e = wall_force(qq, vv, p["wall"], p["ke"], p["be"])
        return vv, plant_accel(qq, vv, tau_s, tau_e, pc, p["g"])

    k1q, k1v = f(q, dq)
    k2q, k2v = f(q + 0.5 * h * k1q, dq + 0.5 * h * k1v)
    k3q, k3v = f(q + 0.5 * h * k2q, dq + 0.5 * h * k2v)
    k4q, k4v = f(q + h * k3q, dq + h * k3v)
    q_new = q + (h / 6.0) * (k1q + 2.0 * k2q + 2.0 * k3q + k4q)
    dq_new = dq + (h / 6.0) * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
    return q_new, dq_new


# --------------------------------------------------------------------------
# Observer (SPEC §9) and RBF grid (§6)
# --------------------------------------------------------------------------
def observer_zoh(eps: float, lam1: np.ndarray, Ts: float):
    """Exact ZOH discretisation of the high-gain observer, per joint (SPEC §11 step 5).

    Returns ``Phi`` (n, 2, 2) and ``Gam`` (n, 2) such that
    ``pi[j] <- Phi[j] @ pi[j] + Gam[j] * x[j]``; computed from
    ``expm([[A, B], [0, 0]] * Ts)`` with ``A = [[0, 1], [-1, -lam1]] / eps``,
    ``B = [0, 1] / eps``.
    """
    n = len(lam1)
    Phi = np.empty((n, 2, 2))
    Gam = np.empty((n, 2))
    for j in range(n):
        M = np.zeros((3, 3))
        M[:2, :2] = np.array([[0.0, 1.0], [-1.0, -lam1[j]]]) / eps
        M[:2, 2] = np.array([0.0, 1.0]) / eps
        E = expm(M * Ts)
        Phi[j] = E[:2, :2]
        Gam[j] = E[:2, 2]
    return Phi, Gam


def rbf_centers(n: int) -> np.ndarray:
    """The 2^(4n) x 4n grid of centres: ``mu[j, d] = +1 if (j >> d) & 1 else -1``."""
    dims = 4 * n
    j = np.arange(2**dims)[:, None]
    d = np.arange(dims)[None, :]
    return np.where((j >> d) & 1, 1.0, -1.0)


# --------------------------------------------------------------------------
# Controller (SPEC §4-§9, one step of §11)
# --------------------------------------------------------------------------
class Controller:
    """Discrete-time impedance controller of SPEC §11 for ``case`` in ("pd", "sf", "of").

    ``step(q, tau_e, dq=None)`` runs one period at t_k = k·Ts (own clock from
    k = 0) and returns the applied torque sat(τ) (N m).  After a step:

    * ``tau``, ``tau_sat``, ``dtau`` (N m): commanded τ, sat(τ), Δτ = sat(τ) - τ;
    * ``z1`` (rad), ``z2`` (rad/s; ẑ2 for "of"), ``dq_hat`` (rad/s, the
      velocity used), ``zeta`` (N m), ``xd`` (rad): the values *at t_k* used
      by this step (what the simulator records);
    * ``w_norms``: Frobenius norms of (WD, WC, WG) before this step's update;
    * ``xd_next``, ``dxd_next``, ``zeta_next``, ``pi_next``: internal state
      advanced to t_{k+1};
    * ``weights``: ``{"D": WD, "C": WC, "G": WG}``, the live weight arrays,
      already updated to t_{k+1}.
    """

    def __init__(self, case: str = "sf", **params):
        self.case = case
        self.p = make_params(case, **params)
        self.n = N_JOINTS
        self.centers = rbf_centers(self.n)
        self.n_nodes = self.centers.shape[0]
        self.Phi, self.Gam = observer_zoh(self.p["eps"], self.p["lam1"], self.p["Ts"])
        self.reset()

    def reset(self) -> None:
        """Back to t = 0: xd = xc(0), ẋd = ẋc(0), ζ = 0, π = 0, weights = 0."""
        n, nl = self.n, self.n_nodes
        self.k = 0
        xc, dxc, _ = commanded(0.0)
        self.xd_next = xc.copy()
        self.dxd_next = dxc.copy()
        self.zeta_next = np.zeros(n)
        self.pi_next = np.zeros((n, 2))
        self.weights = {
            "D": np.zeros((n, n, nl)),
            "C": np.zeros((n, n, nl)),
            "G": np.zeros((n, nl)),
        }
        self.w_norms = np.zeros(3)
        self.tau = np.zeros(n)
        self.tau_sat = np.zeros(n)
        self.dtau = np.zeros(n)
        self.z1 = np.zeros(n)
        self.z2 = np.zeros(n)
        self.dq_hat = np.zeros(n)
        self.zeta = self.zeta_next.copy()
        self.xd = self.xd_next.copy()

    def step(self, q, tau_e, dq=None) -> np.ndarray:
        """One controller period (SPEC §11 steps 1-5).

        q: measured joint position x_k (rad), shape (n,).
        tau_e: measured interaction torque τe_k (N m), shape (n,).
        dq: measured joint velocity (rad/s), required for "pd" and "sf",
            ignored for "of" (which uses its observer).
        Returns sat(τ) (N m), shape (n,).
        """
        p = self.p
        Ts = p["Ts"]
        t = self.k * Ts
        x = np.asarray(q, dtype=float)
        tau_e = np.asarray(tau_e, dtype=float)
        xd, dxd, zeta = self.xd_next, self.dxd_next, self.zeta_next

        # 1. commanded trajectory and impedance reference model (§4)
        xc, dxc, ddxc = commanded(t)
        ddxd = ddxc + (p["Cd"] * (dxc - dxd) + p["Gd"] * (xc - xd) - tau_e) / p["Dd"]

        # 2. velocity: measured, or the high-gain observer estimate (§9)
        if self.case == "of":
            v = self.pi_next[:, 1] / p["eps"]
        else:
            if dq is None:
                raise ValueError(f"case {self.case!r} needs the measured velocity dq")
            v = np.asarray(dq, dtype=float)

        # 3. errors (§5)
        z1 = xd - x
        alpha1 = dxd + p["K1"] * z1
        z2 = alpha1 - v
        dalpha1 = ddxd + p["K1"] * (dxd - v)

        # 4. control law (§7) and saturation (§2)
        robust = p["kr"] * np.sign(z2)
        if self.case == "pd":
            tau = p["Kp"] * (z2 + zeta) + robust
        else:
            Z = np.concatenate([x, v, alpha1, dalpha1])
            S = np.exp(-((Z - self.centers) ** 2).sum(axis=1) / p["eta2"])
            WD, WC, WG = self.weights["D"], self.weights["C"], self.weights["G"]
            D_hat = np.einsum("kji,i,j->k", WD, S, dalpha1)
            C_hat = np.einsum("kji,i,j->k", WC, S, alpha1)
            G_hat = WG @ S
            tau = z1 + D_hat + C_hat + G_hat + p["Kp"] * (z2 + zeta) + robust + tau_e
        tau_sat = np.clip(tau, -p["tau_max"], p["tau_max"])
        dtau = tau_sat - tau

        # 5. advance the internal state to t_{k+1}
        self.w_norms = np.array([np.linalg.norm(self.weights[name]) for name in "DCG"])
        if self.case != "pd":  # weights (15)-(17)/(37)-(39), explicit Euler
            gD, gC, gG = p["gamma"]
            sD, sC, sG = p["sigma"]
            WD += Ts * gD * (np.einsum("k,j,i->kji", z2, dalpha1, S) - sD * WD)
            WC += Ts * gC * (np.einsum("k,j,i->kji", z2, alpha1, S) - sC * WC)
            WG += Ts * gG * (np.outer(z2, S) - sG * WG)

        zeta_norm2 = zeta @ zeta  # auxiliary system (11), semi-implicit
        inside = np.sqrt(zeta_norm2) < p["mu"]
        if inside and p["aux_law"] == "printed":
            zeta_new = zeta.copy()  # printed inner law: dzeta/dt = 0
        else:
            beta = 0.0 if inside else (abs(z2 @ dtau) + 0.5 * (dtau @ dtau)) / zeta_norm2
            zeta_new = (zeta + Ts * dtau) / (1.0 + Ts * (p["Kzeta"] + beta))

        dxd_new = dxd + Ts * ddxd  # reference model, then position with the new ẋd
        xd_new = xd + Ts * dxd_new

        if self.case == "of":  # observer, exact ZOH with x_k held
            self.pi_next = np.einsum("jab,jb->ja", self.Phi, self.pi_next) + self.Gam * x[:, None]

        # expose the step's values, store the advanced state
        self.tau, self.tau_sat, self.dtau = tau, tau_sat, dtau
        self.z1, self.z2, self.dq_hat, self.zeta, self.xd = z1, z2, v, zeta, xd
        self.xd_next, self.dxd_next, self.zeta_next = xd_new, dxd_new, zeta_new
        self.k += 1
        return tau_sat


# --------------------------------------------------------------------------
# Simulator (SPEC §11) and metrics (§12)
# --------------------------------------------------------------------------
def simulate(case: str = "sf", **params) -> dict:
    """Closed-loop run of SPEC §11; returns recorded rows k = 0..K-1 and §12 metrics.

    Arrays: ``t`` (K,) s; ``q``, ``xc``, ``xd`` (K, n) rad; ``dq``, ``dq_hat``
    (K, n) rad/s; ``tau``, ``tau_sat``, ``tau_e``, ``zeta`` (K, n) N m; ``z1``
    (K, n) rad; ``w_norms`` (K, 3) Frobenius norms of WD, WC, WG before the
    step's update.  ``metrics``: see :func:`compute_metrics`.
    """
    ctrl = Controller(case, **params)
    p = ctrl.p
    pc = arm_coefficients(p)
    n = ctrl.n
    Ts = p["Ts"]
    K = round(p["T"] / Ts)
    h = Ts / p["substeps"]

    rec = {"t": np.arange(K) * Ts}
    for key in (
        "q",
        "dq",
        "xc",
        "xd",
        "dq_hat",
        "tau",
        "tau_sat",
        "tau_e",
        "zeta",
        "z1",
    ):
        rec[key] = np.zeros((K, n))
    rec["w_norms"] = np.zeros((K, 3))

    q, dq = p["q0"].copy(), p["dq0"].copy()
    for k in range(K):
        t = k * Ts
        tau_e = wall_force(q, dq, p["wall"], p["ke"], p["be"])
        tau_sat = ctrl.step(q, tau_e, dq)

        rec["q"][k], rec["dq"][k] = q, dq
        rec["xc"][k] = commanded(t)[0]
        rec["xd"][k], rec["dq_hat"][k] = ctrl.xd, ctrl.dq_hat
        rec["tau"][k], rec["tau_sat"][k], rec["tau_e"][k] = ctrl.tau, tau_sat, tau_e
        rec["zeta"][k], rec["z1"][k] = ctrl.zeta, ctrl.z1
        rec["w_norms"][k] = ctrl.w_norms

        for _ in range(p["substeps"]):
            q, dq = rk4_step(q, dq, tau_sat, h, p, pc)

    rec["metrics"] = compute_metrics(rec, p)
    return rec


def compute_metrics(rec: dict, p: dict) -> dict:
    """SPEC §12 figures over the recorded rows; "after2" means t_k >= 2 s - 1e-9.

    * ``rms_z1``, ``rms_z1_after2`` (rad): sqrt(mean ||z1||²);
    * ``rms_z1_joint_after2``, ``max_abs_z1_joint_after2`` (rad), shape (n,);
    * ``sat_duty`` (-): fraction of rows with any Δτ_i ≠ 0;
    * ``steps_in_contact`` (-): rows with τe ≠ 0;
    * ``peak_contact_after2``, ``mean_contact`` (N m): of |τe| = f, the peak
      over t ≥ 2 s and the mean over contact rows (0 when there are none);
    * ``peak_abs_tau`` (N m), shape (n,): max |τ_i| of the commanded torque;
    * ``imp_err_rms_after2`` (N m): RMS over t ≥ 2 s of
      ||Dd(ẍc - ẍ) + Cd(ẋc - ẋ) + Gd(xc - x) - τe||, ẍ the plant acceleration
      at the row's state with that row's sat(τ) and τe.
    """
    t, z1 = rec["t"], rec["z1"]
    after = t >= 2.0 - 1e-9
    e2 = (z1**2).sum(axis=1)
    contact = np.any(rec["tau_e"] != 0.0, axis=1)
    f = np.linalg.norm(rec["tau_e"], axis=1)

    q, dq = rec["q"][after], rec["dq"][after]
    pc = arm_coefficients(p)
    c2, s2 = np.cos(q[:, 1]), np.sin(q[:, 1])
    D = np.empty((len(q), 2, 2))
    D[:, 0, 0] = pc[0] + pc[1] + 2.0 * pc[2] * c2
    D[:, 0, 1] = D[:, 1, 0] = pc[1] + pc[2] * c2
    D[:, 1, 1] = pc[1]
    Cdq = np.stack(
        [
            -pc[2] * dq[:, 1] * s2 * dq[:, 0] + -pc[2] * (dq[:, 0] + dq[:, 1]) * s2 * dq[:, 1],
            pc[2] * dq[:, 0] * s2 * dq[:, 0],
        ],
        axis=1,
    )
    c12 = np.cos(q[:, 0] + q[:, 1])
    G = np.stack(
        [pc[3] * p["g"] * np.cos(q[:, 0]) + pc[4] * p["g"] * c12, pc[4] * p["g"] * c12],
        axis=1,
    )
    tau_e = rec["tau_e"][after]
    rhs = rec["tau_sat"][after] - tau_e - Cdq - G
    ddq = np.linalg.solve(D, rhs[..., None])[..., 0]
    xc, dxc, ddxc = (a.T for a in commanded(t[after]))
    imp = p["Dd"] * (ddxc - ddq) + p["Cd"] * (dxc - dq) + p["Gd"] * (xc - q) - tau_e
    imp2 = (imp**2).sum(axis=1)

    def _rms(a, axis=None):
        if a.shape[0] == 0:  # no rows (e.g. T <= 2 s for the "after2" figures)
            return np.full(a.shape[1:], np.nan) if axis is not None else float("nan")
        out = np.sqrt(np.mean(a, axis=axis))
        return out if axis is not None else float(out)

    n = z1.shape[1]
    return {
        "rms_z1": _rms(e2),
        "rms_z1_after2": _rms(e2[after]),
        "rms_z1_joint_after2": _rms(z1[after] ** 2, axis=0),
        "max_abs_z1_joint_after2": np.abs(z1[after]).max(axis=0)
        if after.any()
        else np.full(n, np.nan),
        "sat_duty": float(np.mean(np.any(rec["tau_sat"] != rec["tau"], axis=1))),
        "steps_in_contact": int(contact.sum()),
        "peak_contact_after2": float(f[after].max()) if after.any() else 0.0,
        "mean_contact": float(f[contact].mean()) if contact.any() else 0.0,
        "peak_abs_tau": np.abs(rec["tau"]).max(axis=0),
        "imp_err_rms_after2": _rms(imp2),
    }
