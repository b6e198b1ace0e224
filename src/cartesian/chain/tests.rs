use super::*;

/// A 3-joint arm with every kind of element ([`sample_joints`]).
fn arm() -> Chain<3> {
    Chain::new(
        &sample_joints(),
        &Transform::from_xyz_rpy([0.0, 0.0, 0.15], [0.1, 0.2, 0.3]),
    )
    .unwrap()
}

#[test]
fn jacobian_and_bias_are_the_derivatives_of_the_pose() {
    let c = arm();
    let q = Vector::<3>::new(0.4, 0.12, -0.7);
    let dq = Vector::<3>::new(0.9, -0.3, 1.4);
    let h = 1e-6;
    let j = c.jacobian(&q);
    for i in 0..3 {
        let mut e = Vector::<3>::zeros();
        e[i] = h;
        let dp = (c.fk(&(q + e)) - c.fk(&(q - e))) / (2.0 * h);
        let dr = c.rotation(&(q + e)) * c.rotation(&(q - e)).inverse();
        let w = crate::cartesian::rotation::log_quaternion(
            &nalgebra::UnitQuaternion::from_rotation_matrix(&dr),
        ) / (2.0 * h);
        assert!(
            (dp - j.fixed_view::<3, 1>(0, i)).norm() < 1e-8,
            "J_v column {i}"
        );
        assert!(
            (w - j.fixed_view::<3, 1>(3, i)).norm() < 1e-8,
            "J_ω column {i}"
        );
    }
    let numeric = (c.jacobian(&(q + h * dq)) - c.jacobian(&(q - h * dq))) / (2.0 * h) * dq;
    let bias = c.jdot_qdot(&q, &dq);
    assert!((bias - numeric).norm() < 1e-7, "{bias} vs {numeric}");
}

#[test]
fn bad_descriptions_are_refused_by_name() {
    let ok = Joint::revolute(Transform::IDENTITY, [0.0, 0.0, 1.0]);
    let e = Chain::<1>::new(
        &[Joint::revolute(Transform::IDENTITY, [0.0; 3])],
        &Transform::IDENTITY,
    )
    .unwrap_err();
    assert!(e.to_string().contains("‖axis‖ > 0"), "{e}");
    assert!(e.to_string().contains("joint axis[0]"), "{e}");
    let mut skew = Transform::IDENTITY;
    skew.rotation[0][1] = 0.1;
    let e = Chain::<1>::new(
        &[Joint::revolute(skew, [0.0, 0.0, 1.0])],
        &Transform::IDENTITY,
    )
    .unwrap_err();
    assert!(e.to_string().contains("orthonormal"), "{e}");
    let e = Chain::<2>::new(&[ok], &Transform::IDENTITY).unwrap_err();
    assert!(e.to_string().contains("movable joints = 1"), "{e}");
    let e = Chain::<8>::new(&[ok; 8], &Transform::IDENTITY).unwrap_err();
    assert!(e.to_string().contains("1 ≤ n ≤ 7"), "{e}");
    assert!(Transform::from_pos_quat([0.0; 3], [0.0; 4]).is_err());
    let mut m = [0.0; 16];
    (m[0], m[3], m[5], m[10], m[15]) = (1.0, 0.4, 1.0, 1.0, 1.0);
    let t = Transform::from_matrix(&m).unwrap();
    assert_eq!(
        (t.translation, t.rotation),
        ([0.4, 0.0, 0.0], Transform::IDENTITY.rotation)
    );
    for bad in [0.5, f64::NAN] {
        m[14] = bad;
        let e = Transform::from_matrix(&m).unwrap_err().to_string();
        assert!(
            e.contains("last row of a homogeneous transform") && e.contains("m[3][2]"),
            "{e}"
        );
    }
}

#[test]
fn an_axis_whose_norm_overflows_or_underflows_is_normalised_not_zeroed() {
    // ‖[0, 0, 1e200]‖ overflows: it made a zero axis (J = 0, fk ignored q).
    let unit = Chain::<1>::new(
        &[Joint::revolute(Transform::IDENTITY, [0.0, 0.0, 1.0])],
        &Transform::from_xyz_rpy([0.3, 0.0, 0.0], [0.0; 3]),
    )
    .unwrap();
    for axis in [[0.0, 0.0, 1e200], [0.0, 0.0, f64::MAX], [0.0, 0.0, 1e-11]] {
        let c = Chain::<1>::new(
            &[Joint::revolute(Transform::IDENTITY, axis)],
            &Transform::from_xyz_rpy([0.3, 0.0, 0.0], [0.0; 3]),
        )
        .unwrap();
        let q = Vector::<1>::new(0.7);
        assert_eq!(c.jacobian(&q), unit.jacobian(&q), "{axis:?}");
        assert_eq!(c.fk(&q), unit.fk(&q), "{axis:?}");
    }
    // Below 1e-12 (a subnormal one too) it is no axis.
    let e = Chain::<1>::new(
        &[Joint::revolute(Transform::IDENTITY, [0.0, 1e-320, 0.0])],
        &Transform::IDENTITY,
    )
    .unwrap_err();
    assert!(e.to_string().contains("‖axis‖ > 0"), "{e}");
}

