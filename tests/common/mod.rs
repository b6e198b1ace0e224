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

/// The Panda's reference posture (rad), the SRDF's `default`.
pub const PANDA_HOME: [f64; 7] = [0.0, -0.785398, 0.0, -2.35619, 0.0, 1.5707, 0.785398];
