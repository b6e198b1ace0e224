//! Transforms and chains: a transform from a URDF origin, a position and
//! quaternion or a 4 × 4 matrix; a chain of joints and its tip; the
//! parameters of the group "cartesian".

use super::*;

/// URDF's `<origin xyz="…" rpy="…">`: translation `xyz` (3 reals, m) and the
/// fixed-axis roll, pitch, yaw `rpy` (3 reals, rad), R = Rot_z(yaw)
/// Rot_y(pitch) Rot_x(roll). Values are checked by the chain.
///
/// # Safety
/// `xyz` and `rpy` are NULL or hold 3 reals; `out` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_transform_xyz_rpy(
    xyz: *const f64,
    rpy: *const f64,
    out: *mut AdaptimpTransform,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let xyz = unsafe { slice(xyz, 3, "xyz") }?;
        let rpy = unsafe { slice(rpy, 3, "rpy") }?;
        let out = unsafe { crate::out(out, "out") }?;
        *out = transform_out(&Transform::from_xyz_rpy(
            [xyz[0], xyz[1], xyz[2]],
            [rpy[0], rpy[1], rpy[2]],
        ));
        Ok(())
    })
}

/// A position `pos` (3 reals, m) and a quaternion `quat` = [w, x, y, z]
/// (MuJoCo's `body_pos`, `body_quat`; normalised as MuJoCo does, finite and
/// non-zero, else INVALID_CONFIG).
///
/// # Safety
/// `pos` holds 3 reals, `quat` 4, or is NULL; `out` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_transform_pos_quat(
    pos: *const f64,
    quat: *const f64,
    out: *mut AdaptimpTransform,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let pos = unsafe { slice(pos, 3, "pos") }?;
        let quat = unsafe { slice(quat, 4, "quat") }?;
        let out = unsafe { crate::out(out, "out") }?;
        let t = Transform::from_pos_quat(
            [pos[0], pos[1], pos[2]],
            [quat[0], quat[1], quat[2], quat[3]],
        )
        .map_err(|e| core_error(e, Context::Config))?;
        *out = transform_out(&t);
        Ok(())
    })
}

/// A 4 × 4 homogeneous transform `m` (16 reals, row-major: [R p; 0 0 0 1]).
/// Its last row must be 0 0 0 1 (to 1e-6; else INVALID_CONFIG); R is checked
/// by the chain.
///
/// # Safety
/// `m` is NULL or holds 16 reals; `out` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_transform_matrix(
    m: *const f64,
    out: *mut AdaptimpTransform,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let m = unsafe { slice(m, 16, "m") }?;
        let out = unsafe { crate::out(out, "out") }?;
        let m: [f64; 16] = core::array::from_fn(|i| m[i]);
        let t = Transform::from_matrix(&m).map_err(|e| core_error(e, Context::Config))?;
        *out = transform_out(&t);
        Ok(())
    })
}

/// The chain of `count` joints `joints` (base to tip, fixed ones included;
/// 1 … 7 movable) and the `tip` transform (the last joint's frame → the
/// tip; NULL: the identity) into `*out` (free it with
/// [`adaptimp_chain_free`]). Checked by the core, each error naming the
/// condition and the joint's index: a zero or non-finite axis, a rotation
/// that is not orthonormal or is a reflection, an origin beyond 1e6 m
/// (INVALID_CONFIG); a `kind` that is not an `AdaptimpJointKind`
/// (INVALID_CONFIG); no or more than 7 movable joints (BAD_SIZE).
///
/// # Safety
/// `joints` is NULL or holds `count` joints; `tip` and `out` are NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_chain_new(
    joints: *const AdaptimpJoint,
    count: usize,
    tip: *const AdaptimpTransform,
    out: *mut *mut AdaptimpChain,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let given = if count == 0 {
            &[][..]
        } else {
            unsafe { slice(joints, count, "joints") }?
        };
        let out = unsafe { crate::out(out, "out") }?;
        let tip = if tip.is_null() {
            Transform::IDENTITY
        } else {
            transform_of(unsafe { read(tip, "tip") }?)
        };
        let mut js = Vec::with_capacity(count);
        for (i, j) in given.iter().enumerate() {
            let kind = match decode::<AdaptimpJointKind>(j.kind, &format!("joints[{i}].kind"))? {
                AdaptimpJointKind::Fixed => JointKind::Fixed,
                AdaptimpJointKind::Revolute => JointKind::Revolute,
                AdaptimpJointKind::Prismatic => JointKind::Prismatic,
            };
            js.push(Joint {
                kind,
                origin: transform_of(&j.origin),
                axis: j.axis,
                offset: j.offset,
            });
        }
        *out = publish_chain(Chain::new(&js, &tip).map_err(chain_error)?)?;
        Ok(())
    })
}

/// Free a chain (NULL and dead handles are ignored). A Cartesian controller
/// keeps its own copy: the chain can be freed after `adaptimp_cartesian_new`.
///
/// # Safety
/// `chain` is NULL or came from `adaptimp_chain_new`.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_chain_free(chain: *mut AdaptimpChain) {
    // SAFETY: the caller's contract.
    unsafe { free(chain, "chain") }
}

