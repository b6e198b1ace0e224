//! Computed torque (inverse-dynamics) impedance control, SPEC §20 (20.3),
//! (20.4), with the drive's friction compensated (20.6): the model-based baseline the paper's model-free laws are compared
//! with, on the core's [`Dynamics`]. No allocation.
//!
//! [`ComputedTorque`] holds the parameters and the model (immutable);
//! [`ComputedState`] the caller-owned state (the compliant reference, the
//! clock, the last command, the torque applied, the last fault), as for the
//! paper's [`Controller`](crate::Controller) and its `State`.
//!
//! Units: rad, rad/s, rad/s², N m (m, N for prismatic joints), s.

use crate::cartesian::dynamics::Dynamics;
use crate::control::impedance::{ImpedanceMode, Reference, TargetImpedance};
use crate::control::io::{Command, Measurement, TaskTorque};
use crate::control::safety::Fault;
use crate::control::saturation::Saturation;
use crate::error::{check, Error, BOUND, PARAM_BOUND};
use crate::trajectory::Setpoint;
use crate::types::Vector;

/// The parameters of a computed-torque controller (20.3).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ComputedTorqueConfig<const N: usize> {
    /// Sampling period Ts (s), > 0.
    pub ts: f64,
    /// Stiffness K_P of the error dynamics (1/s²), > 0 each.
    pub kp: Vector<N>,
    /// Damping K_D of the error dynamics (1/s), ≥ 0 each.
    pub kd: Vector<N>,
    /// Actuator limits τmax (N m), > 0 each.
    pub tau_max: Vector<N>,
    /// The target impedance (3) of the compliant reference (SPEC §4).
    pub impedance: TargetImpedance<N>,
    /// Where the impedance is realised: the reference model of SPEC §4
    /// (`Joint`) or an outer loop (`External`, xd = xc).
    pub mode: ImpedanceMode,
}

impl<const N: usize> ComputedTorqueConfig<N> {
    /// K_P = 400 (ω = 20 rad/s), K_D = 40 (critical), the paper's target
    /// impedance, the reference model in joint space.
    pub fn new(ts: f64, tau_max: Vector<N>) -> Self {
        Self {
            ts,
            kp: Vector::from_element(400.0),
            kd: Vector::from_element(40.0),
            tau_max,
            impedance: TargetImpedance::paper(),
            mode: ImpedanceMode::Joint,
        }
    }
}

/// The caller-owned state of a [`ComputedTorque`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ComputedState<const N: usize> {
    /// Steps taken k (the next step is at t_k = k·Ts).
    pub k: u64,
    /// The compliant reference x_d, ẋ_d at t_k (`Joint` mode).
    pub reference: Reference<N>,
    /// The last step's command (zeros before the first).
    pub last: Command<N>,
    /// The torque last applied (N m): the last command's sat(τ), held on a
    /// refused step.
    pub applied: Vector<N>,
    /// The last refused step's error and step, if any.
    pub fault: Option<Fault>,
}

impl<const N: usize> Default for ComputedState<N> {
    fn default() -> Self {
        Self {
            k: 0,
            reference: Reference::zeros(),
            last: Command::zeros(),
            applied: Vector::zeros(),
            fault: None,
        }
    }
}

/// Computed torque with the core's rigid-body model: see the [module
/// docs](self) and SPEC §20.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ComputedTorque<const N: usize> {
    cfg: ComputedTorqueConfig<N>,
    model: Dynamics<N>,
    sat: Saturation<N>,
}

