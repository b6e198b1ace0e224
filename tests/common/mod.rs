//! Shared helpers for the integration tests.
#![allow(dead_code)]

use std::collections::HashMap;
use std::path::Path;

/// A CSV fixture from `tests/data` (written by `benches/reference/make_fixtures.py`
/// from the independent Python implementation of the SPEC).
pub struct Fixture {
    pub header: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Fixture {
    pub fn load(name: &str) -> Self {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name);
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut lines = text.lines();
        let header = lines
            .next()
            .expect("header")
            .split(',')
            .map(str::to_owned)
            .collect();
        let rows = lines
            .filter(|l| !l.is_empty())
            .map(|l| l.split(',').map(|v| v.parse().expect("number")).collect())
            .collect();
        Self { header, rows }
    }

    pub fn col(&self, name: &str) -> usize {
        self.header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    }
}

/// `case,metric,value` → map from (case, metric) to value.
pub fn reference_metrics() -> HashMap<(String, String), f64> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/paper_metrics.csv");
    std::fs::read_to_string(path)
        .expect("paper_metrics.csv")
        .lines()
        .skip(1)
        .map(|l| {
            let mut it = l.split(',');
            let case = it.next().expect("case").to_owned();
            let metric = it.next().expect("metric").to_owned();
            let value = it.next().expect("value").parse().expect("number");
            ((case, metric), value)
        })
        .collect()
}

/// The Franka Emika Panda to its tool centre point, from the joint data of
/// example-robot-data's `panda.urdf` (`<origin xyz rpy>`, `<axis>`; the fixed
/// joints `panda_joint8`, `panda_hand_joint`, `panda_hand_tcp_joint`).
pub fn panda() -> adaptimp::Chain<7> {
    use adaptimp::{Chain, Joint, Transform};
    let h = std::f64::consts::FRAC_PI_2;
    let rev = |xyz: [f64; 3], roll: f64| {
        Joint::revolute(
            Transform::from_xyz_rpy(xyz, [roll, 0.0, 0.0]),
            [0.0, 0.0, 1.0],
        )
    };
    let joints = [
        rev([0.0, 0.0, 0.333], 0.0),
        rev([0.0, 0.0, 0.0], -h),
        rev([0.0, -0.316, 0.0], h),
        rev([0.0825, 0.0, 0.0], h),
        rev([-0.0825, 0.384, 0.0], -h),
        rev([0.0, 0.0, 0.0], h),
        rev([0.088, 0.0, 0.0], h),
        Joint::fixed(Transform::from_xyz_rpy([0.0, 0.0, 0.107], [0.0; 3])),
        Joint::fixed(Transform::from_xyz_rpy(
            [0.0; 3],
            [0.0, 0.0, -std::f64::consts::FRAC_PI_4],
        )),
    ];
    let tcp = Transform::from_xyz_rpy([0.0, 0.0, 0.1034], [0.0; 3]);
    Chain::new(&joints, &tcp).expect("the Panda's joint data")
}

/// The Panda's torque limits (N m), the URDF's `<limit effort>`.
pub const PANDA_EFFORT: [f64; 7] = [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0];

/// The Panda's reference posture (rad), the SRDF's `default`.
// The SRDF's numbers as written (close to, not exactly, π/4 and π/2).
#[allow(clippy::approx_constant)]
pub const PANDA_HOME: [f64; 7] = [0.0, -0.785398, 0.0, -2.35619, 0.0, 1.5707, 0.785398];

