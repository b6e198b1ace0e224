//! MuJoCo driven from Rust at run time, for adaptimp's native MuJoCo loop.
//!
//! Nothing links against MuJoCo at build time (it is an optional extra of
//! adaptimp): [`Library`] opens the engine's C library where the `mujoco`
//! Python package installed it — the library that package has already
//! loaded, so the same code and the same global state — and resolves the few
//! functions a closed loop needs (`mj_step`, `mj_forward`, `mj_forwardSkip`,
//! `mj_checkPos`, `mj_checkVel`, `mj_checkAcc`, `mj_Euler`, `mj_RungeKutta`,
//! `mj_implicit`, `mj_getState`, `mj_jacSite`, `mj_jacBody`,
//! `mj_rnePostConstraint`, `mju_warningText`, `mj_version`). [`Sim`] is a
//! handle on one `mjModel` and its `mjData` whose arrays (`qpos`, `qvel`,
//! `qacc`, `ctrl`, `qfrc_applied`, `sensordata`, `site_xpos`, `site_xmat`,
//! `xpos`, `subtree_com`, `cfrc_ext`, the warning counters) are reached
//! through the addresses the Python objects give (NumPy views of MuJoCo's
//! own memory), never through `mjData`'s struct layout, which changes
//! between MuJoCo versions. (So the contact list, `d->contact`, which lives
//! in MuJoCo's per-step arena behind a pointer and a count of `mjData`'s
//! own, is not read: the contact forces on a body are read from `cfrc_ext`,
//! which `mj_rnePostConstraint` fills from that list.)
//!
//! Everything `unsafe` of adaptimp's MuJoCo support is in this crate, each
//! block with its invariant. The API is safe: `Sim::from_python` (feature
//! `python`) checks the objects it is given and keeps them alive; a `Sim` is
//! the only user of its `mjData` while it exists (a process-wide lease), so
//! runs on distinct data go in parallel threads (MuJoCo's functions are
//! re-entrant on distinct `mjData`; no global callback such as `mjcb_control`
//! is used).
//!
//! MuJoCo reports a fatal error through `mju_error`, whose default handler
//! ends the process. On opening the library this crate installs a handler in
//! `mju_user_error` if none is set: inside a [`Sim`] call it unwinds back to
//! that call, which returns [`Error::Fatal`] with MuJoCo's message (the
//! engine's C frames have unwind tables and no cleanup to run); anywhere
//! else it prints the message and exits as MuJoCo's default does.

use std::cell::Cell;
use std::collections::HashSet;
use std::ffi::{c_char, c_int, c_void, CStr};
use std::fmt;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

#[cfg(feature = "python")]
mod python;

/// An error of this crate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Error {
    /// The library or one of its functions could not be loaded, or the
    /// objects given are not what they must be.
    Load(String),
    /// MuJoCo raised a fatal error (`mju_error`) with this message.
    Fatal(String),
    /// The `mjData` is in use by another [`Sim`].
    Busy,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Load(m) => write!(f, "cannot drive MuJoCo: {m}"),
            Error::Fatal(m) => write!(f, "MuJoCo error: {m}"),
            Error::Busy => f.write_str(
                "this MuJoCo data is in use by another run (give each thread its own Plant)",
            ),
        }
    }
}

impl std::error::Error for Error {}

// ---------------------------------------------------------------------------
// The library.
// ---------------------------------------------------------------------------

type ModelP = *const c_void;
type DataP = *mut c_void;
// "C-unwind": MuJoCo's fatal errors unwind through these calls (see the crate doc).
type StepFn = unsafe extern "C-unwind" fn(ModelP, DataP);
type SkipFn = unsafe extern "C-unwind" fn(ModelP, DataP, c_int, c_int);
type RkFn = unsafe extern "C-unwind" fn(ModelP, DataP, c_int);
type StateFn = unsafe extern "C-unwind" fn(ModelP, *const c_void, *mut f64, c_int);
type JacFn = unsafe extern "C-unwind" fn(ModelP, *const c_void, *mut f64, *mut f64, c_int);
type TextFn = unsafe extern "C-unwind" fn(c_int, usize) -> *const c_char;
type VersionFn = unsafe extern "C-unwind" fn() -> c_int;
type Handler = Option<unsafe extern "C-unwind" fn(*const c_char)>;