impl<const N: usize> ComputedTorque<N> {
    /// The controller of `cfg` with the model `model` (the controller's, not
    /// necessarily the plant's: [`Dynamics::scaled`] for a model error).
    ///
    /// Errors naming the parameter: Ts ≤ 0, beyond 1 s or not finite (as
    /// the joint controller's), K_P ≤ 0, K_D < 0, τmax ≤ 0, any of them
    /// beyond 1e9 or not finite.
    pub fn new(cfg: ComputedTorqueConfig<N>, model: Dynamics<N>) -> Result<Self, Error> {
        check::positive("Ts > 0", "Ts", cfg.ts)?;
        check::at_most("Ts ≤ 1 s", "Ts", cfg.ts, 1.0)?;
        check::positive_vec("Kp > 0", "Kp", &cfg.kp)?;
        check::nonnegative_vec("Kd ≥ 0", "Kd", &cfg.kd)?;
        check::at_most_each("|value| ≤ 1e9", "Kp", cfg.kp.as_slice(), PARAM_BOUND)?;
        check::at_most_each("|value| ≤ 1e9", "Kd", cfg.kd.as_slice(), PARAM_BOUND)?;
        check::at_most_each(
            "|value| ≤ 1e9",
            "tau_max",
            cfg.tau_max.as_slice(),
            PARAM_BOUND,
        )?;
        let sat = Saturation::new(cfg.tau_max)?;
        Ok(Self { cfg, model, sat })
    }

    /// The parameters.
    pub fn config(&self) -> &ComputedTorqueConfig<N> {
        &self.cfg
    }

    /// The controller's model.
    pub fn model(&self) -> &Dynamics<N> {
        &self.model
    }

    /// Sampling period Ts (s).
    pub fn period(&self) -> f64 {
        self.cfg.ts
    }

    /// The target impedance (3).
    pub fn impedance(&self) -> &TargetImpedance<N> {
        &self.cfg.impedance
    }

