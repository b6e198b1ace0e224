//! The kinematic tree of a robot description, SPEC (21.1): links with their
//! inertials, joints between them, named frames on links. What a URDF file
//! or a compiled MuJoCo model holds, as plain data, validated once by
//! [`Tree::new`].

use super::error::{DescriptionError, ErrorKind};
use crate::cartesian::chain::{Frame, Transform};
use crate::cartesian::dynamics::Inertial;
use alloc::collections::BTreeMap;
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use nalgebra::{Matrix3, Rotation3, Vector3};

mod check;
use check::*;

/// What a joint of a tree does.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum JointType {
    /// Rigid (URDF `fixed`; a MuJoCo body without joints).
    Fixed,
    /// Rotation about the axis within limits (URDF `revolute`; a MuJoCo
    /// `hinge`), in rad.
    Revolute,
    /// Rotation about the axis without limits (URDF `continuous`), in rad.
    Continuous,
    /// Translation along the axis (URDF `prismatic`; MuJoCo `slide`), in m.
    Prismatic,
    /// Six degrees of freedom (URDF `floating`; MuJoCo `free`).
    Floating,
    /// Motion in a plane (URDF `planar`).
    Planar,
    /// Three rotations about a point (URDF `spherical`; MuJoCo `ball`).
    Ball,
}

impl JointType {
    /// Revolute, continuous or prismatic: one coordinate, a joint an arm can drive.
    pub fn is_movable(self) -> bool {
        matches!(self, Self::Revolute | Self::Continuous | Self::Prismatic)
    }

    /// The name a description of `dialect` gives it.
    pub fn name_in(self, dialect: Dialect) -> &'static str {
        match (dialect, self) {
            (Dialect::Mujoco, Self::Fixed) => "fixed (no joint)",
            (Dialect::Mujoco, Self::Revolute | Self::Continuous) => "hinge",
            (Dialect::Mujoco, Self::Prismatic) => "slide",
            (Dialect::Mujoco, Self::Floating) => "free",
            (Dialect::Mujoco, Self::Ball) => "ball",
            _ => self.urdf_name(),
        }
    }

    /// The name a URDF gives it.
    pub fn urdf_name(self) -> &'static str {
        match self {
            Self::Fixed => "fixed",
            Self::Revolute => "revolute",
            Self::Continuous => "continuous",
            Self::Prismatic => "prismatic",
            Self::Floating => "floating",
            Self::Planar => "planar",
            Self::Ball => "spherical",
        }
    }
}

/// A transform as the description states it: URDF's `xyz`/`rpy`, MuJoCo's
/// `pos`/`quat` ([w, x, y, z]) or a computed one. Kept as written, so a
/// reduced URDF writes the numbers it read (MuJoCo then compiles the same
/// model from them).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Origin {
    /// URDF `<origin xyz="…" rpy="…">` (m, rad): R = Rot_z(y) Rot_y(p) Rot_x(r).
    XyzRpy([f64; 3], [f64; 3]),
    /// A position (m) and a quaternion [w, x, y, z] (normalised when used).
    PosQuat([f64; 3], [f64; 4]),
    /// A translation and a rotation matrix.
    Matrix(Transform),
}

impl Origin {
    /// No translation, no rotation.
    pub const IDENTITY: Self = Self::XyzRpy([0.0; 3], [0.0; 3]);

    /// The transform (a zero or non-finite quaternion is an error).
    pub fn transform(&self) -> Result<Transform, crate::error::Error> {
        match *self {
            Self::XyzRpy(xyz, rpy) => Ok(Transform::from_xyz_rpy(xyz, rpy)),
            Self::PosQuat(pos, quat) => Transform::from_pos_quat(pos, quat),
            Self::Matrix(t) => Ok(t),
        }
    }

    /// As URDF writes it: `xyz` (m) and `rpy` (rad); exact for
    /// [`Origin::XyzRpy`], from the rotation matrix otherwise.
    pub fn xyz_rpy(&self) -> Result<([f64; 3], [f64; 3]), crate::error::Error> {
        if let Self::XyzRpy(xyz, rpy) = *self {
            return Ok((xyz, rpy));
        }
        let t = self.transform()?;
        let r = Rotation3::from_matrix_unchecked(Matrix3::from_fn(|i, j| t.rotation[i][j]));
        let (roll, pitch, yaw) = r.euler_angles();
        Ok((t.translation, [roll, pitch, yaw]))
    }
}

/// The share of the trace by which the two smaller principal moments of an
/// inertia may fall short of the largest before [`LinkInertial::balance`]
/// balances it (rounding in a file's six numbers).
pub const BALANCE_TOLERANCE: f64 = 1e-9;

