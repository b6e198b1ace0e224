use super::*;
use crate::control::state::HeapState;
use crate::networks::learning::{LearningStep, SaturationLearning};
use crate::trajectory::Sinusoid;

fn measurement() -> Measurement<2> {
    Measurement {
        x: Vector::<2>::new(0.15, 0.25),
        dx: Some(Vector::<2>::new(0.4, -0.3)),
        tau_e: Vector::<2>::zeros(),
    }
}

/// The circle's setpoint at the state's next step.
fn setpoint(c: &Controller<2>, st: &HeapState<2>) -> Setpoint<2> {
    Sinusoid::paper().sample(c.time(st))
}

/// Change of the network output per unit z2 made by one learning step,
/// at that step's basis: the per-step learning gain (N m per rad/s).
fn per_step_gain(cfg: Config<2>) -> Vector<2> {
    let c = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).unwrap();
    let mut st = c.new_state();
    let m = measurement();
    let before: Vec<f64> = (0..10).flat_map(|i| row(&st, i)).collect();
    let sp = setpoint(&c, &st);
    let cmd = c.step(&mut st, &m, &sp).unwrap();
    let s = st.basis().to_vec();
    let e = c.errors(
        &Reference::start(&Sinusoid::paper().sample(0.0)),
        &Sinusoid::paper().sample(0.0),
        &m,
        &m.dx.unwrap(),
    );
    let old = crate::networks::network::Weights::<2>::from_rows(&before, 256).unwrap();
    let out = |w: &crate::networks::network::Weights<'_, 2>| {
        w.output(c.simd(), &s, &e.dalpha1, &e.alpha1)
    };
    let delta = out(&st.weights()) - out(&old);
    delta.component_div(&cmd.z2)
}

fn row(st: &HeapState<2>, i: usize) -> Vec<f64> {
    let w = st.weights();
    match i {
        0..=3 => w.d(i / 2, i % 2).to_vec(),
        4..=7 => w.c((i - 4) / 2, i % 2).to_vec(),
        _ => w.g(i - 8).to_vec(),
    }
}

#[test]
fn the_unified_regressors_do_not_carry_the_compliant_acceleration() {
    // (19.2): ẍd of the compliant reference holds this sample's wrench
    // (J⁺F_e/M_d); the regressor D̂ multiplies must not, or the learnt
    // inertia closes the admittance's algebraic loop through the contact.
    let commanded = Setpoint {
        x: Vector::<2>::new(0.1, 0.2),
        dx: Vector::<2>::new(0.3, -0.1),
        ddx: Vector::<2>::new(-2.0, 1.5),
    };
    let task = Task {
        errors: Errors {
            ddxd: Vector::zeros(),
            z1: Vector::zeros(),
            alpha1: Vector::zeros(),
            z2: Vector::zeros(),
            dalpha1: Vector::zeros(),
        },
        torque: Vector::zeros(),
        share: 0.3,
        commanded,
    };
    let errors = |ddxd: Vector<2>| Errors {
        ddxd,
        z1: Vector::<2>::new(1e-3, -2e-3),
        alpha1: Vector::<2>::new(0.25, -0.05),
        z2: Vector::<2>::new(0.01, 0.02),
        dalpha1: ddxd + Vector::<2>::new(0.5, -0.25), // ẍd + K1 (ẋd − v)
    };
    let d = Vector::<2>::new(2.0, 0.5);
    let (e_quiet, e_pushed) = (
        errors(Vector::<2>::new(0.1, -0.2)),
        errors(Vector::<2>::new(50.0, -80.0)),
    );
    let quiet = task.signals(&e_quiet, e_quiet.z2.component_mul(&d));
    let pushed = task.signals(&e_pushed, e_pushed.z2.component_mul(&d));
    assert_eq!(quiet.dalpha1, pushed.dalpha1);
    // q̈_c + n K1 (ẋd − v): the commanded acceleration and the share's feedback.
    let expected = commanded.ddx + 0.3 * Vector::<2>::new(0.5, -0.25);
    assert!((quiet.dalpha1 - expected).amax() < 1e-15, "{quiet:?}");
    assert_eq!(quiet.z2, Vector::<2>::new(0.02, 0.01));
}

