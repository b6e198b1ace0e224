//! Soak: the robot scenario (Ts = 1 ms, state feedback, the hardened options)
//! run for many simulated hours in one go, recording one row in 1000. Prints,
//! per hour, the RMS tracking error, the peak weight norms and the peak
//! applied torque, then the process's peak resident memory; exits with an
//! error if anything was non-finite, the weights left their bounds, the last
//! hour tracked worse than 1.1 × the second, or memory grew.
//!
//! ```text
//! cargo run --release --example soak -- 24    # 86.4 M steps (a few minutes)
//! cargo run --release --example soak -- 1     # the slow tier's version
//! ```

use adaptimp::{run, Controller, Law, Recorder, Row, SimConfig, Sinusoid, TwoLinkArm, Wall};

/// Per-hour figures and one row in `every`.
struct Soak {
    every: u64,
    rows_per_hour: u64,
    k: u64,
    /// Decimated rows: t, ‖z1‖, ‖Ŵ‖ (kept to show the memory stays bounded).
    kept: Vec<(f64, f64, [f64; 3])>,
    hours: Vec<Hour>,
    non_finite: bool,
}

#[derive(Clone, Copy, Default)]
struct Hour {
    sum_z1: f64,
    rows: u64,
    peak_norms: [f64; 3],
    peak_applied: f64,
}

impl Recorder<2> for Soak {
    fn record(&mut self, row: &Row<2>) {
        let h = (self.k / self.rows_per_hour) as usize;
        if h == self.hours.len() {
            self.hours.push(Hour::default());
        }
        let hour = &mut self.hours[h];
        hour.sum_z1 += row.z1.norm_squared();
        hour.rows += 1;
        for (p, n) in hour.peak_norms.iter_mut().zip(row.w_norms) {
            *p = p.max(n);
        }
        hour.peak_applied = hour.peak_applied.max(row.tau_sat.amax());
        let values = [row.x, row.dx, row.tau, row.tau_sat, row.z1, row.zeta];
        self.non_finite |= values.iter().any(|v| v.iter().any(|x| !x.is_finite()))
            || row.w_norms.iter().any(|x| !x.is_finite());
        if self.k.is_multiple_of(self.every) {
            self.kept.push((row.t, row.z1.norm(), row.w_norms));
        }
        self.k += 1;
    }
}

/// Peak resident set size of this process (kB), from /proc (Linux).
fn peak_rss_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Under the test harness the arguments are the harness's (filters, flags).
    let arg = if cfg!(test) {
        None
    } else {
        std::env::args().nth(1)
    };
    let hours: f64 = arg
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(if cfg!(test) { 0.0005 } else { 24.0 });
    let ctrl = Controller::robot(Law::StateFeedback);
    let bounds = ctrl
        .learning()
        .bound()
        .ok_or("the robot scenario projects its weights")?;
    let mut state = ctrl.new_state();
    let sim = SimConfig {
        t_final: hours * 3600.0,
        ..SimConfig::robot()
    };
    let rows_per_hour = (3600.0 / ctrl.period()).round() as u64;
    let mut soak = Soak {
        every: 1000,
        rows_per_hour,
        k: 0,
        kept: Vec::with_capacity((sim.t_final / ctrl.period() / 1000.0) as usize + 1),
        hours: Vec::new(),
        non_finite: false,
    };
    let rss_before = peak_rss_kb();
    let start = std::time::Instant::now();
    let m = run(
        &TwoLinkArm::paper(),
        &Wall::paper(),
        &mut ctrl.bind(&mut state),
        &Sinusoid::paper(),
        &sim,
        &mut soak,
    )?;
    let secs = start.elapsed().as_secs_f64();
    println!(
        "soak: {hours} h simulated ({} steps) in {secs:.0} s; state feedback, robot scenario",
        m.rows
    );
    println!("| hour | RMS ‖z1‖ (rad) | peak ‖Ŵ‖ D, C, G | peak applied \\|τ\\| (N m) |");
    println!("|---:|---:|---|---:|");
    for (h, hour) in soak.hours.iter().enumerate() {
        let n = hour.peak_norms;
        println!(
            "| {} | {:.5} | {:.3}, {:.3}, {:.3} | {:.2} |",
            h + 1,
            (hour.sum_z1 / hour.rows as f64).sqrt(),
            n[0],
            n[1],
            n[2],
            hour.peak_applied
        );
    }
    let rss_after = peak_rss_kb();
    println!(
        "peak RSS: {} kB after start-up, {} kB at the end; {} decimated rows kept",
        rss_before.map_or("?".into(), |v| v.to_string()),
        rss_after.map_or("?".into(), |v| v.to_string()),
        soak.kept.len()
    );
    let mut failures = Vec::new();
    if soak.non_finite {
        failures.push("a recorded value was not finite".to_owned());
    }
    for hour in &soak.hours {
        for (n, b) in hour.peak_norms.iter().zip(bounds) {
            if *n > b * (1.0 + 1e-12) {
                failures.push(format!("a weight norm {n} exceeded its bound {b}"));
            }
        }
    }
    let rms = |h: &Hour| (h.sum_z1 / h.rows as f64).sqrt();
    if let (Some(second), Some(last)) = (soak.hours.get(1), soak.hours.last()) {
        if rms(last) > 1.1 * rms(second) {
            failures.push(format!(
                "the last hour tracked worse: {} vs {}",
                rms(last),
                rms(second)
            ));
        }
    }
    // The decimated rows are the only growth (their pages are touched as
    // they fill): allow them and 1 MiB.
    let kept_kb = (soak.kept.len() * std::mem::size_of::<(f64, f64, [f64; 3])>() / 1024) as u64;
    if let (Some(a), Some(b)) = (rss_before, rss_after) {
        if b > a + kept_kb + 1024 {
            failures.push(format!(
                "peak RSS grew by {} kB ({kept_kb} kB of rows)",
                b - a
            ));
        }
    }
    if failures.is_empty() {
        println!("ok: finite, weights within their bounds, tracking steady, memory flat");
        Ok(())
    } else {
        Err(failures.join("; ").into())
    }
}

/// `cargo test` runs this example, shortened (`cfg!(test)`).
#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main().unwrap();
    }
}