/// The inertial of a link: its mass, centre of mass and rotational inertia
/// about the centre of mass, in the frame `origin` of the link
/// (URDF `<inertial>`; MuJoCo `body_mass`, `body_ipos`, `body_iquat`,
/// `body_inertia`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct LinkInertial {
    /// Mass (kg), ≥ 0.
    pub mass: f64,
    /// The centre of mass (m) and the inertia's axes in the link's frame.
    pub origin: Origin,
    /// Rotational inertia about the centre of mass in `origin`'s axes (kg
    /// m², row-major), symmetric.
    pub inertia: [[f64; 3]; 3],
    /// The share of its weight gravity compensation lifts (MuJoCo's body
    /// `gravcomp`; 0 in a URDF): a force of `gravcomp` × mass × (−gravity)
    /// at its centre of mass.
    pub gravcomp: f64,
}

impl LinkInertial {
    /// The inertia balanced where its principal moments break the triangle
    /// inequality (A + B ≥ C, which every rigid body's meet): the moments
    /// set to their mean, about the same centre of mass (MuJoCo's
    /// `balanceinertia`), SPEC (21.4). Returns whether it changed it. An
    /// inertia with a negative moment is left as it is (not a body's).
    pub fn balance(&mut self) -> bool {
        let m = Matrix3::from_fn(|i, j| self.inertia[i][j]);
        let d = m.symmetric_eigenvalues();
        let (lo, hi) = (d.min(), d.max());
        let sum = d[0] + d[1] + d[2];
        if !sum.is_finite() || lo < 0.0 || sum - hi >= hi - BALANCE_TOLERANCE * sum {
            return false;
        }
        let mean = sum / 3.0;
        self.inertia = [[mean, 0.0, 0.0], [0.0, mean, 0.0], [0.0, 0.0, mean]];
        true
    }

    /// No mass.
    pub const NONE: Self = Self {
        mass: 0.0,
        origin: Origin::IDENTITY,
        inertia: [[0.0; 3]; 3],
        gravcomp: 0.0,
    };

    /// Whether it has a mass or an inertia.
    pub fn has_mass(&self) -> bool {
        self.mass != 0.0 || self.inertia.iter().flatten().any(|&x| x != 0.0)
    }

    /// As the core's dynamics takes it.
    pub fn to_inertial(&self) -> Result<Inertial, crate::error::Error> {
        Ok(Inertial {
            mass: self.mass,
            origin: self.origin.transform()?,
            inertia: self.inertia,
        })
    }
}

/// The description a tree was read from, for the words of its messages.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Dialect {
    /// A URDF: `revolute`, `continuous`, `prismatic`.
    Urdf,
    /// A MuJoCo model: `hinge`, `slide`.
    Mujoco,
}

impl Dialect {
    /// The joints an arm drives, in these words.
    pub fn rotary(self) -> &'static str {
        match self {
            Dialect::Urdf => "revolute or continuous joint",
            Dialect::Mujoco => "hinge joint",
        }
    }

    /// A joint that translates, in these words.
    pub fn linear(self) -> &'static str {
        match self {
            Dialect::Urdf => "prismatic joint",
            Dialect::Mujoco => "slide joint",
        }
    }
}

/// A link (URDF `<link>`, a MuJoCo body).
#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    /// Its name, unique in the tree.
    pub name: String,
    /// Its inertial (None: the description states none).
    pub inertial: Option<LinkInertial>,
}

impl Link {
    /// A link without mass.
    pub fn new(name: &str) -> Self {
        Self {
            name: name.into(),
            inertial: None,
        }
    }
}

/// A joint whose value follows another's: q = multiplier · q_master + offset
/// (URDF `<mimic>`; a MuJoCo joint equality).
#[derive(Clone, Debug, PartialEq)]
pub struct Mimic {
    /// The joint it follows.
    pub joint: String,
    /// The factor on the master's value.
    pub multiplier: f64,
    /// The value (rad or m) at a master's value of zero.
    pub offset: f64,
}

/// A joint of a tree (SPEC (21.1)).
#[derive(Clone, Debug, PartialEq)]
pub struct TreeJoint {
    /// Its name, unique in the tree.
    pub name: String,
    /// What it does.
    pub kind: JointType,
    /// The link it hangs from.
    pub parent: String,
    /// The link it carries: its frame is the joint's.
    pub child: String,
    /// The parent link's frame → the joint's frame at the joint value
    /// `offset`.
    pub origin: Origin,
    /// The axis (in the joint's frame; URDF's default (1, 0, 0)).
    pub axis: [f64; 3],
    /// The joint value (rad or m) at which the joint's frame is `origin`
    /// (URDF: 0; MuJoCo: `qpos0`), and the value a held joint is held at.
    pub offset: f64,
    /// Position limits (rad or m); −∞ and +∞ where there are none.
    pub lower: f64,
    /// See `lower`.
    pub upper: f64,
    /// The largest torque (N m) or force (N) the joint's drive gives; NaN
    /// where the description states none.
    pub effort: f64,
    /// The largest speed (rad/s or m/s); NaN where the description states none.
    pub velocity: f64,
    /// Viscous damping (N m s/rad or N s/m), ≥ 0.
    pub damping: f64,
    /// Dry friction loss (N m or N), ≥ 0.
    pub friction: f64,
    /// Armature: the rotor's inertia reflected to the joint (kg m² or kg), ≥ 0.
    pub armature: f64,
    /// The joint it follows, if it is a mimic joint.
    pub mimic: Option<Mimic>,
    /// What couples it to other joints, if anything does (a MuJoCo fixed
    /// tendon of two or more joints): it does not move on its own.
    pub coupled: Option<String>,
}