/// A feedforward of a constant torque, for (20.10)'s test.
#[derive(Debug)]
struct Constant(Vector<2>);

impl Feedforward<2> for Constant {
    fn torque(&self, _q: &Vector<2>) -> Vector<2> {
        self.0
    }
}

#[test]
fn the_feedforward_adds_to_the_law_before_the_saturation() {
    // SPEC (20.10): τ = τ_law + τ_ff; sat(τ) of the sum; Δτ of ζ from the sum.
    let plain = Controller::paper(Law::StateFeedback);
    let ff = Vector::<2>::new(3.0, -40.0); // the second beyond τmax = 15 N m
    let fed = plain
        .clone()
        .with_feedforward(alloc::sync::Arc::new(Constant(ff)));
    assert!(plain.feedforward().is_none());
    assert!(fed.feedforward().is_some());
    let (mut a, mut b) = (plain.new_state(), fed.new_state());
    let m = measurement();
    let (sa, sb) = (setpoint(&plain, &a), setpoint(&fed, &b));
    let without = plain.step(&mut a, &m, &sa).unwrap();
    let with = fed.step(&mut b, &m, &sb).unwrap();
    assert_eq!(with.tau, without.tau + ff);
    assert_eq!(with.tau_sat, fed.saturation().apply(&with.tau));
    assert_eq!(with.dtau, with.tau_sat - with.tau);
    assert!(with.tau_sat[1] == -15.0 && with.dtau[1] > 0.0, "{with:?}");
}

#[test]
fn printed_euler_gain_exceeds_kp_at_1ms_normalized_stays_below_kappa_kp() {
    let mut printed = Config::paper(Law::StateFeedback);
    printed.ts = 1e-3;
    let g = per_step_gain(printed);
    // The Jury condition for explicit-Euler learning is g < Kp = 10.
    assert!(g.min() > 10.0, "printed per-step gain {g}");
    let mut normalized = printed;
    normalized.learning_step = LearningStep::Normalized;
    let g = per_step_gain(normalized);
    assert!(
        g.max() <= 5.0 + 1e-9 && g.min() > 0.0,
        "normalised per-step gain {g}"
    );
}

#[test]
fn normalized_step_is_the_printed_step_when_the_gain_is_small() {
    // At Ts = 1 µs the per-step gain is tiny and the scale is ≈ 1.
    let mut printed = Config::paper(Law::StateFeedback);
    printed.ts = 1e-6;
    let g_printed = per_step_gain(printed);
    let mut normalized = printed;
    normalized.learning_step = LearningStep::Normalized;
    let g = per_step_gain(normalized);
    assert!(
        ((g - g_printed).norm() / g_printed.norm()) < 0.01,
        "{g} vs {g_printed}"
    );
}

#[test]
fn freeze_stops_learning_into_the_limit_only() {
    let mut cfg = Config::paper(Law::StateFeedback);
    cfg.saturation_learning = SaturationLearning::Freeze;
    cfg.tau_max = Vector::<2>::new(0.1, 100.0); // joint 1 saturates
    let c = Controller::new(cfg, Grid::paper()).unwrap();
    let mut st = c.new_state();
    let mut w = vec![0.0; 10 * 256];
    w[8 * 256..].fill(0.01); // ŴG
    st.load_weights(&crate::networks::network::Weights::from_rows(&w, 256).unwrap())
        .unwrap();
    let m = measurement();
    let sp = setpoint(&c, &st);
    let cmd = c.step(&mut st, &m, &sp).unwrap();
    // Joint 1 saturates with learning pushing out: z2 and Δτ of opposite signs.
    assert!(
        cmd.dtau[0] != 0.0 && cmd.z2[0] * cmd.dtau[0] < 0.0,
        "{cmd:?}"
    );
    assert_eq!(cmd.dtau[1], 0.0);
    let decay = 1.0 - c.config().ts * 100.0 * 0.01;
    // Joint 1's rows only leak; joint 2's rows learn.
    let w = st.weights();
    assert!(w.g(0).iter().all(|&v| (v - 0.01 * decay).abs() < 1e-18));
    assert!(w.d(0, 1).iter().all(|&v| v == 0.0));
    assert!(w.g(1).iter().any(|&v| (v - 0.01 * decay).abs() > 1e-12));
}

