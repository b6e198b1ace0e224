//! The run-time API (`adaptimp::dynamic`) against the const-generic core
//! it wraps: the same bits, step for step, for every n = 1 … 7 (the
//! controller, the Cartesian controller, the chain, the dynamics, computed
//! torque, the closed loop), and the same errors.

mod common;
use adaptimp::control::tuning::Rule;
use adaptimp::dynamic as dy;
use adaptimp::schema::{Preset, Scenario, Value};
use adaptimp::{
    AnyBasis, Basis, CartesianController, CartesianImpedance, CartesianMeasurement, Chain, Command,
    ComputedState, ComputedTorque, ComputedTorqueConfig, Controller, Dynamics, Error,
    ImpedanceMode, Inertial, Joint, Kinematics, Law, Measurement, PoseTarget, Setpoint, Sinusoid,
    Trajectory, Transform, Vector,
};
use common::{bits, joints, q_of};

/// `a` and `b` hold the same bits.
#[track_caller]
fn same(what: &str, a: &[f64], b: &[f64]) {
    assert_eq!(bits(a), bits(b), "{what}: {a:?} ≠ {b:?}");
}

/// A run-time command equals the core's, bit for bit.
#[track_caller]
fn same_command<const N: usize>(d: &dy::Command, c: &Command<N>) {
    for (what, a, b) in [
        ("tau_sat", &d.tau_sat, &c.tau_sat),
        ("tau", &d.tau, &c.tau),
        ("dtau", &d.dtau, &c.dtau),
        ("z1", &d.z1, &c.z1),
        ("z2", &d.z2, &c.z2),
        ("xc", &d.xc, &c.xc),
        ("xd", &d.xd, &c.xd),
        ("v", &d.v, &c.v),
        ("zeta", &d.zeta, &c.zeta),
    ] {
        same(what, a, b.as_slice());
    }
    same("w_norms", &d.w_norms, &c.w_norms);
}

/// The parameters both sides are given for N joints: a sinusoid of N
/// joints, the limits of a robot's and the learning on.
fn items<const N: usize>() -> Vec<(&'static str, Vec<f64>)> {
    let j = |f: fn(usize) -> f64| (0..N).map(f).collect::<Vec<f64>>();
    vec![
        ("xc_offset", j(|i| 0.1 * i as f64 - 0.2)),
        ("xc_sin", j(|i| 0.1 + 0.02 * i as f64)),
        ("xc_cos", j(|_| 0.0)),
        ("xc_omega", j(|i| 1.0 + 0.3 * i as f64)),
        ("tau_max", j(|i| 40.0 - 4.0 * i as f64)),
    ]
}

fn scenario<const N: usize>(law: Law, external: bool) -> (dy::Scenario, Scenario<N>) {
    let mut d = dy::Scenario::new(N, Preset::Robot, law).expect("n");
    let mut s = Scenario::<N>::preset(Preset::Robot, law);
    for (name, v) in items::<N>() {
        d.set(name, Value::Vec(&v)).expect(name);
        s.set(name, Value::Vec(&v)).expect(name);
    }
    if external {
        d.set("impedance", Value::Str("external"))
            .expect("impedance");
        s.set("impedance", Value::Str("external"))
            .expect("impedance");
    }
    (d, s)
}

/// The core's controller of `s`, with the basis the run-time builder
/// decides: the grid for n ≤ 3, the rule's default basis beyond.
fn core_controller<const N: usize>(s: &Scenario<N>) -> (Controller<N, AnyBasis<N>>, Sinusoid<N>) {
    let traj = s.trajectory().expect("trajectory");
    let basis = if N <= 3 {
        AnyBasis::Grid(s.grid().expect("grid"))
    } else {
        AnyBasis::Centers(Rule::default().default_basis(&traj).expect("basis"))
    };
    let ctrl = Controller::for_trajectory(s.config, basis, &traj).expect("controller");
    (ctrl, traj)
}

/// The measurement of step k near the trajectory (a NaN at `bad`).
fn measurement<const N: usize>(traj: &Sinusoid<N>, k: usize, bad: usize) -> Measurement<N> {
    let t = k as f64 * 1e-3;
    let c = traj.sample(t);
    let mut x = c.x + Vector::<N>::from_fn(|i, _| 0.01 * (3.0 * t + i as f64).sin());
    if k == bad {
        x[N - 1] = f64::NAN;
    }
    Measurement {
        x,
        dx: Some(c.dx * 0.9),
        tau_e: Vector::from_fn(|i, _| if i == 0 { 2.0 * (t * 5.0).sin() } else { 0.0 }),
    }
}

fn joint_controller<const N: usize>(law: Law) {
    let (d, s) = scenario::<N>(law, false);
    let dc = d.controller().expect("run-time controller");
    let (cc, traj) = core_controller(&s);
    assert_eq!((dc.n(), dc.nodes(), dc.law()), (N, cc.basis().nodes(), law));
    let (mut ds, mut cs) = (dc.new_state(), cc.new_state());
    for k in 0..200 {
        let m = measurement(&traj, k, 120);
        let dm = dy::Measurement {
            x: m.x.as_slice(),
            dx: m.dx.as_ref().map(|v| v.as_slice()),
            tau_e: m.tau_e.as_slice(),
        };
        // Every third step with a setpoint of the caller's, else its own.
        let given = traj.sample(k as f64 * 1e-3 + 1e-4);
        let (a, b) = if k % 3 == 0 {
            let sp = dy::Setpoint {
                x: given.x.as_slice(),
                dx: given.dx.as_slice(),
                ddx: given.ddx.as_slice(),
            };
            (
                dc.step_or_fallback(&mut ds, &dm, Some(&sp)),
                cc.step_or_fallback(&mut cs, &m, &given),
            )
        } else {
            let own = traj.sample(cc.time(&cs));
            (
                dc.step_or_fallback(&mut ds, &dm, None),
                cc.step_or_fallback(&mut cs, &m, &own),
            )
        };
        same("applied", &a.0.expect("same n"), b.0.as_slice());
        match (a.1, b.1) {
            (Ok(x), Ok(y)) => same_command(&x, &y),
            (Err(x), Err(y)) => assert_eq!(x, y, "step {k}"),
            (x, y) => panic!("step {k}: {x:?} against {y:?}"),
        }
    }
    assert!(ds.fault().is_some(), "the NaN step was refused");
    assert_eq!(ds.fault(), cs.fault());
    same("zeta", ds.zeta(), cs.zeta().as_slice());
    let mut snap = vec![0.0; cs.snapshot_len()];
    cs.save(&mut snap).expect("save");
    let mut dsnap = vec![0.0; ds.snapshot_len()];
    ds.save(&mut dsnap).expect("save");
    same("snapshot", &dsnap, &snap);
    // The typed accessors reach this very controller and state: a typed
    // step from them is the run-time step, bit for bit, and another N is none.
    let (tc, tt) = dc.typed::<N>().expect("typed for its own N");
    assert_eq!(tt.sample(0.37).x, traj.sample(0.37).x);
    let other = if N == 1 {
        dc.typed::<2>().is_none() && ds.typed::<2>().is_none()
    } else {
        dc.typed::<1>().is_none() && ds.typed::<1>().is_none()
    };
    assert!(other, "no typed view for another N");
    let mut copy = ds.clone();
    let m = measurement(&traj, 7, usize::MAX);
    let own = traj.sample(cc.time(&cs));
    let typed = tc
        .step(copy.typed_mut::<N>().expect("typed state"), &m, &own)
        .expect("typed step");
    let reference = cc.step(&mut cs, &m, &own).expect("const-generic step");
    same("typed tau", typed.tau.as_slice(), reference.tau.as_slice());
    let back = copy.typed::<N>().expect("typed state");
    same("typed zeta", back.zeta().as_slice(), cs.zeta().as_slice());
}

#[test]
fn the_joint_step_is_the_const_generic_one_bit_for_bit_for_every_n() {
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        joint_controller::<1>(law);
        joint_controller::<2>(law);
        joint_controller::<3>(law);
        joint_controller::<4>(law);
        joint_controller::<5>(law);
        joint_controller::<6>(law);
        joint_controller::<7>(law);
    }
}

#[test]
fn the_joint_step_refuses_inputs_of_another_length_by_name_and_records_it() {
    let (d, _) = scenario::<3>(Law::Pd, false);
    let c = d.controller().expect("controller");
    let mut st = c.new_state();
    let m = dy::Measurement {
        x: &[0.0; 2],
        dx: Some(&[0.0; 3]),
        tau_e: &[0.0; 3],
    };
    let e = c.step(&mut st, &m, None).unwrap_err();
    assert_eq!(
        e.to_string(),
        "x: needs one value per joint (as many as the controller has)"
    );
    assert_eq!(st.fault().map(|f| f.error), Some(e));
    // A state of another controller is refused and left as it was.
    let (d2, _) = scenario::<2>(Law::Pd, false);
    let mut other = d2.controller().expect("controller").new_state();
    let m = dy::Measurement {
        x: &[0.0; 3],
        dx: Some(&[0.0; 3]),
        tau_e: &[0.0; 3],
    };
    let e = c.step(&mut other, &m, None).unwrap_err();
    assert_eq!(
        e.to_string(),
        "state: was made for another number of joints"
    );
    assert_eq!(other.steps(), 0);
    assert!(other.fault().is_none());
    let e = dy::Scenario::new(8, Preset::Robot, Law::Pd).unwrap_err();
    assert_eq!(
        e.to_string(),
        "condition 1 ≤ n ≤ 7 joints is violated: n = 8 (SPEC §10)"
    );
}