/// mjtStage: `mjSTAGE_VEL` (mjtype.h), the stage `mj_forwardSkip` skips to.
const STAGE_VEL: c_int = 2;
/// mjtStage: `mjSTAGE_NONE` (mjtype.h): `mj_forwardSkip` skips nothing.
const STAGE_NONE: c_int = 0;
/// mjtState: `mjSTATE_TIME` (mjtype.h).
const STATE_TIME: c_int = 1;

/// The MuJoCo C library, opened at run time, with the functions a loop uses.
pub struct Library {
    path: PathBuf,
    version: i32,
    step: StepFn,
    forward: StepFn,
    forward_skip: SkipFn,
    check_pos: StepFn,
    check_vel: StepFn,
    check_acc: StepFn,
    euler: StepFn,
    runge_kutta: RkFn,
    implicit: StepFn,
    get_state: StateFn,
    jac_site: JacFn,
    jac_body: JacFn,
    rne_post_constraint: StepFn,
    warning_text: TextFn,
    // Kept open for as long as the function pointers above are used.
    _lib: libloading::Library,
}

impl fmt::Debug for Library {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Library")
            .field("path", &self.path)
            .field("version", &self.version)
            .finish()
    }
}

/// The libraries opened so far (a process opens MuJoCo once).
static LIBRARIES: Mutex<Vec<Arc<Library>>> = Mutex::new(Vec::new());

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Library {
    /// Open the MuJoCo library at `path` (once per process; later calls with
    /// the same path share it) and resolve its functions.
    ///
    /// # Safety
    ///
    /// `path` must be a MuJoCo C library (`libmujoco.so.*`, `libmujoco.*.dylib`,
    /// `mujoco.dll`) whose exported functions have the signatures of
    /// `mujoco.h` 3.x–4.x for the functions listed in the crate doc: loading
    /// runs its initialisers and the symbols are called with those types.
    pub unsafe fn open(path: &Path) -> Result<Arc<Library>, Error> {
        let mut libs = lock(&LIBRARIES);
        if let Some(l) = libs.iter().find(|l| l.path == path) {
            return Ok(l.clone());
        }
        let err = |e: libloading::Error| Error::Load(format!("{}: {e}", path.display()));
        // SAFETY: the caller guarantees a MuJoCo library; opening one that the
        // Python package already loaded returns that same instance.
        let lib = unsafe { libloading::Library::new(path) }.map_err(err)?;
        macro_rules! sym {
            ($name:literal, $ty:ty) => {{
                // SAFETY: the symbol has this signature in mujoco.h (caller's guarantee).
                let s: libloading::Symbol<'_, $ty> = unsafe { lib.get($name) }.map_err(err)?;
                *s
            }};
        }
        let version_fn = sym!(b"mj_version\0", VersionFn);
        let step = sym!(b"mj_step\0", StepFn);
        let forward = sym!(b"mj_forward\0", StepFn);
        let forward_skip = sym!(b"mj_forwardSkip\0", SkipFn);
        let check_pos = sym!(b"mj_checkPos\0", StepFn);
        let check_vel = sym!(b"mj_checkVel\0", StepFn);
        let check_acc = sym!(b"mj_checkAcc\0", StepFn);
        let euler = sym!(b"mj_Euler\0", StepFn);
        let runge_kutta = sym!(b"mj_RungeKutta\0", RkFn);
        let implicit = sym!(b"mj_implicit\0", StepFn);
        let get_state = sym!(b"mj_getState\0", StateFn);
        let jac_site = sym!(b"mj_jacSite\0", JacFn);
        let jac_body = sym!(b"mj_jacBody\0", JacFn);
        let rne_post_constraint = sym!(b"mj_rnePostConstraint\0", StepFn);
        let warning_text = sym!(b"mju_warningText\0", TextFn);
        // SAFETY: `mju_user_error` is the global `void (*)(const char*)` of
        // mujoco.h. It is read and written here only, under LIBRARIES' lock,
        // and set only if nobody has set it (MuJoCo then reads it in mju_error).
        unsafe {
            let slot: libloading::Symbol<'_, *mut Handler> =
                lib.get(b"mju_user_error\0").map_err(err)?;
            let slot: *mut Handler = *slot;
            if (*slot).is_none() {
                *slot = Some(on_error);
            }
        }
        // SAFETY: `int mj_version(void)`, no preconditions.
        let version = unsafe { version_fn() };
        let l = Arc::new(Library {
            path: path.to_path_buf(),
            version,
            step,
            forward,
            forward_skip,
            check_pos,
            check_vel,
            check_acc,
            euler,
            runge_kutta,
            implicit,
            get_state,
            jac_site,
            jac_body,
            rne_post_constraint,
            warning_text,
            _lib: lib,
        });
        libs.push(l.clone());
        Ok(l)
    }

    /// MuJoCo's version number, `mj_version()` (e.g. 400 for 4.0.0).
    pub fn version(&self) -> i32 {
        self.version
    }

    /// The path it was opened from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// MuJoCo's text for warning `warning` with its `info`
    /// (`mju_warningText`), e.g. "Nan, Inf or huge value in QACC at DOF 2.
    /// The simulation is unstable.".
    pub fn warning_text(&self, warning: usize, info: i32) -> String {
        let Ok(w) = c_int::try_from(warning) else {
            return format!("warning {warning}");
        };
        // SAFETY: mju_warningText returns a pointer to a static or
        // thread-local buffer holding a NUL-terminated string, for any input.
        unsafe {
            let p = (self.warning_text)(w, usize::try_from(info).unwrap_or(0));
            if p.is_null() {
                format!("warning {warning}")
            } else {
                CStr::from_ptr(p).to_string_lossy().into_owned()
            }
        }
    }
}

