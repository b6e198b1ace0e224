//! The run-time API: the core for a number of joints n known only at run
//! time (a file's movable joints, a Python array's length, a C struct's `n`),
//! as pinocchio's `Model` is sized when it is read. Each type is the
//! const-generic core's (`Controller<N>`, `Chain<N>`, `Dynamics<N>`, …) for
//! its n, chosen once at construction: its buffers are sized then, its steps
//! allocate nothing, return the same errors and compute the same bits (a
//! test compares them for n = 1 … [`MAX_JOINTS`]). Firmware and callers who
//! know n keep the const-generic types.
//!
//! | here | the const-generic core | what |
//! |---|---|---|
//! | [`Scenario`] | [`schema::Scenario`](crate::schema::Scenario) | every parameter by name, and the one builder of the joint controller (feature `alloc`) |
//! | [`Tuning`] | [`tuning::Rule`](crate::tuning::Rule) | the gain and basis rule of SPEC §18: an arm's inertia, limits and period (and its task's path) to a [`Scenario`]; with a delay, the inertia-shaped gains of (18.12) |
//! | [`Controller`], [`State`] | [`Controller`](crate::Controller), [`State`](crate::State) | the joint controller, its own trajectory, its state (heap or the caller's buffer) |
//! | [`Measurement`], [`Setpoint`], [`Command`], [`Joints`] | [`Measurement`](crate::Measurement), … | a step's typed input and output: n values per joint quantity |
//! | [`Chain`], [`Dynamics`] | [`Chain`](crate::Chain), [`Dynamics`](crate::Dynamics) | kinematics and rigid-body dynamics, from joint data or an [`Arm`](crate::description::Arm) read from a URDF or an MJCF |
//! | [`ComputedTorque`], [`ComputedState`] | [`ComputedTorque`](crate::ComputedTorque) | the model-based baseline (SPEC §20) |
//! | [`CartesianImpedance`], [`CartesianController`] | [`CartesianImpedance`](crate::CartesianImpedance), [`CartesianController`](crate::CartesianController) | the 6-D outer loop, alone or with the joint controller it drives (SPEC §16) |
//! | [`operational_inertia`] | [`operational_inertia`](crate::cartesian::opspace::operational_inertia) | the operational-space inertia Λ of robosuite's OSC_POSE, SPEC (23.7) |
//! | [`pose_target`], [`HeldRotation`] | [`PoseTarget`](crate::PoseTarget) | a commanded pose from its flat layout, and the rotation a target without one keeps |
//! | [`simulate`], [`simulate_cartesian`], [`Plant`] (feature `sim`) | [`simulate_disturbed`](crate::sim::simulator::simulate_disturbed), [`Plant`](crate::Plant) | the closed loop over a plant of n joints, its rows and SPEC §12 metrics |
//! | [`Replay`], [`RowMetrics`] (feature `sim`) | a loop of [`Controller::step`](crate::Controller::step), [`MetricsAccumulator`](crate::sim::metrics::MetricsAccumulator) | the controller along recorded rows; the metrics of rows given one at a time |
//!
//! The Python bindings and the C ABI convert to and from these types; the
//! list of sizes a front is built for is [`MAX_JOINTS`], dispatched here
//! once ([`with_joints!`](crate::with_joints), [`joint_counts!`](crate::joint_counts)).
//!
//! A Rust program whose arm comes from a URDF read at run time steps the
//! joint controller and the Cartesian controller without a match over n
//! (a whole `src/main.rs`; give it the path of your URDF):
#![cfg_attr(
    feature = "urdf",
    doc = concat!("\n```\n", include_str!("../../tests/snippets/dynamic_urdf.rs"), "```\n")
)]
//!
//! The list of sizes itself, for code that needs a const `N`:
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

/// The joint counts the run-time API is built for: 1 … `MAX_JOINTS`.
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

/// A computation over the const-generic core for one number of joints N,
/// which a caller holding run-time values ([`ComputedTorque::typed`], …)
/// runs through [`for_joints`]: the one dispatch of a run-time n to a const
/// N, here, for code that must be generic over N (a typed loop).
pub trait ForJoints {
    /// What it gives.
    type Output;
    /// The computation for N joints.
    fn call<const N: usize>(self) -> Self::Output;
}

