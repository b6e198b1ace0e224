//! The arm reader (SPEC §21): the reduction's decisions on representative
//! descriptions, its errors word for word, the reduced URDF, the bodies, and
//! a compiled MuJoCo model's arrays to the same tree.

use adaptimp::description::{
    reduce, urdf, ErrorKind, Held, JointType, MujocoArrays, Origin, Tree, TreeJoint,
};
use adaptimp::{Chain, Dynamics, Kinematics, Vector, GRAVITY};

/// A link with a unit box's inertial (1 kg, 0.01 kg m²).
fn link(name: &str) -> String {
    format!(
        "<link name='{name}'><inertial><mass value='1'/>\
         <inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/></inertial></link>"
    )
}

/// A joint (name, type, parent, child) 0.1 m up, about y, with limits ±2 rad and 10 N m.
fn joint(name: &str, kind: &str, parent: &str, child: &str, extra: &str) -> String {
    format!(
        "<joint name='{name}' type='{kind}'><parent link='{parent}'/><child link='{child}'/>\
         <origin xyz='0 0 0.1'/><axis xyz='0 1 0'/>\
         <limit lower='-2' upper='2' effort='10' velocity='1'/>{extra}</joint>"
    )
}

/// A URDF of `joints` (name, type, parent, child, extra), every link a unit
/// box but those in `frames` (massless).
fn robot(joints: &[(&str, &str, &str, &str, &str)], frames: &[&str]) -> String {
    let mut links: Vec<&str> = std::vec!["root"];
    for j in joints {
        links.push(j.3);
    }
    let mut out = String::from("<robot name='t'>");
    for l in links {
        if frames.contains(&l) {
            out += &format!("<link name='{l}'/>");
        } else {
            out += &link(l);
        }
    }
    for (name, kind, parent, child, extra) in joints {
        out += &joint(name, kind, parent, child, extra);
    }
    out + "</robot>"
}

/// Six arm joints a1 … a6, root → l6.
fn arm6() -> Vec<(
    &'static str,
    &'static str,
    &'static str,
    &'static str,
    &'static str,
)> {
    std::vec![
        ("a1", "revolute", "root", "l1", ""),
        ("a2", "revolute", "l1", "l2", ""),
        ("a3", "revolute", "l2", "l3", ""),
        ("a4", "revolute", "l3", "l4", ""),
        ("a5", "revolute", "l4", "l5", ""),
        ("a6", "revolute", "l5", "l6", ""),
    ]
}

fn names(arm: &adaptimp::description::Arm) -> Vec<&str> {
    arm.joints.iter().map(|j| j.name.as_str()).collect()
}

fn reason(arm: &adaptimp::description::Arm, name: &str) -> String {
    arm.held_reason(name)
        .map_or_else(|| format!("'{name}' is not held"), ToString::to_string)
}

#[test]
fn a_mimic_gripper_is_held_its_drive_by_structure() {
    // A gripper whose drive has a name no word list knows, and a finger that mimics it.
    let mut js = arm6();
    js.push(("base_to_palm", "fixed", "l6", "palm", ""));
    js.push(("drive", "revolute", "palm", "left", ""));
    js.push((
        "follower",
        "revolute",
        "palm",
        "right",
        "<mimic joint='drive' multiplier='-1' offset='0.1'/>",
    ));
    let tree = urdf::read_str(&robot(&js, &[])).unwrap();
    let arm = reduce(&tree, None, &[]).unwrap();
    assert_eq!(names(&arm), ["a1", "a2", "a3", "a4", "a5", "a6"]);
    assert_eq!(arm.tip, "l6");
    // Another joint mimics it: a gripper's drive (and the palm, where two
    // branches shorter than the arm start, is a hand anyway).
    assert_eq!(
        reason(&arm, "drive"),
        "drives a gripper ('follower' mimic it)"
    );
    assert_eq!(
        reason(&arm, "follower"),
        "mimics 'drive': it moves with 'drive', not on its own"
    );
    // A mimic joint is held where its master's value puts it (0 × −1 + 0.1).
    let follower = arm.held.iter().find(|h| h.name == "follower").unwrap();
    assert_eq!(follower.value, 0.1);
}

