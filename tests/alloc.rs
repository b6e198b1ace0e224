//! Zero heap allocations in the hot path, counted exactly: a global allocator
//! that counts the allocations of the calling thread only (a thread-local
//! counter), so the test harness's own threads, or any other test running
//! beside this one, cannot change the count.

use adaptimp::{
    run, Controller, Environment, Law, Manipulator, Measurement, SimConfig, Sinusoid, Trajectory,
    TwoLinkArm, Vector, Wall,
};
use std::alloc::{GlobalAlloc, Layout, System};

mod common;
use std::cell::Cell;

/// The system allocator, counting every allocation (and reallocation) made
/// by the current thread.
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn count() {
    // `try_with`: allocations during thread teardown (after the counter is
    // destroyed) are not this test's.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: every call is forwarded unchanged to `System`, which upholds the
// `GlobalAlloc` contract; the counter is a thread-local `Cell` that never
// allocates (a `const` initialiser).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// The allocations this thread makes while running `f`.
fn allocations_in<T>(f: impl FnOnce() -> T) -> (u64, T) {
    let before = ALLOCATIONS.with(Cell::get);
    let out = f();
    (ALLOCATIONS.with(Cell::get) - before, out)
}

#[test]
fn the_counter_counts_this_threads_allocations_only() {
    let (n, v) = allocations_in(|| Vec::<u8>::with_capacity(16));
    assert_eq!(n, 1);
    drop(v);
    // Another thread's allocations are not ours.
    let (n, _) = allocations_in(|| {
        std::thread::scope(|s| {
            s.spawn(|| (0..100).map(|i| vec![i; 8]).collect::<Vec<_>>().len());
        })
    });
    // Spawning itself allocates here (the thread's handle), but not the
    // other thread's hundred vectors.
    assert!(n < 100, "{n}");
}

#[test]
fn no_heap_allocation_in_steps() {
    let arm = TwoLinkArm::paper();
    let wall = Wall::paper();
    let circle = Sinusoid::paper();
    let laws = [Law::Pd, Law::StateFeedback, Law::OutputFeedback];
    // The printed laws (fused pass) and the hardened ones (deferred update).
    for ctrl in laws
        .map(Controller::paper)
        .into_iter()
        .chain(laws.map(Controller::robot))
    {
        let law = ctrl.config().law;
        // Construction may allocate (the state's buffer); the step may not.
        let mut state = ctrl.new_state();
        let (mut x, mut dx) = (Vector::<2>::new(0.25, -0.05), Vector::<2>::zeros());
        let (n, ()) = allocations_in(|| {
            for _ in 0..10_000 {
                let tau_e = wall.force(0.0, &x, &dx);
                let sp = circle.sample(ctrl.time(&state));
                let m = Measurement {
                    x,
                    dx: Some(dx),
                    tau_e,
                };
                let cmd = ctrl.step(&mut state, &m, &sp).expect("step");
                // A crude plant update, just to vary the inputs.
                let a = arm.forward_dynamics(&x, &dx, &cmd.tau_sat, &tau_e);
                dx += 5e-5 * a;
                x += 5e-5 * dx;
            }
        });
        assert_eq!(n, 0, "{law:?}: the step allocated");
    }
}

#[test]
fn no_heap_allocation_in_a_simulation() {
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        let ctrl = Controller::robot(law);
        let mut state = ctrl.new_state();
        let sim = SimConfig {
            t_final: 0.5,
            ..SimConfig::robot()
        };
        let (n, m) = allocations_in(|| {
            run(
                &TwoLinkArm::paper(),
                &Wall::paper(),
                &mut ctrl.bind(&mut state),
                &Sinusoid::paper(),
                &sim,
                &mut (),
            )
            .expect("simulate")
        });
        assert_eq!(n, 0, "{law:?}: simulate allocated");
        assert_eq!(m.rows, 500);
    }
}

