//! The core's side of `benches/peers.py`: the rows of its table computed by
//! the core, on the arm and the states the peer side (Pinocchio, in
//! `benches/peers/peers.cpp`) reads. The modes are the peer's:
//!
//! ```text
//! peers ARM STATES check          the rows' values on the states ({:e}, 17 digits)
//! peers ARM STATES time MS        ns per call of each row (≥ MS ms of calls each)
//! peers ARM STATES count CALLS    CALLS calls of each row inside measured_ROW
//!                                 (valgrind --tool=callgrind --toggle-collect='*measured_*')
//! ```
//!
//! ARM: the core's description of the arm, one line per entry (what
//! `benches/peers.py` writes from the URDF; lengths in m, masses in kg,
//! inertias in kg m², row-major rotations):
//!
//! ```text
//! joint KIND tx ty tz r00 … r22 ax ay az     KIND: revolute, prismatic or fixed
//! inertial m cx cy cz i00 … i22              one per joint: the child link's, about its centre
//! tip tx ty tz r00 … r22                     the tool frame in the last joint's frame
//! gravity gx gy gz                           (m/s²)
//! ```
//!
//! STATES: "K n" then K rows of q, q̇, q̈ (3n numbers each). Rows and the
//! impedance law's parameters: see `benches/peers/peers.cpp` and SPEC (20.7).

use adaptimp::{
    Chain, ComputedState, ComputedTorque, ComputedTorqueConfig, Dynamics, ImpedanceMode,
    ImpedanceTorque, Inertial, Joint, JointKind, Kinematics, Measurement, PoseGoal, Setpoint,
    Transform, Vector,
};
use std::hint::black_box;
use std::process::exit;
use std::time::Instant;

type Vec6 = Vector<6>;

struct Arm {
    joints: Vec<Joint>,
    inertials: Vec<Inertial>,
    tip: Transform,
    gravity: [f64; 3],
}

fn die(msg: &str) -> ! {
    eprintln!("{msg}");
    exit(2)
}

fn numbers(words: &[&str]) -> Vec<f64> {
    words
        .iter()
        .map(|w| {
            w.parse()
                .unwrap_or_else(|_| die(&format!("not a number: {w}")))
        })
        .collect()
}

fn transform(x: &[f64]) -> Transform {
    Transform {
        translation: [x[0], x[1], x[2]],
        rotation: [[x[3], x[4], x[5]], [x[6], x[7], x[8]], [x[9], x[10], x[11]]],
    }
}

fn read_arm(path: &str) -> Arm {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| die(&format!("{path}: {e}")));
    let mut arm = Arm {
        joints: Vec::new(),
        inertials: Vec::new(),
        tip: Transform::IDENTITY,
        gravity: [0.0, 0.0, -9.81],
    };
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first().copied() {
            Some("joint") => {
                let x = numbers(&words[2..]);
                let kind = match words[1] {
                    "revolute" => JointKind::Revolute,
                    "prismatic" => JointKind::Prismatic,
                    "fixed" => JointKind::Fixed,
                    k => die(&format!("unknown joint kind {k}")),
                };
                arm.joints.push(Joint {
                    kind,
                    origin: transform(&x[..12]),
                    axis: [x[12], x[13], x[14]],
                    offset: 0.0,
                });
            }
            Some("inertial") => {
                let x = numbers(&words[1..]);
                arm.inertials.push(Inertial {
                    mass: x[0],
                    origin: Transform {
                        translation: [x[1], x[2], x[3]],
                        ..Transform::IDENTITY
                    },
                    inertia: [
                        [x[4], x[5], x[6]],
                        [x[7], x[8], x[9]],
                        [x[10], x[11], x[12]],
                    ],
                });
            }
            Some("tip") => arm.tip = transform(&numbers(&words[1..])),
            Some("gravity") => {
                let x = numbers(&words[1..]);
                arm.gravity = [x[0], x[1], x[2]];
            }
            _ => {}
        }
    }
    arm
}

struct State<const N: usize> {
    q: Vector<N>,
    dq: Vector<N>,
    ddq: Vector<N>,
}

fn read_states<const N: usize>(path: &str) -> Vec<State<N>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| die(&format!("{path}: {e}")));
    let mut words = text.split_whitespace();
    let mut next = || -> f64 {
        words
            .next()
            .and_then(|w| w.parse().ok())
            .unwrap_or_else(|| die(&format!("{path}: fewer numbers than K rows of 3n")))
    };
    let (k, n) = (next() as usize, next() as usize);
    if n != N {
        die(&format!("{path}: n = {n}, the arm has {N} joints"));
    }
    (0..k)
        .map(|_| {
            let q = Vector::<N>::from_fn(|_, _| next());
            let dq = Vector::<N>::from_fn(|_, _| next());
            let ddq = Vector::<N>::from_fn(|_, _| next());
            State { q, dq, ddq }
        })
        .collect()
}