#[test]
fn projection_keeps_each_network_in_its_ball() {
    let mut cfg = Config::paper(Law::StateFeedback);
    cfg.ts = 1e-3;
    let bound = [1e-3, 2e-3, 3e-3];
    cfg.weight_bound = WeightBound::Fixed(bound);
    let c = Controller::new(cfg, Grid::paper()).unwrap();
    let mut st = c.new_state();
    let m = measurement();
    let mut hit = [false; 3];
    for _ in 0..200 {
        let sp = setpoint(&c, &st);
        c.step(&mut st, &m, &sp).unwrap();
        let n = st.weights().norms();
        for net in 0..3 {
            assert!(n[net] <= bound[net] * (1.0 + 1e-12), "{n:?}");
            hit[net] |= n[net] > 0.999 * bound[net];
        }
        // The cached norms reported next step are the weights' norms.
        let cached = st.weight_norms();
        assert!(
            (cached[0] - n[0]).abs() <= 1e-12 * n[0],
            "{cached:?} vs {n:?}"
        );
    }
    assert_eq!(hit, [true; 3], "every bound was reached");
}

#[test]
fn auto_bounds_need_the_trajectory_and_match_the_documented_values() {
    let e = Controller::new(Config::robot(Law::StateFeedback), Grid::paper()).unwrap_err();
    assert!(e.to_string().contains("Controller::for_trajectory"), "{e}");
    let c = Controller::robot(Law::StateFeedback);
    let b = c.learning().bound().unwrap();
    for (v, e) in b.iter().zip([0.718, 2.255, 1.417]) {
        assert!((v - e).abs() < 1e-3, "{b:?}");
    }
}

#[test]
fn one_description_drives_many_states_and_is_shareable() {
    fn shareable<T: Send + Sync>(_: &T) {}
    let c = Controller::paper(Law::StateFeedback);
    shareable(&c);
    let (mut a, mut b) = (c.new_state(), c.new_state());
    let m = measurement();
    for _ in 0..10 {
        let sp = setpoint(&c, &a);
        let ca = c.step(&mut a, &m, &sp).unwrap();
        let cb = c.step(&mut b, &m, &sp).unwrap();
        assert_eq!(ca, cb);
    }
    // A state of another basis is refused, and left as it was.
    let small = Controller::new(
        Config::new(Law::StateFeedback, Vector::<2>::new(1.0, 1.0)),
        crate::networks::rbf::Centers::uniform(vec![0.0; 8], 1.0).unwrap(),
    )
    .unwrap();
    let sp = setpoint(&c, &a);
    let e = small.step(&mut a, &m, &sp).unwrap_err();
    assert!(e.to_string().contains("another number of nodes"), "{e}");
    assert_eq!(a.steps(), 10);
}

#[test]
fn a_snapshot_restores_a_state_that_continues_bit_identically() {
    for c in [
        Controller::paper(Law::OutputFeedback),
        Controller::robot(Law::StateFeedback),
    ] {
        let m = measurement();
        let circle = Sinusoid::paper();
        let mut a = c.new_state();
        for _ in 0..100 {
            let sp = circle.sample(c.time(&a));
            c.step(&mut a, &m, &sp).unwrap();
        }
        let mut snap = vec![0.0; a.snapshot_len()];
        assert_eq!(a.save(&mut snap).unwrap(), snap.len());
        let mut b = c.new_state();
        b.load(&snap).unwrap();
        for k in 0..50 {
            let x = m.x + Vector::<2>::from_element(1e-3 * k as f64);
            let mk = Measurement { x, ..m };
            let sp = circle.sample(c.time(&a));
            assert_eq!(c.step(&mut a, &mk, &sp), c.step(&mut b, &mk, &sp));
        }
        assert_eq!(a.weight_norms(), b.weight_norms());
        // A corrupt snapshot is refused and changes nothing.
        let before = format!("{:?}", b.weights());
        let last = snap.len() - 1;
        snap[last] = f64::NAN;
        assert!(b.load(&snap).is_err());
        snap[4] = 0.5;
        let e = b.load(&snap).unwrap_err();
        assert!(e.to_string().contains("whole number"), "{e}");
        assert!(b.load(&snap[1..]).is_err());
        assert_eq!(format!("{:?}", b.weights()), before);
    }
}

