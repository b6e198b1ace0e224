//! The handles the C caller holds, and the registry that checks them.
//!
//! A handle (`AdaptimpController *`, `AdaptimpState *`, …) is not the
//! address of the object: it is a pointer-sized number this library gave
//! out, and only this library reads it; the caller copies and compares it
//! but never dereferences it. Each number names one slot of a fixed table
//! (static memory: no allocation) and one creation: the slot holds the
//! number of the handle that lives in it now and the object's address. So
//! checking a handle reads nothing the caller gave: a handle that was never
//! made (a pointer to anything else, zeroed memory, an unmapped address), a
//! freed one, and a freed one whose memory (or slot) a newer handle reuses
//! are all refused (BAD_HANDLE) by comparing numbers, before any memory is
//! touched. Each object is `#[repr(C)]` and begins with a [`Header`]: its
//! kind's tag and its handle's number. Once the registry says a handle is
//! live, its header is read (valid: a live object of some kind) to refuse a
//! handle of another kind (a joint state given as a Cartesian one) and a
//! caller buffer in which a newer state was placed over a live one.
//!
//! What stays the caller's contract (docs/reliability.md, "Where C's
//! guarantees stop"): a handle is used by one thread at a time, and not
//! while another thread frees it; a caller buffer outlives the state placed
//! in it; a number equal to a live handle's is that handle (a forged one is
//! refused unless it happens to equal a live handle's number: about one in
//! 2^50 on a 64-bit target).

use crate::{fail, null, AdaptimpStatus};
use core::ffi::c_void;
use std::sync::atomic::{AtomicPtr, AtomicUsize, Ordering};
use std::sync::Mutex;

/// How many handles can live at once, of every kind together (a freed one
/// does not count): making one more is refused with TOO_MANY_HANDLES.
pub const ADAPTIMP_MAX_HANDLES: usize = 16384;

/// The slot of a handle is the low bits of its number (after the mix).
const SLOT_BITS: u32 = ADAPTIMP_MAX_HANDLES.trailing_zeros();
const _: () = assert!(ADAPTIMP_MAX_HANDLES.is_power_of_two());

/// Mixed into every handle's number, so that small integers, addresses and
/// zeroed memory do not decode to a slot and a creation that are live.
const MIX: usize = 0x9e37_79b9_7f4a_7c15_u64 as usize;

/// Where an object's memory is.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Place {
    /// A `Box` of this library's ([`publish`]): freed by [`free`].
    Heap,
    /// The caller's buffer ([`publish_in`]): [`free`] only ends its life.
    Caller,
}

/// The first field of every object behind a handle (`#[repr(C)]`, so at
/// offset 0 whatever the kind: reading it is valid for any live object).
#[repr(C)]
#[derive(Debug)]
pub(crate) struct Header {
    /// The kind's tag ([`Handle::TAG`]); zero once freed.
    tag: u64,
    /// The number of the handle this object was published under.
    id: usize,
    /// Where the object is.
    place: Place,
}

impl Header {
    /// A header to be filled in when the object is published.
    pub(crate) const fn unpublished() -> Self {
        Self {
            tag: 0,
            id: 0,
            place: Place::Heap,
        }
    }
}

