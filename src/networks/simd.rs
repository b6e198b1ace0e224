//! Which instruction set the weight pass runs on, chosen at run time.
//!
//! The pass over the (2N² + N)·L weights (the `network` module) is written once,
//! generic over [`pulp::Simd`] on 4-lane f64 vectors, and compiled twice:
//!
//! - **avx2-fma**: pulp's `x86::V3` (x86-64-v3: AVX2, FMA, every x86-64 CPU
//!   since 2013, Haswell and Zen). Each 4-lane operation is one 256-bit
//!   instruction; pulp runs the pass inside a function compiled with those
//!   features, so a plain build (no `-C target-cpu`) gets them.
//! - **portable**: pulp's `Scalar256b`, the same 4-lane vectors as arrays of
//!   four reals, compiled for the build's target (two SSE2 instructions per
//!   operation on a baseline x86-64, NEON on aarch64, scalar elsewhere).
//!
//! Both paths do the same operations in the same order (two accumulators,
//! products and sums never fused, the same lane reduction), so they give the
//! same results. A [`Controller`](crate::Controller) picks its path once, when
//! it is built ([`SimdPath::detect`]), and passes it down to every pass
//! (through [`Learning`](crate::Learning) to [`WeightsMut`](crate::WeightsMut))
//! and to the evaluation of its basis ([`SimdPath::eval_basis`]).
//!
//! Detection: with `std`, the standard library's CPU feature detection (CPUID,
//! and XGETBV for the operating system's support of the 256-bit registers).
//! Without `std`, the fast path is taken only if the build itself enables
//! AVX2 and FMA (e.g. `-C target-cpu=x86-64-v3`): CPUID alone cannot tell
//! whether the environment saves the 256-bit registers. On other
//! architectures the pass is portable.

use crate::networks::rbf::Basis;
use crate::types::Vector;
use pulp::{Scalar256b, Simd, WithSimd};

#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
use pulp::x86::V3;

/// The environment variable read by [`SimdPath::detect`] (with `std`):
/// `ADAPTIMP_SIMD=portable` forces the portable path; any other value, or
/// none, leaves the choice to the CPU.
pub const ENV_VAR: &str = "ADAPTIMP_SIMD";

/// The implementation of the weight pass a [`Controller`](crate::Controller)
/// runs: `"avx2-fma"` or `"portable"` ([`name`](Self::name)); see the
/// [module docs](self). A value is proof that the CPU supports its path: the
/// fast one can only be had from detection.
#[derive(Copy, Clone)]
pub struct SimdPath(Path);

#[derive(Copy, Clone)]
enum Path {
    /// 256-bit AVX2 vectors; the token proves the CPU has them.
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    Avx2Fma(V3),
    /// 4-lane arrays compiled for the build's target.
    Portable,
}

impl SimdPath {
    /// The portable path: runs on any CPU the build targets.
    pub const fn portable() -> Self {
        Self(Path::Portable)
    }

    /// The fastest path this CPU supports, whatever the environment says.
    pub fn fastest() -> Self {
        #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
        if let Some(v3) = avx2_fma() {
            return Self(Path::Avx2Fma(v3));
        }
        Self::portable()
    }

    /// The path a new controller takes: [`portable`](Self::portable) if the
    /// environment variable [`ENV_VAR`] (`ADAPTIMP_SIMD`) is `portable` (read
    /// only with `std`), [`fastest`](Self::fastest) otherwise.
    pub fn detect() -> Self {
        #[cfg(feature = "std")]
        if std::env::var_os(ENV_VAR).is_some_and(|v| v == "portable") {
            return Self::portable();
        }
        Self::fastest()
    }

    /// `"avx2-fma"` or `"portable"`.
    pub const fn name(&self) -> &'static str {
        match self.0 {
            #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
            Path::Avx2Fma(_) => "avx2-fma",
            Path::Portable => "portable",
        }
    }

    /// True on the portable path.
    pub const fn is_portable(&self) -> bool {
        matches!(self.0, Path::Portable)
    }

    /// Evaluate `basis` at `z` into `s` ([`Basis::eval`]) inside this path's
    /// function, as the controller's step does: a basis whose `eval` is
    /// inlined there (the paper's [`Grid`](crate::Grid)) is compiled for AVX2
    /// too when the path is the fast one. The same operations, so the same
    /// values.
    pub fn eval_basis<const N: usize, B: Basis<N> + ?Sized>(
        self,
        basis: &B,
        z: &[Vector<N>; 4],
        s: &mut [f64],
    ) {
        struct Eval<'a, const N: usize, B: ?Sized> {
            basis: &'a B,
            z: &'a [Vector<N>; 4],
            s: &'a mut [f64],
        }
        impl<const N: usize, B: Basis<N> + ?Sized> WithSimd for Eval<'_, N, B> {
            type Output = ();
            #[inline(always)]
            fn with_simd<S: Simd>(self, _: S) {
                self.basis.eval(self.z, self.s);
            }
        }
        self.run(Eval { basis, z, s });
    }

    /// Run `op` on this path: inside a function compiled for AVX2 and FMA, or
    /// on the portable vectors.
    #[inline(always)]
    pub(crate) fn run<Op: WithSimd>(self, op: Op) -> Op::Output {
        match self.0 {
            #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
            Path::Avx2Fma(v3) => Simd::vectorize(v3, op),
            Path::Portable => portable(op),
        }
    }
}

/// `op` on the portable vectors, in a function of its own as the AVX2 path
/// is: inlined into a large caller (the whole controller step), the pass was
/// compiled with ~20% more instructions (callgrind).
#[inline(never)]
fn portable<Op: WithSimd>(op: Op) -> Op::Output {
    Simd::vectorize(Scalar256b, op)
}

impl PartialEq for SimdPath {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

impl Eq for SimdPath {}

impl core::fmt::Debug for SimdPath {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_tuple("SimdPath").field(&self.name()).finish()
    }
}

impl core::fmt::Display for SimdPath {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// pulp's x86-64-v3 token if the CPU (and, with `std`, the operating system)
/// supports AVX2 and FMA.
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
fn avx2_fma() -> Option<V3> {
    if cfg!(feature = "std") || cfg!(all(target_feature = "avx2", target_feature = "fma")) {
        V3::try_new()
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fastest_is_avx2_fma_exactly_when_the_cpu_has_it() {
        let fast = SimdPath::fastest();
        #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
        {
            let has = std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
            assert_eq!(fast.name(), if has { "avx2-fma" } else { "portable" });
        }
        #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
        assert!(fast.is_portable());
        assert!(SimdPath::portable().is_portable());
        assert_eq!(SimdPath::portable().to_string(), "portable");
        assert_eq!(
            format!("{:?}", SimdPath::portable()),
            r#"SimdPath("portable")"#
        );
    }
}