#[test]
fn external_impedance_tracks_the_setpoint_itself_under_contact() {
    // Joint: the reference yields to τe; external: xd = xc whatever τe.
    let mut cfg = Config::paper(Law::StateFeedback);
    let joint = Controller::new(cfg, Grid::paper()).unwrap();
    cfg.impedance = crate::control::impedance::ImpedanceMode::External;
    let external = Controller::new(cfg, Grid::paper()).unwrap();
    let m = Measurement {
        tau_e: Vector::<2>::new(30.0, -5.0),
        ..measurement()
    };
    let (mut a, mut b) = (joint.new_state(), external.new_state());
    let (mut ca, mut cb) = (Command::zeros(), Command::zeros());
    for _ in 0..100 {
        let sp = setpoint(&joint, &a);
        ca = joint.step(&mut a, &m, &sp).unwrap();
        cb = external.step(&mut b, &m, &sp).unwrap();
        assert_eq!(cb.xd, sp.x);
        assert_eq!(cb.z1, sp.x - m.x);
    }
    assert!((ca.xd - ca.xc).norm() > 1e-4, "{ca:?}");
    assert_ne!(ca.tau, cb.tau);
}

/// The mean estimated error ẑ2 over t ∈ [0.1, 0.5) s of output feedback
/// (robot preset, external impedance: xd = xc) whose measurement follows a
/// ramp-accelerating setpoint exactly, xc = x0 + ½ a t²: the true z2 is 0.
fn estimated_error_on_a_parabola(lead: bool) -> (Vector<2>, Vector<2>, Vector<2>) {
    let mut cfg = Config::robot(Law::OutputFeedback);
    cfg.impedance = crate::control::impedance::ImpedanceMode::External;
    cfg.observer_lead = lead;
    let c = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).unwrap();
    let (x0, a) = (Vector::<2>::new(0.1, -0.2), Vector::<2>::new(2.0, -1.5));
    let mut st = c.new_state();
    let (mut sum, mut rows) = (Vector::<2>::zeros(), 0.0);
    for k in 0..500 {
        let t = k as f64 * c.period();
        let sp = Setpoint {
            x: x0 + a * (0.5 * t * t),
            dx: a * t,
            ddx: a,
        };
        let m = Measurement {
            x: sp.x,
            dx: None,
            tau_e: Vector::zeros(),
        };
        let cmd = c.step(&mut st, &m, &sp).unwrap();
        assert_eq!(cmd.z1, Vector::<2>::zeros());
        if k >= 100 {
            sum += cmd.z2;
            rows += 1.0;
        }
    }
    (sum / rows, a, *c.observer().lag())
}

/// (9.1), SPEC §9: without the lead the estimated error of exact tracking
/// is a L (the estimate half a period late: learning would drive the true
/// z2 to −a L); with it, −K1 a L², second order (K1 L = 0.003 here).
#[test]
fn the_lead_removes_the_estimated_errors_bias_on_a_ramp_accelerating_path() {
    let (paper, a, lag) = estimated_error_on_a_parabola(false);
    let (lead, ..) = estimated_error_on_a_parabola(true);
    let k1 = Config::<2>::robot(Law::OutputFeedback).k1;
    assert!((lag[0] / 1e-3 - 0.5263).abs() < 1e-4, "{lag}");
    for i in 0..2 {
        let bias = a[i] * lag[i];
        assert!(
            (paper[i] - bias).abs() < 1e-6 * bias.abs(),
            "joint {i}: {} against a L = {bias}",
            paper[i]
        );
        let second = -k1[i] * a[i] * lag[i] * lag[i];
        assert!(
            (lead[i] - second).abs() < 1e-6 * second.abs(),
            "joint {i}: {} against −K1 a L² = {second}",
            lead[i]
        );
        assert!(lead[i].abs() < 0.02 * paper[i].abs(), "{lead} vs {paper}");
    }
}