#[test]
fn a_knuckle_gripper_is_not_an_arm_joint() {
    // A linkage gripper on one side only: its drive "…knuckle…" carries a
    // finger that mimics it, in one branch (no hand): the drive is held
    // because other joints mimic it, not because of its name.
    let mut js = arm6();
    js.push((
        "robotiq_left_knuckle_joint",
        "revolute",
        "l6",
        "knuckle",
        "",
    ));
    js.push((
        "finger_tip_joint",
        "revolute",
        "knuckle",
        "tip",
        "<mimic joint='robotiq_left_knuckle_joint' multiplier='-1'/>",
    ));
    let tree = urdf::read_str(&robot(&js, &[])).unwrap();
    let arm = reduce(&tree, None, &[]).unwrap();
    assert_eq!(names(&arm), ["a1", "a2", "a3", "a4", "a5", "a6"]);
    assert_eq!(
        reason(&arm, "robotiq_left_knuckle_joint"),
        "drives a gripper ('finger_tip_joint' mimic it)"
    );
    // Without the mimic, the name is the last hint.
    let mut js = arm6();
    js.push((
        "robotiq_left_knuckle_joint",
        "revolute",
        "l6",
        "knuckle",
        "",
    ));
    let arm = reduce(&urdf::read_str(&robot(&js, &[])).unwrap(), None, &[]).unwrap();
    assert_eq!(names(&arm).len(), 6);
    assert_eq!(
        reason(&arm, "robotiq_left_knuckle_joint"),
        "a gripper's (its name contains 'knuckle')"
    );
}

#[test]
fn a_jaw_beside_the_tool_frame_is_held() {
    // so101's shape: the wrist link carries a massless tool frame and a jaw
    // (a plain revolute joint, no mimic, a name that says nothing).
    let mut js = arm6();
    js.push(("tool_joint", "fixed", "l6", "tool", ""));
    js.push(("j7", "revolute", "l6", "moving_part", ""));
    let tree = urdf::read_str(&robot(&js, &["tool"])).unwrap();
    let arm = reduce(&tree, None, &[]).unwrap();
    assert_eq!(names(&arm).len(), 6);
    assert_eq!(
        reason(&arm, "j7"),
        "moves a jaw beside the tool frame 'tool' (the arm ends at the tool)"
    );
    // A frame below the joint: the joint carries the tool, so it is the arm's.
    let mut js = arm6();
    js.push(("tool_joint", "fixed", "l6", "camera", ""));
    js.push(("j7", "revolute", "l6", "l7", ""));
    js.push(("flange", "fixed", "l7", "tool0", ""));
    let tree = urdf::read_str(&robot(&js, &["camera", "tool0"])).unwrap();
    assert_eq!(reduce(&tree, None, &[]).unwrap().n(), 7);
}

#[test]
fn a_hand_of_fingers_ends_the_arm_and_two_arms_tie() {
    // Three fingers of three joints on a three-joint arm: none longer than the arm.
    let mut js = std::vec![
        ("a1", "revolute", "root", "l1", ""),
        ("a2", "revolute", "l1", "l2", ""),
        ("a3", "revolute", "l2", "palm", ""),
    ];
    let fingers = [
        ["f1a", "f1b", "f1c", "f1x", "f1y", "f1z"],
        ["f2a", "f2b", "f2c", "f2x", "f2y", "f2z"],
        ["f3a", "f3b", "f3c", "f3x", "f3y", "f3z"],
    ];
    for f in &fingers {
        js.push((f[0], "revolute", "palm", f[3], ""));
        js.push((f[1], "revolute", f[3], f[4], ""));
        js.push((f[2], "revolute", f[4], f[5], ""));
    }
    let arm = reduce(&urdf::read_str(&robot(&js, &[])).unwrap(), None, &[]).unwrap();
    assert_eq!(names(&arm), ["a1", "a2", "a3"]);
    assert!(reason(&arm, "f2c").starts_with("in the hand at 'palm'"));
    // A torso joint and two arms of three: the arms are longer than the
    // torso (no hand), and they tie.
    let mut js = std::vec![("t", "revolute", "root", "torso", "")];
    for (side, links) in [("l", ["l0", "l1", "l2"]), ("r", ["r0", "r1", "r2"])] {
        let mut parent = "torso";
        for (k, l) in links.iter().enumerate() {
            let name: &'static str = Box::leak(format!("{side}{k}j").into_boxed_str());
            js.push((name, "revolute", parent, l, ""));
            parent = l;
        }
    }
    let tree = urdf::read_str(&robot(&js, &[])).unwrap();
    let e = reduce(&tree, None, &[]).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Arm);
    assert_eq!(
        e.to_string(),
        "URDF text: 2 serial chains of 4 joints from the root tie for the arm (legs, or two \
         arms), ending at the links 'l2', 'r2': name one with tip= or hold the others' joints \
         with fix="
    );
    let left = reduce(&tree, Some("l2"), &[]).unwrap();
    assert_eq!(names(&left), ["t", "l0j", "l1j", "l2j"]);
    assert_eq!(reason(&left, "r1j"), "not on the way to 'l2'");
    let held = reduce(&tree, None, &["r0j"]).unwrap();
    assert_eq!(names(&held), ["t", "l0j", "l1j", "l2j"]);
    assert_eq!(reason(&held, "r0j"), "asked (fix=)");
    assert_eq!(
        reason(&held, "r1j"),
        "off the arm's chain (another arm, a leg, a head)"
    );
}

