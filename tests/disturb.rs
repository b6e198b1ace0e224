//! The disturbances of SPEC §17 in closed loops: each one has the physical
//! effect it should, none of them changes a bit when it is off, and a seed
//! fixes a run bit for bit, in any thread. Every assertion is exact or has a
//! tolerance fixed by a fixed seed.

use adaptimp::impedance::TargetImpedance;
use adaptimp::schema::{Preset, Scenario, Value};
use adaptimp::{
    run, run_disturbed, simulate_disturbed, Command, Control, Controller, DisturbanceParams,
    Disturbances, Error, FreeSpace, Friction, Injected, Injection, Law, Manipulator, Measurement,
    Plant, RigidBody, SimConfig, Sinusoid, Trace, TwoLinkArm, Vector, Wall, WithFriction,
};
use adaptimp::{Setpoint, TipPayload};

type V2 = Vector<2>;

fn tau_max() -> V2 {
    V2::new(17.0, 15.0)
}

fn disturbances(p: DisturbanceParams<2>) -> Disturbances<2> {
    Disturbances::new(p, tau_max()).expect("valid disturbances")
}

/// Every disturbance on at once (a real robot's bad day).
fn everything(seed: u64) -> DisturbanceParams<2> {
    DisturbanceParams {
        payload: 0.3,
        noise_q: V2::from_element(1e-4),
        noise_dq: V2::from_element(1e-2),
        noise_tau_e: V2::from_element(0.2),
        seed,
        delay: 2,
        jitter: 0.1,
        friction_viscous: V2::from_element(0.05),
        friction_coulomb: V2::from_element(0.2),
        friction_vs: 0.01,
        actuator_fraction: V2::new(0.9, 0.8),
    }
}

/// A controller that applies a fixed torque and remembers what it saw: the
/// plant's motion does not depend on its measurements.
struct Spy {
    ts: f64,
    tau: V2,
    target: TargetImpedance<2>,
    seen: Vec<Measurement<2>>,
    setpoints: Vec<Setpoint<2>>,
}

impl Spy {
    fn new(ts: f64, tau: V2) -> Self {
        Self {
            ts,
            tau,
            target: TargetImpedance::paper(),
            seen: Vec::new(),
            setpoints: Vec::new(),
        }
    }
}

impl Control<2> for Spy {
    fn period(&self) -> f64 {
        self.ts
    }
    fn target(&self) -> &TargetImpedance<2> {
        &self.target
    }
    fn step(&mut self, m: &Measurement<2>, c: &Setpoint<2>) -> Result<Command<2>, Error> {
        self.seen.push(*m);
        self.setpoints.push(*c);
        Ok(Command {
            tau_sat: self.tau,
            tau: self.tau,
            ..Command::zeros()
        })
    }
}

/// The paper controller `law` at 1 kHz (robot scenario) closing the loop for
/// `t` s against the wall, with `d`; its rows.
fn robot_run(law: Law, t: f64, d: &Disturbances<2>) -> Trace<2> {
    let ctrl = Controller::robot(law);
    let mut state = ctrl.new_state();
    let sim = SimConfig {
        t_final: t,
        ..SimConfig::robot()
    };
    let mut trace = Trace::default();
    run_disturbed(
        &TwoLinkArm::paper(),
        &Wall::paper(),
        &mut ctrl.bind(&mut state),
        &Sinusoid::paper(),
        &sim,
        d,
        &mut trace,
    )
    .expect("the run completes");
    trace
}

fn rms_z1(trace: &Trace<2>, from: f64) -> f64 {
    let rows: Vec<_> = trace.rows.iter().filter(|r| r.t >= from).collect();
    (rows.iter().map(|r| r.z1.norm_squared()).sum::<f64>() / rows.len() as f64).sqrt()
}

