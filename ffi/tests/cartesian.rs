//! The Cartesian C API against the core (SPEC §16): a chain from joint data
//! gives the core's kinematics bit for bit, the Cartesian step the core's
//! `CartesianController` step bit for bit, the orbit centres the core's;
//! bad chains, bad targets and wrong sizes get a status naming them and
//! change nothing.

use adaptimp::cartesian::rotation::rotation_error;
use adaptimp::schema::Value;
use adaptimp::{
    AnyBasis, CartesianConfig, CartesianController, CartesianImpedance, CartesianMeasurement,
    Centers, Chain, Controller, Formulation, Joint, Kinematics, Law, PoseTarget, Preset, Scenario,
    Setpoint, Transform, Vector,
};
use adaptimp_ffi::*;
use nalgebra::{Matrix3, UnitQuaternion};
use std::ptr;

mod common;
use common::{defaults, last_error};

const N: usize = 3;

/// A 3-joint arm with every kind of element: a fixed base offset, a revolute
/// joint with a tilted origin, a prismatic joint, a fixed elbow, a revolute
/// joint about an oblique axis with an offset; a tip.
fn joints() -> (Vec<AdaptimpJoint>, AdaptimpTransform) {
    let t = |xyz: [f64; 3], rpy: [f64; 3]| {
        let mut out = AdaptimpTransform {
            translation: [0.0; 3],
            rotation: [[0.0; 3]; 3],
        };
        // SAFETY: 3 reals each and a valid out pointer.
        let s = unsafe { adaptimp_transform_xyz_rpy(xyz.as_ptr(), rpy.as_ptr(), &mut out) };
        assert_eq!(s, AdaptimpStatus::Ok);
        out
    };
    let j = |kind: AdaptimpJointKind, origin, axis, offset| AdaptimpJoint {
        kind: kind.into(),
        origin,
        axis,
        offset,
    };
    use AdaptimpJointKind::{Fixed, Prismatic, Revolute};
    (
        vec![
            j(Fixed, t([0.0, 0.0, 0.1], [0.0, 0.0, 0.3]), [0.0; 3], 0.0),
            j(
                Revolute,
                t([0.0, 0.05, 0.2], [0.2, -0.1, 0.0]),
                [0.0, 0.0, 1.0],
                0.0,
            ),
            j(
                Prismatic,
                t([0.3, 0.0, 0.0], [0.0, 0.5, 0.0]),
                [1.0, 0.0, 0.0],
                0.0,
            ),
            j(Fixed, t([0.1, 0.0, 0.0], [0.0, 0.0, 1.0]), [0.0; 3], 0.0),
            j(
                Revolute,
                t([0.0, 0.2, 0.0], [0.0, 0.0, 0.0]),
                [1.0, 2.0, 2.0],
                0.25,
            ),
        ],
        t([0.0, 0.0, 0.15], [0.1, 0.2, 0.3]),
    )
}

/// The same chain in the core.
fn core_chain() -> Chain<N> {
    let (js, tip) = joints();
    let js: Vec<Joint> = js
        .iter()
        .map(|j| Joint {
            kind: match j.kind.0 {
                1300 => adaptimp::JointKind::Fixed,
                1301 => adaptimp::JointKind::Revolute,
                _ => adaptimp::JointKind::Prismatic,
            },
            origin: Transform {
                translation: j.origin.translation,
                rotation: j.origin.rotation,
            },
            axis: j.axis,
            offset: j.offset,
        })
        .collect();
    Chain::new(
        &js,
        &Transform {
            translation: tip.translation,
            rotation: tip.rotation,
        },
    )
    .unwrap()
}

fn c_chain() -> *mut AdaptimpChain {
    let (js, tip) = joints();
    let mut chain = ptr::null_mut();
    // SAFETY: valid arrays and out pointer.
    let s = unsafe { adaptimp_chain_new(js.as_ptr(), js.len(), &tip, &mut chain) };
    assert_eq!(s, AdaptimpStatus::Ok, "{}", last_error());
    chain
}

fn cart_defaults() -> AdaptimpCartesianParams {
    let mut p = std::mem::MaybeUninit::uninit();
    // SAFETY: a valid place; Ok means it was written whole.
    unsafe {
        assert_eq!(
            adaptimp_cartesian_params_default(p.as_mut_ptr()),
            AdaptimpStatus::Ok
        );
        p.assume_init()
    }
}

const Q0: [f64; N] = [0.4, 0.12, -0.7];

/// The commanded pose at step k: from the start pose, a slow circle in x–y and
/// a turn about z.
fn target(p0: &Vector<3>, r0: &Matrix3<f64>, k: usize) -> AdaptimpPoseTarget {
    let t = k as f64 * 1e-3;
    let (s, c) = (t.sin(), t.cos());
    let r = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0) * r0;
    AdaptimpPoseTarget {
        p: [p0[0] + 0.02 * s, p0[1] + 0.02 * (1.0 - c), p0[2]],
        dp: [0.02 * c, 0.02 * s, 0.0],
        ddp: [-0.02 * s, 0.02 * c, 0.0],
        rotation: core::array::from_fn(|i| core::array::from_fn(|j| r[(i, j)])),
        w: [0.0, 0.0, 1.0],
        dw: [0.0; 3],
    }
}

