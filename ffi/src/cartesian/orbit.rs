//! The orbit rule: RBF centres along the joint orbit of a Cartesian path
//! (SPEC §15, §16), the core running the outer loop kinematically.

use super::*;

/// RBF centres along the joint orbit of a Cartesian path (SPEC §15, (15.2),
/// and §16): the core runs the outer loop of `cart` over `chain` at period
/// `ts` kinematically (F_e = 0) from `q0` (`n` reals, rad) along `targets`
/// (`steps` poses, one per step), keeps the joint reference (q_d, q̇_d) of
/// every max(1, ⌊steps/nodes⌋)-th step (L ≤ `nodes` samples), and makes them
/// centres with widths per block η_q = max(2 h_q, `tube[0]`) (rad), η_v =
/// max(2 h_v, `tube[1]`) (rad/s) (α1, α̇1 left out: width INFINITY). Writes
/// the centres into `centers` (room for `nodes` rows of 4n reals; L rows
/// written), the squared widths into `widths2` (4n reals) and L into
/// `*written`: what `AdaptimpParams.centers`, `.nodes` and `.widths2` take.
///
/// # Safety
/// `chain`, `cart` NULL or valid; `q0` NULL or `n` reals; `targets` NULL or
/// `steps` poses; `tube` NULL or 2 reals; `centers` NULL or `nodes × 4n`
/// reals; `widths2` NULL or `4n` reals; `written` NULL or valid.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn adaptimp_cartesian_orbit_centres(
    chain: *const AdaptimpChain,
    cart: *const AdaptimpCartesianParams,
    ts: f64,
    n: usize,
    q0: *const f64,
    targets: *const AdaptimpPoseTarget,
    steps: usize,
    nodes: usize,
    tube: *const f64,
    centers: *mut f64,
    widths2: *mut f64,
    written: *mut usize,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let chain = unsafe { handle(chain, "chain") }?;
        let cfg = cartesian_of(unsafe { read(cart, "cart") }?)?;
        let targets = unsafe { slice(targets, steps, "targets") }?;
        let tube = unsafe { slice(tube, 2, "tube") }?;
        let written = unsafe { out(written, "written") }?;
        if nodes == 0 {
            return Err(fail(AdaptimpStatus::BadSize, &"nodes must be ≥ 1"));
        }
        let c = &chain.chain;
        check_n(n, c.n(), "chain")?;
        let q0 = unsafe { slice(q0, n, "q0") }?;
        let len = nodes
            .checked_mul(4 * n)
            .ok_or_else(|| fail(AdaptimpStatus::BadSize, &"nodes × 4n overflows"))?;
        let centers = unsafe { slice_mut(centers, len, "centers") }?;
        let widths2 = unsafe { slice_mut(widths2, 4 * n, "widths2") }?;
        let config = |e| core_error(e, Context::Config);
        let outer = CartesianImpedance::new(cfg, c, ts).map_err(config)?;
        let samples = outer
            .orbit(q0, targets.len(), |k| pose_target(&targets[k]), nodes)
            .map_err(config)?;
        let along = Centres::along(&samples, [tube[0], tube[1]], false).map_err(config)?;
        centers[..along.rows.len()].copy_from_slice(&along.rows);
        if let Some(w) = &along.widths2 {
            widths2.copy_from_slice(w);
        }
        *written = samples.len();
        Ok(())
    })
}
