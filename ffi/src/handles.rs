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

/// The first field of every object behind a handle (`#[repr(C)]`, so at
/// offset 0 whatever the kind: reading it is valid for any live object).
#[repr(C)]
#[derive(Debug)]
pub(crate) struct Header {
    /// The kind's tag ([`Handle::TAG`]); zero once freed.
    tag: u64,
    /// The number of the handle this object was published under.
    id: usize,
}

impl Header {
    /// A header to be filled in when the object is published.
    pub(crate) const fn unpublished() -> Self {
        Self { tag: 0, id: 0 }
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
/// `o` points to a valid object of `T` that stays valid until [`release`].
unsafe fn register<T: Handle>(o: *mut T::Object) -> Result<*mut T, AdaptimpStatus> {
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
    SLOTS[slot].object.store(o.cast(), Ordering::Relaxed);
    SLOTS[slot].live.store(id, Ordering::Release);
    Ok(std::ptr::without_provenance_mut(id))
}

/// Publish a heap object as a handle of kind `T` (freed again if the table is full).
pub(crate) fn publish<T: Handle>(o: Box<T::Object>) -> Result<*mut T, AdaptimpStatus> {
    let p = Box::into_raw(o);
    // SAFETY: a fresh box, valid until `free` takes it back.
    unsafe { register::<T>(p) }.inspect_err(|_| {
        // SAFETY: from Box::into_raw just above, never published.
        drop(unsafe { Box::from_raw(p) });
    })
}

/// Publish an object the caller's buffer holds (written there) as a handle of kind `T`.
///
/// # Safety
/// `o` points to a valid object that stays where it is until [`release`] (the caller's promise).
pub(crate) unsafe fn publish_at<T: Handle>(o: *mut T::Object) -> Result<*mut T, AdaptimpStatus> {
    // SAFETY: the caller's contract.
    unsafe { register::<T>(o) }
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

/// Free a heap handle (NULL and dead ones ignored; a dead one records a message).
///
/// # Safety
/// `p` is NULL or any pointer; if live, it was published with [`publish`]
/// and no other thread uses it during the call.
pub(crate) unsafe fn free<T: Handle>(p: *mut T, what: &str) {
    if let Some(o) = release(p, what) {
        // SAFETY: from Box::into_raw in `publish`, released once.
        drop(unsafe { Box::from_raw(o) });
    }
}
