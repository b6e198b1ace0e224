//! Cartesian impedance for an `N`-joint arm, SPEC §16: the target impedance
//! (3) on the end-effector position, as an outer loop that hands the
//! joint-space controller its reference.
//!
//! Position-based impedance (admittance; Siciliano & Villani, *Robot Force
//! Control*, 1999, ch. 3; the paper's own structure, where the impedance model
//! produces the compliant reference that the adaptive loop tracks):
//!
//! 1. the impedance model, driven by the measured contact force F_e (N, the
//!    force the robot exerts), integrates the compliant reference p_d (C1);
//! 2. second-order closed-loop inverse kinematics (Siciliano, "A closed-loop
//!    inverse kinematic scheme for on-line joint-based robot control",
//!    Robotica 8, 1990; Siciliano et al., *Robotics*, 2009, §3.7) with a
//!    damped-least-squares inverse (Nakamura & Hanafusa 1986; Wampler 1986)
//!    and a null-space posture task for redundant arms (Ott 2008, ch. 3)
//!    turns p_d into a joint reference q_d, q̇_d, q̈_d (C2)–(C4);
//! 3. the joint controller, with [`ImpedanceMode::External`]
//!    (no joint impedance on top), tracks that reference, with τe = Jᵀ(q) F_e
//!    in its feedforward (C5); saturation stays per joint.
//!
//! A [`CartesianImpedance`] is the validated description (with the arm's
//! [`Kinematics`]); a [`CartesianState`] is what a run changes. A
//! [`CartesianController`] holds the outer loop and a joint [`Controller`];
//! its step takes both states, transactionally: if the joint step refuses a
//! measurement, the outer state is left as it was too.

use crate::cartesian::kinematics::Kinematics;
use crate::control::controller::Controller;
use crate::control::impedance::ImpedanceMode;
use crate::control::io::{Command, Measurement};
use crate::control::state::State;
use crate::error::{check, Error, BOUND, PARAM_BOUND};
use crate::networks::rbf::Basis;
use crate::trajectory::Setpoint;
use crate::types::{Jacobian, Vector};

/// Parameters of the Cartesian impedance and of the inverse kinematics; every
/// diagonal gain by its diagonal (x, y, z). Start from [`CartesianConfig::new`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianConfig<const N: usize> {
    /// Sampling period Ts (s), the joint controller's.
    pub ts: f64,
    /// Target inertia M_d (kg), > 0.
    pub md: Vector<3>,
    /// Target damping B_d (N s/m), ≥ 0.
    pub bd: Vector<3>,
    /// Target stiffness K_d (N/m), ≥ 0.
    pub kd: Vector<3>,
    /// CLIK position gain K_P (1/s²), > 0: e = p_d − fk(q_d) obeys ë + K_D ė + K_P e = 0.
    pub clik_kp: f64,
    /// CLIK velocity gain K_D (1/s), > 0.
    pub clik_kd: f64,
    /// Damping λ (m) of the least-squares inverse J⁺ = Jᵀ(J Jᵀ + λ² I)⁻¹, > 0.
    pub lambda: f64,
    /// Null-space posture stiffness k_0 (1/s²), ≥ 0.
    pub null_k: f64,
    /// Null-space damping d_0 (1/s), ≥ 0.
    pub null_d: f64,
    /// Posture q_posture (rad) the null-space task pulls toward.
    pub posture: Vector<N>,
}

impl<const N: usize> CartesianConfig<N> {
    /// The defaults of SPEC §16 at period `ts` (s) with `posture` (rad):
    /// M_d = 2 kg, K_d = 500 N/m, B_d = 2√(K_d M_d) ≈ 63.2 N s/m (critically
    /// damped, ω = 15.8 rad/s), CLIK at ω = 40 rad/s (K_P = 1600 1/s²,
    /// K_D = 80 1/s), λ = 0.01 m, k_0 = 25 1/s², d_0 = 10 1/s.
    pub fn new(ts: f64, posture: Vector<N>) -> Self {
        let (md, kd) = (2.0, 500.0);
        Self {
            ts,
            md: Vector::from_element(md),
            bd: Vector::from_element(2.0 * crate::math::sqrt(kd * md)),
            kd: Vector::from_element(kd),
            clik_kp: 1600.0,
            clik_kd: 80.0,
            lambda: 0.01,
            null_k: 25.0,
            null_d: 10.0,
            posture,
        }
    }
}

