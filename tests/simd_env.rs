//! `ADAPTIMP_SIMD=portable` forces the portable weight pass. In a file of its
//! own, with one test, because the environment is process-wide: no other test
//! runs in this process.

use adaptimp::{simd, Controller, Law, SimdPath};

#[test]
fn adaptimp_simd_portable_forces_the_portable_path() {
    assert_eq!(simd::ENV_VAR, "ADAPTIMP_SIMD");
    std::env::set_var(simd::ENV_VAR, "portable");
    assert!(SimdPath::detect().is_portable());
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        assert_eq!(Controller::paper(law).simd().name(), "portable");
        assert_eq!(Controller::robot(law).simd().name(), "portable");
    }
    // Any other value leaves the choice to the CPU.
    std::env::set_var(simd::ENV_VAR, "auto");
    assert_eq!(SimdPath::detect(), SimdPath::fastest());
    assert_eq!(
        Controller::paper(Law::StateFeedback).simd(),
        SimdPath::fastest()
    );
    std::env::remove_var(simd::ENV_VAR);
    assert_eq!(SimdPath::detect(), SimdPath::fastest());
}
