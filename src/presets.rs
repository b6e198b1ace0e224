//! The presets: every SPEC default as a constructor ([`Config::new`],
//! [`Config::paper`], [`Config::robot`], [`Config::hardened`],
//! [`Controller::paper`], [`Controller::robot`], [`SimConfig::paper`],
//! [`Sinusoid::paper`], [`Wall::paper`], [`TwoLinkArm::paper`], the default
//! [`ArmParams`] and [`CartesianConfig`], [`Grid::paper`], and
//! [`Tracker::paper`]), each read from the parameter table of
//! [`schema`](crate::schema).
//!
//! This module sits above both the schema and the types it builds: the
//! controller, the networks, task space and the simulator never call into it
//! (nor into the schema), so the module graph runs one way, from here down.

use crate::cartesian::CartesianConfig;
use crate::control::config::{Config, Law};
use crate::control::controller::Controller;
#[cfg(feature = "alloc")]
use crate::control::tracker::Tracker;
use crate::networks::rbf::Grid;
use crate::schema::{preset_error, Group, Preset, Scenario, PARAMS};
#[cfg(feature = "sim")]
use crate::sim::environment::Wall;
#[cfg(feature = "sim")]
use crate::sim::model::{ArmParams, TwoLinkArm};
#[cfg(feature = "sim")]
use crate::sim::simulator::SimConfig;
use crate::trajectory::Sinusoid;
use crate::types::Vector;

impl<const N: usize> Config<N> {
    /// The paper's gains for `N` joints with limits `tau_max` (N m); Ts = 50 µs
    /// (the paper scenario, SPEC §11): the schema's paper defaults.
    pub fn new(law: Law, tau_max: Vector<N>) -> Self {
        let mut cfg = Scenario::<N>::preset(Preset::Paper, law).config;
        cfg.tau_max = tau_max;
        cfg
    }

    /// This configuration with every hardened option of the robot scenario
    /// (SPEC §13), whatever Ts is: each controller parameter whose robot
    /// default differs from the paper's, except Ts. That is:
    ///
    /// - [`LearningStep::Normalized`](crate::networks::learning::LearningStep::Normalized) with κ = 0.5 (the per-step learning gain
    ///   stays below Kp/2; the printed Euler step exceeds Kp at 1 ms);
    /// - [`SaturationLearning::Freeze`](crate::networks::learning::SaturationLearning::Freeze) (no learning into the limits);
    /// - [`WeightBound::Auto`](crate::control::config::WeightBound::Auto) (bounds from τmax and the commanded trajectory);
    /// - the tanh robust term (sgn chatters at 1 kHz) with φ = 0.05 rad/s;
    /// - observer: [`Hold::Triangle`](crate::control::observer::Hold::Triangle) (at Ts ≫ ε it is the backward difference
    ///   of the samples, where ZOH estimates ≈ 0 at the sample instants),
    ///   started at the first measurement, its estimate compared with the
    ///   reference the observer's lag back (`observer_lead`, (9.1), SPEC §9).
    pub fn hardened(self) -> Self {
        let mut s = Scenario::<N>::preset(Preset::Paper, self.law);
        s.config = self;
        for p in PARAMS {
            if let (Group::Controller, Some(v), false) = (p.group, p.robot, p.name == "Ts") {
                if let Err(e) = s.set(p.name, v) {
                    preset_error(p.name, e)
                }
            }
        }
        s.config
    }
}

impl Config<2> {
    /// The paper scenario (SPEC §11) for the 2-link arm: every default of the SPEC.
    pub fn paper(law: Law) -> Self {
        Scenario::<2>::preset(Preset::Paper, law).config
    }

    /// The "robot" scenario (SPEC §13, beyond the paper): the paper's arm,
    /// gains, Γ, σ, η² and 256 nodes at a robot's Ts = 1 ms, with the
    /// [hardened](Self::hardened) options as defaults.
    pub fn robot(law: Law) -> Self {
        Scenario::<2>::preset(Preset::Robot, law).config
    }
}

#[cfg(feature = "sim")]
impl SimConfig<2> {
    /// The paper scenario: T = 20 s, M = 1, q(0) = [0.25, −0.05], q̇(0) = 0 (SPEC §11, (65)).
    pub fn paper() -> Self {
        Scenario::<2>::preset(Preset::Paper, Law::Pd).sim
    }

    /// The "robot" scenario's run: the paper scenario with M = 10 RK4 substeps
    /// per 1 ms period (SPEC §13). Use with [`Config::robot`].
    pub fn robot() -> Self {
        Scenario::<2>::preset(Preset::Robot, Law::Pd).sim
    }
}

