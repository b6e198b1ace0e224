//! A state in the caller's buffer (the core's `state_in` through the C ABI,
//! for firmware without a heap): its size and alignment, no allocation from
//! its init to its free, steps bit-identical to a heap state's, and buffers
//! that are too small or misaligned refused. Allocations are counted exactly
//! with a thread-local counter in the global allocator (as tests/alloc.rs).

use adaptimp_ffi::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ptr;

mod common;
use common::{defaults, last_error, poisoned, Handles};

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn count() {
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: every call is forwarded unchanged to `System`; the counter is a
// thread-local `Cell` with a `const` initialiser (it never allocates).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

fn allocations_in<T>(f: impl FnOnce() -> T) -> (u64, T) {
    let before = ALLOCATIONS.with(Cell::get);
    let out = f();
    (ALLOCATIONS.with(Cell::get) - before, out)
}

/// A buffer of `size` bytes aligned to 64 (any alignment up to 64 asked for).
fn buffer(size: usize) -> Vec<[u64; 8]> {
    vec![[0u64; 8]; size.div_ceil(64)]
}

#[test]
fn a_state_in_a_caller_buffer_steps_as_a_heap_state_without_allocating() {
    for (law, preset) in [
        (AdaptimpLaw::StateFeedback, AdaptimpPreset::Robot),
        (AdaptimpLaw::OutputFeedback, AdaptimpPreset::Paper),
    ] {
        let h = Handles::new(&defaults(2, law, preset)).unwrap();
        let (mut size, mut align) = (0, 0);
        // SAFETY: valid pointers.
        assert_eq!(
            unsafe { adaptimp_state_buffer_size(h.ctrl, &mut size, &mut align) },
            AdaptimpStatus::Ok
        );
        assert!(align.is_power_of_two() && align <= 64);
        // The 256-node grid's basis and weights (L (2n² + n + 1) reals, a cache
        // line of slack each side) and a header.
        let reals = 256 * (2 * 4 + 2 + 1);
        assert!(size > 8 * reals && size < 8 * reals + 4096, "{size}");
        let mut buf = buffer(size);
        let mut st = ptr::null_mut();
        let q = [0.25, -0.05];
        let (n, ()) = allocations_in(|| {
            // SAFETY: `size` writable bytes, aligned to 64, unused otherwise.
            unsafe {
                assert_eq!(
                    adaptimp_state_init(h.ctrl, buf.as_mut_ptr().cast(), size, &mut st),
                    AdaptimpStatus::Ok
                );
                for k in 0..500 {
                    let qk = [q[0] + 1e-3 * (k as f64 * 0.01).sin(), q[1]];
                    let dq = [0.01, 0.0];
                    let te = [0.0, 0.0];
                    let mut a = poisoned();
                    let s = adaptimp_step(
                        h.ctrl,
                        st,
                        2,
                        qk.as_ptr(),
                        dq.as_ptr(),
                        te.as_ptr(),
                        ptr::null(),
                        &mut a,
                    );
                    assert_eq!(s, AdaptimpStatus::Ok);
                    let b = h.step(&qk, Some(&dq), &te).unwrap();
                    assert_eq!(a, b, "k = {k}");
                }
                // A refusal too: the fallback, no allocation.
                let nan = [f64::NAN, 0.0];
                let mut a = poisoned();
                let s = adaptimp_step(
                    h.ctrl,
                    st,
                    2,
                    nan.as_ptr(),
                    q.as_ptr(),
                    q.as_ptr(),
                    ptr::null(),
                    &mut a,
                );
                assert_eq!(s, AdaptimpStatus::NonFinite);
                assert_eq!(adaptimp_state_steps(st), 500);
                adaptimp_state_free(st);
            }
        });
        assert_eq!(n, 0, "{law:?} {preset:?}: allocations");
    }
}

#[test]
fn a_buffer_too_small_or_misaligned_is_refused() {
    let h = Handles::new(&defaults(
        2,
        AdaptimpLaw::StateFeedback,
        AdaptimpPreset::Robot,
    ))
    .unwrap();
    let (mut size, mut align) = (0, 0);
    // SAFETY: valid pointers.
    unsafe { adaptimp_state_buffer_size(h.ctrl, &mut size, &mut align) };
    let mut buf = buffer(size + 64);
    let mut st = ptr::null_mut();
    // SAFETY: the buffer holds size + 64 bytes; what is passed stays within it.
    unsafe {
        let base: *mut u8 = buf.as_mut_ptr().cast();
        assert_eq!(
            adaptimp_state_init(h.ctrl, base.cast(), size - 1, &mut st),
            AdaptimpStatus::BadSize
        );
        assert!(
            last_error().contains(&format!("needs {size} bytes")),
            "{}",
            last_error()
        );
        assert_eq!(
            adaptimp_state_init(h.ctrl, base.add(1).cast(), size, &mut st),
            AdaptimpStatus::BadSize
        );
        assert!(
            last_error().contains("that is not a multiple of"),
            "{}",
            last_error()
        );
        assert_eq!(
            adaptimp_state_init(h.ctrl, ptr::null_mut(), size, &mut st),
            AdaptimpStatus::NullPointer
        );
        assert!(st.is_null());
        // Any aligned start within the buffer works (the basis aligns itself).
        assert_eq!(
            adaptimp_state_init(h.ctrl, base.add(align).cast(), size, &mut st),
            AdaptimpStatus::Ok
        );
        let s = [0.1, 0.2];
        let mut out = poisoned();
        assert_eq!(
            adaptimp_step(
                h.ctrl,
                st,
                2,
                s.as_ptr(),
                s.as_ptr(),
                s.as_ptr(),
                ptr::null(),
                &mut out
            ),
            AdaptimpStatus::Ok
        );
        // Snapshots move a state between the heap and a caller buffer.
        let len = adaptimp_state_snapshot_len(st);
        let mut snap = vec![0.0; len];
        assert_eq!(
            adaptimp_state_save(st, snap.as_mut_ptr(), len, ptr::null_mut()),
            AdaptimpStatus::Ok
        );
        assert_eq!(
            adaptimp_state_restore(h.ctrl, h.state, snap.as_ptr(), len),
            AdaptimpStatus::Ok
        );
        assert_eq!(adaptimp_state_steps(h.state), 1);
        adaptimp_state_free(st);
    }
}
