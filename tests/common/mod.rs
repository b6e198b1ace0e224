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