fn pose(t: &AdaptimpPoseTarget) -> PoseTarget {
    PoseTarget {
        p: Vector::<3>::from(t.p),
        dp: Vector::<3>::from(t.dp),
        ddp: Vector::<3>::from(t.ddp),
        r: Matrix3::from_fn(|i, j| t.rotation[i][j]),
        w: Vector::<3>::from(t.w),
        dw: Vector::<3>::from(t.dw),
    }
}

#[test]
fn the_chain_is_the_cores_bit_for_bit() {
    let chain = c_chain();
    let core = core_chain();
    // SAFETY: a valid chain.
    assert_eq!(unsafe { adaptimp_chain_joints(chain) }, N);
    let (q, dq) = ([0.4, 0.12, -0.7], [0.9, -0.3, 1.4]);
    // SAFETY: zeroed is a valid AdaptimpTip (numbers only).
    let mut tip: AdaptimpTip = unsafe { std::mem::zeroed() };
    // SAFETY: valid handle, 3 reals each, a valid out pointer.
    let s = unsafe { adaptimp_chain_tip(chain, N, q.as_ptr(), dq.as_ptr(), &mut tip) };
    assert_eq!(s, AdaptimpStatus::Ok);
    let t = core.tip(&Vector::from(q), &Vector::from(dq));
    assert_eq!(tip.position, [t.position[0], t.position[1], t.position[2]]);
    for i in 0..3 {
        for j in 0..3 {
            assert_eq!(tip.rotation[i][j], t.rotation[(i, j)]);
        }
    }
    for i in 0..6 {
        for j in 0..7 {
            let want = if j < N { t.jacobian[(i, j)] } else { 0.0 };
            assert_eq!(tip.jacobian[i][j], want);
        }
        assert_eq!(tip.bias[i], t.bias[i]);
    }
    // Sizes and values.
    let nan = [f64::NAN, 0.0, 0.0];
    // SAFETY: as above.
    unsafe {
        assert_eq!(
            adaptimp_chain_tip(chain, 2, q.as_ptr(), ptr::null(), &mut tip),
            AdaptimpStatus::BadSize
        );
        assert_eq!(
            adaptimp_chain_tip(chain, N, nan.as_ptr(), ptr::null(), &mut tip),
            AdaptimpStatus::NonFinite
        );
        assert_eq!(last_error(), "q[0] is not finite (NaN or infinite)");
        adaptimp_chain_free(chain);
    }
}

#[test]
fn bad_chains_are_refused_by_name() {
    let (js, tip) = joints();
    let build = |js: &[AdaptimpJoint]| {
        let mut chain = ptr::null_mut();
        // SAFETY: valid arrays and out pointer.
        let s = unsafe { adaptimp_chain_new(js.as_ptr(), js.len(), &tip, &mut chain) };
        assert!(chain.is_null());
        (s, last_error())
    };
    let mut zero_axis = js.clone();
    zero_axis[4].axis = [0.0; 3];
    assert_eq!(
        build(&zero_axis),
        (
            AdaptimpStatus::InvalidConfig,
            "condition ‖axis‖ > 0 (a movable joint needs an axis) is violated: joint axis[4] = 0 (SPEC §10)"
                .to_string()
        )
    );
    let mut reflection = js.clone();
    reflection[1].origin.rotation[2] = [0.0, 0.0, -1.0];
    reflection[1].origin.rotation[0] = [1.0, 0.0, 0.0];
    reflection[1].origin.rotation[1] = [0.0, 1.0, 0.0];
    let (s, msg) = build(&reflection);
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(msg.contains("det R = +1"), "{msg}");
    let mut skew = js.clone();
    skew[2].origin.rotation[0][1] += 1e-3;
    let (s, msg) = build(&skew);
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(msg.contains("orthonormal") && msg.contains("[2]"), "{msg}");
    let eight: Vec<AdaptimpJoint> = (0..8).map(|_| js[1]).collect();
    assert_eq!(
        build(&eight),
        (
            AdaptimpStatus::BadSize,
            "condition 1 ≤ n ≤ 7 movable joints is violated: movable joints = 8 (SPEC §10)"
                .to_string()
        )
    );
    assert_eq!(build(&[js[0]]).0, AdaptimpStatus::BadSize);
    let mut kind = js.clone();
    kind[3].kind = AdaptimpJointKindRaw(AdaptimpLaw::Pd as u32);
    let (s, msg) = build(&kind);
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(msg.starts_with("joints[3].kind = 100 is not an AdaptimpJointKind"));
    assert!(msg.contains("ADAPTIMP_LAW_PD"), "{msg}");
    let mut chain = ptr::null_mut();
    // SAFETY: NULL joints with a count: refused.
    let s = unsafe { adaptimp_chain_new(ptr::null(), 3, ptr::null(), &mut chain) };
    assert_eq!(s, AdaptimpStatus::NullPointer);
    // A 4 × 4 with a bad last row; a non-unit quaternion of a MuJoCo body is normalised.
    let mut tf = tip;
    let m = [
        1.0, 0.0, 0.0, 0.1, 0.0, 1.0, 0.0, 0.2, 0.0, 0.0, 1.0, 0.3, 0.0, 0.0, 0.0, 1.0,
    ];
    // SAFETY: 16 reals, valid out pointers.
    unsafe {
        assert_eq!(
            adaptimp_transform_matrix(m.as_ptr(), &mut tf),
            AdaptimpStatus::Ok
        );
        assert_eq!(tf.translation, [0.1, 0.2, 0.3]);
        let mut bad = m;
        bad[14] = f64::NAN;
        assert_eq!(
            adaptimp_transform_matrix(bad.as_ptr(), &mut tf),
            AdaptimpStatus::InvalidConfig
        );
        let pos = [0.0; 3];
        let zero = [0.0; 4];
        assert_eq!(
            adaptimp_transform_pos_quat(pos.as_ptr(), zero.as_ptr(), &mut tf),
            AdaptimpStatus::InvalidConfig
        );
    }
}

