//! Manipulator dynamics `D(q) q̈ + C(q, q̇) q̇ + G(q) = sat(τ) − τe`, (4), SPEC §1.
//!
//! [`Manipulator`] is the trait an n-joint model implements; [`TwoLinkArm`] is
//! the paper's arm (55)–(63) with the SPEC §1 defaults; [`PlanarArm`] is an
//! n-link planar arm in a vertical plane for any `N` (it reduces to
//! [`TwoLinkArm`] for `N = 2`).

use crate::cartesian::kinematics::{Jacobian6, Kinematics, Tip};
use crate::error::{check, Error, PARAM_BOUND};
use crate::math::{cos, sin};
use crate::types::{Matrix, Vector};
use nalgebra::{Rotation3, Vector2, Vector3};

/// Rigid-body dynamics of an `N`-joint manipulator in joint coordinates.
///
/// Units: q in rad, q̇ in rad/s, torques in N m, D in kg m², C in kg m²/s,
/// G in N m. Implementations must make `D` symmetric positive definite
/// (Property 1) and `Ḋ − 2C` skew-symmetric (Property 2).
pub trait Manipulator<const N: usize> {
    /// Inertia matrix D(q) (kg m²), (56).
    fn inertia(&self, q: &Vector<N>) -> Matrix<N>;
    /// Centripetal and Coriolis matrix C(q, q̇) (kg m²/s), (57).
    fn coriolis(&self, q: &Vector<N>, dq: &Vector<N>) -> Matrix<N>;
    /// Gravity torque G(q) (N m), (58).
    fn gravity(&self, q: &Vector<N>) -> Vector<N>;

    /// Joint acceleration q̈ (rad/s²) from (4):
    /// `q̈ = D⁻¹ (τ − τe − C q̇ − G)`, where `tau` is the torque the actuators
    /// apply (already saturated) and `tau_e` the force the robot exerts on the
    /// environment. Returns NaN entries if D is not positive definite.
    fn forward_dynamics(
        &self,
        q: &Vector<N>,
        dq: &Vector<N>,
        tau: &Vector<N>,
        tau_e: &Vector<N>,
    ) -> Vector<N> {
        let rhs = tau - tau_e - self.coriolis(q, dq) * dq - self.gravity(q);
        match self.inertia(q).cholesky() {
            Some(chol) => chol.solve(&rhs),
            None => Vector::from_element(f64::NAN),
        }
    }
}

/// Physical parameters of the paper's 2-link arm (Fig. 1, Table I), SPEC §1.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ArmParams {
    /// Mass of link 1 (kg).
    pub m1: f64,
    /// Mass of link 2 (kg).
    pub m2: f64,
    /// Length of link 1 (m).
    pub l1: f64,
    /// Length of link 2 (m).
    pub l2: f64,
    /// Distance from joint 1 to the centre of mass of link 1 (m).
    pub lc1: f64,
    /// Distance from joint 2 to the centre of mass of link 2 (m).
    pub lc2: f64,
    /// Moment of inertia of link 1 about its centre of mass (kg m²).
    pub i1: f64,
    /// Moment of inertia of link 2 about its centre of mass (kg m²).
    pub i2: f64,
    /// Gravitational acceleration (m/s²); the arm moves in a vertical plane.
    pub g: f64,
}

/// The paper's 2-link arm in a vertical plane, (55)–(63), SPEC §1.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TwoLinkArm {
    params: ArmParams,
    /// p1..p5 of (59)–(63), with the erratum of (62) corrected (p4 uses lc1).
    p: [f64; 5],
}