#[test]
fn one_builder_gives_both_fronts_the_same_basis() {
    // n > 3 without centres: the rule's default basis (SPEC §18), not an error.
    let (d, s) = scenario::<5>(Law::StateFeedback, false);
    let (cc, _) = core_controller(&s);
    assert_eq!(d.controller().expect("n = 5").nodes(), cc.basis().nodes());
    // The grid asked for beyond n = 3 is the grid's error.
    let mut d = d;
    let e = d.basis(dy::Basis::Grid).controller().unwrap_err();
    assert_eq!(e, s.grid().unwrap_err());
    // Centres without widths take η² everywhere; widths of another length are refused.
    let rows = vec![0.0; 2 * 4 * 5];
    d.basis(dy::Basis::Centres(dy::Centres {
        rows: rows.clone(),
        widths2: None,
    }));
    assert_eq!(d.controller().expect("centres").nodes(), 2);
    d.basis(dy::Basis::Centres(dy::Centres {
        rows,
        widths2: Some(vec![1.0; 4]),
    }));
    assert_eq!(
        d.controller().unwrap_err().to_string(),
        "widths: need one width per input dimension (4n: x, v, α1, α̇1)"
    );
}

fn chain_and_dynamics<const N: usize>() {
    let js = joints::<N>();
    let tip = Transform::from_xyz_rpy([0.0, 0.02, 0.05], [0.0; 3]);
    let (dc, cc) = (
        dy::Chain::new(&js, &tip).expect("run-time chain"),
        Chain::<N>::new(&js, &tip).expect("chain"),
    );
    for k in 0..5 {
        let (q, dq) = (q_of::<N>(k), q_of::<N>(k + 10));
        let (a, b) = (
            dc.tip(q.as_slice(), dq.as_slice()).expect("tip"),
            cc.tip_checked(&q, &dq).expect("tip"),
        );
        same("position", a.position.as_slice(), b.position.as_slice());
        same(
            "rotation",
            a.rotation.matrix().as_slice(),
            b.rotation.matrix().as_slice(),
        );
        let j = a.jacobian.matrix().iter().copied().collect::<Vec<_>>();
        same("jacobian", &j, b.jacobian.as_slice());
        same("bias", a.bias.as_slice(), b.bias.as_slice());
        let (p, r) = dc.pose(q.as_slice()).expect("pose");
        let (p2, r2) = cc.pose(&q);
        same("pose", p.as_slice(), p2.as_slice());
        same("pose R", r.matrix().as_slice(), r2.matrix().as_slice());
        let j = dc.jacobian(q.as_slice()).expect("jacobian");
        let j = j.matrix().iter().copied().collect::<Vec<_>>();
        same("jacobian(q)", &j, cc.pose_jacobian(&q).jacobian.as_slice());
        same(
            "bias(q, dq)",
            dc.bias(q.as_slice(), dq.as_slice())
                .expect("bias")
                .as_slice(),
            cc.bias(&q, &dq).as_slice(),
        );
    }
    let mut bad = q_of::<N>(0);
    bad[0] = f64::NAN;
    assert_eq!(
        dc.tip(bad.as_slice(), bad.as_slice()).unwrap_err(),
        cc.tip_checked(&bad, &bad).unwrap_err()
    );
    // The dynamics, with a drive.
    // One inertial per joint of the list, the fixed one's too.
    let inertials: Vec<Inertial> = (0..=N)
        .map(|i| Inertial::point(1.0 + 0.1 * i as f64, [0.02, 0.01, 0.06]))
        .collect();
    let g = adaptimp::GRAVITY;
    let drive = [0.1; N];
    // Gravity compensation (SPEC (20.1')): a share of each link lifted.
    let lifted: Vec<adaptimp::cartesian::Lifted> = (0..=N)
        .map(|i| adaptimp::cartesian::Lifted {
            mass: 0.3 + 0.05 * i as f64,
            moment: [0.01, -0.02, 0.03 * i as f64],
        })
        .collect();
    let dd = dy::Dynamics::new(&js, &inertials, g)
        .and_then(|d| d.with_gravity_compensation(&js, &lifted))
        .and_then(|d| {
            d.with_drive(&dy::Drive {
                armature: &drive,
                damping: &drive,
                friction: &drive,
            })
        })
        .expect("run-time dynamics");
    let cd = Dynamics::<N>::new(&js, &inertials, g)
        .and_then(|d| d.with_gravity_compensation(&js, &lifted))
        .and_then(|d| {
            d.with_drive(adaptimp::Drive {
                armature: Vector::from(drive),
                damping: Vector::from(drive),
                friction: Vector::from(drive),
            })
        })
        .expect("dynamics");
    assert_eq!(dd.mass().to_bits(), cd.mass().to_bits());
    for k in 0..5 {
        let (q, dq, ddq) = (q_of::<N>(k), q_of::<N>(k + 3), q_of::<N>(k + 6));
        same(
            "inverse dynamics",
            &dd.inverse_dynamics(q.as_slice(), dq.as_slice(), ddq.as_slice())
                .expect("id"),
            cd.inverse_dynamics_checked(&q, &dq, &ddq)
                .expect("id")
                .as_slice(),
        );
        let m = dd.mass_matrix(q.as_slice()).expect("M");
        let m = m.matrix().iter().copied().collect::<Vec<_>>();
        same("mass matrix", &m, cd.mass_matrix(&q).as_slice());
        same(
            "gravity",
            &dd.gravity_torque(q.as_slice()).expect("G"),
            cd.gravity_torque(&q).as_slice(),
        );
    }
    // The compensation is there: the lifted share's weight is off G (where
    // the arm bears any: a first joint about the vertical bears none).
    let plain = dy::Dynamics::new(&js, &inertials, g).expect("plain");
    let q = q_of::<N>(1);
    let bare = plain.gravity_torque(q.as_slice()).expect("G");
    if bare.iter().any(|x| x.abs() > 1e-9) {
        assert_ne!(
            bits(&bare),
            bits(&dd.gravity_torque(q.as_slice()).expect("G"))
        );
    }
    // Computed torque on that model (SPEC §20).
    let tau_max = [30.0; N];
    let (kp, kd, ones) = ([400.0; N], [40.0; N], [1.0; N]);
    let dct = dy::ComputedTorque::new(
        &dy::ComputedTorqueConfig {
            ts: 1e-3,
            kp: &kp,
            kd: &kd,
            tau_max: &tau_max,
            dd: &ones,
            cd: &[20.0; N],
            gd: &[100.0; N],
            mode: ImpedanceMode::Joint,
        },
        dd,
    )
    .expect("run-time computed torque");
    let cct = ComputedTorque::new(
        ComputedTorqueConfig {
            ts: 1e-3,
            kp: Vector::from(kp),
            kd: Vector::from(kd),
            tau_max: Vector::from(tau_max),
            impedance: adaptimp::TargetImpedance::new(
                Vector::from(ones),
                Vector::from_element(20.0),
                Vector::from_element(100.0),
            )
            .expect("impedance"),
            mode: ImpedanceMode::Joint,
        },
        cd,
    )
    .expect("computed torque");
    let (mut ds, mut cs) = (dct.new_state(), ComputedState::default());
    for k in 0..100 {
        let (q, dq) = (q_of::<N>(k), q_of::<N>(k + 1));
        let c = Setpoint {
            x: q_of::<N>(k + 2),
            dx: q_of::<N>(k + 3),
            ddx: q_of::<N>(k + 4),
        };
        let m = Measurement {
            x: q,
            dx: (k != 50).then_some(dq),
            tau_e: Vector::zeros(),
        };
        let a = dct.step(
            &mut ds,
            &dy::Measurement {
                x: q.as_slice(),
                dx: m.dx.as_ref().map(|v| v.as_slice()),
                tau_e: &[0.0; N],
            },
            &dy::Setpoint {
                x: c.x.as_slice(),
                dx: c.dx.as_slice(),
                ddx: c.ddx.as_slice(),
            },
        );
        match (a, cct.step(&mut cs, &m, &c)) {
            (Ok(x), Ok(y)) => same_command(&x, &y),
            (Err(x), Err(y)) => assert_eq!(x, y),
            (x, y) => panic!("{x:?} against {y:?}"),
        }
    }
    assert_eq!(ds.fault(), cs.fault);
    assert_eq!(ds.fault().map(|f| f.error), Some(Error::MissingVelocity));
}

#[test]
fn the_chain_dynamics_and_computed_torque_are_the_const_generic_ones_bit_for_bit() {
    chain_and_dynamics::<1>();
    chain_and_dynamics::<2>();
    chain_and_dynamics::<3>();
    chain_and_dynamics::<4>();
    chain_and_dynamics::<5>();
    chain_and_dynamics::<6>();
    chain_and_dynamics::<7>();
}