/// The Cartesian controller through the ABI and the same in the core.
struct Pair {
    cart: *mut AdaptimpCartesian,
    state: *mut AdaptimpCartesianState,
    core: CartesianController<N, Chain<N>, AnyBasis<N>>,
}

impl Drop for Pair {
    fn drop(&mut self) {
        // SAFETY: made by the library, freed once.
        unsafe {
            adaptimp_cartesian_state_free(self.state);
            adaptimp_cartesian_free(self.cart);
        }
    }
}

fn pair(law: AdaptimpLaw, core_law: Law) -> Pair {
    pair_formulated(law, core_law, AdaptimpFormulation::Admittance)
}

/// [`pair`] with the impedance reaching the torque as `form` says (SPEC §19),
/// the unified formulation at the admittance share 0.3.
fn pair_formulated(law: AdaptimpLaw, core_law: Law, form: AdaptimpFormulation) -> Pair {
    let chain = c_chain();
    let mut cart = cart_defaults();
    cart.formulation = form.into();
    cart.admittance_share = 0.3;
    let config = CartesianConfig {
        formulation: match form {
            AdaptimpFormulation::Admittance => Formulation::Admittance,
            AdaptimpFormulation::Impedance => Formulation::Impedance,
            AdaptimpFormulation::Unified => Formulation::Unified,
        },
        admittance_share: 0.3,
        ..CartesianConfig::default()
    };
    let core = core_chain();
    let tip0 = core.tip(&Vector::from(Q0), &Vector::zeros());
    let (p0, r0) = (tip0.position, *tip0.rotation.matrix());
    // Centres along the orbit, through the ABI, equal to the core's.
    let path: Vec<AdaptimpPoseTarget> = (0..400).map(|k| target(&p0, &r0, k)).collect();
    let (mut centers, mut widths2, mut l) = (vec![0.0; 16 * 4 * N], vec![0.0; 4 * N], 0);
    let tube = [0.05, 0.2];
    // SAFETY: valid handles, arrays of the stated lengths.
    let s = unsafe {
        adaptimp_cartesian_orbit_centres(
            chain,
            &cart,
            1e-3,
            N,
            Q0.as_ptr(),
            path.as_ptr(),
            path.len(),
            16,
            tube.as_ptr(),
            centers.as_mut_ptr(),
            widths2.as_mut_ptr(),
            &mut l,
        )
    };
    assert_eq!(s, AdaptimpStatus::Ok, "{}", last_error());
    assert_eq!(l, 16);
    let outer = CartesianImpedance::new(config, core, 1e-3).unwrap();
    let zero = Setpoint {
        x: Vector::<N>::zeros(),
        dx: Vector::zeros(),
        ddx: Vector::zeros(),
    };
    let mut samples = vec![zero; 16];
    let k = outer
        .orbit(Vector::from(Q0), 400, |k| pose(&path[k]), &mut samples)
        .unwrap();
    let centres = Centers::along(&samples[..k], tube).unwrap();
    assert_eq!(centres.centers(), &centers[..]);
    let w = centres.widths2();
    assert_eq!(
        w.iter().flat_map(|b| b.iter().copied()).collect::<Vec<_>>(),
        widths2
    );
    // The joint controller: the robot scenario's, impedance external, these centres.
    let mut joint = defaults(N, law, AdaptimpPreset::Robot);
    joint.impedance = AdaptimpImpedance::External.into();
    joint.tau_max[..N].copy_from_slice(&[30.0, 200.0, 10.0]);
    joint.centers = centers.as_ptr();
    joint.nodes = l;
    joint.widths2 = widths2.as_ptr();
    let mut c = ptr::null_mut();
    // SAFETY: valid handles and structs; the centres live through the call.
    let s = unsafe { adaptimp_cartesian_new(chain, &cart, &joint, &mut c) };
    assert_eq!(s, AdaptimpStatus::Ok, "{}", last_error());
    // SAFETY: the controller keeps its own copy of the chain.
    unsafe { adaptimp_chain_free(chain) };
    let mut state = ptr::null_mut();
    // SAFETY: valid handle, 3 reals.
    let s = unsafe { adaptimp_cartesian_state_new(c, N, Q0.as_ptr(), &mut state) };
    assert_eq!(s, AdaptimpStatus::Ok);
    let mut sc = Scenario::<N>::preset(Preset::Robot, core_law);
    sc.set("impedance", Value::Str("external")).unwrap();
    sc.set("tau_max", Value::Vec(&[30.0, 200.0, 10.0])).unwrap();
    let basis = AnyBasis::Centers(Centers::new(centers.clone(), w).unwrap());
    let inner = Controller::for_trajectory(sc.config, basis, &sc.trajectory().unwrap()).unwrap();
    Pair {
        cart: c,
        state,
        core: CartesianController::new(outer, inner).unwrap(),
    }
}