/// The rows' context: the core's models of the arm, the states, the law's
/// parameters (SPEC (20.7)).
struct Ctx<const N: usize> {
    chain: Chain<N>,
    dynamics: Dynamics<N>,
    computed: ComputedTorque<N>,
    states: Vec<State<N>>,
    law: ImpedanceTorque<N>,
    goal: PoseGoal,
    qn: Vector<N>,
    sink: f64,
}

impl<const N: usize> Ctx<N> {
    fn impedance(&self, s: &State<N>) -> Vector<N> {
        let tip = self.chain.pose_jacobian(&s.q);
        self.law.torque(&tip, &self.goal, &self.qn, &s.q, &s.dq)
    }
}

#[inline(never)]
fn measured_pose_jacobian<const N: usize>(c: &mut Ctx<N>, calls: usize) {
    for i in 0..calls {
        let s = &c.states[i % c.states.len()];
        let t = c.chain.pose_jacobian(black_box(&s.q));
        c.sink += t.jacobian[(0, 0)] + t.position[0] + t.rotation[(0, 0)];
    }
}

#[inline(never)]
fn measured_fk<const N: usize>(c: &mut Ctx<N>, calls: usize) {
    for i in 0..calls {
        let s = &c.states[i % c.states.len()];
        let (p, r) = c.chain.pose(black_box(&s.q));
        c.sink += p[0] + r[(0, 0)];
    }
}

#[inline(never)]
fn measured_ct_step<const N: usize>(c: &mut Ctx<N>, calls: usize) {
    let mut st = ComputedState::default();
    for i in 0..calls {
        let s = &c.states[i % c.states.len()];
        let m = Measurement {
            x: s.q,
            dx: Some(s.dq),
            tau_e: Vector::zeros(),
        };
        let sp = Setpoint {
            x: s.q,
            dx: s.dq,
            ddx: s.ddq,
        };
        if let Ok(cmd) = c.computed.step(&mut st, black_box(&m), black_box(&sp)) {
            c.sink += cmd.tau_sat[0];
        }
    }
}

#[inline(never)]
fn measured_jdot_qdot<const N: usize>(c: &mut Ctx<N>, calls: usize) {
    for i in 0..calls {
        let s = &c.states[i % c.states.len()];
        c.sink += c.chain.jdot_qdot(black_box(&s.q), black_box(&s.dq))[0];
    }
}

#[inline(never)]
fn measured_rnea<const N: usize>(c: &mut Ctx<N>, calls: usize) {
    for i in 0..calls {
        let s = &c.states[i % c.states.len()];
        c.sink += c
            .dynamics
            .inverse_dynamics(black_box(&s.q), black_box(&s.dq), black_box(&s.ddq))[0];
    }
}

#[inline(never)]
fn measured_crba<const N: usize>(c: &mut Ctx<N>, calls: usize) {
    for i in 0..calls {
        let s = &c.states[i % c.states.len()];
        c.sink += c.dynamics.mass_matrix(black_box(&s.q))[(0, 0)];
    }
}

#[inline(never)]
fn measured_impedance<const N: usize>(c: &mut Ctx<N>, calls: usize) {
    for i in 0..calls {
        let s = &c.states[i % c.states.len()];
        c.sink += c.impedance(black_box(s))[0];
    }
}

