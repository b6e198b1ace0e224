//! Read an arm from a URDF in Rust (SPEC §21), the same in Python
//! (`examples/16_read_urdf.py`) and C (`ffi/examples/16_read_urdf.c`): the
//! core reads the file, finds the arm by its one rule (which chain, which
//! joints, the tip, what is held and why) and builds its chain and dynamics.
//!
//! ```text
//! cargo run --example read_urdf [PATH] [--tip LINK] [--fix JOINT]...
//! ```
//!
//! Without PATH, the URDF text below: a 3-joint arm holding a gripper whose
//! jaw a finger mimics (the jaw is held: a gripper's drive).

use adaptimp::description::{reduce, urdf};
use adaptimp::{Chain, Dynamics, Kinematics, Vector, GRAVITY};

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

/// The tip's position at q = 0 and the moving mass, for an arm of `N` joints.
fn report<const N: usize>(arm: &adaptimp::description::Arm) -> Result<(), adaptimp::Error> {
    let chain: Chain<N> = arm.to_chain()?;
    let dynamics: Dynamics<N> = arm.to_dynamics(GRAVITY)?;
    let p = chain.fk(&Vector::<N>::zeros());
    println!("tip at q = 0: {} {} {}", p.x, p.y, p.z);
    println!("moving mass: {:.6} kg", dynamics.mass());
    Ok(())
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
    match arm.n() {
        1 => report::<1>(&arm)?,
        2 => report::<2>(&arm)?,
        3 => report::<3>(&arm)?,
        4 => report::<4>(&arm)?,
        5 => report::<5>(&arm)?,
        6 => report::<6>(&arm)?,
        7 => report::<7>(&arm)?,
        n => return Err(format!("the arm has {n} joints; hold some with --fix").into()),
    }
    Ok(())
}

/// `cargo test` runs this example on the text (`cfg!(test)`).
#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main().unwrap();
    }
}
