//! The 6-D Cartesian impedance for an `N`-joint arm, SPEC §16: the target
//! impedance (3) on the tip's pose, as an outer loop that hands the
//! joint-space controller its reference.
//!
//! Position-based impedance (admittance; Siciliano & Villani, *Robot Force
//! Control*, 1999, ch. 3; the paper's own structure, where the impedance model
//! produces the compliant reference that the adaptive loop tracks):
//!
//! 1. the measured wrench F_e = [f; m] (N, N m; what the tip exerts on the
//!    environment) and the commanded pose, both through first-order filters
//!    (16.6), drive the compliant reference pose (p_d, R_d) through the target
//!    impedance in translation and rotation (C1), with a hemisphere-safe
//!    rotation error ([`rotation`](crate::cartesian::rotation)) and error
//!    clipping (16.5);
//! 2. second-order closed-loop inverse kinematics on the pose (Siciliano,
//!    "A closed-loop inverse kinematic scheme for on-line joint-based robot
//!    control", Robotica 8, 1990; Siciliano et al., *Robotics*, 2009, §3.7)
//!    with a damped-least-squares inverse weighted per task direction
//!    (Nakamura & Hanafusa 1986; Wampler 1986) and a null-space posture task
//!    (Ott 2008, ch. 3) turns it into a joint reference q_d, q̇_d, q̈_d
//!    (C2)–(C4);
//! 3. the joint controller, with [`ImpedanceMode::External`](crate::ImpedanceMode)
//!    (no joint impedance on top), tracks that reference, with τe = Jᵀ(q) F_e
//!    in its feedforward or not (`force_feedforward`, C5); saturation stays
//!    per joint ([`CartesianController`](crate::cartesian::CartesianController)).
//!
//! Orientation stiffness 0 on every axis at construction makes the loop
//! position-only: the orientation is then no task of the inverse kinematics
//! (SPEC §16's 3-D loop).
//!
//! A [`CartesianImpedance`] is the validated description (with the arm's
//! [`Kinematics`] and the period); a [`CartesianState`] is what a run
//! changes. A step is staged on a copy ([`CartesianImpedance::stage`]) and
//! committed by the caller, so a refused input changes nothing.

use crate::cartesian::kinematics::{Jacobian6, Kinematics, Tip};
use crate::cartesian::rotation::{self, clip, exp, rotation_error};
use crate::control::io::TaskTorque;
use crate::control::safety::{
    CEILING_ACCELERATION, CEILING_POSITION, CEILING_TORQUE, CEILING_VELOCITY,
};
use crate::error::{check, Error, BOUND, PARAM_BOUND};
use crate::math::sqrt;
use crate::trajectory::Setpoint;
use crate::types::{choices, Vector};
use nalgebra::{Matrix3, SMatrix, UnitQuaternion};

mod config;
mod ik;
mod target;
pub use config::*;
use ik::*;
pub use target::*;

fn bounded(what: &'static str, v: &Vector<3>) -> Result<(), Error> {
    check::at_most_each("|value| ≤ 1e9", what, v.as_slice(), PARAM_BOUND)
}

/// SPEC §16 (C1)'s damping: `given`, or critical for the filtered
/// stiffness, 2√(K̃ M) per row (`row`: 0 translation, 3 rotation).
#[inline]
fn impedance_damping(
    given: &Option<Vector<3>>,
    m: &Vector<3>,
    k: &Vector<6>,
    row: usize,
) -> Vector<3> {
    match given {
        Some(b) => *b,
        None => Vector::<3>::from_fn(|i, _| 2.0 * sqrt(k[row + i] * m[i])),
    }
}

/// What (C1) of SPEC §16 gives a step: the clipped errors (16.5), the
/// compliant accelerations (16.13) and the damping used.
struct Impedance {
    ep: Vector<3>,
    eo: Vector<3>,
    ddpd: Vector<3>,
    dwd: Vector<3>,
    damping: Vector<6>,
}