fn step(
    p: &Pair,
    q: &[f64; N],
    dq: Option<&[f64; N]>,
    wrench: &[f64; 6],
    t: Option<&AdaptimpPoseTarget>,
) -> (AdaptimpStatus, AdaptimpCartesianCommand) {
    let mut out = AdaptimpCartesianCommand::ZERO;
    out.n = 99;
    out.tau_sat = [f64::NAN; 7];
    // SAFETY: valid handles; arrays of the stated lengths.
    let s = unsafe {
        adaptimp_cartesian_step(
            p.cart,
            p.state,
            N,
            q.as_ptr(),
            dq.map_or(ptr::null(), |d| d.as_ptr()),
            wrench.as_ptr(),
            t.map_or(ptr::null(), |t| t as *const _),
            &mut out,
        )
    };
    (s, out)
}

#[test]
fn the_cartesian_step_is_the_cores_bit_for_bit() {
    for form in [
        AdaptimpFormulation::Admittance,
        AdaptimpFormulation::Impedance,
        AdaptimpFormulation::Unified,
    ] {
        cartesian_steps_are_the_cores(form);
    }
}

#[test]
fn a_formulation_outside_its_enum_is_refused_by_name() {
    let chain = c_chain();
    let mut cart = cart_defaults();
    cart.formulation = AdaptimpFormulationRaw(1503);
    let joint = defaults(N, AdaptimpLaw::Pd, AdaptimpPreset::Robot);
    let mut c = ptr::null_mut();
    // SAFETY: valid handles and structs.
    let s = unsafe { adaptimp_cartesian_new(chain, &cart, &joint, &mut c) };
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(c.is_null());
    assert!(
        last_error().contains("cart.formulation"),
        "{}",
        last_error()
    );
    // SAFETY: a live chain.
    unsafe { adaptimp_chain_free(chain) };
}

fn cartesian_steps_are_the_cores(form: AdaptimpFormulation) {
    for (law, core_law) in [
        (AdaptimpLaw::Pd, Law::Pd),
        (AdaptimpLaw::StateFeedback, Law::StateFeedback),
        (AdaptimpLaw::OutputFeedback, Law::OutputFeedback),
    ] {
        let p = pair_formulated(law, core_law, form);
        let chain = core_chain();
        let tip0 = chain.tip(&Vector::from(Q0), &Vector::zeros());
        let (p0, r0) = (tip0.position, *tip0.rotation.matrix());
        let (mut ost, mut ist) = (
            p.core.outer().start(Vector::from(Q0)),
            p.core.inner().new_state(),
        );
        for k in 0..300 {
            let s = k as f64 * 1e-3;
            let q = [
                Q0[0] + 0.01 * s,
                Q0[1] - 0.02 * s,
                Q0[2] + 0.005 * (3.0 * s).sin(),
            ];
            let dq = [0.01, -0.02, 0.015 * (3.0 * s).cos()];
            let wrench = [0.0, 0.0, -2.0 * s, 0.1, 0.0, 0.0];
            let t = target(&p0, &r0, k);
            // Every 50th step holds the last target.
            let given = (k % 50 != 49).then_some(&t);
            let dq_in = (core_law != Law::OutputFeedback).then_some(&dq);
            let (status, out) = step(&p, &q, dq_in, &wrench, given);
            assert_eq!(
                status,
                AdaptimpStatus::Ok,
                "{form:?} {law:?} k = {k}: {}",
                last_error()
            );
            let m = CartesianMeasurement {
                q: Vector::from(q),
                dq: dq_in.map(|d| Vector::from(*d)),
                wrench: Vector::<6>::from(wrench),
            };
            let want = p
                .core
                .step(&mut ost, &mut ist, &m, given.map(pose).as_ref())
                .unwrap();
            assert_eq!(out.n, N);
            assert_eq!(
                &out.tau_sat[..N],
                want.joint.tau_sat.as_slice(),
                "{form:?} {law:?} k = {k}"
            );
            assert_eq!(&out.tau[..N], want.joint.tau.as_slice());
            assert_eq!(&out.z1[..N], want.joint.z1.as_slice());
            assert_eq!(&out.q_d[..N], want.reference.x.as_slice());
            assert_eq!(&out.dq_d[..N], want.reference.dx.as_slice());
            assert_eq!(&out.ddq_d[..N], want.reference.ddx.as_slice());
            assert_eq!(&out.tau_e[..N], want.tau_e.as_slice());
            assert_eq!(
                out.p_d,
                [
                    want.compliant.p[0],
                    want.compliant.p[1],
                    want.compliant.p[2]
                ]
            );
            assert_eq!(out.p, [want.p[0], want.p[1], want.p[2]]);
            assert_eq!(out.error.as_slice(), want.error.as_slice());
            assert!(out.tau_sat[N..].iter().all(|v| *v == 0.0));
        }
    }
}

