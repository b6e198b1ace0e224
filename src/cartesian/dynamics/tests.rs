use super::*;
use crate::cartesian::chain::Transform;

/// The chain tests' joints (every kind of element; the fixed elbow
/// carries a second inertial), inertials with rotated axes.
fn arm() -> Dynamics<3> {
    let joints = crate::cartesian::chain::sample_joints();
    let inertial = |m: f64, xyz: [f64; 3], rpy: [f64; 3], d: [f64; 3]| Inertial {
        mass: m,
        origin: Transform::from_xyz_rpy(xyz, rpy),
        inertia: [[d[0], 0.01, 0.0], [0.01, d[1], 0.002], [0.0, 0.002, d[2]]],
    };
    let inertials = [
        inertial(5.0, [0.0; 3], [0.0; 3], [1.0; 3]),
        inertial(2.0, [0.1, 0.02, 0.05], [0.3, 0.1, -0.2], [0.05, 0.04, 0.03]),
        inertial(
            1.5,
            [0.15, 0.0, -0.01],
            [0.0, 0.2, 0.0],
            [0.02, 0.03, 0.025],
        ),
        inertial(
            0.7,
            [0.05, 0.01, 0.0],
            [0.1, 0.0, 0.4],
            [0.01, 0.012, 0.011],
        ),
        inertial(0.9, [0.0, 0.1, 0.03], [-0.2, 0.3, 0.1], [0.015, 0.01, 0.02]),
    ];
    Dynamics::new(&joints, &inertials, [0.3, -0.2, -9.81]).unwrap()
}

fn state() -> (Vector<3>, Vector<3>, Vector<3>) {
    (
        Vector::<3>::new(0.4, 0.12, -0.7),
        Vector::<3>::new(0.9, -0.3, 1.4),
        Vector::<3>::new(-1.1, 0.6, 2.0),
    )
}

#[test]
fn the_mass_matrix_is_symmetric_positive_definite() {
    let d = arm();
    let (q, _, _) = state();
    let m = d.mass_matrix(&q);
    let mut raw = Matrix::<3>::zeros();
    for j in 0..3 {
        let mut e = Vector::<3>::zeros();
        e[j] = 1.0;
        raw.set_column(j, &d.mass_times(&q, &e));
    }
    assert!((raw - raw.transpose()).amax() < 1e-12, "{raw}");
    assert!(m.cholesky().is_some(), "{m}");
    // Affine in q̈ with the mass matrix as its slope.
    let (q, dq, ddq) = state();
    let lhs = d.inverse_dynamics(&q, &dq, &ddq) - d.inverse_dynamics(&q, &dq, &Vector::zeros());
    assert!((lhs - m * ddq).amax() < 1e-12, "{lhs} vs {}", m * ddq);
}

/// The potential energy −Σ m_i gᵀ p_ci from the bodies' centres of mass.
fn potential(d: &Dynamics<3>, q: &Vector<3>) -> f64 {
    let mut v = 0.0;
    d.chain
        .walk(q, &Vector::zeros(), None, Vector3::zeros(), |i, m| {
            let b = &d.bodies[i];
            v -= d.gravity.dot(&(b.m * m.c + m.r * b.h));
        });
    v
}

#[test]
fn gravity_compensation_lifts_its_share_of_each_weight() {
    // Every link's whole weight lifted (MuJoCo's gravcomp = 1): no
    // gravity torque, the rest of inverse dynamics unchanged; half of it:
    // half the gravity torque.
    let joints = crate::cartesian::chain::sample_joints();
    let d = arm();
    let (q, dq, ddq) = state();
    let inertials = [
        (5.0, [0.0; 3]),
        (2.0, [0.1, 0.02, 0.05]),
        (1.5, [0.15, 0.0, -0.01]),
        (0.7, [0.05, 0.01, 0.0]),
        (0.9, [0.0, 0.1, 0.03]),
    ];
    let lift = |share: f64| {
        inertials.map(|(m, c)| Lifted {
            mass: share * m,
            moment: c.map(|x| share * m * x),
        })
    };
    let whole = d.with_gravity_compensation(&joints, &lift(1.0)).unwrap();
    assert!(whole.gravity_torque(&q).amax() < 1e-12);
    let free = d.inverse_dynamics(&q, &dq, &ddq) - d.gravity_torque(&q);
    assert!((whole.inverse_dynamics(&q, &dq, &ddq) - free).amax() < 1e-12);
    let half = d.with_gravity_compensation(&joints, &lift(0.5)).unwrap();
    assert!((half.gravity_torque(&q) - 0.5 * d.gravity_torque(&q)).amax() < 1e-12);
    // Scaled with the masses; refused on other joints.
    let scaled = half.scaled(2.0).unwrap();
    assert!((scaled.gravity_torque(&q) - d.gravity_torque(&q)).amax() < 1e-12);
    assert!(d
        .with_gravity_compensation(&joints[1..], &lift(1.0)[1..])
        .is_err());
}

