//! A commanded pose as a front or a table holds it: flat, [`TARGET_LEN`]
//! values ([`pose_target`]), and the rotation a target without one keeps
//! ([`HeldRotation`]: a path that gives positions alone steers the
//! position and holds the last rotation given).

use crate::cartesian::PoseTarget;
use crate::types::Vector;
use nalgebra::Matrix3;

/// The length of a flat pose target: p (m), ṗ (m/s), p̈ (m/s²) (3 each), R
/// row-major (9), ω (rad/s), ω̇ (rad/s²) (3 each).
pub const TARGET_LEN: usize = 24;

/// A pose target from its flat layout (see [`TARGET_LEN`]). Its values are
/// checked by the step that takes it
/// ([`CartesianImpedance::check_target`](super::CartesianImpedance::check_target)).
pub fn pose_target(v: &[f64; TARGET_LEN]) -> PoseTarget {
    let v3 = |i: usize| Vector::<3>::new(v[i], v[i + 1], v[i + 2]);
    PoseTarget {
        p: v3(0),
        dp: v3(3),
        ddp: v3(6),
        r: Matrix3::from_fn(|i, j| v[9 + 3 * i + j]),
        w: v3(18),
        dw: v3(21),
    }
}

/// The commanded rotation a pose target without one keeps: the last one a
/// step accepted (the identity before any).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HeldRotation {
    r: Matrix3<f64>,
}

impl Default for HeldRotation {
    fn default() -> Self {
        Self {
            r: Matrix3::identity(),
        }
    }
}

impl HeldRotation {
    /// The rotation held (world ← tip).
    pub fn rotation(&self) -> &Matrix3<f64> {
        &self.r
    }

    /// Hold `r` from now on.
    pub fn hold(&mut self, r: Matrix3<f64>) {
        self.r = r;
    }

    /// The pose target of a path's sample: position p_c (m) and its rates
    /// ṗ_c, p̈_c (m/s, m/s²), the rotation R_c (`None`: the one held) and its
    /// rates ω_c, ω̇_c (rad/s, rad/s²). Hold its rotation
    /// ([`hold`](Self::hold)) once a step has accepted it.
    pub fn target(
        &self,
        p: Vector<3>,
        [dp, ddp]: [Vector<3>; 2],
        r: Option<Matrix3<f64>>,
        [w, dw]: [Vector<3>; 2],
    ) -> PoseTarget {
        PoseTarget {
            p,
            dp,
            ddp,
            r: r.unwrap_or(self.r),
            w,
            dw,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_target_is_read_in_its_order() {
        let v: [f64; TARGET_LEN] = core::array::from_fn(|i| i as f64);
        let t = pose_target(&v);
        assert_eq!(t.p, Vector::<3>::new(0.0, 1.0, 2.0));
        assert_eq!(t.dp, Vector::<3>::new(3.0, 4.0, 5.0));
        assert_eq!(t.ddp, Vector::<3>::new(6.0, 7.0, 8.0));
        assert_eq!(
            t.r,
            Matrix3::new(9.0, 10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0, 17.0)
        );
        assert_eq!(t.w, Vector::<3>::new(18.0, 19.0, 20.0));
        assert_eq!(t.dw, Vector::<3>::new(21.0, 22.0, 23.0));
    }

    #[test]
    fn a_target_without_a_rotation_takes_the_one_held() {
        let mut held = HeldRotation::default();
        assert_eq!(*held.rotation(), Matrix3::identity());
        let p = Vector::<3>::new(0.1, 0.2, 0.3);
        let rates = [
            Vector::<3>::new(1.0, 0.0, 0.0),
            Vector::<3>::new(0.0, 2.0, 0.0),
        ];
        let w = [
            Vector::<3>::new(0.0, 0.0, 0.5),
            Vector::<3>::new(0.0, 0.0, -0.5),
        ];
        let t = held.target(p, rates, None, w);
        assert_eq!((t.p, t.dp, t.ddp), (p, rates[0], rates[1]));
        assert_eq!((t.r, t.w, t.dw), (Matrix3::identity(), w[0], w[1]));
        let r = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let t = held.target(p, rates, Some(r), w);
        assert_eq!((t.r, t.w, t.dw), (r, w[0], w[1]));
        // Held only once a step accepted it.
        assert_eq!(held.target(p, rates, None, w).r, Matrix3::identity());
        held.hold(t.r);
        assert_eq!(held.target(p, rates, None, w).r, r);
    }
}
