//! Read an arm from a URDF in Rust (SPEC §21), the same in Python
//! (`examples/16_read_urdf.py`) and C (`ffi/examples/16_read_urdf.c`): the
//! core reads the file, finds the arm by its one rule (which chain, which
//! joints, the tip, what is held and why) and builds its chain and dynamics;
//! then the joint and the Cartesian controller step, through the run-time
//! API (`adaptimp::dynamic`): the number of joints is the file's, known only
//! when it is read, and nothing here matches over it.
//!
//! ```text
//! cargo run --example read_urdf [PATH] [--tip LINK] [--fix JOINT]...
//! ```
//!
//! Without PATH, the URDF text below: a 3-joint arm holding a gripper whose
//! jaw a finger mimics (the jaw is held: a gripper's drive).

use adaptimp::description::{reduce, urdf, Arm, ArmJoint};
use adaptimp::dynamic::{
    CartesianController, CartesianImpedance, CartesianMeasurement, Chain, Dynamics, Measurement,
    Scenario,
};
use adaptimp::{schema::Value, Law, Preset, Vector, GRAVITY};

const URDF: &str = "<robot name='demo'>\
<link name='base'/>\
<link name='upper'><inertial><origin xyz='0.15 0 0'/><mass value='2'/>\
<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.02' iyz='0' izz='0.02'/></inertial></link>\
<link name='fore'><inertial><origin xyz='0.1 0 0'/><mass value='1'/>\
<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link>\
<link name='hand'><inertial><mass value='0.3'/>\
<inertia ixx='1e-4' ixy='0' ixz='0' iyy='1e-4' iyz='0' izz='1e-4'/></inertial></link>\
<link name='tool'/><link name='jaw'/><link name='finger'/>\
<joint name='shoulder' type='revolute'><parent link='base'/><child link='upper'/>\
<origin xyz='0 0 0.1'/><axis xyz='0 0 1'/>\
<limit lower='-3' upper='3' effort='20' velocity='2'/><dynamics damping='0.5'/></joint>\
<joint name='elbow' type='revolute'><parent link='upper'/><child link='fore'/>\
<origin xyz='0.3 0 0'/><axis xyz='0 1 0'/>\
<limit lower='-2' upper='2' effort='10' velocity='2'/></joint>\
<joint name='wrist' type='continuous'><parent link='fore'/><child link='hand'/>\
<origin xyz='0.2 0 0'/><axis xyz='1 0 0'/></joint>\
<joint name='flange' type='fixed'><parent link='hand'/><child link='tool'/>\
<origin xyz='0.05 0 0'/></joint>\
<joint name='jaw_joint' type='revolute'><parent link='hand'/><child link='jaw'/>\
<axis xyz='0 0 1'/><limit lower='0' upper='1' effort='1' velocity='1'/></joint>\
<joint name='finger_joint' type='revolute'><parent link='hand'/><child link='finger'/>\
<axis xyz='0 0 1'/><limit lower='-1' upper='0' effort='1' velocity='1'/>\
<mimic joint='jaw_joint' multiplier='-1'/></joint>\
</robot>";

/// The arm's model and both controllers through the run-time API (n known
/// only now, no match over it): the tip and the moving mass, then 0.1 s of
/// steps of the joint controller and of the Cartesian controller with the
/// arm measured 0.05 rad from the start q = 0 on every joint.
fn drive(arm: &Arm) -> Result<(), Box<dyn std::error::Error>> {
    let n = arm.n();
    let chain = Chain::from_arm(arm)?;
    let (p, _) = chain.pose(&vec![0.0; n])?;
    println!("tip at q = 0: {} {} {}", p.x, p.y, p.z);
    let mass = Dynamics::from_arm(arm, GRAVITY)?.mass();
    println!("moving mass: {mass:.6} kg");
    let tau_max: Vec<f64> = arm.joints.iter().map(effort).collect();
    let mut s = Scenario::new(n, Preset::Robot, Law::Pd)?; // every parameter by name
    s.set("tau_max", Value::Vec(&tau_max))?;
    let joint = s.controller()?; // sized for n, once; its steps allocate nothing
    let mut state = joint.new_state();
    let (q, zero) = (vec![0.05; n], vec![0.0; n]);
    let m = Measurement {
        x: &q,
        dx: Some(&zero),
        tau_e: &zero,
    };
    for _ in 0..100 {
        joint.step(&mut state, &m, None)?; // along its own trajectory
    }
    println!("joint controller: tau = {:.3?} N m", state.last().tau_sat);
    s.set("impedance", Value::Str("external"))?; // the outer loop is the impedance
    let outer = CartesianImpedance::new(s.cartesian(), &chain, joint.period())?;
    let pair = CartesianController::new(outer, s.controller()?)?;
    let (mut task, mut inner) = (pair.start(&zero)?, pair.joint().new_state());
    let m = CartesianMeasurement {
        q: &q,
        dq: Some(&zero),
        wrench: Vector::zeros(),
    };
    for _ in 0..100 {
        pair.step(&mut task, &mut inner, &m, None)?; // hold the pose of q = 0
    }
    println!(
        "Cartesian controller: tau = {:.3?} N m",
        inner.last().tau_sat
    );
    Ok(())
}

/// τmax of a joint (N m): the URDF's effort limit; where it states none,
/// 10 N m, and said.
fn effort(j: &ArmJoint) -> f64 {
    if j.effort > 0.0 {
        return j.effort;
    }
    println!(
        "  {}: no effort limit in the URDF, tau_max = 10 N m",
        j.name
    );
    10.0
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (mut source, mut tip, mut fix) = (None, None, Vec::new());
    // Under `cargo test` the arguments are the harness's: the text below.
    let mut args = std::env::args().skip(if cfg!(test) { usize::MAX } else { 1 });
    while let Some(a) = args.next() {
        match a.as_str() {
            "--tip" => tip = args.next(),
            "--fix" => fix.extend(args.next()),
            _ => source = Some(a),
        }
    }
    let tree = match &source {
        Some(path) => urdf::read_file(path)?,
        None => urdf::read_str(URDF)?,
    };
    let fix: Vec<&str> = fix.iter().map(String::as_str).collect();
    let arm = reduce(&tree, tip.as_deref(), &fix)?;
    println!("{}: n = {}, tip '{}'", arm.source, arm.n(), arm.tip);
    for j in &arm.joints {
        println!(
            "  {}: limits [{}, {}], effort {}, damping {}, friction {}",
            j.name, j.lower, j.upper, j.effort, j.damping, j.friction
        );
    }
    for h in &arm.held {
        println!("  held {} = {}: {}", h.name, h.value, h.reason);
    }
    drive(&arm)
}

/// `cargo test` runs this example on the text (`cfg!(test)`).
#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main().unwrap();
    }
}