#[test]
fn no_disturbance_is_the_undisturbed_run_bit_for_bit() {
    let sim = SimConfig {
        t_final: 0.3,
        ..SimConfig::paper()
    };
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        let ctrl = Controller::paper(law);
        let plain = {
            let mut state = ctrl.new_state();
            let mut trace = Trace::default();
            run(
                &TwoLinkArm::paper(),
                &Wall::paper(),
                &mut ctrl.bind(&mut state),
                &Sinusoid::paper(),
                &sim,
                &mut trace,
            )
            .expect("run");
            trace
        };
        // The explicit "none", and the schema's defaults in both presets.
        let mut all = vec![Disturbances::none()];
        for preset in Preset::ALL {
            all.push(Scenario::<2>::preset(preset, law).disturbances().unwrap());
        }
        for d in all {
            assert!(d.is_none());
            let mut state = ctrl.new_state();
            let mut trace = Trace::default();
            run_disturbed(
                &TwoLinkArm::paper(),
                &Wall::paper(),
                &mut ctrl.bind(&mut state),
                &Sinusoid::paper(),
                &sim,
                &d,
                &mut trace,
            )
            .expect("run");
            assert!(trace == plain, "{law:?}: a run without disturbance changed");
        }
    }
}

#[test]
fn a_seed_fixes_the_run_bit_for_bit_in_any_thread() {
    let d = disturbances(everything(42));
    let serial = robot_run(Law::StateFeedback, 1.0, &d);
    assert_eq!(serial.rows.len(), 1000);
    assert!(serial
        .rows
        .iter()
        .all(|r| r.x.iter().all(|x| x.is_finite())));
    let parallel: Vec<Trace<2>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..2)
            .map(|_| s.spawn(|| robot_run(Law::StateFeedback, 1.0, &d)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("thread"))
            .collect()
    });
    for p in &parallel {
        assert!(*p == serial, "a parallel run differs from the serial one");
    }
    let other = robot_run(Law::StateFeedback, 1.0, &disturbances(everything(43)));
    assert!(other != serial, "another seed, the same run");
}

#[test]
fn delay_shows_the_controller_the_sample_of_k_minus_d() {
    let ts = 1e-3;
    // A constant torque pushes joint 1 into the wall: q, q̇ and τe all move.
    let spy_run = |delay: usize| {
        let mut plant = RigidBody::new(
            TwoLinkArm::paper(),
            Wall::paper(),
            V2::new(0.1, 0.0),
            V2::zeros(),
            10,
        )
        .unwrap();
        let mut spy = Spy::new(ts, V2::new(12.0, 2.0));
        let d = disturbances(DisturbanceParams {
            delay,
            ..DisturbanceParams::default()
        });
        let mut trace = Trace::default();
        simulate_disturbed(
            &mut plant,
            &mut spy,
            &Sinusoid::paper(),
            0.5,
            None,
            &d,
            &mut trace,
        )
        .unwrap();
        (spy.seen, spy.setpoints, trace)
    };
    let (now, at, truth) = spy_run(0);
    assert!(
        truth.rows.iter().any(|r| r.tau_e[0] > 0.0),
        "the wall is touched"
    );
    let motion = |t: &Trace<2>| -> Vec<(V2, V2, V2, V2)> {
        t.rows.iter().map(|r| (r.x, r.dx, r.tau_e, r.xc)).collect()
    };
    for delay in [1, 7, 64] {
        let (late, late_at, rows) = spy_run(delay);
        assert!(
            motion(&rows) == motion(&truth),
            "the delay changed the plant's motion"
        );
        for (k, m) in late.iter().enumerate() {
            let then = k.saturating_sub(delay);
            assert_eq!(*m, now[then], "d = {delay}, k = {k}");
            // SPEC (17.1): the setpoint of the sample's own instant, t_(k−d).
            assert_eq!(late_at[k], at[then], "d = {delay}, k = {k}");
            // The row's z1: the spy's (zero) plus the sample's error, here the
            // delay's: the true q of step k − d less the true q of step k − d.
            assert_eq!(rows.rows[k].z1, V2::zeros(), "d = {delay}, k = {k}");
        }
    }
    // What the controller saw without delay is the plant's sample, exactly.
    for (m, r) in now.iter().zip(&truth.rows) {
        assert_eq!((m.x, m.dx, m.tau_e), (r.x, Some(r.dx), r.tau_e));
    }
}

/// A plant whose end effector measures a different wrench at every sample
/// (its sample count in f_x, the joint position in f_y, f_z): the wrench a
/// controller is given tells which sample it is.
struct Sensing<P> {
    plant: P,
    k: f64,
}

