//! The figures SPEC (16.9) judges a posture by: σmin of the task's rows of
//! the Jacobian ([`sigma_min`], [`TaskRows`]), a planar arm's plane
//! ([`plane_normal`]) and the conditioning of the joint rule's sampled
//! velocity loop ([`loop_conditioning`]).

use crate::cartesian::kinematics::Jacobian6;
use crate::control::tuning::inertia_scales;
use crate::error::Error;
use crate::math::sqrt;
use crate::types::{Matrix, Vector};

/// The smallest singular value (m/rad for the translation rows) of the first
/// `rows` rows of the Jacobian `j` (`rows` = 6: the 6 × N Jacobian; 3: its
/// translation rows, for a position-only task): √λmin(J Jᵀ). Zero when the
/// arm has fewer joints than rows (the task cannot be met in every direction).
pub fn sigma_min<const N: usize>(j: &Jacobian6<N>, rows: usize) -> f64 {
    if N < rows {
        return 0.0;
    }
    let jjt = j * j.transpose();
    let least = if rows >= 6 {
        jjt.symmetric_eigenvalues().min()
    } else {
        jjt.fixed_view::<3, 3>(0, 0)
            .into_owned()
            .symmetric_eigenvalues()
            .min()
    };
    sqrt(least.max(0.0))
}

/// The smallest singular value (m/rad) of the translation rows of `j` within
/// the plane of the unit `normal` (a planar arm's task, SPEC (16.8)): of P J_v,
/// P the 2 × 3 projection onto two orthonormal directions of the plane. Zero
/// for an arm of one joint.
pub fn sigma_min_in_plane<const N: usize>(j: &Jacobian6<N>, normal: &Vector<3>) -> f64 {
    if N < 2 {
        return 0.0;
    }
    let (u, v) = plane_axes(normal);
    let jv = j.fixed_rows::<3>(0);
    let (a, b) = (u.transpose() * jv, v.transpose() * jv);
    // The 2 × 2 Gram matrix of the projected rows and its smaller eigenvalue.
    let (p, q, r) = (a.dot(&a), a.dot(&b), b.dot(&b));
    let mean = 0.5 * (p + r);
    let spread = sqrt((0.5 * (p - r)) * (0.5 * (p - r)) + q * q);
    sqrt((mean - spread).max(0.0))
}

/// Two orthonormal directions of the plane of the unit `normal`: x less its
/// part along the normal (y for a normal along x), and normal × that.
pub(super) fn plane_axes(normal: &Vector<3>) -> (Vector<3>, Vector<3>) {
    let axis = if normal[0].abs() > 0.9 {
        Vector::<3>::new(0.0, 1.0, 0.0)
    } else {
        Vector::<3>::new(1.0, 0.0, 0.0)
    };
    let w = axis - normal.dot(&axis) * normal;
    let u = w / w.norm();
    (u, normal.cross(&u))
}

/// The normal (unit, world frame) of a planar arm's plane, from its 6 × N
/// Jacobian `j` at any posture, SPEC (16.8): every revolute joint's axis (a
/// column of J_ω) parallel to one direction n (|a_i × n| ≤ 1e-9 |a_i|) and
/// every prismatic joint's (a column of J_v where J_ω's is zero) at right
/// angles to it: the tip then moves in the plane ⊥ n at every posture
/// (rotations about parallel axes keep them parallel). None for an arm that
/// is not planar or has one joint (its tip moves along a curve). The sign
/// makes the largest component positive (+z for an arm in the horizontal
/// plane).
pub fn plane_normal<const N: usize>(j: &Jacobian6<N>) -> Option<Vector<3>> {
    if N < 2 {
        return None;
    }
    let mut normal: Option<Vector<3>> = None;
    for i in 0..N {
        let w = Vector::<3>::new(j[(3, i)], j[(4, i)], j[(5, i)]);
        let size = w.norm();
        if size == 0.0 {
            continue;
        }
        match normal {
            None => normal = Some(w / size),
            Some(n) if n.cross(&w).norm() <= 1e-9 * size => {}
            Some(_) => return None,
        }
    }
    let mut n = normal?;
    for i in 0..N {
        let w = Vector::<3>::new(j[(3, i)], j[(4, i)], j[(5, i)]);
        let t = Vector::<3>::new(j[(0, i)], j[(1, i)], j[(2, i)]);
        if w.norm() == 0.0 && n.dot(&t).abs() > 1e-9 * t.norm() {
            return None;
        }
    }
    let k = n.iamax();
    if n[k] < 0.0 {
        n = -n;
    }
    Some(n)
}

/// The conditioning of the joint rule's sampled velocity loop at an inertia
/// matrix `d` (kg m², symmetric positive definite): λmin(Dₛ^½ D⁻¹ Dₛ^½),
/// Dₛ = diag(d_i), d_i = 1/(D⁻¹)_ii (SPEC (18.1)). The matrix has a unit
/// diagonal, so the value lies in (0, 1]; with Kp = m Dₛ/Ts the slowest mode
/// of the velocity loop decays at m·λmin/Ts (1/s).
pub fn loop_conditioning<const N: usize>(d: &Matrix<N>) -> Result<f64, Error> {
    let scales = inertia_scales(d)?;
    let inv = d
        .cholesky()
        .ok_or(Error::Invalid {
            what: "inertia matrix",
            reason: "must be positive definite",
        })?
        .inverse();
    if N > 7 {
        return Err(Error::Invalid {
            what: "inertia matrix",
            reason: "the velocity-loop conditioning is for arms of at most 7 joints",
        });
    }
    let s = scales.map(sqrt);
    // The N × N matrix in the corner of a 7 × 7 one with a unit diagonal
    // beyond it: its eigenvalues and 1, and λmin ≤ 1 (a unit diagonal).
    let m = Matrix::<7>::from_fn(|i, j| {
        if i < N && j < N {
            s[i] * inv[(i, j)] * s[j]
        } else if i == j {
            1.0
        } else {
            0.0
        }
    });
    Ok(m.symmetric_eigenvalues().min())
}

/// The directions a task commands, over which [`PostureRule::assess`](super::PostureRule::assess) takes
/// σmin(J), SPEC (16.9): the pose (the 6 × N Jacobian), the position (its
/// translation rows), or a position in a plane (a planar arm's task: its
/// translation rows within the plane of the normal, [`plane_normal`]).
/// `true` is the pose, `false` the position.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum TaskRows {
    /// Position and orientation.
    Pose,
    /// The position in space.
    Position,
    /// The position in the plane of this unit normal (world frame).
    Plane(Vector<3>),
}

impl TaskRows {
    /// σmin of the task's rows of `j` (m/rad for the translation rows).
    pub fn sigma_min<const N: usize>(&self, j: &Jacobian6<N>) -> f64 {
        match self {
            TaskRows::Pose => sigma_min(j, 6),
            TaskRows::Position => sigma_min(j, 3),
            TaskRows::Plane(n) => sigma_min_in_plane(j, n),
        }
    }
}

impl From<bool> for TaskRows {
    fn from(orients: bool) -> Self {
        if orients {
            TaskRows::Pose
        } else {
            TaskRows::Position
        }
    }
}