/// `f` for N = `n`, or `None` outside 1 … [`MAX_JOINTS`].
pub fn for_joints<F: ForJoints>(n: usize, f: F) -> Option<F::Output> {
    with_joints!(n, N => Some(f.call::<N>()), _ => None)
}

/// `$m! { J1 => 1, J2 => 2, …, J7 => 7 }`: a macro that defines one item
/// per joint count (the run-time types' impls for each N) gets the same
/// sizes as [`with_joints!`](crate::with_joints).
#[macro_export]
macro_rules! joint_counts {
    ($m:ident) => {
        $m! { J1 => 1, J2 => 2, J3 => 3, J4 => 4, J5 => 5, J6 => 6, J7 => 7 }
    };
}

// One family of const-generic types, indexed by the number of joints, and
// one value of it for the n known at run time: every type of this module is
// a `ByJoints` of its family, so the match over n is written once, here.
#[cfg(feature = "alloc")]
mod sized {
    /// A type for each number of joints N = 1 … [`MAX_JOINTS`](super::MAX_JOINTS).
    pub(crate) trait Family {
        /// The type for N joints.
        type Of<const N: usize>;
    }

    /// The value of a [`Family`] for the number of joints it was made for.
    pub(crate) enum ByJoints<F: Family> {
        J1(F::Of<1>),
        J2(F::Of<2>),
        J3(F::Of<3>),
        J4(F::Of<4>),
        J5(F::Of<5>),
        J6(F::Of<6>),
        J7(F::Of<7>),
    }

    /// `$body` with `$x` the value in `$e` (a `ByJoints`, by value or by
    /// reference) and `$N` its number of joints, a `const usize`.
    macro_rules! each {
        ($e:expr, $x:ident, $N:ident => $body:expr) => {
            match $e {
                $crate::dynamic::sized::ByJoints::J1($x) => {
                    #[allow(dead_code)]
                    const $N: usize = 1;
                    $body
                }
                $crate::dynamic::sized::ByJoints::J2($x) => {
                    #[allow(dead_code)]
                    const $N: usize = 2;
                    $body
                }
                $crate::dynamic::sized::ByJoints::J3($x) => {
                    #[allow(dead_code)]
                    const $N: usize = 3;
                    $body
                }
                $crate::dynamic::sized::ByJoints::J4($x) => {
                    #[allow(dead_code)]
                    const $N: usize = 4;
                    $body
                }
                $crate::dynamic::sized::ByJoints::J5($x) => {
                    #[allow(dead_code)]
                    const $N: usize = 5;
                    $body
                }
                $crate::dynamic::sized::ByJoints::J6($x) => {
                    #[allow(dead_code)]
                    const $N: usize = 6;
                    $body
                }
                $crate::dynamic::sized::ByJoints::J7($x) => {
                    #[allow(dead_code)]
                    const $N: usize = 7;
                    $body
                }
            }
        };
    }

    /// `$body` with `$x`, `$y` the values in `$a`, `$b` when both were made
    /// for the same number of joints `$N`, else `$other`.
    macro_rules! pair {
        ($a:expr, $b:expr, $x:ident, $y:ident, $N:ident => $body:expr, _ => $other:expr) => {
            match ($a, $b) {
                (
                    $crate::dynamic::sized::ByJoints::J1($x),
                    $crate::dynamic::sized::ByJoints::J1($y),
                ) => {
                    #[allow(dead_code)]
                    const $N: usize = 1;
                    $body
                }
                (
                    $crate::dynamic::sized::ByJoints::J2($x),
                    $crate::dynamic::sized::ByJoints::J2($y),
                ) => {
                    #[allow(dead_code)]
                    const $N: usize = 2;
                    $body
                }
                (
                    $crate::dynamic::sized::ByJoints::J3($x),
                    $crate::dynamic::sized::ByJoints::J3($y),
                ) => {
                    #[allow(dead_code)]
                    const $N: usize = 3;
                    $body
                }
                (
                    $crate::dynamic::sized::ByJoints::J4($x),
                    $crate::dynamic::sized::ByJoints::J4($y),
                ) => {
                    #[allow(dead_code)]
                    const $N: usize = 4;
                    $body
                }
                (
                    $crate::dynamic::sized::ByJoints::J5($x),
                    $crate::dynamic::sized::ByJoints::J5($y),
                ) => {
                    #[allow(dead_code)]
                    const $N: usize = 5;
                    $body
                }
                (
                    $crate::dynamic::sized::ByJoints::J6($x),
                    $crate::dynamic::sized::ByJoints::J6($y),
                ) => {
                    #[allow(dead_code)]
                    const $N: usize = 6;
                    $body
                }
                (
                    $crate::dynamic::sized::ByJoints::J7($x),
                    $crate::dynamic::sized::ByJoints::J7($y),
                ) => {
                    #[allow(dead_code)]
                    const $N: usize = 7;
                    $body
                }
                #[allow(unreachable_patterns)]
                _ => $other,
            }
        };
    }

