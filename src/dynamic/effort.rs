//! The effort limits of an arm whose description states none (SPEC §18's
//! plant preparation): 2 (max |G_i| + a · max Σ_j |D_ij| + b_i · v + F_i)
//! over postures within the joint limits, a = [`EFFORT_ACCEL`], v =
//! [`EFFORT_SPEED`]: gravity and an acceleration of a of every joint at
//! once, twice over, with the joint's own viscous damping b_i at v and dry
//! friction F_i where the plant has them. The postures and the physics
//! engine that evaluates G and D there are the caller's; the rule is here,
//! once, for every front.

use crate::error::Error;
use alloc::vec::Vec;

/// The acceleration (rad/s², m/s²) an estimated effort limit leaves beyond
/// gravity.
pub const EFFORT_ACCEL: f64 = 10.0;

/// The joint speed (rad/s, m/s) at which an estimated effort limit
/// overcomes the joint's viscous damping.
pub const EFFORT_SPEED: f64 = 1.0;

/// The sampled arm the estimate reads: at each of K postures, the gravity
/// torque G (n values, N m) and the joint-space inertia D (n × n,
/// row-major, kg m²; with the rotors' armature if the plant has it).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Sampled<'a> {
    /// The number of joints n.
    pub n: usize,
    /// K rows of G (n each).
    pub gravity: &'a [f64],
    /// K matrices D (n × n each, row-major).
    pub inertia: &'a [f64],
}

/// The effort limits (N m, N) per joint: 2 (max_k |G_ki| + [`EFFORT_ACCEL`]
/// · max_k Σ_j |D_kij| + b_i [`EFFORT_SPEED`] + F_i), the sum over j in
/// order; `drag`: the joints' viscous damping b (N m s/rad) and dry
/// friction F (N m), n values each, if the plant has them. A NaN sample
/// gives NaN. Errors name the input whose length is not K n (K ≥ 1), K n²
/// or n.
pub fn estimate_effort(s: &Sampled<'_>, drag: Option<(&[f64], &[f64])>) -> Result<Vec<f64>, Error> {
    let n = s.n;
    let k = s.gravity.len().checked_div(n).unwrap_or(0);
    if n == 0 || k == 0 || s.gravity.len() != k * n {
        return Err(Error::Invalid {
            what: "gravity",
            reason: "needs K ≥ 1 rows of n values",
        });
    }
    if s.inertia.len() != k * n * n {
        return Err(Error::Invalid {
            what: "inertia",
            reason: "needs one n × n matrix per row of gravity",
        });
    }
    if let Some((b, f)) = drag {
        if b.len() != n {
            return Err(Error::Invalid {
                what: "damping",
                reason: "needs n values",
            });
        }
        if f.len() != n {
            return Err(Error::Invalid {
                what: "friction",
                reason: "needs n values",
            });
        }
    }
    // NumPy's maximum: NaN wins.
    let maximum = |a: f64, b: f64| {
        if a.is_nan() || b.is_nan() {
            f64::NAN
        } else {
            a.max(b)
        }
    };
    let mut g = alloc::vec![0.0; n];
    let mut d = alloc::vec![0.0; n];
    for (gk, dk) in s.gravity.chunks_exact(n).zip(s.inertia.chunks_exact(n * n)) {
        for i in 0..n {
            g[i] = maximum(g[i], gk[i].abs());
            let row: f64 = dk[i * n..(i + 1) * n].iter().map(|v| v.abs()).sum();
            d[i] = maximum(d[i], row);
        }
    }
    Ok((0..n)
        .map(|i| {
            let drive = drag.map_or(0.0, |(b, f)| EFFORT_SPEED * b[i] + f[i]);
            2.0 * (g[i] + EFFORT_ACCEL * d[i] + drive)
        })
        .collect())
}
