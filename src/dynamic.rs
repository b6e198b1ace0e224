//! The run-time number of joints, dispatched once: the const-generic core
//! (`Controller<N>`, `Chain<N>`, `Dynamics<N>`, …) behind a count the caller
//! knows only at run time (a Python array's length, a C struct's `n`, a
//! file's movable joints). The Python bindings and the C ABI both go through
//! [`with_joints!`](crate::with_joints) and [`joint_counts!`](crate::joint_counts),
//! so the list of sizes a front is built for lives here and nowhere else.
//!
//! ```
//! use adaptimp::{with_joints, Vector};
//!
//! // The norm of a vector whose length is known at run time only.
//! fn norm(x: &[f64]) -> Option<f64> {
//!     with_joints!(x.len(), N => Some(Vector::<N>::from_column_slice(x).norm()), _ => None)
//! }
//! assert_eq!(norm(&[3.0, 4.0]), Some(5.0));
//! assert_eq!(norm(&[0.0; 8]), None); // beyond MAX_JOINTS
//! ```

/// The joint counts the run-time fronts are built for: 1 … `MAX_JOINTS`.
pub const MAX_JOINTS: usize = 7;

/// `$body` with `$N` a `const usize` equal to the run-time `$n` when
/// 1 ≤ `$n` ≤ [`MAX_JOINTS`](crate::dynamic::MAX_JOINTS), else `$other`.
/// `$N` can stand wherever a const generic argument or an array length can.
#[macro_export]
macro_rules! with_joints {
    ($n:expr, $N:ident => $body:expr, _ => $other:expr $(,)?) => {
        match $n {
            1 => {
                const $N: usize = 1;
                $body
            }
            2 => {
                const $N: usize = 2;
                $body
            }
            3 => {
                const $N: usize = 3;
                $body
            }
            4 => {
                const $N: usize = 4;
                $body
            }
            5 => {
                const $N: usize = 5;
                $body
            }
            6 => {
                const $N: usize = 6;
                $body
            }
            7 => {
                const $N: usize = 7;
                $body
            }
            _ => $other,
        }
    };
}

/// `$m! { J1 => 1, J2 => 2, …, J7 => 7 }`: a front's macro that defines one
/// enum variant per joint count (a C handle holds a `Controller<N>` by value
/// of its size) gets the same sizes as [`with_joints!`](crate::with_joints).
#[macro_export]
macro_rules! joint_counts {
    ($m:ident) => {
        $m! { J1 => 1, J2 => 2, J3 => 3, J4 => 4, J5 => 5, J6 => 6, J7 => 7 }
    };
}

#[cfg(test)]
mod tests {
    use super::MAX_JOINTS;

    fn size_of_count(n: usize) -> Option<usize> {
        with_joints!(n, K => Some([0u8; K].len()), _ => None)
    }

    #[test]
    fn every_count_dispatches_to_itself_and_no_other() {
        for n in 1..=MAX_JOINTS {
            assert_eq!(size_of_count(n), Some(n));
        }
        assert_eq!(size_of_count(0), None);
        assert_eq!(size_of_count(MAX_JOINTS + 1), None);
    }

    #[test]
    fn joint_counts_lists_the_same_sizes() {
        macro_rules! collect {
            ($($v:ident => $n:literal),+) => {
                [$($n),+]
            };
        }
        let counts: [usize; MAX_JOINTS] = joint_counts!(collect);
        assert_eq!(counts, core::array::from_fn(|i| i + 1));
    }
}
