"""numba-compiled reference implementation of the adaptimp SPEC, §1-§12.

The same maths as ``spec_numpy.py``, written for speed the way a good numba
user would: explicit loops, preallocated arrays, no temporaries in the step,
and the whole closed-loop scenario inside one ``@njit`` function.  The
network outputs, the weight update and the weight norms share one pass over
the weights (outputs use the old weights, as the SPEC requires).
``Controller.replay`` steps through K logged measurements inside one jitted
loop, the counterpart of ``adaptimp.Controller.replay`` in
``benches/compare.py``.

Units: rad, rad/s, rad/s², N m, s.  n = 2 joints.  Conventions (network
input, centre ordering, weight layouts) are those of ``spec_numpy.py``.
Parameter handling, the observer discretisation and the §12 metrics are not
hot code and are shared with ``spec_numpy.py``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

try:  # imported as part of a package, or with this folder on sys.path
    from . import spec_numpy as _np_ref
except ImportError:
    import spec_numpy as _np_ref

CASES = _np_ref.CASES
N_JOINTS = _np_ref.N_JOINTS
default_params = _np_ref.default_params
make_params = _np_ref.make_params
compute_metrics = _np_ref.compute_metrics

_CASE_CODE = {"pd": 0, "sf": 1, "of": 2}
_AUX_CODE = {"default": 0, "printed": 1}

# Layout of the packed float vectors handed to the jitted code.
# cfg:   Ts, mu, eta2, kr, eps, gammaD, gammaC, gammaG, sigmaD, sigmaC, sigmaG
# gains: rows Kp, K1, Kzeta, tau_max, Dd, Cd, Gd (each (n,))
# plant: p1..p5, g, wall, ke, be
# out:   rows tau, tau_sat, dtau, z1, dq_hat, zeta (at t_k), xd (at t_k), z2,
#        and a scratch row for the network output
_OUT_ROWS = ("tau", "tau_sat", "dtau", "z1", "dq_hat", "zeta", "xd", "z2")


def _pack(p: dict):
    """Packed (cfg, gains, plant) float arrays for the jitted functions."""
    cfg = np.array([p["Ts"], p["mu"], p["eta2"], p["kr"], p["eps"], *p["gamma"], *p["sigma"]])
    gains = np.stack([p[k] for k in ("Kp", "K1", "Kzeta", "tau_max", "Dd", "Cd", "Gd")])
    plant = np.array([*_np_ref.arm_coefficients(p), p["g"], p["wall"], p["ke"], p["be"]])
    return cfg, gains, plant


# --------------------------------------------------------------------------
# Jitted kernels
# --------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _sgn(a):
    """sgn with sgn(0) = 0."""
    if a > 0.0:
        return 1.0
    if a < 0.0:
        return -1.0
    return 0.0


@njit(cache=True)
def _wall_force(q0, dq0, plant):
    """f (N m) of the penalty wall on joint 1 (SPEC §3)."""
    delta = q0 - plant[6]
    if delta > 0.0:
        return max(0.0, plant[7] * delta + plant[8] * dq0)
    return 0.0


@njit(cache=True)
def _accel(q, dq, tau_s, f, plant, ddq):
    """Writes q̈ (rad/s²) of SPEC §1 into ``ddq``; τe = [f, 0] (N m)."""
    p1, p2, p3, p4, p5, g = plant[0], plant[1], plant[2], plant[3], plant[4], plant[5]
    c2 = np.cos(q[1])
    s2 = np.sin(q[1])
    d11 = p1 + p2 + 2.0 * p3 * c2
    d12 = p2 + p3 * c2
    d22 = p2
    cdq0 = -p3 * dq[1] * s2 * dq[0] + -p3 * (dq[0] + dq[1]) * s2 * dq[1]
    cdq1 = p3 * dq[0] * s2 * dq[0]
    c12 = np.cos(q[0] + q[1])
    g0 = p4 * g * np.cos(q[0]) + p5 * g * c12
    g1 = p5 * g * c12
    r0 = tau_s[0] - f - cdq0 - g0
    r1 = tau_s[1] - 0.0 - cdq1 - g1
    det = d11 * d22 - d12 * d12
    ddq[0] = (d22 * r0 - d12 * r1) / det
    ddq[1] = (d11 * r1 - d12 * r0) / det


@njit(cache=True)
def _rk4(q, dq, tau_s, h, plant, work):
    """One RK4 step of length h (s), in place, τe recomputed at every stage."""
    qs, vs = work[0], work[1]
    k1v, k2v, k3v, k4v = work[2], work[3], work[4], work[5]
    k1q, k2q, k3q, k4q = work[6], work[7], work[8], work[9]
    for i in range(2):
        k1q[i] = dq[i]
    _accel(q, dq, tau_s, _wall_force(q[0], dq[0], plant), plant, k1v)
    for i in range(2):
        qs[i] = q[i] + 0.5 * h * k1q[i]
        vs[i] = dq[i] + 0.5 * h * k1v[i]
        k2q[i] = vs[i]
    _accel(qs, vs, tau_s, _wall_force(qs[0], vs[0], plant), plant, k2v)
    for i in range(2):
        qs[i] = q[i] + 0.5 * h * k2q[i]
        vs[i] = dq[i] + 0.5 * h * k2v[i]
        k3q[i] = vs[i]
    _accel(qs, vs, tau_s, _wall_force(qs[0], vs[0], plant), plant, k3v)
    for i in range(2):
        qs[i] = q[i] + h * k3q[i]
        vs[i] = dq[i] + h * k3v[i]
        k4q[i] = vs[i]
    _accel(qs, vs, tau_s, _wall_force(qs[0], vs[0], plant), plant, k4v)
    for i in range(2):
        q[i] = q[i] + (h / 6.0) * (k1q[i] + 2.0 * k2q[i] + 2.0 * k3q[i] + k4q[i])
        dq[i] = dq[i] + (h / 6.0) * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i])


@njit(cache=True)
def _rbf(Z, centers, eta2, S):
    """S_j = exp(-||Z - mu_j||² / eta2) for every node j (SPEC §6), into ``S``."""
    for j in range(centers.shape[0]):
        d2 = 0.0
        for d in range(Z.shape[0]):
            e = Z[d] - centers[j, d]
            d2 += e * e
        S[j] = np.exp(-d2 / eta2)


# Reassociation lets LLVM vectorise the 256-long dot products; it changes
# results only at the rounding level (the sums are reordered).
@njit(cache=True, fastmath={"reassoc", "nsz"})
def _network(WD, WC, WG, S, alpha1, dalpha1, z2, cfg, hat, wnorm):
    """One fused pass over the weights (SPEC §6, update laws (15)-(17)).

    hat[k] = (D̂ α̇1)_k + (Ĉ α1)_k + Ĝ_k (N m) with the old weights; wnorm gets
    the Frobenius norms of WD, WC, WG before the update; then every weight
    takes one explicit Euler step W <- W + Ts Γ (S_i u_j z2_k - σ W).
    """
    n = z2.shape[0]
    nl = S.shape[0]
    Ts = cfg[0]
    gD, gC, gG, sD, sC, sG = cfg[5], cfg[6], cfg[7], cfg[8], cfg[9], cfg[10]
    nD = 0.0
    nC = 0.0
    nG = 0.0
    for kk in range(n):
        z2k = z2[kk]
        acc = 0.0
        for jj in range(n):
            uD = dalpha1[jj]
            uC = alpha1[jj]
            rD = 0.0
            rC = 0.0
            for i in range(nl):
                wd = WD[kk, jj, i]
                wc = WC[kk, jj, i]
                rD += wd * S[i]
                rC += wc * S[i]
                nD += wd * wd
                nC += wc * wc
                WD[kk, jj, i] = wd + Ts * gD * (S[i] * uD * z2k - sD * wd)
                WC[kk, jj, i] = wc + Ts * gC * (S[i] * uC * z2k - sC * wc)
            acc += rD * uD + rC * uC
        rG = 0.0
        for i in range(nl):
            wg = WG[kk, i]
            rG += wg * S[i]
            nG += wg * wg
            WG[kk, i] = wg + Ts * gG * (S[i] * z2k - sG * wg)
        hat[kk] = acc + rG
    wnorm[0] = np.sqrt(nD)
    wnorm[1] = np.sqrt(nC)
    wnorm[2] = np.sqrt(nG)


@njit(cache=True)
def _step(
    case,
    aux,
    k,
    x,
    dq,
    tau_e,
    cfg,
    gains,
    centers,
    phi,
    gam,
    xd,
    dxd,
    zeta,
    pi,
    WD,
    WC,
    WG,
    S,
    Z,
    out,
    wnorm,
):
    """One controller period at t_k = k·Ts (SPEC §11 steps 1-5), in place.

    Reads x (rad), dq (rad/s; unused for "of"), tau_e (N m); advances xd,
    dxd, zeta, pi and the weights to t_{k+1}; writes the step's values into
    ``out`` (rows ``_OUT_ROWS``) and the pre-update weight norms into ``wnorm``.
    """
    n = x.shape[0]
    Ts, mu, kr, eps = cfg[0], cfg[1], cfg[3], cfg[4]
    tau, tau_s, dtau, z1 = out[0], out[1], out[2], out[3]
    v, zeta_k, xd_k, z2, hat = out[4], out[5], out[6], out[7], out[8]

    # 1. commanded trajectory (64) and reference model (§4)
    t = k * Ts
    a = 0.2
    w = np.pi
    s = np.sin(w * t)
    c = np.cos(w * t)
    xc0, xc1 = a - a * c, a + a * s
    dxc0, dxc1 = a * w * s, a * w * c
    ddxc0, ddxc1 = a * w * w * c, -(a * w * w) * s
    ddxd0 = (
        ddxc0
        + (gains[5, 0] * (dxc0 - dxd[0]) + gains[6, 0] * (xc0 - xd[0]) - tau_e[0]) / gains[4, 0]
    )
    ddxd1 = (
        ddxc1
        + (gains[5, 1] * (dxc1 - dxd[1]) + gains[6, 1] * (xc1 - xd[1]) - tau_e[1]) / gains[4, 1]
    )

    # 2.-3. velocity (measured or observer) and errors (§5)
    for i in range(n):
        if case == 2:
            v[i] = pi[i, 1] / eps
        else:
            v[i] = dq[i]
    alpha1 = Z[2 * n : 3 * n]
    dalpha1 = Z[3 * n : 4 * n]
    for i in range(n):
        ddxd_i = ddxd0 if i == 0 else ddxd1
        z1[i] = xd[i] - x[i]
        alpha1[i] = dxd[i] + gains[1, i] * z1[i]
        dalpha1[i] = ddxd_i + gains[1, i] * (dxd[i] - v[i])
        Z[i] = x[i]
        Z[n + i] = v[i]
        zeta_k[i] = zeta[i]
        xd_k[i] = xd[i]

    # 4. control law (§7); network outputs use the old weights (§6)
    for kk in range(n):
        z2[kk] = alpha1[kk] - v[kk]
        tau[kk] = gains[0, kk] * (z2[kk] + zeta[kk]) + kr * _sgn(z2[kk])
    if case != 0:
        _rbf(Z, centers, cfg[2], S)
        _network(WD, WC, WG, S, alpha1, dalpha1, z2, cfg, hat, wnorm)
        for kk in range(n):
            tau[kk] += z1[kk] + hat[kk] + tau_e[kk]
    else:
        wnorm[0] = 0.0
        wnorm[1] = 0.0
        wnorm[2] = 0.0

    # saturation (§2)
    for i in range(n):
        tau_s[i] = min(max(tau[i], -gains[3, i]), gains[3, i])
        dtau[i] = tau_s[i] - tau[i]

    # 5. auxiliary system (11), semi-implicit
    zz = 0.0
    z2dt = 0.0
    dtdt = 0.0
    for i in range(n):
        zz += zeta[i] * zeta[i]
        z2dt += z2[i] * dtau[i]
        dtdt += dtau[i] * dtau[i]
    inside = np.sqrt(zz) < mu
    if not (inside and aux == 1):
        beta = 0.0 if inside else (abs(z2dt) + 0.5 * dtdt) / zz
        for i in range(n):
            zeta[i] = (zeta[i] + Ts * dtau[i]) / (1.0 + Ts * (gains[2, i] + beta))

    # reference model: velocity first, then position with the new velocity
    dxd[0] = dxd[0] + Ts * ddxd0
    dxd[1] = dxd[1] + Ts * ddxd1
    for i in range(n):
        xd[i] = xd[i] + Ts * dxd[i]

    # observer, exact ZOH with x_k held
    if case == 2:
        for i in range(n):
            p1 = pi[i, 0]
            p2 = pi[i, 1]
            pi[i, 0] = phi[i, 0, 0] * p1 + phi[i, 0, 1] * p2 + gam[i, 0] * x[i]
            pi[i, 1] = phi[i, 1, 0] * p1 + phi[i, 1, 1] * p2 + gam[i, 1] * x[i]


@njit(cache=True)
def _replay(
    case,
    aux,
    k0,
    q,
    dq,
    tau_e,
    cfg,
    gains,
    centers,
    phi,
    gam,
    xd,
    dxd,
    zeta,
    pi,
    WD,
    WC,
    WG,
    S,
    Z,
    out,
    wnorm,
    tau_sat,
):
    """K controller periods on logged measurements, all inside one jitted loop.

    Row k of q (rad), dq (rad/s; unused for "of") and tau_e (N m), each (K, n),
    is step k0 + k of ``_step`` (the same maths, no Python per step); the
    applied torques sat(τ) (N m) go to the rows of ``tau_sat`` (K, n).  The
    state arrays and ``out``/``wnorm`` end as after the last step.
    """
    n = q.shape[1]
    for k in range(q.shape[0]):
        _step(
            case,
            aux,
            k0 + k,
            q[k],
            dq[k],
            tau_e[k],
            cfg,
            gains,
            centers,
            phi,
            gam,
            xd,
            dxd,
            zeta,
            pi,
            WD,
            WC,
            WG,
            S,
            Z,
            out,
            wnorm,
        )
        for i in range(n):
            tau_sat[k, i] = out[1, i]


@njit(cache=True)
def _simulate(case, aux, K, substeps, q0, dq0, cfg, gains, plant, centers, phi, gam, xd0, dxd0):
    """Whole closed-loop run of SPEC §11; returns the recorded (K, ·) arrays."""
    n = q0.shape[0]
    nl = centers.shape[0]
    Ts = cfg[0]
    h = Ts / substeps
    q = q0.copy()
    dq = dq0.copy()
    xd = xd0.copy()
    dxd = dxd0.copy()
    zeta = np.zeros(n)
    pi = np.zeros((n, 2))
    WD = np.zeros((n, n, nl))
    WC = np.zeros((n, n, nl))
    WG = np.zeros((n, nl))
    S = np.zeros(nl)
    Z = np.zeros(4 * n)
    out = np.zeros((9, n))
    wnorm = np.zeros(3)
    tau_e = np.zeros(n)
    work = np.zeros((10, n))

    rq = np.zeros((K, n))
    rdq = np.zeros((K, n))
    rxc = np.zeros((K, n))
    rte = np.zeros((K, n))
    rout = np.zeros((K, 8, n))
    rw = np.zeros((K, 3))
    for k in range(K):
        t = k * Ts
        tau_e[0] = _wall_force(q[0], dq[0], plant)
        _step(
            case,
            aux,
            k,
            q,
            dq,
            tau_e,
            cfg,
            gains,
            centers,
            phi,
            gam,
            xd,
            dxd,
            zeta,
            pi,
            WD,
            WC,
            WG,
            S,
            Z,
            out,
            wnorm,
        )
        for i in range(n):
            rq[k, i] = q[i]
            rdq[k, i] = dq[i]
            rte[k, i] = tau_e[i]
            for r in range(8):
                rout[k, r, i] = out[r, i]
        rxc[k, 0] = 0.2 - 0.2 * np.cos(np.pi * t)
        rxc[k, 1] = 0.2 + 0.2 * np.sin(np.pi * t)
        for r in range(3):
            rw[k, r] = wnorm[r]
        for _ in range(substeps):
            _rk4(q, dq, out[1], h, plant, work)
    return rq, rdq, rxc, rte, rout, rw


# --------------------------------------------------------------------------
# Python API (same as spec_numpy)
# --------------------------------------------------------------------------
class Controller:
    """Discrete-time impedance controller of SPEC §11, jitted step.

    Same API and attributes as ``spec_numpy.Controller``: after ``step``,
    ``tau``, ``tau_sat``, ``dtau`` (N m), ``z1`` (rad), ``z2`` (rad/s),
    ``dq_hat`` (rad/s), ``zeta`` (N m) and ``xd`` (rad) are the step's values
    at t_k;
    ``xd_next``, ``dxd_next``, ``zeta_next``, ``pi_next`` and ``weights``
    (live arrays) are the state advanced to t_{k+1}.  ``w_norms`` holds the
    Frobenius norms (WD, WC, WG) before the step's update.
    """

    def __init__(self, case: str = "sf", **params):
        self.case = case
        self.p = make_params(case, **params)
        self.n = N_JOINTS
        self.centers = _np_ref.rbf_centers(self.n)
        self.n_nodes = self.centers.shape[0]
        self.Phi, self.Gam = _np_ref.observer_zoh(self.p["eps"], self.p["lam1"], self.p["Ts"])
        self._cfg, self._gains, _ = _pack(self.p)
        self._case = _CASE_CODE[case]
        self._aux = _AUX_CODE[self.p["aux_law"]]
        self.reset()

    def reset(self) -> None:
        """Back to t = 0: xd = xc(0), ẋd = ẋc(0), ζ = 0, π = 0, weights = 0."""
        n, nl = self.n, self.n_nodes
        self.k = 0
        xc, dxc, _ = _np_ref.commanded(0.0)
        self.xd_next = xc.copy()
        self.dxd_next = dxc.copy()
        self.zeta_next = np.zeros(n)
        self.pi_next = np.zeros((n, 2))
        self.weights = {
            "D": np.zeros((n, n, nl)),
            "C": np.zeros((n, n, nl)),
            "G": np.zeros((n, nl)),
        }
        self._S = np.zeros(nl)
        self._Z = np.zeros(4 * n)
        self._out = np.zeros((9, n))
        self._out[5] = self.zeta_next
        self._out[6] = self.xd_next
        self.w_norms = np.zeros(3)
        self._zero = np.zeros(n)

    def step(self, q, tau_e, dq=None) -> np.ndarray:
        """One controller period; q (rad), tau_e (N m), dq (rad/s, "pd"/"sf" only).

        Returns sat(τ) (N m), shape (n,).
        """
        if dq is None:
            if self._case != 2:
                raise ValueError(f"case {self.case!r} needs the measured velocity dq")
            dq = self._zero
        _step(
            self._case,
            self._aux,
            self.k,
            np.ascontiguousarray(q, dtype=np.float64),
            np.ascontiguousarray(dq, dtype=np.float64),
            np.ascontiguousarray(tau_e, dtype=np.float64),
            self._cfg,
            self._gains,
            self.centers,
            self.Phi,
            self.Gam,
            self.xd_next,
            self.dxd_next,
            self.zeta_next,
            self.pi_next,
            self.weights["D"],
            self.weights["C"],
            self.weights["G"],
            self._S,
            self._Z,
            self._out,
            self.w_norms,
        )
        self.k += 1
        return self._out[1].copy()

    def replay(self, q, tau_e, dq=None) -> np.ndarray:
        """K periods on logged measurements in one jitted loop (no Python per step).

        q (rad), tau_e (N m) and dq (rad/s, "pd"/"sf" only) have shape (K, n);
        row k is the measurement of step ``self.k + k``.  Equivalent to calling
        :meth:`step` on each row in turn; returns sat(τ) (N m), shape (K, n).
        """
        q = np.ascontiguousarray(q, dtype=np.float64)
        tau_e = np.ascontiguousarray(tau_e, dtype=np.float64)
        if dq is None:
            if self._case != 2:
                raise ValueError(f"case {self.case!r} needs the measured velocity dq")
            dq = np.zeros_like(q)
        dq = np.ascontiguousarray(dq, dtype=np.float64)
        shape = (q.shape[0], self.n)
        if q.shape != shape or tau_e.shape != shape or dq.shape != shape:
            raise ValueError(f"q, tau_e, dq must have shape (K, {self.n})")
        tau_sat = np.empty(shape)
        _replay(
            self._case,
            self._aux,
            self.k,
            q,
            dq,
            tau_e,
            self._cfg,
            self._gains,
            self.centers,
            self.Phi,
            self.Gam,
            self.xd_next,
            self.dxd_next,
            self.zeta_next,
            self.pi_next,
            self.weights["D"],
            self.weights["C"],
            self.weights["G"],
            self._S,
            self._Z,
            self._out,
            self.w_norms,
            tau_sat,
        )
        self.k += shape[0]
        return tau_sat

    def _row(self, r: int) -> np.ndarray:
        return self._out[r].copy()

    tau = property(lambda self: self._row(0), doc="Commanded τ (N m).")
    tau_sat = property(lambda self: self._row(1), doc="sat(τ) (N m).")
    dtau = property(lambda self: self._row(2), doc="Δτ = sat(τ) - τ (N m).")
    z1 = property(lambda self: self._row(3), doc="z1 = xd - x at t_k (rad).")
    dq_hat = property(lambda self: self._row(4), doc="Velocity used at t_k (rad/s).")
    zeta = property(lambda self: self._row(5), doc="ζ at t_k (N m).")
    xd = property(lambda self: self._row(6), doc="xd at t_k (rad).")
    z2 = property(lambda self: self._row(7), doc="z2 (ẑ2 for 'of') at t_k (rad/s).")


def simulate_args(case: str, p: dict) -> tuple:
    """The arguments of the jitted closed loop ``_simulate`` for ``case`` and the
    complete parameters ``p`` (from :func:`make_params`)."""
    cfg, gains, plant = _pack(p)
    Phi, Gam = _np_ref.observer_zoh(p["eps"], p["lam1"], p["Ts"])
    xc0, dxc0, _ = _np_ref.commanded(0.0)
    return (
        _CASE_CODE[case],
        _AUX_CODE[p["aux_law"]],
        round(p["T"] / p["Ts"]),
        p["substeps"],
        p["q0"],
        p["dq0"],
        cfg,
        gains,
        plant,
        _np_ref.rbf_centers(N_JOINTS),
        Phi,
        Gam,
        xc0,
        dxc0,
    )


def simulate(case: str = "sf", **params) -> dict:
    """Closed-loop run of SPEC §11 (jitted); same outputs as ``spec_numpy.simulate``."""
    p = make_params(case, **params)
    Ts = p["Ts"]
    K = round(p["T"] / Ts)
    rq, rdq, rxc, rte, rout, rw = _simulate(*simulate_args(case, p))
    rec = {"t": np.arange(K) * Ts, "q": rq, "dq": rdq, "xc": rxc}
    for r, name in enumerate(_OUT_ROWS):
        if name in ("tau", "tau_sat", "z1", "dq_hat", "zeta", "xd"):
            rec[name] = rout[:, r, :].copy()
    rec["tau_e"] = rte
    rec["w_norms"] = rw
    rec["metrics"] = compute_metrics(rec, p)
    return rec