    /// One step at t_k, (20.3): the measurement `m` (q̇ required) and the
    /// setpoint `c` in, the command out. On an error the step is refused
    /// (`st.fault` records it, the torque last applied is held) and nothing
    /// else changes.
    pub fn step(
        &self,
        st: &mut ComputedState<N>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> Result<Command<N>, Error> {
        let r = self.try_step(st, m, c, None);
        self.refused(st, r)
    }

    /// One step of the torque-level formulations of a Cartesian impedance
    /// (SPEC §19) with the compliant reference `c` and the task terms
    /// `task`, (20.4); the share n = 1 is [`step`](Self::step) in the
    /// external mode.
    pub fn step_task(
        &self,
        st: &mut ComputedState<N>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
        task: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        let r = self.try_step(st, m, c, Some(task));
        self.refused(st, r)
    }

    /// A step refused before it reached the controller (by a caller that
    /// checked its arguments, or an outer loop that refused its target):
    /// recorded as a refused step; returns the torque held.
    pub fn refuse(&self, st: &mut ComputedState<N>, error: Error) -> Vector<N> {
        st.fault = Some(Fault { error, step: st.k });
        st.applied
    }

    fn refused(
        &self,
        st: &mut ComputedState<N>,
        r: Result<Command<N>, Error>,
    ) -> Result<Command<N>, Error> {
        if let Err(e) = r {
            self.refuse(st, e);
        }
        r
    }

    fn try_step(
        &self,
        st: &mut ComputedState<N>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
        task: Option<&TaskTorque<N>>,
    ) -> Result<Command<N>, Error> {
        let dq = check_measurement(m, c)?;
        let q = m.x;
        let external = self.cfg.mode == ImpedanceMode::External || task.is_some();
        let r = if st.k == 0 || external {
            Reference::start(c)
        } else {
            st.reference
        };
        // The reference's acceleration, SPEC §4 ("external": ẍd = ẍc).
        let ddxd = if external {
            c.ddx
        } else {
            self.cfg.impedance.accel(c, &r, &m.tau_e)
        };
        // (20.3): the error dynamics' acceleration on the reference.
        let (kp, kd) = (&self.cfg.kp, &self.cfg.kd);
        // The reference's velocity where the plant's reported one is, SPEC
        // (20.9'): h/2 back for semi-implicit steps, else now.
        let dxd = r.dxd - self.model.velocity_lag() * ddxd;
        let a = ddxd + kd.component_mul(&(dxd - dq)) + kp.component_mul(&(r.xd - q));
        let (tau, xc) = match task.filter(|t| t.share < 1.0) {
            None => (self.joint_torque(m, &dq, &r, &a), c.x),
            Some(t) => (self.task_torque(m, &dq, &r, &a, t)?, t.commanded.x),
        };
        if tau.iter().any(|t| !t.is_finite()) {
            return Err(Error::Diverged { what: "tau" });
        }
        let tau_sat = self.sat.apply(&tau);
        let cmd = Command {
            tau_sat,
            tau,
            dtau: tau_sat - tau,
            z1: r.xd - q,
            z2: Vector::zeros(),
            xc,
            xd: r.xd,
            v: dq,
            zeta: Vector::zeros(),
            w_norms: [0.0; 3],
        };
        // Advance the reference to t_{k+1} as the arm moves under the torque
        // held over the period, at the constant acceleration ẍd (SPEC (20.3)):
        // xd + Ts ẋd + Ts²/2 ẍd. §11's semi-implicit step (xd + Ts ẋd + Ts² ẍd)
        // would lead the arm by Ts²/2 ẍd each step, an error the feedback
        // chases at every gain (7e-5 rad on one joint of the default task).
        let ts = self.cfg.ts;
        let next = Reference {
            xd: r.xd + ts * r.dxd + (0.5 * ts * ts) * ddxd,
            dxd: r.dxd + ts * ddxd,
        };
        st.reference = next;
        st.k += 1;
        st.last = cmd;
        st.applied = tau_sat;
        Ok(cmd)
    }

    /// (20.3) in joint space: τ = RNEA(q, q̇, a) + the friction term (20.6)
    /// on the reference's velocity + τe.
    fn joint_torque(
        &self,
        m: &Measurement<N>,
        dq: &Vector<N>,
        r: &Reference<N>,
        a: &Vector<N>,
    ) -> Vector<N> {
        self.model.inverse_dynamics(&m.x, dq, a)
            + self.model.drive_torque(&m.x, dq, a, &r.dxd)
            + m.tau_e
    }

    /// (20.4): the blend, by the admittance share n, of the joint law on the
    /// compliant reference and the task-level force JᵀF with its null-space
    /// posture term on the commanded one, in one RNEA pass (RNEA is affine
    /// in q̈). Errors if the task's quantities are not finite or in range.
    fn task_torque(
        &self,
        m: &Measurement<N>,
        dq: &Vector<N>,
        r: &Reference<N>,
        a: &Vector<N>,
        t: &TaskTorque<N>,
    ) -> Result<Vector<N>, Error> {
        check_task(t)?;
        let (kp, kd) = (&self.cfg.kp, &self.cfg.kd);
        let q = m.x;
        let n = t.share;
        let qc = &t.commanded;
        let pd = kp.component_mul(&(qc.x - q)) + kd.component_mul(&(qc.dx - dq));
        let null = t.null_space(kp).apply(&self.model.mass_times(&q, &pd));
        let ddq = n * a + (1.0 - n) * qc.ddx;
        let task_part = t.jacobian.transpose() * t.force(dq) + null;
        // (20.6) on the velocity the blend of references moves at.
        let v_r = n * r.dxd + (1.0 - n) * qc.dx;
        Ok(self.model.inverse_dynamics(&q, dq, &ddq)
            + self.model.drive_torque(&q, dq, &ddq, &v_r)
            + n * m.tau_e
            + (1.0 - n) * task_part)
    }
}

/// The measurement's velocity, once the measurement and the setpoint are
/// checked finite and within [`BOUND`] (named as the core names them).
fn check_measurement<const N: usize>(
    m: &Measurement<N>,
    c: &Setpoint<N>,
) -> Result<Vector<N>, Error> {
    let dq = m.dx.ok_or(Error::MissingVelocity)?;
    for (what, v) in [
        ("x", &m.x),
        ("dx", &dq),
        ("tau_e", &m.tau_e),
        ("xc", &c.x),
        ("dxc", &c.dx),
        ("ddxc", &c.ddx),
    ] {
        check::finite_slice(what, v.as_slice())?;
        check::within(what, v.as_slice(), BOUND)?;
    }
    Ok(dq)
}

/// The task-level input of (20.4) checked: 0 ≤ share ≤ 1, every quantity
/// finite and within [`BOUND`].
fn check_task<const N: usize>(t: &TaskTorque<N>) -> Result<(), Error> {
    check::within("share", &[t.share], 1.0)?;
    if t.share.is_nan() || t.share < 0.0 {
        return Err(Error::Condition {
            condition: "0 ≤ admittance_share ≤ 1",
            lhs: "admittance_share",
            index: None,
            value: t.share,
        });
    }
    for (what, x) in [
        ("jacobian", t.jacobian.as_slice()),
        ("spring", t.spring.as_slice()),
        ("damping", t.damping.as_slice()),
        ("twist", t.twist.as_slice()),
        ("lambda2", t.lambda2.as_slice()),
        ("xc", t.commanded.x.as_slice()),
        ("dxc", t.commanded.dx.as_slice()),
        ("ddxc", t.commanded.ddx.as_slice()),
    ] {
        check::finite_slice(what, x)?;
        check::within(what, x, BOUND)?;
    }
    Ok(())
}

#[cfg(all(test, feature = "sim"))]
mod tests {
    use super::*;
    use crate::cartesian::chain::{Joint, Transform};
    use crate::cartesian::dynamics::Inertial;
    use crate::sim::model::{Manipulator, TwoLinkArm};
    use core::f64::consts::PI;

