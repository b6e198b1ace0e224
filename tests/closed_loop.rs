//! Closed-loop behaviour: the paper's three cases (SPEC §11–§12), the
//! auxiliary system's two inner laws, the observer start, and other sizes N.

use adaptimp::model::{Link, PlanarArm};
use adaptimp::{
    run, AuxLaw, Centers, Config, Controller, FreeSpace, Grid, Law, Measurement, Metrics,
    ObserverInit, Recorder, RobustKind, Row, SimConfig, Sinusoid, Tracker, Trajectory, TwoLinkArm,
    Vector, Wall,
};
use proptest::prelude::*;

/// Tracks the worst |sat(τ)_i| / τmax_i and whether anything was non-finite.
struct Guard<const N: usize> {
    tau_max: Vector<N>,
    worst_ratio: f64,
    finite: bool,
    zeta_max: f64,
    peak_dq_hat_10ms: f64,
}

impl<const N: usize> Guard<N> {
    fn new(tau_max: Vector<N>) -> Self {
        Self {
            tau_max,
            worst_ratio: 0.0,
            finite: true,
            zeta_max: 0.0,
            peak_dq_hat_10ms: 0.0,
        }
    }
}

impl<const N: usize> Recorder<N> for Guard<N> {
    fn record(&mut self, row: &Row<N>) {
        for i in 0..N {
            self.worst_ratio = self.worst_ratio.max(row.tau_sat[i].abs() / self.tau_max[i]);
        }
        let all = [
            row.x,
            row.dx,
            row.tau,
            row.tau_sat,
            row.z1,
            row.zeta,
            row.dx_hat,
        ];
        self.finite &= all.iter().all(|v| v.iter().all(|x| x.is_finite()));
        self.finite &= row.w_norms.iter().all(|x| x.is_finite());
        self.zeta_max = self.zeta_max.max(row.zeta.norm());
        if row.t < 0.01 {
            self.peak_dq_hat_10ms = self.peak_dq_hat_10ms.max(row.dx_hat.norm());
        }
    }
}

fn paper_run(cfg: Config<2>, t_final: f64) -> (Metrics<2>, Guard<2>) {
    let tau_max = cfg.tau_max;
    let ctrl = Controller::new(cfg, Grid::paper()).expect("valid");
    let mut state = ctrl.new_state();
    let mut guard = Guard::new(tau_max);
    let sim = SimConfig {
        t_final,
        ..SimConfig::paper()
    };
    let m = run(
        &TwoLinkArm::paper(),
        &Wall::paper(),
        &mut ctrl.bind(&mut state),
        &Sinusoid::paper(),
        &sim,
        &mut guard,
    )
    .expect("simulate");
    (m, guard)
}

#[test]
fn paper_scenario_reproduces_the_papers_findings() {
    let (pd, g_pd) = paper_run(Config::paper(Law::Pd), 20.0);
    let (sf, g_sf) = paper_run(Config::paper(Law::StateFeedback), 20.0);
    let (of, g_of) = paper_run(Config::paper(Law::OutputFeedback), 20.0);
    for (name, m, g) in [("pd", &pd, &g_pd), ("sf", &sf, &g_sf), ("of", &of, &g_of)] {
        assert_eq!(m.rows, 400_000, "{name}");
        assert!(g.finite, "{name}: non-finite values");
        assert!(
            m.rms_z1.is_finite() && m.imp_err_rms_after2.is_finite(),
            "{name}"
        );
        // The actuators never apply more than their limits.
        assert!(
            g.worst_ratio <= 1.0,
            "{name}: |sat(τ)| / τmax reached {}",
            g.worst_ratio
        );
    }
    // PD has large tracking errors, worst on x1 (Figs. 2–4).
    assert!(pd.rms_z1_after2 >= 0.10, "PD {}", pd.rms_z1_after2);
    assert!(pd.rms_z1_joint_after2[0] > 5.0 * pd.rms_z1_joint_after2[1]);
    // Both adaptive controllers have much smaller errors (Figs. 5–10).
    for (name, m) in [("sf", &sf), ("of", &of)] {
        assert!(m.rms_z1_after2 <= 0.02, "{name} {}", m.rms_z1_after2);
        assert!(
            m.rms_z1_after2 <= 0.15 * pd.rms_z1_after2,
            "{name} {}",
            m.rms_z1_after2
        );
    }
    // State feedback tracks joint 2 better than output feedback (SPEC §12).
    assert!(sf.rms_z1_joint_after2[1] < of.rms_z1_joint_after2[1]);
    // The printed learning law winds up under saturation (SPEC §11, Finding).
    assert!(sf.peak_abs_tau[0] > 10.0 * 17.0, "{}", sf.peak_abs_tau[0]);
}