impl TreeJoint {
    /// A joint of `kind` from `parent` to `child` at `origin`, axis (1, 0, 0),
    /// no limits, no effort, velocity, damping, friction, armature or mimic.
    pub fn new(name: &str, kind: JointType, parent: &str, child: &str, origin: Origin) -> Self {
        Self {
            name: name.into(),
            kind,
            parent: parent.into(),
            child: child.into(),
            origin,
            axis: [1.0, 0.0, 0.0],
            offset: 0.0,
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            effort: f64::NAN,
            velocity: f64::NAN,
            damping: 0.0,
            friction: 0.0,
            armature: 0.0,
            mimic: None,
            coupled: None,
        }
    }
}

/// A named frame on a link (a MuJoCo site, a tool frame).
#[derive(Clone, Debug, PartialEq)]
pub struct NamedFrame {
    /// Its name, unique among frames.
    pub name: String,
    /// The link it is fixed to.
    pub link: String,
    /// The link's frame → this frame.
    pub origin: Origin,
    /// A tool frame: where a force/torque sensor measures (a MuJoCo force
    /// sensor's site). Without `tip`, the first one ends the arm.
    pub tool: bool,
}

/// A validated kinematic tree (SPEC (21.1)): links, the joints between them, named frames.
#[derive(Clone, Debug, PartialEq)]
pub struct Tree {
    source: String,
    /// Whose words the messages use for its joints.
    dialect: Dialect,
    /// The links whose inertia the reader balanced ([`LinkInertial::balance`]).
    balanced: Vec<String>,
    name: String,
    links: Vec<Link>,
    joints: Vec<TreeJoint>,
    frames: Vec<NamedFrame>,
    /// Per link: the index of the joint that carries it.
    parent_joint: Vec<Option<usize>>,
    /// Per link: the joints that hang from it, in the description's order.
    children: Vec<Vec<usize>>,
    /// Per link: the frames on it.
    link_frames: Vec<Vec<usize>>,
    /// Per joint: the indices of its parent and child links.
    ends: Vec<(usize, usize)>,
    link_index: BTreeMap<String, usize>,
    joint_index: BTreeMap<String, usize>,
    frame_index: BTreeMap<String, usize>,
}

impl Tree {
    /// A tree of `links` and `joints` (and named `frames` on links) from the
    /// description `source` (for messages, e.g. `"URDF 'panda.urdf'"`),
    /// named `name`.
    ///
    /// Errors (each naming `source`, the element and what to do): two links,
    /// two joints or two frames of one name; a joint whose parent or child
    /// link is not declared; a link carried by two joints; joints that form
    /// a loop; a frame on a link not declared; a non-finite number; a
    /// negative mass, damping, friction or armature; a lower limit above the
    /// upper one. (A mimic joint whose master is not another joint of the
    /// tree is the reduction's to judge: [`Tree::mimic_error`].)
    pub fn new(
        source: &str,
        name: &str,
        links: Vec<Link>,
        joints: Vec<TreeJoint>,
        frames: Vec<NamedFrame>,
    ) -> Result<Self, DescriptionError> {
        let link_index = index_links(source, &links)?;
        let Edges {
            joint_index,
            parent_joint,
            children,
            ends,
        } = Edges::of(source, &link_index, &joints)?;
        for j in &joints {
            if let Some(m) = &j.mimic {
                finite_or(
                    source,
                    "the mimic multiplier and offset",
                    &j.name,
                    &[m.multiplier, m.offset],
                )?;
            }
        }
        check_no_loop(source, &links, &parent_joint, &ends)?;
        let (frame_index, link_frames) = index_frames(source, &link_index, &frames)?;
        Ok(Self {
            source: source.into(),
            dialect: Dialect::Urdf,
            balanced: Vec::new(),
            name: name.into(),
            links,
            joints,
            frames,
            parent_joint,
            children,
            link_frames,
            ends,
            link_index,
            joint_index,
            frame_index,
        })
    }