#[test]
fn gravity_is_the_gradient_of_the_potential_energy() {
    let d = arm();
    let (q, _, _) = state();
    let g = d.gravity_torque(&q);
    let h = 1e-6;
    for i in 0..3 {
        let mut e = Vector::<3>::zeros();
        e[i] = h;
        let num = (potential(&d, &(q + e)) - potential(&d, &(q - e))) / (2.0 * h);
        assert!((num - g[i]).abs() < 1e-7, "joint {i}: {num} vs {}", g[i]);
    }
}

#[test]
fn the_power_of_the_torque_is_the_rate_of_the_kinetic_energy() {
    // q̇ᵀ(τ − G) = d/dt (½ q̇ᵀ M q̇) along q(t) = q0 + t q̇0 + t²/2 q̈0.
    let d = arm();
    let (q0, dq0, ddq) = state();
    let at = |t: f64| (q0 + t * dq0 + 0.5 * t * t * ddq, dq0 + t * ddq);
    let kinetic = |t: f64| {
        let (q, dq) = at(t);
        0.5 * dq.dot(&(d.mass_matrix(&q) * dq))
    };
    let h = 1e-5;
    let rate = (kinetic(h) - kinetic(-h)) / (2.0 * h);
    let power = dq0.dot(&(d.inverse_dynamics(&q0, &dq0, &ddq) - d.gravity_torque(&q0)));
    assert!((rate - power).abs() < 1e-7, "{rate} vs {power}");
}

#[test]
fn scale_and_payload_change_the_model_as_stated() {
    let d = arm();
    let (q, dq, ddq) = state();
    let tau = d.inverse_dynamics(&q, &dq, &ddq);
    let scaled = d.scaled(1.3).unwrap().inverse_dynamics(&q, &dq, &ddq);
    assert!((scaled - 1.3 * tau).amax() < 1e-12);
    // A payload at the last origin weighs on every joint by its gravity.
    let loaded = d.with_payload(2.0).unwrap();
    assert!((loaded.mass() - d.mass() - 2.0).abs() < 1e-15);
    assert!(d.scaled(0.0).is_err() && d.with_payload(-1.0).is_err());
}

#[test]
fn a_model_that_would_overflow_in_use_is_refused_by_name() {
    let d = arm();
    let e = d.scaled(1e300).unwrap_err();
    assert_eq!(
        e.to_string(),
        "condition |value| ≤ 1e9 is violated: mass_scale = 1e300 (SPEC §10)"
    );
    let e = d.with_payload(1e300).unwrap_err();
    assert_eq!(
        e.to_string(),
        "condition |value| ≤ 1e9 is violated: payload = 1e300 (SPEC §10)"
    );
    assert!(
        d.scaled(1e9).is_err(),
        "each link's mass then beyond 1e9 kg"
    );
    let (q, dq, ddq) = state();
    assert_eq!(
        d.inverse_dynamics_checked(&q, &dq, &ddq),
        Ok(d.inverse_dynamics(&q, &dq, &ddq))
    );
    let mut huge = dq;
    huge[0] = 1e200; // the torque was NaN
    let e = d.inverse_dynamics_checked(&q, &huge, &ddq).unwrap_err();
    assert_eq!(
        e.to_string(),
        "dq[0] = 1e200 is beyond its limit ±1e6; the state was left unchanged"
    );
    assert!(d.mass_matrix_checked(&(q * 1e300)).is_err());
}

fn sampled(regularisation: f64, rate: f64) -> SampledDrive<3> {
    SampledDrive {
        substep: 2.5e-4,
        substeps: 4,
        implicit_damping: true,
        semi_implicit: true,
        regularisation: Vector::from_element(regularisation),
        rate: Vector::from_element(rate),
    }
}

