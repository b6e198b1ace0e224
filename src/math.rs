//! Scalar maths that works with and without `std`.
//!
//! With `std` the platform libm is used (it is faster); without it, the
//! `libm` crate. The two agree to within an ulp or so.

#[cfg(feature = "std")]
mod imp {
    #[inline(always)]
    pub fn exp(x: f64) -> f64 {
        x.exp()
    }
    #[inline(always)]
    pub fn sin(x: f64) -> f64 {
        x.sin()
    }
    #[inline(always)]
    pub fn cos(x: f64) -> f64 {
        x.cos()
    }
    #[inline(always)]
    pub fn tanh(x: f64) -> f64 {
        x.tanh()
    }
    #[inline(always)]
    pub fn sqrt(x: f64) -> f64 {
        x.sqrt()
    }

    #[inline(always)]
    pub fn atan2(y: f64, x: f64) -> f64 {
        y.atan2(x)
    }
}

#[cfg(not(feature = "std"))]
mod imp {
    #[inline(always)]
    pub fn exp(x: f64) -> f64 {
        libm::exp(x)
    }
    #[inline(always)]
    pub fn sin(x: f64) -> f64 {
        libm::sin(x)
    }
    #[inline(always)]
    pub fn cos(x: f64) -> f64 {
        libm::cos(x)
    }
    #[inline(always)]
    pub fn tanh(x: f64) -> f64 {
        libm::tanh(x)
    }
    #[inline(always)]
    pub fn sqrt(x: f64) -> f64 {
        libm::sqrt(x)
    }

    #[inline(always)]
    pub fn atan2(y: f64, x: f64) -> f64 {
        libm::atan2(y, x)
    }
}

pub use imp::*;

/// (sin x, cos x) with one argument reduction, the same with and without
/// `std` (within 1 ulp of the platform's; the kinematics' and dynamics' joint
/// angles, SPEC §16, §20): for |x| < 2²⁰ the reduction by π/2 of fdlibm's
/// `__rem_pio2` (two terms, with the tail) and its kernels `__kernel_sin`,
/// `__kernel_cos` on [−π/4, π/4] (FreeBSD's msun, as musl and the `libm`
/// crate have them), inlined; beyond, and for non-finite x, the `libm`
/// crate's `sincos`.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    const INV_PIO2: f64 = core::f64::consts::FRAC_2_PI;
    // π/2 in two parts (fdlibm's pio2_1, pio2_1t): 33 bits, and the rest.
    const PIO2_1: f64 = f64::from_bits(0x3FF9_21FB_5440_0000);
    const PIO2_1T: f64 = f64::from_bits(0x3DD0_B461_1A62_6331);
    const TOINT: f64 = 1.5 / f64::EPSILON;
    // Beyond the fast path: ±∞ and NaN (whose sin and cos are NaN) too.
    if x.abs() >= 1_048_576.0 || x.is_nan() {
        return libm::sincos(x);
    }
    // x = k π/2 + (y0 + y1), |y0| ≤ π/4 (k exact: |x 2/π| < 2^51).
    let f = (x * INV_PIO2 + TOINT) - TOINT;
    let r = x - f * PIO2_1;
    let w = f * PIO2_1T;
    let y0 = r - w;
    let y1 = (r - y0) - w;
    let (s, c) = (kernel_sin(y0, y1), kernel_cos(y0, y1));
    match (f as i64) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// sin(x + y) for |x| ≤ π/4, |y| ≤ ulp(x)/2 (fdlibm's `__kernel_sin`; its
/// coefficients as published).
#[inline(always)]
#[allow(clippy::excessive_precision)]
fn kernel_sin(x: f64, y: f64) -> f64 {
    const S1: f64 = -1.666_666_666_666_663_243_48e-1;
    const S2: f64 = 8.333_333_333_322_489_461_24e-3;
    const S3: f64 = -1.984_126_982_985_794_931_34e-4;
    const S4: f64 = 2.755_731_370_707_006_767_89e-6;
    const S5: f64 = -2.505_076_025_340_686_341_95e-8;
    const S6: f64 = 1.589_690_995_211_550_102_21e-10;
    let z = x * x;
    let w = z * z;
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let v = z * x;
    x - ((z * (0.5 * y - v * r) - y) - v * S1)
}

/// cos(x + y) for |x| ≤ π/4, |y| ≤ ulp(x)/2 (fdlibm's `__kernel_cos`; its
/// coefficients as published).
#[inline(always)]
#[allow(clippy::excessive_precision)]
fn kernel_cos(x: f64, y: f64) -> f64 {
    const C1: f64 = 4.166_666_666_666_660_190_37e-2;
    const C2: f64 = -1.388_888_888_887_410_957_49e-3;
    const C3: f64 = 2.480_158_728_947_672_941_78e-5;
    const C4: f64 = -2.755_731_435_139_066_330_35e-7;
    const C5: f64 = 2.087_572_321_298_174_827_90e-9;
    const C6: f64 = -1.135_964_755_778_819_482_65e-11;
    let z = x * x;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + (z * r - x * y))
}

/// The sign function with `sgn(0) = 0` (SPEC notation); NaN maps to 0.
#[inline(always)]
pub fn sgn(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_cos_is_the_platforms_to_an_ulp() {
        // xorshift over |x| ≤ 10 (joint angles) and |x| ≤ 1e4, the branch's
        // edges, multiples of π/2, and beyond the fast path.
        let mut st = 0x9e37_79b9_7f4a_7c15_u64;
        let mut xs = std::vec::Vec::new();
        for k in 0..200_000 {
            st ^= st << 13;
            st ^= st >> 7;
            st ^= st << 17;
            let u = (st >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            xs.push(u * if k % 2 == 0 { 20.0 } else { 2e4 });
        }
        for k in -8..=8 {
            xs.push(k as f64 * core::f64::consts::FRAC_PI_2);
            xs.push(k as f64 * core::f64::consts::FRAC_PI_4);
        }
        xs.extend([
            0.0,
            -0.0,
            1e-300,
            -1e-310,
            1_048_575.9,
            1_048_576.0,
            1e10,
            -3e300,
        ]);
        for x in xs {
            let (s, c) = sin_cos(x);
            assert!(
                (s - x.sin()).abs() <= 2.3e-16,
                "sin {x}: {s} vs {}",
                x.sin()
            );
            assert!(
                (c - x.cos()).abs() <= 2.3e-16,
                "cos {x}: {c} vs {}",
                x.cos()
            );
        }
        assert_eq!(sin_cos(-0.0).0.to_bits(), (-0.0f64).to_bits());
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (s, c) = sin_cos(x);
            assert!(s.is_nan() && c.is_nan(), "{x}");
        }
    }
}