/// The end of a staged step (SPEC §16 (C4)): every integrated quantity
/// within [`BOUND`] (`OutOfRange`), joint ones first.
#[inline]
fn check_integrated<const N: usize>(
    s: &CartesianState<N>,
    imp: &Impedance,
    ddqd: &Vector<N>,
    ddqc: &Vector<N>,
) -> Result<(), Error> {
    for (what, v) in [
        ("ddqd", ddqd),
        ("qd", &s.qd),
        ("dqd", &s.dqd),
        ("ddqc", ddqc),
        ("qc", &s.qc),
        ("dqc", &s.dqc),
    ] {
        check::within(what, v.as_slice(), BOUND)?;
    }
    for (what, v) in [("pd", &s.pd), ("dpd", &s.dpd), ("ddpd", &imp.ddpd)] {
        check::within(what, v.as_slice(), BOUND)?;
    }
    for (what, v) in [("wd", &s.wd), ("dwd", &imp.dwd)] {
        check::within(what, v.as_slice(), BOUND)?;
    }
    Ok(())
}

/// The state of the outer loop: the compliant reference, the joint
/// reference and the filters. Plain data; a step replaces it as a whole.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianState<const N: usize> {
    /// Compliant reference position p_d (m).
    pub pd: Vector<3>,
    /// Compliant reference velocity ṗ_d (m/s).
    pub dpd: Vector<3>,
    /// Compliant reference rotation R_d (world ← tip); a position-only loop
    /// keeps R(q_d) here.
    pub rd: UnitQuaternion<f64>,
    /// Compliant reference angular velocity ω_d (rad/s).
    pub wd: Vector<3>,
    /// Joint reference q_d (rad).
    pub qd: Vector<N>,
    /// Joint reference velocity q̇_d (rad/s).
    pub dqd: Vector<N>,
    /// Commanded joint reference q_c (rad): the inverse kinematics of the
    /// commanded pose alone, F_e = 0 (formulations other than admittance,
    /// SPEC §19; q0 otherwise).
    pub qc: Vector<N>,
    /// Commanded joint reference velocity q̇_c (rad/s).
    pub dqc: Vector<N>,
    /// Posture q_posture (rad) the null-space task pulls toward.
    pub posture: Vector<N>,
    /// The stiffness asked for, [K_d; K_d,rot] (N/m, N m/rad).
    pub stiffness: Vector<6>,
    /// The filtered stiffness the impedance uses (16.6).
    pub stiffness_filtered: Vector<6>,
    /// The target filter's offset [o_p (m); o_r (rad)] (16.6).
    pub offset: Vector<6>,
    /// The filtered wrench [f (N); m (N m)] (16.6).
    pub wrench: Vector<6>,
    /// The commanded target of the last step (held when a step has none).
    last: Target,
    /// The weakest direction of Λ⁻¹J found so far (unit, task rows), for
    /// the compliant reference's and the commanded reference's inverse
    /// kinematics ((C3'): one inverse iteration per step, started here).
    weak: [Vector<6>; 2],
    /// Steps taken.
    pub k: u64,
}

/// The compliant reference pose and its rates at t_k, world frame.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CompliantPose {
    /// p_d (m).
    pub p: Vector<3>,
    /// ṗ_d (m/s).
    pub dp: Vector<3>,
    /// p̈_d (m/s²).
    pub ddp: Vector<3>,
    /// R_d.
    pub r: UnitQuaternion<f64>,
    /// ω_d (rad/s).
    pub w: Vector<3>,
    /// ω̇_d (rad/s²).
    pub dw: Vector<3>,
}

/// One staged step of the outer loop ([`CartesianImpedance::stage`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct OuterStep<const N: usize> {
    /// The joint reference q_d, q̇_d, q̈_d at t_k (rad, rad/s, rad/s²).
    pub reference: Setpoint<N>,
    /// The commanded joint reference q_c, q̇_c, q̈_c at t_k (the inverse
    /// kinematics of the commanded pose alone, SPEC §19; the reference
    /// itself for the admittance formulation).
    pub commanded: Setpoint<N>,
    /// The commanded twist [ṗ_c (m/s); ω_c (rad/s)] at t_k.
    pub twist: Vector<6>,
    /// The damping [B (N s/m); B_o (N m s/rad)] the impedance used at t_k.
    pub damping: Vector<6>,
    /// The compliant reference at t_k.
    pub compliant: CompliantPose,
    /// The commanded pose at t_k after the target filter (p_t (m), R_t).
    pub target: (Vector<3>, UnitQuaternion<f64>),
    /// The error [e_p (m); e_o (rad)] the impedance acted on (after clipping).
    pub error: Vector<6>,
    /// The state at t_{k+1}, to commit.
    pub next: CartesianState<N>,
}