thread_local! {
    /// True while this thread is inside a guarded MuJoCo call.
    static GUARDED: Cell<bool> = const { Cell::new(false) };
}

/// The panic payload that carries `mju_error`'s message back to the call.
struct FatalPayload(String);

/// The handler in `mju_user_error` (see the crate doc).
unsafe extern "C-unwind" fn on_error(msg: *const c_char) {
    let text = if msg.is_null() {
        String::from("(no message)")
    } else {
        // SAFETY: mju_error passes a NUL-terminated message buffer.
        unsafe { CStr::from_ptr(msg) }
            .to_string_lossy()
            .into_owned()
    };
    if GUARDED.with(Cell::get) {
        // Unwinds through MuJoCo's C frames (plain frames with unwind
        // tables, nothing to clean up) back to `guarded`. resume_unwind does
        // not run the panic hook: nothing is printed.
        resume_unwind(Box::new(FatalPayload(text)));
    }
    // Not inside one of our calls: MuJoCo's default behaviour.
    eprintln!("ERROR: {text}");
    std::process::exit(1);
}

/// Run `f` (a call into MuJoCo) so that a fatal MuJoCo error returns
/// [`Error::Fatal`] instead of ending the process.
fn guarded<R>(f: impl FnOnce() -> R) -> Result<R, Error> {
    let outer = GUARDED.with(|g| g.replace(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    GUARDED.with(|g| g.set(outer));
    match result {
        Ok(r) => Ok(r),
        Err(payload) => match payload.downcast::<FatalPayload>() {
            Ok(fatal) => Err(Error::Fatal(fatal.0)),
            Err(other) => resume_unwind(other),
        },
    }
}

// ---------------------------------------------------------------------------
// One model and its data.
// ---------------------------------------------------------------------------

/// An array of `f64` in MuJoCo's memory.
#[derive(Copy, Clone, Debug)]
pub struct Span {
    /// First element (any value if `len` is 0).
    pub ptr: *mut f64,
    /// Number of elements.
    pub len: usize,
}

/// The warning counters `mjData.warning[i].number` and `.lastinfo`
/// (`mjWarningStat`: two ints, `stride` bytes apart from one warning to the next).
#[derive(Copy, Clone, Debug)]
pub struct Warnings {
    /// `&warning[0].number`.
    pub number: *const c_int,
    /// `&warning[0].lastinfo`.
    pub lastinfo: *const c_int,
    /// Bytes from one warning's fields to the next's.
    pub stride: usize,
    /// Number of warnings (`mjNWARNING`), at most [`MAX_WARNINGS`].
    pub count: usize,
}

/// The most warning kinds a [`Sim`] reads (MuJoCo 4 has 7).
pub const MAX_WARNINGS: usize = 16;

/// The addresses a [`Sim`] is made of.
#[derive(Copy, Clone, Debug)]
pub struct RawParts {
    /// `const mjModel*`.
    pub model: *const c_void,
    /// `mjData*` of that model.
    pub data: *mut c_void,
    /// `d->qpos` (nq).
    pub qpos: Span,
    /// `d->qvel` (nv).
    pub qvel: Span,
    /// `d->qacc` (nv).
    pub qacc: Span,
    /// `d->ctrl` (nu).
    pub ctrl: Span,
    /// `d->qfrc_applied` (nv).
    pub qfrc_applied: Span,
    /// `d->sensordata` (nsensordata).
    pub sensordata: Span,
    /// `d->site_xpos` (3 nsite).
    pub site_xpos: Span,
    /// `d->site_xmat` (9 nsite).
    pub site_xmat: Span,
    /// `d->xpos` (3 nbody).
    pub xpos: Span,
    /// `d->subtree_com` (3 nbody).
    pub subtree_com: Span,
    /// `d->cfrc_ext` (6 nbody).
    pub cfrc_ext: Span,
    /// `d->userdata` (nuserdata): the user's, never written by MuJoCo's steps.
    pub userdata: Span,
    /// `d->warning`.
    pub warnings: Warnings,
    /// `m->nv`.
    pub nv: usize,
}

/// The data addresses in use by a [`Sim`].
static LEASES: Mutex<Option<HashSet<usize>>> = Mutex::new(None);

/// The lease of one `mjData`: taken on construction, given back on drop.
#[derive(Debug)]
struct Lease(usize);

impl Lease {
    fn take(data: *mut c_void) -> Result<Self, Error> {
        let key = data as usize;
        let mut set = lock(&LEASES);
        if !set.get_or_insert_with(HashSet::new).insert(key) {
            return Err(Error::Busy);
        }
        Ok(Lease(key))
    }
}

impl Drop for Lease {
    fn drop(&mut self) {
        if let Some(set) = lock(&LEASES).as_mut() {
            set.remove(&self.0);
        }
    }
}

/// A handle on one `mjModel` and its `mjData`: the calls of a closed loop.
///
/// Safe to use: its parts were checked when it was made (see
/// [`Sim::from_raw`]), whoever owns the memory is kept alive in `owner`, and
/// it holds the only lease on the data.
pub struct Sim {
    lib: Arc<Library>,
    p: RawParts,
    jacp: Vec<f64>,
    jacr: Vec<f64>,
    _lease: Lease,
    _owner: Box<dyn Send>,
}

impl fmt::Debug for Sim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Sim")
            .field("lib", &self.lib)
            .field("nv", &self.p.nv)
            .finish_non_exhaustive()
    }
}

