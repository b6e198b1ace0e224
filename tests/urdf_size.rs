//! The URDF reader's work grows linearly with the file, counted exactly: the
//! allocations it makes and the most memory it holds at once (a global
//! allocator that counts the calling thread's allocations and live bytes),
//! and how often it asks its caller whether to go on (a front's Ctrl-C).
//!
//! The reader before this built the whole document three times over (XML
//! elements, text again, urdf-rs's events): it held 76 bytes for each byte
//! read (2.4 GB for a 27 MB file of 200 000 links, which took 10.9 s of CPU
//! against 1.1 s for 20 000), and never asked to go on.
#![cfg(feature = "urdf")]

use adaptimp::description::{reduce, urdf, ErrorKind};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting the allocations and the live bytes of the
/// current thread (the harness's other threads do not count).
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
    static LIVE: Cell<i64> = const { Cell::new(0) };
    static PEAK: Cell<i64> = const { Cell::new(0) };
}

fn grow(bytes: i64) {
    // `try_with`: allocations during thread teardown are not this test's.
    let _ = LIVE.try_with(|l| {
        l.set(l.get() + bytes);
        let _ = PEAK.try_with(|p| p.set(p.get().max(l.get())));
    });
}

fn alloc_counted(bytes: usize) {
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
    grow(bytes as i64);
}

// SAFETY: every call is forwarded unchanged to `System`, which upholds the
// `GlobalAlloc` contract; the counters are thread-local `Cell`s that never
// allocate (`const` initialisers).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        alloc_counted(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        alloc_counted(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        alloc_counted(new_size);
        grow(-(layout.size() as i64));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        grow(-(layout.size() as i64));
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// A URDF of `n` links in a chain: fixed joints, the last three revolute.
fn chain(n: usize) -> String {
    let mut s = String::from("<robot name='big'>\n<link name='l0'/>\n");
    for i in 1..=n {
        s.push_str(&format!("<link name='l{i}'/>\n"));
        if i + 3 > n {
            s.push_str(&format!(
                "<joint name='j{i}' type='revolute'><parent link='l{}'/><child link='l{i}'/>\
                 <axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>\n",
                i - 1
            ));
        } else {
            s.push_str(&format!(
                "<joint name='j{i}' type='fixed'><parent link='l{}'/><child link='l{i}'/>\
                 <origin xyz='0 0 0.001'/></joint>\n",
                i - 1
            ));
        }
    }
    s.push_str("</robot>");
    s
}

/// Reading and reducing `text` (the tip `l{n}`): the allocations made and
/// the most bytes held at once beyond what was held before.
fn work(text: &str, n: usize) -> (u64, i64) {
    let (a0, l0) = (ALLOCATIONS.with(Cell::get), LIVE.with(Cell::get));
    PEAK.with(|p| p.set(l0));
    let tree = urdf::read_str(text).expect("a URDF");
    let arm = reduce(&tree, Some(&format!("l{n}")), &[]).expect("an arm");
    assert_eq!(arm.n(), 3);
    drop((tree, arm));
    let allocations = ALLOCATIONS.with(Cell::get) - a0;
    (allocations, PEAK.with(Cell::get) - l0)
}

#[test]
fn reading_a_urdf_is_linear_in_its_size() {
    let (small, large) = (4_000, 16_000);
    let (ts, tl) = (chain(small), chain(large));
    let (a_small, peak_small) = work(&ts, small);
    let (a_large, peak_large) = work(&tl, large);
    let ratio = a_large as f64 / a_small as f64;
    let per_byte = peak_large as f64 / tl.len() as f64;
    let peak_ratio = peak_large as f64 / peak_small as f64;
    // Four times the links, four times the allocations (2 % for the
    // reduction's logarithmic searches).
    assert!((3.9..=4.1).contains(&ratio), "allocations ×{ratio}");
    // Memory held at once: the tree and one batch of elements, linear too
    // (a batch's share shrinks), 6.5 bytes per byte of the file (76 before).
    assert!(per_byte < 10.0, "{per_byte} bytes held per byte read");
    assert!((3.2..=4.2).contains(&peak_ratio), "peak ×{peak_ratio}");
}

#[test]
fn a_reading_asks_to_go_on_once_per_chunk_and_batch() {
    let n = 16_000;
    let text = chain(n);
    let mut asks = 0;
    urdf::read_str_with(&text, None, &mut || {
        asks += 1;
        true
    })
    .expect("a URDF");
    let least = text.len() / urdf::CHUNK_BYTES + 2 * n / urdf::BATCH_ELEMENTS;
    assert!(asks >= least, "{asks} asks, at least {least}");
}

#[test]
fn a_reading_stops_when_asked_and_says_so() {
    let text = chain(8_000);
    let mut asks = 0;
    let e = urdf::read_str_with(&text, None, &mut || {
        asks += 1;
        asks < 3
    })
    .expect_err("stopped");
    assert_eq!(e.kind(), ErrorKind::Stopped);
    assert_eq!(e.to_string(), "the reading was stopped by its caller");
    assert_eq!(asks, 3);
    // The same for the kind of a text that could be xacro (read to its end
    // for its markup, here in the last joint).
    let xacro = text.replace("name='j8000'", "name='${j}'");
    let mut asks = 0;
    let e = urdf::kind_of_with(&xacro, &mut || {
        asks += 1;
        false
    })
    .expect_err("stopped");
    assert_eq!(e.kind(), ErrorKind::Stopped);
}
