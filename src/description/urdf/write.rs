//! The reduced URDF an [`Arm`] leaves for MuJoCo's compiler, SPEC (21.3):
//! the arm's links with their inertials only, every other joint held.

use super::*;

/// `s` as an XML attribute value (quoted, escaped).
pub(super) fn attr(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out.push('"');
    out
}

pub(super) fn triple(v: [f64; 3]) -> String {
    format!("{} {} {}", v[0], v[1], v[2])
}

/// The reduced URDF of `arm` (from `tree`) for MuJoCo's compiler, SPEC
/// (21.3): every link with its inertial only (no visual or collision, so no
/// mesh is needed); every joint that is not the arm's fixed at the value it
/// is held at; the arm's joints with their limits, and, with `drive`, their
/// `<dynamics damping friction>`. Names and numbers are those of the
/// description, in its order.
pub fn reduced_urdf(tree: &Tree, arm: &Arm, drive: bool) -> Result<String, DescriptionError> {
    let config = |e: crate::error::Error| {
        DescriptionError::new(ErrorKind::Value, format!("{}: {e}", tree.source()))
    };
    let mut out = format!("<robot name={}>\n", attr(tree.name()));
    for l in tree.links() {
        write_link(&mut out, l).map_err(config)?;
    }
    for (index, j) in tree.joints().iter().enumerate() {
        let arm_joint = arm.joints.iter().find(|a| a.index == index);
        let held = arm.held.iter().find(|h| h.index == index);
        let (kind, origin) = match (arm_joint, held) {
            (Some(_), _) => (j.kind, j.origin),
            (None, Some(h)) => (
                JointType::Fixed,
                held_origin(j, index, h.value).map_err(config)?,
            ),
            (None, None) => (JointType::Fixed, j.origin),
        };
        let (xyz, rpy) = origin.xyz_rpy().map_err(config)?;
        let _ = write!(
            out,
            "  <joint name={} type=\"{}\">\n    <origin xyz=\"{}\" rpy=\"{}\"/>\n    \
             <parent link={}/>\n    <child link={}/>\n",
            attr(&j.name),
            kind.urdf_name(),
            triple(xyz),
            triple(rpy),
            attr(&j.parent),
            attr(&j.child)
        );
        if let Some(a) = arm_joint {
            write_arm_joint(&mut out, j, kind, a, drive);
        }
        out.push_str("  </joint>\n");
    }
    out.push_str("</robot>\n");
    Ok(out)
}

/// Link `l` with its inertial only (SPEC (21.3)), or an empty link.
pub(super) fn write_link(out: &mut String, l: &Link) -> Result<(), crate::error::Error> {
    let Some(i) = &l.inertial else {
        let _ = writeln!(out, "  <link name={}/>", attr(&l.name));
        return Ok(());
    };
    let (xyz, rpy) = i.origin.xyz_rpy()?;
    let m = &i.inertia;
    let _ = writeln!(
        out,
        "  <link name={}>\n    <inertial>\n      <origin xyz=\"{}\" rpy=\"{}\"/>\n      \
         <mass value=\"{}\"/>\n      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" \
         iyz=\"{}\" izz=\"{}\"/>\n    </inertial>\n  </link>",
        attr(&l.name),
        triple(xyz),
        triple(rpy),
        i.mass,
        m[0][0],
        m[0][1],
        m[0][2],
        m[1][1],
        m[1][2],
        m[2][2]
    );
    Ok(())
}

/// The origin of joint `j` (index `index`) held at `value` (SPEC (21.3)):
/// held away from its offset, its motion folds into its origin.
pub(super) fn held_origin(
    j: &TreeJoint,
    index: usize,
    value: f64,
) -> Result<Origin, crate::error::Error> {
    let shift = value - j.offset;
    if !(j.kind.is_movable() && shift != 0.0) {
        return Ok(j.origin);
    }
    let f = j.origin.transform()?.check(index)?;
    let axis = nalgebra::Vector3::from(j.axis);
    let len = axis.norm();
    if len > 1e-12 {
        let moved = f.then(&crate::description::tree::motion(
            j.kind == JointType::Prismatic,
            &(axis / len),
            shift,
        ));
        return Ok(Origin::Matrix(
            crate::cartesian::chain::Transform::from_parts(moved.p, &moved.r),
        ));
    }
    Ok(j.origin)
}

/// An arm joint's axis, its limits (when limited or continuous: a stated
/// effort and velocity, or 0: none) and, with `drive`, its `<dynamics>`.
pub(super) fn write_arm_joint(
    out: &mut String,
    j: &TreeJoint,
    kind: JointType,
    a: &ArmJoint,
    drive: bool,
) {
    let _ = writeln!(out, "    <axis xyz=\"{}\"/>", triple(j.axis));
    if (a.lower.is_finite() && a.upper.is_finite()) || kind == JointType::Continuous {
        // A stated effort (MuJoCo's actuator force range), or 0: none.
        let effort = if a.effort.is_finite() { a.effort } else { 0.0 };
        let velocity = if a.velocity.is_finite() {
            a.velocity
        } else {
            0.0
        };
        let range = if kind == JointType::Continuous {
            String::new()
        } else {
            format!("lower=\"{}\" upper=\"{}\" ", a.lower, a.upper)
        };
        let _ = writeln!(
            out,
            "    <limit {range}effort=\"{effort}\" velocity=\"{velocity}\"/>"
        );
    }
    if drive && (a.damping != 0.0 || a.friction != 0.0) {
        let _ = writeln!(
            out,
            "    <dynamics damping=\"{}\" friction=\"{}\"/>",
            a.damping, a.friction
        );
    }
}