#[test]
fn no_heap_allocation_in_a_disturbed_simulation() {
    // Every disturbance of SPEC §17 on: the generators and the delay line
    // live in a fixed state on the stack.
    let d = adaptimp::Disturbances::new(
        adaptimp::DisturbanceParams {
            payload: 0.3,
            noise_q: Vector::from_element(1e-4),
            noise_dq: Vector::from_element(1e-2),
            noise_tau_e: Vector::from_element(0.2),
            seed: 1,
            delay: 64,
            jitter: 0.1,
            friction_viscous: Vector::from_element(0.05),
            friction_coulomb: Vector::from_element(0.2),
            friction_vs: 0.01,
            actuator_fraction: Vector::from_element(0.8),
        },
        Vector::<2>::new(17.0, 15.0),
    )
    .expect("valid");
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        let ctrl = Controller::robot(law);
        let mut state = ctrl.new_state();
        let sim = SimConfig {
            t_final: 0.5,
            ..SimConfig::robot()
        };
        let (n, m) = allocations_in(|| {
            adaptimp::run_disturbed(
                &TwoLinkArm::paper(),
                &Wall::paper(),
                &mut ctrl.bind(&mut state),
                &Sinusoid::paper(),
                &sim,
                &d,
                &mut (),
            )
            .expect("simulate")
        });
        assert_eq!(n, 0, "{law:?}: run_disturbed allocated");
        assert_eq!(m.rows, 500);
    }
}

#[test]
fn no_heap_allocation_in_seven_joint_and_cartesian_steps() {
    use adaptimp::{
        CartesianConfig, CartesianController, CartesianImpedance, CartesianMeasurement, Centers,
        Config, Grid, ImpedanceMode, Kinematics, PoseTarget, Setpoint,
    };
    // n = 7 with centres along an orbit (SPEC §15).
    let traj = Sinusoid::<7>::new(
        Vector::from_element(0.1),
        Vector::from_element(0.15),
        Vector::zeros(),
        Vector::from_element(1.0),
    )
    .expect("trajectory");
    let samples: Vec<_> = (0..64).map(|j| traj.sample(0.1 * j as f64)).collect();
    let mut cfg = Config::<7>::new(Law::StateFeedback, Vector::from_element(50.0)).hardened();
    cfg.ts = 1e-3;
    let basis = Centers::along(&samples, [0.3, 1.0]).expect("basis");
    let ctrl = Controller::for_trajectory(cfg, basis, &traj).expect("controller");
    let mut state = ctrl.new_state();
    let (n, ()) = allocations_in(|| {
        for _ in 0..1000 {
            let sp = traj.sample(ctrl.time(&state));
            let m = Measurement {
                x: sp.x,
                dx: Some(sp.dx),
                tau_e: Vector::zeros(),
            };
            ctrl.step(&mut state, &m, &sp).expect("step");
        }
    });
    assert_eq!(n, 0, "the n = 7 step allocated");
    // The Cartesian pair (SPEC §16) on the paper's arm, position-only.
    let arm = TwoLinkArm::paper();
    let q0 = Vector::<2>::new(0.5, 1.0);
    let cfg = CartesianConfig::default().position_only();
    let outer = CartesianImpedance::new(cfg, arm, 1e-3).expect("outer");
    let mut cfg = Config::robot(Law::StateFeedback);
    cfg.impedance = ImpedanceMode::External;
    let inner = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).expect("inner");
    let pair = CartesianController::new(outer, inner).expect("pair");
    let (mut ost, mut ist) = (pair.outer().start(q0), pair.inner().new_state());
    let p0 = arm.fk(&q0);
    let (n, ()) = allocations_in(|| {
        for k in 0..1000 {
            let c = Setpoint {
                x: p0 + Vector::<3>::new(0.01 * (k as f64 * 1e-3).sin(), 0.0, 0.0),
                dx: Vector::zeros(),
                ddx: Vector::zeros(),
            };
            let m = CartesianMeasurement {
                q: q0,
                dq: Some(Vector::zeros()),
                wrench: Vector::<6>::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            };
            let target = PoseTarget::from_position(&c);
            pair.step(&mut ost, &mut ist, &m, Some(&target))
                .expect("step");
        }
    });
    assert_eq!(n, 0, "the Cartesian step allocated");
}