/// The state of the outer loop: the compliant reference and the joint reference.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianState<const N: usize> {
    /// Compliant reference position p_d (m).
    pub pd: Vector<3>,
    /// Compliant reference velocity ṗ_d (m/s).
    pub dpd: Vector<3>,
    /// Joint reference q_d (rad).
    pub qd: Vector<N>,
    /// Joint reference velocity q̇_d (rad/s).
    pub dqd: Vector<N>,
    /// Steps taken.
    pub k: u64,
}

/// One sample from the sensors at t_k.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianMeasurement<const N: usize> {
    /// Joint position q (rad).
    pub q: Vector<N>,
    /// Joint velocity q̇ (rad/s), as [`Measurement::dx`].
    pub dq: Option<Vector<N>>,
    /// Force the end effector exerts on the environment F_e (N), from a
    /// force sensor (the environment pushes back with −F_e).
    pub f_e: Vector<3>,
}

/// What a Cartesian step computed; `joint.tau_sat` goes to the actuators.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianCommand<const N: usize> {
    /// The joint controller's command (τ, sat(τ), z1 = q_d − q, …).
    pub joint: Command<N>,
    /// The joint reference q_d, q̇_d, q̈_d (rad, rad/s, rad/s²) at t_k.
    pub reference: Setpoint<N>,
    /// The compliant reference p_d(t_k) (m).
    pub pd: Vector<3>,
    /// The measured end-effector position fk(q) (m).
    pub p: Vector<3>,
    /// τe = Jᵀ(q) F_e (N m), the contact torque the joint controller got.
    pub tau_e: Vector<N>,
}

/// One staged step of the outer loop ([`CartesianImpedance::stage`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct OuterStep<const N: usize> {
    /// The joint reference q_d, q̇_d, q̈_d at t_k (rad, rad/s, rad/s²).
    pub reference: Setpoint<N>,
    /// The compliant reference p_d, ṗ_d, p̈_d at t_k (m, m/s, m/s²).
    pub compliant: Setpoint<3>,
    /// The state at t_{k+1}, to commit.
    pub next: CartesianState<N>,
}

/// The validated outer loop: a [`CartesianConfig`] and the arm's kinematics.
#[derive(Copy, Clone, Debug)]
pub struct CartesianImpedance<const N: usize, K> {
    cfg: CartesianConfig<N>,
    kin: K,
}

/// The damped-least-squares solve `J⁺ v = Jᵀ (J Jᵀ + λ² I)⁻¹ v`: 3 × 3,
/// positive definite for λ > 0 (zero if a non-finite J makes it indefinite;
/// the step's checks then refuse the result).
fn dls<const N: usize>(j: &Jacobian<N>, lambda2: f64, v: &Vector<3>) -> Vector<N> {
    let a = j * j.transpose() + nalgebra::Matrix3::identity() * lambda2;
    match a.cholesky() {
        Some(ch) => j.transpose() * ch.solve(v),
        None => Vector::zeros(),
    }
}