// SAFETY: a Sim is the only user of its mjData (the lease) and reads its
// mjModel only; MuJoCo's functions are re-entrant for distinct mjData and use
// no thread-affine state, so a Sim may move to another thread. It is not
// Sync: its calls take &mut self where they write.
unsafe impl Send for Sim {}

impl Sim {
    /// A handle from raw addresses. `owner` is kept until the handle is
    /// dropped (whatever keeps the memory alive).
    ///
    /// # Safety
    ///
    /// `lib` is the library `model` and `data` were made by; `data` was made
    /// for `model`; every [`Span`] points into `data`'s memory with the
    /// length of that `mjData` field for `model` (`qpos`: nq, `qvel`, `qacc`,
    /// `qfrc_applied`: nv, `ctrl`: nu, `sensordata`: nsensordata, `site_xpos`:
    /// 3 nsite, `site_xmat`: 9 nsite, `xpos`, `subtree_com`: 3 nbody,
    /// `cfrc_ext`: 6 nbody, `userdata`: nuserdata), `warnings` addresses
    /// `data`'s warning counters and `nv` is `model`'s; all of it stays valid
    /// while `owner` lives, and nothing else writes to `data` or `model` while
    /// the handle exists.
    pub unsafe fn from_raw(
        lib: Arc<Library>,
        p: RawParts,
        owner: Box<dyn Send>,
    ) -> Result<Self, Error> {
        if p.warnings.count > MAX_WARNINGS {
            return Err(Error::Load(format!(
                "{} warning kinds, at most {MAX_WARNINGS} supported",
                p.warnings.count
            )));
        }
        let lease = Lease::take(p.data)?;
        Ok(Self {
            lib,
            jacp: vec![0.0; 3 * p.nv],
            jacr: vec![0.0; 3 * p.nv],
            p,
            _lease: lease,
            _owner: owner,
        })
    }

