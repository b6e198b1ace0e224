//! Beyond the paper (SPEC §13): the "robot" scenario at Ts = 1 ms with the
//! hardened options, against the targets of the 1 kHz issue. Metrics, never timings.

use adaptimp::{
    run as run_loop, Config, Controller, Grid, Law, Metrics, Recorder, Row, SimConfig, Sinusoid,
    Trajectory, TwoLinkArm, Vector, Wall, WeightBound,
};

/// Per-row facts the metrics do not keep.
struct Watch {
    /// Peak |τ_i| over rows k ≥ 1.
    peak_after_first: Vector<2>,
    /// τ of row 0.
    first_tau: Vector<2>,
    /// Max weight norms over the first and the second half of the run.
    w_first_half: [f64; 3],
    w_second_half: [f64; 3],
    half: f64,
    rows: usize,
}

impl Recorder<2> for Watch {
    fn record(&mut self, row: &Row<2>) {
        if self.rows == 0 {
            self.first_tau = row.tau;
        } else {
            self.peak_after_first = self
                .peak_after_first
                .zip_map(&row.tau, |p, t| p.max(t.abs()));
        }
        let w = if row.t < self.half {
            &mut self.w_first_half
        } else {
            &mut self.w_second_half
        };
        for (m, n) in w.iter_mut().zip(row.w_norms) {
            *m = m.max(n);
        }
        self.rows += 1;
    }
}

fn run(cfg: Config<2>, sim: SimConfig<2>) -> (Metrics<2>, Watch) {
    let ctrl = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).expect("valid");
    let mut state = ctrl.new_state();
    let mut watch = Watch {
        peak_after_first: Vector::zeros(),
        first_tau: Vector::zeros(),
        w_first_half: [0.0; 3],
        w_second_half: [0.0; 3],
        half: sim.t_final / 2.0,
        rows: 0,
    };
    let m = run_loop(
        &TwoLinkArm::paper(),
        &Wall::paper(),
        &mut ctrl.bind(&mut state),
        &Sinusoid::paper(),
        &sim,
        &mut watch,
    )
    .expect("simulate");
    (m, watch)
}

#[test]
fn printed_laws_fail_at_1khz_as_the_spec_finding_says() {
    let mut cfg = Config::paper(Law::StateFeedback);
    cfg.ts = 1e-3;
    let (m, _) = run(cfg, SimConfig::robot());
    // Worse than PD's 0.128, saturated nearly always, wound up to 10³ N m and more.
    assert!(m.rms_z1_after2 > 0.128, "{}", m.rms_z1_after2);
    assert!(m.sat_duty > 0.9, "{}", m.sat_duty);
    assert!(m.peak_abs_tau.max() > 1e3, "{}", m.peak_abs_tau);
}

#[test]
fn robot_scenario_meets_its_targets() {
    let tau_max = Vector::<2>::new(17.0, 15.0);
    for (law, target) in [(Law::StateFeedback, 0.010), (Law::OutputFeedback, 0.030)] {
        let (m, w) = run(Config::robot(law), SimConfig::robot());
        assert_eq!(m.rows, 20_000);
        // Tracking over t ≥ 2 s.
        assert!(m.rms_z1_after2 <= target, "{law:?}: {}", m.rms_z1_after2);
        // No windup: |τ_i| ≤ 2 τmax_i at every step after the first ...
        for i in 0..2 {
            assert!(
                w.peak_after_first[i] <= 2.0 * tau_max[i],
                "{law:?}: {}",
                w.peak_after_first
            );
        }
        // ... and the first is (14) (OF: (35) with (9.1)) at the paper's initial state, before any
        // learning or saturation: z1 + Kp z2 + r + τe with x(0) 0.05 rad inside
        // the wall (τe = 50 N m): −0.25 + 10·(−1.5) − 0.5·tanh(1.5/0.05) + 50.
        // Output feedback compares with α1 the observer's lag L back, (9.1),
        // along the commanded motion, (9.2): ẑ2 = z2 − L α̇1°, α̇1°(0) = ẍc(0)
        // (ẋc(0) = 0 on joint 1, the estimate starts at 0; not ẍd(0), which
        // holds the wall's −τe/Dd of this sample): Kp L 0.2π² N m less.
        let lead = match law {
            Law::OutputFeedback => {
                let lag = Controller::robot(law).observer().lag()[0];
                let c = Sinusoid::paper().sample(0.0);
                assert_eq!(c.dx[0], 0.0);
                -10.0 * lag * c.ddx[0]
            }
            _ => 0.0,
        };
        let expect = -0.25 - 15.0 - 0.5 * (1.5f64 / 0.05).tanh() + 50.0 + lead;
        assert!(
            (w.first_tau[0] - expect).abs() < 1e-9,
            "{law:?}: τ(0) = {}",
            w.first_tau
        );
        // Saturation duty no higher than the paper scenario's (0.35 sf, 0.41 of).
        assert!(m.sat_duty <= 0.35, "{law:?}: {}", m.sat_duty);
    }
}

#[test]
fn weights_stay_bounded_over_600_s() {
    for law in [Law::StateFeedback, Law::OutputFeedback] {
        let cfg = Config::robot(law);
        let bound = Controller::robot(law)
            .learning()
            .bound()
            .expect("robot bounds");
        let sim = SimConfig {
            t_final: 600.0,
            ..SimConfig::robot()
        };
        let (m, w) = run(cfg, sim);
        assert!(m.rms_z1_after2 <= 0.010, "{law:?}: {}", m.rms_z1_after2);
        for ((second, first), b) in w.w_second_half.iter().zip(w.w_first_half).zip(bound) {
            assert!(*second <= b * (1.0 + 1e-12));
            // No drift: the last 300 s never exceed the first 300 s.
            assert!(
                *second <= first * (1.0 + 1e-9),
                "{law:?}: {:?} then {:?}",
                w.w_first_half,
                w.w_second_half
            );
        }
        // Without the projection, normalisation, conditional integration and
        // σ-leakage alone keep them bounded too.
        let mut free = cfg;
        free.weight_bound = WeightBound::None;
        let (_, w) = run(free, sim);
        for net in 0..3 {
            assert!(
                w.w_second_half[net] <= w.w_first_half[net] * (1.0 + 1e-9),
                "{law:?} unprojected: {:?} then {:?}",
                w.w_first_half,
                w.w_second_half
            );
        }
    }
}

#[test]
fn hardened_options_track_no_worse_in_the_paper_scenario() {
    for law in [Law::StateFeedback, Law::OutputFeedback] {
        let (printed, _) = run(Config::paper(law), SimConfig::paper());
        let (hardened, w) = run(Config::paper(law).hardened(), SimConfig::paper());
        assert!(
            hardened.rms_z1_after2 <= 1.10 * printed.rms_z1_after2,
            "{law:?}: hardened {} printed {}",
            hardened.rms_z1_after2,
            printed.rms_z1_after2
        );
        // And without the printed law's windup: at 50 µs the first few rows all
        // command the initial-contact torque τ1(0) ≈ 34.25 N m (see
        // `robot_scenario_meets_its_targets`); nothing later exceeds it.
        assert!(printed.peak_abs_tau.max() > 1e3);
        assert!(
            w.peak_after_first.max() <= 34.25,
            "{law:?}: {}",
            w.peak_after_first
        );
    }
}