#[test]
fn a_target_that_is_not_a_rotation_is_refused_and_changes_nothing() {
    let p = pair(AdaptimpLaw::StateFeedback, Law::StateFeedback);
    let twin = pair(AdaptimpLaw::StateFeedback, Law::StateFeedback);
    let chain = core_chain();
    let tip0 = chain.tip(&Vector::from(Q0), &Vector::zeros());
    let (p0, r0) = (tip0.position, *tip0.rotation.matrix());
    let dq = [0.0; N];
    let wrench = [0.0; 6];
    for k in 0..10 {
        let t = target(&p0, &r0, k);
        assert_eq!(
            step(&p, &Q0, Some(&dq), &wrench, Some(&t)).0,
            AdaptimpStatus::Ok
        );
        assert_eq!(
            step(&twin, &Q0, Some(&dq), &wrench, Some(&t)).0,
            AdaptimpStatus::Ok
        );
    }
    let good = target(&p0, &r0, 10);
    let mut applied = [0.0; N];
    // SAFETY: a valid state; N reals.
    unsafe { adaptimp_cartesian_state_applied(p.state, N, applied.as_mut_ptr()) };
    // Non-orthonormal (to more than 1e-6), a reflection, a NaN, a unit
    // quaternion's matrix scaled: each refused by the core's check.
    let mut skew = good;
    skew.rotation[0][1] += 1e-4;
    let mut mirror = good;
    mirror.rotation[2] = [
        -good.rotation[2][0],
        -good.rotation[2][1],
        -good.rotation[2][2],
    ];
    let mut nan = good;
    nan.rotation[1][1] = f64::NAN;
    for (bad, status, msg) in [
        (skew, AdaptimpStatus::InvalidInput, "RᵀR = I"),
        (mirror, AdaptimpStatus::InvalidInput, "det R = +1"),
        (nan, AdaptimpStatus::NonFinite, "R_c"),
    ] {
        let (s, out) = step(&p, &Q0, Some(&dq), &wrench, Some(&bad));
        assert_eq!(s, status, "{}", last_error());
        assert!(last_error().contains(msg), "{}", last_error());
        // The fallback (hold: the torque last applied), n, the rest zero.
        assert_eq!(out.n, N);
        assert_eq!(&out.tau_sat[..N], &applied);
        assert_eq!(out.q_d, [0.0; 7]);
        // SAFETY: a valid state.
        unsafe {
            assert!(adaptimp_cartesian_state_fault(p.state, ptr::null_mut()));
            assert_eq!(adaptimp_cartesian_state_steps(p.state), 10);
            adaptimp_cartesian_state_clear_fault(p.state);
        }
    }
    // The quaternion route: a unit quaternion is the matrix; another is refused.
    let q = UnitQuaternion::from_matrix(&Matrix3::from_fn(|i, j| good.rotation[i][j]));
    let mut from_q = good;
    let coeffs = [q.w, q.i, q.j, q.k];
    // SAFETY: a valid target and 4 reals.
    unsafe {
        assert_eq!(
            adaptimp_pose_target_set_quaternion(&mut from_q, coeffs.as_ptr()),
            AdaptimpStatus::Ok
        );
        let twice = coeffs.map(|c| 2.0 * c);
        let before = from_q;
        assert_eq!(
            adaptimp_pose_target_set_quaternion(&mut from_q, twice.as_ptr()),
            AdaptimpStatus::InvalidInput
        );
        assert_eq!(from_q, before);
    }
    let e = rotation_error(
        &UnitQuaternion::from_matrix(&Matrix3::from_fn(|i, j| from_q.rotation[i][j])),
        &q,
    );
    assert!(e.norm() < 1e-15);
    // The run goes on as its twin's, which never saw the bad targets.
    for k in 10..100 {
        let t = target(&p0, &r0, k);
        let a = step(&p, &Q0, Some(&dq), &wrench, Some(&t));
        let b = step(&twin, &Q0, Some(&dq), &wrench, Some(&t));
        assert_eq!(a, b, "k = {k}");
        assert_eq!(a.0, AdaptimpStatus::Ok);
    }
}