    /// The library.
    pub fn library(&self) -> &Library {
        &self.lib
    }

    /// Degrees of freedom nv.
    pub fn nv(&self) -> usize {
        self.p.nv
    }

    fn slice(&self, s: Span) -> &[f64] {
        if s.len == 0 {
            return &[];
        }
        // SAFETY: from_raw's contract: `s` is a live field of the data with
        // this length, written by no one else while `self` is borrowed (every
        // call that makes MuJoCo write takes &mut self).
        unsafe { std::slice::from_raw_parts(s.ptr, s.len) }
    }

    fn slice_mut(&mut self, s: Span) -> &mut [f64] {
        if s.len == 0 {
            return &mut [];
        }
        // SAFETY: as `slice`, and &mut self makes this the only reference.
        unsafe { std::slice::from_raw_parts_mut(s.ptr, s.len) }
    }

    /// `qpos` (nq).
    pub fn qpos(&self) -> &[f64] {
        self.slice(self.p.qpos)
    }
    /// `qvel` (nv).
    pub fn qvel(&self) -> &[f64] {
        self.slice(self.p.qvel)
    }
    /// `qacc` (nv) of the last forward computation.
    pub fn qacc(&self) -> &[f64] {
        self.slice(self.p.qacc)
    }
    /// `sensordata`.
    pub fn sensordata(&self) -> &[f64] {
        self.slice(self.p.sensordata)
    }
    /// `site_xpos` (3 per site).
    pub fn site_xpos(&self) -> &[f64] {
        self.slice(self.p.site_xpos)
    }
    /// `site_xmat` (9 per site, row-major).
    pub fn site_xmat(&self) -> &[f64] {
        self.slice(self.p.site_xmat)
    }
    /// `xpos` (3 per body).
    pub fn xpos(&self) -> &[f64] {
        self.slice(self.p.xpos)
    }
    /// `subtree_com` (3 per body): the centre of mass of each body's subtree.
    pub fn subtree_com(&self) -> &[f64] {
        self.slice(self.p.subtree_com)
    }
    /// `cfrc_ext` (6 per body, [torque; force] about the `subtree_com` of
    /// the body's root, world frame) of the last [`Sim::rne_post_constraint`].
    pub fn cfrc_ext(&self) -> &[f64] {
        self.slice(self.p.cfrc_ext)
    }
    /// `ctrl` (nu), writable.
    pub fn ctrl_mut(&mut self) -> &mut [f64] {
        self.slice_mut(self.p.ctrl)
    }
    /// `qfrc_applied` (nv), writable.
    pub fn qfrc_applied_mut(&mut self) -> &mut [f64] {
        self.slice_mut(self.p.qfrc_applied)
    }
    /// The length of `userdata` (nuserdata).
    pub fn userdata_len(&self) -> usize {
        self.p.userdata.len
    }
    /// `userdata` (nuserdata), writable: MuJoCo's steps leave it alone, so a
    /// loop may keep what it finds there for the caller to read afterwards.
    pub fn userdata_mut(&mut self) -> &mut [f64] {
        self.slice_mut(self.p.userdata)
    }

