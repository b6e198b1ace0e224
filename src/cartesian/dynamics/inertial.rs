//! A link's inertial as a description states it ([`Inertial`]), what gravity
//! compensation lifts of it ([`Lifted`]), and the checks of a physical inertia.

use super::*;

/// The inertial of one link as a URDF or a MuJoCo model states it: the
/// mass, and the rotational inertia about the centre of mass in the frame
/// `origin` (the centre of mass and the inertia's axes in the link's frame).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Inertial {
    /// Mass m (kg), ≥ 0.
    pub mass: f64,
    /// The centre of mass (translation, m) and the axes of `inertia`
    /// (rotation) in the link's frame (URDF's `<inertial><origin>`).
    pub origin: Transform,
    /// Rotational inertia about the centre of mass in `origin`'s axes (kg
    /// m², row-major), symmetric and positive semi-definite
    /// ([`principal_moments`] ≥ 0).
    pub inertia: [[f64; 3]; 3],
}

/// What gravity compensation lifts of one link (MuJoCo's body `gravcomp`,
/// SPEC (20.1')): the mass l whose weight is lifted (kg; Σ gravcomp × mass,
/// negative where a negative share adds weight) and its first moment λ = Σ
/// gravcomp × mass × centre (kg m), in the link's frame. A first moment, not
/// a centre: shares of both signs can lift a couple with l = 0.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Lifted {
    /// l (kg).
    pub mass: f64,
    /// λ (kg m), in the link's frame.
    pub moment: [f64; 3],
}

/// The principal moments of the inertia `i` (kg m², the symmetric part's
/// eigenvalues), smallest first. A rigid body's are ≥ 0 (and any two sum to
/// at least the third): a negative one makes the mass matrix indefinite.
pub fn principal_moments(i: &[[f64; 3]; 3]) -> [f64; 3] {
    let m = Matrix3::from_fn(|r, c| 0.5 * (i[r][c] + i[c][r]));
    let e = m.symmetric_eigenvalues();
    let mut v = [e[0], e[1], e[2]];
    v.sort_unstable_by(f64::total_cmp);
    v
}

/// The most negative smallest principal moment an inertia may have,
/// relative to its largest (rounding in a file that prints six digits of a
/// singular inertia: a rod, a thin plate).
pub const INERTIA_TOLERANCE: f64 = 1e-6;

/// A principal moment (kg m²) no arm's dynamics can tell from zero: an
/// exported file's rounding noise on a massless link (1e-35 in a file of
/// example-robot-data's iCub).
pub const INERTIA_FLOOR: f64 = 1e-12;

/// Whether the inertia `i` is one a rigid body has: positive semi-definite,
/// its smallest principal moment ≥ −([`INERTIA_TOLERANCE`] × its largest +
/// [`INERTIA_FLOOR`]). Returns the principal moments (smallest first) on
/// failure.
pub fn physical_inertia(i: &[[f64; 3]; 3]) -> Result<(), [f64; 3]> {
    let m = principal_moments(i);
    if m[0] >= -(INERTIA_TOLERANCE * m[2].abs() + INERTIA_FLOOR) {
        Ok(())
    } else {
        Err(m)
    }
}

impl Inertial {
    /// No mass (a link whose inertial is not given).
    pub const NONE: Self = Self {
        mass: 0.0,
        origin: Transform::IDENTITY,
        inertia: [[0.0; 3]; 3],
    };

    /// A point mass `mass` (kg) at `com` (m) of the link's frame.
    pub fn point(mass: f64, com: [f64; 3]) -> Self {
        Self {
            mass,
            origin: Transform {
                translation: com,
                ..Transform::IDENTITY
            },
            inertia: [[0.0; 3]; 3],
        }
    }

    /// Validated: finite, mass ≥ 0, the inertia symmetric (to 1e-9 of its
    /// largest entry) with a non-negative diagonal.
    pub(super) fn check(&self, index: usize) -> Result<(Frame, Matrix3<f64>), Error> {
        let frame = self.origin.check(index)?;
        check::finite("link mass", self.mass)?;
        if self.mass < 0.0 {
            return Err(Error::Condition {
                condition: "mass ≥ 0",
                lhs: "link mass",
                index: Some(index),
                value: self.mass,
            });
        }
        // Bounded as every physical parameter (beyond, a model overflows in use).
        if self.mass > PARAM_BOUND {
            return Err(Error::Condition {
                condition: "|value| ≤ 1e9",
                lhs: "link mass",
                index: Some(index),
                value: self.mass,
            });
        }
        let i = Matrix3::from_fn(|r, c| self.inertia[r][c]);
        check::finite_slice("link inertia", i.as_slice())?;
        if i.amax() > PARAM_BOUND {
            return Err(Error::Condition {
                condition: "|value| ≤ 1e9",
                lhs: "link inertia",
                index: Some(index),
                value: i.amax(),
            });
        }
        let scale = i.amax();
        let asym = (i - i.transpose()).amax();
        if asym > 1e-9 * scale {
            return Err(Error::Condition {
                condition: "the inertia is symmetric (|I − Iᵀ| ≤ 1e-9 |I|)",
                lhs: "link inertia asymmetry",
                index: Some(index),
                value: asym,
            });
        }
        if let Err(m) = physical_inertia(&self.inertia) {
            return Err(Error::Condition {
                condition: "the inertia is positive semi-definite (its principal moments ≥ 0)",
                lhs: "link inertia's smallest principal moment",
                index: Some(index),
                value: m[0],
            });
        }
        Ok((frame, i))
    }
}