/// The validated outer loop: a [`CartesianConfig`], the arm's kinematics
/// and the period.
#[derive(Copy, Clone, Debug)]
pub struct CartesianImpedance<const N: usize, K> {
    cfg: CartesianConfig,
    kin: K,
    ts: f64,
    orients: bool,
    /// Λ² of (C3): λ_p² on the translation rows, λ_o² on the rotation rows.
    lambda2: Vector<6>,
}

impl<const N: usize, K: Kinematics<N>> CartesianImpedance<N, K> {
    /// Validate `cfg` (each condition named, as SPEC §10): M > 0, B ≥ 0,
    /// K ≥ 0, K_P, K_D, λ_p, λ_o > 0, k_0, d_0 ≥ 0, clipping limits > 0,
    /// filter time constants ≥ 0, every value finite and at most 1e9; the
    /// period `ts` (s) > 0 and ≤ 1 s, with `Ts·K_D < 1`, `Ts²·K_P < 1` (the
    /// CLIK's explicit step stays far inside its stability region: ω Ts < 1).
    pub fn new(cfg: CartesianConfig, kin: K, ts: f64) -> Result<Self, Error> {
        if N == 0 {
            return Err(Error::Invalid {
                what: "Cartesian impedance",
                reason: "needs at least one joint",
            });
        }
        check::positive("Ts > 0", "Ts", ts)?;
        check::at_most("Ts ≤ 1 s", "Ts", ts, 1.0)?;
        cfg.check()?;
        check::at_most(
            "Ts·clik_kd < 1",
            "Ts·clik_kd",
            ts * cfg.clik_kd,
            1.0 - 1e-12,
        )?;
        let kp = ts * ts * cfg.clik_kp;
        check::at_most("Ts²·clik_kp < 1", "Ts²·clik_kp", kp, 1.0 - 1e-12)?;
        let (lp, lo) = (
            cfg.clik_lambda * cfg.clik_lambda,
            cfg.clik_lambda_rot * cfg.clik_lambda_rot,
        );
        Ok(Self {
            cfg,
            kin,
            ts,
            orients: cfg.orients(),
            lambda2: Vector::<6>::new(lp, lp, lp, lo, lo, lo),
        })
    }

    /// The validated configuration.
    pub fn config(&self) -> &CartesianConfig {
        &self.cfg
    }
    /// The arm's kinematics.
    pub fn kinematics(&self) -> &K {
        &self.kin
    }
    /// The period Ts (s).
    pub fn period(&self) -> f64 {
        self.ts
    }
    /// Whether the orientation is a task (not position-only).
    pub fn orients(&self) -> bool {
        self.orients
    }

    /// A state at t = 0 with the joint reference and the posture at `q0`
    /// (rad; e.g. the measured start). The compliant pose starts on the
    /// commanded one at the first step (on fk(q0) if that step has none),
    /// and q̇_d at J⁺(q0) [ṗ_c; ω_c]; the inverse kinematics then pulls
    /// fk(q_d) onto it, so q0 should be near an inverse-kinematics solution
    /// of the first target.
    pub fn start(&self, q0: Vector<N>) -> CartesianState<N> {
        let mut k = Vector::<6>::zeros();
        k.fixed_rows_mut::<3>(0).copy_from(&self.cfg.kd);
        k.fixed_rows_mut::<3>(3).copy_from(&self.cfg.kd_rot);
        let zero = Target {
            p: Vector::zeros(),
            dp: Vector::zeros(),
            ddp: Vector::zeros(),
            q: UnitQuaternion::identity(),
            w: Vector::zeros(),
            dw: Vector::zeros(),
        };
        CartesianState {
            pd: Vector::zeros(),
            dpd: Vector::zeros(),
            rd: UnitQuaternion::identity(),
            wd: Vector::zeros(),
            qd: q0,
            dqd: Vector::zeros(),
            qc: q0,
            dqc: Vector::zeros(),
            posture: q0,
            stiffness: k,
            stiffness_filtered: k,
            offset: Vector::zeros(),
            wrench: Vector::zeros(),
            last: zero,
            weak: [weak_start(); 2],
            k: 0,
        }
    }