/// (9.2), SPEC §9: the lead extrapolates the commanded motion, so the
/// wrench sampled at t_k (in ẍd: τe in the joint impedance, the compliant
/// reference's acceleration J⁺F/M_d in the torque-level formulations)
/// does not reach ẑ2 of the same step; it still reaches the torque
/// (τe, α̇1), so the steps compared are not one and the same.
#[test]
fn the_lead_does_not_feed_the_sampled_wrench_through() {
    let steps = |cfg: Config<2>, wrench: f64| {
        let c = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).unwrap();
        let mut st = c.new_state();
        let task = |sp: Setpoint<2>, share: f64| TaskTorque {
            commanded: sp,
            jacobian: nalgebra::SMatrix::<f64, 6, 2>::from_fn(|r, k| {
                if r < 2 {
                    0.3 + 0.1 * (r + 2 * k) as f64
                } else {
                    0.0
                }
            }),
            spring: Vector::<6>::from_element(1.0),
            damping: Vector::<6>::from_element(20.0),
            twist: Vector::zeros(),
            lambda2: Vector::<6>::from_element(1e-4),
            share,
        };
        let mut cmd = None;
        for k in 0..40 {
            let sp = Sinusoid::paper().sample(c.time(&st));
            let x = sp.x + Vector::<2>::new(1e-3, -2e-3) * (k as f64 * 0.1).sin();
            let last = k == 39;
            let w = if last { wrench } else { 0.0 };
            let m = Measurement {
                x,
                dx: None,
                tau_e: Vector::<2>::new(3.0, -2.0) * w,
            };
            // The compliant reference the outer loop hands over: the
            // commanded one, but accelerated by this sample's wrench.
            let compliant = Setpoint {
                ddx: sp.ddx + Vector::<2>::new(40.0, 25.0) * w,
                ..sp
            };
            cmd = Some(match cfg.impedance {
                ImpedanceMode::Joint => c.step(&mut st, &m, &sp),
                ImpedanceMode::External => c.step_task(&mut st, &m, &compliant, &task(sp, 0.3)),
            });
        }
        cmd.unwrap().unwrap()
    };
    for impedance in [ImpedanceMode::Joint, ImpedanceMode::External] {
        let mut cfg = Config::robot(Law::OutputFeedback);
        cfg.impedance = impedance;
        assert!(cfg.observer_lead);
        let (free, pressed) = (steps(cfg, 0.0), steps(cfg, 1.0));
        assert_eq!(free.z2, pressed.z2, "{impedance:?}");
        assert_ne!(free.tau, pressed.tau, "{impedance:?}");
        // The lead is on: ẑ2 is not the paper's.
        cfg.observer_lead = false;
        assert_ne!(steps(cfg, 1.0).z2, pressed.z2, "{impedance:?}");
    }
}

#[test]
fn the_lead_is_output_feedbacks_only_and_the_papers_is_off() {
    assert!(!Config::<2>::paper(Law::OutputFeedback).observer_lead);
    assert!(Config::<2>::robot(Law::OutputFeedback).observer_lead);
    // State feedback measures the velocity at t_k: no lag, no lead.
    let mut on = Config::robot(Law::StateFeedback);
    on.observer_lead = true;
    let mut off = on;
    off.observer_lead = false;
    let [a, b] = [on, off].map(|cfg| {
        let c = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).unwrap();
        let mut st = c.new_state();
        let m = measurement();
        (0..20)
            .map(|k| {
                let sp = Sinusoid::paper().sample(k as f64 * c.period());
                c.step(&mut st, &m, &sp).unwrap()
            })
            .last()
            .unwrap()
    });
    assert_eq!(a, b);
}

#[test]
fn a_state_in_a_caller_buffer_steps_like_a_heap_state() {
    let c = Controller::paper(Law::OutputFeedback);
    let mut buf = vec![0.0; c.buffer_len()];
    let mut st = c.state_in(&mut buf[..]).unwrap();
    let mut heap = c.new_state();
    let m = measurement();
    for k in 0..5 {
        let sp = Sinusoid::paper().sample(k as f64 * c.period());
        assert_eq!(c.step(&mut st, &m, &sp), c.step(&mut heap, &m, &sp));
    }
    let e = c.state_in(&mut buf[..10]).unwrap_err();
    assert!(e.to_string().contains("buffer_len"), "{e}");
}