/// The n = 7 Cartesian step (the Panda's chain: kinematics at q_d and at q,
/// the 6-D outer loop with its filters, the hardened state-feedback joint
/// step): in free motion, and saturated, projecting, clipping, in contact.
#[test]
fn no_heap_allocation_in_the_seven_joint_cartesian_step() {
    use adaptimp::{CartesianMeasurement, Kinematics, Vector};
    let low = [1.0, 1.0, 1.0, 1.0, 12.0, 12.0, 12.0];
    for (bound, clip, tau_max, offset, wrench) in [
        (100.0, None, common::PANDA_EFFORT, 0.0, 0.0),
        (1e-3, Some(1e-3), low, 0.02, 20.0),
    ] {
        let pair = common::cart7(bound, clip, tau_max);
        let q0 = Vector::<7>::from_column_slice(&common::PANDA_HOME);
        let tip = pair.outer().kinematics().tip(&q0, &Vector::zeros());
        let (mut ost, mut ist) = (pair.outer().start(q0), pair.inner().new_state());
        let m = CartesianMeasurement {
            q: q0 + Vector::<7>::from_element(offset),
            dq: Some(Vector::zeros()),
            wrench: Vector::<6>::new(0.0, 0.0, -wrench, 0.1 * wrench, 0.0, 0.0),
        };
        let (n, ()) = allocations_in(|| {
            for k in 0..1000 {
                let c = common::circle(&tip, k as f64 * 1e-3);
                pair.step(&mut ost, &mut ist, &m, Some(&c)).expect("step");
            }
        });
        assert_eq!(n, 0, "the n = 7 Cartesian step allocated (bound {bound})");
    }
}

