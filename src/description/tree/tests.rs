use super::*;

fn inertial(d: [f64; 3]) -> LinkInertial {
    LinkInertial {
        mass: 1.0,
        origin: Origin::IDENTITY,
        inertia: [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]],
        gravcomp: 0.0,
    }
}

#[test]
fn an_inertia_that_breaks_the_triangle_inequality_is_balanced_to_its_mean() {
    // (21.4): 0.001 + 0.001 < 0.02 → every moment 0.022/3.
    let mut i = inertial([0.001, 0.001, 0.02]);
    assert!(i.balance());
    let mean = 0.022 / 3.0;
    assert_eq!(
        i.inertia,
        [[mean, 0.0, 0.0], [0.0, mean, 0.0], [0.0, 0.0, mean]]
    );
    // A body's inertia, a thin rod's (A + B = C) and a negative moment stay.
    for d in [[0.01, 0.02, 0.025], [0.0, 0.01, 0.01], [-0.001, 0.01, 0.01]] {
        let mut i = inertial(d);
        assert!(!i.balance(), "{d:?}");
        assert_eq!(i, inertial(d));
    }
}