#[test]
fn tracked_weight_norms_stay_exact_over_a_whole_paper_run() {
    // The fused pass updates the norms algebraically (no second pass); after
    // 400 000 steps they still equal a recomputation from the weights.
    for law in [Law::StateFeedback, Law::OutputFeedback] {
        let ctrl = Controller::paper(law);
        let mut state = ctrl.new_state();
        let sim = SimConfig::paper();
        run(
            &TwoLinkArm::paper(),
            &Wall::paper(),
            &mut ctrl.bind(&mut state),
            &Sinusoid::paper(),
            &sim,
            &mut (),
        )
        .expect("simulate");
        let (tracked, exact) = (state.weight_norms(), state.weights().norms());
        for (t, e) in tracked.iter().zip(exact) {
            assert!(
                e > 1.0 && (t - e).abs() <= 1e-9 * e,
                "{law:?}: {tracked:?} vs {exact:?}"
            );
        }
    }
}

#[test]
fn printed_auxiliary_law_is_dead_the_default_compensates() {
    let mut printed = Config::paper(Law::StateFeedback);
    printed.aux_law = AuxLaw::Printed;
    let (m_printed, g_printed) = paper_run(printed, 2.0);
    let (m_default, g_default) = paper_run(Config::paper(Law::StateFeedback), 2.0);
    // Both saturate ...
    assert!(m_printed.sat_duty > 0.05 && m_default.sat_duty > 0.05);
    // ... but with the printed law ζ(0) = 0 never leaves the origin (SPEC §8).
    assert_eq!(g_printed.zeta_max, 0.0);
    assert!(
        g_default.zeta_max >= 0.01,
        "‖ζ‖ peaked at {}",
        g_default.zeta_max
    );
}

#[test]
fn starting_the_observer_at_the_first_measurement_removes_the_startup_peak() {
    let (_, zero) = paper_run(Config::paper(Law::OutputFeedback), 0.05);
    let mut cfg = Config::paper(Law::OutputFeedback);
    cfg.observer_init = ObserverInit::FirstMeasurement;
    let (_, first) = paper_run(cfg, 0.05);
    // π(0) = 0 against x(0) = [0.25, −0.05] rad: an estimate of hundreds of rad/s.
    assert!(zero.peak_dq_hat_10ms > 100.0, "{}", zero.peak_dq_hat_10ms);
    assert!(
        first.peak_dq_hat_10ms < 0.1 * zero.peak_dq_hat_10ms,
        "{}",
        first.peak_dq_hat_10ms
    );
}

#[test]
fn every_robust_term_runs_and_tracks() {
    for robust in RobustKind::ALL {
        // kr = 0.5 N m; Remark 1: kD = 0.01, kC = 0.05, kG = 0.5 (the defaults).
        let mut cfg = Config::paper(Law::StateFeedback);
        cfg.robust = robust;
        cfg.phi = 0.01;
        let (m, g) = paper_run(cfg, 5.0);
        assert!(g.finite, "{robust:?}");
        assert!(m.rms_z1_after2 < 0.03, "{robust:?}: {}", m.rms_z1_after2);
    }
}

fn link(mass: f64, length: f64) -> Link {
    Link {
        mass,
        length,
        com: length / 2.0,
        inertia: mass * length * length / 12.0,
    }
}

/// A deterministic pseudo-random number in [−1, 1) (no dependency needed).
fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

#[test]
fn three_link_arm_with_custom_centres_learns() {
    // N = 3, L = 64 centres drawn in [−1, 1]^12, free space, a sinusoid per
    // joint, limits with headroom (with tight limits the printed law winds up,
    // as it does on the paper arm: SPEC §11, Finding).
    const N: usize = 3;
    const L: usize = 64;
    let arm = PlanarArm::new([link(2.0, 0.4), link(1.2, 0.3), link(0.5, 0.2)], 9.81).expect("arm");
    let mut seed = 7;
    // The same centres as the earlier block-major layout: block b of node j
    // was drawn at position (b, j) in column order.
    let mut blocks = [[[0.0; L]; N]; 4];
    for block in &mut blocks {
        for j in 0..L {
            for row in block.iter_mut() {
                row[j] = lcg(&mut seed);
            }
        }
    }
    let centers: Vec<f64> = (0..L)
        .flat_map(|j| (0..4).flat_map(move |b| (0..N).map(move |i| (b, i, j))))
        .map(|(b, i, j)| blocks[b][i][j])
        .collect();
    let rbf = Centers::uniform(centers, 25.0).expect("rbf");
    let traj = Sinusoid::new(
        Vector::<N>::new(0.3, -0.4, 0.2),
        Vector::<N>::new(0.2, 0.15, 0.1),
        Vector::<N>::new(0.0, 0.1, -0.1),
        Vector::<N>::new(1.0, 1.5, 2.0),
    )
    .expect("trajectory");
    let sim = SimConfig {
        t_final: 10.0,
        substeps: 2,
        q0: traj.sample_at_zero(),
        dq0: Vector::zeros(),
        settle: 2.0,
    };
    let go = |law: Law| {
        let cfg = Config::<N>::new(law, Vector::<N>::new(100.0, 60.0, 30.0));
        let mut ctrl = Tracker::new(Controller::new(cfg, rbf.clone()).expect("controller"), traj);
        run(&arm, &FreeSpace, &mut ctrl, &traj, &sim, &mut ()).expect("simulate")
    };
    let (pd, sf) = (go(Law::Pd), go(Law::StateFeedback));
    assert!(sf.rms_z1_after2.is_finite());
    assert!(
        sf.rms_z1_after2 < 0.05 * pd.rms_z1_after2,
        "sf {} vs pd {}",
        sf.rms_z1_after2,
        pd.rms_z1_after2
    );
}

