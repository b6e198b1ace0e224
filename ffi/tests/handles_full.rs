//! The registry of live handles is a fixed table (static memory, so that a
//! state in a caller's buffer needs no allocation): making a handle while
//! ADAPTIMP_MAX_HANDLES live is refused by name, and works again once one is
//! freed. Its own test binary: it fills the table, which its process shares.

use adaptimp_ffi::*;
use std::ptr;

mod common;
use common::last_error;

fn chain() -> (AdaptimpStatus, *mut AdaptimpChain) {
    let joint = AdaptimpJoint {
        kind: AdaptimpJointKind::Revolute.into(),
        origin: AdaptimpTransform {
            translation: [0.0; 3],
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        },
        axis: [0.0, 0.0, 1.0],
        offset: 0.0,
    };
    let mut out = ptr::null_mut();
    // SAFETY: one joint, a valid out pointer.
    let s = unsafe { adaptimp_chain_new(&joint, 1, ptr::null(), &mut out) };
    (s, out)
}

#[test]
fn making_a_handle_beyond_the_table_is_refused_by_name() {
    let mut live = Vec::with_capacity(ADAPTIMP_MAX_HANDLES);
    for _ in 0..ADAPTIMP_MAX_HANDLES {
        let (s, c) = chain();
        assert_eq!(s, AdaptimpStatus::Ok);
        live.push(c);
    }
    let (s, c) = chain();
    assert_eq!(s, AdaptimpStatus::TooManyHandles);
    assert!(c.is_null());
    assert_eq!(
        last_error(),
        "16384 handles are live (ADAPTIMP_MAX_HANDLES): free one before making another AdaptimpChain"
    );
    // SAFETY: live handles, freed once.
    unsafe { adaptimp_chain_free(live.pop().unwrap()) };
    let (s, c) = chain();
    assert_eq!(s, AdaptimpStatus::Ok);
    live.push(c);
    // Every handle is distinct and live.
    let distinct: std::collections::BTreeSet<usize> = live.iter().map(|p| p.addr()).collect();
    assert_eq!(distinct.len(), ADAPTIMP_MAX_HANDLES);
    for c in live {
        // SAFETY: live handles, freed once.
        unsafe {
            assert_eq!(adaptimp_chain_joints(c), 1);
            adaptimp_chain_free(c);
        }
    }
}