impl<P: Plant<2>> Plant<2> for Sensing<P> {
    fn state(&self) -> (V2, V2) {
        self.plant.state()
    }
    fn contact(&self) -> V2 {
        self.plant.contact()
    }
    fn advance(&mut self, tau: &V2, h: f64) -> Result<V2, Error> {
        self.k += 1.0;
        self.plant.advance(tau, h)
    }
    fn wrench(&self) -> [f64; 6] {
        let (x, _) = self.plant.state();
        [self.k, x[0], x[1], 0.5, -0.5, self.k * 0.25]
    }
}

/// A [`Spy`] that also remembers the wrenches it was given.
struct WrenchSpy(Spy, Vec<[f64; 6]>);

impl Control<2> for WrenchSpy {
    fn period(&self) -> f64 {
        self.0.period()
    }
    fn target(&self) -> &TargetImpedance<2> {
        self.0.target()
    }
    fn step(&mut self, m: &Measurement<2>, c: &Setpoint<2>) -> Result<Command<2>, Error> {
        self.0.step(m, c)
    }
    fn step_with_wrench(
        &mut self,
        m: &Measurement<2>,
        wrench: &[f64; 6],
        c: &Setpoint<2>,
    ) -> (V2, Result<Command<2>, Error>) {
        self.1.push(*wrench);
        self.step_or_fallback(m, c)
    }
}

#[test]
fn the_wrench_goes_through_the_sensor_path_delayed_and_frozen_with_the_joints() {
    let ts = 1e-3;
    let spy_run = |delay: usize, noise: f64, injection: Option<&Injection<2>>| {
        let mut plant = Sensing {
            plant: RigidBody::new(
                TwoLinkArm::paper(),
                FreeSpace,
                V2::new(0.1, 0.0),
                V2::zeros(),
                2,
            )
            .unwrap(),
            k: 0.0,
        };
        let mut spy = WrenchSpy(Spy::new(ts, V2::new(3.0, 1.0)), Vec::new());
        let d = disturbances(DisturbanceParams {
            delay,
            noise_q: V2::from_element(noise),
            noise_tau_e: V2::from_element(noise),
            ..DisturbanceParams::default()
        });
        let mut trace = Trace::default();
        simulate_disturbed(
            &mut plant,
            &mut spy,
            &Sinusoid::paper(),
            0.2,
            injection,
            &d,
            &mut trace,
        )
        .unwrap();
        (spy.0.seen, spy.1, trace)
    };
    let (now, wrench_now, truth) = spy_run(0, 0.0, None);
    // Undisturbed: the controller is given the row's wrench, exactly.
    assert_eq!(wrench_now.len(), truth.rows.len());
    for (w, r) in wrench_now.iter().zip(&truth.rows) {
        assert_eq!(*w, r.wrench);
    }
    for delay in [1, 5, 64] {
        let (seen, wrench, rows) = spy_run(delay, 0.0, None);
        assert!(rows == truth, "the delay changed the plant's motion");
        for k in 0..rows.rows.len() {
            let then = k.saturating_sub(delay);
            assert_eq!(wrench[k], truth.rows[then].wrench, "d = {delay}, k = {k}");
            assert_eq!(seen[k], now[then], "d = {delay}, k = {k}");
        }
    }
    // Noise is on τe (N m per joint), not on the wrench, and draws nothing for it.
    let (noisy, wrench, _) = spy_run(2, 1e-3, None);
    let (quiet, _, _) = spy_run(2, 0.0, None);
    assert!(noisy != quiet, "the noise reached the joint sample");
    for (k, w) in wrench.iter().enumerate() {
        assert_eq!(*w, truth.rows[k.saturating_sub(2)].wrench, "k = {k}");
    }
    // A stale sensor freezes the wrench with q, q̇, τe; other faults leave it be.
    let stale = Injection {
        fault: Injected::Stale,
        start: 0.05,
        duration: 0.02,
    };
    let (seen, wrench, rows) = spy_run(0, 0.0, Some(&stale));
    let first = 50;
    for (k, r) in rows.rows.iter().enumerate() {
        let want = if stale.active(r.t) { first - 1 } else { k };
        assert_eq!(wrench[k], truth.rows[want].wrench, "k = {k}");
        assert_eq!(seen[k].x, now[want].x, "k = {k}");
    }
    assert!(rows.rows.iter().filter(|r| stale.active(r.t)).count() >= 19);
    let bias = Injection {
        fault: Injected::ForceBias {
            bias: V2::new(1.0, -1.0),
        },
        ..stale
    };
    let (_, wrench, _) = spy_run(0, 0.0, Some(&bias));
    assert_eq!(wrench, wrench_now);
}