    /// The `ByJoints` of `$body` (a `Result` of the family's type for the
    /// const `$N`) for the run-time `$n`, or `Err($other)` outside 1 …
    /// `MAX_JOINTS`.
    macro_rules! make {
        ($n:expr, $N:ident => $body:expr, _ => $other:expr) => {
            match $n {
                1 => {
                    const $N: usize = 1;
                    ($body).map($crate::dynamic::sized::ByJoints::J1)
                }
                2 => {
                    const $N: usize = 2;
                    ($body).map($crate::dynamic::sized::ByJoints::J2)
                }
                3 => {
                    const $N: usize = 3;
                    ($body).map($crate::dynamic::sized::ByJoints::J3)
                }
                4 => {
                    const $N: usize = 4;
                    ($body).map($crate::dynamic::sized::ByJoints::J4)
                }
                5 => {
                    const $N: usize = 5;
                    ($body).map($crate::dynamic::sized::ByJoints::J5)
                }
                6 => {
                    const $N: usize = 6;
                    ($body).map($crate::dynamic::sized::ByJoints::J6)
                }
                7 => {
                    const $N: usize = 7;
                    ($body).map($crate::dynamic::sized::ByJoints::J7)
                }
                _ => Err($other),
            }
        };
    }

    /// The `ByJoints` of another family: `$body` (a `Result`) for the value
    /// `$x` in `$e`, of the same number of joints `$N`.
    macro_rules! map {
        ($e:expr, $x:ident, $N:ident => $body:expr) => {
            $crate::dynamic::sized::each!($e, $x, $N => {
                ($body).map(|v| $crate::dynamic::sized::ByJoints::from_n::<$N>(v))
            })
        };
    }

    pub(crate) use {each, make, map, pair};

    impl<F: Family> ByJoints<F> {
        /// The number of joints it was made for.
        pub(crate) fn n(&self) -> usize {
            each!(self, _x, N => N)
        }
    }

    /// The variant of each N (a const item: every N = 1 … `MAX_JOINTS`
    /// has its impl), checked at compile time.
    pub(crate) trait Variant<F: Family, const N: usize> {
        fn wrap(v: F::Of<N>) -> ByJoints<F>;
        fn get(b: &ByJoints<F>) -> Option<&F::Of<N>>;
        fn get_mut(b: &mut ByJoints<F>) -> Option<&mut F::Of<N>>;
    }

    macro_rules! sized {
        ($($v:ident => $n:literal),+) => {
            $(impl<F: Family> Variant<F, $n> for ByJoints<F> {
                fn wrap(v: F::Of<$n>) -> ByJoints<F> {
                    ByJoints::$v(v)
                }
                fn get(b: &ByJoints<F>) -> Option<&F::Of<$n>> {
                    match b {
                        ByJoints::$v(v) => Some(v),
                        #[allow(unreachable_patterns)]
                        _ => None,
                    }
                }
                fn get_mut(b: &mut ByJoints<F>) -> Option<&mut F::Of<$n>> {
                    match b {
                        ByJoints::$v(v) => Some(v),
                        #[allow(unreachable_patterns)]
                        _ => None,
                    }
                }
            })+
        };
    }
    crate::joint_counts!(sized);