    /// Check a commanded pose as a step would (its parts finite and within
    /// their ceilings, the rotation one, unless the loop is position-only),
    /// without stepping: for a front that keeps a part of it (the last
    /// commanded rotation) only once it is known to be good.
    pub fn check_target(&self, target: &PoseTarget) -> Result<(), Error> {
        Target::check(target, self.orients).map(|_| ())
    }

    /// [`start`](Self::start) at a `q0` checked as a joint position: finite
    /// and within the position ceiling (1e6 rad, [`CEILING_POSITION`]: the
    /// joint reference q_d starts there, and a step refuses a reference
    /// beyond it). Errors name `q0` and the joint.
    pub fn start_checked(&self, q0: &Vector<N>) -> Result<CartesianState<N>, Error> {
        check::finite_slice("q0", q0.as_slice())?;
        check::within("q0", q0.as_slice(), CEILING_POSITION)?;
        Ok(self.start(*q0))
    }

    /// Check a null-space posture for a state whose joint reference is
    /// `qd`: finite, within the position ceiling (1e6 rad), and close enough
    /// that the posture task alone asks at most the ceiling of q̈_d (1e6
    /// rad/s², which a step refuses beyond): k_0·|q_posture − q_d| ≤ 1e6 per
    /// joint. Errors name `posture` and the joint.
    pub fn check_posture(&self, qd: &Vector<N>, posture: &Vector<N>) -> Result<(), Error> {
        check::finite_slice("posture", posture.as_slice())?;
        check::within("posture", posture.as_slice(), CEILING_POSITION)?;
        for i in 0..N {
            let pull = self.cfg.null_k * (posture[i] - qd[i]).abs();
            if pull > CEILING_ACCELERATION {
                return Err(Error::Condition {
                    condition: "null_k·|posture − q_d| ≤ 1e6 rad/s² (the ceiling of q̈_d)",
                    lhs: "null_k·|posture − q_d|",
                    index: Some(i),
                    value: pull,
                });
            }
        }
        Ok(())
    }

    /// Set the null-space posture q_posture (rad) from the next step on,
    /// checked by [`check_posture`](Self::check_posture) against the
    /// state's joint reference; on an error nothing changes.
    pub fn set_posture(
        &self,
        st: &mut CartesianState<N>,
        posture: &Vector<N>,
    ) -> Result<(), Error> {
        self.check_posture(&st.qd, posture)?;
        st.posture = *posture;
        Ok(())
    }

    /// Ask for the stiffness K_d (N/m) and K_d,rot (N m/rad): the impedance
    /// moves to it through the target filter (16.6), so the torque does not
    /// jump. Errors, changing nothing, for a negative, non-finite or larger
    /// than 1e9 value, or a rotational stiffness > 0 for a position-only loop.
    pub fn set_stiffness(
        &self,
        st: &mut CartesianState<N>,
        kd: &Vector<3>,
        kd_rot: &Vector<3>,
    ) -> Result<(), Error> {
        check::nonnegative_vec("Kd ≥ 0", "Kd", kd)?;
        check::nonnegative_vec("Kd_rot ≥ 0", "Kd_rot", kd_rot)?;
        bounded("Kd", kd)?;
        bounded("Kd_rot", kd_rot)?;
        if !self.orients && kd_rot.iter().any(|k| *k > 0.0) {
            return Err(Error::Invalid {
                what: "Kd_rot",
                reason: "a position-only loop (Kd_rot = 0 at construction) has no orientation task: build it with Kd_rot > 0",
            });
        }
        st.stiffness.fixed_rows_mut::<3>(0).copy_from(kd);
        st.stiffness.fixed_rows_mut::<3>(3).copy_from(kd_rot);
        Ok(())
    }