    /// The paper's arm (SPEC §1) as a chain with inertials: hinges about −y
    /// (the plane x–z, gravity −z), links along x.
    fn two_link() -> Dynamics<2> {
        let p = TwoLinkArm::paper();
        let pr = p.params();
        let inertial = |m: f64, lc: f64, i: f64| Inertial {
            mass: m,
            origin: Transform::from_xyz_rpy([lc, 0.0, 0.0], [0.0; 3]),
            inertia: [[i, 0.0, 0.0], [0.0, i, 0.0], [0.0, 0.0, i]],
        };
        let joints = [
            Joint::revolute(Transform::IDENTITY, [0.0, -1.0, 0.0]),
            Joint::revolute(
                Transform::from_xyz_rpy([pr.l1, 0.0, 0.0], [0.0; 3]),
                [0.0, -1.0, 0.0],
            ),
        ];
        let inertials = [
            inertial(pr.m1, pr.lc1, pr.i1),
            inertial(pr.m2, pr.lc2, pr.i2),
        ];
        Dynamics::new(&joints, &inertials, [0.0, 0.0, -pr.g]).unwrap()
    }

    #[test]
    fn the_chain_model_of_the_paper_arm_is_its_closed_form() {
        // D q̈ + C q̇ + G of SPEC (55)–(63) equals RNEA on the chain.
        let arm = TwoLinkArm::paper();
        let d = two_link();
        let q = Vector::<2>::new(0.4, -0.9);
        let dq = Vector::<2>::new(1.2, -0.5);
        let ddq = Vector::<2>::new(-2.0, 3.0);
        let closed = arm.inertia(&q) * ddq + arm.coriolis(&q, &dq) * dq + arm.gravity(&q);
        let rnea = d.inverse_dynamics(&q, &dq, &ddq);
        assert!((closed - rnea).amax() < 1e-12, "{closed} vs {rnea}");
    }