impl Sinusoid<2> {
    /// The paper's commanded circle (64): centre [0.2, 0.2] rad, radius 0.2 rad, ω = π rad/s.
    pub fn paper() -> Self {
        Scenario::<2>::preset(Preset::Paper, Law::Pd)
            .trajectory()
            .unwrap_or_else(|e| preset_error("xc", e))
    }
}

#[cfg(feature = "sim")]
impl Wall<2> {
    /// SPEC §3 defaults: joint 1 (index 0), w = 0.2 rad, ke = 1000 N m/rad, be = 10 N m s/rad.
    pub fn paper() -> Self {
        let s = Scenario::<2>::preset(Preset::Paper, Law::Pd);
        let w = s
            .wall
            .unwrap_or_else(|| unreachable!("the paper has a wall"));
        Wall::new(0, w, s.ke_be[0], s.ke_be[1]).unwrap_or_else(|e| preset_error("wall", e))
    }
}

#[cfg(feature = "sim")]
impl Default for ArmParams {
    /// SPEC §1 defaults: m = [2.00, 0.85] kg, l = [0.35, 0.31] m, lc = l/2,
    /// I = m l²/4, g = 9.81 m/s².
    fn default() -> Self {
        Scenario::<2>::preset(Preset::Paper, Law::Pd).arm.resolve()
    }
}

impl Grid<2> {
    /// The paper's grid for the 2-link arm: 256 nodes, η² = 25 (SPEC §6).
    pub fn paper() -> Self {
        Scenario::<2>::preset(Preset::Paper, Law::Pd)
            .grid()
            .unwrap_or_else(|e| preset_error("eta2", e))
    }
}

#[cfg(feature = "sim")]
impl TwoLinkArm {
    /// The arm with the SPEC §1 default parameters.
    pub fn paper() -> Self {
        // The defaults satisfy every condition checked by `new`.
        Self::from_valid(ArmParams::default())
    }
}

impl Default for CartesianConfig {
    /// The schema's defaults (SPEC §16).
    fn default() -> Self {
        Scenario::<1>::preset(Preset::Robot, Law::Pd).cartesian
    }
}

impl Controller<2, Grid<2>> {
    /// The paper's controller `law` with every SPEC default (the 256-node grid,
    /// η² = 25).
    pub fn paper(law: Law) -> Self {
        Self::new(Config::paper(law), Grid::paper())
            .unwrap_or_else(|e| unreachable!("the paper configuration is valid: {e}"))
    }

    /// The robot scenario's controller `law` (SPEC §13: Ts = 1 ms, the hardened
    /// options), with its weight bounds for the paper's circle.
    pub fn robot(law: Law) -> Self {
        Self::for_trajectory(Config::robot(law), Grid::paper(), &Sinusoid::paper())
            .unwrap_or_else(|e| unreachable!("the robot configuration is valid: {e}"))
    }
}

#[cfg(feature = "alloc")]
impl Tracker<2, Grid<2>, Sinusoid<2>> {
    /// The paper's controller `law` (every SPEC default) on the paper's circle (64).
    pub fn paper(law: Law) -> Self {
        Self::new(Controller::paper(law), Sinusoid::paper())
    }

    /// The robot scenario's controller `law` on the paper's circle (SPEC §13).
    pub fn robot(law: Law) -> Self {
        Self::new(Controller::robot(law), Sinusoid::paper())
    }
}

#[cfg(all(test, feature = "sim"))]
mod tests {
    use super::*;
    use crate::control::config::WeightBound;

    #[test]
    fn presets_are_the_documented_values() {
        let c = Config::paper(Law::StateFeedback);
        assert_eq!(c.ts, 50e-6);
        assert_eq!(c.tau_max, Vector::<2>::new(17.0, 15.0));
        let r = Config::robot(Law::StateFeedback);
        assert_eq!(r.ts, 1e-3);
        assert_eq!(r.weight_bound, WeightBound::Auto);
        assert_eq!(Config::paper(Law::StateFeedback).hardened().ts, 50e-6);
        let mut h = Config::robot(Law::StateFeedback);
        h.ts = 50e-6;
        assert_eq!(Config::paper(Law::StateFeedback).hardened(), h);
        assert_eq!(SimConfig::robot().substeps, 10);
        let a = ArmParams::default();
        assert!((a.i2 - 0.85 * 0.31 * 0.31 / 4.0).abs() < 1e-15);
        assert_eq!(Wall::paper().position(), 0.2);
        assert_eq!(Grid::paper().eta2(), 25.0);
    }
}