impl<const N: usize, K: Kinematics<N>> CartesianImpedance<N, K> {
    /// Validate `cfg` (each condition named, as SPEC §10): Ts > 0 and ≤ 1 s,
    /// M_d > 0, B_d ≥ 0, K_d ≥ 0, K_P > 0, K_D > 0, λ > 0, k_0 ≥ 0, d_0 ≥ 0,
    /// every value finite and at most 1e9 in magnitude, and `Ts·K_D < 1`,
    /// `Ts²·K_P < 1` (the CLIK's explicit step stays far inside its stability
    /// region: ω Ts < 1).
    pub fn new(cfg: CartesianConfig<N>, kin: K) -> Result<Self, Error> {
        if N == 0 {
            return Err(Error::Invalid {
                what: "Cartesian impedance",
                reason: "needs at least one joint",
            });
        }
        check::positive("Ts > 0", "Ts", cfg.ts)?;
        check::at_most("Ts ≤ 1 s", "Ts", cfg.ts, 1.0)?;
        check::positive_vec("Md > 0", "Md", &cfg.md)?;
        check::nonnegative_vec("Bd ≥ 0", "Bd", &cfg.bd)?;
        check::nonnegative_vec("Kd ≥ 0", "Kd", &cfg.kd)?;
        check::positive("K_P > 0", "clik_kp", cfg.clik_kp)?;
        check::positive("K_D > 0", "clik_kd", cfg.clik_kd)?;
        check::positive("λ > 0", "lambda", cfg.lambda)?;
        check::nonnegative("k0 ≥ 0", "null_k", cfg.null_k)?;
        check::nonnegative("d0 ≥ 0", "null_d", cfg.null_d)?;
        check::finite_slice("posture", cfg.posture.as_slice())?;
        for (what, v) in [("Md", &cfg.md), ("Bd", &cfg.bd), ("Kd", &cfg.kd)] {
            check::each("|value| ≤ 1e9", what, v, |_, x| PARAM_BOUND - x, false)?;
        }
        for (what, v) in [
            ("clik_kp", cfg.clik_kp),
            ("clik_kd", cfg.clik_kd),
            ("lambda", cfg.lambda),
            ("null_k", cfg.null_k),
            ("null_d", cfg.null_d),
        ] {
            check::at_most("|value| ≤ 1e9", what, v, PARAM_BOUND)?;
        }
        check::at_most("|posture| ≤ 1e6 rad", "posture", cfg.posture.amax(), 1e6)?;
        check::at_most(
            "Ts·K_D < 1",
            "Ts·clik_kd",
            cfg.ts * cfg.clik_kd,
            1.0 - 1e-12,
        )?;
        let kp = cfg.ts * cfg.ts * cfg.clik_kp;
        check::at_most("Ts²·K_P < 1", "Ts²·clik_kp", kp, 1.0 - 1e-12)?;
        Ok(Self { cfg, kin })
    }

    /// The validated configuration.
    pub fn config(&self) -> &CartesianConfig<N> {
        &self.cfg
    }
    /// The arm's kinematics.
    pub fn kinematics(&self) -> &K {
        &self.kin
    }

    /// A state at t = 0 with the joint reference at `q0` (rad; e.g. the
    /// measured start). p_d starts on the commanded p_c at the first step,
    /// and q̇_d at J⁺(q0) ṗ_c; the inverse kinematics then pulls fk(q_d) onto
    /// p_d, so q0 should be near an inverse-kinematics solution of p_c(0).
    pub fn start(&self, q0: Vector<N>) -> CartesianState<N> {
        CartesianState {
            pd: Vector::zeros(),
            dpd: Vector::zeros(),
            qd: q0,
            dqd: Vector::zeros(),
            k: 0,
        }
    }

    /// The target impedance (C1): `p̈_d = p̈_c + M_d⁻¹ (−B_d (ṗ_d − ṗ_c) −
    /// K_d (p_d − p_c) − F_e)` (m/s²).
    pub fn accel(&self, c: &Setpoint<3>, st: &CartesianState<N>, f_e: &Vector<3>) -> Vector<3> {
        let cfg = &self.cfg;
        let mut a = c.ddx;
        for i in 0..3 {
            a[i] += (-cfg.bd[i] * (st.dpd[i] - c.dx[i]) - cfg.kd[i] * (st.pd[i] - c.x[i]) - f_e[i])
                / cfg.md[i];
        }
        a
    }

    /// The joint reference acceleration (C2), second-order CLIK with the
    /// posture task in the null space (rad/s²):
    /// `q̈_d = w + J⁺ (r − J w)`, with J = J(q_d), J⁺ damped least squares,
    /// `r = p̈_d − J̇ q̇_d + K_D (ṗ_d − J q̇_d) + K_P (p_d − fk(q_d))` and
    /// `w = k_0 (q_posture − q_d) − d_0 q̇_d`; i.e. `J⁺ r + (I − J⁺ J) w`.
    pub fn joint_accel(&self, st: &CartesianState<N>, ddpd: &Vector<3>) -> Vector<N> {
        let cfg = &self.cfg;
        let j = self.kin.jacobian(&st.qd);
        let e = st.pd - self.kin.fk(&st.qd);
        let de = st.dpd - j * st.dqd;
        let r =
            ddpd - self.kin.jacobian_dot_qdot(&st.qd, &st.dqd) + cfg.clik_kd * de + cfg.clik_kp * e;
        let w = cfg.null_k * (cfg.posture - st.qd) - cfg.null_d * st.dqd;
        w + dls(&j, cfg.lambda * cfg.lambda, &(r - j * w))
    }

    /// τe = Jᵀ(q) F_e (N m): the contact force as the joint controller sees it (C5).
    pub fn contact_torque(&self, q: &Vector<N>, f_e: &Vector<3>) -> Vector<N> {
        self.kin.jacobian(q).transpose() * f_e
    }