#[test]
fn the_plants_period_is_inverted_as_stated() {
    // (20.9) with damping only, implicit steps: the closed form
    // u = b v0 + b a s h / (1 − ρ^s), ρ = m / (m + h b), beside ID's m a + b v0.
    let (q, dq, a) = state();
    let drive = Drive {
        armature: Vector::<3>::new(0.1, 0.0, 0.0),
        damping: Vector::<3>::new(1.5, 0.0, 40.0),
        friction: Vector::zeros(),
    };
    let d = arm().with_drive(drive).unwrap();
    let s = sampled(0.0, 0.0);
    let p = d.with_sampled_drive(s).unwrap();
    let tau = p.drive_torque(&q, &dq, &a, &dq);
    let m = p.mass_matrix(&q);
    for i in [0, 2] {
        let (mi, b) = (m[(i, i)], drive.damping[i]);
        let rho = mi / (mi + s.substep * b);
        let u = b * dq[i] + b * a[i] * 1e-3 / (1.0 - libm::pow(rho, 4.0));
        let want = u - (mi * a[i] + b * dq[i]);
        assert!(
            (tau[i] - want).abs() < 1e-9 * (1.0 + u.abs()),
            "{i}: {tau} vs {want}"
        );
    }
    assert_eq!(tau[1], 0.0, "no damping, no friction: ID's torque exactly");
    // First order in h b/m: the damping of the period's mean velocity.
    let first = drive.damping[0] * (1e-3 + s.substep) / 2.0 * a[0];
    assert!(
        (tau[0] - first).abs() < 0.05 * first.abs(),
        "{} vs {first}",
        tau[0]
    );
    // Friction only, far beyond its bound (|q̇| ≫ F R / b_r): (20.6)'s F sign(q̇).
    let drive = Drive {
        armature: Vector::zeros(),
        damping: Vector::zeros(),
        friction: Vector::<3>::new(2.0, 1.0, 0.5),
    };
    let f = arm()
        .with_drive(drive)
        .unwrap()
        .with_sampled_drive(sampled(1e-6, 100.0))
        .unwrap();
    let v = Vector::<3>::new(1.0, -0.5, 2.0);
    let tau = f.drive_torque(&q, &v, &a, &v);
    let want = Vector::<3>::new(2.0, -1.0, 0.5);
    assert!((tau - want).amax() < 1e-9, "{tau} vs {want}");
    // Below the bound it is MuJoCo's regularised force: at rest, asked
    // for no acceleration, nothing; a light joint's friction with a
    // large R is a small damping b_r/R q̇, not F.
    let rest = Vector::<3>::zeros();
    assert!(f.drive_torque(&q, &rest, &rest, &rest).amax() < 1e-12);
    let soft = arm()
        .with_drive(drive)
        .unwrap()
        .with_sampled_drive(sampled(1e4, 100.0))
        .unwrap()
        .drive_torque(&q, &v, &rest, &v);
    let damping = v * (100.0 / 1e4);
    assert!(
        (soft - damping).amax() < 0.1 * damping.amax(),
        "{soft} vs {damping}"
    );
    // Without a SampledDrive: (20.6) as before.
    let plain = arm().with_drive(drive).unwrap();
    assert_eq!(
        plain.drive_torque(&q, &v, &a, &v),
        drive.friction_torque(&v, &v)
    );
}

#[test]
fn a_semi_implicit_plants_velocity_is_half_a_step_old() {
    // (20.9'): h/2 for semi-implicit steps; 0 for RK4 or no SampledDrive.
    let d = arm();
    assert_eq!(d.velocity_lag(), 0.0);
    let s = sampled(1.0, 1.0);
    assert_eq!(d.with_sampled_drive(s).unwrap().velocity_lag(), 1.25e-4);
    let rk4 = SampledDrive {
        semi_implicit: false,
        ..s
    };
    assert_eq!(d.with_sampled_drive(rk4).unwrap().velocity_lag(), 0.0);
}

#[test]
fn springs_and_sampled_drives_are_checked() {
    let d = arm();
    let (q, dq, ddq) = state();
    let spring = Spring {
        stiffness: Vector::<3>::new(10.0, 0.0, 2.0),
        reference: Vector::<3>::new(0.1, 0.2, -0.3),
    };
    let k = d.with_spring(spring).unwrap();
    let tau = k.inverse_dynamics(&q, &dq, &ddq) - d.inverse_dynamics(&q, &dq, &ddq);
    let want = spring.stiffness.component_mul(&(q - spring.reference));
    assert!((tau - want).amax() < 1e-13, "{tau} vs {want}");
    let mut bad = spring;
    bad.stiffness[1] = -1.0;
    let e = d.with_spring(bad).unwrap_err().to_string();
    assert!(e.contains("stiffness") && e.contains("[1]"), "{e}");
    bad = spring;
    bad.reference[2] = f64::NAN;
    assert!(d.with_spring(bad).is_err());
    for (what, s) in [
        (
            "substep",
            SampledDrive {
                substep: 0.0,
                ..sampled(1.0, 1.0)
            },
        ),
        (
            "substeps",
            SampledDrive {
                substeps: 0,
                ..sampled(1.0, 1.0)
            },
        ),
        (
            "substeps",
            SampledDrive {
                substeps: 1001,
                ..sampled(1.0, 1.0)
            },
        ),
        ("regularisation", sampled(-1.0, 1.0)),
        ("rate", sampled(1.0, f64::NAN)),
    ] {
        let e = d.with_sampled_drive(s).unwrap_err().to_string();
        assert!(e.contains(what), "{what}: {e}");
    }
}