#[test]
fn prismatic_joints_are_driven_only_on_the_way_to_a_tip() {
    let js = [
        ("rail", "prismatic", "root", "carriage", ""),
        ("a1", "revolute", "carriage", "l1", ""),
        ("a2", "revolute", "l1", "l2", ""),
    ];
    let tree = urdf::read_str(&robot(&js, &[])).unwrap();
    let found = reduce(&tree, None, &[]).unwrap();
    assert_eq!(names(&found), ["a1", "a2"]);
    assert!(reason(&found, "rail").starts_with("prismatic (a lift, a rail or a finger)"));
    let asked = reduce(&tree, Some("l2"), &[]).unwrap();
    assert_eq!(names(&asked), ["rail", "a1", "a2"]);
    assert!(asked.joints[0].prismatic);
}

#[test]
fn the_chain_and_the_bodies_are_the_held_arm() {
    // An arm of two joints whose gripper (held at its mimic offset) rides on
    // the last link: its mass joins the last body, at the place the held
    // value puts it.
    let js = [
        ("a1", "revolute", "root", "l1", ""),
        ("a2", "revolute", "l1", "l2", ""),
        (
            "g",
            "prismatic",
            "l2",
            "finger",
            "<mimic joint='a1' multiplier='0' offset='0.05'/>",
        ),
    ];
    let text = robot(&js, &[]).replace(
        "<joint name='g' type='prismatic'><parent link='l2'/><child link='finger'/>\
         <origin xyz='0 0 0.1'/><axis xyz='0 1 0'/>",
        "<joint name='g' type='prismatic'><parent link='l2'/><child link='finger'/>\
         <origin xyz='0 0 0.1'/><axis xyz='1 0 0'/>",
    );
    let tree = urdf::read_str(&text).unwrap();
    let arm = reduce(&tree, None, &[]).unwrap();
    assert_eq!(names(&arm), ["a1", "a2"]);
    let dynamics: Dynamics<2> = arm.to_dynamics(GRAVITY).unwrap();
    assert_eq!(dynamics.mass(), 3.0);
    let body = arm.inertials[1];
    assert_eq!(body.mass, 2.0);
    // l2 at the joint's origin, the finger 0.1 m up and 0.05 m along x.
    let c = body.origin.translation;
    assert!((c[0] - 0.025).abs() < 1e-15 && c[1] == 0.0 && (c[2] - 0.05).abs() < 1e-15);
    // Each box's 0.01 kg m² plus m d² about the centre of mass.
    let i = body.inertia;
    assert!((i[1][1] - (0.02 + 2.0 * (0.025f64.powi(2) + 0.05f64.powi(2)))).abs() < 1e-15);
    let chain: Chain<2> = arm.to_chain().unwrap();
    let p = chain.fk(&Vector::<2>::zeros());
    assert!((p - nalgebra::Vector3::new(0.0, 0.0, 0.2)).norm() < 1e-15);
}

#[test]
fn the_reduced_urdf_reads_back_as_the_same_arm() {
    let mut js = arm6();
    js.push(("tool_joint", "fixed", "l6", "tool", ""));
    js.push((
        "g",
        "revolute",
        "l6",
        "jaw",
        "<mimic joint='a1' multiplier='2' offset='0.3'/>",
    ));
    let tree = urdf::read_str(&robot(&js, &["tool"])).unwrap();
    let arm = reduce(&tree, Some("tool"), &[]).unwrap();
    let text = urdf::reduced_urdf(&tree, &arm, true).unwrap();
    assert!(!text.contains("<mimic"));
    assert!(text.contains("<joint name=\"g\" type=\"fixed\">"));
    let again = urdf::read_str(&text).unwrap();
    let back = reduce(&again, Some("tool"), &[]).unwrap();
    assert_eq!(names(&back), names(&arm));
    let (a, b): (Chain<6>, Chain<6>) = (arm.to_chain().unwrap(), back.to_chain().unwrap());
    let q = Vector::<6>::new(0.1, -0.4, 0.3, 1.0, -0.7, 0.2);
    assert_eq!(a.fk(&q), b.fk(&q));
    // The held jaw sits where the mimic put it (rotated by 0.3 rad), in both.
    let (da, db): (Dynamics<6>, Dynamics<6>) = (
        arm.to_dynamics(GRAVITY).unwrap(),
        back.to_dynamics(GRAVITY).unwrap(),
    );
    let (ta, tb) = (
        da.inverse_dynamics(&q, &q, &q),
        db.inverse_dynamics(&q, &q, &q),
    );
    assert!((ta - tb).norm() < 1e-12, "{ta} vs {tb}");
}

