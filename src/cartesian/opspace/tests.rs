use super::*;
use crate::types::Vector;
use proptest::prelude::*;

/// A planar arm of two unit links at q = (0, π/2) (rows x, y and ω_z move;
/// J_v = [[−1, −1], [1, 0], [0, 0]], J_ω = [[0, 0], [0, 0], [1, 1]]) with
/// D = diag(2, 1) kg m².
fn two_link() -> (Jacobian6<2>, Matrix<2>) {
    let mut j = Jacobian6::<2>::zeros();
    j[(0, 0)] = -1.0;
    j[(0, 1)] = -1.0;
    j[(1, 0)] = 1.0;
    j[(5, 0)] = 1.0;
    j[(5, 1)] = 1.0;
    (j, Matrix::<2>::from_diagonal(&Vector::<2>::new(2.0, 1.0)))
}

fn close(got: &Matrix<6>, want: &Matrix<6>, tol: f64) {
    let err = (got - want).abs().max();
    assert!(err <= tol, "Λ = {got}, expected {want}: off by {err}");
}

#[test]
fn the_two_link_arms_lambda_is_the_hand_computed_one() {
    let (j, d) = two_link();
    // Uncoupled: Λ_v = [[1.5, −0.5], [−0.5, 0.5]]⁻¹ = [[1, 1], [1, 3]] on
    // (x, y), 0 on z; Λ_ω = (J_ω D⁻¹ J_ωᵀ)⁺ = 1/1.5 on ω_z, 0 on ω_x, ω_y.
    let mut want = Matrix::<6>::zeros();
    want[(0, 0)] = 1.0;
    want[(0, 1)] = 1.0;
    want[(1, 0)] = 1.0;
    want[(1, 1)] = 3.0;
    want[(5, 5)] = 2.0 / 3.0;
    close(&operational_inertia(&j, &d, true).unwrap(), &want, 1e-14);
    // Coupled: B = J's rows (x, y, ω_z) has full column rank, so
    // (B D⁻¹ Bᵀ)⁺ = B⁺ᵀ D B⁺, B⁺ = (BᵀB)⁻¹Bᵀ = [[0, 1, 0], [−½, −1, ½]].
    let mut want = Matrix::<6>::zeros();
    for (r, &a) in [0usize, 1, 5].iter().enumerate() {
        for (c, &b) in [0usize, 1, 5].iter().enumerate() {
            want[(a, b)] = [[0.25, 0.5, -0.25], [0.5, 3.0, -0.5], [-0.25, -0.5, 0.25]][r][c];
        }
    }
    close(&operational_inertia(&j, &d, false).unwrap(), &want, 1e-14);
}

#[test]
fn a_block_the_joints_do_not_move_is_zero() {
    // Two prismatic joints along x and y: J_ω = 0, so Λ_ω = 0⁺ = 0 (NumPy's
    // pinv of the zero matrix), and Λ_v = D on (x, y).
    let mut j = Jacobian6::<2>::zeros();
    j[(0, 0)] = 1.0;
    j[(1, 1)] = 1.0;
    let d = Matrix::<2>::new(3.0, 1.0, 1.0, 2.0);
    let mut want = Matrix::<6>::zeros();
    want.fixed_view_mut::<2, 2>(0, 0).copy_from(&d);
    for uncoupled in [true, false] {
        close(
            &operational_inertia(&j, &d, uncoupled).unwrap(),
            &want,
            1e-14,
        );
    }
}