    /// One step of the outer loop on a copy of the state: the joint reference
    /// at t_k and the state at t_{k+1}, SPEC §16 (C0)–(C4). `target`: the
    /// commanded pose at t_k (`None`: hold the last one at rest; at the first
    /// step, fk(q_d)); `wrench`: the measured F_e = [f (N); m (N m)], world
    /// frame, about the tip. Errors, changing nothing, if an input is not
    /// finite or beyond its ceiling (p_c 1e6 m, ṗ_c and ω_c 1e6 m/s and
    /// rad/s, p̈_c and ω̇_c 1e6 m/s² and rad/s², the wrench 1e9 N and N m: those
    /// of a joint setpoint and τe, docs/reliability.md), the target's
    /// rotation is not one, or a result would be beyond [`BOUND`]
    /// (`OutOfRange`).
    pub fn stage(
        &self,
        st: &CartesianState<N>,
        target: Option<&PoseTarget>,
        wrench: &Vector<6>,
    ) -> Result<OuterStep<N>, Error> {
        check::finite_slice("wrench", wrench.as_slice())?;
        // The ceiling of a measured τe (N m), here in N and N m.
        check::within("wrench", wrench.as_slice(), CEILING_TORQUE)?;
        let ts = self.ts;
        let mut s = *st;
        let c = self.commanded_pose(&s, target)?;
        self.filter(&mut s, &c, wrench);
        s.last = c;
        // (16.13) The commanded rates half a step back, at t_k − Ts/2, where
        // the semi-implicit velocities of (C4) live: against them the
        // damping holds a path exactly (with ṗ_c(t_k) the compliant pose
        // lagged it by B·Ts·p̈_c/(2K)).
        let dp_half = c.dp - (0.5 * ts) * c.ddp;
        let w_half = c.w - (0.5 * ts) * c.dw;
        let pt = c.p + s.offset.fixed_rows::<3>(0);
        let qt = exp(&s.offset.fixed_rows::<3>(3).into_owned()) * c.q;
        let imp = self.impedance(&s, &c, (&pt, &qt), (&dp_half, &w_half));
        let ddqd = self.reference_acceleration(&mut s, &imp);
        let (commanded, twist_c) =
            self.commanded_reference(&mut s, &c, (&pt, &qt), (&dp_half, &w_half), &ddqd);
        let reference = Setpoint {
            x: s.qd,
            dx: s.dqd,
            ddx: ddqd,
        };
        let compliant = CompliantPose {
            p: s.pd,
            dp: s.dpd,
            ddp: imp.ddpd,
            r: s.rd,
            w: s.wd,
            dw: imp.dwd,
        };
        let mut error = Vector::<6>::zeros();
        error.fixed_rows_mut::<3>(0).copy_from(&imp.ep);
        error.fixed_rows_mut::<3>(3).copy_from(&imp.eo);
        self.integrate(&mut s, &imp, &ddqd, &commanded.ddx);
        check_integrated(&s, &imp, &ddqd, &commanded.ddx)?;
        Ok(OuterStep {
            reference,
            commanded,
            twist: twist_c,
            damping: imp.damping,
            compliant,
            target: (pt, qt),
            error,
            next: s,
        })
    }

    /// The commanded pose at t_k of [`Self::stage`], SPEC §16 (C0): the
    /// given `target` checked, or with none the last one held at rest (at
    /// the first step, fk(q_d) at rest).
    #[inline]
    fn commanded_pose(
        &self,
        s: &CartesianState<N>,
        target: Option<&PoseTarget>,
    ) -> Result<Target, Error> {
        Ok(match target {
            Some(t) => Target::check(t, self.orients)?,
            None if s.k == 0 => {
                let tip = self.kin.tip(&s.qd, &Vector::zeros());
                Target {
                    p: tip.position,
                    dp: Vector::zeros(),
                    ddp: Vector::zeros(),
                    q: UnitQuaternion::from_rotation_matrix(&tip.rotation),
                    w: Vector::zeros(),
                    dw: Vector::zeros(),
                }
            }
            None => s.last.held(),
        })
    }

