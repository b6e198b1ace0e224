//! A controller stepped along recorded rows (a log of a real robot, a run
//! of another simulator): the open loop, no plant. [`Controller::replay`]
//! steps K rows of n values each, writes each step's sat(τ) and shows the
//! controller's state to the caller every [`HOOK_EVERY`] rows and after the
//! last (a progress bar, a signal check, a copy for code that reads it).

use super::super::controller::{Controller, State};
use super::super::sized::pair;
use super::super::values::mismatch;
use super::{RunError, HOOK_EVERY};
use crate::error::Error;
use crate::types::Vector;

/// Recorded rows to replay, K rows of n values each, row-major: the
/// measurement of each step and, if given, its setpoint (else the
/// controller's own trajectory at its clock).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Replay<'a> {
    /// Positions x (rad), K × n.
    pub x: &'a [f64],
    /// Velocities ẋ (rad/s), K × n, if measured.
    pub dx: Option<&'a [f64]>,
    /// The force on the environment τe (N m), K × n.
    pub tau_e: &'a [f64],
    /// The setpoints xc, ẋc, ẍc (rad, rad/s, rad/s²), K × n each.
    pub setpoint: Option<[&'a [f64]; 3]>,
}

impl Replay<'_> {
    /// The number of rows K of n values, every table checked.
    pub fn rows(&self, n: usize) -> Result<usize, Error> {
        let bad = Error::Invalid {
            what: "rows",
            reason: "every table needs K rows of n values",
        };
        if n == 0 || !self.x.len().is_multiple_of(n) {
            return Err(bad);
        }
        let len = self.x.len();
        let mut others = [self.tau_e].into_iter().chain(self.dx);
        if others.any(|t| t.len() != len)
            || self
                .setpoint
                .is_some_and(|s| s.iter().any(|t| t.len() != len))
        {
            return Err(bad);
        }
        Ok(len / n)
    }
}

impl Controller {
    /// Step along the K rows of `rows` from `state` on (not reset), each
    /// step's sat(τ) (N m) into row k of `out` (K × n). `seen(k, K, state)`
    /// is called after every [`HOOK_EVERY`]-th step and after the last; false
    /// stops the replay ([`RunError::Stopped`]). A refused step ends it with
    /// the error and its row ([`RunError::Core`]), recorded in the state.
    pub fn replay<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        state: &mut State<S>,
        rows: &Replay<'_>,
        out: &mut [f64],
        mut seen: impl FnMut(u64, u64, &State<S>) -> bool,
    ) -> Result<(), RunError> {
        let n = self.n();
        let k_all = rows.rows(n)?;
        if state.n() != n {
            return Err(mismatch("state").into());
        }
        if out.len() != rows.x.len() {
            return Err(Error::Invalid {
                what: "out",
                reason: "needs K rows of n values",
            }
            .into());
        }
        let total = k_all as u64;
        let mut k = 0;
        while k < k_all {
            let end = (k + HOOK_EVERY as usize).min(k_all);
            pair!(&self.inner, &mut state.inner, c, s, N => {
                let row = |v: &[f64], i: usize| Vector::<N>::from_column_slice(&v[i * N..(i + 1) * N]);
                for i in k..end {
                    let m = crate::control::io::Measurement {
                        x: row(rows.x, i),
                        dx: rows.dx.map(|d| row(d, i)),
                        tau_e: row(rows.tau_e, i),
                    };
                    let sp = match rows.setpoint {
                        Some([x, dx, ddx]) => crate::trajectory::Setpoint {
                            x: row(x, i),
                            dx: row(dx, i),
                            ddx: row(ddx, i),
                        },
                        None => crate::trajectory::Trajectory::sample(&c.traj, c.ctrl.time(s)),
                    };
                    let cmd = c
                        .ctrl
                        .step(s, &m, &sp)
                        .map_err(|e| RunError::Core(e, Some(i as u64)))?;
                    out[i * N..(i + 1) * N].copy_from_slice(cmd.tau_sat.as_slice());
                }
                Ok::<(), RunError>(())
            }, _ => Err(mismatch("state").into()))?;
            k = end;
            if !seen(k as u64, total, state) {
                return Err(RunError::Stopped);
            }
        }
        Ok(())
    }
}