    impl<F: Family> ByJoints<F> {
        /// The variant of N holding `v`.
        pub(crate) fn from_n<const N: usize>(v: F::Of<N>) -> Self
        where
            Self: Variant<F, N>,
        {
            <Self as Variant<F, N>>::wrap(v)
        }

        /// The value, if it was made for N joints.
        pub(crate) fn get<const N: usize>(&self) -> Option<&F::Of<N>>
        where
            Self: Variant<F, N>,
        {
            <Self as Variant<F, N>>::get(self)
        }

        /// The value, to change, if it was made for N joints.
        pub(crate) fn get_mut<const N: usize>(&mut self) -> Option<&mut F::Of<N>>
        where
            Self: Variant<F, N>,
        {
            <Self as Variant<F, N>>::get_mut(self)
        }
    }

    impl<F: Family> Clone for ByJoints<F>
    where
        F::Of<1>: Clone,
        F::Of<2>: Clone,
        F::Of<3>: Clone,
        F::Of<4>: Clone,
        F::Of<5>: Clone,
        F::Of<6>: Clone,
        F::Of<7>: Clone,
    {
        fn clone(&self) -> Self {
            map!(self, x, N => Ok::<_, core::convert::Infallible>(x.clone()))
                .unwrap_or_else(|e| match e {})
        }
    }

    impl<F: Family> core::fmt::Debug for ByJoints<F>
    where
        F::Of<1>: core::fmt::Debug,
        F::Of<2>: core::fmt::Debug,
        F::Of<3>: core::fmt::Debug,
        F::Of<4>: core::fmt::Debug,
        F::Of<5>: core::fmt::Debug,
        F::Of<6>: core::fmt::Debug,
        F::Of<7>: core::fmt::Debug,
    {
        fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            each!(self, x, N => f.debug_tuple("ByJoints").field(&N).field(x).finish())
        }
    }
}

#[cfg(feature = "alloc")]
mod cartesian;
#[cfg(feature = "alloc")]
mod controller;
#[cfg(feature = "alloc")]
mod effort;
#[cfg(feature = "alloc")]
mod model;
mod opspace;
#[cfg(all(feature = "alloc", feature = "sim"))]
mod run;
#[cfg(feature = "alloc")]
mod target;
#[cfg(feature = "alloc")]
mod tuning;

#[cfg(feature = "alloc")]
mod values;

#[cfg(feature = "alloc")]
pub use cartesian::{
    CartesianCommand, CartesianController, CartesianImpedance, CartesianMeasurement,
    CartesianState, Joint, JointInput, TaskInput,
};
#[cfg(feature = "alloc")]
pub use controller::{Basis, Centres, Controller, Scenario, State};
#[cfg(feature = "alloc")]
pub use effort::{estimate_effort, Sampled, EFFORT_ACCEL, EFFORT_SPEED};
#[cfg(feature = "alloc")]
pub use model::{
    Chain, ComputedState, ComputedTorque, ComputedTorqueConfig, Drive, Dynamics, Jacobian,
    JointMatrix, SampledDrive, Spring, Tip,
};
pub use opspace::operational_inertia;
#[cfg(all(feature = "alloc", feature = "sim"))]
pub use run::{
    cartesian_steps, drive_cartesian, kept_rows, metrics_of, reads_the_wrench, run, simulate,
    simulate_cartesian, Arm as ModelArm, CartesianDriver, CartesianLoop, Control, Controlled,
    Disturbances, Hooks, Injected, Injection, Jacobian3, Loop, LoopJoint, Metrics, Output, Plant,
    Recorded, Reference, Replay, RigidBody, RowMetrics, Rows, Run, RunError, Spec, Table, TaskRows,
    TaskStep, TypedTaskStep, HOOK_EVERY,
};
#[cfg(feature = "alloc")]
pub use target::{pose_target, HeldRotation, TARGET_LEN};
#[cfg(feature = "alloc")]
pub use tuning::{default_task, Inertia, TaskPath, Tuning};
#[cfg(feature = "alloc")]
pub use values::{Command, Joints, Measurement, Setpoint};

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