#[test]
fn wrong_sizes_and_nulls_write_the_fallback_and_record_the_refusal() {
    let p = pair(AdaptimpLaw::Pd, Law::Pd);
    let dq = [0.0; N];
    let wrench = [0.0; 6];
    assert_eq!(
        step(&p, &Q0, Some(&dq), &wrench, None).0,
        AdaptimpStatus::Ok
    );
    let mut out = AdaptimpCartesianCommand::ZERO;
    // SAFETY: valid handles; n = 2 is refused before anything is read.
    let s = unsafe {
        adaptimp_cartesian_step(
            p.cart,
            p.state,
            2,
            Q0.as_ptr(),
            dq.as_ptr(),
            wrench.as_ptr(),
            ptr::null(),
            &mut out,
        )
    };
    assert_eq!(s, AdaptimpStatus::BadSize);
    assert_eq!(out.n, N);
    // SAFETY: as above; NULL wrench.
    let s = unsafe {
        adaptimp_cartesian_step(
            p.cart,
            p.state,
            N,
            Q0.as_ptr(),
            dq.as_ptr(),
            ptr::null(),
            ptr::null(),
            &mut out,
        )
    };
    assert_eq!(s, AdaptimpStatus::NullPointer);
    assert_eq!(last_error(), "wrench is NULL");
    assert_eq!(out.n, N);
    // SAFETY: a valid state.
    assert!(unsafe { adaptimp_cartesian_state_fault(p.state, ptr::null_mut()) });
    // PD without q̇: the core's MISSING_VELOCITY, the fallback written.
    let (s, out) = step(&p, &Q0, None, &wrench, None);
    assert_eq!(s, AdaptimpStatus::MissingVelocity);
    assert_eq!(out.n, N);
    // A state of another controller's size: no controller to ask.
    let other = {
        let mut c = ptr::null_mut();
        let mut st = ptr::null_mut();
        let mut params = defaults(2, AdaptimpLaw::Pd, AdaptimpPreset::Robot);
        params.impedance = AdaptimpImpedance::External.into();
        let joints = [AdaptimpJoint {
            kind: AdaptimpJointKind::Revolute.into(),
            origin: AdaptimpTransform {
                translation: [0.0, 0.0, 0.3],
                rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            },
            axis: [0.0, 0.0, 1.0],
            offset: 0.0,
        }; 2];
        let mut chain = ptr::null_mut();
        // SAFETY: valid arrays and structs.
        unsafe {
            assert_eq!(
                adaptimp_chain_new(joints.as_ptr(), 2, ptr::null(), &mut chain),
                AdaptimpStatus::Ok
            );
            let cart = cart_defaults();
            assert_eq!(
                adaptimp_cartesian_new(chain, &cart, &params, &mut c),
                AdaptimpStatus::Ok,
                "{}",
                last_error()
            );
            let q0 = [0.1, 0.2];
            assert_eq!(
                adaptimp_cartesian_state_new(c, 2, q0.as_ptr(), &mut st),
                AdaptimpStatus::Ok
            );
            adaptimp_chain_free(chain);
        }
        (c, st)
    };
    let mut out = AdaptimpCartesianCommand::ZERO;
    out.n = 5;
    // SAFETY: valid handles of different sizes.
    let s = unsafe {
        adaptimp_cartesian_step(
            p.cart,
            other.1,
            N,
            Q0.as_ptr(),
            dq.as_ptr(),
            wrench.as_ptr(),
            ptr::null(),
            &mut out,
        )
    };
    assert_eq!(s, AdaptimpStatus::WrongState);
    assert_eq!(out, AdaptimpCartesianCommand::ZERO);
    // SAFETY: made by the library, freed once.
    unsafe {
        adaptimp_cartesian_state_free(other.1);
        adaptimp_cartesian_free(other.0);
    }
}

#[test]
fn a_joint_controller_with_its_own_impedance_or_another_size_is_refused() {
    let chain = c_chain();
    let cart = cart_defaults();
    let mut joint = defaults(N, AdaptimpLaw::Pd, AdaptimpPreset::Robot);
    joint.eta2 = 25.0;
    let mut c = ptr::null_mut();
    // SAFETY: valid handles and structs.
    unsafe {
        assert_eq!(
            adaptimp_cartesian_new(chain, &cart, &joint, &mut c),
            AdaptimpStatus::InvalidConfig
        );
        assert!(
            last_error().contains("impedance = \"external\""),
            "{}",
            last_error()
        );
        joint.impedance = AdaptimpImpedance::External.into();
        let mut two = defaults(2, AdaptimpLaw::Pd, AdaptimpPreset::Robot);
        two.impedance = AdaptimpImpedance::External.into();
        assert_eq!(
            adaptimp_cartesian_new(chain, &cart, &two, &mut c),
            AdaptimpStatus::BadSize
        );
        assert_eq!(last_error(), "joint.n = 2, but the chain has 3 joints");
        let mut bad = cart;
        bad.clik_kd = 2000.0;
        assert_eq!(
            adaptimp_cartesian_new(chain, &bad, &joint, &mut c),
            AdaptimpStatus::InvalidConfig
        );
        assert!(last_error().contains("Ts·clik_kd < 1"));
        let mut bad = cart;
        bad.bd_critical = AdaptimpBoolRaw(2);
        assert_eq!(
            adaptimp_cartesian_new(chain, &bad, &joint, &mut c),
            AdaptimpStatus::InvalidConfig
        );
        assert_eq!(last_error(), "cart.bd_critical = 2 is not a bool (0 or 1)");
        let mut bad = cart;
        bad.md[1] = f64::NAN;
        assert_eq!(
            adaptimp_cartesian_new(chain, &bad, &joint, &mut c),
            AdaptimpStatus::InvalidConfig
        );
        assert!(c.is_null());
        // INFINITY is no clipping; a finite value clips; zero is refused.
        let mut clip = cart;
        clip.pos_error_max = 0.0;
        assert_eq!(
            adaptimp_cartesian_new(chain, &clip, &joint, &mut c),
            AdaptimpStatus::InvalidConfig
        );
        assert!(last_error().contains("pos_error_max > 0"));
        clip.pos_error_max = 0.01;
        assert_eq!(
            adaptimp_cartesian_new(chain, &clip, &joint, &mut c),
            AdaptimpStatus::Ok
        );
        adaptimp_cartesian_free(c);
        adaptimp_chain_free(chain);
    }
}