    #[test]
    fn with_the_exact_model_the_error_obeys_the_chosen_dynamics() {
        // Step the plant exactly (RK4 under the applied torque) and compare
        // the error with ë + K_D ė + K_P e = 0 from the same start.
        let arm = TwoLinkArm::paper();
        let ts = 1e-3;
        let mut cfg = ComputedTorqueConfig::new(ts, Vector::<2>::new(1e3, 1e3));
        cfg.mode = ImpedanceMode::External;
        let ct = ComputedTorque::new(cfg, two_link()).unwrap();
        let mut st = ComputedState::default();
        let c = Setpoint {
            x: Vector::<2>::new(0.5, 0.3),
            dx: Vector::zeros(),
            ddx: Vector::zeros(),
        };
        let (mut q, mut dq) = (Vector::<2>::new(0.45, 0.32), Vector::<2>::zeros());
        for _ in 0..2000 {
            let m = Measurement {
                x: q,
                dx: Some(dq),
                tau_e: Vector::zeros(),
            };
            let tau = ct.step(&mut st, &m, &c).unwrap().tau_sat;
            // Ten RK4 substeps of the plant under the held torque.
            let f = |q: &Vector<2>, dq: &Vector<2>| {
                (*dq, arm.forward_dynamics(q, dq, &tau, &Vector::zeros()))
            };
            let h = ts / 10.0;
            for _ in 0..10 {
                let (k1q, k1v) = f(&q, &dq);
                let (k2q, k2v) = f(&(q + 0.5 * h * k1q), &(dq + 0.5 * h * k1v));
                let (k3q, k3v) = f(&(q + 0.5 * h * k2q), &(dq + 0.5 * h * k2v));
                let (k4q, k4v) = f(&(q + h * k3q), &(dq + h * k3v));
                q += h / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
                dq += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            }
        }
        // ω = 20 rad/s critically damped: after 2 s the error is e⁻⁴⁰-small,
        // up to the sample-and-hold's residue.
        assert!((c.x - q).amax() < 1e-6, "{}", c.x - q);
        assert!(st.fault.is_none() && st.k == 2000);
    }

    /// RMS of x_c − q over t ≥ 1 s of 3 s tracking x_c = 0.2 sin(π t) with
    /// `ct` on the model's own plant stepped as MuJoCo's Euler does it: 4
    /// semi-implicit steps a period (q ← q + h q̇_{j+1}), the torque held.
    fn semi_implicit_tracking(ct: &ComputedTorque<2>) -> f64 {
        let model = ct.model();
        let (ts, s) = (1e-3, 4);
        let h = ts / f64::from(s);
        let mut st = ComputedState::default();
        let (mut q, mut dq) = (Vector::<2>::zeros(), Vector::<2>::new(0.2, 0.2) * PI);
        let (mut sum, mut rows) = (0.0, 0);
        for k in 0..3000 {
            let t = f64::from(k) * ts;
            let (sn, cs) = libm::sincos(PI * t);
            let c = Setpoint {
                x: Vector::from_element(0.2 * sn),
                dx: Vector::from_element(0.2 * PI * cs),
                ddx: Vector::from_element(-0.2 * PI * PI * sn),
            };
            if t >= 1.0 {
                sum += (c.x - q).norm_squared();
                rows += 1;
            }
            let m = Measurement {
                x: q,
                dx: Some(dq),
                tau_e: Vector::zeros(),
            };
            let tau = ct.step(&mut st, &m, &c).unwrap().tau_sat;
            for _ in 0..s {
                let bias = model.inverse_dynamics(&q, &dq, &Vector::zeros());
                let a = model.mass_matrix(&q).lu().solve(&(tau - bias)).unwrap();
                dq += h * a;
                q += h * dq;
            }
        }
        (sum / f64::from(rows)).sqrt()
    }

    #[test]
    fn a_semi_implicit_plants_velocity_is_compared_half_a_step_back() {
        // (20.9'): on a plant stepped semi-implicitly the measured velocity is
        // the continuous one h/2 back; compared with the reference's at the
        // same instant the error falls from −K_D (h/2) ẍ_d / K_P to what the
        // torque held over the period leaves (2.5e-5 → 7.1e-6 rad measured).
        use crate::cartesian::dynamics::SampledDrive;
        let mut cfg = ComputedTorqueConfig::new(1e-3, Vector::<2>::new(1e3, 1e3));
        cfg.mode = ImpedanceMode::External;
        let drive = SampledDrive {
            substep: 2.5e-4,
            substeps: 4,
            implicit_damping: true,
            semi_implicit: true,
            regularisation: Vector::zeros(),
            rate: Vector::zeros(),
        };
        let with = |semi_implicit| {
            let model = two_link()
                .with_sampled_drive(SampledDrive {
                    semi_implicit,
                    ..drive
                })
                .unwrap();
            semi_implicit_tracking(&ComputedTorque::new(cfg, model).unwrap())
        };
        let (lagged, plain) = (with(true), with(false));
        assert!(plain > 1e-5, "{plain}");
        assert!(lagged < 0.35 * plain, "{lagged} vs {plain}");
    }