#[test]
fn delay_degrades_closed_loop_tracking() {
    let delayed = |d| {
        robot_run(
            Law::Pd,
            4.0,
            &disturbances(DisturbanceParams {
                delay: d,
                ..DisturbanceParams::default()
            }),
        )
    };
    let rms: Vec<f64> = [0, 5, 10].map(|d| rms_z1(&delayed(d), 2.0)).to_vec();
    eprintln!("PD at 1 kHz, RMS ‖z1‖ (t ≥ 2 s) for delay 0, 5, 10 steps: {rms:?}");
    assert!(rms[0] < rms[1] && rms[1] < rms[2], "{rms:?}");
}

/// The error of one measured channel at one row.
type ChannelError = dyn Fn(&Measurement<2>, &adaptimp::Row<2>) -> f64;

#[test]
fn sensor_noise_has_the_given_standard_deviation_and_is_seeded() {
    let ts = 1e-3;
    let sd = (2e-3, 0.05, 0.4);
    let noisy = |seed| {
        let mut plant = RigidBody::new(
            TwoLinkArm::paper(),
            FreeSpace,
            V2::new(0.3, 0.2),
            V2::zeros(),
            10,
        )
        .unwrap();
        let mut spy = Spy::new(ts, V2::new(3.0, -1.0));
        let d = disturbances(DisturbanceParams {
            noise_q: V2::from_element(sd.0),
            noise_dq: V2::new(sd.1, 0.0),
            noise_tau_e: V2::from_element(sd.2),
            seed,
            ..DisturbanceParams::default()
        });
        let mut trace = Trace::default();
        simulate_disturbed(
            &mut plant,
            &mut spy,
            &Sinusoid::paper(),
            10.0,
            None,
            &d,
            &mut trace,
        )
        .unwrap();
        (spy.seen, trace)
    };
    let (seen, truth) = noisy(11);
    let (again, _) = noisy(11);
    assert!(seen == again, "the same seed gave other noise");
    let (other, _) = noisy(12);
    assert!(seen != other, "another seed gave the same noise");
    let n = seen.len() as f64;
    let std_of = |f: &ChannelError| {
        let e: Vec<f64> = seen.iter().zip(&truth.rows).map(|(m, r)| f(m, r)).collect();
        let mean = e.iter().sum::<f64>() / n;
        let std = (e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        (mean, std)
    };
    let channels: [(&ChannelError, f64); 5] = [
        (&|m, r| m.x[0] - r.x[0], sd.0),
        (&|m, r| m.x[1] - r.x[1], sd.0),
        (&|m, r| m.dx.expect("a velocity")[0] - r.dx[0], sd.1),
        (&|m, r| m.tau_e[0] - r.tau_e[0], sd.2),
        (&|m, r| m.tau_e[1] - r.tau_e[1], sd.2),
    ];
    // 10 000 samples: the sample std's relative error has std 0.7 %; 3 % is
    // over four of those (a fixed seed: deterministic).
    for (f, sd) in channels {
        let (mean, std) = std_of(f);
        assert!((std / sd - 1.0).abs() < 0.03, "std {std} for σ {sd}");
        assert!(mean.abs() < 4.0 * sd / n.sqrt(), "mean {mean} for σ {sd}");
    }
    // A channel with σ = 0 is exact.
    let dq = |m: &Measurement<2>| m.dx.expect("a velocity");
    assert!(seen
        .iter()
        .zip(&truth.rows)
        .all(|(m, r)| dq(m)[1] == r.dx[1]));
}

/// A plant that remembers the intervals it was advanced by.
struct Intervals<P> {
    plant: P,
    h: Vec<f64>,
}

impl<P: Plant<2>> Plant<2> for Intervals<P> {
    fn state(&self) -> (V2, V2) {
        self.plant.state()
    }
    fn contact(&self) -> V2 {
        self.plant.contact()
    }
    fn advance(&mut self, tau: &V2, h: f64) -> Result<V2, Error> {
        self.h.push(h);
        self.plant.advance(tau, h)
    }
}

#[test]
fn jitter_advances_the_plant_by_the_true_intervals() {
    let ts = 1e-3;
    let j = 0.25;
    let rigid = RigidBody::new(
        TwoLinkArm::paper(),
        FreeSpace,
        V2::new(0.3, 0.2),
        V2::zeros(),
        10,
    )
    .unwrap();
    let mut plant = Intervals {
        plant: rigid,
        h: Vec::new(),
    };
    let mut spy = Spy::new(ts, V2::new(3.0, -1.0));
    let d = disturbances(DisturbanceParams {
        jitter: j,
        seed: 5,
        ..DisturbanceParams::default()
    });
    let mut trace = Trace::default();
    simulate_disturbed(
        &mut plant,
        &mut spy,
        &Sinusoid::paper(),
        5.0,
        None,
        &d,
        &mut trace,
    )
    .unwrap();
    let h = &plant.h;
    assert_eq!(h.len(), 5000);
    assert!(h
        .iter()
        .all(|h| ((1.0 - j) * ts..(1.0 + j) * ts).contains(h)));
    let mean = h.iter().sum::<f64>() / h.len() as f64;
    // u ~ U[−j, j): std j/√3 = 0.144; the mean of 5000 is within 4 σ (0.8 %) of Ts.
    assert!((mean / ts - 1.0).abs() < 8e-3, "{mean}");
    // The plant's clock is the sum of the true intervals; the rows keep the
    // controller's clock k·Ts.
    let elapsed: f64 = h.iter().sum();
    assert_eq!(plant.plant.time(), h.iter().fold(0.0, |t, h| t + h));
    assert!(
        (elapsed - 5.0).abs() > 1e-6,
        "the plant's clock drifts from k·Ts"
    );
    assert!(trace
        .rows
        .iter()
        .enumerate()
        .all(|(k, r)| r.t == k as f64 * ts));
    // Without jitter every interval is Ts exactly.
    let mut plant = Intervals {
        plant: rigid,
        h: Vec::new(),
    };
    let d = disturbances(DisturbanceParams {
        seed: 5,
        ..DisturbanceParams::default()
    });
    simulate_disturbed(
        &mut plant,
        &mut spy,
        &Sinusoid::paper(),
        1.0,
        None,
        &d,
        &mut (),
    )
    .unwrap();
    assert!(plant.h.iter().all(|h| *h == ts));
}

/// Kinetic plus potential energy (J) of the paper's arm: ½ q̇ᵀ D q̇ + U,
/// U = p4 g sin q1 + p5 g sin(q1 + q2) (so that ∂U/∂q = G, (58)).
fn energy(arm: &TwoLinkArm, q: &V2, dq: &V2) -> f64 {
    let [_, _, _, p4, p5] = arm.lumped();
    let g = arm.params().g;
    0.5 * dq.dot(&(arm.inertia(q) * dq)) + p4 * g * q[0].sin() + p5 * g * (q[0] + q[1]).sin()
}

#[test]
fn friction_dissipates_the_energy_of_a_free_swing() {
    let arm = TwoLinkArm::paper();
    let swing = |friction: Friction<2>| {
        let plant = WithFriction::new(arm, friction);
        let mut rigid =
            RigidBody::new(plant, FreeSpace, V2::new(0.5, 0.3), V2::zeros(), 10).unwrap();
        let mut spy = Spy::new(1e-3, V2::zeros());
        let mut trace = Trace::default();
        let none = Disturbances::none();
        simulate_disturbed(
            &mut rigid,
            &mut spy,
            &Sinusoid::paper(),
            5.0,
            None,
            &none,
            &mut trace,
        )
        .unwrap();
        trace
            .rows
            .iter()
            .map(|r| energy(&arm, &r.x, &r.dx))
            .collect::<Vec<f64>>()
    };
    // Without friction the swing keeps its energy (RK4 at 0.1 ms).
    let free = swing(Friction::none());
    let drift = free.iter().map(|e| (e - free[0]).abs()).fold(0.0, f64::max);
    eprintln!("energy drift without friction: {drift:e} J");
    assert!(drift < 1e-8, "energy drift without friction: {drift} J");
    // With friction it never gains energy, and loses most of it.
    for friction in [
        Friction::new(V2::from_element(0.05), V2::zeros(), 0.01).unwrap(),
        Friction::new(V2::zeros(), V2::from_element(0.1), 0.01).unwrap(),
        Friction::new(V2::from_element(0.05), V2::from_element(0.1), 0.01).unwrap(),
    ] {
        let e = swing(friction);
        assert!(
            e.windows(2).all(|w| w[1] <= w[0] + 1e-10),
            "{friction:?} gained energy"
        );
        // The lowest energy of this arm is at q = (−π/2, 0): U = −(p4 + p5) g.
        let [_, _, _, p4, p5] = arm.lumped();
        let lowest = -(p4 + p5) * arm.params().g;
        let swing_energy = e[0] - lowest;
        let left = e[e.len() - 1] - lowest;
        eprintln!("{friction:?}: {left} of {swing_energy} J left after 5 s");
        assert!(
            left < 0.5 * swing_energy,
            "{friction:?}: {left} of {swing_energy} J left"
        );
    }
}

#[test]
fn the_plant_carries_the_payload_the_controller_does_not_know() {
    // The nominal gravity torque applied at rest holds the nominal arm: the
    // loaded one accelerates by −D'⁻¹ ΔG, ΔG = m g (lever of the tip).
    let arm = TwoLinkArm::paper();
    let q0 = V2::new(0.3, -0.4);
    let mp = 0.4;
    let first_row = |payload: f64| {
        let mut spy = Spy::new(1e-3, arm.gravity(&q0));
        let sim = SimConfig {
            t_final: 0.001,
            q0,
            dq0: V2::zeros(),
            ..SimConfig::robot()
        };
        let d = disturbances(DisturbanceParams {
            payload,
            ..DisturbanceParams::default()
        });
        let mut trace = Trace::default();
        run_disturbed(
            &arm,
            &FreeSpace,
            &mut spy,
            &Sinusoid::paper(),
            &sim,
            &d,
            &mut trace,
        )
        .unwrap();
        trace.rows[0]
    };
    assert!(first_row(0.0).ddx.norm() < 1e-12);
    let a = arm.params();
    let dg = V2::new(
        mp * a.g * (a.l1 * q0[0].cos() + a.l2 * (q0[0] + q0[1]).cos()),
        mp * a.g * a.l2 * (q0[0] + q0[1]).cos(),
    );
    let loaded = arm.with_payload(mp).unwrap();
    let expect = -loaded.inertia(&q0).cholesky().unwrap().solve(&dg);
    let got = first_row(mp).ddx;
    assert!(
        (got - expect).norm() < 1e-9 * expect.norm(),
        "{got} vs {expect}"
    );
}

#[test]
fn arm_parameters_and_disturbances_reach_the_plant_only() {
    let nominal = Scenario::<2>::preset(Preset::Robot, Law::StateFeedback);
    let mut changed = nominal;
    for (name, v) in [
        ("m1", Value::Real(2.4)),
        ("m2", Value::Real(1.1)),
        ("l1", Value::Real(0.37)),
        ("l2", Value::Real(0.29)),
        ("payload", Value::Real(0.5)),
        ("noise_q", Value::Real(1e-4)),
        ("friction_coulomb", Value::Vec(&[0.2, 0.1])),
        ("actuator_fraction", Value::Real(0.7)),
        ("plant_delay", Value::Int(3)),
        ("jitter", Value::Real(0.05)),
        ("seed", Value::Int(9)),
    ] {
        changed.set(name, v).unwrap();
    }
    // The controller is built from the configuration, the grid and the
    // trajectory: none of them changed.
    assert_eq!(changed.config, nominal.config);
    assert_eq!(changed.grid().unwrap(), nominal.grid().unwrap());
    assert_eq!(changed.trajectory().unwrap(), nominal.trajectory().unwrap());
    // The plant did.
    let arm = changed.arm().unwrap();
    assert_eq!((arm.params().m1, arm.params().l2), (2.4, 0.29));
    assert_eq!(arm.params().lc2, 0.29 / 2.0);
    let d = changed.disturbances().unwrap();
    assert_eq!(d.payload(), 0.5);
    assert_eq!(d.params().actuator_fraction, V2::from_element(0.7));
    assert_eq!(d.params().seed, 9);
    // And the run with the heavier arm is another run.
    let run_with = |s: &Scenario<2>| {
        let traj = s.trajectory().unwrap();
        let ctrl = Controller::for_trajectory(s.config, s.grid().unwrap(), &traj).unwrap();
        let mut state = ctrl.new_state();
        let sim = SimConfig {
            t_final: 0.5,
            ..s.sim
        };
        let mut trace = Trace::default();
        run_disturbed(
            &s.arm().unwrap(),
            &Wall::paper(),
            &mut ctrl.bind(&mut state),
            &traj,
            &sim,
            &s.disturbances().unwrap(),
            &mut trace,
        )
        .unwrap();
        trace
    };
    let a = run_with(&nominal);
    let b = run_with(&changed);
    assert_eq!(a.rows[0].x, b.rows[0].x);
    assert!(a.rows[1].x != b.rows[1].x);
}

#[test]
fn a_weak_actuator_never_delivers_more_than_rho_tau_max() {
    let rho = V2::new(0.5, 0.4);
    let d = disturbances(DisturbanceParams {
        actuator_fraction: rho,
        ..DisturbanceParams::default()
    });
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        let trace = robot_run(law, 2.0, &d);
        let limit = rho.component_mul(&tau_max());
        for r in &trace.rows {
            for i in 0..2 {
                assert!(
                    r.tau_sat[i].abs() <= limit[i],
                    "{law:?}: {} at t = {}",
                    r.tau_sat,
                    r.t
                );
            }
        }
        // The weak actuator is the limit at times (the start in the wall).
        assert!(
            trace.rows.iter().any(|r| r.tau_sat[0].abs() == limit[0]),
            "{law:?}: never at the weakened limit"
        );
    }
}