type Row<const N: usize> = (&'static str, fn(&mut Ctx<N>, usize));

/// The rows against Pinocchio, then the core's calls behind the Python
/// entry points of `benches/python_calls.py` (`fk`: the pose alone;
/// `ct_step`: a computed-torque step, SPEC (20.3), external mode).
fn rows<const N: usize>() -> [Row<N>; 7] {
    [
        ("pose_jacobian", measured_pose_jacobian::<N>),
        ("jdot_qdot", measured_jdot_qdot::<N>),
        ("rnea", measured_rnea::<N>),
        ("crba", measured_crba::<N>),
        ("impedance", measured_impedance::<N>),
        ("fk", measured_fk::<N>),
        ("ct_step", measured_ct_step::<N>),
    ]
}

fn print(what: &str, v: impl IntoIterator<Item = f64>) {
    let mut line = String::from(what);
    for x in v {
        line.push_str(&format!(" {x:.16e}"));
    }
    println!("{line}");
}

fn run<const N: usize>(arm: &Arm, states: &str, mode: &str, arg: Option<&str>) {
    let chain = Chain::<N>::new(&arm.joints, &arm.tip).unwrap_or_else(|e| die(&e.to_string()));
    let dynamics = Dynamics::<N>::new(&arm.joints, &arm.inertials, arm.gravity)
        .unwrap_or_else(|e| die(&e.to_string()));
    let mut cfg = ComputedTorqueConfig::new(1e-3, Vector::from_element(1e3));
    cfg.mode = ImpedanceMode::External;
    let computed = ComputedTorque::new(cfg, dynamics).unwrap_or_else(|e| die(&e.to_string()));
    let states = read_states::<N>(states);
    if states.is_empty() {
        die("no states");
    }
    let qn = states[0].q;
    let home = chain.tip(&qn, &Vector::zeros());
    let k = Vec6::new(500.0, 500.0, 500.0, 20.0, 20.0, 20.0);
    let law = ImpedanceTorque::new(
        k,
        k.map(|x| 2.0 * x.sqrt()),
        25.0,
        10.0,
        Vec6::from_element(1e-4),
    )
    .unwrap_or_else(|e| die(&e.to_string()));
    let mut c = Ctx {
        chain,
        dynamics,
        computed,
        states,
        law,
        goal: PoseGoal {
            position: home.position,
            rotation: home.rotation,
        },
        qn,
        sink: 0.0,
    };
    match mode {
        "check" => {
            for s in &c.states {
                let t = c.chain.tip(&s.q, &Vector::zeros());
                print("position", t.position.iter().copied());
                let r = t.rotation.matrix();
                print("rotation", (0..9).map(|i| r[(i / 3, i % 3)]));
                let j = t.jacobian;
                print("jacobian", (0..6 * N).map(|i| j[(i / N, i % N)]));
                print("jdot_qdot", c.chain.jdot_qdot(&s.q, &s.dq).iter().copied());
                print(
                    "rnea",
                    c.dynamics
                        .inverse_dynamics(&s.q, &s.dq, &s.ddq)
                        .iter()
                        .copied(),
                );
                let m = c.dynamics.mass_matrix(&s.q);
                print("crba", (0..N * N).map(|i| m[(i / N, i % N)]));
                print("impedance", c.impedance(s).iter().copied());
            }
        }
        "time" => {
            let ms: f64 = arg.and_then(|a| a.parse().ok()).unwrap_or(50.0);
            for (name, f) in rows::<N>() {
                f(&mut c, 2000);
                let mut calls = 1000;
                let ns = loop {
                    let t0 = Instant::now();
                    f(&mut c, calls);
                    let spent = t0.elapsed().as_secs_f64() * 1e9;
                    if spent >= ms * 1e6 {
                        break spent / calls as f64;
                    }
                    calls *= 2;
                };
                println!("{name} {ns:.3}");
            }
            eprintln!("sink {}", c.sink);
        }
        "count" => {
            let calls: usize = arg.and_then(|a| a.parse().ok()).unwrap_or(1000);
            for (_, f) in rows::<N>() {
                f(&mut c, calls);
            }
            eprintln!("sink {}", c.sink);
        }
        m => die(&format!("unknown mode {m}")),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    // `cargo bench` passes --bench; the script calls the binary itself.
    let args: Vec<&str> = args
        .iter()
        .skip(1)
        .map(String::as_str)
        .filter(|a| !a.starts_with("--"))
        .collect();
    if args.len() < 3 {
        eprintln!("usage: peers ARM STATES check|time MS|count CALLS");
        return;
    }
    let arm = read_arm(args[0]);
    let n = arm
        .joints
        .iter()
        .filter(|j| j.kind != JointKind::Fixed)
        .count();
    let (states, mode, arg) = (args[1], args[2], args.get(3).copied());
    match n {
        1 => run::<1>(&arm, states, mode, arg),
        2 => run::<2>(&arm, states, mode, arg),
        3 => run::<3>(&arm, states, mode, arg),
        4 => run::<4>(&arm, states, mode, arg),
        5 => run::<5>(&arm, states, mode, arg),
        6 => run::<6>(&arm, states, mode, arg),
        7 => run::<7>(&arm, states, mode, arg),
        _ => die(&format!("{n} movable joints: the core takes 1 … 7")),
    }
}