#[test]
fn no_heap_allocation_in_computed_torque_steps() {
    // SPEC §20: RNEA and both forms of the law on seven joints.
    use adaptimp::control::io::TaskTorque;
    use adaptimp::{
        ComputedState, ComputedTorque, ComputedTorqueConfig, Dynamics, ImpedanceMode, Inertial,
        Joint, Kinematics, Setpoint, Transform, Vector,
    };
    let joints: Vec<Joint> = (0..7)
        .map(|i| {
            let axis = if i % 2 == 0 {
                [0.0, 0.0, 1.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            Joint::revolute(Transform::from_xyz_rpy([0.0, 0.0, 0.12], [0.0; 3]), axis)
        })
        .collect();
    let inertials = [Inertial::point(1.5, [0.02, 0.01, 0.06]); 7];
    let model = Dynamics::<7>::new(&joints, &inertials, adaptimp::GRAVITY).expect("model");
    let mut cfg = ComputedTorqueConfig::new(1e-3, Vector::<7>::from(common::PANDA_EFFORT));
    cfg.mode = ImpedanceMode::External;
    let ct = ComputedTorque::new(cfg, model).expect("controller");
    let mut st = ComputedState::default();
    let q = Vector::<7>::from_column_slice(&common::PANDA_HOME);
    let tip = model.chain().tip(&q, &Vector::zeros());
    let c = Setpoint {
        x: q,
        dx: Vector::from_element(0.1),
        ddx: Vector::zeros(),
    };
    let task = TaskTorque {
        commanded: c,
        jacobian: tip.jacobian,
        spring: Vector::<6>::from_element(1.0),
        damping: Vector::<6>::from_element(20.0),
        twist: Vector::zeros(),
        lambda2: Vector::<6>::from_element(1e-4),
        share: 0.3,
    };
    let m = adaptimp::Measurement {
        x: q,
        dx: Some(Vector::zeros()),
        tau_e: Vector::zeros(),
    };
    let (n, ()) = allocations_in(|| {
        for _ in 0..1000 {
            ct.step(&mut st, &m, &c).expect("step");
            ct.step_task(&mut st, &m, &c, &task).expect("task step");
        }
    });
    assert_eq!(n, 0, "a computed-torque step allocated");
    assert_eq!(st.k, 2000);
}

/// The run-time API (`adaptimp::dynamic`, n known at run time): built once
/// for its n, its steps allocate nothing, as the const-generic ones: the
/// n = 7 joint step (the rule's default basis), the n = 7 Cartesian pair,
/// computed torque, the chain and the dynamics, and the closed loops with
/// their rows sized before.
#[test]
fn no_heap_allocation_in_the_run_time_api() {
    use adaptimp::dynamic as dy;
    use adaptimp::schema::{Preset, Value};
    use adaptimp::{ImpedanceMode, Inertial, Joint, Link, Transform};
    const N: usize = 7;
    let mut s = dy::Scenario::new(N, Preset::Robot, Law::StateFeedback).expect("n");
    let tau_max = common::PANDA_EFFORT;
    s.set("tau_max", Value::Vec(&tau_max)).expect("tau_max");
    s.set("impedance", Value::Str("external"))
        .expect("impedance");
    let joint = s.controller().expect("joint controller");
    let mut st = joint.new_state();
    let q = common::PANDA_HOME;
    let (zero, dq) = ([0.0; N], [0.01; N]);
    let (n, ()) = allocations_in(|| {
        for _ in 0..1000 {
            let m = dy::Measurement {
                x: &q,
                dx: Some(&dq),
                tau_e: &zero,
            };
            joint.step(&mut st, &m, None).expect("step");
        }
    });
    assert_eq!(n, 0, "the run-time n = 7 step allocated");
    // The Cartesian pair on the Panda's chain, along a circle.
    let h = std::f64::consts::FRAC_PI_2;
    let rev = |xyz: [f64; 3], roll: f64| {
        Joint::revolute(
            Transform::from_xyz_rpy(xyz, [roll, 0.0, 0.0]),
            [0.0, 0.0, 1.0],
        )
    };
    let js = [
        rev([0.0, 0.0, 0.333], 0.0),
        rev([0.0, 0.0, 0.0], -h),
        rev([0.0, -0.316, 0.0], h),
        rev([0.0825, 0.0, 0.0], h),
        rev([-0.0825, 0.384, 0.0], -h),
        rev([0.0, 0.0, 0.0], h),
        rev([0.088, 0.0, 0.0], h),
    ];
    let tcp = Transform::from_xyz_rpy([0.0, 0.0, 0.2104], [0.0; 3]);
    let chain = dy::Chain::new(&js, &tcp).expect("chain");
    let outer = dy::CartesianImpedance::new(s.cartesian(), &chain, 1e-3).expect("outer");
    let pair = dy::CartesianController::new(outer, joint).expect("pair");
    let (mut ost, mut ist) = (pair.start(&q).expect("start"), pair.joint().new_state());
    let tip = chain.tip(&q, &zero).expect("tip");
    let (n, ()) = allocations_in(|| {
        for k in 0..1000 {
            let t = k as f64 * 1e-3;
            let target = adaptimp::PoseTarget::at(
                tip.position + Vector::<3>::new(0.02 * t.sin(), 0.0, 0.0),
                *tip.rotation.matrix(),
            );
            let m = dy::CartesianMeasurement {
                q: &q,
                dq: Some(&dq),
                wrench: Vector::<6>::new(0.0, 0.0, -2.0, 0.0, 0.0, 0.0),
            };
            pair.step(&mut ost, &mut ist, &m, Some(&target))
                .expect("step");
            chain.tip(&q, &dq).expect("tip");
        }
    });
    assert_eq!(n, 0, "the run-time Cartesian step allocated");
    // Computed torque and the dynamics (one inertial per joint of the list).
    let inertials = [Inertial::point(1.5, [0.02, 0.01, 0.06]); N];
    let model = dy::Dynamics::new(&js, &inertials, adaptimp::GRAVITY).expect("model");
    let ct = dy::ComputedTorque::new(
        &dy::ComputedTorqueConfig {
            ts: 1e-3,
            kp: &[400.0; N],
            kd: &[40.0; N],
            tau_max: &tau_max,
            dd: &[1.0; N],
            cd: &[20.0; N],
            gd: &[100.0; N],
            mode: ImpedanceMode::External,
        },
        model.clone(),
    )
    .expect("computed torque");
    let mut cst = ct.new_state();
    let sp = dy::Setpoint {
        x: &q[..],
        dx: &dq[..],
        ddx: &zero[..],
    };
    let (n, ()) = allocations_in(|| {
        for _ in 0..1000 {
            let m = dy::Measurement {
                x: &q,
                dx: Some(&dq),
                tau_e: &zero,
            };
            ct.step(&mut cst, &m, &sp).expect("step");
            model.inverse_dynamics(&q, &dq, &zero).expect("id");
            model.mass_matrix(&q).expect("M");
        }
    });
    assert_eq!(n, 0, "run-time computed torque or dynamics allocated");
    // OSC_POSE's Λ (SPEC (23.7)) on the chain's Jacobian and the model's D.
    let mut jr = [0.0; 6 * N];
    chain.jacobian_rows(&q, &mut jr).expect("J");
    let d = model.mass_matrix(&q).expect("D");
    let dr: [f64; N * N] = std::array::from_fn(|k| d[(k / N, k % N)]);
    let (n, ()) = allocations_in(|| {
        for uncoupled in [true, false] {
            dy::operational_inertia(&jr, &dr, uncoupled).expect("Λ");
        }
    });
    assert_eq!(n, 0, "the operational inertia allocated");
    // The closed loop: a planar arm of three links, its rows sized before.
    let mut s = dy::Scenario::new(3, Preset::Paper, Law::StateFeedback).expect("n");
    s.set("q0", Value::Vec(&[0.1, 0.2, 0.3])).expect("q0");
    let ctrl = s.controller().expect("controller");
    let mut st = ctrl.new_state();
    let dist = s.disturbances().expect("disturbances");
    let arm = dy::ModelArm::Planar {
        links: vec![
            Link {
                mass: 1.0,
                length: 0.3,
                com: 0.15,
                inertia: 0.01
            };
            3
        ],
        g: 9.81,
    };
    let mut plant = dy::RigidBody::new(&arm, &s, &dist).expect("plant");
    let run = dy::Run {
        t_final: 0.05,
        settle: 0.0,
        every: 1,
        disturbances: Some(&dist),
        injection: None,
    };
    let mut rows = dy::Rows::for_run(3, &run, ctrl.period()).expect("rows");
    let (n, metrics) = allocations_in(|| {
        dy::simulate(
            &mut plant,
            dy::Controlled::Joint(dy::Joint::Adaptive(&ctrl, &mut st)),
            dy::Reference::Trajectory,
            &run,
            &mut (),
            &mut rows,
        )
    });
    assert_eq!(metrics.expect("run").rows, 1000);
    assert_eq!(n, 0, "the run-time closed loop allocated");
    // The Cartesian loop on the same arm, position-only, its rows sized before.
    let js: Vec<Joint> = (0..3)
        .map(|i| {
            let x = if i == 0 { 0.0 } else { 0.3 };
            Joint::revolute(
                Transform::from_xyz_rpy([x, 0.0, 0.0], [0.0; 3]),
                [0.0, 0.0, 1.0],
            )
        })
        .collect();
    let tip = Transform::from_xyz_rpy([0.3, 0.0, 0.0], [0.0; 3]);
    let chain = dy::Chain::new(&js, &tip).expect("chain");
    s.set("impedance", Value::Str("external"))
        .expect("impedance");
    let joint = s.controller().expect("joint");
    let cfg = adaptimp::CartesianConfig::default().position_only();
    let outer = dy::CartesianImpedance::new(cfg, &chain, joint.period()).expect("outer");
    let mut ost = outer.start(&[0.1, 0.2, 0.3]).expect("start");
    let mut ist = joint.new_state();
    let mut plant = dy::RigidBody::new(&arm, &s, &dist).expect("plant");
    let mut rows = dy::Rows::for_run(3, &run, joint.period()).expect("rows");
    let mut task = dy::TaskRows::for_run(3, &run, joint.period()).expect("rows");
    let (n, metrics) = allocations_in(|| {
        dy::simulate_cartesian(
            &mut plant,
            &outer,
            &mut ost,
            dy::Joint::Adaptive(&joint, &mut ist),
            None,
            &run,
            &mut (),
            &mut rows,
            &mut task,
        )
    });
    assert_eq!(metrics.expect("run").rows, 1000);
    assert_eq!(n, 0, "the run-time Cartesian loop allocated");
}