#[test]
fn bad_descriptions_are_refused_by_name() {
    let cases: [(&str, ErrorKind, &str); 7] = [
        (
            "<robot name='x'><link name='a'/><joint name='j' type='revolute'>\
             <parent link='a'/><child link='b'/></joint></robot>",
            ErrorKind::Structure,
            "URDF text: joint 'j' names the child link 'b', which is not declared (a missing \
             link): declare it or correct the joint's <child>",
        ),
        (
            "<robot name='x'><link name='a'/><link name='b'/>\
             <joint name='j' type='fixed'><parent link='a'/><child link='b'/></joint>\
             <joint name='k' type='fixed'><parent link='b'/><child link='a'/></joint></robot>",
            ErrorKind::Structure,
            "URDF text: the joints form a loop through the link 'a': a tree cannot hold it; \
             remove a joint of the loop",
        ),
        (
            "<robot name='x'><link name='a'/><link name='b'/><link name='c'/>\
             <joint name='j' type='fixed'><parent link='a'/><child link='c'/></joint>\
             <joint name='k' type='fixed'><parent link='b'/><child link='c'/></joint></robot>",
            ErrorKind::Structure,
            "URDF text: link 'c' is the child of two joints ('j' and 'k'): a kinematic loop, \
             which a tree cannot hold; remove one of them",
        ),
        (
            "<robot name='x' xmlns:xacro='http://www.ros.org/wiki/xacro'>\
             <xacro:macro name='m'/></robot>",
            ErrorKind::Xacro,
            "URDF text is xacro, not a URDF (it has the element <xacro:macro>): expand it into \
             a URDF first with `xacro FILE.xacro -o robot.urdf` (the xacro package: pip \
             install xacro)",
        ),
        (
            "<robot name='x'><link name='a'><inertial><mass value='${m}'/>\
             <inertia ixx='1' ixy='0' ixz='0' iyy='1' iyz='0' izz='1'/></inertial></link></robot>",
            ErrorKind::Xacro,
            "URDF text is xacro, not a URDF (it has the expression value=\"${m}\" in <mass>): \
             expand it into a URDF first with `xacro FILE.xacro -o robot.urdf` (the xacro \
             package: pip install xacro)",
        ),
        (
            "<mujoco model='m'/>",
            ErrorKind::Parse,
            "the URDF text is an MJCF (its root element is <mujoco>), not a URDF: read it \
             through MuJoCo's compiler (Python: give its path to adaptimp, which compiles it)",
        ),
        (
            "<robot name='x'><link name='a'/><link name='b'/><joint name='j' type='fixed'>\
             <origin xyz='0 0'/><parent link='a'/><child link='b'/></joint></robot>",
            ErrorKind::Parse,
            "cannot read the URDF text as a URDF: <joint name=\"j\">: ",
        ),
    ];
    for (text, kind, message) in cases {
        let e = urdf::read_str(text).unwrap_err();
        assert_eq!(e.kind(), kind, "{e}");
        assert!(
            e.to_string().starts_with(message),
            "{e}\nexpected: {message}"
        );
    }
    let e = urdf::read_file("no/such.urdf").unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Io);
    assert!(e
        .to_string()
        .starts_with("cannot read the URDF 'no/such.urdf': "));
    // A comment or a leftover namespace is no xacro; a mesh is not needed.
    let text = "<robot name='x' xmlns:xacro='http://www.ros.org/wiki/xacro'>\
        <!-- <xacro:include filename='${f}'/> --><link name='a'><visual><geometry><mesh/>\
        </geometry></visual></link></robot>";
    assert_eq!(urdf::read_str(text).unwrap().links().len(), 1);
    // The reduction names what it cannot do.
    let tree = urdf::read_str(&robot(&arm6(), &[])).unwrap();
    let e = reduce(&tree, Some("l9"), &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "URDF text: tip= 'l9' is neither a link nor a frame of it: name the link (a MuJoCo \
         body) or the frame (a site) that ends the arm; its 7 links and 0 frames, closest \
         first: ['l1', 'l2', 'l3', 'l4', 'l5', 'l6', 'root']"
    );
    // Closest first: a misspelt link name leads the list.
    let e = reduce(&tree, Some("L_5"), &[]).unwrap_err();
    assert!(
        e.to_string()
            .ends_with("closest first: ['l5', 'l1', 'l2', 'l3', 'l4', 'l6', 'root']"),
        "{e}"
    );
    let e = reduce(&tree, None, &["a9"]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "URDF text: fix= names joints it does not have: ['a9']; its movable joints are ['a1', \
         'a2', 'a3', 'a4', 'a5', 'a6']"
    );
    let all = ["a1", "a2", "a3", "a4", "a5", "a6"];
    let e = reduce(&tree, None, &all).unwrap_err();
    assert!(
        e.to_string().starts_with(
            "URDF text: it has no revolute or continuous joint to drive (held: 'a1' asked (fix=)"
        ),
        "{e}"
    );
}

