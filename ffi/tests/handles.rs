//! Handles that cannot be forged into a crash (issue 33, A): a handle is a
//! number checked against the registry of live handles before anything is
//! read, so a freed handle, a handle whose memory a newer object reuses, a
//! handle of another kind and a pointer that was never a handle (even one to
//! unmapped memory) are refused with BAD_HANDLE and change nothing.

use adaptimp_ffi::*;
use std::ptr;

mod common;
use common::{defaults, last_error, poisoned, Handles};

const Q: [f64; 2] = [0.25, -0.05];
const DQ: [f64; 2] = [0.1, 0.0];
const TE: [f64; 2] = [0.0, 0.0];

fn robot_sf() -> AdaptimpParams {
    defaults(2, AdaptimpLaw::StateFeedback, AdaptimpPreset::Robot)
}

/// One step of `state` under `ctrl`: the status and the output.
fn step(
    ctrl: *mut AdaptimpController,
    state: *mut AdaptimpState,
) -> (AdaptimpStatus, AdaptimpCommand) {
    let mut out = poisoned();
    // SAFETY: handles are checked by the library; the arrays hold 2 reals.
    let s = unsafe {
        adaptimp_step(
            ctrl,
            state,
            2,
            Q.as_ptr(),
            DQ.as_ptr(),
            TE.as_ptr(),
            ptr::null(),
            &mut out,
        )
    };
    (s, out)
}

#[test]
fn a_stale_handle_is_refused_even_when_a_new_state_reuses_its_memory() {
    let h = Handles::new(&robot_sf()).unwrap();
    // Free and make heap states until the allocator gives a new one the
    // memory of a freed one (it does at once here, but the test does not
    // rely on it): the stale handle never steps the new state.
    for _ in 0..8 {
        let mut old = ptr::null_mut();
        let mut new = ptr::null_mut();
        // SAFETY: a live controller, valid out pointers.
        unsafe {
            assert_eq!(adaptimp_state_new(h.ctrl, &mut old), AdaptimpStatus::Ok);
            assert_eq!(step(h.ctrl, old).0, AdaptimpStatus::Ok);
            adaptimp_state_free(old);
            assert_eq!(adaptimp_state_new(h.ctrl, &mut new), AdaptimpStatus::Ok);
        }
        assert_ne!(old, new, "a handle's number is never given twice");
        let (s, out) = step(h.ctrl, old);
        assert_eq!(s, AdaptimpStatus::BadHandle);
        assert_eq!(
            last_error(),
            "state is not a live AdaptimpState (freed, never made, or another object)"
        );
        assert_eq!(out, AdaptimpCommand::ZERO);
        // SAFETY: handles checked by the library.
        unsafe {
            assert_eq!(
                adaptimp_state_steps(new),
                0,
                "the new state was not stepped"
            );
            assert_eq!(adaptimp_state_reset(old), AdaptimpStatus::BadHandle);
            // Freeing the stale handle again does not free the new state.
            adaptimp_state_free(old);
            assert_eq!(step(h.ctrl, new).0, AdaptimpStatus::Ok);
            assert_eq!(adaptimp_state_steps(new), 1);
            adaptimp_state_free(new);
        }
    }
}

#[test]
fn a_stale_handle_into_a_reused_caller_buffer_is_refused() {
    let h = Handles::new(&robot_sf()).unwrap();
    let (mut size, mut align) = (0, 0);
    // SAFETY: valid pointers.
    assert_eq!(
        unsafe { adaptimp_state_buffer_size(h.ctrl, &mut size, &mut align) },
        AdaptimpStatus::Ok
    );
    assert!(align <= 8);
    let mut buf = vec![0u64; size.div_ceil(8)];
    let (mut first, mut second, mut third) = (ptr::null_mut(), ptr::null_mut(), ptr::null_mut());
    // SAFETY: a buffer of `size` bytes aligned to 8, used for nothing else.
    unsafe {
        let b = buf.as_mut_ptr().cast();
        assert_eq!(
            adaptimp_state_init(h.ctrl, b, size, &mut first),
            AdaptimpStatus::Ok
        );
        assert_eq!(step(h.ctrl, first).0, AdaptimpStatus::Ok);
        adaptimp_state_free(first);
        // The same buffer, a new state: the old handle is not the new state.
        assert_eq!(
            adaptimp_state_init(h.ctrl, b, size, &mut second),
            AdaptimpStatus::Ok
        );
        assert_eq!(step(h.ctrl, first).0, AdaptimpStatus::BadHandle);
        assert_eq!(adaptimp_state_steps(second), 0);
        // A state placed over a live one (the caller's bug): the older
        // handle is refused, not the newer state stepped through it.
        assert_eq!(
            adaptimp_state_init(h.ctrl, b, size, &mut third),
            AdaptimpStatus::Ok
        );
        assert_eq!(step(h.ctrl, second).0, AdaptimpStatus::BadHandle);
        assert_eq!(
            last_error(),
            "state is not a live AdaptimpState (freed, never made, or another object)"
        );
        assert_eq!(step(h.ctrl, third).0, AdaptimpStatus::Ok);
        assert_eq!(adaptimp_state_steps(third), 1);
        adaptimp_state_free(third);
        // Freeing the overwritten one gives its handle back and leaves the
        // memory alone (the third state's was already ended).
        adaptimp_state_free(second);
        assert_eq!(adaptimp_state_steps(second), 0);
    }
}