#[test]
fn the_schema_defaults_are_no_disturbance() {
    for preset in Preset::ALL {
        for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
            let s = Scenario::<2>::preset(preset, law);
            assert_eq!(s.disturb, DisturbanceParams::default(), "{preset:?}");
        }
    }
}

#[test]
fn the_schema_builds_the_disturbances_and_names_bad_values() {
    let mut s = Scenario::<2>::preset(Preset::Paper, Law::Pd);
    let e = s.set("seed", Value::Int(-1)).unwrap_err();
    assert!(e.to_string().contains("seed ≥ 0"), "{e}");
    let e = s.set("plant_delay", Value::Int(65)).unwrap_err();
    assert!(e.to_string().contains("0 ≤ plant_delay ≤ 64"), "{e}");
    // The controller's own delay (SPEC (18.11)) is checked by the same bound.
    let e = s.set("delay", Value::Int(65)).unwrap_err();
    assert!(e.to_string().contains("0 ≤ delay ≤ 64"), "{e}");
    for (name, v, condition) in [
        ("jitter", Value::Real(1.0), "0 ≤ jitter < 1"),
        ("payload", Value::Real(-0.1), "payload ≥ 0"),
        ("noise_tau_e", Value::Real(-1.0), "noise ≥ 0"),
        ("friction_vs", Value::Real(0.0), "v_s > 0"),
        ("actuator_fraction", Value::Vec(&[1.0, 0.0]), "0 < ρ ≤ 1"),
    ] {
        let mut bad = s;
        bad.set(name, v).unwrap();
        let e = bad.disturbances().unwrap_err();
        assert!(e.to_string().contains(condition), "{name}: {e}");
        let p = adaptimp::schema::param(name).unwrap();
        assert_eq!(
            p.condition, condition,
            "{name}: the schema states another condition"
        );
    }
    s.set("plant_delay", Value::Int(64)).unwrap();
    s.set("seed", Value::Int(i64::MAX)).unwrap();
    let d = s.disturbances().unwrap();
    assert_eq!((d.params().delay, d.params().seed), (64, i64::MAX as u64));
}

#[test]
fn the_rows_tracking_error_is_the_true_states_not_the_noisy_samples() {
    // SPEC (17.1): with sensor noise the controller compares its reference
    // with a noisy q; the row's z1 is the reference less the plant's true q.
    let noisy = disturbances(DisturbanceParams {
        noise_q: V2::from_element(1e-3),
        seed: 5,
        ..DisturbanceParams::default()
    });
    let trace = robot_run(Law::StateFeedback, 0.3, &noisy);
    for r in &trace.rows {
        let truth = r.xd - r.x;
        assert!(
            (r.z1 - truth).amax() <= 1e-12,
            "{:?} against {:?}",
            r.z1,
            truth
        );
    }
    // Without noise or delay the row's z1 is the controller's own, bit for bit.
    let clean = robot_run(Law::StateFeedback, 0.3, &Disturbances::none());
    assert!(clean.rows.iter().all(|r| r.z1 == r.xd - r.x));
}