/// The buffer of reals a state works in: the heap's, or the caller's.
#[derive(Debug)]
pub(crate) enum Buf {
    Heap(Vec<f64>),
    Caller(&'static mut [f64]),
}

impl AsRef<[f64]> for Buf {
    fn as_ref(&self) -> &[f64] {
        match self {
            Buf::Heap(v) => v,
            Buf::Caller(s) => s,
        }
    }
}

impl AsMut<[f64]> for Buf {
    fn as_mut(&mut self) -> &mut [f64] {
        match self {
            Buf::Heap(v) => v,
            Buf::Caller(s) => s,
        }
    }
}

/// A kind of handle: the opaque type the header names, and the object
/// behind it.
pub(crate) trait Handle: Sized {
    /// The object: `#[repr(C)]` with a [`Header`] named `head` as its first field.
    type Object;
    /// The tag of a live object of this kind.
    const TAG: u64;
    /// The C name, for messages.
    const NAME: &'static str;
    /// The object's header.
    fn head(o: &mut Self::Object) -> &mut Header;
}

/// Implements [`Handle`] for the opaque type `$t` whose objects are `$o`
/// (checked at compile time: `$o` has its `head` at offset 0).
macro_rules! handle_kind {
    ($t:ident => $o:ty, $tag:literal) => {
        impl $crate::handles::Handle for $t {
            type Object = $o;
            const TAG: u64 = u64::from_le_bytes(*$tag);
            const NAME: &'static str = stringify!($t);
            fn head(o: &mut $o) -> &mut $crate::handles::Header {
                &mut o.head
            }
        }
        const _: () = assert!(core::mem::offset_of!($o, head) == 0);
    };
}

/// The C names of the kinds by tag, for the message about a handle of another kind.
const KINDS: [(&[u8; 8], &str); 5] = [
    (b"adp-CTRL", "AdaptimpController"),
    (b"adpSTATE", "AdaptimpState"),
    (b"adpCHAIN", "AdaptimpChain"),
    (b"adpCARTE", "AdaptimpCartesian"),
    (b"adpCSTAT", "AdaptimpCartesianState"),
];

/// One slot of the table: the number of the handle that lives in it (0:
/// none) and its object's address.
struct Slot {
    live: AtomicUsize,
    object: AtomicPtr<Header>,
}

const CAPACITY: usize = ADAPTIMP_MAX_HANDLES;

// The table: 16 bytes a slot on a 64-bit target, in static memory.
static SLOTS: [Slot; CAPACITY] = [const {
    Slot {
        live: AtomicUsize::new(0),
        object: AtomicPtr::new(std::ptr::null_mut()),
    }
}; CAPACITY];

/// What creating and freeing handles share (behind a lock; lookups take none).
struct Book {
    /// Handles made so far: each gets the next, so a number is never given twice
    /// (but after 2^50 creations on a 64-bit target, 2^18 on a 32-bit one).
    made: usize,
    /// Where the search for a free slot starts (slots are used in turn).
    cursor: usize,
}

static BOOK: Mutex<Book> = Mutex::new(Book { made: 0, cursor: 0 });

fn book() -> std::sync::MutexGuard<'static, Book> {
    // Nothing panics while the lock is held; a poisoned lock is still consistent.
    BOOK.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The slot a handle's number names.
fn slot_of(id: usize) -> &'static Slot {
    &SLOTS[(id ^ MIX) & (CAPACITY - 1)]
}

/// Record the object at `o` (its header first) as a live handle of kind `T`:
/// its header filled in, its number returned as the handle the caller gets.
///
/// # Safety
/// `o` points to a valid object of `T`, at `place`, that stays valid until [`release`].
unsafe fn register<T: Handle>(o: *mut T::Object, place: Place) -> Result<*mut T, AdaptimpStatus> {
    let mut b = book();
    let Some(slot) = (0..CAPACITY)
        .map(|i| (b.cursor + i) % CAPACITY)
        .find(|&i| SLOTS[i].live.load(Ordering::Relaxed) == 0)
    else {
        return Err(fail(
            AdaptimpStatus::TooManyHandles,
            &format_args!(
                "{} handles are live (ADAPTIMP_MAX_HANDLES): free one before making another {}",
                CAPACITY,
                T::NAME
            ),
        ));
    };
    b.cursor = (slot + 1) % CAPACITY;
    let id = loop {
        b.made = b.made.wrapping_add(1);
        let id = ((b.made << SLOT_BITS) | slot) ^ MIX;
        if id != 0 {
            break id;
        }
    };
    // SAFETY: `o` is valid (the caller's contract) and not yet shared.
    let head = T::head(unsafe { &mut *o });
    head.tag = T::TAG;
    head.id = id;
    head.place = place;
    SLOTS[slot].object.store(o.cast(), Ordering::Relaxed);
    SLOTS[slot].live.store(id, Ordering::Release);
    Ok(std::ptr::without_provenance_mut(id))
}

/// Publish a heap object as a handle of kind `T` (freed again if the table is full).
pub(crate) fn publish<T: Handle>(o: Box<T::Object>) -> Result<*mut T, AdaptimpStatus> {
    let p = Box::into_raw(o);
    // SAFETY: a fresh box, valid until `free` takes it back.
    unsafe { register::<T>(p, Place::Heap) }.inspect_err(|_| {
        // SAFETY: from Box::into_raw just above, never published.
        drop(unsafe { Box::from_raw(p) });
    })
}

