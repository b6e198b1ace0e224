//! The linear-algebra aliases every module uses: a leaf (it imports nothing
//! of the crate), so the module graph flows one way (STYLE.md 11).

/// A column vector of `N` reals (joint-space quantities: rad, rad/s, N m, …).
pub type Vector<const N: usize> = nalgebra::SVector<f64, N>;
/// An `N × N` real matrix (inertia, Coriolis, …).
pub type Matrix<const N: usize> = nalgebra::SMatrix<f64, N, N>;
/// The `3 × N` Jacobian ∂p/∂q of an end-effector position p ∈ R³ (m/rad).
pub type Jacobian<const N: usize> = nalgebra::SMatrix<f64, 3, N>;

/// Number of RBF nodes of the paper's vertex grid for `n` joints: `2^(4n)`
/// (256 for the 2-link arm), SPEC §6.
pub const fn grid_nodes(n: usize) -> usize {
    1 << (4 * n)
}

/// The names of an enum's variants in Python and the parameter schema,
/// declared once beside the variants: `NAMES[i]` names `ALL[i]`.
macro_rules! choices {
    ($t:ty { $($name:literal => $variant:expr),+ $(,)? }) => {
        impl $t {
            /// The choices' names (Python, command line, schema), in order.
            pub const NAMES: [&'static str; [$($name),+].len()] = [$($name),+];
            /// The choices, in the order of [`NAMES`](Self::NAMES).
            pub const ALL: [Self; [$($name),+].len()] = [$($variant),+];

            /// This choice's name.
            pub fn name(self) -> &'static str {
                let i = Self::ALL.iter().position(|v| *v == self).unwrap_or(0);
                Self::NAMES[i]
            }
        }
    };
}
pub(crate) use choices;