#[test]
fn the_cartesian_defaults_are_the_schemas() {
    let c = cart_defaults();
    let core = CartesianConfig::default();
    assert_eq!(c.md, [core.md[0], core.md[1], core.md[2]]);
    assert_eq!(c.kd, [500.0; 3]);
    assert_eq!(c.kd_rot, [20.0; 3]);
    assert_eq!(c.bd_critical, AdaptimpBoolRaw(1));
    assert_eq!(c.pos_error_max, f64::INFINITY);
    assert_eq!(c.force_feedforward, AdaptimpBoolRaw(1));
    assert_eq!((c.clik_kp, c.clik_kd), (core.clik_kp, core.clik_kd));
}

#[test]
fn a_posture_or_start_far_out_of_range_is_refused_when_given_by_name() {
    // Issue 33 C: set_posture(1e7) returned OK, then every step was OUT_OF_RANGE.
    let p = pair(AdaptimpLaw::Pd, Law::Pd);
    let far = [0.1, 1e7, 0.0];
    // SAFETY: valid handles; arrays of N reals.
    unsafe {
        let s = adaptimp_cartesian_set_posture(p.cart, p.state, N, far.as_ptr());
        assert_eq!(s, AdaptimpStatus::InvalidConfig);
        assert_eq!(
            last_error(),
            "posture[1] = 1e7 is beyond its limit ±1e6; the state was left unchanged"
        );
        // Within the ceiling, but farther than the posture task may pull.
        let pull = [Q0[0], Q0[1], 1e5];
        let s = adaptimp_cartesian_set_posture(p.cart, p.state, N, pull.as_ptr());
        assert_eq!(s, AdaptimpStatus::InvalidConfig);
        assert!(
            last_error().contains("null_k·|posture − q_d|[2]"),
            "{}",
            last_error()
        );
        let mut state = ptr::null_mut();
        let s = adaptimp_cartesian_state_new(p.cart, N, far.as_ptr(), &mut state);
        assert_eq!(s, AdaptimpStatus::InvalidConfig);
        assert!(state.is_null());
        assert_eq!(
            last_error(),
            "q0[1] = 1e7 is beyond its limit ±1e6; the state was left unchanged"
        );
        let s = adaptimp_cartesian_state_reset(p.cart, p.state, N, far.as_ptr());
        assert_eq!(s, AdaptimpStatus::InvalidConfig);
        // Nothing changed: the loop steps as a twin that never saw them.
        let near = [Q0[0] + 0.1, Q0[1], Q0[2]];
        assert_eq!(
            adaptimp_cartesian_set_posture(p.cart, p.state, N, near.as_ptr()),
            AdaptimpStatus::Ok
        );
    }
    for _ in 0..5 {
        let (s, out) = step(&p, &Q0, Some(&[0.0; N]), &[0.0; 6], None);
        assert_eq!(s, AdaptimpStatus::Ok, "{}", last_error());
        assert!(out.tau_sat[..N].iter().all(|t| t.is_finite()));
    }
}

#[test]
fn an_axis_whose_norm_overflows_is_normalised_and_a_huge_rate_refused() {
    // Issue 33 F: [0, 0, 1e200] made a zero axis (J = 0, fk ignoring q).
    let (mut js, tip) = joints();
    let (mut big, mut unit) = (ptr::null_mut(), ptr::null_mut());
    // SAFETY: valid arrays and out pointers.
    unsafe {
        assert_eq!(
            adaptimp_chain_new(js.as_ptr(), js.len(), &tip, &mut unit),
            AdaptimpStatus::Ok
        );
        js[1].axis = [0.0, 0.0, 1e200];
        assert_eq!(
            adaptimp_chain_new(js.as_ptr(), js.len(), &tip, &mut big),
            AdaptimpStatus::Ok
        );
        let zero = std::mem::MaybeUninit::<AdaptimpTip>::zeroed();
        let (mut a, mut b) = (zero.assume_init(), zero.assume_init());
        assert_eq!(
            adaptimp_chain_tip(unit, N, Q0.as_ptr(), ptr::null(), &mut a),
            AdaptimpStatus::Ok
        );
        assert_eq!(
            adaptimp_chain_tip(big, N, Q0.as_ptr(), ptr::null(), &mut b),
            AdaptimpStatus::Ok
        );
        assert_eq!(a, b);
        assert!(b.jacobian[5][0] != 0.0);
        // A rate whose J̇ q̇ overflowed (NaN with OK): refused by name.
        let huge = [1e200, 0.0, 0.0];
        let mut c = a;
        let s = adaptimp_chain_tip(unit, N, Q0.as_ptr(), huge.as_ptr(), &mut c);
        assert_eq!(s, AdaptimpStatus::OutOfRange);
        assert_eq!(
            last_error(),
            "dq[0] = 1e200 is beyond its limit ±1e6; the state was left unchanged"
        );
        adaptimp_chain_free(big);
        adaptimp_chain_free(unit);
    }
}