/// The bytes a caller buffer gives an object of kind `T` before its reals
/// (a multiple of 8, so the reals are aligned).
const fn head_bytes<T: Handle>() -> usize {
    std::mem::size_of::<T::Object>().next_multiple_of(8)
}

/// The alignment of a caller buffer for an object of kind `T`.
const fn align<T: Handle>() -> usize {
    let a = std::mem::align_of::<T::Object>();
    if a > 8 {
        a
    } else {
        8
    }
}

/// The size (bytes) and alignment of a caller buffer for an object of kind
/// `T` that works in `reals` reals: fixed for a controller and a build of
/// the library.
pub(crate) fn buffer_size<T: Handle>(reals: usize) -> Result<(usize, usize), AdaptimpStatus> {
    let size = reals
        .checked_mul(8)
        .and_then(|b| b.checked_add(head_bytes::<T>()))
        .ok_or_else(|| fail(AdaptimpStatus::BadSize, &"the state's size overflows"))?;
    Ok((size, align::<T>()))
}

/// Publish an object of kind `T` in the caller's buffer `buf` of `size`
/// bytes, no allocation: `make` builds it over the `reals` reals after its
/// place (zeroed first), and it is written at the start of `buf`. NULL_POINTER
/// for a NULL `buf`; BAD_SIZE for a buffer smaller or less aligned than
/// [`buffer_size`] says (`sizer` names the function that says it).
///
/// # Safety
/// `buf` is NULL or `size` writable bytes that nothing else uses while the
/// object lives, and that stay where they are until [`free`] (the caller's
/// promise).
pub(crate) unsafe fn publish_in<T: Handle>(
    buf: *mut c_void,
    size: usize,
    reals: usize,
    sizer: &str,
    make: impl FnOnce(Buf) -> Result<T::Object, AdaptimpStatus>,
) -> Result<*mut T, AdaptimpStatus> {
    if buf.is_null() {
        return Err(null("buf"));
    }
    let (need, align) = buffer_size::<T>(reals)?;
    let aligned = (buf as usize).is_multiple_of(align);
    if size < need || !aligned {
        return Err(fail(
            AdaptimpStatus::BadSize,
            &format_args!(
                "buf: {size} bytes at an address {} a multiple of {align}; a state of this controller needs {need} bytes aligned to {align} ({sizer})",
                if aligned { "that is" } else { "that is not" }
            ),
        ));
    }
    // SAFETY: `buf` holds `size` ≥ head_bytes + 8·reals writable bytes,
    // aligned for the object and for reals (the caller's contract, checked
    // above): the reals after the object's place are zeroed (so initialised)
    // before a slice is made, and the object is written once with `write`.
    // The slice and the object do not overlap; 'static is the caller's
    // promise that the buffer outlives the object.
    unsafe {
        let data = buf.cast::<u8>().add(head_bytes::<T>()).cast::<f64>();
        std::ptr::write_bytes(data, 0, reals);
        let data: &'static mut [f64] = std::slice::from_raw_parts_mut(data, reals);
        let o = make(Buf::Caller(data))?;
        let p = buf.cast::<T::Object>();
        p.write(o);
        register::<T>(p, Place::Caller).inspect_err(|_| p.drop_in_place())
    }
}