/// The chain's number of movable joints, or 0 for NULL or a dead handle.
///
/// # Safety
/// `chain` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_chain_joints(chain: *const AdaptimpChain) -> usize {
    // SAFETY (in `handle`): checked.
    match unsafe { handle(chain, "chain") } {
        Ok(c) => c.chain.n(),
        Err(_) => 0,
    }
}

/// The tip at q (rad or m, `n` reals) and q̇ (`n` reals; NULL: zero) into
/// `*out`: pose, Jacobian, J̇ q̇ (the core's one pass, (16.0)). NON_FINITE
/// for a q or q̇ that is not finite; BAD_SIZE for n ≠ the chain's.
///
/// # Safety
/// `chain` and `out` are NULL or valid; `q`, `dq` NULL or hold `n` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_chain_tip(
    chain: *const AdaptimpChain,
    n: usize,
    q: *const f64,
    dq: *const f64,
    out: *mut AdaptimpTip,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let c = unsafe { handle(chain, "chain") }?;
        let out = unsafe { crate::out(out, "out") }?;
        let c = &c.chain;
        check_n(n, c.n(), "chain")?;
        let q = unsafe { slice(q, n, "q") }?;
        let zero = [0.0; ADAPTIMP_MAX_JOINTS];
        let dq = if dq.is_null() {
            &zero[..n]
        } else {
            unsafe { slice(dq, n, "dq") }?
        };
        let t = c.tip(q, dq).map_err(|e| core_error(e, Context::Step))?;
        out.n = n;
        out.position = a3(&t.position);
        out.rotation = rows3(t.rotation.matrix());
        out.jacobian = core::array::from_fn(|i| {
            let mut row = [0.0; ADAPTIMP_MAX_JOINTS];
            for (j, v) in row.iter_mut().enumerate().take(n) {
                *v = t.jacobian[(i, j)];
            }
            row
        });
        out.bias = core::array::from_fn(|i| t.bias[i]);
        Ok(())
    })
}

// ---------------------------------------------------------------------------
// Cartesian parameters.
// ---------------------------------------------------------------------------

/// The parameters as the core's configuration, each set from its field
/// ([`cartesian_fields`]).
pub(super) fn cartesian_of(p: &AdaptimpCartesianParams) -> Result<CartesianConfig, AdaptimpStatus> {
    let mut s =
        Scenario::new(1, Preset::Robot, Law::Pd).map_err(|e| core_error(e, Context::Config))?;
    let mut p = *p;
    read_into(
        &mut s,
        1,
        Group::Cartesian,
        cartesian_fields(&mut p),
        "cart",
    )?;
    Ok(s.cartesian())
}

/// Fill `out` with the schema's defaults of the group "cartesian" (SPEC
/// §16: M_d = 2 kg, K_d = 500 N/m, critical damping, M_d,rot = 0.08 kg m²,
/// K_d,rot = 20 N m/rad, …; no clipping).
///
/// # Safety
/// `out` is NULL or points to an `AdaptimpCartesianParams`.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_params_default(
    out: *mut AdaptimpCartesianParams,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `out`): checked for NULL.
        let out = unsafe { crate::out(out, "out") }?;
        let s =
            Scenario::new(1, Preset::Robot, Law::Pd).map_err(|e| core_error(e, Context::Config))?;
        let mut p = AdaptimpCartesianParams::default();
        write_from(&s, Group::Cartesian, cartesian_fields(&mut p), "cart")?;
        *out = p;
        Ok(())
    })
}

/// The operational-space inertia Λ of robosuite's OSC_POSE, SPEC (23.7), the
/// core's `dynamic::operational_inertia`: `jacobian` the tip's 6 × n
/// geometric Jacobian [J_v; J_ω] (6 n reals, row-major, world-aligned),
/// `inertia` the joint-space inertia D (n² reals, row-major, kg m²),
/// `uncoupled` OSC_POSE's `uncouple_pos_ori` (Λ block-diagonal). Writes Λ
/// (36 reals, row-major, symmetric; kg, kg m², kg m across) to `out`.
/// BAD_SIZE for n outside 1 … 7; INVALID_CONFIG, with the core's message,
/// for a non-finite entry or D not symmetric or not positive definite
/// (`out` then untouched).
///
/// # Safety
/// `jacobian` is NULL or holds 6 n reals, `inertia` n², `out` 36 writable
/// reals that nothing else accesses during the call.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_operational_inertia(
    n: usize,
    jacobian: *const f64,
    inertia: *const f64,
    uncoupled: bool,
    out: *mut f64,
) -> AdaptimpStatus {
    guard(|| {
        if !(1..=ADAPTIMP_MAX_JOINTS).contains(&n) {
            return Err(crate::params::bad_n(n));
        }
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let j = unsafe { slice(jacobian, 6 * n, "jacobian") }?;
        let d = unsafe { slice(inertia, n * n, "inertia") }?;
        let out = unsafe { slice_mut(out, 36, "out") }?;
        let lam = adaptimp::dynamic::operational_inertia(j, d, uncoupled)
            .map_err(|e| core_error(e, Context::Config))?;
        out.copy_from_slice(&lam);
        Ok(())
    })
}