/// The commanded pose of step k: a small circle about `p0`, `r0` held.
fn target(p0: &Vector<3>, r0: &nalgebra::Matrix3<f64>, k: usize) -> PoseTarget {
    let t = k as f64 * 1e-3;
    let (s, c) = ((3.0 * t).sin(), (3.0 * t).cos());
    PoseTarget {
        p: p0 + Vector::<3>::new(0.01 * (c - 1.0), 0.01 * s, 0.0),
        dp: Vector::<3>::new(-0.03 * s, 0.03 * c, 0.0),
        ..PoseTarget::at(*p0, *r0)
    }
}

fn cartesian<const N: usize>() {
    let js = joints::<N>();
    let tip = Transform::IDENTITY;
    let (d, s) = scenario::<N>(Law::StateFeedback, true);
    let (cc, _) = core_controller(&s);
    let chain = Chain::<N>::new(&js, &tip).expect("chain");
    let outer = CartesianImpedance::new(s.cartesian, chain, cc.period()).expect("outer");
    let pair = CartesianController::new(outer, cc).expect("pair");
    let dchain = dy::Chain::new(&js, &tip).expect("chain");
    let douter = dy::CartesianImpedance::new(d.cartesian(), &dchain, 1e-3).expect("outer");
    let dpair = dy::CartesianController::new(douter, d.controller().expect("joint")).expect("pair");
    let q0 = q_of::<N>(0);
    let (mut ost, mut ist) = (pair.start(&q0).expect("start"), pair.inner().new_state());
    let (mut dost, mut dist) = (
        dpair.start(q0.as_slice()).expect("start"),
        dpair.joint().new_state(),
    );
    let t0 = chain.tip(&q0, &Vector::zeros());
    for k in 0..150 {
        let q = q0 + Vector::<N>::from_element(1e-3 * (k as f64 * 0.01).sin());
        let wrench = Vector::<6>::new(1.0, -0.5, 0.2, 0.0, 0.05, 0.0);
        let m = CartesianMeasurement {
            q,
            dq: Some(Vector::from_element(1e-3)),
            wrench: if k == 90 { wrench * f64::NAN } else { wrench },
        };
        let dm = dy::CartesianMeasurement {
            q: m.q.as_slice(),
            dq: m.dq.as_ref().map(|v| v.as_slice()),
            wrench: m.wrench,
        };
        let c = (k % 4 != 3).then(|| target(&t0.position, t0.rotation.matrix(), k));
        let a = dpair.step_or_fallback(&mut dost, &mut dist, &dm, c.as_ref());
        let b = pair.step_or_fallback(&mut ost, &mut ist, &m, c.as_ref());
        same("applied", &a.0.expect("same n"), b.0.as_slice());
        match (a.1, b.1) {
            (Ok(x), Ok(y)) => {
                same_command(&x.joint, &y.joint);
                same("q_d", &x.reference.x, y.reference.x.as_slice());
                same("ddq_d", &x.reference.ddx, y.reference.ddx.as_slice());
                same("q_c", &x.commanded.x, y.commanded.x.as_slice());
                same("p_d", x.compliant.p.as_slice(), y.compliant.p.as_slice());
                same("error", x.error.as_slice(), y.error.as_slice());
                same("tau_e", &x.tau_e, y.tau_e.as_slice());
                assert_eq!(x.compliant, y.compliant);
                assert_eq!((x.p, x.r, x.target), (y.p, y.r, y.target));
            }
            (Err(x), Err(y)) => assert_eq!(x, y, "step {k}"),
            (x, y) => panic!("step {k}: {x:?} against {y:?}"),
        }
    }
    assert!(dist.fault().is_some(), "the NaN wrench was refused");
    assert_eq!(dist.fault(), ist.fault());
    assert_eq!(dost.steps(), ost.k);
    // A joint law of the caller's (`step_with`): the core's joint step on
    // what it is given gives the pair's torque.
    let (cc2, _) = core_controller(&s);
    let mut st2 = cc2.new_state();
    let douter = dy::CartesianImpedance::new(d.cartesian(), &dchain, 1e-3).expect("outer");
    let mut dost = douter.start(q0.as_slice()).expect("start");
    let (mut ost, mut ist) = (pair.start(&q0).expect("start"), pair.inner().new_state());
    for k in 0..50 {
        let q = q0 + Vector::<N>::from_element(1e-3);
        let m = CartesianMeasurement {
            q,
            dq: Some(Vector::zeros()),
            wrench: Vector::<6>::new(0.5, 0.0, 0.0, 0.0, 0.0, 0.0),
        };
        let c = target(&t0.position, t0.rotation.matrix(), k);
        let want = pair.step(&mut ost, &mut ist, &m, Some(&c)).expect("step");
        let dm = dy::CartesianMeasurement {
            q: m.q.as_slice(),
            dq: Some(&[0.0; N]),
            wrench: m.wrench,
        };
        let got = douter
            .step_with(&mut dost, &dm, Some(&c), |input| {
                let meas = Measurement {
                    x: Vector::from_column_slice(input.measurement.x),
                    dx: input.measurement.dx.map(Vector::from_column_slice),
                    tau_e: Vector::from_column_slice(input.measurement.tau_e),
                };
                let r = Setpoint {
                    x: Vector::from_column_slice(input.reference.x),
                    dx: Vector::from_column_slice(input.reference.dx),
                    ddx: Vector::from_column_slice(input.reference.ddx),
                };
                let cmd = cc2.step(&mut st2, &meas, &r)?;
                dy::Joints::from_slice(cmd.tau_sat.as_slice())
            })
            .expect("step_with");
        same(
            "tau of step_with",
            &got.joint.tau_sat,
            want.joint.tau_sat.as_slice(),
        );
        same(
            "q_d of step_with",
            &got.reference.x,
            want.reference.x.as_slice(),
        );
    }
}

#[test]
fn the_cartesian_step_is_the_const_generic_one_bit_for_bit_for_every_n() {
    cartesian::<1>();
    cartesian::<2>();
    cartesian::<3>();
    cartesian::<4>();
    cartesian::<5>();
    cartesian::<6>();
    cartesian::<7>();
}

/// Task rows a loop of its own records from the const-generic outer loop's
/// steps (as the Python front's MuJoCo loop does): a row before any step is
/// NaN, a step's row holds its commanded, compliant and joint references,
/// its error, wrench and z1 bit for bit, and only every `every`-th row is
/// kept.
fn task_rows<const N: usize>() {
    let js = joints::<N>();
    let (_, s) = scenario::<N>(Law::StateFeedback, true);
    let (cc, _) = core_controller(&s);
    let chain = Chain::<N>::new(&js, &Transform::IDENTITY).expect("chain");
    let outer = CartesianImpedance::new(s.cartesian, chain, cc.period()).expect("outer");
    let pair = CartesianController::new(outer, cc).expect("pair");
    let q0 = q_of::<N>(0);
    let (mut ost, mut ist) = (pair.start(&q0).expect("start"), pair.inner().new_state());
    let t0 = chain.tip(&q0, &Vector::zeros());
    let mut rows = dy::TaskRows::new(N, 3, 2).expect("rows");
    assert_eq!((rows.n(), rows.len()), (N, 0));
    rows.record(None, &Vector::<3>::from_element(f64::NAN));
    let mut steps = Vec::new();
    for k in 0..4 {
        let m = CartesianMeasurement {
            q: q0 + Vector::<N>::from_element(1e-3 * k as f64),
            dq: Some(Vector::from_element(1e-3)),
            wrench: Vector::<6>::new(1.0, -0.5, 0.2, 0.0, 0.05, 0.0),
        };
        let c = target(&t0.position, t0.rotation.matrix(), k);
        let cmd = pair.step(&mut ost, &mut ist, &m, Some(&c)).expect("step");
        let step = dy::TaskStep {
            command: dy::CartesianCommand::of(&cmd),
            commanded: [c.p, c.dp, c.ddp],
            wrench: m.wrench.into(),
        };
        same("q_d", &step.command.reference.x, cmd.reference.x.as_slice());
        let z1 = cmd.compliant.p - cmd.p;
        same("z1", step.z1().as_slice(), z1.as_slice());
        rows.record(Some(&step), &step.z1());
        steps.push(step);
    }
    // Rows 0 (before any step), 2 and 4 of five, every second kept.
    assert_eq!(rows.len(), 3);
    assert!(rows.pc.iter().chain(&rows.pd).all(|v| v.len() == 9));
    assert_eq!((rows.qd.len(), rows.error.len()), (3 * N, 18));
    let nan = |v: &[f64]| v.iter().all(|x| x.is_nan());
    assert!(nan(&rows.pc[0][..3]) && nan(&rows.pd[2][..3]) && nan(&rows.z1[..3]));
    assert!(nan(&rows.qd[..N]) && nan(&rows.error[..6]) && nan(&rows.wrench[..6]));
    for (row, s) in [(1, &steps[1]), (2, &steps[3])] {
        let (c, cp) = (&s.command, &s.command.compliant);
        for (i, v) in s.commanded.iter().enumerate() {
            same("p_c", &rows.pc[i][3 * row..3 * row + 3], v.as_slice());
        }
        for (i, v) in [&cp.p, &cp.dp, &cp.ddp].into_iter().enumerate() {
            same("p_d", &rows.pd[i][3 * row..3 * row + 3], v.as_slice());
        }
        same("q_d", &rows.qd[N * row..N * row + N], &c.reference.x);
        same(
            "error",
            &rows.error[6 * row..6 * row + 6],
            c.error.as_slice(),
        );
        same("wrench", &rows.wrench[6 * row..6 * row + 6], &s.wrench);
        same("z1", &rows.z1[3 * row..3 * row + 3], s.z1().as_slice());
    }
}

