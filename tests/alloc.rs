//! Zero heap allocations in the hot path, counted by a global allocator
//! (dhat in testing mode) in this test binary.
//!
//! One test function only: dhat allows one profiler per process.

use adaptimp::{simulate, Controller, Law, Measurement, SimConfig, TwoLinkArm, Vector, Wall};

#[global_allocator]
static ALLOC: dhat::Alloc = dhat::Alloc;

fn blocks() -> u64 {
    dhat::HeapStats::get().total_blocks
}

#[test]
fn no_heap_allocation_in_steps_and_simulation() {
    let _profiler = dhat::Profiler::builder().testing().build();
    let arm = TwoLinkArm::paper();
    let wall = Wall::paper();
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        // Construction is allowed to allocate (here: one Box); the step is not.
        let mut ctrl = Box::new(Controller::paper(law));
        let (mut x, mut dx) = (Vector::<2>::new(0.25, -0.05), Vector::<2>::zeros());
        let before = blocks();
        for _ in 0..10_000 {
            let tau_e = adaptimp::Environment::force(&wall, 0.0, &x, &dx);
            let cmd = ctrl
                .step(&Measurement {
                    x,
                    dx: Some(dx),
                    tau_e,
                })
                .expect("step");
            // A crude plant update, just to vary the inputs.
            let a = adaptimp::Manipulator::forward_dynamics(&arm, &x, &dx, &cmd.tau_sat, &tau_e);
            dx += 5e-5 * a;
            x += 5e-5 * dx;
        }
        assert_eq!(blocks(), before, "{law:?}: the step allocated");

        let sim = SimConfig {
            t_final: 0.5,
            ..SimConfig::paper()
        };
        let before = blocks();
        let m = simulate(&arm, &wall, ctrl.as_mut(), &sim, &mut ()).expect("simulate");
        assert_eq!(blocks(), before, "{law:?}: simulate allocated");
        assert_eq!(m.rows, 10_000);
    }
    // The counter does count: a Vec allocates one block.
    let before = blocks();
    let v: Vec<u8> = Vec::with_capacity(16);
    assert_eq!(blocks(), before + 1);
    drop(v);
}
