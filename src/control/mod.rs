//! The joint-space controller of the paper and what surrounds its step:
//! parameters, the staged step, the caller-owned state, the target impedance,
//! the saturation compensator, the velocity observer, the robust term, the
//! safety layer and the trajectory-owning [`Tracker`](tracker::Tracker).
//! SPEC §4–§11, §13, §14. No allocation (except [`tracker`], feature `alloc`).

pub mod auxiliary;
pub mod config;
pub mod controller;
pub mod coupling;
pub mod impedance;
pub mod io;
pub mod observer;
pub mod robust;
pub mod safety;
pub mod saturation;
pub mod state;
#[cfg(feature = "alloc")]
pub mod tracker;
pub mod tuning;
