//! Ablation of the hardened options (SPEC §13): each modification removed in
//! turn from the hardened set, in the paper scenario (Ts = 50 µs, M = 1) and
//! the robot scenario (Ts = 1 ms, M = 10), for state and output feedback.
//! Prints a Markdown table of the SPEC §12 metrics.
//!
//! ```text
//! cargo run --release --example ablation
//! ```

use adaptimp::observer::Hold;
use adaptimp::{
    run, AuxLaw, Config, Controller, Grid, Law, LearningStep, ObserverInit, Recorder, RobustKind,
    Row, SaturationLearning, SimConfig, Sinusoid, TwoLinkArm, Wall, WeightBound,
};

/// Max weight norms over the run.
struct MaxNorms([f64; 3]);

impl Recorder<2> for MaxNorms {
    fn record(&mut self, row: &Row<2>) {
        for (m, n) in self.0.iter_mut().zip(row.w_norms) {
            *m = m.max(n);
        }
    }
}

type Variant = (&'static str, fn(&mut Config<2>));

const VARIANTS: [Variant; 10] = [
    ("printed (paper)", |c| {
        *c = Config::paper(c.law).with_ts(c.ts)
    }),
    ("hardened", |_| {}),
    ("− normalised step", |c| {
        c.learning_step = LearningStep::Euler
    }),
    ("− conditional integration", |c| {
        c.saturation_learning = SaturationLearning::Ignore
    }),
    ("− weight projection", |c| {
        c.weight_bound = WeightBound::None
    }),
    ("− tanh (sgn robust term)", |c| {
        c.robust = RobustKind::Sign
    }),
    ("− triangle hold (ZOH)", |c| c.observer_hold = Hold::Zero),
    ("− observer start at x(0) (π(0) = 0)", |c| {
        c.observer_init = ObserverInit::Zero
    }),
    ("− observer lead (9.1) (ẑ2 = α1 − ẋ̂)", |c| {
        c.observer_lead = false
    }),
    ("+ β-free auxiliary law", |c| c.aux_law = AuxLaw::Linear),
];

trait WithTs {
    fn with_ts(self, ts: f64) -> Self;
}
impl WithTs for Config<2> {
    fn with_ts(mut self, ts: f64) -> Self {
        self.ts = ts;
        self
    }
}

/// The run, 2.5 s under `cargo test`.
fn short(sim: SimConfig<2>) -> SimConfig<2> {
    if cfg!(test) {
        SimConfig {
            t_final: 2.5,
            ..sim
        }
    } else {
        sim
    }
}

fn main() -> Result<(), adaptimp::Error> {
    let arm = TwoLinkArm::paper();
    let wall = Wall::paper();
    println!("| scenario | law | variant | RMS ‖z1‖, t ≥ 2 s (rad) | saturation duty | peak \\|τ\\| (N m) | impedance error RMS (N m) | max ‖Ŵ‖ D, C, G |");
    println!("|---|---|---|---:|---:|---:|---:|---|");
    for (scenario, base, sim) in [
        (
            "paper 50 µs",
            Config::paper as fn(Law) -> Config<2>,
            short(SimConfig::paper()),
        ),
        (
            "robot 1 ms",
            Config::robot as fn(Law) -> Config<2>,
            short(SimConfig::robot()),
        ),
    ] {
        for (law, name) in [(Law::StateFeedback, "sf"), (Law::OutputFeedback, "of")] {
            for (variant, apply) in VARIANTS {
                let observer_only = variant.contains("hold") || variant.contains("observer");
                if observer_only && law != Law::OutputFeedback {
                    continue;
                }
                let mut cfg = base(law).hardened().with_ts(base(law).ts);
                apply(&mut cfg);
                let circle = Sinusoid::paper();
                let ctrl = Controller::for_trajectory(cfg, Grid::paper(), &circle)?;
                let mut state = ctrl.new_state();
                let mut norms = MaxNorms([0.0; 3]);
                let m = run(
                    &arm,
                    &wall,
                    &mut ctrl.bind(&mut state),
                    &circle,
                    &sim,
                    &mut norms,
                )?;
                println!(
                    "| {scenario} | {name} | {variant} | {:.5} | {:.3} | {:.1}, {:.1} | {:.2} | {:.2}, {:.2}, {:.2} |",
                    m.rms_z1_after2,
                    m.sat_duty,
                    m.peak_abs_tau[0],
                    m.peak_abs_tau[1],
                    m.imp_err_rms_after2,
                    norms.0[0],
                    norms.0[1],
                    norms.0[2]
                );
            }
        }
    }
    Ok(())
}

/// `cargo test` runs this example, shortened (`cfg!(test)`).
#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main().unwrap();
    }
}
