//! Robot descriptions in C (SPEC §21): a URDF file or URDF text to a chain,
//! by the core's one reduction (the arm Python's `adaptimp.Chain.from_urdf`
//! and `adaptimp.mujoco.from_urdf` read from the same file). Every decision
//! is the core's (`adaptimp::description`); this converts strings and
//! checks pointers.

use crate::cartesian::{chain_error, publish_chain, AdaptimpChain};
use crate::*;
use adaptimp::description::{self, urdf, DescriptionError};
use adaptimp::dynamic::Chain;
use core::ffi::{c_char, CStr};

/// What the core read of the arm beside its chain (SPEC §21), per arm joint
/// in the order of q (base to tip); entries from `n` on are 0.
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpArmInfo {
    /// The arm's joints n (the chain's).
    pub n: usize,
    /// Whether each joint is prismatic (m, N) rather than revolute (rad, N m).
    pub prismatic: [AdaptimpBoolRaw; ADAPTIMP_MAX_JOINTS],
    /// Lower position limits (rad or m); -INFINITY for an unlimited joint.
    pub lower: [f64; ADAPTIMP_MAX_JOINTS],
    /// Upper position limits (rad or m); INFINITY for an unlimited joint.
    pub upper: [f64; ADAPTIMP_MAX_JOINTS],
    /// The URDF's effort limits (N m or N); NAN where it states none.
    pub effort: [f64; ADAPTIMP_MAX_JOINTS],
    /// The URDF's velocity limits (rad/s or m/s); NAN where it states none.
    pub velocity: [f64; ADAPTIMP_MAX_JOINTS],
    /// Viscous damping (N m s/rad), the URDF's `<dynamics damping>`; 0 if none.
    pub damping: [f64; ADAPTIMP_MAX_JOINTS],
    /// Dry friction (N m), the URDF's `<dynamics friction>`; 0 if none.
    pub friction: [f64; ADAPTIMP_MAX_JOINTS],
}

/// A C string argument as UTF-8 (NULL: None).
///
/// # Safety
/// A non-NULL `p` points to a NUL-terminated string.
unsafe fn text<'a>(p: *const c_char, what: &str) -> Result<Option<&'a str>, AdaptimpStatus> {
    if p.is_null() {
        return Ok(None);
    }
    // SAFETY: non-NULL and NUL-terminated: the caller's contract.
    let s = unsafe { CStr::from_ptr(p) };
    s.to_str().map(Some).map_err(|_| {
        fail(
            AdaptimpStatus::InvalidConfig,
            &format_args!("{what} is not UTF-8 text"),
        )
    })
}

/// A reader's error (every kind: the file, the element, what to do) as INVALID_CONFIG.
fn described(e: DescriptionError) -> AdaptimpStatus {
    fail(AdaptimpStatus::InvalidConfig, &e)
}

/// The chain of the arm of a URDF into `*out` (free it with
/// `adaptimp_chain_free`), read and reduced by
/// the core (SPEC §21): `source` is the path of a URDF file or, if its first
/// non-blank character is '<', URDF text; `tip` the link that ends the arm
/// (NULL: the arm the rule finds, to its last joint's link); `fix` `nfix`
/// joint names to hold (NULL if `nfix` is 0). With `info` non-NULL, the
/// arm's limits, efforts and drive terms are written there.
///
/// Statuses: INVALID_CONFIG with a message that names the file, the element
/// and what to do (a file that cannot be read, xacro, a URDF the parser
/// refuses, a missing link, a loop, an unknown tip or fix name, chains that
/// tie for the arm, no joint to drive); BAD_SIZE for an arm of more than 7
/// joints (hold some with `fix`); NULL_POINTER for a NULL `source` or `out`.
///
/// # Safety
/// `source`, `tip` are NULL or NUL-terminated strings; `fix` is NULL or holds
/// `nfix` NUL-terminated strings; `out` and `info` are NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_chain_from_urdf(
    source: *const c_char,
    tip: *const c_char,
    fix: *const *const c_char,
    nfix: usize,
    out: *mut *mut AdaptimpChain,
    info: *mut AdaptimpArmInfo,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let source = unsafe { text(source, "source") }?.ok_or_else(|| {
            fail(
                AdaptimpStatus::NullPointer,
                &"source is NULL: give a URDF path or URDF text",
            )
        })?;
        let tip = unsafe { text(tip, "tip") }?;
        let names = if nfix == 0 {
            &[][..]
        } else {
            unsafe { slice(fix, nfix, "fix") }?
        };
        let mut fixed = Vec::with_capacity(nfix);
        for (i, &p) in names.iter().enumerate() {
            let name = unsafe { text(p, &format!("fix[{i}]")) }?.ok_or_else(|| {
                fail(
                    AdaptimpStatus::NullPointer,
                    &format_args!("fix[{i}] is NULL"),
                )
            })?;
            fixed.push(name);
        }
        let out = unsafe { crate::out(out, "out") }?;
        let tree = if urdf::is_text(source) {
            urdf::read_str(source)
        } else {
            urdf::read_file(source)
        }
        .map_err(described)?;
        let arm = description::reduce(&tree, tip, &fixed).map_err(described)?;
        arm.within(ADAPTIMP_MAX_JOINTS)
            .map_err(|e| fail(AdaptimpStatus::BadSize, &e))?;
        *out = publish_chain(Chain::from_arm(&arm).map_err(chain_error)?)?;
        if !info.is_null() {
            // SAFETY: non-NULL and valid: the caller's contract.
            let info = unsafe { crate::out(info, "info") }?;
            let mut filled = AdaptimpArmInfo {
                n: arm.n(),
                prismatic: [AdaptimpBoolRaw(0); ADAPTIMP_MAX_JOINTS],
                lower: [0.0; ADAPTIMP_MAX_JOINTS],
                upper: [0.0; ADAPTIMP_MAX_JOINTS],
                effort: [0.0; ADAPTIMP_MAX_JOINTS],
                velocity: [0.0; ADAPTIMP_MAX_JOINTS],
                damping: [0.0; ADAPTIMP_MAX_JOINTS],
                friction: [0.0; ADAPTIMP_MAX_JOINTS],
            };
            for (i, j) in arm.joints.iter().enumerate() {
                filled.prismatic[i] = AdaptimpBoolRaw(u8::from(j.prismatic));
                filled.lower[i] = j.lower;
                filled.upper[i] = j.upper;
                filled.effort[i] = j.effort;
                filled.velocity[i] = j.velocity;
                filled.damping[i] = j.damping;
                filled.friction[i] = j.friction;
            }
            *info = filled;
        }
        Ok(())
    })
}
