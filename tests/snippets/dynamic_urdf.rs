use adaptimp::description::{reduce, urdf};
use adaptimp::dynamic::{
    CartesianController, CartesianImpedance, CartesianMeasurement, Chain, Measurement, Scenario,
};
use adaptimp::{schema::Value, Law, Preset, Vector};

/// Two links, when no file is given.
const TWO_LINKS: &str = r#"<robot name="two"><link name="base"/><link name="upper"/><link name="fore"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="20" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
</robot>"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let tree = match std::env::args().nth(1) {
        Some(path) => urdf::read_file(&path)?, // a URDF file of yours
        None => urdf::read_str(TWO_LINKS)?,
    };
    let arm = reduce(&tree, None, &[])?; // the arm's joints: n is known from here on
    let n = arm.n();
    // τmax (N m): the URDF's effort limits; where it states none, 10 N m (said).
    let tau_max: Vec<f64> = arm.joints.iter().map(|j| if j.effort > 0.0 { j.effort } else {
        println!("{}: no effort limit in the URDF, tau_max = 10 N m", j.name);
        10.0
    }).collect();
    let mut s = Scenario::new(n, Preset::Robot, Law::Pd)?; // every parameter by name
    s.set("tau_max", Value::Vec(&tau_max))?;
    let joint = s.controller()?; // sized for n, once; its steps allocate nothing
    let mut state = joint.new_state();
    let (q, zero) = (vec![0.05; n], vec![0.0; n]); // measured q (rad), q̇ (rad/s), τe (N m)
    let m = Measurement { x: &q, dx: Some(&zero), tau_e: &zero };
    for _ in 0..100 { joint.step(&mut state, &m, None)?; } // 0.1 s along its own trajectory
    println!("joint controller, t = 0.1 s: tau = {:.3?} N m", state.last().tau_sat);

    // The Cartesian controller: the outer loop over the arm's chain and a
    // joint controller that leaves the impedance to it.
    s.set("impedance", Value::Str("external"))?;
    let chain = Chain::from_arm(&arm)?;
    let outer = CartesianImpedance::new(s.cartesian(), &chain, joint.period())?;
    let pair = CartesianController::new(outer, s.controller()?)?;
    let (mut task, mut inner) = (pair.start(&zero)?, pair.joint().new_state());
    let m = CartesianMeasurement { q: &q, dq: Some(&zero), wrench: Vector::zeros() };
    for _ in 0..100 { pair.step(&mut task, &mut inner, &m, None)?; } // hold the pose of q = 0
    println!("Cartesian controller, t = 0.1 s: tau = {:.3?} N m", inner.last().tau_sat);
    Ok(())
}