/// The n = 7 Cartesian controller of the allocation test, the benchmark
/// `step/cart7` and the instruction counts: the Panda's chain, the 6-D outer
/// loop with SPEC §16's defaults, and the hardened state-feedback joint
/// controller at 1 kHz (L = 64 centres along the joint orbit of a 4 cm
/// circle, by the core's orbit rule; the Panda's effort limits; Kp of
/// docs/panda.md). `bound`: the weight bound of every network (the
/// projection acts when a norm exceeds it); `clip`: pos/rot error limits;
/// `tau_max`: the actuator limits (N m).
pub fn cart7(
    bound: f64,
    clip: Option<f64>,
    tau_max: [f64; 7],
) -> adaptimp::CartesianController<7, adaptimp::Chain<7>, adaptimp::Centers<7, Vec<f64>>> {
    use adaptimp::{
        CartesianConfig, CartesianController, CartesianImpedance, Centers, Config, Controller,
        ImpedanceMode, Kinematics, Law, Setpoint, Vector, WeightBound,
    };
    let chain = panda();
    let q0 = Vector::<7>::from_column_slice(&PANDA_HOME);
    let cfg = CartesianConfig {
        pos_error_max: clip,
        rot_error_max: clip,
        ..CartesianConfig::default()
    };
    let outer = CartesianImpedance::new(cfg, chain, 1e-3).expect("outer loop");
    let tip = chain.tip(&q0, &Vector::zeros());
    let zero = Setpoint {
        x: Vector::<7>::zeros(),
        dx: Vector::zeros(),
        ddx: Vector::zeros(),
    };
    let mut samples = vec![zero; 64];
    let written = outer
        .orbit(q0, 2000, |k| circle(&tip, k as f64 * 1e-3), &mut samples)
        .expect("orbit");
    let basis = Centers::along(&samples[..written], [0.05, 0.2]).expect("basis");
    let tau_max = Vector::<7>::from(tau_max);
    let mut joint = Config::<7>::new(Law::StateFeedback, tau_max).hardened();
    joint.ts = 1e-3;
    joint.impedance = ImpedanceMode::External;
    joint.kp = Vector::from_column_slice(&[66.6, 242.0, 136.0, 101.0, 9.24, 8.44, 1.63]);
    joint.kzeta = joint.kp.map(|k| (1.0 + k * k) / 2.0 + 10.0);
    joint.k1 = Vector::from_element(20.0);
    joint.gamma = [1.0; 3];
    joint.weight_bound = WeightBound::Fixed([bound; 3]);
    let inner = Controller::new(joint, basis).expect("joint controller");
    CartesianController::new(outer, inner).expect("pair")
}

/// A 4 cm circle at 0.5 Hz in the horizontal plane through the tip of `tip`,
/// the orientation held: the commanded pose at `t` (s).
pub fn circle(tip: &adaptimp::Tip<7>, t: f64) -> adaptimp::PoseTarget {
    use adaptimp::{PoseTarget, Vector};
    let w = std::f64::consts::PI;
    let (s, c) = ((w * t).sin(), (w * t).cos());
    PoseTarget {
        p: tip.position + Vector::<3>::new(0.04 * (c - 1.0), 0.04 * s, 0.0),
        dp: Vector::<3>::new(-0.04 * w * s, 0.04 * w * c, 0.0),
        ddp: Vector::<3>::new(-0.04 * w * w * c, -0.04 * w * w * s, 0.0),
        ..PoseTarget::at(tip.position, *tip.rotation.matrix())
    }
}

/// The bits of each of `v` (to compare two computations exactly).
pub fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A chain of N revolute joints about alternating axes, a fixed joint and
/// a tip offset (the run-time API's tests against the const-generic core).
pub fn joints<const N: usize>() -> Vec<adaptimp::Joint> {
    use adaptimp::{Joint, Transform};
    let mut js: Vec<Joint> = (0..N)
        .map(|i| {
            let axis = if i % 2 == 0 {
                [0.0, 0.0, 1.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            Joint::revolute(
                Transform::from_xyz_rpy([0.05 * i as f64, 0.0, 0.12], [0.1 * i as f64, 0.0, 0.0]),
                axis,
            )
        })
        .collect();
    js.push(Joint::fixed(Transform::from_xyz_rpy(
        [0.0, 0.0, 0.1],
        [0.0; 3],
    )));
    js
}

/// A posture of N joints, the k-th of a smooth sequence (rad).
pub fn q_of<const N: usize>(k: usize) -> adaptimp::Vector<N> {
    adaptimp::Vector::from_fn(|i, _| 0.3 * ((k + 1) as f64 * 0.7 + i as f64).sin())
}
