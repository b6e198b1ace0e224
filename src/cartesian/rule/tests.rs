use super::*;
use crate::cartesian::chain::{Chain, Joint, Transform};
use crate::cartesian::kinematics::Jacobian6;

#[test]
fn an_orbit_of_a_delayed_loop_slows_d_and_c_only() {
    // A slow circle in two joints: 0.1 rad across, 0.3 rad/s.
    let path: alloc::vec::Vec<Setpoint<2>> = (0..100)
        .map(|k| {
            let a = 2.0 * core::f64::consts::PI * k as f64 / 100.0;
            Setpoint {
                x: Vector::<2>::new(0.05 * a.cos(), 0.05 * a.sin()),
                dx: Vector::<2>::new(-0.3 * a.sin(), 0.3 * a.cos()),
                ddx: Vector::<2>::zeros(),
            }
        })
        .collect();
    let now = resolving(&Rule::default(), &path);
    assert_eq!(now.learn_dc, Rule::default().learn_dc);
    assert!(now.tube[0] < Rule::default().tube[0]);
    for delay in [1, 2] {
        let late = resolving(&Rule::default().with_delay(delay).unwrap(), &path);
        assert_eq!(late.learn_dc, now.learn_dc / (delay as f64 + 1.0));
        // Not the joint task's undelayed ω_D: the orbit's of the delayed ω_G.
        let bounded = Rule::default().with_delay(delay).unwrap().bounded(6.0);
        assert!(bounded.dc_boost > 1.0);
        assert_eq!(resolving(&bounded, &path).dc_boost, 1.0);
        assert_eq!((late.tube, late.learn), (now.tube, now.learn));
    }
}

#[test]
fn the_shaped_gains_orbit_learns_g_at_least_at_the_loops_geometric_mean() {
    // (18.6)'s ½ doubled; the critical rule's, faster already, kept.
    let rule = Rule::default();
    assert_eq!(rule.learn, 0.5);
    let shaped = shaped_orbit(&rule);
    assert_eq!(shaped.learn, 1.0);
    assert_eq!(
        Rule {
            learn: 0.5,
            ..shaped
        },
        rule
    );
    let critical = rule.critical(1e-3);
    assert!(critical.learn > 1.0);
    assert_eq!(shaped_orbit(&critical), critical);
}

#[test]
fn sigma_min_is_the_smallest_singular_value() {
    let mut j = Jacobian6::<7>::zeros();
    for (i, s) in [3.0, 2.0, 1.5, 1.0, 0.5, 0.25].iter().enumerate() {
        j[(i, i)] = *s;
    }
    assert!((sigma_min(&j, 6) - 0.25).abs() < 1e-12);
    assert!((sigma_min(&j, 3) - 1.5).abs() < 1e-12);
    let j2 = Jacobian6::<2>::from_element(1.0);
    assert_eq!(sigma_min(&j2, 6), 0.0);
    // A planar arm: both axes along −y, its tip in the x–z plane.
    let mut planar = Jacobian6::<2>::zeros();
    planar[(0, 0)] = 0.5;
    planar[(2, 1)] = 0.2;
    planar[(4, 0)] = -1.0;
    planar[(4, 1)] = -1.0;
    assert_eq!(sigma_min(&planar, 3), 0.0);
    let n = plane_normal(&planar).unwrap();
    assert_eq!(n, Vector::<3>::new(0.0, 1.0, 0.0));
    assert!((sigma_min_in_plane(&planar, &n) - 0.2).abs() < 1e-15);
    // Not planar: axes that are not parallel.
    assert_eq!(plane_normal(&j), None);
    let mut spatial = planar;
    spatial[(5, 1)] = 1.0;
    assert_eq!(plane_normal(&spatial), None);
}

#[test]
fn a_planar_arm_s_circle_lies_in_its_plane() {
    let p0 = Vector::<3>::new(0.4, 0.0, 0.3);
    let c = PoseCircle::in_plane(
        p0,
        Matrix3::identity(),
        Vector::<3>::new(0.0, -2.0, 0.0),
        0.03,
        0.5,
        1.0,
        1.0,
    )
    .unwrap();
    // Toward the base's axis (the y axis through the origin), in the x–z plane.
    assert!((c.centre() - p0 * (1.0 - 0.03 / 0.5)).norm() < 1e-15);
    for t in [1.5, 2.2, 3.9] {
        assert_eq!(c.sample(t).p[1], 0.0);
    }
    // The horizontal plane's circle is the one of `with`, to the bit.
    let r = *nalgebra::Rotation3::from_euler_angles(0.1, 0.2, 0.3).matrix();
    let z = Vector::<3>::new(0.0, 0.0, 1.0);
    let a = PoseCircle::in_plane(p0, r, z, 0.03, 0.5, 1.0, 1.0).unwrap();
    assert_eq!(a, PoseCircle::new(p0, r).unwrap());
    assert!(PoseCircle::in_plane(p0, r, Vector::<3>::zeros(), 0.03, 0.5, 1.0, 1.0).is_err());
}

#[test]
fn a_diagonal_inertia_is_perfectly_conditioned() {
    let d = Matrix::<3>::from_diagonal(&Vector::<3>::new(2.0, 0.5, 0.01));
    assert!((loop_conditioning(&d).unwrap() - 1.0).abs() < 1e-12);
    let mut c = d;
    c[(0, 1)] = 0.99;
    c[(1, 0)] = 0.99;
    assert!(loop_conditioning(&c).unwrap() < 0.05);
    assert!(loop_conditioning(&(-d)).is_err());
}