impl TwoLinkArm {
    /// An arm with the given parameters, validated: masses and lengths > 0,
    /// centre-of-mass distances and inertias ≥ 0, everything finite, and D(q)
    /// positive definite for every q (p1·p2 − p3² > 0).
    pub fn new(params: ArmParams) -> Result<Self, Error> {
        let a = &params;
        check::positive("m1 > 0", "m1", a.m1)?;
        check::positive("m2 > 0", "m2", a.m2)?;
        check::positive("l1 > 0", "l1", a.l1)?;
        check::positive("l2 > 0", "l2", a.l2)?;
        check::nonnegative("lc1 ≥ 0", "lc1", a.lc1)?;
        check::nonnegative("lc2 ≥ 0", "lc2", a.lc2)?;
        check::nonnegative("I1 ≥ 0", "I1", a.i1)?;
        check::nonnegative("I2 ≥ 0", "I2", a.i2)?;
        check::finite("g", a.g)?;
        for (what, v) in [
            ("m1", a.m1),
            ("m2", a.m2),
            ("l1", a.l1),
            ("l2", a.l2),
            ("lc1", a.lc1),
            ("lc2", a.lc2),
            ("I1", a.i1),
            ("I2", a.i2),
            ("g", a.g),
        ] {
            check::at_most("|value| ≤ 1e9", what, v, PARAM_BOUND)?;
        }
        let arm = Self::from_valid(params);
        let [p1, p2, p3, _, _] = arm.p;
        let det = p1 * p2 - p3 * p3;
        if det <= 0.0 {
            return Err(Error::Condition {
                condition: "D(q) > 0 for all q",
                lhs: "p1·p2 − p3²",
                index: None,
                value: det,
            });
        }
        Ok(arm)
    }

    pub(crate) fn from_valid(a: ArmParams) -> Self {
        let p = [
            a.m1 * a.lc1 * a.lc1 + a.m2 * a.l1 * a.l1 + a.i1, // (59)
            a.m2 * a.lc2 * a.lc2 + a.i2,                      // (60)
            a.m2 * a.l1 * a.lc2,                              // (61)
            a.m1 * a.lc1 + a.m2 * a.l1,                       // (62), erratum: lc1, SPEC §1
            a.m2 * a.lc2,                                     // (63)
        ];
        Self { params: a, p }
    }

    /// The physical parameters.
    pub fn params(&self) -> &ArmParams {
        &self.params
    }

    /// The lumped parameters p1..p5 of (59)–(63) (kg m², kg m², kg m², kg m, kg m).
    pub fn lumped(&self) -> [f64; 5] {
        self.p
    }

    /// The link lengths [l1, l2] (m).
    pub fn lengths(&self) -> [f64; 2] {
        [self.params.l1, self.params.l2]
    }
}

impl Default for TwoLinkArm {
    fn default() -> Self {
        Self::paper()
    }
}

impl Manipulator<2> for TwoLinkArm {
    fn inertia(&self, q: &Vector<2>) -> Matrix<2> {
        let [p1, p2, p3, _, _] = self.p;
        let c2 = cos(q[1]);
        let d12 = p2 + p3 * c2;
        Matrix::<2>::new(p1 + p2 + 2.0 * p3 * c2, d12, d12, p2) // (56)
    }

    fn coriolis(&self, q: &Vector<2>, dq: &Vector<2>) -> Matrix<2> {
        let h = self.p[2] * sin(q[1]);
        Matrix::<2>::new(-h * dq[1], -h * (dq[0] + dq[1]), h * dq[0], 0.0) // (57)
    }

    fn gravity(&self, q: &Vector<2>) -> Vector<2> {
        let g = self.params.g;
        let g12 = self.p[4] * g * cos(q[0] + q[1]);
        Vector::<2>::new(self.p[3] * g * cos(q[0]) + g12, g12) // (58)
    }

    /// Closed-form 2×2 solve (D is positive definite for a validated arm).
    fn forward_dynamics(
        &self,
        q: &Vector<2>,
        dq: &Vector<2>,
        tau: &Vector<2>,
        tau_e: &Vector<2>,
    ) -> Vector<2> {
        let [p1, p2, p3, p4, p5] = self.p;
        let g = self.params.g;
        let (s1, c1) = (sin(q[0]), cos(q[0]));
        let (s2, c2) = (sin(q[1]), cos(q[1]));
        // Two sin/cos pairs (one libm sincos each) instead of three calls: the
        // plant is evaluated four times per RK4 step.
        let c12 = c1 * c2 - s1 * s2;
        let h = p3 * s2;
        // rhs = τ − τe − C q̇ − G
        let r0 = tau[0] - tau_e[0] + h * dq[1] * (2.0 * dq[0] + dq[1]) - p4 * g * c1 - p5 * g * c12;
        let r1 = tau[1] - tau_e[1] - h * dq[0] * dq[0] - p5 * g * c12;
        let d11 = p1 + p2 + 2.0 * p3 * c2;
        let d12 = p2 + p3 * c2;
        let det = d11 * p2 - d12 * d12;
        Vector::<2>::new((p2 * r0 - d12 * r1) / det, (d11 * r1 - d12 * r0) / det)
    }
}