#[test]
fn a_long_chain_reads_in_linear_time_without_recursion() {
    // 20 000 links in a line: no stack overflow, no quadratic walk.
    let n = 20_000;
    let mut text = String::from("<robot name='long'>");
    for i in 0..=n {
        text += &format!("<link name='l{i}'/>");
    }
    for i in 0..n {
        let kind = if i < 3 { "revolute" } else { "fixed" };
        text += &format!(
            "<joint name='j{i}' type='{kind}'><parent link='l{i}'/><child link='l{}'/>\
             <axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>",
            i + 1
        );
    }
    text += "</robot>";
    let tree = urdf::read_str(&text).unwrap();
    let arm = reduce(&tree, Some(&format!("l{n}")), &[]).unwrap();
    assert_eq!(arm.n(), 3);
}

/// Two bodies of a MuJoCo model: a hinge with an anchor and a reference
/// value, then a slide and a hinge in one body, and a site.
fn mujoco_arrays() -> MujocoArrays {
    MujocoArrays {
        model_name: "m".into(),
        body_name: ["world", "a", "b"].map(String::from).to_vec(),
        body_parentid: std::vec![0, 0, 1],
        body_pos: std::vec![[0.0; 3], [0.1, 0.0, 0.2], [0.3, 0.0, 0.0]],
        body_quat: std::vec![
            [1.0, 0.0, 0.0, 0.0],
            [0.9, 0.1, 0.0, 0.3],
            [1.0, 0.0, 0.0, 0.0]
        ],
        body_mass: std::vec![0.0, 1.0, 2.0],
        body_gravcomp: Vec::new(),
        body_ipos: std::vec![[0.0; 3], [0.05, 0.0, 0.0], [0.0, 0.1, 0.0]],
        body_iquat: std::vec![[1.0, 0.0, 0.0, 0.0]; 3],
        body_inertia: std::vec![[0.0; 3], [0.01; 3], [0.02; 3]],
        jnt_name: ["j1", "j2", "j3"].map(String::from).to_vec(),
        jnt_type: std::vec![3, 2, 3],
        jnt_bodyid: std::vec![1, 2, 2],
        jnt_pos: std::vec![[0.05, 0.0, 0.0], [0.0; 3], [0.0, 0.02, 0.1]],
        jnt_axis: std::vec![[0.0, 0.0, 1.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        jnt_limited: std::vec![true, false, false],
        jnt_range: std::vec![[-1.0, 1.0], [0.0; 2], [0.0; 2]],
        jnt_qpos0: std::vec![0.4, 0.1, 0.0],
        jnt_armature: std::vec![0.1, 0.0, 0.2],
        jnt_damping: std::vec![1.0, 0.0, 0.5],
        jnt_frictionloss: std::vec![0.3, 0.0, 0.0],
        jnt_actfrclimited: std::vec![false, false, true],
        jnt_actfrcrange: std::vec![[0.0; 2], [0.0; 2], [-4.0, 4.0]],
        site_name: std::vec!["tip".into()],
        site_bodyid: std::vec![2],
        site_pos: std::vec![[0.05, 0.01, 0.0]],
        site_quat: std::vec![[1.0, 0.0, 0.0, 0.0]],
        // A motor on j1 (gear 2, ctrl ±5), a position actuator on j3 with a force range ±6.
        actuator_trntype: std::vec![0, 0],
        actuator_trnid: std::vec![0, 2],
        actuator_gear: std::vec![2.0, 1.0],
        actuator_forcelimited: std::vec![false, true],
        actuator_forcerange: std::vec![[0.0; 2], [-6.0, 6.0]],
        actuator_ctrllimited: std::vec![true, true],
        actuator_ctrlrange: std::vec![[-5.0, 5.0], [-1.0, 1.0]],
        actuator_gaintype: std::vec![0, 0],
        actuator_gain: std::vec![1.0, 100.0],
        actuator_biastype: std::vec![0, 1],
        eq_type: Vec::new(),
        eq_obj1id: Vec::new(),
        eq_obj2id: Vec::new(),
        eq_data: Vec::new(),
        eq_active: Vec::new(),
        force_sites: Vec::new(),
        tendons: Vec::new(),
    }
}

#[test]
fn a_mujoco_model_is_the_same_kind_of_tree() {
    let tree: Tree = mujoco_arrays().tree("MJCF 'm.xml'").unwrap();
    let links: Vec<&str> = tree.links().iter().map(|l| l.name.as_str()).collect();
    assert_eq!(links, ["world", "a", "b", "b:j2"]);
    let j: Vec<(&str, JointType, &str, &str)> = tree
        .joints()
        .iter()
        .map(|j| (j.name.as_str(), j.kind, j.parent.as_str(), j.child.as_str()))
        .collect();
    assert_eq!(
        j,
        [
            ("j1", JointType::Revolute, "world", "a"),
            ("j2", JointType::Prismatic, "a", "b:j2"),
            ("j3", JointType::Continuous, "b:j2", "b"),
        ]
    );
    // The second joint of body b: from the first's anchor (0) to its own.
    assert_eq!(
        tree.joints()[2].origin,
        Origin::XyzRpy([0.0, 0.02, 0.1], [0.0; 3])
    );
    let arm = reduce(&tree, Some("tip"), &[]).unwrap();
    assert!(arm.tip_is_frame);
    assert_eq!(names(&arm), ["j1", "j2", "j3"]);
    let effort: Vec<f64> = arm.joints.iter().map(|j| j.effort).collect();
    assert_eq!(effort[0], 10.0); // gear 2 × ctrl 5
    assert!(effort[1].is_nan()); // no actuator
    assert_eq!(effort[2], 4.0); // a force range of 6, bounded by actfrcrange 4
    assert_eq!(arm.joints[0].armature, 0.1);
    assert_eq!(arm.joints[0].friction, 0.3);
    assert_eq!(arm.joints[2].damping, 0.5);
    assert_eq!(arm.chain[0].offset, 0.4);
    let mass: f64 = arm.inertials.iter().map(|i| i.mass).sum();
    assert_eq!(mass, 3.0);
    // Without tip=, rule 7 of SPEC (21.2): the site on the last arm joint's
    // body (b) is the tip; the slide is not the rule's arm.
    let arm = reduce(&tree, None, &[]).unwrap();
    assert_eq!((arm.tip.as_str(), arm.tip_is_frame), ("tip", true));
    assert_eq!(names(&arm), ["j1", "j3"]);
    // Without a site there, the body's origin.
    let mut m = mujoco_arrays();
    m.site_bodyid = std::vec![1];
    let arm = reduce(&m.tree("MJCF 'm.xml'").unwrap(), None, &[]).unwrap();
    assert_eq!((arm.tip.as_str(), arm.tip_is_frame), ("b", false));
}

#[test]
fn couplings_and_tool_sites_of_a_mujoco_model() {
    // j2 mimics j1 through a joint equality; j3 is coupled by a fixed tendon;
    // a force sensor's site ends the arm without tip=.
    let mut m = mujoco_arrays();
    m.eq_type = std::vec![2];
    m.eq_obj1id = std::vec![1];
    m.eq_obj2id = std::vec![0];
    m.eq_data = std::vec![[0.0, 0.5, 0.0, 0.0, 0.0]];
    m.eq_active = std::vec![true];
    m.tendons = std::vec![("split".into(), std::vec![2, 0])];
    let tree = m.tree("MJCF 'm.xml'").unwrap();
    let mimic = tree.joints()[1].mimic.as_ref().unwrap();
    assert_eq!((mimic.joint.as_str(), mimic.multiplier), ("j1", 0.5));
    assert_eq!(mimic.offset, 0.1 - 0.5 * 0.4);
    let arm = reduce(&tree, Some("tip"), &["j3"]);
    let e = arm.unwrap_err();
    assert!(
        e.to_string()
            .contains("'j1' coupled to other joints by 'split'"),
        "{e}"
    );
    let mut m = mujoco_arrays();
    m.force_sites = std::vec![0];
    let arm = reduce(&m.tree("MJCF 'm.xml'").unwrap(), None, &[]).unwrap();
    assert_eq!((arm.tip.as_str(), arm.tip_is_frame), ("tip", true));
    // Arrays of one kind that differ in length are the front's mistake, named.
    let mut m = mujoco_arrays();
    m.jnt_axis.pop();
    let e = m.tree("MJCF 'm.xml'").unwrap_err();
    assert_eq!(
        e.to_string(),
        "MJCF 'm.xml': the jnt_* arrays differ in length: give one entry per jnt"
    );
}

#[test]
fn a_tree_is_built_from_plain_data_too() {
    let mut j = TreeJoint::new(
        "hinge",
        JointType::Revolute,
        "base",
        "arm",
        Origin::XyzRpy([0.0, 0.0, 0.5], [0.0; 3]),
    );
    j.axis = [0.0, 0.0, 1.0];
    let links = std::vec![
        adaptimp::description::Link::new("base"),
        adaptimp::description::Link::new("arm"),
    ];
    let tree = Tree::new("plain data", "r", links, std::vec![j], Vec::new()).unwrap();
    let arm = reduce(&tree, None, &[]).unwrap();
    assert_eq!(names(&arm), ["hinge"]);
    assert!(arm.held_reason("hinge").is_none());
    assert!(matches!(
        reduce(&tree, None, &["hinge"]).unwrap_err().kind(),
        ErrorKind::Arm
    ));
    let _: Option<&Held> = arm.held_reason("nothing");
}

/// A link the arm moves with an inertia no rigid body has (ixy = 5 on a
/// 0.01 kg m² box: a negative principal moment) is named with the file, and
/// the arm's dynamics refused with it (its mass matrix was indefinite); the
/// kinematics reads. Links the arm does not move are not its business.
#[test]
fn an_inertia_no_rigid_body_has_refuses_the_arms_dynamics_by_name() {
    let text = robot(
        &[
            ("j1", "revolute", "root", "a", ""),
            ("j2", "revolute", "a", "b", ""),
        ],
        &[],
    )
    .replacen(
        "<link name='b'><inertial><mass value='1'/><inertia ixx='0.01' ixy='0'",
        "<link name='b'><inertial><mass value='1'/><inertia ixx='0.01' ixy='5'",
        1,
    );
    let tree = urdf::read_str(&text).expect("a URDF");
    let arm = reduce(&tree, None, &[]).expect("its kinematics reads");
    assert!(arm.to_chain::<2>().is_ok());
    let e = arm.to_dynamics::<2>(GRAVITY).expect_err("indefinite");
    assert_eq!(e.kind(), ErrorKind::Value);
    assert!(
        e.to_string().starts_with(
            "URDF text: link 'b' has the inertia [[0.01, 5, 0], [5, 0.01, 0], [0, 0, 0.01]] \
             kg m², which no rigid body has: its principal moments are -4.990e0, 1.000e-2, \
             5.010e0 kg m², one negative"
        ),
        "{e}"
    );
    assert_eq!(arm.inertia_error.as_ref(), Some(&e));
    // The root's link is the base's: nothing of the arm.
    let text = text.replace("ixy='5'", "ixy='0'").replacen(
        "<inertia ixx='0.01' ixy='0'",
        "<inertia ixx='0.01' ixy='5'",
        1,
    );
    let arm = reduce(&urdf::read_str(&text).unwrap(), None, &[]).unwrap();
    assert!(arm.inertia_error.is_none());
    assert!(arm.to_dynamics::<2>(GRAVITY).is_ok());
}

/// SPEC (21.5): a file of the kinematics alone (no link the arm moves states
/// a mass) and a last joint whose link has its mass on the axis and no
/// inertia refuse the arm's dynamics by name; the kinematics reads.
#[test]
fn a_description_with_nothing_to_move_refuses_the_arms_dynamics_by_name() {
    let two = [
        ("j1", "revolute", "root", "a", ""),
        ("j2", "revolute", "a", "b", ""),
    ];
    let arm = reduce(
        &urdf::read_str(&robot(&two, &["a", "b"])).unwrap(),
        None,
        &[],
    )
    .unwrap();
    assert!(arm.to_chain::<2>().is_ok());
    let e = arm.to_dynamics::<2>(GRAVITY).expect_err("massless");
    assert_eq!(e.kind(), ErrorKind::Value);
    assert_eq!(
        e.to_string(),
        "URDF text: no link the arm moves states a mass (<inertial>): the file describes the \
         arm's kinematics alone, and its dynamics (the plant, the rule's gains, computed \
         torque) needs each link's mass and inertia: use a description of the arm with its \
         links' <inertial> (the maker's, or example-robot-data's)"
    );
    // A point mass on j2's axis (y, through the link's origin): nothing to turn.
    let point = robot(&two, &[]).replacen(
        "<link name='b'><inertial><mass value='1'/>\
         <inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/>",
        "<link name='b'><inertial><origin xyz='0 0.2 0'/><mass value='1'/>\
         <inertia ixx='0' ixy='0' ixz='0' iyy='0' iyz='0' izz='0'/>",
        1,
    );
    let arm = reduce(&urdf::read_str(&point).unwrap(), None, &[]).unwrap();
    let e = arm
        .to_dynamics::<2>(GRAVITY)
        .expect_err("nothing about the axis");
    assert_eq!(
        e.to_string(),
        "URDF text: the last arm joint 'j2' moves 0e0 kg m² about its axis (less than 1e-9, \
         its armature included): its link states no inertia there, so no torque controls it: \
         give the link its <inertial> or the joint an armature, or hold the joint \
         (fix=['j2'])"
    );
    // The same mass 0.1 m off the axis moves m r² = 0.01 kg m².
    let off = point.replace("<origin xyz='0 0.2 0'/>", "<origin xyz='0.1 0.2 0'/>");
    let arm = reduce(&urdf::read_str(&off).unwrap(), None, &[]).unwrap();
    assert!(arm.inertia_error.is_none());
    assert!(arm.to_dynamics::<2>(GRAVITY).is_ok());
}

/// A mimic joint whose master is not another joint of the file was held
/// silently (on the arm's way: the arm one joint short), in every front.
/// On the way it is refused by name; off the arm it is held and said
/// (`Arm::warnings`): real files have such mimics on hands off the arm.
#[test]
fn a_mimic_of_no_joint_is_refused_on_the_way_and_said_off_it() {
    for (mimic, why) in [
        (
            "nope",
            "joint 'j2' mimics 'nope', which is not a joint of it",
        ),
        ("j2", "joint 'j2' mimics itself"),
    ] {
        let text = robot(
            &[
                ("j1", "revolute", "root", "a", ""),
                (
                    "j2",
                    "revolute",
                    "a",
                    "b",
                    &format!("<mimic joint='{mimic}'/>"),
                ),
                ("j3", "revolute", "b", "c", ""),
            ],
            &[],
        );
        let tree = urdf::read_str(&text).expect("a tree");
        for tip in [None, Some("c")] {
            let e = reduce(&tree, tip, &[]).expect_err("on the way");
            assert_eq!(
                e.to_string(),
                format!(
                    "URDF text: {why}, on the way to 'c': correct its <mimic joint=…>, or \
                     hold it with fix="
                )
            );
        }
        // The last joint of the rule's arm: the rule ended short of it.
        let last = robot(
            &[
                ("j1", "revolute", "root", "a", ""),
                ("j2", "revolute", "a", "b", ""),
                (
                    "j3",
                    "revolute",
                    "b",
                    "c",
                    &format!("<mimic joint='{}'/>", mimic.replace("j2", "j3")),
                ),
            ],
            &[],
        );
        let e = reduce(&urdf::read_str(&last).unwrap(), None, &[]).expect_err("the rule's end");
        assert_eq!(
            e.to_string(),
            format!(
                "URDF text: {}, on the way to 'c': correct its <mimic joint=…>, or hold it \
                 with fix=",
                why.replace("j2", "j3")
            )
        );
        // Held as asked: the file's mistake is then the user's choice.
        assert_eq!(reduce(&tree, Some("c"), &["j2"]).unwrap().n(), 2);
        // Off the arm (the way to 'a'): held, and said.
        let arm = reduce(&tree, Some("a"), &[]).expect("off the arm");
        assert_eq!(arm.n(), 1);
        assert_eq!(
            arm.warnings,
            [format!(
                "URDF text: {why}: held at its reference position (correct its <mimic joint=…>)"
            )]
        );
    }
}

/// A floating joint on the way to the arm the rule finds was held silently
/// (refused with the same tip given, as the docs say).
#[test]
fn a_floating_joint_on_the_way_is_refused_with_or_without_a_tip() {
    let text = robot(
        &[
            ("float", "floating", "root", "a", ""),
            ("j1", "revolute", "a", "b", ""),
            ("j2", "revolute", "b", "c", ""),
        ],
        &[],
    );
    let tree = urdf::read_str(&text).expect("a tree");
    for tip in [None, Some("c")] {
        let e = reduce(&tree, tip, &[]).expect_err("floating on the way");
        assert_eq!(
            e.to_string(),
            "URDF text: the joint 'float' on the way to 'c' is floating: a chain has revolute, \
             continuous, prismatic and fixed joints only; give a tip below it or fix it with fix="
        );
    }
    assert_eq!(reduce(&tree, None, &["float"]).unwrap().n(), 2);
}
