//! Fuzzed robot descriptions (SPEC §21): URDF text made of arbitrary links
//! and joints (any kind, parent and child indices that may name nothing,
//! mimics of anything, numbers including NaN and infinities, names with
//! markup), or arbitrary bytes. Reading and reducing return Ok or an error,
//! never panic or hang; an arm that was found reads back the same from its
//! reduced URDF.
#![no_main]

use adaptimp::description::{reduce, urdf};
use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;

#[derive(Arbitrary, Debug)]
struct J {
    kind: u8,
    parent: u8,
    child: u8,
    xyz: [f64; 3],
    rpy: [f64; 3],
    axis: [f64; 3],
    limits: Option<(f64, f64, f64)>,
    mimic: Option<(u8, f64)>,
}

#[derive(Arbitrary, Debug)]
enum Input {
    Bytes(Vec<u8>),
    Robot {
        links: u8,
        masses: Vec<f64>,
        joints: Vec<J>,
        tip: Option<u8>,
        fix: Vec<u8>,
        odd_name: bool,
    },
}

const KINDS: [&str; 8] = [
    "fixed",
    "revolute",
    "continuous",
    "prismatic",
    "floating",
    "planar",
    "spherical",
    "bogus",
];

fn text(links: u8, masses: &[f64], joints: &[J], odd_name: bool) -> String {
    let name = |i: u8| {
        if odd_name && i == 0 {
            "a&amp;&lt;b".to_string()
        } else {
            format!("l{i}")
        }
    };
    let mut out = String::from("<robot name='f'>");
    for i in 0..links.min(40) {
        match masses.get(usize::from(i)) {
            Some(m) => {
                out += &format!(
                    "<link name='{}'><inertial><origin xyz='0.1 0 0'/><mass value='{m}'/>\
                 <inertia ixx='1' ixy='0' ixz='0' iyy='1' iyz='0' izz='{m}'/></inertial></link>",
                    name(i)
                )
            }
            None => out += &format!("<link name='{}'/>", name(i)),
        }
    }
    for (k, j) in joints.iter().take(40).enumerate() {
        let [x, y, z] = j.xyz;
        let [r, p, w] = j.rpy;
        let [a, b, c] = j.axis;
        out += &format!(
            "<joint name='j{k}' type='{}'><parent link='{}'/><child link='{}'/>\
             <origin xyz='{x} {y} {z}' rpy='{r} {p} {w}'/><axis xyz='{a} {b} {c}'/>",
            KINDS[usize::from(j.kind) % KINDS.len()],
            name(j.parent),
            name(j.child)
        );
        if let Some((lo, hi, e)) = j.limits {
            out += &format!("<limit lower='{lo}' upper='{hi}' effort='{e}' velocity='1'/>");
        }
        if let Some((m, f)) = j.mimic {
            out += &format!("<mimic joint='j{m}' multiplier='{f}'/>");
        }
        out += "</joint>";
    }
    out + "</robot>"
}

fuzz_target!(|input: Input| {
    let (source, tip, fix) = match &input {
        Input::Bytes(b) => match std::str::from_utf8(b) {
            Ok(s) => (s.to_string(), None, Vec::new()),
            Err(_) => return,
        },
        Input::Robot {
            links,
            masses,
            joints,
            tip,
            fix,
            odd_name,
        } => (
            text(*links, masses, joints, *odd_name),
            tip.map(|t| format!("l{t}")),
            fix.iter().map(|f| format!("j{f}")).collect(),
        ),
    };
    let Ok(tree) = urdf::read_str(&source) else {
        return;
    };
    let fix: Vec<&str> = fix.iter().map(String::as_str).collect();
    let Ok(arm) = reduce(&tree, tip.as_deref(), &fix) else {
        return;
    };
    assert!(arm.n() >= 1);
    assert_eq!(arm.chain.len(), arm.n());
    assert_eq!(arm.inertials.len(), arm.n());
    // The reduced URDF reads back as the same arm.
    let Ok(reduced) = urdf::reduced_urdf(&tree, &arm, true) else {
        return;
    };
    let again = urdf::read_str(&reduced).expect("the reduced URDF reads");
    let back = reduce(&again, Some(&arm.tip), &[]).expect("the reduced URDF reduces");
    let names = |a: &adaptimp::description::Arm| -> Vec<String> {
        a.joints.iter().map(|j| j.name.clone()).collect()
    };
    assert_eq!(names(&back), names(&arm));
});