/// Per-link, per-joint planar vectors: `[k][i]`.
type LinkTable<const N: usize> = [[Vector2<f64>; N]; N];

/// Parameters of one link of a [`PlanarArm`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Link {
    /// Mass (kg).
    pub mass: f64,
    /// Length, joint to joint (m).
    pub length: f64,
    /// Distance from the proximal joint to the centre of mass (m).
    pub com: f64,
    /// Moment of inertia about the centre of mass, normal to the plane (kg m²).
    pub inertia: f64,
}

/// An `N`-link serial arm of revolute joints moving in a vertical plane.
///
/// Joint angles are relative (q_i is link i's angle to link i−1); link i's
/// absolute angle θ_i = q_1 + … + q_i is measured from the horizontal, and
/// gravity acts along −y. D is assembled from the centre-of-mass Jacobians and
/// C from the Christoffel symbols of D, so `Ḋ − 2C` is skew-symmetric by
/// construction. For `N = 2` it equals [`TwoLinkArm`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PlanarArm<const N: usize> {
    links: [Link; N],
    g: f64,
}

impl<const N: usize> PlanarArm<N> {
    /// A validated arm: mass and length > 0, centre-of-mass distance and
    /// inertia ≥ 0, every number finite.
    pub fn new(links: [Link; N], g: f64) -> Result<Self, Error> {
        for link in &links {
            check::positive("mass > 0", "mass", link.mass)?;
            check::positive("length > 0", "length", link.length)?;
            check::nonnegative("com ≥ 0", "com", link.com)?;
            check::nonnegative("inertia ≥ 0", "inertia", link.inertia)?;
            for (what, v) in [
                ("mass", link.mass),
                ("length", link.length),
                ("com", link.com),
                ("inertia", link.inertia),
            ] {
                check::at_most("|value| ≤ 1e9", what, v, PARAM_BOUND)?;
            }
        }
        check::at_most("|value| ≤ 1e9", "g", g, PARAM_BOUND)?;
        Ok(Self { links, g })
    }

    /// The links.
    pub fn links(&self) -> &[Link; N] {
        &self.links
    }

    /// Gravitational acceleration g (m/s²).
    pub fn g(&self) -> f64 {
        self.g
    }

    /// Absolute link angles θ (rad) with their sines and cosines.
    fn angles(q: &Vector<N>) -> [(f64, f64); N] {
        let mut out = [(0.0, 0.0); N];
        let mut theta = 0.0;
        for (o, &qi) in out.iter_mut().zip(q.iter()) {
            theta += qi;
            *o = (sin(theta), cos(theta));
        }
        out
    }

    /// Jacobian column ∂p_k/∂q_i of link k's centre of mass (zero for i > k),
    /// and the second derivative ∂²p_k/∂q_i∂q_j, which depends on max(i, j) only.
    ///
    /// With u(θ) = (cos θ, sin θ): ∂p_k/∂q_i = Σ_{a=i}^{k−1} l_a u'(θ_a) + lc_k u'(θ_k),
    /// u' = (−sin, cos), and ∂²p_k/∂q_i∂q_j = −(Σ_{a=m}^{k−1} l_a u(θ_a) + lc_k u(θ_k)),
    /// m = max(i, j).
    fn com_jacobians(&self, sc: &[(f64, f64); N]) -> (LinkTable<N>, LinkTable<N>) {
        // jac[k][i] = ∂p_k/∂q_i ; hess[k][m] = ∂²p_k/∂q_i∂q_j with max(i, j) = m.
        let mut jac = [[Vector2::zeros(); N]; N];
        let mut hess = [[Vector2::zeros(); N]; N];
        for k in 0..N {
            let (s, c) = sc[k];
            let lc = self.links[k].com;
            let mut dj = Vector2::new(-lc * s, lc * c);
            let mut dh = Vector2::new(-lc * c, -lc * s);
            for i in (0..=k).rev() {
                if i < k {
                    let (s, c) = sc[i];
                    let l = self.links[i].length;
                    dj += Vector2::new(-l * s, l * c);
                    dh += Vector2::new(-l * c, -l * s);
                }
                jac[k][i] = dj;
                hess[k][i] = dh;
            }
        }
        (jac, hess)
    }
}