#[test]
fn a_handle_of_another_kind_is_refused_by_name_without_an_invalid_read() {
    let h = Handles::new(&robot_sf()).unwrap();
    let mut out = [0.0; 2];
    // SAFETY: handles are checked by the library.
    unsafe {
        // A joint state given as a Cartesian state.
        let cs: *mut AdaptimpCartesianState = h.state.cast();
        assert_eq!(adaptimp_cartesian_state_steps(cs), 0);
        assert_eq!(
            adaptimp_cartesian_state_applied(cs, 2, out.as_mut_ptr()),
            AdaptimpStatus::BadHandle
        );
        assert_eq!(
            last_error(),
            "state is a live AdaptimpState, not an AdaptimpCartesianState"
        );
        adaptimp_cartesian_state_free(cs);
        // ... and still a live joint state.
        assert_eq!(step(h.ctrl, h.state).0, AdaptimpStatus::Ok);
        // A controller given as a chain, a state as a controller.
        assert_eq!(adaptimp_chain_joints(h.ctrl.cast()), 0);
        assert_eq!(
            adaptimp_state_clear_fault(h.ctrl.cast()),
            AdaptimpStatus::BadHandle
        );
        assert_eq!(
            last_error(),
            "state is a live AdaptimpController, not an AdaptimpState"
        );
        let (s, o) = step(h.state.cast(), h.state);
        assert_eq!(s, AdaptimpStatus::BadHandle);
        assert_eq!(o, AdaptimpCommand::ZERO);
    }
}

#[test]
fn pointers_that_were_never_handles_are_refused_without_reading_them() {
    let h = Handles::new(&robot_sf()).unwrap();
    // Addresses nothing is mapped at, the top of the address space, small
    // integers, and memory of the caller's that looks like a handle's
    // object: none is read.
    let zeros = [0u64; 64];
    let looks = [u64::from_le_bytes(*b"adpSTATE"), 0, 0, 0];
    let forged: [*mut AdaptimpState; 7] = [
        ptr::without_provenance_mut(0x10),
        ptr::without_provenance_mut(0x1000),
        ptr::without_provenance_mut(usize::MAX - 7),
        ptr::without_provenance_mut(1),
        zeros.as_ptr().cast_mut().cast(),
        looks.as_ptr().cast_mut().cast(),
        // A real handle's number plus one.
        ptr::without_provenance_mut(h.state.addr() + 1),
    ];
    for p in forged {
        let (s, out) = step(h.ctrl, p);
        assert_eq!(s, AdaptimpStatus::BadHandle, "{p:?}");
        assert_eq!(out, AdaptimpCommand::ZERO);
        // SAFETY: handles are checked by the library.
        unsafe {
            assert_eq!(adaptimp_state_steps(p), 0);
            assert_eq!(adaptimp_cartesian_state_steps(p.cast()), 0);
            assert_eq!(adaptimp_controller_joints(p.cast()), 0);
            assert_eq!(adaptimp_chain_joints(p.cast()), 0);
            assert_eq!(adaptimp_cartesian_joints(p.cast()), 0);
            adaptimp_state_free(p);
            adaptimp_controller_free(p.cast());
            adaptimp_chain_free(p.cast());
            adaptimp_cartesian_free(p.cast());
            adaptimp_cartesian_state_free(p.cast());
        }
    }
    assert_eq!(step(h.ctrl, h.state).0, AdaptimpStatus::Ok);
}

#[test]
fn every_handle_is_a_repr_c_object_with_its_tag_first() {
    // The layout the registry reads (its header, at offset 0 of every kind)
    // is checked at compile time; here: a handle is not an address of the
    // library's memory that a caller could read or write by mistake, and
    // two live handles differ.
    let a = Handles::new(&robot_sf()).unwrap();
    let b = Handles::new(&robot_sf()).unwrap();
    assert_ne!(a.state, b.state);
    assert_ne!(a.ctrl, b.ctrl);
    assert_ne!(a.ctrl.addr(), a.state.addr());
}