#[test]
fn task_rows_record_the_steps_of_a_loop_of_its_own() {
    task_rows::<2>();
    task_rows::<7>();
}

/// The closed loop of the paper's arm and wall with disturbances and a
/// fault, through the run-time plant and loop, against the core's
/// `run_disturbed_with`: the same rows and metrics.
#[test]
fn the_closed_loop_is_the_const_generic_one_bit_for_bit() {
    use adaptimp::sim::simulator::run_disturbed_with;
    use adaptimp::{Injected, Injection, Row, TwoLinkArm, Wall};
    let law = Law::StateFeedback;
    let settings = [
        ("T", Value::Real(0.3)),
        ("noise_q", Value::Real(1e-4)),
        ("payload", Value::Real(0.2)),
        ("friction_viscous", Value::Real(0.3)),
        ("delay", Value::Int(2)),
    ];
    let mut d = dy::Scenario::new(2, Preset::Paper, law).expect("n");
    let mut s = Scenario::<2>::preset(Preset::Paper, law);
    for (name, v) in settings {
        d.set(name, v).expect(name);
        s.set(name, v).expect(name);
    }
    // The core's run.
    struct Rows(Vec<Row<2>>);
    impl adaptimp::Recorder<2> for Rows {
        fn record(&mut self, r: &Row<2>) {
            self.0.push(*r);
        }
    }
    let ctrl = Controller::for_trajectory(s.config, s.grid().unwrap(), &s.trajectory().unwrap())
        .expect("controller");
    let mut state = ctrl.new_state();
    let arm = TwoLinkArm::paper();
    let wall = Wall::<2>::new(0, s.wall.unwrap(), s.ke_be[0], s.ke_be[1]).unwrap();
    let dist = s.disturbances().unwrap();
    let inj = Injection {
        fault: Injected::Stale,
        start: 0.1,
        duration: 0.02,
    };
    let mut rows = Rows(Vec::new());
    let metrics = run_disturbed_with(
        &arm,
        &wall,
        &mut ctrl.bind(&mut state),
        &s.trajectory().unwrap(),
        &s.sim,
        &dist,
        Some(&inj),
        &mut (),
        &mut rows,
    )
    .expect("core run");
    // The run-time one.
    let dc = d.controller().expect("controller");
    let mut ds = dc.new_state();
    let ddist = d.disturbances().expect("disturbances");
    let mut plant = dy::RigidBody::new(&dy::ModelArm::Paper(arm), &d, &ddist).expect("plant");
    let (t_final, settle, _) = d.run_settings();
    let dinj = dy::Injection {
        fault: dy::Injected::Stale,
        start: 0.1,
        duration: 0.02,
    };
    let run = dy::Run {
        t_final,
        settle,
        every: 1,
        disturbances: Some(&ddist),
        injection: Some(&dinj),
    };
    let mut drows = dy::Rows::for_run(2, &run, dc.period()).expect("rows");
    let dmetrics = dy::simulate(
        &mut plant,
        dy::Controlled::Joint(dy::Joint::Adaptive(&dc, &mut ds)),
        dy::Reference::Trajectory,
        &run,
        &mut (),
        &mut drows,
    )
    .expect("run-time run");
    assert_eq!(drows.len(), rows.0.len());
    assert!(drows.refused.iter().any(|r| *r) || rows.0.iter().all(|r| !r.refused));
    let col = |f: fn(&Row<2>) -> Vector<2>| -> Vec<f64> {
        rows.0
            .iter()
            .flat_map(|r| f(r).iter().copied().collect::<Vec<_>>())
            .collect()
    };
    same("x", &drows.x, &col(|r| r.x));
    same("ddx", &drows.ddx, &col(|r| r.ddx));
    same("tau_sat", &drows.tau_sat, &col(|r| r.tau_sat));
    same("tau_e", &drows.tau_e, &col(|r| r.tau_e));
    same("z1", &drows.z1, &col(|r| r.z1));
    same("zeta", &drows.zeta, &col(|r| r.zeta));
    assert_eq!(
        drows.refused,
        rows.0.iter().map(|r| r.refused).collect::<Vec<_>>()
    );
    same(
        "metrics",
        &[
            dmetrics.rms_z1,
            dmetrics.rms_z1_after2,
            dmetrics.sat_duty,
            dmetrics.imp_err_rms_after2,
            dmetrics.peak_contact_after2,
        ],
        &[
            metrics.rms_z1,
            metrics.rms_z1_after2,
            metrics.sat_duty,
            metrics.imp_err_rms_after2,
            metrics.peak_contact_after2,
        ],
    );
    same(
        "peak τ",
        &dmetrics.peak_abs_tau,
        metrics.peak_abs_tau.as_slice(),
    );
    assert_eq!(ds.steps(), state.steps());
    // The typed run: the same rows and metrics, its rows sized by itself.
    let mut ds2 = dc.new_state();
    let mut plant2 = dy::RigidBody::new(&dy::ModelArm::Paper(arm), &d, &ddist).expect("plant");
    let out = dy::run(dy::Spec {
        plant: &mut plant2,
        looped: dy::Loop::Joint {
            ctrl: dy::Controlled::Joint(dy::Joint::Adaptive(&dc, &mut ds2)),
            reference: dy::Reference::Trajectory,
        },
        run,
        hooks: None,
    });
    same_rows(&out.rows, &drows);
    assert!(out.task.is_none());
    same_metrics(&out.ended.expect("typed run"), &dmetrics);
    // The rows fed back, as a loop in another language gives them: the
    // same metrics, whole tables or row by row.
    let r = &drows;
    let recorded = dy::Recorded {
        n: 2,
        m: 2,
        t: &r.t,
        x: [&r.x, &r.dx, &r.ddx],
        c: [&r.xc, &r.dxc, &r.ddxc],
        z1: &r.z1,
        tau: [&r.tau, &r.tau_sat, &r.tau_e],
    };
    let target = dc.impedance();
    let target = [&target[0][..], &target[1][..], &target[2][..]];
    let tables = dy::metrics_of(&recorded, settle, target, None).expect("metrics of rows");
    same_metrics(&tables, &dmetrics);
    let mut by_row = dy::RowMetrics::new(2, 2, true, settle, target).expect("row metrics");
    for k in 0..r.len() {
        let at = |v: &[f64]| v[2 * k..2 * k + 2].to_vec();
        let (x, dx, ddx) = (at(&r.x), at(&r.dx), at(&r.ddx));
        let (xc, dxc, ddxc, z1) = (at(&r.xc), at(&r.dxc), at(&r.ddxc), at(&r.z1));
        let (tau, tau_sat, tau_e) = (at(&r.tau), at(&r.tau_sat), at(&r.tau_e));
        by_row
            .push(
                r.t[k],
                [&x, &dx, &ddx],
                [&xc, &dxc, &ddxc],
                &z1,
                [&tau, &tau_sat, &tau_e],
            )
            .expect("row");
    }
    same_metrics(&by_row.finish(), &dmetrics);
    let short = by_row.push(0.0, [&[0.0]; 3], [&[0.0; 2]; 3], &[0.0; 2], [&[0.0; 2]; 3]);
    assert_eq!(
        short.unwrap_err().to_string(),
        "rows: a row needs n values per joint quantity, m per reference one"
    );
}

/// Every metric of two runs, bit for bit (NaN included).
fn same_metrics(a: &dy::Metrics, b: &dy::Metrics) {
    assert_eq!((a.rows, a.steps_in_contact), (b.rows, b.steps_in_contact));
    let scalars = |m: &dy::Metrics| {
        [
            m.rms_z1,
            m.rms_z1_after2,
            m.sat_duty,
            m.peak_contact_after2,
            m.mean_contact,
            m.imp_err_rms_after2,
        ]
    };
    same("metrics", &scalars(a), &scalars(b));
    same(
        "rms z1 per joint",
        &a.rms_z1_joint_after2,
        &b.rms_z1_joint_after2,
    );
    same(
        "max z1 per joint",
        &a.max_abs_z1_joint_after2,
        &b.max_abs_z1_joint_after2,
    );
    same("peak τ", &a.peak_abs_tau, &b.peak_abs_tau);
}