#[test]
fn the_circle_starts_at_rest_on_the_start_pose_and_closes() {
    let r = *nalgebra::Rotation3::from_euler_angles(0.1, 0.2, 0.3).matrix();
    let p0 = Vector::<3>::new(0.4, 0.3, 0.5);
    let c = PoseCircle::new(p0, r).unwrap();
    for t in [0.0, 0.5, 1.0] {
        let s = c.sample(t);
        assert_eq!(s.p, p0);
        assert_eq!(s.dp, Vector::<3>::zeros());
    }
    // Toward the base's axis, in the horizontal plane.
    let centre = c.centre();
    assert!((centre - (p0 - 0.03 * Vector::<3>::new(0.8, 0.6, 0.0))).norm() < 1e-15);
    // On the circle at full speed, one period later the same point.
    let (a, b) = (c.sample(2.5), c.sample(4.5));
    assert!((a.p - b.p).norm() < 1e-12);
    assert!(((a.p - centre).norm() - 0.03).abs() < 1e-15);
    assert!((a.dp.norm() - 0.03 * core::f64::consts::PI).abs() < 1e-12);
    assert_eq!(a.r, r);
    // ṗ and p̈ are the derivatives of p (central differences).
    for t in [1.3, 1.7, 2.2, 3.1] {
        let h = 1e-6;
        let (m, s, p) = (c.sample(t - h), c.sample(t), c.sample(t + h));
        assert!(((p.p - m.p) / (2.0 * h) - s.dp).norm() < 1e-8, "{t}");
        assert!(((p.dp - m.dp) / (2.0 * h) - s.ddp).norm() < 1e-7, "{t}");
    }
    assert!((c.span() - 4.0).abs() < 1e-15);
    let e = PoseCircle::with(p0, r, 0.0, 0.5, 1.0, 1.0).unwrap_err();
    assert!(e.to_string().contains("radius > 0"), "{e}");
}

/// A 3-joint elbow arm in space (yaw, shoulder, elbow; links 0.4 m and
/// 0.3 m): stretched, it is singular.
fn elbow() -> Chain<3> {
    let at = |x: f64| Transform {
        translation: [x, 0.0, 0.0],
        ..Transform::IDENTITY
    };
    Chain::new(
        &[
            Joint::revolute(Transform::IDENTITY, [0.0, 0.0, 1.0]),
            Joint::revolute(Transform::IDENTITY, [0.0, 1.0, 0.0]),
            Joint::revolute(at(0.4), [0.0, 1.0, 0.0]),
        ],
        &at(0.3),
    )
    .unwrap()
}

#[test]
fn a_singular_posture_is_refused_by_name() {
    let arm = elbow();
    let rule = PostureRule::default();
    let lo = Vector::<3>::from_element(-3.0);
    let hi = Vector::<3>::from_element(3.0);
    let d0 = Matrix::<3>::from_diagonal(&Vector::<3>::new(1.0, 0.5, 0.2));
    let tau = Vector::<3>::from_element(10.0);
    let g = [Vector::<3>::zeros()];
    let assess = |q: Vector<3>| {
        let p = arm.fk(&q);
        rule.assess(&arm, false, &[q], &[p], &g, &d0, (&lo, &hi), &tau)
            .unwrap()
    };
    // Stretched: the translation rows lose rank.
    let a = assess(Vector::<3>::new(0.3, -0.5, 0.0));
    assert!(a.sigma_min < 1e-6, "{}", a.sigma_min);
    let e = rule.check(&a).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("condition σmin(J) ≥ 0.05 m/rad along the task"),
        "{e}"
    );
    let a = assess(Vector::<3>::new(0.3, -0.5, 1.2));
    rule.check(&a).unwrap();
    assert!(rule.score(&a) > 0.0);
    // Too near a limit: joint 0 at 2.95 rad, 0.05 rad from it, inside its 0.1 rad margin.
    let a = assess(Vector::<3>::new(2.95, -0.5, 1.2));
    let e = rule.check(&a).unwrap_err();
    assert_eq!(
        e.to_string(),
        "condition every joint min(0.1 rad, range/8) inside its limits along the task is \
         violated: distance to the limit − margin (rad), joint[0] = -0.05 (SPEC (16.9))"
    );
    // Gravity beyond half an actuator: named with the load.
    let heavy = [Vector::<3>::new(0.0, 6.0, 1.0)];
    let q = Vector::<3>::new(0.3, -0.5, 1.2);
    let a = rule
        .assess(
            &arm,
            false,
            &[q],
            &[arm.fk(&q)],
            &heavy,
            &d0,
            (&lo, &hi),
            &tau,
        )
        .unwrap();
    let e = rule.check(&a).unwrap_err();
    assert_eq!(
        e.to_string(),
        "condition gravity load max_i |G_i|/τmax_i ≤ 0.5 along the task (gravity within \
         the actuators) is violated: gravity load = 0.6 (SPEC (16.9))"
    );
    // What each condition needs, with the best values found.
    assert_eq!(
        rule.needs(&a).to_string(),
        "σmin(J) ≥ 0.05 m/rad along the task (not near a singularity) (best 0.1779); every \
         joint min(0.1 rad, range/8) inside its limits along the task (best 1.7 rad, joint \
         2); gravity load max_i |G_i|/τmax_i ≤ 0.5 along the task (gravity within the \
         actuators) (best 0.6); velocity-loop conditioning λmin(Dₛ^½ D⁻¹ Dₛ^½) ≥ K1·Ts/m = \
         0.2 at the start (best 1); the path reachable: the inverse kinematics within 0.001 \
         m of it (best 0)"
    );
    // A condition no start reached (the path's reach when every path checked
    // diverged) printed as such, not as "best inf".
    let unmeasured = Assessment {
        reach: f64::INFINITY,
        ..a
    };
    assert!(rule.needs(&unmeasured).to_string().ends_with(
        "the path reachable: the inverse kinematics within 0.001 m of it (none measured: \
         no start checked along the task)"
    ));
}