#[test]
fn rotations_within_the_tolerance_are_made_orthonormal() {
    // Seven origins each 5e-7 off (accepted, within 1e-6): the product
    // was 8e-6 from a rotation (det 1.0000084).
    let mut sloppy = Transform::from_xyz_rpy([0.0, 0.0, 0.1], [0.3, -0.2, 0.5]);
    for row in &mut sloppy.rotation {
        for v in row.iter_mut() {
            *v *= 1.0 + 2.5e-7;
        }
    }
    let joints = [Joint::revolute(sloppy, [0.0, 0.0, 1.0]); 7];
    let c = Chain::<7>::new(&joints, &sloppy).unwrap();
    let r = c.rotation(&Vector::<7>::from_element(0.2));
    let m = r.matrix();
    assert!((m.transpose() * m - Matrix3::identity()).amax() < 1e-14);
    assert!((m.determinant() - 1.0).abs() < 1e-14, "{}", m.determinant());
    // An orthonormal one (to rounding) is kept as given, bit for bit.
    let exact = Transform::from_xyz_rpy([0.0; 3], [0.3, -0.2, 0.5]);
    assert_eq!(exact.check(0).unwrap().r, exact.matrix());
}

#[test]
fn a_checked_tip_refuses_inputs_beyond_the_ceilings_by_name() {
    let c = Chain::<2>::new(
        &[
            Joint::revolute(Transform::IDENTITY, [0.0, 0.0, 1.0]),
            Joint::revolute(
                Transform::from_xyz_rpy([0.3, 0.0, 0.0], [0.0; 3]),
                [0.0, 1.0, 0.0],
            ),
        ],
        &Transform::from_xyz_rpy([0.2, 0.0, 0.0], [0.0; 3]),
    )
    .unwrap();
    let q = Vector::<2>::new(0.1, 0.2);
    // J̇ q̇ at q̇ = 1e200 was −inf with an OK status.
    let e = c
        .tip_checked(&q, &Vector::<2>::new(1e200, 0.0))
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "dq[0] = 1e200 is beyond its limit ±1e6; the state was left unchanged"
    );
    let e = c
        .tip_checked(&Vector::<2>::new(0.0, f64::NAN), &q)
        .unwrap_err();
    assert_eq!(e.to_string(), "q[1] is not finite (NaN or infinite)");
    let t = c.tip_checked(&q, &Vector::<2>::from_element(1e6)).unwrap();
    assert!(t.bias.iter().all(|x| x.is_finite()));
    assert_eq!(t, c.tip(&q, &Vector::<2>::from_element(1e6)));
}

#[test]
fn an_axis_of_any_finite_length_is_its_direction() {
    let tip = Transform::from_xyz_rpy([0.3, 0.1, 0.0], [0.0, 0.0, 0.0]);
    let unit = Chain::<1>::new(
        &[Joint::revolute(Transform::IDENTITY, [1.0, 0.0, 0.0])],
        &tip,
    )
    .unwrap();
    for axis in [[1e300, 0.0, 0.0], [1e300, 0.0, 1.0], [1e-10, 0.0, 0.0]] {
        let c = Chain::<1>::new(&[Joint::revolute(Transform::IDENTITY, axis)], &tip).unwrap();
        let q = Vector::<1>::new(0.7);
        let (a, b) = (c.pose(&q), unit.pose(&q));
        assert!((a.0 - b.0).norm() < 1e-15, "{axis:?}");
        assert!((a.1.matrix() - b.1.matrix()).norm() < 1e-15, "{axis:?}");
    }
}

#[test]
fn offset_shifts_the_joint_value() {
    let origin = Transform::from_xyz_rpy([0.1, 0.0, 0.0], [0.0, 0.0, 0.0]);
    let tip = Transform::from_xyz_rpy([0.3, 0.0, 0.0], [0.0, 0.0, 0.0]);
    let plain = Chain::<1>::new(&[Joint::revolute(origin, [0.0, 0.0, 1.0])], &tip).unwrap();
    let shifted = Chain::<1>::new(
        &[Joint {
            offset: 0.4,
            ..Joint::revolute(origin, [0.0, 0.0, 1.0])
        }],
        &tip,
    )
    .unwrap();
    let q = Vector::<1>::new(0.9);
    let a = plain.fk(&Vector::<1>::new(0.5));
    let b = shifted.fk(&q);
    assert!((a - b).norm() < 1e-15, "{a} vs {b}");
}