/// Every table of two runs' rows, bit for bit (NaN included).
fn same_rows(a: &dy::Rows, b: &dy::Rows) {
    assert_eq!(a.len(), b.len());
    for (what, x, y) in [
        ("t", &a.t, &b.t),
        ("x", &a.x, &b.x),
        ("dx", &a.dx, &b.dx),
        ("ddx", &a.ddx, &b.ddx),
        ("xc", &a.xc, &b.xc),
        ("tau_sat", &a.tau_sat, &b.tau_sat),
        ("tau_e", &a.tau_e, &b.tau_e),
        ("z1", &a.z1, &b.z1),
        ("w_norms", &a.w_norms, &b.w_norms),
    ] {
        same(what, x, y);
    }
    assert_eq!(a.refused, b.refused);
}

/// The Cartesian loop on a planar arm of three links: its joint rows are
/// those of the core's loop with the pair's step as the controller.
#[test]
fn the_cartesian_loop_steps_the_pair_as_the_core_loop_does() {
    use adaptimp::sim::simulator::simulate;
    use adaptimp::{
        CartesianConfig, FreeSpace, Link, PlanarArm, RigidBody, Row, TargetImpedance, WrenchControl,
    };
    const N: usize = 3;
    let links = [Link {
        mass: 1.0,
        length: 0.3,
        com: 0.15,
        inertia: 0.01,
    }; N];
    let js: Vec<Joint> = (0..N)
        .map(|i| {
            let x = if i == 0 { 0.0 } else { 0.3 };
            Joint::revolute(
                Transform::from_xyz_rpy([x, 0.0, 0.0], [0.0; 3]),
                [0.0, 0.0, 1.0],
            )
        })
        .collect();
    let tip = Transform::from_xyz_rpy([0.3, 0.0, 0.0], [0.0; 3]);
    let q0 = [0.3, 0.5, 0.4];
    let (mut d, mut s) = scenario::<N>(Law::Pd, true);
    for (name, v) in [
        ("q0", Value::Vec(&q0)),
        ("T", Value::Real(0.2)),
        ("wall", Value::None),
    ] {
        d.set(name, v).expect(name);
        s.set(name, v).expect(name);
    }
    let cfg = CartesianConfig::default().position_only();
    // The core's: the pair as a `WrenchControl` in the core's loop.
    struct Pair<'a> {
        pair: &'a CartesianController<N, Chain<N>, AnyBasis<N>>,
        ost: &'a mut adaptimp::CartesianState<N>,
        ist: &'a mut adaptimp::HeapState<N>,
        target: TargetImpedance<N>,
    }
    impl WrenchControl<N> for Pair<'_> {
        fn period(&self) -> f64 {
            1e-3
        }
        fn target(&self) -> &TargetImpedance<N> {
            &self.target
        }
        fn step_with_wrench(
            &mut self,
            m: &Measurement<N>,
            wrench: &[f64; 6],
            _c: &Setpoint<N>,
        ) -> (Vector<N>, Result<Command<N>, Error>) {
            let meas = CartesianMeasurement {
                q: m.x,
                dq: m.dx,
                wrench: Vector::<6>::from(*wrench),
            };
            let (tau, r) = self.pair.step_or_fallback(self.ost, self.ist, &meas, None);
            (tau, r.map(|c| c.joint))
        }
    }
    struct Rows(Vec<Row<N>>);
    impl adaptimp::Recorder<N> for Rows {
        fn record(&mut self, r: &Row<N>) {
            self.0.push(*r);
        }
    }
    let (cc, _) = core_controller(&s);
    let chain = Chain::<N>::new(&js, &tip).expect("chain");
    let pair = CartesianController::new(
        CartesianImpedance::new(cfg, chain, 1e-3).expect("outer"),
        cc,
    )
    .expect("pair");
    let q0v = Vector::from(q0);
    let (mut ost, mut ist) = (pair.start(&q0v).expect("start"), pair.inner().new_state());
    let target = *pair.inner().impedance();
    let mut plant = RigidBody::new(
        PlanarArm::new(links, 9.81).expect("arm"),
        FreeSpace,
        q0v,
        Vector::zeros(),
        s.sim.substeps,
    )
    .expect("plant");
    let mut rows = Rows(Vec::new());
    let nan = |_t: f64| Setpoint {
        x: Vector::<N>::from_element(f64::NAN),
        dx: Vector::from_element(f64::NAN),
        ddx: Vector::from_element(f64::NAN),
    };
    let mut ctrl = Pair {
        pair: &pair,
        ost: &mut ost,
        ist: &mut ist,
        target,
    };
    simulate(&mut plant, &mut ctrl, &nan, 0.2, &mut rows).expect("core run");
    // The run-time one.
    let outer =
        dy::CartesianImpedance::new(cfg, &dy::Chain::new(&js, &tip).unwrap(), 1e-3).expect("outer");
    let joint = d.controller().expect("joint");
    let mut dstate = outer.start(&q0).expect("start");
    let mut jstate = joint.new_state();
    let none = dy::Disturbances::none(N).expect("n");
    let mut dplant = dy::RigidBody::new(
        &dy::ModelArm::Planar {
            links: links.to_vec(),
            g: 9.81,
        },
        &d,
        &none,
    )
    .expect("plant");
    let run = dy::Run {
        t_final: 0.2,
        settle: 0.1,
        every: 1,
        disturbances: None,
        injection: None,
    };
    let mut drows = dy::Rows::for_run(N, &run, 1e-3).expect("rows");
    let mut task = dy::TaskRows::for_run(N, &run, 1e-3).expect("rows");
    let metrics = dy::simulate_cartesian(
        &mut dplant,
        &outer,
        &mut dstate,
        dy::Joint::Adaptive(&joint, &mut jstate),
        None,
        &run,
        &mut (),
        &mut drows,
        &mut task,
    )
    .expect("run-time run");
    let col = |f: fn(&Row<N>) -> Vector<N>| -> Vec<f64> {
        rows.0
            .iter()
            .flat_map(|r| f(r).iter().copied().collect::<Vec<_>>())
            .collect()
    };
    assert_eq!(drows.len(), 200);
    same("x", &drows.x, &col(|r| r.x));
    same("tau_sat", &drows.tau_sat, &col(|r| r.tau_sat));
    same("z1", &drows.z1, &col(|r| r.z1));
    assert_eq!(task.len(), 200);
    assert_eq!(
        task.last.map(|s| s.command.joint.tau_sat.to_vec()),
        Some(drows.tau_sat[drows.tau_sat.len() - N..].to_vec())
    );
    // Task space: z1 = p_d − p (m), the impedance residual not defined there.
    assert_eq!(metrics.rms_z1_joint_after2.len(), 3);
    assert!(metrics.imp_err_rms_after2.is_nan());
    let rms = (task
        .z1
        .chunks(3)
        .map(|z| z.iter().map(|v| v * v).sum::<f64>())
        .sum::<f64>()
        / 200.0)
        .sqrt();
    assert!(
        (metrics.rms_z1 - rms).abs() <= 1e-12 * rms,
        "{} {rms}",
        metrics.rms_z1
    );
    // The typed run: the same joint and task rows, the same metrics.
    let mut dstate2 = outer.start(&q0).expect("start");
    let mut jstate2 = joint.new_state();
    let mut dplant2 = dy::RigidBody::new(
        &dy::ModelArm::Planar {
            links: links.to_vec(),
            g: 9.81,
        },
        &d,
        &none,
    )
    .expect("plant");
    let out = dy::run(dy::Spec {
        plant: &mut dplant2,
        looped: dy::Loop::Cartesian {
            outer: &outer,
            state: &mut dstate2,
            joint: dy::Joint::Adaptive(&joint, &mut jstate2),
            targets: None,
        },
        run,
        hooks: None,
    });
    same_rows(&out.rows, &drows);
    let out_task = out.task.expect("task rows");
    same("task z1", &out_task.z1, &task.z1);
    assert_eq!(out_task.last, task.last);
    same_metrics(&out.ended.expect("typed run"), &metrics);
}