#[test]
fn the_drive_adds_armature_and_damping_as_stated() {
    // (20.5): M_a = M + diag(I_a), ID = RNEA + I_a ⊙ q̈ + b ⊙ q̇, G unchanged.
    let d = arm();
    let drive = Drive {
        armature: Vector::<3>::new(0.1, 0.25, 0.04),
        damping: Vector::<3>::new(1.5, 0.0, 0.3),
        friction: Vector::<3>::new(2.0, 1.0, 0.0),
    };
    let a = d.with_drive(drive).unwrap();
    let (q, dq, ddq) = state();
    let m = a.mass_matrix(&q) - d.mass_matrix(&q);
    assert!(
        (m - Matrix::<3>::from_diagonal(&drive.armature)).amax() < 1e-14,
        "{m}"
    );
    let tau = a.inverse_dynamics(&q, &dq, &ddq) - d.inverse_dynamics(&q, &dq, &ddq);
    let want = drive.armature.component_mul(&ddq) + drive.damping.component_mul(&dq);
    assert!((tau - want).amax() < 1e-13, "{tau} vs {want}");
    assert_eq!(a.gravity_torque(&q), d.gravity_torque(&q));
    let mv = a.mass_times(&q, &ddq) - a.mass_matrix(&q) * ddq;
    assert!(mv.amax() < 1e-12, "{mv}");
    // (20.6): the full friction beyond a few v_s when the joint moves
    // with its reference, none at rest or against it, odd.
    let drive = a.drive();
    let v = Vector::<3>::new(1.0, -1.0, 1.0);
    let f = drive.friction_torque(&v, &v);
    assert!((f - Vector::<3>::new(2.0, -1.0, 0.0)).amax() < 1e-12, "{f}");
    let zero = Vector::<3>::zeros();
    assert_eq!(drive.friction_torque(&zero, &v), zero);
    assert_eq!(drive.friction_torque(&v, &zero), zero);
    assert_eq!(drive.friction_torque(&v, &-v), zero);
    // The slower of the two: a joint starting to follow its reference.
    let slow = drive.friction_torque(&v, &Vector::from_element(FRICTION_VELOCITY));
    assert!((slow[0] - 2.0 * libm::tanh(1.0)).abs() < 1e-15, "{slow}");
    assert!(slow[1] == 0.0, "{slow}");
    // The default is no drive, bit for bit the rigid model.
    assert_eq!(d.with_drive(Drive::none()).unwrap(), d);
}

#[test]
fn a_bad_drive_is_refused_by_term_and_joint() {
    let d = arm();
    let bad = |f: fn(&mut Drive<3>)| {
        let mut drive = Drive::none();
        f(&mut drive);
        d.with_drive(drive).unwrap_err().to_string()
    };
    let e = bad(|d| d.armature[1] = -0.1);
    assert!(
        e.contains("armature ≥ 0 is violated: armature[1] = -0.1"),
        "{e}"
    );
    let e = bad(|d| d.damping[2] = -1.0);
    assert!(e.contains("damping ≥ 0") && e.contains("damping[2]"), "{e}");
    let e = bad(|d| d.friction[0] = f64::NAN);
    assert!(e.contains("friction") && e.contains("[0]"), "{e}");
    let e = bad(|d| d.armature[0] = f64::INFINITY);
    assert!(e.contains("armature"), "{e}");
}

#[test]
fn bad_inertials_are_refused_by_name() {
    let joints = [Joint::revolute(Transform::IDENTITY, [0.0, 0.0, 1.0])];
    let e = Dynamics::<1>::new(&joints, &[Inertial::point(-1.0, [0.0; 3])], GRAVITY).unwrap_err();
    assert!(
        e.to_string()
            .contains("mass ≥ 0 is violated: link mass[0] = -1"),
        "{e}"
    );
    let mut skew = Inertial::point(1.0, [0.0; 3]);
    skew.inertia = [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let e = Dynamics::<1>::new(&joints, &[skew], GRAVITY).unwrap_err();
    assert!(e.to_string().contains("symmetric"), "{e}");
    let e = Dynamics::<1>::new(&joints, &[], GRAVITY).unwrap_err();
    assert!(e.to_string().contains("one inertial per joint"), "{e}");
    let e = Dynamics::<1>::new(&joints, &[Inertial::NONE], [0.0, f64::NAN, 0.0]).unwrap_err();
    assert!(e.to_string().contains("gravity"), "{e}");
}