    /// `mj_step`: one timestep.
    pub fn step(&mut self) -> Result<(), Error> {
        let (f, m, d) = (self.lib.step, self.p.model, self.p.data);
        // SAFETY: model and data are a live pair (from_raw), used by us only.
        guarded(|| unsafe { f(m, d) })
    }

    /// `mj_step` whose forward computation at the current state and
    /// controls is already done (`mj_forward`, or `mj_forwardSkip` after a
    /// change of the controls only): `mj_checkPos`, `mj_checkVel` (if they
    /// warn, a full `mj_forward` as `mj_step` would then compute),
    /// `mj_checkAcc` and the model's `integrator` (`mjtIntegrator`: 0 Euler,
    /// 1 RK4, 2 implicit, 3 implicitfast). The same state as `mj_step`, one
    /// forward computation fewer.
    pub fn step_computed(&mut self, integrator: i32) -> Result<(), Error> {
        let (before, _) = self.warnings();
        let l = &self.lib;
        let (m, d) = (self.p.model, self.p.data);
        // SAFETY: model and data are a live pair (from_raw), used by us only.
        guarded(|| unsafe {
            (l.check_pos)(m, d);
            (l.check_vel)(m, d);
        })?;
        if self.warnings().0 != before {
            self.forward()?;
        }
        let l = &self.lib;
        // SAFETY: as above; the integrator functions take the computed data.
        guarded(|| unsafe {
            (l.check_acc)(m, d);
            match integrator {
                0 => (l.euler)(m, d),
                1 => (l.runge_kutta)(m, d, 4),
                _ => (l.implicit)(m, d),
            }
        })
    }

    /// `mj_step` without the sensors of its forward computation: what
    /// `mj_step` does (`mj_checkPos`, `mj_checkVel`, the forward
    /// computation, `mj_checkAcc`, the model's `integrator` as in
    /// [`Sim::step_computed`]) with the forward computation
    /// `mj_forwardSkip(m, d, mjSTAGE_NONE, 1)`. The same state as `mj_step`
    /// when the model's sensors are pure functions of the state (no noise,
    /// history, delay or interval, no user or plugin sensors): only
    /// `sensordata` (and what the acceleration sensors leave in `cacc`,
    /// `cfrc_int`, `cfrc_ext`) is not brought up to date.
    pub fn step_without_sensors(&mut self, integrator: i32) -> Result<(), Error> {
        let l = &self.lib;
        let (m, d) = (self.p.model, self.p.data);
        // SAFETY: model and data are a live pair (from_raw), used by us only.
        guarded(|| unsafe {
            (l.check_pos)(m, d);
            (l.check_vel)(m, d);
            (l.forward_skip)(m, d, STAGE_NONE, 1);
            (l.check_acc)(m, d);
            match integrator {
                0 => (l.euler)(m, d),
                1 => (l.runge_kutta)(m, d, 4),
                _ => (l.implicit)(m, d),
            }
        })
    }

    /// `mj_forward`: everything at the current state and controls.
    pub fn forward(&mut self) -> Result<(), Error> {
        let (f, m, d) = (self.lib.forward, self.p.model, self.p.data);
        // SAFETY: as `step`.
        guarded(|| unsafe { f(m, d) })
    }

    /// `mj_forwardSkip(m, d, mjSTAGE_VEL, 1)`: the actuation and acceleration
    /// stages only (positions and velocities unchanged since the last
    /// forward computation; sensors not recomputed): `qacc` for new controls.
    pub fn forward_acceleration(&mut self) -> Result<(), Error> {
        let (f, m, d) = (self.lib.forward_skip, self.p.model, self.p.data);
        // SAFETY: as `step`.
        guarded(|| unsafe { f(m, d, STAGE_VEL, 1) })
    }

