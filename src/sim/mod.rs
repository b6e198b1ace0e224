//! Simulation only (feature `sim`, on by default; firmware builds leave it
//! out, and with it the random-number crates): rigid-body arm models, the
//! environments, the `Plant` trait and its RK4 plant, the closed loop, the
//! recorded rows and the SPEC §12 metrics, disturbances (SPEC §17) and
//! injected faults.

pub mod disturb;
pub mod environment;
pub mod inject;
pub mod metrics;
pub mod model;
pub mod plant;
pub mod record;
pub mod simulator;