    /// SPEC §16 (C0), the filters (16.6): at the first step their start
    /// (the compliant pose on the target, its rates half a step back
    /// (16.13), q̇_d and q̇_c by (C3) from them); after it, the target's
    /// unexplained jump decayed into the offset, the stiffness and the
    /// wrench low-passed.
    #[inline]
    fn filter(&self, s: &mut CartesianState<N>, c: &Target, wrench: &Vector<6>) {
        let cfg = &self.cfg;
        let ts = self.ts;
        if s.k == 0 {
            s.pd = c.p;
            s.dpd = c.dp - (0.5 * ts) * c.ddp;
            s.rd = c.q;
            s.wd = c.w - (0.5 * ts) * c.dw;
            s.wrench = *wrench;
            s.stiffness_filtered = s.stiffness;
            s.offset = Vector::zeros();
            let j = self.select_jacobian(self.kin.jacobian(&s.qd));
            let mut v = Vector::<6>::zeros();
            v.fixed_rows_mut::<3>(0).copy_from(&s.dpd);
            v.fixed_rows_mut::<3>(3).copy_from(&s.wd);
            s.dqd = self.dls(&j, &self.select(v), &mut s.weak[0]);
            s.dqc = s.dqd;
        } else {
            let at = ts / (cfg.target_filter + ts);
            let af = ts / (cfg.force_filter + ts);
            let last = &s.last;
            // The part of the target's change its rates do not explain (trapezoid).
            let dp = c.p - last.p - 0.5 * ts * (c.dp + last.dp);
            let dr = rotation_error(&c.q, &last.q) - 0.5 * ts * (c.w + last.w);
            let mut jump = Vector::<6>::zeros();
            jump.fixed_rows_mut::<3>(0).copy_from(&dp);
            jump.fixed_rows_mut::<3>(3).copy_from(&dr);
            s.offset = (1.0 - at) * (s.offset - jump);
            s.stiffness_filtered += at * (s.stiffness - s.stiffness_filtered);
            s.wrench += af * (wrench - s.wrench);
        }
    }

    /// SPEC §16 (C1), the target impedance on the clipped errors (16.5)
    /// toward the filtered target (p_t, R_t), against the commanded rates
    /// half a step back (16.13); the damping given, or critical for the
    /// filtered stiffness. The rotation rows stay zero when not orienting.
    #[inline]
    fn impedance(
        &self,
        s: &CartesianState<N>,
        c: &Target,
        (pt, qt): (&Vector<3>, &UnitQuaternion<f64>),
        (dp_half, w_half): (&Vector<3>, &Vector<3>),
    ) -> Impedance {
        let cfg = &self.cfg;
        let k = &s.stiffness_filtered;
        let (f, mom) = (s.wrench.fixed_rows::<3>(0), s.wrench.fixed_rows::<3>(3));
        let ep = clip(&(pt - s.pd), cfg.pos_error_max.unwrap_or(f64::INFINITY));
        let b = impedance_damping(&cfg.bd, &cfg.md, k, 0);
        let mut damping_used = Vector::<6>::zeros();
        damping_used.fixed_rows_mut::<3>(0).copy_from(&b);
        let kp = k.fixed_rows::<3>(0);
        let ddpd = c.ddp
            + (-b.component_mul(&(s.dpd - dp_half)) + kp.component_mul(&ep) - f)
                .component_div(&cfg.md);
        let (eo, dwd) = if self.orients {
            let eo = clip(
                &rotation_error(qt, &s.rd),
                cfg.rot_error_max.unwrap_or(f64::INFINITY),
            );
            let b = impedance_damping(&cfg.bd_rot, &cfg.md_rot, k, 3);
            damping_used.fixed_rows_mut::<3>(3).copy_from(&b);
            let ko = k.fixed_rows::<3>(3);
            let dwd = c.dw
                + (-b.component_mul(&(s.wd - w_half)) + ko.component_mul(&eo) - mom)
                    .component_div(&cfg.md_rot);
            (eo, dwd)
        } else {
            (Vector::zeros(), Vector::zeros())
        };
        Impedance {
            ep,
            eo,
            ddpd,
            dwd,
            damping: damping_used,
        }
    }