    /// One step of the outer loop on a copy of the state: the joint reference
    /// at t_k and the state at t_{k+1} (semi-implicit Euler, as SPEC §11's
    /// reference: ṗ_d ← ṗ_d + Ts p̈_d, p_d ← p_d + Ts ṗ_d, then the same for
    /// q̇_d, q_d). Errors, changing nothing, if an input is not finite or
    /// beyond [`BOUND`], or a result would be (`OutOfRange`).
    pub fn stage(
        &self,
        st: &CartesianState<N>,
        c: &Setpoint<3>,
        f_e: &Vector<3>,
    ) -> Result<OuterStep<N>, Error> {
        for (what, v) in [("pc", &c.x), ("dpc", &c.dx), ("ddpc", &c.ddx), ("f_e", f_e)] {
            check::finite_slice(what, v.as_slice())?;
            check::within(what, v.as_slice(), BOUND)?;
        }
        let mut s = *st;
        if s.k == 0 {
            s.pd = c.x;
            s.dpd = c.dx;
            let j = self.kin.jacobian(&s.qd);
            s.dqd = dls(&j, self.cfg.lambda * self.cfg.lambda, &c.dx);
        }
        let ddpd = self.accel(c, &s, f_e);
        let ddqd = self.joint_accel(&s, &ddpd);
        let reference = Setpoint {
            x: s.qd,
            dx: s.dqd,
            ddx: ddqd,
        };
        let compliant = Setpoint {
            x: s.pd,
            dx: s.dpd,
            ddx: ddpd,
        };
        let ts = self.cfg.ts;
        s.dpd += ts * ddpd;
        s.pd += ts * s.dpd;
        s.dqd += ts * ddqd;
        s.qd += ts * s.dqd;
        s.k += 1;
        for (what, v) in [("ddqd", &ddqd), ("qd", &s.qd), ("dqd", &s.dqd)] {
            check::within(what, v.as_slice(), BOUND)?;
        }
        for (what, v) in [("pd", &s.pd), ("dpd", &s.dpd), ("ddpd", &ddpd)] {
            check::within(what, v.as_slice(), BOUND)?;
        }
        Ok(OuterStep {
            reference,
            compliant,
            next: s,
        })
    }

    /// [`stage`](Self::stage) and commit: the joint reference at t_k, for a
    /// joint controller of the caller's.
    pub fn step(
        &self,
        st: &mut CartesianState<N>,
        c: &Setpoint<3>,
        f_e: &Vector<3>,
    ) -> Result<Setpoint<N>, Error> {
        let staged = self.stage(st, c, f_e)?;
        *st = staged.next;
        Ok(staged.reference)
    }
}

/// The outer Cartesian impedance and the joint controller it drives.
#[derive(Clone, Debug)]
pub struct CartesianController<const N: usize, K, B> {
    outer: CartesianImpedance<N, K>,
    inner: Controller<N, B>,
}

impl<const N: usize, K: Kinematics<N>, B: Basis<N>> CartesianController<N, K, B> {
    /// The pair, validated: the joint controller must have
    /// `impedance = "external"` (the Cartesian impedance is the only one:
    /// a joint impedance would answer τe a second time) and the same Ts.
    pub fn new(outer: CartesianImpedance<N, K>, inner: Controller<N, B>) -> Result<Self, Error> {
        if inner.config().impedance != ImpedanceMode::External {
            return Err(Error::Invalid {
                what: "joint controller of a Cartesian impedance",
                reason: "needs impedance = \"external\" (ImpedanceMode::External): the joint impedance would act on τe a second time",
            });
        }
        if inner.period() != outer.config().ts {
            return Err(Error::Invalid {
                what: "joint controller of a Cartesian impedance",
                reason: "needs the same Ts as the Cartesian impedance",
            });
        }
        Ok(Self { outer, inner })
    }

    /// The outer loop.
    pub fn outer(&self) -> &CartesianImpedance<N, K> {
        &self.outer
    }
    /// The joint controller.
    pub fn inner(&self) -> &Controller<N, B> {
        &self.inner
    }