impl<const N: usize> Manipulator<N> for PlanarArm<N> {
    fn inertia(&self, q: &Vector<N>) -> Matrix<N> {
        let (jac, _) = self.com_jacobians(&Self::angles(q));
        let mut d = Matrix::<N>::zeros();
        for (k, link) in self.links.iter().enumerate() {
            for i in 0..=k {
                for j in 0..=k {
                    d[(i, j)] += link.mass * jac[k][i].dot(&jac[k][j]) + link.inertia;
                }
            }
        }
        d
    }

    fn coriolis(&self, q: &Vector<N>, dq: &Vector<N>) -> Matrix<N> {
        let (jac, hess) = self.com_jacobians(&Self::angles(q));
        // ∂D_ij/∂q_l = Σ_k m_k (H_k[max(i,l)]·J_k[j] + J_k[i]·H_k[max(j,l)]), for i, j, l ≤ k.
        let dd = |i: usize, j: usize, l: usize| -> f64 {
            let mut acc = 0.0;
            for k in i.max(j).max(l)..N {
                let m = self.links[k].mass;
                acc += m * (hess[k][i.max(l)].dot(&jac[k][j]) + jac[k][i].dot(&hess[k][j.max(l)]));
            }
            acc
        };
        // Christoffel symbols: C_ij = Σ_l ½ (∂D_ij/∂q_l + ∂D_il/∂q_j − ∂D_jl/∂q_i) q̇_l.
        let mut c = Matrix::<N>::zeros();
        for i in 0..N {
            for j in 0..N {
                let mut acc = 0.0;
                for l in 0..N {
                    acc += 0.5 * (dd(i, j, l) + dd(i, l, j) - dd(j, l, i)) * dq[l];
                }
                c[(i, j)] = acc;
            }
        }
        c
    }

    fn gravity(&self, q: &Vector<N>) -> Vector<N> {
        let (jac, _) = self.com_jacobians(&Self::angles(q));
        let mut g = Vector::<N>::zeros();
        for (k, link) in self.links.iter().enumerate() {
            for i in 0..=k {
                g[i] += link.mass * self.g * jac[k][i].y;
            }
        }
        g
    }
}

// The planar arms' kinematics, SPEC (16.0) (the trait's module docs).

/// The tip of a planar arm with link `lengths` at (q, q̇): the sums of the
/// module docs of `Kinematics`, in one pass.
fn planar<const N: usize>(lengths: &[f64; N], q: &Vector<N>, dq: &Vector<N>) -> Tip<N> {
    let mut p = Vector::<3>::zeros();
    let mut jac = Jacobian6::<N>::zeros();
    let mut bias = Vector::<6>::zeros();
    let (mut theta, mut rate) = (0.0, 0.0);
    for a in 0..N {
        theta += q[a];
        rate += dq[a];
        let (s, c) = (sin(theta), cos(theta));
        let l = lengths[a];
        p[0] += l * c;
        p[1] += l * s;
        // Link a moves with every joint i ≤ a.
        for i in 0..=a {
            jac[(0, i)] -= l * s;
            jac[(1, i)] += l * c;
        }
        jac[(5, a)] = 1.0;
        bias[0] -= l * rate * rate * c;
        bias[1] -= l * rate * rate * s;
    }
    Tip {
        position: p,
        rotation: Rotation3::from_axis_angle(&Vector3::z_axis(), theta),
        jacobian: jac,
        bias,
    }
}

impl<const N: usize> Kinematics<N> for PlanarArm<N> {
    fn tip(&self, q: &Vector<N>, dq: &Vector<N>) -> Tip<N> {
        planar(&self.links().map(|l| l.length), q, dq)
    }
}

