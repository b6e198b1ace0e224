//! Fault injection in the robot scenario (as `cargo run --example faults`):
//! for PD, state and output feedback and each fault, the applied torque never
//! exceeds the limits, no NaN appears, the pre-fault tracking error is back
//! within 2 s of the fault's end, and the learned weights are not lost.

use adaptimp::simulator::run_with_injection;
use adaptimp::{
    Controller, Injected, Injection, Law, SimConfig, Sinusoid, TwoLinkArm, Vector, Wall,
};

#[test]
fn every_transient_fault_is_survived_and_recovered_from_within_2_s() {
    let sim = SimConfig {
        t_final: 10.0,
        ..SimConfig::robot()
    };
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        let ctrl = Controller::robot(law);
        let tau_max = *ctrl.saturation().limits();
        let at = |fault, duration| Injection {
            fault,
            start: 5.0,
            duration,
        };
        let run = |injection: &Injection<2>| {
            let mut state = ctrl.new_state();
            run_with_injection(
                &TwoLinkArm::paper(),
                &Wall::paper(),
                &mut ctrl.bind(&mut state),
                &Sinusoid::paper(),
                &sim,
                injection,
                &tau_max,
            )
            .expect("the run goes on through the fault")
        };
        // The same run without a fault (an empty window).
        let twin = run(&at(Injected::Stale, 0.0));
        for injection in [
            at(Injected::Stale, 0.05),
            at(Injected::NanBurst, 0.05),
            at(
                Injected::ForceBias {
                    bias: Vector::<2>::new(5.0, 0.0),
                },
                1.0,
            ),
            at(
                Injected::ActuatorDrop {
                    tau_max,
                    fraction: 0.3,
                },
                0.5,
            ),
            at(Injected::Skipped, 0.02),
        ] {
            let f = run(&injection);
            let what = format!("{law:?} {:?}: {f:?}", injection.fault);
            assert!(f.peak_applied_ratio <= 1.0, "{what}");
            assert!(!f.non_finite, "{what}");
            assert!(f.recovery.is_some_and(|r| r <= 2.0), "{what}");
            // The weights learned before the fault are kept: at the end they
            // are where the run without the fault has them, within a factor 2.
            let (after, expect) = (f.norms.1, twin.norms.1);
            for n in 0..3 {
                let kept = after[n] >= 0.5 * expect[n] && after[n] <= 2.0 * expect[n] + 1e-12;
                assert!(kept, "{what}");
            }
            // The refused rows are the fault's, and only for the faults that cause them.
            let expect = match injection.fault {
                Injected::NanBurst => 50,
                Injected::Skipped => 20,
                _ => 0,
            };
            assert_eq!(f.refused, expect, "{what}");
        }
    }
}