    /// SPEC §16 (C2): q̈_d by the second-order CLIK on the compliant pose at
    /// q_d, the posture in the null space; position-only, the compliant
    /// orientation is the reference's own (set in `s`).
    #[inline]
    fn reference_acceleration(&self, s: &mut CartesianState<N>, imp: &Impedance) -> Vector<N> {
        let tip = self.kin.tip(&s.qd, &s.dqd);
        if !self.orients {
            // Position-only: the compliant orientation is the reference's own.
            s.rd = UnitQuaternion::from_rotation_matrix(&tip.rotation);
            s.wd = tip.jacobian.fixed_rows::<3>(3) * s.dqd;
        }
        self.clik(
            &tip,
            (&s.qd, &s.dqd, &s.posture),
            (&s.pd, &s.dpd, &imp.ddpd),
            (&s.rd, &s.wd, &imp.dwd),
            &mut s.weak[0],
        )
    }

    /// SPEC (19.1), the commanded joint reference: the same CLIK on the
    /// filtered commanded pose alone (F_e = 0), for the formulations whose
    /// torque must not carry the measured wrench, with the commanded twist;
    /// the admittance's is the compliant reference itself (twist zero).
    #[inline]
    fn commanded_reference(
        &self,
        s: &mut CartesianState<N>,
        c: &Target,
        (pt, qt): (&Vector<3>, &UnitQuaternion<f64>),
        (dp_half, w_half): (&Vector<3>, &Vector<3>),
        ddqd: &Vector<N>,
    ) -> (Setpoint<N>, Vector<6>) {
        if self.cfg.formulation == Formulation::Admittance {
            return (
                Setpoint {
                    x: s.qd,
                    dx: s.dqd,
                    ddx: *ddqd,
                },
                Vector::<6>::zeros(),
            );
        }
        let tip_c = self.kin.tip(&s.qc, &s.dqc);
        let (rc, wc, dwc) = if self.orients {
            (*qt, *w_half, c.dw)
        } else {
            let r = UnitQuaternion::from_rotation_matrix(&tip_c.rotation);
            (
                r,
                tip_c.jacobian.fixed_rows::<3>(3) * s.dqc,
                Vector::zeros(),
            )
        };
        let ddqc = self.clik(
            &tip_c,
            (&s.qc, &s.dqc, &s.posture),
            (pt, dp_half, &c.ddp),
            (&rc, &wc, &dwc),
            &mut s.weak[1],
        );
        let mut tw = Vector::<6>::zeros();
        tw.fixed_rows_mut::<3>(0).copy_from(&c.dp);
        if self.orients {
            tw.fixed_rows_mut::<3>(3).copy_from(&c.w);
        }
        (
            Setpoint {
                x: s.qc,
                dx: s.dqc,
                ddx: ddqc,
            },
            tw,
        )
    }

    /// SPEC §16 (C4), (16.3): semi-implicit Euler, the velocity first; R_d
    /// on SO(3); q_c only when the formulation has its own reference.
    #[inline]
    fn integrate(
        &self,
        s: &mut CartesianState<N>,
        imp: &Impedance,
        ddqd: &Vector<N>,
        ddqc: &Vector<N>,
    ) {
        let ts = self.ts;
        s.dpd += ts * imp.ddpd;
        s.pd += ts * s.dpd;
        if self.orients {
            s.wd += ts * imp.dwd;
            s.rd = exp(&(ts * s.wd)) * s.rd;
        }
        s.dqd += ts * ddqd;
        s.qd += ts * s.dqd;
        if self.cfg.formulation != Formulation::Admittance {
            s.dqc += ts * ddqc;
            s.qc += ts * s.dqc;
        }
        s.k += 1;
    }