    #[test]
    fn the_drive_enters_the_law_and_its_friction_is_compensated() {
        // (20.3) with (20.5), (20.6): the same step with and without a drive
        // differs by I_a ⊙ a + b ⊙ q̇ + F ⊙ tanh(v / v_s) (external mode: v the
        // slower of ẋ_c and q̇ where they agree in sign, else 0).
        use crate::cartesian::dynamics::{Drive, FRICTION_VELOCITY};
        let drive = Drive {
            armature: Vector::<2>::new(0.2, 0.1),
            damping: Vector::<2>::new(0.5, 0.3),
            friction: Vector::<2>::new(1.5, 0.7),
        };
        let mut cfg = ComputedTorqueConfig::new(1e-3, Vector::<2>::new(1e3, 1e3));
        cfg.mode = ImpedanceMode::External;
        let rigid = ComputedTorque::new(cfg, two_link()).unwrap();
        let driven = ComputedTorque::new(cfg, two_link().with_drive(drive).unwrap()).unwrap();
        let c = Setpoint {
            x: Vector::<2>::new(0.5, 0.3),
            dx: Vector::<2>::new(0.02, -0.004),
            ddx: Vector::<2>::new(0.3, -0.1),
        };
        let m = Measurement {
            x: Vector::<2>::new(0.48, 0.31),
            dx: Some(Vector::<2>::new(0.1, 0.2)),
            tau_e: Vector::zeros(),
        };
        let step =
            |ct: &ComputedTorque<2>| ct.step(&mut ComputedState::default(), &m, &c).unwrap().tau;
        let dq = m.dx.unwrap();
        let a = c.ddx + cfg.kd.component_mul(&(c.dx - dq)) + cfg.kp.component_mul(&(c.x - m.x));
        let want = drive.armature.component_mul(&a)
            + drive.damping.component_mul(&dq)
            // Joint 0 moves with its reference (the slower: ẋ_c), joint 1 against it.
            + Vector::<2>::new(
                drive.friction[0] * libm::tanh(c.dx[0] / FRICTION_VELOCITY),
                0.0,
            );
        let got = step(&driven) - step(&rigid);
        assert!((got - want).amax() < 1e-12, "{got} vs {want}");
    }

    #[test]
    fn a_missing_velocity_is_refused_and_the_torque_held() {
        let ct = ComputedTorque::new(
            ComputedTorqueConfig::new(1e-3, Vector::<2>::new(17.0, 15.0)),
            two_link(),
        )
        .unwrap();
        let mut st = ComputedState::default();
        let c = Setpoint {
            x: Vector::<2>::new(0.5, 0.3),
            dx: Vector::zeros(),
            ddx: Vector::zeros(),
        };
        let m = Measurement {
            x: c.x,
            dx: Some(Vector::zeros()),
            tau_e: Vector::zeros(),
        };
        let held = ct.step(&mut st, &m, &c).unwrap().tau_sat;
        let e = ct
            .step(&mut st, &Measurement { dx: None, ..m }, &c)
            .unwrap_err();
        assert_eq!(e, Error::MissingVelocity);
        assert_eq!(st.applied, held);
        assert_eq!(st.fault.map(|f| f.step), Some(1));
        assert_eq!(st.k, 1);
        let bad = ComputedTorqueConfig {
            kp: Vector::<2>::new(1.0, -1.0),
            ..ComputedTorqueConfig::new(1e-3, Vector::<2>::new(17.0, 15.0))
        };
        let e = ComputedTorque::new(bad, two_link()).unwrap_err();
        assert!(e.to_string().contains("Kp > 0"), "{e}");
    }
}