    /// `mj_rnePostConstraint`: the external forces on every body (`cfrc_ext`:
    /// the contacts' and the equality constraints' forces, and
    /// `xfrc_applied`) at the last forward computation, with `cacc` and
    /// `cfrc_int`. Changes nothing a later step reads.
    pub fn rne_post_constraint(&mut self) -> Result<(), Error> {
        let (f, m, d) = (self.lib.rne_post_constraint, self.p.model, self.p.data);
        // SAFETY: as `step`.
        guarded(|| unsafe { f(m, d) })
    }

    /// The simulation time `d->time` (s), through `mj_getState`.
    pub fn time(&self) -> f64 {
        let mut t = [0.0f64; 1];
        let (f, m, d) = (self.lib.get_state, self.p.model, self.p.data);
        // SAFETY: mjSTATE_TIME has size 1 (mj_stateSize): one value written.
        let _ = guarded(|| unsafe { f(m, d, t.as_mut_ptr(), STATE_TIME) });
        t[0]
    }

    /// The warning counters: (number, lastinfo) of each kind.
    pub fn warnings(&self) -> ([(i32, i32); MAX_WARNINGS], usize) {
        let w = self.p.warnings;
        let mut out = [(0, 0); MAX_WARNINGS];
        for (i, o) in out.iter_mut().enumerate().take(w.count) {
            // SAFETY: from_raw's contract: `count` mjWarningStat `stride`
            // bytes apart in the live data; read-only.
            unsafe {
                let n = w.number.byte_add(i * w.stride).read();
                let l = w.lastinfo.byte_add(i * w.stride).read();
                *o = (n, l);
            }
        }
        (out, w.count)
    }

    /// `mj_jacSite` (`by_site`) or `mj_jacBody`: the translational and
    /// rotational Jacobians of site or body `id`, each 3 × nv row-major.
    pub fn jacobian(&mut self, by_site: bool, id: usize) -> Result<(&[f64], &[f64]), Error> {
        let (f, count) = if by_site {
            (self.lib.jac_site, self.p.site_xpos.len / 3)
        } else {
            (self.lib.jac_body, self.p.xpos.len / 3)
        };
        let id = match c_int::try_from(id) {
            Ok(i) if id < count => i,
            _ => {
                let what = if by_site { "site" } else { "body" };
                return Err(Error::Load(format!(
                    "no {what} {id} (the model has {count})"
                )));
            }
        };
        let (m, d) = (self.p.model, self.p.data);
        let (jp, jr) = (self.jacp.as_mut_ptr(), self.jacr.as_mut_ptr());
        // SAFETY: jacp and jacr hold 3 nv values each, what MuJoCo writes.
        guarded(|| unsafe { f(m, d, jp, jr, id) })?;
        Ok((&self.jacp, &self.jacr))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_lease_per_data_until_it_is_given_back() {
        let mut a = 0u8;
        let data = (&mut a as *mut u8).cast::<c_void>();
        let first = Lease::take(data).expect("free");
        assert_eq!(Lease::take(data).unwrap_err(), Error::Busy);
        drop(first);
        let again = Lease::take(data).expect("given back");
        drop(again);
    }

    #[test]
    fn a_fatal_error_returns_and_other_panics_go_on() {
        // What `on_error` does inside a guarded call.
        let r: Result<(), Error> = guarded(|| resume_unwind(Box::new(FatalPayload("boom".into()))));
        assert_eq!(r, Err(Error::Fatal("boom".into())));
        assert!(!GUARDED.with(Cell::get));
        assert_eq!(guarded(|| 7), Ok(7));
        let other = catch_unwind(|| guarded(|| resume_unwind(Box::new(3_i32))));
        assert_eq!(
            *other
                .unwrap_err()
                .downcast::<i32>()
                .expect("the same payload"),
            3
        );
        assert!(!GUARDED.with(Cell::get));
    }
}