/// What the registry knows of a number given as a handle of kind `T`.
enum Lookup<O> {
    /// A live handle of kind `T`: its object.
    Live(*mut O),
    /// Not a live handle (never made, or freed).
    Dead,
    /// A live handle of another kind (its C name).
    OtherKind(&'static str),
    /// A live handle of a state in a caller's buffer in which a newer state
    /// was placed (without freeing this one): its object is gone.
    Overwritten,
}

/// Looks `p` up: reads nothing at `p`; reads the header of the live object
/// the registry holds for it.
fn lookup<T: Handle>(p: *const T) -> Lookup<T::Object> {
    let id = p.addr();
    let slot = slot_of(id);
    if id == 0 || slot.live.load(Ordering::Acquire) != id {
        return Lookup::Dead;
    }
    let o = slot.object.load(Ordering::Relaxed);
    // SAFETY: a live handle's object is valid (every kind's begins with its
    // header: `#[repr(C)]`, checked at compile time by `handle_kind!`).
    let head = unsafe { &*o };
    if head.tag != T::TAG {
        return Lookup::OtherKind(
            KINDS
                .iter()
                .find(|(tag, _)| u64::from_le_bytes(**tag) == head.tag)
                .map_or("handle of another kind", |(_, name)| *name),
        );
    }
    if head.id != id {
        return Lookup::Overwritten;
    }
    Lookup::Live(o.cast())
}

/// The object of a live handle `p` of kind `T`, or NULL_POINTER / BAD_HANDLE
/// naming `what`.
fn object<T: Handle>(p: *const T, what: &str) -> Result<*mut T::Object, AdaptimpStatus> {
    if p.is_null() {
        return Err(null(what));
    }
    match lookup(p) {
        Lookup::Live(o) => Ok(o),
        Lookup::OtherKind(kind) => Err(fail(
            AdaptimpStatus::BadHandle,
            &format_args!("{what} is a live {kind}, not an {}", T::NAME),
        )),
        Lookup::Dead | Lookup::Overwritten => Err(fail(
            AdaptimpStatus::BadHandle,
            &format_args!(
                "{what} is not a live {} (freed, never made, or another object)",
                T::NAME
            ),
        )),
    }
}

/// `&*p` for a live handle of kind `T`.
///
/// # Safety
/// No other thread frees `p` or uses it mutably during the call (the C contract).
pub(crate) unsafe fn handle<'a, T: Handle>(
    p: *const T,
    what: &str,
) -> Result<&'a T::Object, AdaptimpStatus> {
    // SAFETY: a live object; no concurrent mutation (the caller's contract).
    object(p, what).map(|o| unsafe { &*o })
}

/// `&mut *p` for a live handle of kind `T`.
///
/// # Safety
/// No other thread frees or uses `p` during the call (the C contract).
pub(crate) unsafe fn handle_mut<'a, T: Handle>(
    p: *mut T,
    what: &str,
) -> Result<&'a mut T::Object, AdaptimpStatus> {
    // SAFETY: a live object, used by this call alone (the caller's contract).
    object(p, what).map(|o| unsafe { &mut *o })
}

/// Remove a live handle from the table (its number is refused from now on)
/// and clear its object's tag; the object, still valid, is returned for the
/// caller to drop (NULL and dead handles: None, a dead one's message recorded).
pub(crate) fn release<T: Handle>(p: *mut T, what: &str) -> Option<*mut T::Object> {
    if p.is_null() {
        return None;
    }
    let _b = book();
    let slot = slot_of(p.addr());
    let o = match lookup(p) {
        Lookup::Live(o) => o,
        Lookup::Overwritten => {
            // Its object is gone (a newer state has the memory): the slot
            // is given back, nothing is dropped.
            slot.live.store(0, Ordering::Release);
            slot.object.store(std::ptr::null_mut(), Ordering::Relaxed);
            return None;
        }
        Lookup::Dead | Lookup::OtherKind(_) => {
            // Recorded as the last error; nothing to free.
            let _ = object(p, what);
            return None;
        }
    };
    slot.live.store(0, Ordering::Release);
    slot.object.store(std::ptr::null_mut(), Ordering::Relaxed);
    // SAFETY: live until now, and no longer reachable through the table.
    T::head(unsafe { &mut *o }).tag = 0;
    Some(o)
}

/// Free a handle (NULL and dead ones ignored; a dead one records a
/// message): a heap object's memory is freed; one in a caller's buffer
/// ends its life, and the buffer is the caller's again.
///
/// # Safety
/// `p` is NULL or any pointer; if live, no other thread uses it during the call.
pub(crate) unsafe fn free<T: Handle>(p: *mut T, what: &str) {
    if let Some(o) = release(p, what) {
        // SAFETY: live until `release`, now unreachable by its handle: a
        // heap one came from Box::into_raw in `publish`, released once; one
        // in a caller's buffer is dropped in place (its reals are the
        // caller's, it owns no other memory).
        unsafe {
            if T::head(&mut *o).place == Place::Heap {
                drop(Box::from_raw(o));
            } else {
                o.drop_in_place();
            }
        }
    }
}