/// An arm read from a URDF at run time (one this crate did not write the
/// code for): its chain, its dynamics and both controllers, no match over n.
#[test]
fn a_urdf_read_at_run_time_drives_both_controllers() {
    use adaptimp::description::{reduce, urdf};
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/hobby_arm.urdf");
    let arm = reduce(&urdf::read_file(path).expect("urdf"), None, &[]).expect("arm");
    let n = arm.n();
    // More joints than a chain may hold: refused by name, with what to do.
    arm.within(dy::MAX_JOINTS).expect("within 7");
    let e = arm.within(n - 1).unwrap_err().to_string();
    assert!(e.contains(&format!("the arm has {n} joints (")), "{e}");
    assert!(
        e.ends_with(&format!(
            "a chain has at most {}: hold some with fix",
            n - 1
        )),
        "{e}"
    );
    let chain = dy::Chain::from_arm(&arm).expect("chain");
    let dynamics = dy::Dynamics::from_arm(&arm, adaptimp::GRAVITY).expect("dynamics");
    assert_eq!((chain.n(), dynamics.n()), (n, n));
    let (q, zero) = (vec![0.1; n], vec![0.0; n]);
    // At rest, inverse dynamics is gravity plus nothing of the drive.
    let id = dynamics.inverse_dynamics(&q, &zero, &zero).expect("id");
    same("G", &id, &dynamics.gravity_torque(&q).expect("G"));
    // Where the URDF states no effort limit, one of ours (5 N m).
    let effort: Vec<f64> = arm
        .joints
        .iter()
        .map(|j| if j.effort > 0.0 { j.effort } else { 5.0 })
        .collect();
    let mut s = dy::Scenario::new(n, Preset::Robot, Law::Pd).expect("n");
    s.set("tau_max", Value::Vec(&effort)).expect("tau_max");
    s.set("impedance", Value::Str("external"))
        .expect("impedance");
    let joint = s.controller().expect("joint controller");
    let outer = dy::CartesianImpedance::new(s.cartesian(), &chain, joint.period()).expect("outer");
    let pair = dy::CartesianController::new(outer, joint).expect("pair");
    let (mut task, mut inner) = (pair.start(&q).expect("start"), pair.joint().new_state());
    let m = dy::CartesianMeasurement {
        q: &q,
        dq: Some(&zero),
        wrench: Vector::zeros(),
    };
    for _ in 0..10 {
        let cmd = pair.step(&mut task, &mut inner, &m, None).expect("step");
        assert_eq!(cmd.joint.tau_sat.len(), n);
        // Held at q: the outer loop keeps the reference where the arm is.
        assert!(
            cmd.joint.z1.iter().all(|z| z.abs() < 1e-9),
            "{:?}",
            cmd.joint.z1
        );
    }
}

/// The centres along an orbit, the model arms' dynamics and kinematics and
/// the parameters' listing: the const-generic ones.
#[test]
fn the_orbit_centres_and_the_model_arms_are_the_const_generic_ones() {
    use adaptimp::{Centers, Link, Manipulator, PlanarArm, TwoLinkArm};
    let traj = Sinusoid::<3>::new(
        Vector::from_element(0.1),
        Vector::from_element(0.2),
        Vector::zeros(),
        Vector::from_element(1.5),
    )
    .expect("trajectory");
    let samples: Vec<Setpoint<3>> = (0..40).map(|k| traj.sample(0.1 * k as f64)).collect();
    let dsamples: Vec<dy::Setpoint> = samples
        .iter()
        .map(|s| dy::Setpoint {
            x: dy::Joints::from_slice(s.x.as_slice()).unwrap(),
            dx: dy::Joints::from_slice(s.dx.as_slice()).unwrap(),
            ddx: dy::Joints::from_slice(s.ddx.as_slice()).unwrap(),
        })
        .collect();
    for periodic in [false, true] {
        let c = if periodic {
            Centers::along_periodic(&samples, [0.2, 0.5])
        } else {
            Centers::along(&samples, [0.2, 0.5])
        }
        .expect("centres");
        let d = dy::Centres::along(&dsamples, [0.2, 0.5], periodic).expect("centres");
        same("centres", &d.rows, c.centers());
        let w: Vec<f64> = c.widths2().iter().flat_map(|b| b.iter().copied()).collect();
        same("widths", d.widths2.as_deref().unwrap(), &w);
    }
    // The model arms.
    let links = [Link {
        mass: 1.2,
        length: 0.4,
        com: 0.2,
        inertia: 0.02,
    }; 3];
    let planar = PlanarArm::new(links, 9.81).unwrap();
    let arm = dy::ModelArm::Planar {
        links: links.to_vec(),
        g: 9.81,
    };
    let (q, dq, tau) = (q_of::<3>(1), q_of::<3>(2), q_of::<3>(3));
    let (d, c, g, a) = arm
        .dynamics(q.as_slice(), dq.as_slice(), tau.as_slice(), &[0.0; 3])
        .expect("dynamics");
    let m = |j: &dy::JointMatrix| j.matrix().iter().copied().collect::<Vec<_>>();
    same("D", &m(&d), planar.inertia(&q).as_slice());
    same("C", &m(&c), planar.coriolis(&q, &dq).as_slice());
    same("G", &g, planar.gravity(&q).as_slice());
    let a2 = planar.forward_dynamics(&q, &dq, &tau, &Vector::zeros());
    same("q̈", &a, a2.as_slice());
    let (p, j) = arm.kinematics(q.as_slice()).expect("kinematics");
    same("fk", p.as_slice(), planar.fk(&q).as_slice());
    let j: Vec<f64> = j.matrix().iter().copied().collect();
    same("Jp", &j, planar.position_jacobian(&q).as_slice());
    let two = dy::ModelArm::Paper(TwoLinkArm::paper());
    assert_eq!(two.n(), 2);
    let e = two.dynamics(&[0.0; 3], &[0.0; 3], &[0.0; 3], &[0.0; 3]);
    assert_eq!(
        e.unwrap_err().to_string(),
        "q: needs one value per joint (as many as the controller has)"
    );
    // The parameters' listing.
    let (d, s) = scenario::<4>(Law::Pd, false);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    d.visit(|name, v| a.push(format!("{name} {v:?}")));
    s.visit(|name, v| b.push(format!("{name} {v:?}")));
    assert_eq!(a, b);
    assert!(!a.is_empty());
}

/// An arm's inertia at posture k: symmetric, diagonally dominant (so
/// positive definite), row-major.
fn inertia<const N: usize>(k: usize) -> Vec<f64> {
    (0..N * N)
        .map(|e| {
            let (i, j) = (e / N, e % N);
            if i == j {
                1.0 + 0.2 * i as f64 + 0.01 * k as f64
            } else {
                0.05 / (1.0 + i.abs_diff(j) as f64)
            }
        })
        .collect()
}

/// The rule of SPEC §18 the run-time way ([`dy::Tuning::suggest`]) and the
/// const-generic way, step for step as the fronts took it: the same
/// parameters and centres, bit for bit.
fn rule<const N: usize>() {
    use adaptimp::cartesian::rule::resolving;
    use adaptimp::control::tuning::{
        damped_scales, inertia_scales, inertia_scales_along, loop_bound,
    };
    use adaptimp::Matrix;
    let tau: Vec<f64> = (0..N).map(|i| 20.0 - i as f64).collect();
    let period = 2.0;
    let path: Vec<f64> = (0..64)
        .flat_map(|k| {
            let w = core::f64::consts::TAU / period;
            let t = period * k as f64 / 64.0;
            let q = (0..N).map(move |i| 0.3 * (w * t + i as f64).sin());
            let dq = (0..N).map(move |i| 0.3 * w * (w * t + i as f64).cos());
            let ddq = (0..N).map(move |i| -0.3 * w * w * (w * t + i as f64).sin());
            q.chain(dq).chain(ddq).collect::<Vec<_>>()
        })
        .collect();
    let gravity: Vec<f64> = (0..N).map(|i| 3.0 - 0.5 * i as f64).collect();
    let damping: Vec<f64> = (0..N).map(|i| 0.1 * (i + 1) as f64).collect();
    let orbit: Vec<f64> = path
        .chunks_exact(3 * N)
        .flat_map(|r| r[..N].to_vec())
        .collect();
    let along: Vec<f64> = (0..3).flat_map(inertia::<N>).collect();
    let at = inertia::<N>(0);
    for (case, law) in [Law::Pd, Law::StateFeedback, Law::OutputFeedback]
        .into_iter()
        .enumerate()
    {
        let ts = 1e-3;
        let mut t = dy::Tuning::new(law, dy::Inertia::At(&at), &tau, ts);
        // The const-generic rule is the diagonal one of (18.1)–(18.11); the
        // shaping of (18.12), the run-time rule's default with a delay, is
        // tested in tests/coupling.rs.
        t.coupled = Some(false);
        if case >= 1 {
            t.delay = case;
            t.path = Some(dy::TaskPath {
                rows: &path,
                period,
            });
            t.gravity = Some(&gravity);
        }
        if case == 2 {
            t.inertia = dy::Inertia::Along(&along);
            t.damping = Some(&damping);
            t.orbit = Some(&orbit);
            t.resolve = true;
            t.critical = true;
        }
        let got = t.suggest().expect("suggest");
        // The const-generic rule, as the fronts took it.
        let mut rule = Rule::default().with_delay(t.delay).unwrap();
        if t.critical {
            rule = rule.critical(ts);
        }
        let flat = if case == 2 { &along } else { &at };
        let ds: Vec<Matrix<N>> = flat
            .chunks_exact(N * N)
            .map(Matrix::<N>::from_row_slice)
            .collect();
        let scales = if case == 2 {
            inertia_scales_along(&ds)
        } else {
            inertia_scales(&ds[0])
        }
        .unwrap();
        rule = rule.bounded(loop_bound(&ds, &scales).unwrap());
        let scales = match t.damping {
            None => scales,
            Some(b) => damped_scales(&scales, &Vector::<N>::from_column_slice(b), ts).unwrap(),
        };
        let tau_v = Vector::<N>::from_column_slice(&tau);
        let mut want = Scenario::<N>::preset(Preset::Robot, law);
        let centres = if t.path.is_none() {
            want.config = rule.gains_scaled(law, &scales, &tau_v, ts).unwrap();
            None
        } else {
            let samples: Vec<Setpoint<N>> = path
                .chunks_exact(3 * N)
                .map(|r| Setpoint {
                    x: Vector::from_column_slice(&r[..N]),
                    dx: Vector::from_column_slice(&r[N..2 * N]),
                    ddx: Vector::from_column_slice(&r[2 * N..]),
                })
                .collect();
            if t.resolve {
                rule = resolving(&rule, &samples);
            }
            if t.orbit.is_some() {
                let qs: Vec<Vector<N>> = orbit
                    .chunks_exact(N)
                    .map(Vector::from_column_slice)
                    .collect();
                rule = rule.spanning(&qs);
            }
            let g = Vector::<N>::from_column_slice(&gravity);
            let sug = rule
                .suggest_scaled(law, &scales, &tau_v, ts, &samples, period, Some(&g))
                .unwrap();
            want.config = sug.config;
            Some(sug.centers)
        };
        let (mut a, mut b) = (Vec::new(), Vec::new());
        got.visit(|name, v| a.push(format!("{name} {v:?}")));
        want.visit(|name, v| b.push(format!("{name} {v:?}")));
        assert_eq!(a, b, "N = {N}, case {case}");
        assert_eq!((got.n(), got.law()), (N, law));
        match (got.centres(), centres) {
            (None, None) => {}
            (Some(d), Some(c)) => {
                same("centres", &d.rows, c.centers());
                let w: Vec<f64> = c.widths2().iter().flat_map(|b| b.iter().copied()).collect();
                same("widths", d.widths2.as_deref().unwrap(), &w);
                // The scenario builds the controller on its centres.
                assert_eq!(got.controller().unwrap().nodes(), c.nodes());
            }
            (d, c) => panic!("centres {d:?} against {c:?}"),
        }
    }
}