    /// One step at t_k: the measurement `m` and the commanded position
    /// `c` (p_c, ṗ_c, p̈_c at t_k; m, m/s, m/s²) in, the command out; no
    /// allocation. The outer loop is staged, the joint step runs with the
    /// joint reference and τe = Jᵀ(q) F_e, and only if it succeeds is the
    /// outer state committed (on an error both states are as before, except
    /// the joint state's recorded fault).
    pub fn step<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        outer: &mut CartesianState<N>,
        inner: &mut State<N, S>,
        m: &CartesianMeasurement<N>,
        c: &Setpoint<3>,
    ) -> Result<CartesianCommand<N>, Error> {
        let staged = self.outer.stage(outer, c, &m.f_e)?;
        check::finite_slice("q", m.q.as_slice())?;
        check::within("q", m.q.as_slice(), BOUND)?;
        let tau_e = self.outer.contact_torque(&m.q, &m.f_e);
        let meas = Measurement {
            x: m.q,
            dx: m.dq,
            tau_e,
        };
        let joint = self.inner.step(inner, &meas, &staged.reference)?;
        *outer = staged.next;
        Ok(CartesianCommand {
            joint,
            reference: staged.reference,
            pd: staged.compliant.x,
            p: self.outer.kin.fk(&m.q),
            tau_e,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::config::{Config, Law};
    use crate::networks::rbf::Grid;
    use crate::sim::model::TwoLinkArm;

    fn outer() -> CartesianImpedance<2, TwoLinkArm> {
        let q0 = Vector::<2>::new(0.5, 1.0);
        CartesianImpedance::new(CartesianConfig::new(1e-3, q0), TwoLinkArm::paper()).unwrap()
    }

    #[test]
    fn bad_gains_are_rejected_by_name() {
        let q0 = Vector::<2>::new(0.5, 1.0);
        let arm = TwoLinkArm::paper();
        let mut cfg = CartesianConfig::new(1e-3, q0);
        cfg.md[1] = 0.0;
        let e = CartesianImpedance::new(cfg, arm).unwrap_err();
        assert!(e.to_string().contains("Md > 0"), "{e}");
        let mut cfg = CartesianConfig::new(1e-3, q0);
        cfg.lambda = 0.0;
        let e = CartesianImpedance::new(cfg, arm).unwrap_err();
        assert!(e.to_string().contains("λ > 0"), "{e}");
        let mut cfg = CartesianConfig::new(1e-3, q0);
        cfg.clik_kd = 2000.0;
        let e = CartesianImpedance::new(cfg, arm).unwrap_err();
        assert!(e.to_string().contains("Ts·K_D < 1"), "{e}");
    }

    #[test]
    fn the_joint_controller_must_leave_the_impedance_to_the_outer_loop() {
        let mut cfg = Config::paper(Law::StateFeedback);
        cfg.ts = 1e-3;
        let joint = Controller::new(cfg, Grid::paper()).unwrap();
        let e = CartesianController::new(outer(), joint).unwrap_err();
        assert!(e.to_string().contains("external"), "{e}");
        cfg.impedance = ImpedanceMode::External;
        let joint = Controller::new(cfg, Grid::paper()).unwrap();
        assert!(CartesianController::new(outer(), joint).is_ok());
    }

    #[test]
    fn a_static_force_deflects_the_reference_by_f_over_kd_and_ik_follows() {
        let o = outer();
        let mut st = o.start(Vector::<2>::new(0.5, 1.0));
        let pc = o.kinematics().fk(&st.qd);
        let c = Setpoint {
            x: pc,
            dx: Vector::zeros(),
            ddx: Vector::zeros(),
        };
        let f = Vector::<3>::new(5.0, -2.0, 0.0);
        for _ in 0..20_000 {
            o.step(&mut st, &c, &f).unwrap();
        }
        // K_d (p_c − p_d) = F_e at rest, (C1); fk(q_d) = p_d, (C2), up to
        // the posture term the damped inverse lets into the task,
        // O(λ²/σ²)·k0‖q_posture − q_d‖/K_P (measured 9.5e-8 m).
        let kd = o.config().kd[0];
        assert!((kd * (pc - st.pd) - f).norm() < 1e-9, "{}", st.pd);
        let e = (o.kinematics().fk(&st.qd) - st.pd).norm();
        assert!(e < 1e-6, "{e}");
        // A non-finite force is refused and changes nothing.
        let before = st;
        assert!(o
            .step(&mut st, &c, &Vector::from_element(f64::NAN))
            .is_err());
        assert_eq!(st, before);
    }
}