    /// The torque-level part of (19.2) for a staged step at the measured
    /// tip `tip` (pose and Jacobian at the measured q): the spring K̃ e with
    /// e = [clip(p_t − p); clip(Log(R_t Rᵀ))] (16.5), the damping and the
    /// commanded twist, the task Jacobian and (C3)'s damping, the
    /// admittance's share.
    pub fn task_torque(&self, staged: &OuterStep<N>, tip: &Tip<N>) -> TaskTorque<N> {
        let cfg = &self.cfg;
        let j = self.select_jacobian(tip.jacobian);
        let k = staged.next.stiffness_filtered;
        let mut e = Vector::<6>::zeros();
        let ep = clip(
            &(staged.target.0 - tip.position),
            cfg.pos_error_max.unwrap_or(f64::INFINITY),
        );
        e.fixed_rows_mut::<3>(0).copy_from(&ep);
        if self.orients {
            let r = UnitQuaternion::from_rotation_matrix(&tip.rotation);
            let eo = clip(
                &rotation_error(&staged.target.1, &r),
                cfg.rot_error_max.unwrap_or(f64::INFINITY),
            );
            e.fixed_rows_mut::<3>(3).copy_from(&eo);
        }
        TaskTorque {
            commanded: staged.commanded,
            jacobian: j,
            spring: self.select(k.component_mul(&e)),
            damping: self.select(staged.damping),
            twist: self.select(staged.twist),
            lambda2: self.lambda2,
            share: cfg.formulation.share(cfg.admittance_share),
        }
    }

    /// [`stage`](Self::stage) and commit: the joint reference at t_k, for a
    /// joint controller of the caller's.
    pub fn step(
        &self,
        st: &mut CartesianState<N>,
        target: Option<&PoseTarget>,
        wrench: &Vector<6>,
    ) -> Result<Setpoint<N>, Error> {
        let staged = self.stage(st, target, wrench)?;
        *st = staged.next;
        Ok(staged.reference)
    }

    /// The orbit-centre rule of SPEC §15 (15.2) for a Cartesian task: run the
    /// outer loop kinematically (F_e = 0) from `q0` for `steps` steps along
    /// the commanded `path(k)` (the target at t_k = k·Ts), and write the joint
    /// reference (q_d, q̇_d) of every `every`-th step, `every` = max(1, ⌊steps /
    /// L⌋) for L = `out.len()`, into `out` until it is full or the steps run
    /// out; returns how many were written. [`Centers::along`](crate::Centers)
    /// makes them RBF centres.
    pub fn orbit<F: FnMut(usize) -> PoseTarget>(
        &self,
        q0: Vector<N>,
        steps: usize,
        mut path: F,
        out: &mut [Setpoint<N>],
    ) -> Result<usize, Error> {
        check_orbit_size(steps, out.len())?;
        let every = (steps / out.len().max(1)).max(1);
        let mut st = self.start(q0);
        let mut written = 0;
        for k in 0..steps {
            let sp = self.step(&mut st, Some(&path(k)), &Vector::zeros())?;
            if k % every == 0 && written < out.len() {
                out[written] = sp;
                written += 1;
            }
        }
        Ok(written)
    }

    /// [`orbit`](Self::orbit) from `q0` (rad, checked finite) into a buffer
    /// it sizes for L = min(`nodes`, `steps`) samples (at least one: one a
    /// step at most, so a huge `nodes` allocates no more); the samples
    /// written.
    #[cfg(feature = "alloc")]
    pub fn orbit_samples<F: FnMut(usize) -> PoseTarget>(
        &self,
        q0: Vector<N>,
        steps: usize,
        path: F,
        nodes: usize,
    ) -> Result<alloc::vec::Vec<Setpoint<N>>, Error> {
        check::finite_slice("q0", q0.as_slice())?;
        let zero = Setpoint {
            x: Vector::<N>::zeros(),
            dx: Vector::zeros(),
            ddx: Vector::zeros(),
        };
        let mut out = alloc::vec![zero; nodes.min(steps).max(1)];
        let k = self.orbit(q0, steps, path, &mut out)?;
        out.truncate(k);
        Ok(out)
    }
}

#[cfg(test)]
mod tests;