#[test]
fn the_rule_at_run_time_is_the_const_generic_rule_bit_for_bit() {
    rule::<1>();
    rule::<2>();
    rule::<4>();
    rule::<7>();
    // Inputs of the wrong length, by name.
    let tau = [10.0; 3];
    let e = |t: dy::Tuning<'_>| t.suggest().unwrap_err().to_string();
    let t = dy::Tuning::new(Law::Pd, dy::Inertia::At(&[1.0; 4]), &tau, 1e-3);
    assert_eq!(
        e(t),
        "inertia: needs n × n values (n: tau_max's), or K ≥ 1 matrices of n × n along a path"
    );
    let d = inertia::<3>(0);
    let mut t = dy::Tuning::new(Law::Pd, dy::Inertia::At(&d), &tau, 1e-3);
    t.damping = Some(&[0.1; 2]);
    assert_eq!(
        e(t),
        "damping: needs one value per joint (as many as the controller has)"
    );
    let t = dy::Tuning::new(Law::Pd, dy::Inertia::At(&[1.0; 64]), &[1.0; 8], 1e-3);
    assert_eq!(
        e(t),
        "condition 1 ≤ n ≤ 7 joints is violated: n = 8 (SPEC §10)"
    );
    let mut t = dy::Tuning::new(Law::Pd, dy::Inertia::At(&d), &tau, 1e-3);
    t.delay = 65;
    assert!(e(t).contains("delay"));
}

/// A Cartesian state restarted at another q0: a fresh start there, with the
/// null-space posture kept (the outer loop's and the pair's restart).
#[test]
fn a_restarted_cartesian_state_is_a_fresh_start_that_keeps_its_posture() {
    const N: usize = 3;
    let js = joints::<N>();
    let (d, s) = scenario::<N>(Law::StateFeedback, true);
    let (cc, _) = core_controller(&s);
    let chain = Chain::<N>::new(&js, &Transform::IDENTITY).expect("chain");
    let outer = CartesianImpedance::new(s.cartesian, chain, cc.period()).expect("outer");
    let pair = CartesianController::new(outer, cc).expect("pair");
    let dchain = dy::Chain::new(&js, &Transform::IDENTITY).expect("chain");
    let douter = dy::CartesianImpedance::new(d.cartesian(), &dchain, 1e-3).expect("outer");
    let dpair =
        dy::CartesianController::new(douter.clone(), d.controller().expect("joint")).expect("pair");
    let (q0, q1, posture) = (q_of::<N>(0), q_of::<N>(1), q_of::<N>(2));
    let mut dst = dpair.start(q0.as_slice()).expect("start");
    let mut jst = dpair.joint().new_state();
    let m = dy::CartesianMeasurement {
        q: q0.as_slice(),
        dq: Some(&[0.0; N]),
        wrench: Vector::zeros(),
    };
    for _ in 0..5 {
        dpair.step(&mut dst, &mut jst, &m, None).expect("step");
    }
    dpair
        .set_posture(&mut dst, posture.as_slice())
        .expect("posture");
    for (restart, want) in [
        (dpair.restart(&mut dst, q1.as_slice()), pair.start(&q1)),
        (
            douter.restart(&mut dst, q1.as_slice()),
            outer.start_checked(&q1),
        ),
    ] {
        restart.expect("restart");
        let want = want.expect("start");
        assert_eq!(dst.steps(), 0);
        same("posture", &dst.posture(), posture.as_slice());
        let (qd, dqd) = dst.joint_d();
        same("q_d", &qd, want.qd.as_slice());
        same("q̇_d", &dqd, want.dqd.as_slice());
        assert_eq!(dst.pose_d(), (want.pd, want.rd));
        assert_eq!(dst.stiffness(), (want.stiffness, want.stiffness_filtered));
    }
    // Checked as a start is, nothing changed on an error.
    let e = dpair.restart(&mut dst, &[f64::NAN, 0.0, 0.0]).unwrap_err();
    assert_eq!(e.to_string(), "q0[0] is not finite (NaN or infinite)");
    same("posture", &dst.posture(), posture.as_slice());
    let e = dpair.restart(&mut dst, &[0.0; 2]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "q0: needs one value per joint (as many as the controller has)"
    );
    let other = dy::Chain::new(&joints::<2>(), &Transform::IDENTITY).expect("chain");
    let (d2, _) = scenario::<2>(Law::StateFeedback, true);
    let outer2 = dy::CartesianImpedance::new(d2.cartesian(), &other, 1e-3).expect("outer");
    let e = outer2.restart(&mut dst, &[0.0; 2]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "state: was made for another number of joints"
    );
}

/// The effort estimate of SPEC §18's plant preparation: 2 (max |G_i| + 10 ·
/// max Σ_j |D_ij| + b_i · 1 + F_i), each maximum over the postures on its
/// own; inputs of another length named.
#[test]
fn the_effort_estimate_takes_each_maximum_over_the_postures() {
    // Two postures of a 2-joint arm.
    let gravity = [3.0, -1.0, -4.0, 0.5];
    let inertia = [2.0, -0.5, -0.5, 1.0, 1.0, 0.25, 0.25, 1.5];
    let s = dy::Sampled {
        n: 2,
        gravity: &gravity,
        inertia: &inertia,
    };
    let tau = dy::estimate_effort(&s, None).expect("estimate");
    assert_eq!(tau, [2.0 * (4.0 + 10.0 * 2.5), 2.0 * (1.0 + 10.0 * 1.75)]);
    let drag = dy::estimate_effort(&s, Some((&[0.5, 1.0], &[0.1, 0.2]))).expect("estimate");
    assert_eq!(drag, [2.0 * (4.0 + 25.0 + 0.6), 2.0 * (1.0 + 17.5 + 1.2)]);
    let nan = dy::Sampled {
        gravity: &[f64::NAN, 0.0, 0.0, 0.0],
        ..s
    };
    assert!(dy::estimate_effort(&nan, None).expect("estimate")[0].is_nan());
    let short = dy::Sampled {
        inertia: &inertia[..7],
        ..s
    };
    assert_eq!(
        dy::estimate_effort(&short, None).unwrap_err().to_string(),
        "inertia: needs one n × n matrix per row of gravity"
    );
    assert_eq!(
        dy::estimate_effort(&s, Some((&[0.5], &[0.1, 0.2])))
            .unwrap_err()
            .to_string(),
        "damping: needs n values"
    );
}

/// A model arm's quantities one by one are those of `dynamics`, and a
/// planar arm is checked when it is made.
#[test]
fn a_model_arm_gives_each_quantity_of_its_dynamics() {
    use adaptimp::Link;
    let link = Link {
        mass: 1.0,
        length: 0.3,
        com: 0.15,
        inertia: 0.01,
    };
    let arm = dy::ModelArm::planar(&[link; 3], 9.81).expect("arm");
    let (q, dq, tau, te) = (
        [0.1, -0.2, 0.3],
        [0.5, 0.0, -1.0],
        [1.0, 2.0, 3.0],
        [0.0; 3],
    );
    let (d, c, g, acc) = arm.dynamics(&q, &dq, &tau, &te).expect("dynamics");
    assert_eq!(arm.inertia(&q).expect("D"), d);
    assert_eq!(arm.coriolis(&q, &dq).expect("C"), c);
    assert_eq!(&*arm.gravity(&q).expect("G"), &*g);
    assert_eq!(
        &*arm.forward_dynamics(&q, &dq, &tau, &te).expect("q̈"),
        &*acc
    );
    assert_eq!(
        dy::ModelArm::planar(&[], 9.81).unwrap_err().to_string(),
        "n: the number of links must be between 1 and 7"
    );
    let bad = Link { mass: -1.0, ..link };
    assert!(dy::ModelArm::planar(&[bad], 9.81).is_err());
    assert_eq!(
        arm.inertia(&q[..2]).unwrap_err().to_string(),
        dy::ModelArm::planar(&[link; 2], 9.81)
            .expect("arm")
            .gravity(&q)
            .unwrap_err()
            .to_string()
    );
}