/// A URDF arm of more joints than a chain holds: BAD_SIZE, naming its
/// joints and what to do; holding one gives the chain of the rest.
#[test]
fn a_urdf_arm_of_eight_joints_is_refused_by_name_and_read_with_one_held() {
    let mut urdf = String::from("<robot name='eight'><link name='l0'/>");
    for i in 0..8 {
        urdf += &format!(
            "<link name='l{}'><inertial><mass value='1'/><inertia ixx='0.01' ixy='0' ixz='0' \
             iyy='0.01' iyz='0' izz='0.01'/></inertial></link>\
             <joint name='j{i}' type='revolute'><parent link='l{i}'/><child link='l{}'/>\
             <origin xyz='0 0 0.1'/><axis xyz='0 0 1'/>\
             <limit lower='-1' upper='1' effort='5' velocity='1'/></joint>",
            i + 1,
            i + 1
        );
    }
    urdf += "</robot>\0";
    let source = urdf.as_ptr().cast();
    let mut chain = ptr::null_mut();
    // SAFETY: NUL-terminated text, a valid out pointer.
    let s = unsafe {
        adaptimp_chain_from_urdf(
            source,
            ptr::null(),
            ptr::null(),
            0,
            &mut chain,
            ptr::null_mut(),
        )
    };
    assert_eq!(s, AdaptimpStatus::BadSize);
    assert!(chain.is_null());
    assert!(
        last_error().ends_with(
            "the arm has 8 joints (j0, j1, j2, j3, j4, j5, j6, j7); a chain has at most 7: \
             hold some with fix"
        ),
        "{}",
        last_error()
    );
    let fix = [c"j7".as_ptr()];
    // SAFETY: as above, one NUL-terminated name.
    let s = unsafe {
        adaptimp_chain_from_urdf(
            source,
            ptr::null(),
            fix.as_ptr(),
            1,
            &mut chain,
            ptr::null_mut(),
        )
    };
    assert_eq!(s, AdaptimpStatus::Ok, "{}", last_error());
    // SAFETY: a live chain.
    unsafe {
        assert_eq!(adaptimp_chain_joints(chain), 7);
        adaptimp_chain_free(chain);
    }
}

/// SPEC (23.7) through the C ABI: the core's Λ bit for bit, row-major; the
/// refusals are statuses naming the input, `out` untouched.
#[test]
fn the_operational_inertia_is_the_cores_and_refuses_by_name() {
    // A planar arm of two unit links at (0, π/2), D = diag(2, 1) kg m².
    let j = [
        -1.0, -1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, //
    ];
    let d = [2.0, 0.0, 0.0, 1.0];
    let call = |n: usize, j: *const f64, d: *const f64, out: *mut f64| {
        // SAFETY: the pointers are NULL or hold what `n` asks for.
        unsafe { adaptimp_operational_inertia(n, j, d, false, out) }
    };
    let mut out = [7.0; 36];
    assert_eq!(
        call(2, j.as_ptr(), d.as_ptr(), out.as_mut_ptr()),
        AdaptimpStatus::Ok
    );
    let core = adaptimp::dynamic::operational_inertia(&j, &d, false).unwrap();
    assert_eq!(out, core);
    assert!(
        (out[7] - 3.0).abs() < 1e-14,
        "Λ_yy = {} (hand-computed: 3)",
        out[7]
    );
    let mut out = [7.0; 36];
    assert_eq!(
        call(0, j.as_ptr(), d.as_ptr(), out.as_mut_ptr()),
        AdaptimpStatus::BadSize
    );
    assert_eq!(last_error(), "n = 0: the number of joints must be 1 … 7");
    assert_eq!(
        call(2, ptr::null(), d.as_ptr(), out.as_mut_ptr()),
        AdaptimpStatus::NullPointer
    );
    assert!(last_error().contains("jacobian"), "{}", last_error());
    assert_eq!(
        call(2, j.as_ptr(), ptr::null(), out.as_mut_ptr()),
        AdaptimpStatus::NullPointer
    );
    assert!(last_error().contains("inertia"), "{}", last_error());
    assert_eq!(
        call(2, j.as_ptr(), d.as_ptr(), ptr::null_mut()),
        AdaptimpStatus::NullPointer
    );
    assert!(last_error().contains("out"), "{}", last_error());
    let skew = [2.0, 0.5, 0.0, 1.0];
    assert_eq!(
        call(2, j.as_ptr(), skew.as_ptr(), out.as_mut_ptr()),
        AdaptimpStatus::InvalidConfig
    );
    assert_eq!(
        last_error(),
        "inertia: must be symmetric (D_ij = D_ji to 1e-12 relative)"
    );
    let nan = [2.0, 0.0, 0.0, f64::NAN];
    assert_eq!(
        call(2, j.as_ptr(), nan.as_ptr(), out.as_mut_ptr()),
        AdaptimpStatus::InvalidConfig
    );
    assert_eq!(last_error(), "inertia[3] is not finite (NaN or infinite)");
    assert_eq!(out, [7.0; 36]);
}