    /// The tree in the words of `dialect` (its messages name MuJoCo's
    /// `hinge` and `slide` for a model MuJoCo compiled).
    pub fn in_dialect(mut self, dialect: Dialect) -> Self {
        self.dialect = dialect;
        self
    }

    /// Whose words the messages use for its joints.
    pub fn dialect(&self) -> Dialect {
        self.dialect
    }

    /// Every link's inertia balanced where it breaks the triangle
    /// inequality ([`LinkInertial::balance`], SPEC (21.4)): the reader does
    /// it once, so every model built from the tree (the plant, the chain,
    /// computed torque, Pinocchio's from the reduced URDF) has the same.
    pub fn balanced_inertias(mut self) -> Self {
        for link in &mut self.links {
            if let Some(inertial) = link.inertial.as_mut() {
                if inertial.balance() {
                    self.balanced.push(link.name.clone());
                }
            }
        }
        self
    }

    /// The links whose inertia the reader balanced, in the tree's order.
    pub fn balanced(&self) -> &[String] {
        &self.balanced
    }

    /// Why joint `j`'s mimic names no joint it can follow, if it does not:
    /// a joint the tree does not have, itself, or a circle of mimics none of
    /// which is driven (a file's mistake: real files have mimics of joints
    /// renamed since, on hands off the arm).
    pub fn mimic_error(&self, j: usize) -> Option<String> {
        let m = self.joints[j].mimic.as_ref()?;
        let name = &self.joints[j].name;
        let Some(mut k) = self.joint_index(&m.joint) else {
            return Some(format!(
                "joint '{name}' mimics '{}', which is not a joint of it",
                m.joint
            ));
        };
        if k == j {
            return Some(format!("joint '{name}' mimics itself"));
        }
        // Following masters ends at a joint that mimics none, within as many
        // steps as there are joints.
        for _ in 0..self.joints.len() {
            match self.joints[k]
                .mimic
                .as_ref()
                .map(|m| self.joint_index(&m.joint))
            {
                None | Some(None) => return None,
                Some(Some(next)) if next == j => {
                    return Some(format!(
                        "joint '{name}' mimics '{}', which follows it back: a circle of mimic \
                         joints none of which is driven",
                        m.joint
                    ))
                }
                Some(Some(next)) => k = next,
            }
        }
        None
    }

    /// What the tree was read from, for messages (e.g. `"URDF 'panda.urdf'"`).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The robot's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The links, in the description's order.
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// The joints, in the description's order.
    pub fn joints(&self) -> &[TreeJoint] {
        &self.joints
    }

    /// The named frames.
    pub fn frames(&self) -> &[NamedFrame] {
        &self.frames
    }

    /// The index of the link `name`.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.link_index.get(name).copied()
    }

    /// The index of the joint `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joint_index.get(name).copied()
    }

    /// The index of the frame `name`.
    pub fn frame_index(&self, name: &str) -> Option<usize> {
        self.frame_index.get(name).copied()
    }

    /// The joint that carries link `l` (None for a root).
    pub fn parent_joint(&self, l: usize) -> Option<usize> {
        self.parent_joint[l]
    }

    /// The joints hanging from link `l`, in the description's order.
    pub fn child_joints(&self, l: usize) -> &[usize] {
        &self.children[l]
    }

    /// The frames on link `l`.
    pub fn link_frames(&self, l: usize) -> &[usize] {
        &self.link_frames[l]
    }

    /// The parent and child link of joint `j`.
    pub fn joint_links(&self, j: usize) -> (usize, usize) {
        self.ends[j]
    }

    /// The links no joint carries.
    pub fn roots(&self) -> Vec<usize> {
        (0..self.links.len())
            .filter(|&l| self.parent_joint[l].is_none())
            .collect()
    }

    /// The root at the top of link `l`'s way up.
    pub fn root_of(&self, mut l: usize) -> usize {
        while let Some(j) = self.parent_joint[l] {
            l = self.ends[j].0;
        }
        l
    }

    /// The joints from the root down to link `l` (base to tip).
    pub fn path_to(&self, mut l: usize) -> Vec<usize> {
        let mut path = Vec::new();
        while let Some(j) = self.parent_joint[l] {
            path.push(j);
            l = self.ends[j].0;
        }
        path.reverse();
        path
    }
}

/// The motion of a joint about or along its unit `axis` by `value` (rad or
/// m), as the chain moves a joint (SPEC (16.0)).
pub(crate) fn motion(prismatic: bool, axis: &Vector3<f64>, value: f64) -> Frame {
    if prismatic {
        Frame {
            p: axis * value,
            r: Matrix3::identity(),
        }
    } else {
        Frame {
            p: Vector3::zeros(),
            r: crate::cartesian::chain::axis_rotation(axis, value),
        }
    }
}

#[cfg(test)]
mod tests;
