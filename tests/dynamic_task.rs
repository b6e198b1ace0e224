//! The run-time chain's task-space queries the fronts call (a tip's motion
//! along recorded rows, a recorded posture's pose, the posture rule of SPEC
//! (16.9), a planar arm's normal) against the const-generic core: the same
//! bits for every n = 1 … 7, and the same errors.

mod common;
use adaptimp::cartesian::rule::plane_normal;
use adaptimp::cartesian::{PostureRule, TaskRows};
use adaptimp::control::tuning::Rule;
use adaptimp::dynamic as dy;
use adaptimp::{Chain, Error, Kinematics, Transform, Vector};
use common::{bits, joints, q_of};

fn task_queries<const N: usize>() {
    let (js, tip) = (
        joints::<N>(),
        Transform::from_xyz_rpy([0.0, 0.02, 0.05], [0.0; 3]),
    );
    let (dc, cc) = (
        dy::Chain::new(&js, &tip).expect("run-time chain"),
        Chain::<N>::new(&js, &tip).expect("chain"),
    );
    for k in 0..4 {
        let (q, dq, ddq) = (q_of::<N>(k), q_of::<N>(k + 10), q_of::<N>(k + 20));
        // The motion: J q̇ and J q̈ + J̇ q̇, each row's sum in joint order.
        let (v, a) = dc
            .motion(q.as_slice(), dq.as_slice(), ddq.as_slice())
            .expect("motion");
        let t = cc.tip_checked(&q, &dq).expect("tip");
        let row = |i: usize, x: &Vector<N>| (0..N).map(|j| t.jacobian[(i, j)] * x[j]).sum::<f64>();
        let want_v: Vec<f64> = (0..6).map(|i| row(i, &dq)).collect();
        let want_a: Vec<f64> = (0..6).map(|i| row(i, &ddq) + t.bias[i]).collect();
        assert_eq!(bits(v.as_slice()), bits(&want_v), "twist, n = {N}");
        assert_eq!(bits(a.as_slice()), bits(&want_a), "acceleration, n = {N}");
        // The Jacobian row-major, as a front's array holds it.
        let mut rows = vec![0.0; 6 * N];
        dc.jacobian_rows(q.as_slice(), &mut rows).expect("rows");
        assert_eq!(
            bits(&rows),
            bits(cc.pose_jacobian(&q).jacobian.transpose().as_slice())
        );
        assert!(dc.jacobian_rows(q.as_slice(), &mut [0.0; 5]).is_err());
        // A recorded posture's pose, unchecked.
        let (p, r) = dc.pose_unchecked(q.as_slice()).expect("pose");
        let (p2, r2) = cc.pose(&q);
        assert_eq!(bits(p.as_slice()), bits(p2.as_slice()));
        assert_eq!(bits(r.matrix().as_slice()), bits(r2.matrix().as_slice()));
        // A Jacobian from its rows, and the plane's normal of SPEC (16.8).
        let j = cc.pose_jacobian(&q).jacobian;
        let rows: Vec<f64> = (0..6)
            .flat_map(|i| (0..N).map(move |c| (i, c)))
            .map(|ij| j[ij])
            .collect();
        let dj = dy::Jacobian::from_rows(&rows).expect("rows");
        assert_eq!(
            bits(dj.matrix().iter().copied().collect::<Vec<_>>().as_slice()),
            bits(j.as_slice())
        );
        assert_eq!(dj.plane_normal(), plane_normal(&j));
    }
    // Unchecked is unchecked: a NaN posture gives NaN, not an error; the
    // motion refuses it as the tip does.
    let mut bad = q_of::<N>(0);
    bad[0] = f64::NAN;
    assert!(dc.pose_unchecked(bad.as_slice()).expect("unchecked").0[0].is_nan());
    assert_eq!(
        dc.motion(bad.as_slice(), bad.as_slice(), bad.as_slice())
            .unwrap_err(),
        cc.tip_checked(&bad, &bad).unwrap_err()
    );
    assert_eq!(
        dc.pose_unchecked(&[0.0; 8]).unwrap_err(),
        Error::Invalid {
            what: "q",
            reason: "needs one value per joint (as many as the controller has)"
        }
    );
    // The posture rule over rows.
    let rule = PostureRule::for_loop(Rule::default().k1(1e-3), 1e-3, &Rule::default());
    let orbit: Vec<Vector<N>> = (0..5).map(q_of::<N>).collect();
    let targets: Vec<Vector<3>> = orbit
        .iter()
        .map(|q| cc.pose(q).0 + Vector::<3>::new(0.0, 0.01, 0.0))
        .collect();
    let gravity: Vec<Vector<N>> = (0..5).map(|k| q_of::<N>(k + 3) * 4.0).collect();
    let d0 =
        adaptimp::types::Matrix::<N>::from_fn(|i, j| if i == j { 2.0 + i as f64 } else { 0.1 });
    let (lo, hi, tau) = (
        Vector::<N>::repeat(-2.5),
        Vector::<N>::repeat(2.5),
        Vector::<N>::repeat(30.0),
    );
    let flat = |v: &[Vector<N>]| {
        v.iter()
            .flat_map(|x| x.iter().copied())
            .collect::<Vec<f64>>()
    };
    let d0_rows: Vec<f64> = (0..N * N).map(|k| d0[(k / N, k % N)]).collect();
    let p_rows: Vec<f64> = targets.iter().flat_map(|x| x.iter().copied()).collect();
    for task in [TaskRows::Pose, TaskRows::Position] {
        let got = dc
            .assess_posture(
                &rule,
                task,
                (&flat(&orbit), &p_rows, &flat(&gravity)),
                &d0_rows,
                (lo.as_slice(), hi.as_slice()),
                tau.as_slice(),
            )
            .expect("assessment");
        let want = rule
            .assess(&cc, task, &orbit, &targets, &gravity, &d0, (&lo, &hi), &tau)
            .expect("assessment");
        assert_eq!(format!("{got:?}"), format!("{want:?}"), "n = {N}");
    }
    assert_eq!(
        dc.assess_posture(
            &rule,
            TaskRows::Pose,
            (&[0.0; 1], &p_rows, &flat(&gravity)),
            &d0_rows,
            (lo.as_slice(), hi.as_slice()),
            tau.as_slice()
        )
        .unwrap_err(),
        if N == 1 {
            // One posture of one joint, five targets: the rule's own refusal.
            rule.assess(
                &cc,
                TaskRows::Pose,
                &[Vector::<N>::zeros()],
                &targets,
                &gravity,
                &d0,
                (&lo, &hi),
                &tau,
            )
            .unwrap_err()
        } else {
            Error::Invalid {
                what: "orbit",
                reason: "needs one value per joint (as many as the controller has)",
            }
        }
    );
    let _ = Kinematics::tip(&cc, &q_of::<N>(0), &Vector::zeros());
}

#[test]
fn the_chain_task_queries_are_the_const_generic_ones_bit_for_bit() {
    task_queries::<1>();
    task_queries::<2>();
    task_queries::<3>();
    task_queries::<4>();
    task_queries::<5>();
    task_queries::<6>();
    task_queries::<7>();
}

#[test]
fn a_jacobian_of_another_shape_is_refused_by_name() {
    let e = Error::Invalid {
        what: "jacobian",
        reason: "needs 6 rows of n values, 1 ≤ n ≤ 7",
    };
    assert_eq!(dy::Jacobian::from_rows(&[0.0; 5]).unwrap_err(), e);
    assert_eq!(dy::Jacobian::from_rows(&[0.0; 13]).unwrap_err(), e);
    assert_eq!(dy::Jacobian::from_rows(&[0.0; 48]).unwrap_err(), e);
    assert_eq!(dy::Jacobian::from_rows(&[0.0; 6]).expect("n = 1").n(), 1);
}