#[test]
fn one_link_pendulum_on_the_sixteen_node_grid_learns() {
    let arm = PlanarArm::new([link(1.0, 0.5)], 9.81).expect("arm");
    let rbf = Grid::<1>::new(25.0).expect("grid");
    let traj = Sinusoid::new(
        Vector::<1>::new(0.2),
        Vector::<1>::new(0.3),
        Vector::<1>::new(0.0),
        Vector::<1>::new(2.0),
    )
    .expect("trajectory");
    let sim = SimConfig {
        t_final: 10.0,
        substeps: 1,
        q0: Vector::<1>::new(0.2),
        dq0: Vector::zeros(),
        settle: 2.0,
    };
    let go = |law: Law| {
        let mut cfg = Config::<1>::new(law, Vector::<1>::new(20.0));
        cfg.ts = 1e-4;
        let mut ctrl = Tracker::new(Controller::new(cfg, rbf).expect("controller"), traj);
        run(&arm, &FreeSpace, &mut ctrl, &traj, &sim, &mut ()).expect("simulate")
    };
    let (pd, sf) = (go(Law::Pd), go(Law::StateFeedback));
    assert!(
        sf.rms_z1_after2 < 0.25 * pd.rms_z1_after2,
        "sf {} vs pd {}",
        sf.rms_z1_after2,
        pd.rms_z1_after2
    );
}

#[test]
fn a_metrics_window_before_the_start_is_refused_by_name() {
    let arm = PlanarArm::new([link(1.0, 0.5)], 9.81).expect("arm");
    let traj = Sinusoid::new(
        Vector::<1>::new(0.2),
        Vector::<1>::new(0.3),
        Vector::<1>::new(0.0),
        Vector::<1>::new(2.0),
    )
    .expect("trajectory");
    let go = |settle: f64| {
        let sim = SimConfig {
            t_final: 0.01,
            substeps: 1,
            q0: Vector::<1>::new(0.2),
            dq0: Vector::zeros(),
            settle,
        };
        let cfg = Config::<1>::new(Law::Pd, Vector::<1>::new(20.0));
        let rbf = Grid::<1>::new(25.0).expect("grid");
        let mut ctrl = Tracker::new(Controller::new(cfg, rbf).expect("controller"), traj);
        run(&arm, &FreeSpace, &mut ctrl, &traj, &sim, &mut ())
    };
    let e = go(-1.0).expect_err("settle < 0");
    assert_eq!(
        e.to_string(),
        "condition settle ≥ 0 is violated: settle = -1 (SPEC §10)"
    );
    assert!(go(f64::NAN)
        .expect_err("NaN")
        .to_string()
        .contains("settle"));
    assert!(go(0.0).expect("settle = 0").rms_z1_after2.is_finite());
}

trait AtZero<const N: usize> {
    fn sample_at_zero(&self) -> Vector<N>;
}
impl<const N: usize> AtZero<N> for Sinusoid<N> {
    fn sample_at_zero(&self) -> Vector<N> {
        Trajectory::sample(self, 0.0).x
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// No panic and no poison on any finite input, however large: the step
    /// returns a finite command within the limits, or, for an input whose
    /// signals would go beyond `BOUND`, `Error::OutOfRange` with the state
    /// unchanged. It never diverges: the weights stay finite.
    #[test]
    fn step_never_panics_or_diverges_on_finite_input(
        law in prop::sample::select(vec![Law::Pd, Law::StateFeedback, Law::OutputFeedback]),
        values in prop::collection::vec(prop_oneof![-1e3..1e3f64, -1e300..1e300f64], 6 * 20),
    ) {
        let mut c = Tracker::paper(law);
        for v in values.chunks(6) {
            let m = Measurement {
                x: Vector::<2>::new(v[0], v[1]),
                dx: Some(Vector::<2>::new(v[2], v[3])),
                tau_e: Vector::<2>::new(v[4], v[5]),
            };
            let before = c.state().clone();
            match c.step(&m) {
                Ok(cmd) => {
                    prop_assert!(cmd.tau_sat.iter().all(|t| t.is_finite()));
                    prop_assert!(cmd.tau_sat[0].abs() <= 17.0 && cmd.tau_sat[1].abs() <= 15.0);
                }
                Err(adaptimp::Error::OutOfRange { .. }) => {
                    prop_assert_eq!(c.state().steps(), before.steps());
                    prop_assert_eq!(c.state().weights().norms(), before.weights().norms());
                    prop_assert_eq!(c.state().zeta(), before.zeta());
                }
                Err(e) => prop_assert!(false, "unexpected error {e:?}"),
            }
            let norms = c.state().weights().norms();
            prop_assert!(norms.iter().all(|n| n.is_finite()), "{:?}", norms);
        }
    }
}