#[test]
fn the_refusals_name_the_input() {
    let (j, d) = two_link();
    let mut nan = j;
    nan[(1, 0)] = f64::NAN;
    let e = operational_inertia(&nan, &d, true).unwrap_err();
    assert_eq!(
        e,
        Error::NonFinite {
            what: "jacobian",
            index: 1
        }
    );
    let mut inf = d;
    inf[(1, 1)] = f64::INFINITY;
    let e = operational_inertia(&j, &inf, true).unwrap_err();
    assert_eq!(e.to_string(), "inertia[3] is not finite (NaN or infinite)");
    let skew = Matrix::<2>::new(2.0, 0.1, 0.0, 1.0);
    let e = operational_inertia(&j, &skew, true).unwrap_err();
    assert_eq!(
        e.to_string(),
        "inertia: must be symmetric (D_ij = D_ji to 1e-12 relative)"
    );
    let singular = Matrix::<2>::new(1.0, 1.0, 1.0, 1.0);
    let e = operational_inertia(&j, &singular, true).unwrap_err();
    assert_eq!(
        e.to_string(),
        "inertia: must be positive definite (its Cholesky factorisation failed: D is singular)"
    );
    let tiny = Matrix::<2>::from_diagonal(&Vector::<2>::new(1e-320, 1.0));
    let e = operational_inertia(&j, &tiny, true).unwrap_err();
    assert_eq!(
        e.to_string(),
        "J D⁻¹ Jᵀ: beyond f64 (a jacobian too large, or an inertia too near singular)"
    );
    let mut huge = j;
    huge[(0, 0)] = 1e300;
    let e = operational_inertia(&huge, &d, false).unwrap_err();
    assert!(e.to_string().starts_with("J D⁻¹ Jᵀ: beyond f64"), "{e}");
    // Λ = 1/(J D⁻¹ Jᵀ) beyond f64: a one-joint arm that barely moves its tip.
    let jt = Jacobian6::<1>::from_column_slice(&[1e-160, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let e = operational_inertia(&jt, &Matrix::<1>::new(1.0), true).unwrap_err();
    let near_zero =
        "Λ: beyond f64 (J D⁻¹ Jᵀ too near zero: a jacobian near 0, or an inertia too large)";
    assert_eq!(e.to_string(), near_zero);
    // Smaller still, J D⁻¹ Jᵀ underflows to exactly zero: refused as well,
    // not taken for a direction the joints cannot move (whose Λ is 0), in
    // either form and in a rotation block alone.
    for scale in [1e-162, 1e-200, f64::MIN_POSITIVE] {
        let jt = Jacobian6::<1>::from_column_slice(&[scale, 0.0, 0.0, 0.0, 0.0, 0.0]);
        for uncoupled in [true, false] {
            let e = operational_inertia(&jt, &Matrix::<1>::new(1.0), uncoupled).unwrap_err();
            assert_eq!(e.to_string(), near_zero, "scale {scale:e}");
        }
    }
    let mut rot = j;
    for r in 3..6 {
        for c in 0..2 {
            rot[(r, c)] *= 1e-200;
        }
    }
    let e = operational_inertia(&rot, &d, true).unwrap_err();
    assert_eq!(e.to_string(), near_zero);
}

#[test]
fn the_run_time_door_is_the_typed_function_row_major() {
    use crate::dynamic::operational_inertia as run_time;
    let (j, d) = two_link();
    let flat_j: std::vec::Vec<f64> = j.transpose().iter().copied().collect();
    let flat_d: std::vec::Vec<f64> = d.transpose().iter().copied().collect();
    for uncoupled in [true, false] {
        let typed = operational_inertia(&j, &d, uncoupled).unwrap();
        let got = run_time(&flat_j, &flat_d, uncoupled).unwrap();
        assert_eq!(Matrix::<6>::from_row_slice(&got), typed);
    }
    let shape = |e: Error| e.to_string();
    assert_eq!(
        shape(run_time(&flat_j[..11], &flat_d, true).unwrap_err()),
        "jacobian: needs 6 × n values, row-major, n = 1 … 7 joints"
    );
    assert_eq!(
        shape(run_time(&[0.0; 48], &[0.0; 64], true).unwrap_err()),
        "jacobian: needs 6 × n values, row-major, n = 1 … 7 joints"
    );
    assert_eq!(
        shape(run_time(&[], &[], true).unwrap_err()),
        "jacobian: needs 6 × n values, row-major, n = 1 … 7 joints"
    );
    assert_eq!(
        shape(run_time(&flat_j, &flat_d[..3], true).unwrap_err()),
        "inertia: needs n × n values, row-major (n: the jacobian's columns)"
    );
    // Non-finite entries are indexed as the caller laid them out (row-major).
    let mut nan = flat_j.clone();
    nan[1] = f64::NAN;
    assert_eq!(
        run_time(&nan, &flat_d, true).unwrap_err(),
        Error::NonFinite {
            what: "jacobian",
            index: 1
        }
    );
}

/// A well-conditioned 6 × 7 Jacobian and 7 × 7 inertia from entries in ±1.
fn arm(jv: &[f64], dv: &[f64]) -> (Jacobian6<7>, Matrix<7>) {
    let mut j = Jacobian6::<7>::from_row_slice(jv);
    for k in 0..6 {
        j[(k, k)] += 3.0;
    }
    let b = Matrix::<7>::from_row_slice(dv);
    let d = b * b.transpose() + Matrix::<7>::identity();
    (j, d)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// With J of full row rank, Λ is the inverse: J D⁻¹ Jᵀ Λ = I (coupled),
    /// and each block's product is I₃ (uncoupled).
    #[test]
    fn lambda_inverts_j_d_inv_jt_when_j_has_full_rank(
        jv in proptest::collection::vec(-1.0f64..1.0, 42),
        dv in proptest::collection::vec(-1.0f64..1.0, 49),
    ) {
        let (j, d) = arm(&jv, &dv);
        let a = j * d.cholesky().unwrap().inverse() * j.transpose();
        let full = operational_inertia(&j, &d, false).unwrap();
        prop_assert!((a * full - Matrix::<6>::identity()).abs().max() < 1e-10);
        prop_assert_eq!(full, full.transpose());
        let blocks = operational_inertia(&j, &d, true).unwrap();
        prop_assert_eq!(blocks, blocks.transpose());
        for k in [0, 3] {
            let ak = a.fixed_view::<3, 3>(k, k);
            let lk = blocks.fixed_view::<3, 3>(k, k);
            prop_assert!((ak * lk - Matrix::<3>::identity()).abs().max() < 1e-10);
        }
        prop_assert_eq!(blocks.fixed_view::<3, 3>(0, 3).abs().max(), 0.0);
        prop_assert_eq!(blocks.fixed_view::<3, 3>(3, 0).abs().max(), 0.0);
    }
}