impl Kinematics<2> for TwoLinkArm {
    fn tip(&self, q: &Vector<2>, dq: &Vector<2>) -> Tip<2> {
        planar(&self.lengths(), q, dq)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_default_lumped_parameters() {
        // SPEC §1: p ≈ [0.2266, 0.04084, 0.04611, 0.6475, 0.13175].
        let p = TwoLinkArm::paper().lumped();
        let expect = [0.2266, 0.04084, 0.04611, 0.6475, 0.13175];
        for (a, b) in p.iter().zip(expect) {
            assert!((a - b).abs() < 5e-5 * b.max(1.0), "{p:?}");
        }
    }

    #[test]
    fn peak_gravity_torque_matches_spec() {
        // SPEC §1: peak gravity torque ≈ 7.6 N m (both links horizontal).
        let g = TwoLinkArm::paper().gravity(&Vector::<2>::zeros());
        assert!((g[0] - 7.6).abs() < 0.05, "{g}");
    }

    #[test]
    fn rejects_bad_parameters_by_name() {
        let bad = ArmParams {
            m1: -1.0,
            ..ArmParams::default()
        };
        let e = TwoLinkArm::new(bad).unwrap_err();
        assert!(e.to_string().contains("m1 > 0"), "{e}");
        let nan = ArmParams {
            g: f64::NAN,
            ..ArmParams::default()
        };
        assert_eq!(
            TwoLinkArm::new(nan).unwrap_err(),
            Error::NonFinite {
                what: "g",
                index: 0
            }
        );
    }

    #[test]
    fn closed_form_forward_dynamics_equals_generic_solve() {
        struct Generic(TwoLinkArm);
        impl Manipulator<2> for Generic {
            fn inertia(&self, q: &Vector<2>) -> Matrix<2> {
                self.0.inertia(q)
            }
            fn coriolis(&self, q: &Vector<2>, dq: &Vector<2>) -> Matrix<2> {
                self.0.coriolis(q, dq)
            }
            fn gravity(&self, q: &Vector<2>) -> Vector<2> {
                self.0.gravity(q)
            }
        }
        let arm = TwoLinkArm::paper();
        let q = Vector::<2>::new(0.3, -1.2);
        let dq = Vector::<2>::new(2.0, -0.7);
        let tau = Vector::<2>::new(5.0, -3.0);
        let te = Vector::<2>::new(1.5, 0.0);
        let a = arm.forward_dynamics(&q, &dq, &tau, &te);
        let b = Generic(arm).forward_dynamics(&q, &dq, &tau, &te);
        assert!((a - b).norm() < 1e-12 * b.norm(), "{a} vs {b}");
    }
}

#[cfg(test)]
mod kinematics_tests {
    use super::*;

    fn arm3() -> PlanarArm<3> {
        let link = |mass, length: f64| Link {
            mass,
            length,
            com: length / 2.0,
            inertia: mass * length * length / 12.0,
        };
        PlanarArm::new([link(2.0, 0.4), link(1.5, 0.35), link(1.0, 0.25)], 9.81).unwrap()
    }

    #[test]
    fn jacobian_and_its_derivative_match_finite_differences() {
        let arm = arm3();
        let q = Vector::<3>::new(0.3, -0.8, 1.1);
        let dq = Vector::<3>::new(0.7, -1.2, 0.4);
        let j = arm.jacobian(&q);
        let h = 1e-6;
        for i in 0..3 {
            let mut e = Vector::<3>::zeros();
            e[i] = h;
            let col = (arm.fk(&(q + e)) - arm.fk(&(q - e))) / (2.0 * h);
            assert!(
                (col - j.fixed_view::<3, 1>(0, i)).norm() < 1e-8,
                "column {i}"
            );
            // ω = J_ω q̇: the tip turns with every joint about z.
            let dr = arm.rotation(&(q + e)) * arm.rotation(&(q - e)).inverse();
            let w = crate::cartesian::rotation::log_quaternion(
                &nalgebra::UnitQuaternion::from_rotation_matrix(&dr),
            ) / (2.0 * h);
            assert!((w - j.fixed_view::<3, 1>(3, i)).norm() < 1e-8, "column {i}");
        }
        // J̇ q̇ = d/dt (J(q + t q̇)) q̇ at t = 0, by a central difference.
        let numeric = (arm.jacobian(&(q + h * dq)) - arm.jacobian(&(q - h * dq))) / (2.0 * h) * dq;
        let closed = arm.jdot_qdot(&q, &dq);
        assert!((closed - numeric).norm() < 1e-7, "{closed} vs {numeric}");
        assert_eq!(arm.fk(&q)[2], 0.0);
    }

    #[test]
    fn two_link_arm_reaches_l1_plus_l2_stretched_out() {
        let arm = TwoLinkArm::paper();
        let p = arm.fk(&Vector::<2>::zeros());
        assert!((p[0] - 0.66).abs() < 1e-15 && p[1] == 0.0, "{p}");
        let p = arm.fk(&Vector::<2>::new(core::f64::consts::FRAC_PI_2, 0.0));
        assert!((p[1] - 0.66).abs() < 1e-15, "{p}");
    }
}