/// Whether the run-time disturbances have friction, and its torque: the
/// const-generic ones'.
#[test]
fn run_time_disturbances_have_the_friction_of_their_scenario() {
    let none = dy::Scenario::new(3, Preset::Robot, Law::StateFeedback)
        .unwrap()
        .disturbances()
        .unwrap();
    assert_eq!(none.n(), 3);
    assert!(!none.has_friction());
    let b = [0.5, 0.25, 0.125];
    let mut s = Scenario::<3>::preset(Preset::Robot, Law::StateFeedback);
    s.set("friction_viscous", Value::Vec(&b)).unwrap();
    let mut d = dy::Scenario::new(3, Preset::Robot, Law::StateFeedback).unwrap();
    d.set("friction_viscous", Value::Vec(&b)).unwrap();
    let run_time = d.disturbances().unwrap();
    assert!(run_time.has_friction());
    let dq = [0.3, -0.2, 0.1];
    let mut out = [0.0; 3];
    assert!(run_time.friction_torque(&dq, &mut out).unwrap());
    let typed = s.disturbances().unwrap();
    let want = typed
        .friction()
        .torque(&Vector::<3>::from_column_slice(&dq));
    same("friction", &out, want.as_slice());
}

/// The one builder feeds forward a nominal model's gravity (SPEC (20.10)):
/// the same torques as the const-generic controller given the same model,
/// other than without it; a model of another n is refused by name.
#[test]
fn the_one_builder_feeds_forward_the_gravity_of_a_model() {
    const N: usize = 3;
    let (mut d, s) = scenario::<N>(Law::StateFeedback, false);
    let js = joints::<N>();
    let inertials: Vec<Inertial> = (0..=N)
        .map(|i| Inertial::point(1.0 + 0.1 * i as f64, [0.02, 0.01, 0.06]))
        .collect();
    let g = [0.0, 0.0, -9.81];
    let plain = d.controller().expect("without");
    d.feedforward(dy::Dynamics::new(&js, &inertials, g).expect("model"));
    let dc = d.controller().expect("with the model");
    let (cc, traj) = core_controller(&s);
    let model = Dynamics::<N>::new(&js, &inertials, g).expect("typed model");
    let cc = cc.with_feedforward(std::sync::Arc::new(model));
    let (mut ds, mut ps, mut cs) = (dc.new_state(), plain.new_state(), cc.new_state());
    for k in 0..50 {
        let m = measurement(&traj, k, usize::MAX);
        let dm = dy::Measurement {
            x: m.x.as_slice(),
            dx: m.dx.as_ref().map(|v| v.as_slice()),
            tau_e: m.tau_e.as_slice(),
        };
        let own = traj.sample(cc.time(&cs));
        let a = dc.step(&mut ds, &dm, None).expect("run-time step");
        let b = cc.step(&mut cs, &m, &own).expect("typed step");
        same_command(&a, &b);
        let p = plain.step(&mut ps, &dm, None).expect("plain step");
        assert_ne!(
            bits(&p.tau),
            bits(&a.tau),
            "step {k}: the gravity is fed forward"
        );
    }
    d.feedforward(dy::Dynamics::new(&joints::<2>(), &inertials[..3], g).expect("model"));
    assert_eq!(
        d.controller().unwrap_err().to_string(),
        "feedforward: was made for another number of joints"
    );
}

/// A replay of recorded rows is the controller's steps, one per row, bit for
/// bit: with its own trajectory and with the rows' setpoints; the caller sees
/// the state every 64 rows and after the last, and can stop it.
#[test]
fn a_replay_is_the_steps_of_its_rows() {
    const N: usize = 3;
    const K: usize = 150;
    let (d, s) = scenario::<N>(Law::StateFeedback, false);
    let dc = d.controller().expect("controller");
    let (_, traj) = core_controller(&s);
    let mut tables: [Vec<f64>; 6] = Default::default();
    for k in 0..K {
        let m = measurement(&traj, k, usize::MAX);
        let c = traj.sample(k as f64 * 1e-3 + 2e-4);
        for (t, v) in tables
            .iter_mut()
            .zip([m.x, m.dx.expect("dx"), m.tau_e, c.x, c.dx, c.ddx])
        {
            t.extend_from_slice(v.as_slice());
        }
    }
    let [x, dx, tau_e, xc, dxc, ddxc] = &tables;
    for setpoint in [None, Some([&xc[..], &dxc[..], &ddxc[..]])] {
        let rows = dy::Replay {
            x,
            dx: Some(dx),
            tau_e,
            setpoint,
        };
        let mut by_step = dc.new_state();
        let mut want = Vec::new();
        for k in 0..K {
            let r = |v: &[f64]| v[k * N..(k + 1) * N].to_vec();
            let (q, v, f) = (r(x), r(dx), r(tau_e));
            let m = dy::Measurement {
                x: &q,
                dx: Some(&v),
                tau_e: &f,
            };
            let (a, b, c) = (r(xc), r(dxc), r(ddxc));
            let sp = dy::Setpoint {
                x: &a[..],
                dx: &b[..],
                ddx: &c[..],
            };
            let cmd = dc
                .step(&mut by_step, &m, setpoint.map(|_| &sp))
                .expect("step");
            want.extend_from_slice(&cmd.tau_sat);
        }
        let mut state = dc.new_state();
        let mut out = vec![0.0; K * N];
        let mut calls = Vec::new();
        dc.replay(&mut state, &rows, &mut out, |k, total, st| {
            calls.push((k, total, st.steps()));
            true
        })
        .expect("replay");
        same("sat(τ)", &out, &want);
        assert_eq!(calls, [(64, 150, 64), (128, 150, 128), (150, 150, 150)]);
        same("zeta", state.zeta(), by_step.zeta());
        // Stopped at the first look: 64 rows taken.
        let mut again = dc.new_state();
        let stopped = dc.replay(&mut again, &rows, &mut out, |_, _, _| false);
        assert_eq!(stopped, Err(dy::RunError::Stopped));
        assert_eq!(again.steps(), 64);
    }
    // Tables of another length are refused by name.
    let short = dy::Replay {
        x: &tables[0],
        dx: None,
        tau_e: &tables[2][..3],
        setpoint: None,
    };
    let mut state = dc.new_state();
    let e = dc.replay(&mut state, &short, &mut [0.0; K * N], |_, _, _| true);
    assert_eq!(
        e.unwrap_err().to_string(),
        "rows: every table needs K rows of n values"
    );
}

/// The default task of SPEC §18 at run time: the core's sinusoid for every
/// n, and its errors (a home outside the swing's room, lo or hi of another
/// length, n beyond 7).
#[test]
fn the_default_task_is_the_cores() {
    fn check<const N: usize>() {
        let home = Vector::<N>::from_fn(|i, _| 0.1 * i as f64 - 0.2);
        let lo = Vector::<N>::from_fn(|i, _| -1.0 - 0.5 * i as f64);
        let hi = Vector::<N>::from_fn(|i, _| if i == 0 { f64::INFINITY } else { 0.9 });
        let t = adaptimp::control::tuning::default_task(&home, &lo, &hi).expect("the core's");
        let d = dy::default_task(home.as_slice(), lo.as_slice(), hi.as_slice()).expect("run time");
        for (what, a, b) in [
            ("offset", &d[0], t.offset()),
            ("sin", &d[1], t.sin_amplitude()),
            ("cos", &d[2], t.cos_amplitude()),
            ("omega", &d[3], t.omega()),
        ] {
            same(what, a, b.as_slice());
        }
    }
    check::<1>();
    check::<2>();
    check::<3>();
    check::<4>();
    check::<5>();
    check::<6>();
    check::<7>();
    let e = dy::default_task(&[0.0, 0.0], &[-1.0], &[1.0, 1.0]).expect_err("lo of one");
    assert_eq!(
        e.to_string(),
        dy::default_task(&[0.0, 0.0], &[-1.0, -1.0], &[1.0])
            .expect_err("hi of one")
            .to_string()
            .replace("hi", "lo")
    );
    assert!(e.to_string().starts_with("lo"), "{e}");
    let outside = dy::default_task(&[0.95], &[-1.0], &[1.0]).expect_err("no room");
    let core = adaptimp::control::tuning::default_task(
        &Vector::<1>::new(0.95),
        &Vector::<1>::new(-1.0),
        &Vector::<1>::new(1.0),
    )
    .expect_err("no room");
    assert_eq!(outside, core);
    assert!(dy::default_task(&[0.0; 8], &[-1.0; 8], &[1.0; 8]).is_err());
}
